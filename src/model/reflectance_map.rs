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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::CompTable;

    /// Half up to `map_bits`, clamped, NaN as 0.
    #[test]
    fn quantise_rounds_half_up_and_clamps() {
        let cfg = Config::default(); // map_bits 8
        let q = |i: f64| quantise(&cfg, i);
        assert_eq!(
            [q(0.0), q(1.0), q(0.5), q(-0.1), q(1.5)],
            [0, 255, 128, 0, 255]
        );
        assert_eq!(
            [q(f64::NAN), q(f64::INFINITY), q(f64::NEG_INFINITY)],
            [0, 255, 0]
        );
        // Exactly half a step rounds up; just below it, down.
        assert_eq!(q(0.5 / 255.0), 1);
        assert_eq!(q(0.499 / 255.0), 0);
        assert_eq!(q(10.5 / 255.0), 11);
        assert_eq!(q(10.499 / 255.0), 10);
        let wide = Config {
            map_bits: 12,
            ..Config::default()
        };
        assert_eq!(quantise(&wide, 1.0), 4095);
        assert_eq!(quantise(&wide, 0.25), 1024);
    }

    /// An entry's direction: the max axis, its sign, and the two tangents with their signs,
    /// along the tangents of the entries (angles with compensation).
    #[test]
    fn an_entrys_direction_is_its_axis_signs_and_tangents() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let t = (std::f64::consts::FRAC_PI_4 / 7.0).tan(); // entry 1 of 8, compensated
        for (cfg, t1) in [
            (Config::default(), t),
            (
                Config {
                    compensation: false,
                    ..Config::default()
                },
                1.0 / 7.0,
            ),
        ] {
            assert_eq!(entry_tangent(&cfg, 0), 0.0);
            assert!((entry_tangent(&cfg, 1) - t1).abs() < 1e-15);
            assert_eq!(entry_tangent(&cfg, 7), 1.0);
            let d = |axis, s_max, s_u, i_u, s_v, i_v| {
                entry_direction(&cfg, axis, s_max, s_u, i_u, s_v, i_v).to_array()
            };
            let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-15);
            assert_eq!(d(0, 0, 0, 0, 0, 0), [1.0, 0.0, 0.0]);
            assert_eq!(d(0, 1, 0, 0, 0, 0), [-1.0, 0.0, 0.0]);
            assert_eq!(d(1, 1, 1, 0, 1, 0), [0.0, -1.0, 0.0]);
            assert_eq!(d(2, 0, 0, 0, 0, 0), [0.0, 0.0, 1.0]);
            assert!(near(d(2, 1, 1, 7, 0, 0), [-h, 0.0, -h]));
            assert!(near(d(1, 0, 0, 0, 1, 7), [0.0, h, -h]));
            let n = (1.0 + t1 * t1).sqrt();
            assert!(near(d(0, 0, 1, 1, 0, 0), [1.0 / n, -t1 / n, 0.0]));
            assert!(near(d(1, 1, 0, 0, 0, 1), [0.0, -1.0 / n, t1 / n]));
            let c = 1.0 / 3f64.sqrt();
            assert!(near(d(2, 0, 1, 7, 1, 7), [-c, -c, c]));
        }
    }

    /// Every entry of every axis holds the light model at that entry's direction, at the
    /// address of its fields.
    #[test]
    fn each_entry_holds_the_light_model_at_its_direction() {
        let cfg = Config {
            index_bits: 2,
            ..Config::default()
        };
        let light = |n: DVec3| 0.5 + 0.3 * n.x + 0.15 * n.y + 0.05 * n.z;
        let maps = contents(&cfg, light);
        let mut seen = std::collections::HashSet::new();
        for axis in 0..3 {
            assert_eq!(maps.axis(axis).len(), cfg.map_entries() as usize);
            for a in 0..cfg.map_entries() {
                let f = map_addr::MapAddr::decode(&cfg, a);
                let d = entry_direction(&cfg, axis, f.s_max, f.s_u, f.i_u, f.s_v, f.i_v);
                assert_eq!(
                    maps.get(axis, a),
                    quantise(&cfg, light(d)),
                    "axis {axis} {f:?}"
                );
                assert_eq!(maps.axis(axis)[a as usize], maps.get(axis, a));
                seen.insert(maps.get(axis, a));
            }
        }
        assert!(seen.len() > 100, "{} distinct entries", seen.len());
        assert_eq!(maps.table, None);
    }

    /// A RAM table design's maps carry the atan table out of reset; a table of another
    /// length, one past the largest position, or any table for a ROM design, is refused.
    #[test]
    fn a_table_is_checked_before_it_is_taken() {
        let cfg = Config {
            comp_table: CompTable::Ram,
            ..Config::default()
        };
        let data = vec![7; 3 * cfg.map_entries() as usize];
        let maps = Maps::from_data(&cfg, data.clone());
        let atan = crate::stages::atan_rom::model::contents(&cfg);
        assert_eq!(maps.table.as_ref(), Some(&atan));
        let n = cfg.atan_entries() as usize;
        let mut table = vec![cfg.pos_max(); n];
        table[0] = 0;
        let taken = maps.clone().with_table(&cfg, table.clone()).unwrap();
        assert_eq!((taken.table.as_ref(), &taken.data), (Some(&table), &data));
        let e = |t: Vec<u32>| maps.clone().with_table(&cfg, t).unwrap_err().to_string();
        assert_eq!(
            e(vec![0; n + 1]),
            format!(
                "a compensation table of {} entries; the design has {n} (2^frac_bits)",
                n + 1
            )
        );
        assert!(e(vec![0; n - 1]).starts_with(&format!("a compensation table of {} ", n - 1)));
        table[9] = cfg.pos_max() + 1;
        assert_eq!(
            e(table),
            format!(
                "compensation table entry 9 is {}, past the largest position {}",
                cfg.pos_max() + 1,
                cfg.pos_max()
            )
        );
        let rom = Config::default();
        let rom_maps = Maps::from_data(&rom, data);
        assert_eq!(rom_maps.table, None);
        assert_eq!(
            rom_maps
                .with_table(&rom, vec![0; n])
                .unwrap_err()
                .to_string(),
            "a compensation table for a design whose table is a ROM (comp_table = rom)"
        );
    }

    #[test]
    #[should_panic(expected = "assertion `left == right` failed")]
    fn maps_of_the_wrong_size_are_a_bug() {
        let cfg = Config::default();
        Maps::from_data(&cfg, vec![0; 3 * cfg.map_entries() as usize - 1]);
    }
}
