//! One frame's maps as the host write port's stream (`rmapgen maps`): every entry of the three
//! axis maps as one write (`wr_axis_i`, `wr_addr_i`, `wr_data_i`), in write order (axis x, y,
//! z; within an axis, address 0 upwards, so write k of an axis is address k, line k of its
//! `map_<axis>.hex`). The top testbench loads its second map in this order too.
//!
//! Formats (docs/USAGE.md, "Host map stream"):
//! - **hex**: header lines starting with `//`, then one write per line, `axis address data` in
//!   lower-case hex, zero-padded to 1, ceil(A/4) and ceil(M/4) digits, single spaces.
//!   `$readmemh` reads it as 3 words per write.
//! - **bin**: no header; one 6-byte record per write, three unsigned 16-bit little-endian
//!   numbers: axis, address, data.
//! - **c**: a C header: a comment naming the scene, configuration and fields, a
//!   `#define <TOP>_MAP_WRITES` count and `static const uint16_t <top>_map_writes[][3]`, one
//!   `{axis, address, data}` row per write.

use crate::config::Config;
use crate::model::Maps;
use crate::scene::Scene;
use crate::stages;
use crate::toml_input::quoted;
use anyhow::{bail, Context, Result};

/// The first characters of a hex or C stream rmapgen wrote (after `//` or `/*`).
const MARK: &str = " rmapgen map stream:";

/// Bytes per record of the binary format.
pub const RECORD_BYTES: usize = 6;

/// Output formats of `rmapgen maps`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// One write per line: `axis address data` in hex.
    Hex,
    /// Fixed 6-byte records: axis, address, data as little-endian u16.
    Bin,
    /// A C array `{axis, address, data}` with a header comment.
    C,
}

/// One host write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Write {
    pub axis: u32,
    pub addr: u32,
    pub data: u32,
}

/// The write-port axis slot of the compensation table (`comp_table = ram`).
pub const TABLE_SLOT: u32 = 3;

/// Writes in one frame's stream: every entry of the three maps and, with `comp_table = ram`,
/// of the table.
pub fn write_count(cfg: &Config) -> u32 {
    3 * cfg.map_entries()
        + if cfg.comp_table.is_rom() {
            0
        } else {
            cfg.atan_entries()
        }
}

/// Every entry of `maps` as a write, in write order; with `comp_table = ram` the table
/// follows the maps, in axis slot [`TABLE_SLOT`], address u 0 upwards.
pub fn writes(cfg: &Config, maps: &Maps) -> Vec<Write> {
    let mut v: Vec<Write> = (0..3)
        .flat_map(|axis| {
            (0..cfg.map_entries()).map(move |addr| Write {
                axis,
                addr,
                data: maps.get(axis, addr),
            })
        })
        .collect();
    if let Some(table) = &maps.table {
        v.extend(table.iter().enumerate().map(|(u, &data)| Write {
            axis: TABLE_SLOT,
            addr: u as u32,
            data,
        }));
    }
    v
}

/// The maps a stream writes: each write's entry placed by its axis and address. Every entry
/// must be written exactly once, with an axis 0..=2 (and [`TABLE_SLOT`] with `comp_table =
/// ram`), an address and data that fit.
pub fn to_maps(cfg: &Config, writes: &[Write]) -> Result<Maps> {
    let n = cfg.map_entries();
    let ram = !cfg.comp_table.is_rom();
    let mut data: Vec<Option<u32>> = vec![None; 3 * n as usize];
    let mut table: Vec<Option<u32>> = vec![None; if ram { cfg.atan_entries() as usize } else { 0 }];
    for (k, w) in writes.iter().enumerate() {
        let slot = if w.axis == TABLE_SLOT && ram {
            (w.addr < cfg.atan_entries() && w.data <= cfg.pos_max())
                .then(|| &mut table[w.addr as usize])
        } else {
            (w.axis < 3 && w.addr < n && w.data <= cfg.map_max())
                .then(|| &mut data[(w.axis * n + w.addr) as usize])
        };
        let Some(slot) = slot else {
            bail!("write {k}: {w:?} does not fit the configuration");
        };
        if slot.replace(w.data).is_some() {
            bail!(
                "write {k}: axis {} address {} written twice",
                w.axis,
                w.addr
            );
        }
    }
    let data: Option<Vec<u32>> = data.into_iter().collect();
    let maps = Maps::from_data(cfg, data.context("the stream does not write every entry")?);
    if !ram {
        return Ok(maps);
    }
    let table: Option<Vec<u32>> = table.into_iter().collect();
    maps.with_table(
        cfg,
        table.context("the stream does not write every entry of the compensation table")?,
    )
}

