//! Ports as data: each stage's unit lists its own (`Unit::ports`), its template prints them
//! with [`render`] (so the Verilog cannot disagree with the list) and the manifest, the README
//! and the testbenches read the same list.

use crate::config::Config;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Dir {
    Input,
    Output,
}

/// A port's width: fixed by the configuration, or a parameter of a generic module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum Width {
    Bits(u32),
    Param(&'static str),
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Port {
    pub name: &'static str,
    pub dir: Dir,
    pub width: Width,
    /// What the port carries, printed as its comment.
    pub note: &'static str,
}

fn port(dir: Dir, name: &'static str, bits: u32, note: &'static str) -> Port {
    Port {
        name,
        dir,
        width: Width::Bits(bits),
        note,
    }
}
pub fn i(name: &'static str, bits: u32, note: &'static str) -> Port {
    port(Dir::Input, name, bits, note)
}
pub fn o(name: &'static str, bits: u32, note: &'static str) -> Port {
    port(Dir::Output, name, bits, note)
}

/// The clock port of every stage and top: the one clock the FPGA flows time
/// (`flow::fpga` checks nextpnr's Fmax is for it).
pub const CLOCK: &str = "clk_i";

/// The host write port of a stage with writable memories (map_lookup's banks, and atan_rom's
/// table with `comp_table = ram`): every stage on the port sees every write and takes those
/// of its own axis slots (the maps 0..=2, the table 3), into the back buffer `wr_buf_i`.
pub fn host_write(cfg: &Config) -> Vec<Port> {
    vec![
        i("wr_en_i", 1, "host write, independent of en_i"),
        i("wr_buf_i", 1, ""),
        i("wr_axis_i", 2, ""),
        i(
            "wr_addr_i",
            cfg.map_addr_bits(),
            "{s_max, s_u, i_u, s_v, i_v}",
        ),
        i("wr_data_i", cfg.map_bits, ""),
    ]
}

/// clk_i, rst_ni, en_i, valid_i: the head of every pipeline stage.
pub fn stage_head() -> Vec<Port> {
    vec![
        i(CLOCK, 1, ""),
        i(
            "rst_ni",
            1,
            "asynchronous, active low: clears valid bits only",
        ),
        i("en_i", 1, "clock enable: low holds every register"),
        i("valid_i", 1, ""),
    ]
}

fn range(w: Width) -> String {
    match w {
        Width::Bits(1) => String::new(),
        Width::Bits(n) => format!("[{}:0]", n - 1),
        Width::Param(p) => format!("[{p}-1:0]"),
    }
}

/// The ANSI port list as it appears between `module name (` and `);`, columns aligned.
pub fn render(ports: &[Port]) -> String {
    let rw = ports
        .iter()
        .map(|p| range(p.width).len())
        .max()
        .unwrap_or(0);
    let nw = ports.iter().map(|p| p.name.len()).max().unwrap_or(0) + 1;
    let mut lines = Vec::with_capacity(ports.len());
    for (k, p) in ports.iter().enumerate() {
        let dir = match p.dir {
            Dir::Input => "input ",
            Dir::Output => "output",
        };
        let sep = if k + 1 == ports.len() { "" } else { "," };
        let name = format!("{}{sep}", p.name);
        let mut line = format!("  {dir} wire {:rw$} {name:nw$}", range(p.width));
        if !p.note.is_empty() {
            line.push_str(&format!("  // {}", p.note));
        }
        lines.push(line.trim_end().to_string());
    }
    lines.join("\n")
}
