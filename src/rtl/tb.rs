//! Self-checking Verilog testbenches, one per stage module present in a configuration and one
//! for `rmap_top`, rendered from `templates/tb/<module>_tb.v` (which extend
//! `templates/tb/base_tb.v`) into `<out>/tb/<module>_tb.v`.
//!
//! Everything a testbench knows comes from one place: the vector fields from
//! [`Stage::fields`], the ports from [`rtl::ports::ports`], the latency from
//! [`rtl::latency`], the ROM and map files from [`rtl::manifest::memories`]. A field whose port
//! is missing or has another width is an error here, not a silent mismatch in simulation.
//!
//! Beside the testbenches this writes `tb/config.toml` (the configuration, for
//! `rmapgen vectors --config`) and `tb/rmap_top_config.h` (the widths the Verilator C++
//! harness `tb/top_stream.cpp` of the repository needs).

use crate::config::Config;
use crate::output::StagedDir;
use crate::rtl::{self, manifest, Module, Width};
use crate::vectors::{self, Dir, Stage};
use anyhow::{bail, Context, Result};
use askama::Template;

/// A signal of the testbench: a design port.
pub struct Sig {
    pub name: &'static str,
    /// `[n-1:0]`, or empty for one bit.
    /// `[n-1:0]`, or blanks for one bit, padded so the names line up.
    pub range: String,
    pub init: String,
    /// The instance connection, `.name (name)`, names padded.
    pub pin: String,
}

/// A vector field as the testbench stores and drives or checks it.
pub struct FieldView {
    pub name: &'static str,
    pub bits: u32,
    /// Always a range, `[0:0]` for one bit, so every ring is declared alike.
    pub range: String,
    /// The design port the field drives or is compared with; empty for `map` of the top,
    /// which steers the testbench itself.
    pub port: String,
}

/// Everything the testbench templates read.
pub struct TbData {
    pub header: String,
    pub module: &'static str,
    pub summary: String,
    pub vector_file: String,
    pub field_list: String,
    pub latency: u32,
    pub depth: u32,
    pub depth_bits: u32,
    pub full_speed: u32,
    pub reset_at: u32,
    pub timeout: u32,
    pub seed: u32,
    pub has_en: bool,
    /// The top with valid/ready flow control: ready_i random, acceptance by ready_o.
    pub handshake: bool,
    /// `{zero_o, i_o, ...}`: every checked output, and its width (the hold check).
    pub outs_concat: String,
    pub outs_bits: u32,
    pub inputs: Vec<Sig>,
    pub outputs: Vec<Sig>,
    pub ports: Vec<Sig>,
    pub fields: Vec<FieldView>,
    /// Input fields with a port.
    pub in_fields: Vec<FieldView>,
    pub out_fields: Vec<FieldView>,
    pub scan_format: String,
    pub scan_args: String,
    pub in_format: String,
    pub in_args: String,
    pub out_format: String,
    pub exp_args: String,
    pub got_args: String,
    /// Files the design reads with `$readmemh` (and the testbench itself, for `map2_*`).
    pub hex_files: Vec<String>,
    /// The second map, loaded through the host port (map_lookup and the top).
    pub map2_files: Vec<String>,
    pub map_entries: u32,
    pub map_addr_bits: u32,
    pub map_bits: u32,
    pub nwrites: u32,
}

macro_rules! tb_template {
    ($name:ident, $path:literal) => {
        #[derive(Template)]
        #[template(path = $path, syntax = "verilog")]
        struct $name<'a> {
            t: &'a TbData,
        }
    };
}

tb_template!(ZeroDetectTb, "tb/zero_detect_tb.v");
tb_template!(SortShiftTb, "tb/sort_shift_tb.v");
tb_template!(NormaliseTb, "tb/normalise_tb.v");
tb_template!(AtanRomTb, "tb/atan_rom_tb.v");
tb_template!(LinearIndexTb, "tb/linear_index_tb.v");
tb_template!(MapLookupTb, "tb/map_lookup_tb.v");
tb_template!(InterpolateTb, "tb/interpolate_tb.v");
tb_template!(ColorMulTb, "tb/color_mul_tb.v");
tb_template!(RmapTopTb, "tb/rmap_top_tb.v");

