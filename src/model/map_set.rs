//! The two map buffers a design holds: buffer 0 is the scene's map (the design's initial
//! contents of both buffers), buffer 1 the second map that testbenches load through the host
//! port. The vectors, the testbenches and the bank init files all read this one value.

use crate::config::Config;
use crate::model::Maps;
use crate::scene::Scene;
use anyhow::{bail, Context, Result};
use std::path::Path;

/// The two map buffers the vectors assume: buffer 0 holds the scene's map (the design's
/// initial contents), buffer 1 the second map the testbenches load through the host port.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MapSet {
    pub scene: Maps,
    pub second: Maps,
}

impl MapSet {
    /// The standard scene's map and the alternate scene's.
    pub fn standard(cfg: &Config) -> MapSet {
        MapSet::from_scenes(cfg, &Scene::standard(), &Scene::alternate())
    }

    /// With `comp_table = ram` the second buffer's table is the linear index's positions
    /// (`linear_index::eval`), not the first buffer's atan table: a testbench that loads the
    /// second buffer must see the table change with the maps.
    pub fn from_scenes(cfg: &Config, scene: &Scene, second: &Scene) -> MapSet {
        let mut second = second.maps(cfg);
        if second.table.is_some() {
            let linear = (0..cfg.atan_entries())
                .map(|u| crate::model::linear_index::eval(cfg, u))
                .collect();
            second = second
                .with_table(cfg, linear)
                .expect("positions within range");
        }
        MapSet {
            scene: scene.maps(cfg),
            second,
        }
    }

    /// Reads `map_{x,y,z}.hex` and `map2_{x,y,z}.hex` ([`map_file`], with the
    /// configuration's prefix) from a generated design directory, so the vectors match
    /// whatever scene the design was generated with.
    pub fn from_dir(cfg: &Config, dir: &Path) -> Result<MapSet> {
        Ok(MapSet {
            scene: read_maps(cfg, dir, 0)?,
            second: read_maps(cfg, dir, 1)?,
        })
    }

    /// Buffer 0 or 1.
    pub fn buffer(&self, buf: u64) -> &Maps {
        if buf == 0 {
            &self.scene
        } else {
            &self.second
        }
    }
}

/// Largest map file `vectors --maps` reads (16 MiB): the widest configuration's map has
/// 32 768 entries of a few bytes each; a file far beyond that is not a map.
pub const MAX_MAP_FILE_BYTES: u64 = 16 << 20;

/// The axes' names in map file names, in axis order.
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// The compensation table's name in map file names (`map_table.hex`), with `comp_table =
/// ram`: the host streams it with the maps, as axis slot 3.
pub const TABLE: &str = "table";

/// The logical files of one buffer, by name: the three axes' maps ([`AXES`]) and, with
/// `comp_table = ram`, the compensation table ([`TABLE`]). Index k is write-port axis slot k.
pub fn buffer_names(cfg: &Config) -> Vec<&'static str> {
    let mut v = AXES.to_vec();
    if !cfg.comp_table.is_rom() {
        v.push(TABLE);
    }
    v
}

/// The logical map file (`$readmemh`, logical address order) of buffer `buf` (0 the scene's
/// map, 1 the second map) and axis `axis` (one of [`AXES`], or a pattern such as `*` or
/// `<axis>` in messages): `<prefix>map_<axis>.hex` and `<prefix>map2_<axis>.hex`.
pub fn map_file(cfg: &Config, buf: u32, axis: &str) -> String {
    let map = if buf == 0 { "map" } else { "map2" };
    cfg.prefixed(&format!("{map}_{axis}.hex"))
}

/// Reads the `$readmemh` files of buffer `buf`, [`map_file`] (logical address order): one
/// per name of [`buffer_names`], the table too with `comp_table = ram`.
pub fn read_maps(cfg: &Config, dir: &Path, buf: u32) -> Result<Maps> {
    let mut data = Vec::with_capacity(3 * cfg.map_entries() as usize);
    let mut table = Vec::new();
    for name in buffer_names(cfg) {
        let (data, max, bits, entries) = if name == TABLE {
            (
                &mut table,
                cfg.pos_max(),
                cfg.pos_bits(),
                cfg.atan_entries(),
            )
        } else {
            (&mut data, cfg.map_max(), cfg.map_bits, cfg.map_entries())
        };
        let p = dir.join(map_file(cfg, buf, name));
        if p.is_dir() {
            bail!("map {} is a directory, not a map file", p.display());
        }
        if let Ok(m) = std::fs::metadata(&p) {
            if m.len() > MAX_MAP_FILE_BYTES {
                bail!(
                    "map {} is {} bytes, more than the limit of {MAX_MAP_FILE_BYTES} for a map file",
                    p.display(),
                    m.len()
                );
            }
        }
        let text = std::fs::read_to_string(&p)
            .with_context(|| format!("cannot read map {}", p.display()))?;
        let before = data.len();
        for (n, line) in text.lines().enumerate() {
            let t = line.split("//").next().unwrap_or("").trim();
            if t.is_empty() {
                continue;
            }
            let v = u32::from_str_radix(t, 16)
                .with_context(|| format!("{}:{}: not a hex entry: {t:?}", p.display(), n + 1))?;
            if v > max {
                let limit = if name == TABLE {
                    format!("past the largest position {max} (pos_max)")
                } else {
                    format!("wider than map_bits = {bits}")
                };
                bail!("{}:{}: entry {v:#x} is {limit}", p.display(), n + 1);
            }
            data.push(v);
        }
        let got = data.len() - before;
        if got != entries as usize {
            bail!(
                "{} has {got} entries; the configuration needs {entries}",
                p.display(),
            );
        }
    }
    let maps = Maps::from_data(cfg, data);
    if cfg.comp_table.is_rom() {
        Ok(maps)
    } else {
        maps.with_table(cfg, table)
    }
}