/// The C array's name: `<top module>_map_writes`, the design's top ([`stages::top`]: with
/// the prefix, `rmap_lanes` with lanes, `rmap_axis` with AXI4-Stream ports).
pub fn c_array(cfg: &Config) -> String {
    format!("{}_map_writes", stages::top(cfg).module(cfg))
}

/// The C array's length macro: `<TOP MODULE>_MAP_WRITES_COUNT`.
pub fn c_count(cfg: &Config) -> String {
    format!("{}_COUNT", c_array(cfg).to_uppercase())
}

fn digits(bits: u32) -> usize {
    bits.div_ceil(4) as usize
}

/// The header's lines (without comment marks): what the stream holds and how to read it.
fn header(cfg: &Config, scene: &Scene, format: Format) -> Vec<String> {
    let scene_name = if scene.name.is_empty() {
        "(unnamed)"
    } else {
        &scene.name
    };
    let (a, m) = (cfg.map_addr_bits(), cfg.map_bits);
    let ram = !cfg.comp_table.is_rom();
    let n = write_count(cfg);
    let table = if ram {
        format!(
            ", then 3 (the compensation table), address u 0..={}",
            cfg.atan_entries() - 1
        )
    } else {
        String::new()
    };
    let mut v = vec![
        format!(
            "{MARK} scene {scene_name}, map_fit {}, {}",
            scene.map_fit.name(),
            cfg.summary()
        ),
        format!(
            "generated by rmapgen {}; {n} host writes in write order: axis 0 (x), 1 (y), 2 (z), \
             each address 0..={}{table}",
            env!("CARGO_PKG_VERSION"),
            cfg.map_entries() - 1
        ),
        format!(
            "fields: wr_axis_i (2 bits), wr_addr_i ({a} bits: {{s_max, s_u, i_u, s_v, i_v}}), \
             wr_data_i ({m} bits)"
        ),
    ];
    if format == Format::Hex {
        v.push(format!(
            "one write per line: axis address data, hex ({}, {} and {} digits)",
            1,
            digits(a),
            digits(m)
        ));
    }
    v
}

/// The stream of `maps` (the maps of `scene` for `cfg`) in `format`.
pub fn encode(cfg: &Config, scene: &Scene, maps: &Maps, format: Format) -> Vec<u8> {
    let ws = writes(cfg, maps);
    let (da, dm) = (digits(cfg.map_addr_bits()), digits(cfg.map_bits));
    match format {
        Format::Hex => {
            let mut s: String = header(cfg, scene, format)
                .iter()
                .map(|l| format!("//{}{l}\n", if l.starts_with(' ') { "" } else { " " }))
                .collect();
            for w in &ws {
                s += &format!("{:x} {:0da$x} {:0dm$x}\n", w.axis, w.addr, w.data);
            }
            s.into_bytes()
        }
        Format::Bin => ws
            .iter()
            .flat_map(|w| {
                [w.axis, w.addr, w.data]
                    .into_iter()
                    .flat_map(|x| (x as u16).to_le_bytes())
            })
            .collect(),
        Format::C => {
            let (name, count) = (c_array(cfg), c_count(cfg));
            let lines = header(cfg, scene, format);
            let mut s = format!("/*{}\n", lines[0]);
            for l in &lines[1..] {
                s += &format!(" * {l}\n");
            }
            s += " */\n#include <stdint.h>\n\n";
            s += &format!("#define {count} {}u\n\n", ws.len());
            s += &format!("static const uint16_t {name}[{count}][3] = {{\n");
            for w in &ws {
                s += &format!(
                    "    {{0x{:x}, 0x{:0da$x}, 0x{:0dm$x}}},\n",
                    w.axis, w.addr, w.data
                );
            }
            s += "};\n";
            s.into_bytes()
        }
    }
}

/// Reads a hex stream back (comments and blank lines skipped).
pub fn decode_hex(text: &str) -> Result<Vec<Write>> {
    let mut v = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let t = line.split("//").next().unwrap_or("").trim();
        if t.is_empty() {
            continue;
        }
        let f: Vec<u32> = t
            .split(' ')
            .map(|x| u32::from_str_radix(x, 16))
            .collect::<Result<_, _>>()
            .with_context(|| format!("line {}: not hex: {}", n + 1, quoted(t)))?;
        let [axis, addr, data] = f[..] else {
            bail!("line {}: {} fields, not 3", n + 1, f.len());
        };
        v.push(Write { axis, addr, data });
    }
    Ok(v)
}

