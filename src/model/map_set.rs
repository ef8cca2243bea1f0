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
            let v = u32::from_str_radix(t, 16).with_context(|| {
                format!(
                    "{}:{}: not a hex entry: {}",
                    p.display(),
                    n + 1,
                    crate::toml_input::quoted(t)
                )
            })?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::CompTable;
    use crate::hexfile;
    use crate::toml_input::{quoted, QUOTED_MAX};

    fn ram(prefix: &str) -> Config {
        Config {
            comp_table: CompTable::Ram,
            prefix: prefix.into(),
            ..Config::default()
        }
    }

    /// Writes buffer `buf` of `maps` as the design's `$readmemh` files (header comments and
    /// all), the table too when the maps carry one.
    fn write_buffer(cfg: &Config, dir: &Path, buf: u32, maps: &Maps) {
        for (k, name) in buffer_names(cfg).into_iter().enumerate() {
            let (bits, entries) = if name == TABLE {
                (cfg.pos_bits(), maps.table.clone().unwrap())
            } else {
                (cfg.map_bits, maps.axis(k as u32).to_vec())
            };
            let text = hexfile::format(cfg, name, bits, &entries);
            std::fs::write(dir.join(map_file(cfg, buf, name)), text).unwrap();
        }
    }

    #[test]
    fn file_names_carry_the_buffer_the_axis_and_the_prefix() {
        let rom = Config::default();
        assert_eq!(map_file(&rom, 0, "x"), "map_x.hex");
        assert_eq!(map_file(&rom, 1, "z"), "map2_z.hex");
        assert_eq!(map_file(&ram("p_"), 1, TABLE), "p_map2_table.hex");
        assert_eq!(map_file(&ram("p_"), 0, "*"), "p_map_*.hex");
        assert_eq!(buffer_names(&rom), ["x", "y", "z"]);
        assert_eq!(buffer_names(&ram("")), ["x", "y", "z", "table"]);
    }

    /// The second buffer holds the alternate scene, and with `comp_table = ram` the linear
    /// index's positions as its table while the first holds the atan table.
    #[test]
    fn the_standard_set_is_two_scenes_and_two_tables() {
        for cfg in [Config::default(), ram("")] {
            let set = MapSet::standard(&cfg);
            assert_eq!(set.scene.data, Scene::standard().maps(&cfg).data);
            assert_eq!(set.second.data, Scene::alternate().maps(&cfg).data);
            assert_ne!(set.scene.data, set.second.data);
            assert_eq!(set.buffer(0), &set.scene);
            assert_eq!(set.buffer(1), &set.second);
            if cfg.comp_table.is_rom() {
                assert_eq!((&set.scene.table, &set.second.table), (&None, &None));
                continue;
            }
            let atan = crate::stages::atan_rom::model::contents(&cfg);
            let linear: Vec<u32> = (0..cfg.atan_entries())
                .map(|u| crate::model::linear_index::eval(&cfg, u))
                .collect();
            assert_ne!(atan, linear);
            assert_eq!(set.scene.table.as_ref(), Some(&atan));
            assert_eq!(set.second.table.as_ref(), Some(&linear));
        }
    }

    /// What the design's files hold is read back whole, comments, blank lines and trailing
    /// comments skipped, the prefix and the table with `comp_table = ram` included.
    #[test]
    fn a_design_directory_is_read_back_as_written() {
        for cfg in [Config::default(), ram("p_")] {
            let dir = tempfile::tempdir().unwrap();
            let set = MapSet::standard(&cfg);
            write_buffer(&cfg, dir.path(), 0, &set.scene);
            write_buffer(&cfg, dir.path(), 1, &set.second);
            assert_eq!(MapSet::from_dir(&cfg, dir.path()).unwrap(), set);
            // A trailing comment and blank lines are not entries.
            let p = dir.path().join(map_file(&cfg, 0, "y"));
            let text = std::fs::read_to_string(&p).unwrap();
            let mut lines: Vec<&str> = text.lines().collect();
            let first = format!("{} // the first entry", lines[2]);
            lines[2] = &first;
            lines.splice(3..3, ["", "   ", "// a comment line"]);
            std::fs::write(&p, lines.join("\n")).unwrap();
            assert_eq!(read_maps(&cfg, dir.path(), 0).unwrap(), set.scene);
        }
    }

    /// Each malformed file is refused with its name, its line and what is wrong.
    #[test]
    fn malformed_map_files_are_refused_by_line() {
        let cfg = &ram("");
        let set = MapSet::standard(cfg);
        let err = |edit: &dyn Fn(&Path)| {
            let dir = tempfile::tempdir().unwrap();
            write_buffer(cfg, dir.path(), 0, &set.scene);
            edit(dir.path());
            let e = read_maps(cfg, dir.path(), 0).unwrap_err();
            format!("{e:#}").replace(&format!("{}/", dir.path().display()), "")
        };
        // Lines 1 and 2 are the header; entry k is on line k + 3.
        let entry = |name: &'static str, k: usize, v: &str| {
            let v = v.to_string();
            move |d: &Path| {
                let p = d.join(map_file(cfg, 0, name));
                let mut lines: Vec<String> = std::fs::read_to_string(&p)
                    .unwrap()
                    .lines()
                    .map(String::from)
                    .collect();
                if v.is_empty() {
                    lines.remove(k + 2);
                } else if v == "+" {
                    lines.push("00".into());
                } else {
                    lines[k + 2] = v.clone();
                }
                std::fs::write(&p, lines.join("\n") + "\n").unwrap();
            }
        };
        assert_eq!(
            err(&entry("y", 4, "0g")),
            "map_y.hex:7: not a hex entry: \"0g\": invalid digit found in string"
        );
        assert_eq!(
            err(&entry("z", 0, "100")),
            "map_z.hex:3: entry 0x100 is wider than map_bits = 8"
        );
        // A table entry may be pos_max but no more; 255 is the widest map entry.
        assert_eq!(
            err(&entry(TABLE, 2, &format!("{:x}", cfg.pos_max() + 1))),
            format!(
                "map_table.hex:5: entry {:#x} is past the largest position {} (pos_max)",
                cfg.pos_max() + 1,
                cfg.pos_max()
            )
        );
        let dir = tempfile::tempdir().unwrap();
        write_buffer(cfg, dir.path(), 0, &set.scene);
        entry(TABLE, 2, &format!("{:x}", cfg.pos_max()))(dir.path());
        entry("z", 0, "ff")(dir.path());
        let read = read_maps(cfg, dir.path(), 0).unwrap();
        assert_eq!(
            (read.table.as_ref().unwrap()[2], read.get(2, 0)),
            (cfg.pos_max(), 255)
        );
        assert_eq!(
            err(&entry("x", 7, "")),
            "map_x.hex has 511 entries; the configuration needs 512"
        );
        assert_eq!(
            err(&entry("x", 0, "+")),
            "map_x.hex has 513 entries; the configuration needs 512"
        );
        assert_eq!(
            err(&entry(TABLE, 0, "")),
            format!(
                "map_table.hex has {} entries; the configuration needs {}",
                cfg.atan_entries() - 1,
                cfg.atan_entries()
            )
        );
        assert_eq!(
            err(&|d: &Path| std::fs::remove_file(d.join("map_y.hex")).unwrap()),
            "cannot read map map_y.hex: No such file or directory (os error 2)"
        );
        assert_eq!(
            err(&|d: &Path| {
                std::fs::remove_file(d.join("map_y.hex")).unwrap();
                std::fs::create_dir(d.join("map_y.hex")).unwrap();
            }),
            "map map_y.hex is a directory, not a map file"
        );
        // A file past the limit is refused by its size, before it is read; at the limit it
        // is read (and then refused for what it holds).
        let sized = |len: u64| {
            move |d: &Path| {
                let f = std::fs::File::create(d.join("map_z.hex")).unwrap();
                f.set_len(len).unwrap();
            }
        };
        assert_eq!(
            err(&sized(MAX_MAP_FILE_BYTES + 1)),
            format!(
                "map map_z.hex is {} bytes, more than the limit of {MAX_MAP_FILE_BYTES} for a map file",
                MAX_MAP_FILE_BYTES + 1
            )
        );
        assert_eq!(
            err(&sized(MAX_MAP_FILE_BYTES)),
            format!(
                "map_z.hex:1: not a hex entry: {:?}... ({MAX_MAP_FILE_BYTES} bytes): invalid digit found in string",
                "\0".repeat(QUOTED_MAX)
            )
        );
        assert_eq!(
            quoted(&"é".repeat(QUOTED_MAX)),
            format!("{:?}", "é".repeat(QUOTED_MAX))
        );
        assert_eq!(
            quoted(&"é".repeat(QUOTED_MAX + 1)),
            format!(
                "{:?}... ({} bytes)",
                "é".repeat(QUOTED_MAX),
                2 * QUOTED_MAX + 2
            )
        );
    }
}
