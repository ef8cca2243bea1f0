//! The three reflectance maps: for each max axis, each sign of the max and each entry
//! (s_u, i_u, s_v, i_v), the light model evaluated at the entry's direction and quantised to
//! `map_bits`. The host rebuilds them every frame; the RTL holds them in RAM.

use super::map_addr;
use crate::config::Config;
use glam::DVec3;

/// All three maps of one buffer, `map_bits` per entry, indexed [axis][addr], and with
/// `comp_table = ram` the buffer's compensation table, which the host loads with them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Maps {
    entries_per_map: usize,
    pub data: Vec<u32>,
    /// The compensation table of this buffer, one position per fraction code (`comp_table =
    /// ram`); None with the ROM, whose contents the model holds ([`crate::model::Model`]).
    pub table: Option<Vec<u32>>,
}

impl Maps {
    /// The maps `data`; with `comp_table = ram`, beside the atan table (what both buffers
    /// hold out of reset), which [`Maps::with_table`] replaces.
    pub fn from_data(cfg: &Config, data: Vec<u32>) -> Maps {
        assert_eq!(data.len(), 3 * cfg.map_entries() as usize);
        Maps {
            entries_per_map: cfg.map_entries() as usize,
            data,
            table: (!cfg.comp_table.is_rom())
                .then(|| crate::stages::atan_rom::model::contents(cfg)),
        }
    }

    /// These maps with the compensation table `table` (`comp_table = ram`): one position of
    /// at most `pos_max` per fraction code (the hardware takes any such table; a fit keeps it
    /// monotone, so that directions keep their order along a face).
    pub fn with_table(mut self, cfg: &Config, table: Vec<u32>) -> anyhow::Result<Maps> {
        if cfg.comp_table.is_rom() {
            anyhow::bail!(
                "a compensation table for a design whose table is a ROM (comp_table = rom)"
            );
        }
        if table.len() != cfg.atan_entries() as usize {
            anyhow::bail!(
                "a compensation table of {} entries; the design has {} (2^frac_bits)",
                table.len(),
                cfg.atan_entries()
            );
        }
        if let Some((u, &p)) = table.iter().enumerate().find(|(_, &p)| p > cfg.pos_max()) {
            anyhow::bail!(
                "compensation table entry {u} is {p}, past the largest position {}",
                cfg.pos_max()
            );
        }
        self.table = Some(table);
        Ok(self)
    }
    #[inline]
    pub fn get(&self, axis: u32, addr: u32) -> u32 {
        self.data[axis as usize * self.entries_per_map + addr as usize]
    }
    /// The map of one axis.
    pub fn axis(&self, axis: u32) -> &[u32] {
        let n = self.entries_per_map;
        &self.data[axis as usize * n..(axis as usize + 1) * n]
    }
}

/// The tangent at which entry `index` sits along one component.
pub fn entry_tangent(cfg: &Config, index: u32) -> f64 {
    crate::geometry::face_tangent(cfg.compensation, index as f64 / (cfg.entries() - 1) as f64)
}

/// Unit direction of one map entry, given by its axis and address fields.
pub fn entry_direction(
    cfg: &Config,
    axis: u32,
    s_max: u32,
    s_u: u32,
    i_u: u32,
    s_v: u32,
    i_v: u32,
) -> DVec3 {
    let sgn = |s: u32| if s == 1 { -1.0 } else { 1.0 };
    let mx = sgn(s_max);
    let u = sgn(s_u) * entry_tangent(cfg, i_u);
    let v = sgn(s_v) * entry_tangent(cfg, i_v);
    crate::geometry::sym_normalize(DVec3::from_array(crate::geometry::place(axis, mx, u, v)))
}

/// Quantises a light-model intensity (clamped to 0..=1) to `map_bits`, half up.
pub fn quantise(cfg: &Config, intensity: f64) -> u32 {
    let i = if intensity.is_nan() {
        0.0
    } else {
        intensity.clamp(0.0, 1.0)
    };
    (i * cfg.map_max() as f64 + 0.5).floor() as u32
}

/// The maps' contents for a light model given as a function of the unit normal: used by the
/// model and by the hex writer.
pub fn contents(cfg: &Config, shade: impl Fn(DVec3) -> f64) -> Maps {
    let n = cfg.entries();
    let mut data = vec![0u32; 3 * cfg.map_entries() as usize];
    for axis in 0..3 {
        for s_max in 0..2 {
            for s_u in 0..2 {
                for s_v in 0..2 {
                    for i_u in 0..n {
                        for i_v in 0..n {
                            let a = map_addr::addr(cfg, s_max, s_u, i_u, s_v, i_v);
                            let d = entry_direction(cfg, axis, s_max, s_u, i_u, s_v, i_v);
                            data[(axis * cfg.map_entries() + a) as usize] = quantise(cfg, shade(d));
                        }
                    }
                }
            }
        }
    }
    Maps::from_data(cfg, data)
}