/// Accepted vectors before the first bubble or stall: the pipeline runs full first.
const FULL_SPEED: u32 = 64;
/// Accepted vectors before the mid-stream reset (at most half the top's map-0 corners).
const RESET_AT: u32 = 37;

fn range(bits: u32) -> String {
    if bits == 1 {
        String::new()
    } else {
        format!("[{}:0]", bits - 1)
    }
}

/// The design port a vector field drives or is checked against.
fn port_name(stage: Stage, name: &str, dir: Dir) -> Option<String> {
    match (stage, name) {
        (Stage::Top, "map") => None,
        (Stage::MapLookup, "buf") => Some("rd_buf_i".into()),
        (_, n) if n.ends_with("_o") => Some(n.into()),
        (_, n) => Some(format!("{n}{}", if dir == Dir::In { "_i" } else { "_o" })),
    }
}

/// The `$readmemh` files the design under `m` reads, from the manifest's memory list (the
/// instances below `rmap_top` are named `u_<module>`).
fn memory_files(cfg: &Config, m: Module) -> Vec<String> {
    let prefix = format!("u_{}.", m.name());
    let mut v: Vec<String> = manifest::memories(cfg)
        .into_iter()
        .filter(|mem| m == Module::RmapTop || mem.instance.starts_with(&prefix))
        .map(|mem| mem.init_file)
        .collect();
    v.dedup();
    v
}

