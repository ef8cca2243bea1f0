//! Self-checking Verilog testbenches, one per stage module present in a configuration and one
//! for `rmap_top`, rendered from each stage's `src/stages/<module>/<module>_tb.v` (which
//! extend `templates/tb/base_tb.v`) into `<out>/tb/<module>_tb.v`.
//!
//! Everything a testbench knows comes from its stage's unit: the vector fields
//! ([`Vectors::fields`]) and the ports they drive ([`Vectors::port`]), the ports
//! ([`Unit::ports`]), the latency ([`Unit::latency`]), the ROM and map files
//! ([`Unit::memories`]). A field whose port is missing or has another width is an error here,
//! not a silent mismatch in simulation.
//!
//! Beside the testbenches this writes `tb/config.toml` (the configuration, for
//! `rmapgen vectors --config`) and `tb/rmap_top_config.h` (the widths the Verilator C++
//! harness `tb/top_stream.cpp` of the repository needs).

use crate::config::Config;
use crate::design::Design;
use crate::hdl::ports::{self, Width};
use crate::model::map_set::{buffer_names, map_file, TABLE};
use crate::output::StagedDir;
use crate::stages::recip_rom::{self, RecipRom};
use crate::stages::rmap_top::top_latency;
use crate::stages::testbench::{FieldView, Map2File, Sig, TbData, TbFile};
use crate::stages::unit::{file_param, file_params, param_overrides, Unit};
use crate::stages::{self, Vectors, TOP};
use crate::vectors::Dir;
use anyhow::{bail, Context, Result};

/// Accepted vectors before the first bubble or stall: the pipeline runs full first.
const FULL_SPEED: u32 = 64;

fn range(bits: u32) -> String {
    if bits == 1 {
        String::new()
    } else {
        format!("[{}:0]", bits - 1)
    }
}

/// The parameter naming the second map's file of `axis` in a testbench: `MAP2_X_FILE`.
fn map2_param(axis: &str) -> String {
    file_param(&format!("map2_{axis}"))
}

/// The reciprocal ROM of a testbench whose module reads a shared one through
/// [`recip_rom::READER`]: the wires, and the ROM with the module on its port a (port b idle),
/// as rmap_lanes wires a lane.
fn tb_rom(cfg: &Config) -> String {
    let (en, addr, data) = recip_rom::READER;
    let [(en_a, addr_a, data_a), (en_b, addr_b, data_b)] = recip_rom::PORTS;
    let (ra, w) = (cfg.recip_addr_bits(), cfg.recip_bits);
    let rw = format!("[{}:0]", ra - 1)
        .len()
        .max(format!("[{}:0]", w - 1).len());
    let r = |b: u32| format!("{:rw$}", range(b));
    let pins = [
        ("clk_i", "clk_i".to_string()),
        (en_a, en.to_string()),
        (addr_a, addr.to_string()),
        (data_a, data.to_string()),
        (en_b, "1'b0".to_string()),
        (addr_b, format!("{ra}'d0")),
        (data_b, "unused_recip_data".to_string()),
    ];
    let pw = pins.iter().map(|(p, _)| p.len()).max().unwrap_or(0);
    let pins: Vec<String> = pins
        .iter()
        .map(|(p, e)| format!("    .{p:pw$} ({e})"))
        .collect();
    format!(
        "\n  // The reciprocal ROM the design reads through its recip_* ports (shared by two lanes in\n  // rmap_lanes): here on its port a alone.\n  wire {} {en};\n  wire {} {addr};\n  wire {} {data};\n  wire {} unused_recip_data;\n\n  {}{} u_recip_rom (\n{}\n  );",
        r(1),
        r(ra),
        r(w),
        r(w),
        RecipRom.module(cfg),
        param_overrides(cfg, &RecipRom),
        pins.join(",\n")
    )
}

/// The width of port `p` of `stage`, which must be fixed.
fn bits_of(stage: &dyn Vectors, p: &ports::Port) -> Result<u32> {
    match p.width {
        Width::Bits(b) => Ok(b),
        Width::Param(w) => bail!(
            "port {} of {} has a parameter width {w}",
            p.name,
            stage.name()
        ),
    }
}

