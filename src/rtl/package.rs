//! The generated directory as a piece of IP: a FuseSoC core (`<prefix>rmap_top.core`, CAPI2,
//! file sets with the `.v` and `.hex` files, targets, the testbench's plusargs as parameters)
//! and a `README.md` with the port table and the timing notes (latency, flow control, reset,
//! buffer swap and write rules), both from the same tables as the Verilog.
//!
//! The core's name ([`vlnv`]) differs between configurations: it carries the top's module
//! name (with the prefix) and a hash of the configuration.

use super::{manifest, Dir, Width};
use crate::config::Config;
use crate::model::map_set::map_file;
use crate::stages::map_bank::MapBank;
use crate::stages::rmap_top::{latency_list, top_latency};
use crate::stages::testbench::TbFile;
use crate::stages::unit::{file_params, FileParam};
use crate::stages::{self, Unit, TOP};
use anyhow::{Context, Result};
use askama::Template;

pub const README_FILE: &str = "README.md";

/// The FuseSoC core file, `<top module>.core`.
pub fn core_file(cfg: &Config) -> String {
    format!("{}.core", TOP.module(cfg))
}

#[derive(Template)]
#[template(path = "pkg/rmap_top.core")]
struct Core {
    version: &'static str,
    summary: String,
    vlnv: String,
    core_file: String,
    top: String,
    tb_file: String,
    vector_file: String,
    latency: u32,
    rtl_files: Vec<String>,
    mem_files: Vec<String>,
    tb_files: Vec<String>,
    /// The top's init-file parameters; the testbench has the same ones and passes them down.
    file_params: Vec<FileParam>,
    /// The testbench's own file parameters (the second map).
    tb_params: Vec<TbFile>,
}

#[derive(Template)]
#[template(path = "pkg/README.md")]
struct Readme {
    version: &'static str,
    summary: String,
    prefix: String,
    top: String,
    core_file: String,
    vlnv: String,
    tb_file: String,
    map2: String,
    bank_glob: String,
    config_rows: Vec<(String, String)>,
    ports: Vec<(String, String, String, String)>,
    handshake: bool,
    latency: u32,
    depth: u32,
    latency_list: String,
    memories: Vec<(String, String, String, String)>,
    /// [`crate::config::Target::name`].
    target: &'static str,
}

/// The core's VLNV name, `rmapgen:ip:<top module>_<hash>:<version>`: the top's module name
/// (with the prefix) and [`config_hash`], so that two configurations never share a name,
/// with or without a prefix, and one configuration always has the same one.
pub fn vlnv(cfg: &Config) -> String {
    format!(
        "rmapgen:ip:{}_{}:{}",
        TOP.module(cfg),
        config_hash(cfg),
        env!("CARGO_PKG_VERSION")
    )
}

/// Eight hex digits naming a configuration: the low 32 bits of the 64-bit FNV-1a hash of
/// its TOML (what `tb/config.toml` holds, prefix included). Stable across runs, machines
/// and rmapgen versions as long as the configuration's fields are; the scene (the maps'
/// initial contents) is data, not configuration, and is not part of it.
pub fn config_hash(cfg: &Config) -> String {
    let text = toml::to_string(cfg).expect("a Config serialises");
    let h = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{:08x}", h as u32)
}

/// `<top module>.core` for `cfg`: the design's modules and the init files they read, and
/// the top's testbench with its vectors and the second map it loads.
pub fn core(cfg: &Config) -> Result<String> {
    let top = TOP.vectors().expect("the top has vectors");
    let file_params = file_params(&TOP.memories(cfg));
    let mem_files = file_params.iter().map(|p| p.default.clone()).collect();
    let (tb_files, _) = super::tb::testbench_files(cfg, &format!("{}_tb", TOP.module(cfg)))?;
    let tb_params: Vec<TbFile> = tb_files
        .into_iter()
        .filter(|f| !file_params.iter().any(|p| p.name == f.param))
        .collect();
    let text = Core {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        vlnv: vlnv(cfg),
        core_file: core_file(cfg),
        top: TOP.module(cfg),
        tb_file: top.testbench_file(cfg),
        vector_file: top.vector_file(cfg),
        latency: top_latency(cfg),
        rtl_files: stages::modules(cfg).iter().map(|m| m.file(cfg)).collect(),
        // Not the logical maps map_<axis>.hex: they are for people and tools.
        mem_files,
        tb_files: tb_params.iter().map(|f| f.default.clone()).collect(),
        file_params,
        tb_params,
    }
    .render()
    .context("cannot render templates/pkg/rmap_top.core")?;
    Ok(text + "\n")
}

/// `README.md` for `cfg`.
pub fn readme(cfg: &Config) -> Result<String> {
    let config_rows = toml::to_string(cfg)
        .context("cannot serialise the configuration")?
        .lines()
        .filter_map(|l| l.split_once(" = "))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let ports = TOP
        .ports(cfg)
        .into_iter()
        .map(|p| {
            (
                p.name.to_string(),
                match p.dir {
                    Dir::Input => "in".to_string(),
                    Dir::Output => "out".to_string(),
                },
                match p.width {
                    Width::Bits(b) => b.to_string(),
                    Width::Param(w) => w.to_string(),
                },
                describe(p.name, p.note),
            )
        })
        .collect();
    let latency_list = latency_list(cfg);
    let memories = manifest::memories(cfg)
        .into_iter()
        .map(|m| {
            (
                m.instance,
                format!("{} x {}", m.entries, m.width),
                m.param,
                m.init_file,
            )
        })
        .collect();
    let text = Readme {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        prefix: cfg.prefix.clone(),
        top: TOP.module(cfg),
        core_file: core_file(cfg),
        vlnv: vlnv(cfg),
        tb_file: TOP
            .vectors()
            .expect("the top has vectors")
            .testbench_file(cfg),
        map2: map_file(cfg, 1, "<axis>"),
        bank_glob: format!("{}*.hex", MapBank.module(cfg)),
        config_rows,
        ports,
        handshake: cfg.handshake,
        latency: top_latency(cfg),
        depth: cfg.pipeline_depth,
        latency_list,
        memories,
        target: cfg.target.name(),
    }
    .render()
    .context("cannot render templates/pkg/README.md")?;
    Ok(text + "\n")
}

/// A port's description for the table: its note, or what the name says.
fn describe(name: &str, note: &str) -> String {
    let base = match name {
        "clk_i" => "clock",
        "rst_ni" => "reset",
        "gx_i" => "gradient x component",
        "gy_i" => "gradient y component, G-bit two's complement",
        "gz_i" => "gradient z component, G-bit two's complement",
        "r_i" | "g_i" | "b_i" => "sample colour channel",
        "wr_axis_i" => "host write: axis map (0 x, 1 y, 2 z)",
        "wr_data_i" => "host write: entry",
        "wr_addr_i" => "host write: logical map address",
        "r_o" | "g_o" | "b_o" => "colour channel times the intensity",
        _ => "",
    };
    match (base.is_empty(), note.is_empty()) {
        (true, _) => note.to_string(),
        (false, true) => base.to_string(),
        (false, false) => format!("{base}: {note}"),
    }
}