/// The testbench data of one stage.
pub fn data(cfg: &Config, stage: Stage) -> Result<TbData> {
    let module = Module::from_name(stage.name())
        .with_context(|| format!("no RTL module named {}", stage.name()))?;
    let latency = rtl::latency(cfg, module)
        .with_context(|| format!("{} has no fixed latency", stage.name()))?;
    let ports = rtl::ports::ports(cfg, module);
    let bits_of = |p: &rtl::Port| match p.width {
        Width::Bits(b) => Ok(b),
        Width::Param(w) => bail!(
            "port {} of {} has a parameter width {w}",
            p.name,
            stage.name()
        ),
    };
    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    let mut sigs = Vec::new();
    let mut rw = 0;
    for p in &ports {
        rw = rw.max(range(bits_of(p)?).len());
    }
    let nw = ports.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in &ports {
        let b = bits_of(p)?;
        let s = || Sig {
            name: p.name,
            range: format!("{:rw$}", range(b)),
            init: format!("{b}'d0"),
            pin: format!(".{:nw$} ({})", p.name, p.name),
        };
        match p.dir {
            rtl::Dir::Input => inputs.push(s()),
            rtl::Dir::Output => outputs.push(s()),
        }
        sigs.push(s());
    }
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

    let mut fields = Vec::new();
    for f in stage.fields(cfg) {
        let port = match port_name(stage, f.name, f.dir) {
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
                    rtl::Dir::Input
                } else {
                    rtl::Dir::Output
                };
                if p.dir != want || bits_of(p)? != f.bits {
                    bail!(
                        "port {pn} of {} is {:?} {:?}; vector field {} needs {:?} of {} bits",
                        stage.name(),
                        p.dir,
                        p.width,
                        f.name,
                        want,
                        f.bits
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

    let map2 = matches!(stage, Stage::MapLookup | Stage::Top);
    let map2_files: Vec<String> = if map2 {
        ["x", "y", "z"]
            .iter()
            .map(|a| format!("map2_{a}.hex"))
            .collect()
    } else {
        Vec::new()
    };
    let mut hex_files = memory_files(cfg, module);
    hex_files.extend(map2_files.iter().cloned());

    // The ring must hold every sample in flight plus the one being read.
    let depth = (latency + 4).next_power_of_two().max(16);
    let reset_at = if stage == Stage::Top {
        RESET_AT.min(vectors::inputs::top_corners(cfg, 0).len() as u32 / 2)
    } else {
        RESET_AT
    };
    Ok(TbData {
        header: format!(
            "// {}_tb.v: generated by rmapgen {}. Do not edit; regenerate with `rmapgen generate`.\n// Configuration: {}",
            stage.name(),
            env!("CARGO_PKG_VERSION"),
            cfg.summary()
        ),
        module: stage.name(),
        summary: cfg.summary(),
        vector_file: stage.vector_file(),
        field_list: join(fields.iter().map(|f| f.name.to_string()).collect(), " "),
        latency,
        depth,
        depth_bits: depth.trailing_zeros(),
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
        outs_bits: out_fields.iter().map(|f| f.bits).sum(),
        scan_format: join(fields.iter().map(|_| "%h".to_string()).collect(), " "),
        scan_args: join(fields.iter().map(|f| format!("s_{}", f.name)).collect(), ", "),
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
        hex_files,
        map2_files,
        map_entries: cfg.map_entries(),
        map_addr_bits: cfg.map_addr_bits(),
        map_bits: cfg.map_bits,
        nwrites: 3 * cfg.map_entries(),
    })
}

/// The Verilog text of one stage's testbench.
pub fn render(cfg: &Config, stage: Stage) -> Result<String> {
    let t = &data(cfg, stage)?;
    let text = match stage {
        Stage::ZeroDetect => ZeroDetectTb { t }.render(),
        Stage::SortShift => SortShiftTb { t }.render(),
        Stage::Normalise => NormaliseTb { t }.render(),
        Stage::AtanRom => AtanRomTb { t }.render(),
        Stage::LinearIndex => LinearIndexTb { t }.render(),
        Stage::MapLookup => MapLookupTb { t }.render(),
        Stage::Interpolate => InterpolateTb { t }.render(),
        Stage::ColorMul => ColorMulTb { t }.render(),
        Stage::Top => RmapTopTb { t }.render(),
    };
    text.with_context(|| format!("cannot render templates/tb/{}_tb.v", stage.name()))
}

/// `tb/rmap_top_config.h`: the widths and flags the Verilator C++ harness compiles against.
pub fn harness_header(cfg: &Config) -> String {
    let fields = Stage::Top.fields(cfg);
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
        rtl::top_latency(cfg),
        fields.len(),
        cfg.handshake as u32,
    )
}

/// Writes `tb/<module>_tb.v` for every stage present in `cfg` and the top, plus
/// `tb/config.toml` and `tb/rmap_top_config.h`.
pub fn write_all(cfg: &Config, out: &StagedDir) -> Result<()> {
    cfg.validate()?;
    for stage in vectors::stages(cfg) {
        out.write_text(&format!("tb/{}_tb.v", stage.name()), &render(cfg, stage)?)?;
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
            for stage in vectors::stages(&cfg) {
                let d = data(&cfg, stage).unwrap_or_else(|e| panic!("{}: {e:#}", stage.name()));
                assert!(!d.out_fields.is_empty());
                assert!(d.depth > d.latency + 2);
            }
        }
    }

    #[test]
    fn files_the_design_reads_are_checked() {
        let cfg = Config::default();
        let top = data(&cfg, Stage::Top).unwrap();
        for f in [
            "recip_rom.hex",
            "atan_rom.hex",
            "map_bank_00.hex",
            "map_bank_11.hex",
            "map2_z.hex",
        ] {
            assert!(
                top.hex_files.iter().any(|h| h == f),
                "{f} in {:?}",
                top.hex_files
            );
        }
        assert_eq!(
            data(&cfg, Stage::Normalise).unwrap().hex_files,
            vec!["recip_rom.hex"]
        );
        assert!(data(&cfg, Stage::SortShift).unwrap().hex_files.is_empty());
    }
}