/// The testbench's signals for the ports of `stage`: its inputs (registers), its outputs
/// (wires), and every port's connection to the instance, names and ranges aligned.
fn signals(cfg: &Config, stage: &dyn Vectors) -> Result<(Vec<Sig>, Vec<Sig>, Vec<Sig>)> {
    let ports = stage.ports(cfg);
    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    let mut sigs = Vec::new();
    let mut rw = 0;
    for p in &ports {
        rw = rw.max(range(bits_of(stage, p)?).len());
    }
    let nw = ports.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in &ports {
        let b = bits_of(stage, p)?;
        let s = || Sig {
            name: p.name,
            range: format!("{:rw$}", range(b)),
            init: format!("{b}'d0"),
            pin: format!(".{:nw$} ({})", p.name, p.name),
        };
        // The reader ports of a shared reciprocal ROM go to the testbench's own ROM.
        let reader = [
            recip_rom::READER.0,
            recip_rom::READER.1,
            recip_rom::READER.2,
        ];
        match p.dir {
            _ if reader.contains(&p.name) => {}
            ports::Dir::Input => inputs.push(s()),
            ports::Dir::Output => outputs.push(s()),
        }
        sigs.push(s());
    }
    Ok((inputs, outputs, sigs))
}

/// The first line of a testbench file: its name, the generator, the configuration.
fn tb_header(cfg: &Config, tb_file: &str) -> String {
    format!(
        "// {}: generated by rmapgen {}. Do not edit; regenerate with `rmapgen generate`.\n// Configuration: {}",
        tb_file.trim_start_matches("tb/"),
        env!("CARGO_PKG_VERSION"),
        cfg.summary()
    )
}

