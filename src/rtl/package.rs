//! The generated directory as a piece of IP: a FuseSoC core (`rmap_top.core`, CAPI2, file
//! sets with the `.v` and `.hex` files, targets, the testbench's plusargs as parameters) and
//! a `README.md` with the port table and the timing notes (latency, flow control, reset,
//! buffer swap and write rules), both from the same tables as the Verilog.

use super::{manifest, Dir, Width};
use crate::config::Config;
use crate::stages::rmap_top::{latency_list, top_latency};
use crate::stages::{self, TOP};
use anyhow::{Context, Result};
use askama::Template;

pub const CORE_FILE: &str = "rmap_top.core";
pub const README_FILE: &str = "README.md";

#[derive(Template)]
#[template(path = "pkg/rmap_top.core")]
struct Core {
    version: &'static str,
    summary: String,
    vlnv: String,
    latency: u32,
    rtl_files: Vec<String>,
    mem_files: Vec<String>,
    tb_files: Vec<String>,
}

#[derive(Template)]
#[template(path = "pkg/README.md")]
struct Readme {
    version: &'static str,
    summary: String,
    config_rows: Vec<(String, String)>,
    ports: Vec<(String, String, String, String)>,
    handshake: bool,
    latency: u32,
    depth: u32,
    latency_list: String,
    memories: Vec<(String, String, String)>,
}

/// The core's VLNV name: rmapgen:ip:rmap_top:<version>.
pub fn vlnv() -> String {
    format!("rmapgen:ip:rmap_top:{}", env!("CARGO_PKG_VERSION"))
}

/// `rmap_top.core` for `cfg`; `hex` are the `$readmemh` and map2 files of the directory.
pub fn core(cfg: &Config, hex: &[String]) -> Result<String> {
    let (tb, mem): (Vec<String>, Vec<String>) =
        hex.iter().cloned().partition(|f| f.starts_with("map2_"));
    let text = Core {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        vlnv: vlnv(),
        latency: top_latency(cfg),
        rtl_files: stages::modules(cfg).iter().map(|m| m.file()).collect(),
        // The logical maps map_<axis>.hex are for people and tools, not the design.
        mem_files: mem
            .into_iter()
            .filter(|f| !["map_x.hex", "map_y.hex", "map_z.hex"].contains(&f.as_str()))
            .collect(),
        tb_files: tb,
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
                m.init_file,
            )
        })
        .collect();
    let text = Readme {
        version: env!("CARGO_PKG_VERSION"),
        summary: cfg.summary(),
        config_rows,
        ports,
        handshake: cfg.handshake,
        latency: top_latency(cfg),
        depth: cfg.pipeline_depth,
        latency_list,
        memories,
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