/// Reads a binary stream back.
pub fn decode_bin(bytes: &[u8]) -> Result<Vec<Write>> {
    if !bytes.len().is_multiple_of(RECORD_BYTES) {
        bail!(
            "{} bytes is not a whole number of {RECORD_BYTES}-byte records",
            bytes.len()
        );
    }
    Ok(bytes
        .chunks(RECORD_BYTES)
        .map(|r| {
            let f = |i: usize| u16::from_le_bytes([r[2 * i], r[2 * i + 1]]) as u32;
            Write {
                axis: f(0),
                addr: f(1),
                data: f(2),
            }
        })
        .collect())
}

/// Reads a C stream back: the rows `{a, b, c}` of its array.
pub fn decode_c(text: &str) -> Result<Vec<Write>> {
    let body = text.split_once("] = {").context("no array initialiser")?.1;
    let mut v = Vec::new();
    for row in body.split('{').skip(1) {
        let row = row.split('}').next().unwrap_or("");
        let f: Vec<u32> = row
            .split(',')
            .map(|x| u32::from_str_radix(x.trim().trim_start_matches("0x"), 16))
            .collect::<Result<_, _>>()
            .with_context(|| format!("not a row of three hex numbers: {}", quoted(row)))?;
        let [axis, addr, data] = f[..] else {
            bail!("{}: {} fields, not 3", quoted(row), f.len());
        };
        v.push(Write { axis, addr, data });
    }
    Ok(v)
}