/// The testbench data of one stage.
pub fn data(cfg: &Config, stage: &dyn Vectors) -> Result<TbData> {
    if let Some(inner) = stage.inner() {
        return wrapped(cfg, stage, inner);
    }
    let latency = stage
        .latency(cfg)
        .with_context(|| format!("{} has no fixed latency", stage.name()))?;
    let ports = stage.ports(cfg);
    let bits_of = |p: &ports::Port| bits_of(stage, p);
    let (inputs, outputs, sigs) = signals(cfg, stage)?;
    for needed in ["clk_i", "rst_ni", "valid_i"] {
        if !inputs.iter().any(|s| s.name == needed) {
            bail!("{} has no {needed} port", stage.name());
        }
    }
    if !outputs.iter().any(|s| s.name == "valid_o") {
        bail!("{} has no valid_o port", stage.name());
    }
    let has_en = inputs.iter().any(|s| s.name == "en_i");
    let handshake = inputs.iter().any(|s| s.name == "ready_i");
    if handshake && !outputs.iter().any(|s| s.name == "ready_o") {
        bail!("{} has ready_i but no ready_o", stage.name());
    }

    // A lanes module's per-sample ports carry every lane: `lanes` times the field's width.
    let lanes = stage.lanes(cfg);
    let mut fields = Vec::new();
    for f in stage.fields(cfg) {
        let port = match stage.port(&f) {
            None => String::new(),
            Some(pn) => {
                let p = ports.iter().find(|p| p.name == pn).with_context(|| {
                    format!(
                        "vector field {} of {} has no port {pn}",
                        f.name,
                        stage.name()
                    )
                })?;
                let want = if f.dir == Dir::In {
                    ports::Dir::Input
                } else {
                    ports::Dir::Output
                };
                if p.dir != want || bits_of(p)? != f.bits * lanes {
                    bail!(
                        "port {pn} of {} is {:?} {:?}; vector field {} needs {:?} of {} bits",
                        stage.name(),
                        p.dir,
                        p.width,
                        f.name,
                        want,
                        f.bits * lanes
                    );
                }
                pn
            }
        };
        fields.push(FieldView {
            name: f.name,
            bits: f.bits,
            range: format!("[{}:0]", f.bits - 1),
            port,
        });
    }
    let is_in = |f: &&FieldView| {
        stage
            .fields(cfg)
            .iter()
            .any(|g| g.name == f.name && g.dir == Dir::In)
    };
    let clone = |f: &FieldView| FieldView {
        name: f.name,
        bits: f.bits,
        range: f.range.clone(),
        port: f.port.clone(),
    };
    let in_all: Vec<&FieldView> = fields.iter().filter(is_in).collect();
    let out_fields: Vec<FieldView> = fields.iter().filter(|f| !is_in(f)).map(clone).collect();
    let in_fields: Vec<FieldView> = in_all
        .iter()
        .filter(|f| !f.port.is_empty())
        .map(|f| clone(f))
        .collect();

    let join = |it: Vec<String>, sep: &str| it.join(sep);
    let fmt_of =
        |fs: &[&FieldView]| join(fs.iter().map(|f| format!("{}=%h", f.name)).collect(), " ");
    let out_refs: Vec<&FieldView> = out_fields.iter().collect();
    let ring = |fs: &[&FieldView]| {
        join(
            fs.iter().map(|f| format!("v_{}[so]", f.name)).collect(),
            ", ",
        )
    };

    // A design with writable memories (the map banks) gets the second map through its host
    // port.
    let memories = stage.memories(cfg);
    let map2 = memories.iter().any(|m| m.writable);
    // A module that reads a reciprocal ROM shared in rmap_lanes: the testbench holds the ROM
    // and passes it the file.
    let reads_rom = ports.iter().any(|p| p.name == recip_rom::READER.0);
    let memories = if reads_rom {
        let mut m = memories;
        m.extend(RecipRom.memories(cfg));
        m
    } else {
        memories
    };
    let map2_axes: Vec<&str> = if map2 { buffer_names(cfg) } else { Vec::new() };
    let table_entries = if map2_axes.contains(&TABLE) {
        cfg.atan_entries()
    } else {
        0
    };
    // Axis k's map fills writes [k 2^A, (k + 1) 2^A), the table the 2^F after the maps.
    let span = |k: usize| match k {
        1 => "MAP_ENTRIES".to_string(),
        _ => format!("{k} * MAP_ENTRIES"),
    };
    let map2_params: Vec<Map2File> = map2_axes
        .iter()
        .enumerate()
        .map(|(k, a)| Map2File {
            param: map2_param(a),
            first: if k == 0 { "0".into() } else { span(k) },
            last: if *a == TABLE {
                format!("{} + TABLE_ENTRIES - 1", span(k))
            } else {
                format!("{} - 1", span(k + 1))
            },
        })
        .collect();
    let mut files: Vec<TbFile> = file_params(&memories)
        .into_iter()
        .map(|p| TbFile {
            param: p.name,
            default: p.default,
        })
        .collect();
    files.extend(map2_axes.iter().map(|a| TbFile {
        param: map2_param(a),
        default: map_file(cfg, 1, a),
    }));

    // The ring must hold every sample in flight plus the one being read.
    let depth = (latency + 4).next_power_of_two().max(16);
    let vdepth = (depth * lanes).next_power_of_two();
    let reset_at = stage.reset_at(cfg);
    let tb_file = stage.testbench_file(cfg);
    Ok(TbData {
        cfg: cfg.clone(),
        header: tb_header(cfg, &tb_file),
        module: stage.module(cfg),
        tb_file,
        summary: cfg.summary(),
        vector_file: stage.vector_file(cfg),
        field_list: join(fields.iter().map(|f| f.name.to_string()).collect(), " "),
        latency,
        depth,
        depth_bits: depth.trailing_zeros(),
        lanes,
        vdepth,
        vdepth_bits: vdepth.trailing_zeros(),
        full_speed: FULL_SPEED,
        reset_at,
        timeout: 1000 + 8 * latency,
        seed: 1,
        has_en,
        handshake,
        outs_concat: format!(
            "{{{}}}",
            out_fields
                .iter()
                .map(|f| f.port.clone())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        outs_bits: out_fields.iter().map(|f| f.bits * lanes).sum(),
        scan_format: join(fields.iter().map(|_| "%h".to_string()).collect(), " "),
        scan_args: join(
            fields.iter().map(|f| format!("s_{}", f.name)).collect(),
            ", ",
        ),
        in_format: fmt_of(&in_all),
        in_args: ring(&in_all),
        out_format: fmt_of(&out_refs),
        exp_args: ring(&out_refs),
        got_args: join(out_fields.iter().map(|f| f.port.clone()).collect(), ", "),
        inputs,
        outputs,
        ports: sigs,
        fields,
        in_fields,
        out_fields,
        files,
        dut_params: param_overrides(cfg, stage),
        rom: if reads_rom {
            tb_rom(cfg)
        } else {
            String::new()
        },
        map2_params,
        map2_pattern: map_file(cfg, 1, "*"),
        map_entries: cfg.map_entries(),
        map_addr_bits: cfg.map_addr_bits(),
        map_bits: cfg.map_bits,
        nwrites: crate::map_stream::write_count(cfg),
        table_entries,
    })
}

/// The testbench data of `stage`, which carries the vector fields of `inner` in ports of its
/// own ([`Vectors::inner`]): `inner`'s (fields, files, latency, flow control), with
/// `stage`'s module, ports and parameters; the stage's testbench maps the fields itself.
fn wrapped(cfg: &Config, stage: &dyn Vectors, inner: &dyn Vectors) -> Result<TbData> {
    let t = data(cfg, inner)?;
    let params = |u: &dyn Vectors| -> Vec<(String, String)> {
        file_params(&u.memories(cfg))
            .into_iter()
            .map(|p| (p.name, p.default))
            .collect()
    };
    if stage.latency(cfg) != Some(t.latency)
        || stage.vector_file(cfg) != t.vector_file
        || params(stage) != params(inner)
    {
        bail!(
            "{} carries {}'s vectors but not its latency, vector file and file parameters",
            stage.name(),
            inner.name()
        );
    }
    let (inputs, outputs, ports) = signals(cfg, stage)?;
    let tb_file = stage.testbench_file(cfg);
    Ok(TbData {
        header: tb_header(cfg, &tb_file),
        module: stage.module(cfg),
        tb_file,
        inputs,
        outputs,
        ports,
        dut_params: param_overrides(cfg, stage),
        ..t
    })
}

/// The files testbench `<module>_tb` of a design reads: its file parameters (defaults relative
/// to the design directory) and its vector file (`+vectors=`), so that a simulator can run it
/// from anywhere.
pub fn testbench_files(cfg: &Config, tb_module: &str) -> Result<(Vec<TbFile>, String)> {
    let stage = stages::checked(cfg)
        .into_iter()
        .find(|s| format!("{}_tb", s.module(cfg)) == tb_module)
        .with_context(|| format!("{tb_module} is not a testbench of this configuration"))?;
    let t = data(cfg, stage)?;
    Ok((t.files, t.vector_file))
}

/// The top's init-file parameters (defaults relative to the design directory), which a
/// simulation of the top without its testbench (the C++ harness) sets.
pub fn top_files(cfg: &Config) -> Vec<TbFile> {
    file_params(&TOP.memories(cfg))
        .into_iter()
        .map(|p| TbFile {
            param: p.name,
            default: p.default,
        })
        .collect()
}

/// The Verilog text of one stage's testbench.
pub fn render(cfg: &Config, stage: &dyn Vectors) -> Result<String> {
    let t = &data(cfg, stage)?;
    stage
        .testbench(t)
        .with_context(|| format!("cannot render src/stages/{0}/{0}_tb.v", stage.name()))
}

/// `tb/rmap_top_config.h`: the widths and flags the Verilator C++ harness compiles against.
pub fn harness_header(cfg: &Config) -> String {
    let fields = TOP.vectors().expect("the top has vectors").fields(cfg);
    format!(
        "// rmap_top_config.h: generated by rmapgen {}. Do not edit.\n\
         // Configuration: {}\n\
         // For tb/top_stream.cpp: vectors/rmap_top.hex fields are {}.\n\
         #pragma once\n\
         #define RMAP_GRAD_BITS {}\n\
         #define RMAP_MAP_BITS {}\n\
         #define RMAP_MAP_ADDR_BITS {}\n\
         #define RMAP_COLOR {}\n\
         #define RMAP_LATENCY {}\n\
         #define RMAP_NFIELDS {}\n\
         #define RMAP_HANDSHAKE {}\n",
        env!("CARGO_PKG_VERSION"),
        cfg.summary(),
        fields.iter().map(|f| f.name).collect::<Vec<_>>().join(" "),
        cfg.grad_bits,
        cfg.map_bits,
        cfg.map_addr_bits(),
        cfg.color as u32,
        top_latency(cfg),
        fields.len(),
        cfg.handshake as u32,
    ) + &if cfg.comp_table.is_rom() {
        String::new()
    } else {
        // The second buffer's compensation table, written after the maps (axis slot 3).
        format!("#define RMAP_TABLE_ENTRIES {}\n", cfg.atan_entries())
    }
}

/// Writes `tb/<module>_tb.v` for every stage present in `cfg` and the top, plus
/// `tb/config.toml` and `tb/rmap_top_config.h` (which keep their names with a prefix: they
/// describe the directory, for `rmapgen vectors` and the repository's C++ harnesses).
pub fn write_all(design: &Design, out: &StagedDir) -> Result<()> {
    let cfg = design.cfg();
    for stage in stages::checked(cfg) {
        out.write_text(&stage.testbench_file(cfg), &render(cfg, stage)?)?;
    }
    let toml = toml::to_string(cfg).context("cannot serialise the configuration")?;
    out.write_text(
        "tb/config.toml",
        &format!("# The configuration of this directory, for `rmapgen vectors --config tb/config.toml`.\n{toml}"),
    )?;
    out.write_text("tb/rmap_top_config.h", &harness_header(cfg))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_has_its_port() {
        for cfg in [
            Config::default(),
            Config {
                compensation: false,
                interpolation: false,
                interp_bits: 0,
                color: true,
                ..Config::default()
            },
        ] {
            for stage in stages::checked(&cfg) {
                let d = data(&cfg, stage).unwrap_or_else(|e| panic!("{}: {e:#}", stage.name()));
                assert!(!d.out_fields.is_empty());
                assert!(d.depth > d.latency + 2);
            }
        }
    }

    #[test]
    fn files_the_design_reads_are_checked() {
        let cfg = Config::default();
        let of = |name: &str| {
            let stage = stages::checked(&cfg)
                .into_iter()
                .find(|s| s.name() == name)
                .unwrap();
            data(&cfg, stage).unwrap()
        };
        let top = of("rmap_top");
        let files = |t: &TbData| -> Vec<(String, String)> {
            t.files
                .iter()
                .map(|f| (f.param.clone(), f.default.clone()))
                .collect()
        };
        for (p, f) in [
            ("RECIP_ROM_FILE", "recip_rom.hex"),
            ("ATAN_ROM_FILE", "atan_rom.hex"),
            ("MAP_BANK_00_FILE", "map_bank_00.hex"),
            ("MAP_BANK_11_FILE", "map_bank_11.hex"),
            ("MAP2_Z_FILE", "map2_z.hex"),
        ] {
            let want = (p.to_string(), f.to_string());
            assert!(files(&top).contains(&want), "{want:?} in {:?}", files(&top));
        }
        // The ROM is read twice but named once.
        assert_eq!(
            files(&of("normalise")),
            vec![("RECIP_ROM_FILE".to_string(), "recip_rom.hex".to_string())]
        );
        assert_eq!(files(&of("atan_rom")).len(), 1);
        assert!(of("sort_shift").files.is_empty());
        assert!(of("sort_shift").dut_params.is_empty());
    }
}