/// Reads a stream of `format` back.
pub fn decode(format: Format, bytes: &[u8]) -> Result<Vec<Write>> {
    match format {
        Format::Bin => decode_bin(bytes),
        Format::Hex | Format::C => {
            let text = std::str::from_utf8(bytes).context("not UTF-8 text")?;
            if format == Format::Hex {
                decode_hex(text)
            } else {
                decode_c(text)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn configs() -> Vec<Config> {
        let mut v: Vec<Config> = crate::grid::rows().into_iter().map(|r| r.config).collect();
        v.push(crate::grid::narrowest());
        v.push(Config {
            prefix: "a_".into(),
            ..Config::default()
        });
        v.push(Config {
            comp_table: crate::config::CompTable::Ram,
            ..Config::default()
        });
        v
    }

    /// With `comp_table = ram` the table is streamed after the maps in slot 3, and comes back
    /// from every format (the second buffer's, the linear index's positions, differs from the
    /// atan table out of reset); a table write that does not fit, or a table not written in
    /// full, is refused, and so is a table write to a design whose table is a ROM.
    #[test]
    fn the_table_streams_after_the_maps_and_comes_back() {
        let cfg = Config {
            comp_table: crate::config::CompTable::Ram,
            ..Config::default()
        };
        let set = crate::model::MapSet::standard(&cfg);
        assert_ne!(set.scene.table, set.second.table);
        let maps = set.second;
        let ws = writes(&cfg, &maps);
        let (n, t) = (3 * cfg.map_entries() as usize, cfg.atan_entries() as usize);
        assert_eq!(ws.len(), n + t);
        assert_eq!(ws.len(), write_count(&cfg) as usize);
        assert!(ws[n..]
            .iter()
            .enumerate()
            .all(|(u, w)| w.axis == TABLE_SLOT && w.addr == u as u32));
        for format in [Format::Hex, Format::Bin, Format::C] {
            let bytes = encode(&cfg, &Scene::alternate(), &maps, format);
            assert_eq!(
                to_maps(&cfg, &decode(format, &bytes).unwrap()).unwrap(),
                maps
            );
        }
        let mut bad = ws.clone();
        bad[n + 7].data = cfg.pos_max() + 1;
        assert!(to_maps(&cfg, &bad)
            .unwrap_err()
            .to_string()
            .contains("does not fit"));
        let e = to_maps(&cfg, &ws[..n + t - 1]).unwrap_err().to_string();
        assert!(e.contains("compensation table"), "{e}");
        let rom = Config::default();
        let e = to_maps(&rom, &ws).unwrap_err().to_string();
        assert!(e.contains("does not fit"), "{e}");
    }

    #[test]
    fn every_format_decodes_to_the_same_maps() {
        let scene = Scene::standard();
        for cfg in configs() {
            let maps = scene.maps(&cfg);
            for format in [Format::Hex, Format::Bin, Format::C] {
                let bytes = encode(&cfg, &scene, &maps, format);
                let ws = decode(format, &bytes).unwrap();
                assert_eq!(ws, writes(&cfg, &maps), "{format:?} {}", cfg.summary());
                assert_eq!(to_maps(&cfg, &ws).unwrap(), maps);
            }
        }
    }

    #[test]
    fn write_order_is_axis_then_address() {
        let cfg = Config::default();
        let ws = writes(&cfg, &Scene::standard().maps(&cfg));
        let n = cfg.map_entries();
        assert_eq!(ws.len(), 3 * n as usize);
        for (k, w) in ws.iter().enumerate() {
            assert_eq!((w.axis, w.addr), (k as u32 / n, k as u32 % n));
        }
    }

    #[test]
    fn fields_fit_the_binary_records() {
        // The widest address and entry of any configuration fit a 16-bit field.
        let (_, max_index) = crate::config::range_of("index_bits").unwrap();
        let (_, max_map) = crate::config::range_of("map_bits").unwrap();
        assert!(3 + 2 * max_index <= 16 && max_map <= 16);
        assert_eq!(RECORD_BYTES, 3 * 2);
    }

    #[test]
    fn hex_lines_and_c_rows_are_as_documented() {
        let cfg = Config::default(); // A = 9, M = 8
        let maps = Scene::standard().maps(&cfg);
        let scene = Scene::standard();
        let hex = String::from_utf8(encode(&cfg, &scene, &maps, Format::Hex)).unwrap();
        let first = hex.lines().find(|l| !l.starts_with("//")).unwrap();
        assert_eq!(first, format!("0 000 {:02x}", maps.get(0, 0)));
        let last = hex.lines().last().unwrap();
        assert_eq!(last, format!("2 1ff {:02x}", maps.get(2, 511)));
        let c = String::from_utf8(encode(&cfg, &scene, &maps, Format::C)).unwrap();
        assert!(c.contains("#define RMAP_TOP_MAP_WRITES_COUNT 1536u"), "{c}");
        assert!(c.contains(
            "static const uint16_t rmap_top_map_writes[RMAP_TOP_MAP_WRITES_COUNT][3] = {"
        ));
        // The array takes the name of the design's top module, whichever it is.
        for (flags, top) in [
            (
                Config {
                    prefix: "vr_".into(),
                    ..cfg.clone()
                },
                "vr_rmap_top",
            ),
            (
                Config {
                    lanes: 4,
                    ..cfg.clone()
                },
                "rmap_lanes",
            ),
            (
                Config {
                    handshake: true,
                    axis: true,
                    ..cfg.clone()
                },
                "rmap_axis",
            ),
        ] {
            let c = String::from_utf8(encode(&flags, &scene, &maps, Format::C)).unwrap();
            let upper = top.to_uppercase();
            assert!(
                c.contains(&format!(
                    "static const uint16_t {top}_map_writes[{upper}_MAP_WRITES_COUNT][3] = {{"
                )),
                "{top}: {c}"
            );
        }
        let bin = encode(&cfg, &scene, &maps, Format::Bin);
        assert_eq!(bin.len(), 1536 * RECORD_BYTES);
        assert_eq!(&bin[6..12], &[0, 0, 1, 0, maps.get(0, 1) as u8, 0]);
    }

    #[test]
    fn foreign_files_and_bad_streams_are_refused() {
        let cfg = Config::default();
        let maps = Scene::standard().maps(&cfg);
        let mut ws = writes(&cfg, &maps);
        ws[5].addr = 4; // entry 4 twice, entry 5 never
        assert!(to_maps(&cfg, &ws).is_err());
        ws.pop();
        assert!(to_maps(&cfg, &writes(&cfg, &maps)[1..]).is_err());
        assert!(decode_bin(&[0; 7]).is_err());
        // A bad line is named and quoted, at most 32 characters of it (a stream that is not
        // one may be a single line of megabytes).
        let msg = |r: Result<Vec<Write>>| format!("{:#}", r.unwrap_err());
        assert_eq!(
            msg(decode_hex("// writes\n0 000\n")),
            "line 2: 2 fields, not 3"
        );
        let long = "x".repeat(1 << 20);
        assert_eq!(
            msg(decode_hex(&format!("0 0 0\n{long}\n"))),
            format!(
                "line 2: not hex: \"{}\"... (1048576 bytes): invalid digit found in string",
                "x".repeat(32)
            )
        );
        assert_eq!(
            msg(decode_c(&format!("x[3] = {{{{0, 1, 2}}, {{{long}}}}};"))),
            format!(
                "not a row of three hex numbers: \"{}\"... (1048576 bytes): invalid digit found in string",
                "x".repeat(32)
            )
        );
        assert_eq!(
            msg(decode_c("x[3] = {{0, 1}};")),
            "\"0, 1\": 2 fields, not 3"
        );
    }
}
