//! The port list of every generated module, defined once: the templates print it (so the
//! Verilog cannot disagree with it) and the manifest lists it.

use super::Module;
use crate::config::{Config, COLOR_BITS};
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
fn i(name: &'static str, bits: u32, note: &'static str) -> Port {
    port(Dir::Input, name, bits, note)
}
fn o(name: &'static str, bits: u32, note: &'static str) -> Port {
    port(Dir::Output, name, bits, note)
}

/// clk_i, rst_ni, en_i, valid_i: the head of every pipeline stage.
fn stage_head() -> Vec<Port> {
    vec![
        i("clk_i", 1, ""),
        i(
            "rst_ni",
            1,
            "asynchronous, active low: clears valid bits only",
        ),
        i("en_i", 1, "clock enable: low holds every register"),
        i("valid_i", 1, ""),
    ]
}

/// The ports of `m` in declaration order.
pub fn ports(cfg: &Config, m: Module) -> Vec<Port> {
    let g = cfg.grad_bits;
    let r = cfg.red_bits;
    let f = cfg.frac_bits;
    let pos = cfg.pos_bits();
    let mb = cfg.map_bits;
    let w = cfg.weight_bits();
    let mut v = Vec::new();
    match m {
        Module::ZeroDetect => {
            v.extend(stage_head());
            v.push(i("gx_i", g, "G-bit two's complement"));
            v.push(i("gy_i", g, ""));
            v.push(i("gz_i", g, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("zero_o", 1, "all three components are zero"));
        }
        Module::SortShift => {
            v.extend(stage_head());
            v.push(i("gx_i", g, "G-bit two's complement"));
            v.push(i("gy_i", g, ""));
            v.push(i("gz_i", g, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("axis_o", 2, "max axis: 0 x, 1 y, 2 z (ties: lowest)"));
            v.push(o("s_max_o", 1, "sign of the max component (1 = negative)"));
            v.push(o("s_u_o", 1, "sign of u"));
            v.push(o("s_v_o", 1, "sign of v"));
            v.push(o("m_o", r, "reduced max magnitude (MSB set unless zero)"));
            v.push(o("a_o", r, "reduced u magnitude"));
            v.push(o("b_o", r, "reduced v magnitude"));
        }
        Module::RecipRom => {
            v.push(i("clk_i", 1, ""));
            v.push(i("en_i", 1, "read enable: low holds data_o"));
            v.push(i(
                "addr_i",
                cfg.recip_addr_bits(),
                "reduced max without its MSB",
            ));
            v.push(o("data_o", cfg.recip_bits, "registered reciprocal"));
        }
        Module::Normalise => {
            v.extend(stage_head());
            v.push(i("m_i", r, "reduced max"));
            v.push(i("a_i", r, ""));
            v.push(i("b_i", r, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("u_o", f, "a / m, all ones for a == m"));
            v.push(o("v_o", f, "b / m"));
        }
        Module::AtanRom | Module::LinearIndex => {
            v.extend(stage_head());
            v.push(i("u_i", f, "normalised fraction"));
            v.push(i("v_i", f, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("pu_o", pos, "map position, 0..POS_MAX"));
            v.push(o("pv_o", pos, ""));
        }
        Module::MapLookup => {
            v.extend(stage_head());
            v.push(i("axis_i", 2, ""));
            v.push(i("s_max_i", 1, ""));
            v.push(i("s_u_i", 1, ""));
            v.push(i("s_v_i", 1, ""));
            v.push(i("pu_i", pos, "position along u"));
            v.push(i("pv_i", pos, "position along v"));
            v.push(i("rd_buf_i", 1, "buffer this sample reads"));
            v.push(i("wr_en_i", 1, "host write, independent of en_i"));
            v.push(i("wr_buf_i", 1, ""));
            v.push(i("wr_axis_i", 2, ""));
            v.push(i(
                "wr_addr_i",
                cfg.map_addr_bits(),
                "{s_max, s_u, i_u, s_v, i_v}",
            ));
            v.push(i("wr_data_i", mb, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("e00_o", mb, "entry (base_u, base_v)"));
            if cfg.interpolation {
                v.push(o("e10_o", mb, "entry (base_u + 1, base_v)"));
                v.push(o("e01_o", mb, "entry (base_u, base_v + 1)"));
                v.push(o("e11_o", mb, "entry (base_u + 1, base_v + 1)"));
                v.push(o("wu_o", w, "weight along u, 0..S"));
                v.push(o("wv_o", w, "weight along v, 0..S"));
            }
        }
        Module::MapBank => {
            let ba = cfg.bank_addr_bits();
            v.push(i("clk_i", 1, ""));
            v.push(i("en_i", 1, "read enable: low holds rd_data_o"));
            v.push(i("rd_addr_i", ba, ""));
            v.push(i("wr_en_i", 1, ""));
            v.push(i("wr_addr_i", ba, ""));
            v.push(i("wr_data_i", mb, ""));
            v.push(o("rd_data_o", mb, "registered"));
        }
        Module::Interpolate => {
            v.extend(stage_head());
            v.push(i("e00_i", mb, ""));
            v.push(i("e10_i", mb, ""));
            v.push(i("e01_i", mb, ""));
            v.push(i("e11_i", mb, ""));
            v.push(i("wu_i", w, "0..S"));
            v.push(i("wv_i", w, "0..S"));
            v.push(o("valid_o", 1, ""));
            v.push(o("i_o", mb, "bilinear intensity, rounded half up"));
        }
        Module::ColorMul => {
            v.extend(stage_head());
            v.push(i("i_i", mb, "intensity"));
            v.push(i("r_i", COLOR_BITS, ""));
            v.push(i("g_i", COLOR_BITS, ""));
            v.push(i("b_i", COLOR_BITS, ""));
            v.push(o("valid_o", 1, ""));
            v.push(o("r_o", COLOR_BITS, "round(r * i / (2^M - 1))"));
            v.push(o("g_o", COLOR_BITS, ""));
            v.push(o("b_o", COLOR_BITS, ""));
        }
        Module::PipeDelay => {
            v.push(i("clk_i", 1, ""));
            v.push(i("en_i", 1, "low holds the line"));
            v.push(Port {
                name: "d_i",
                dir: Dir::Input,
                width: Width::Param("WIDTH"),
                note: "",
            });
            v.push(Port {
                name: "q_o",
                dir: Dir::Output,
                width: Width::Param("WIDTH"),
                note: "d_i of DEPTH enabled clocks ago",
            });
        }
        Module::RmapTop => {
            v.push(i("clk_i", 1, ""));
            v.push(i("rst_ni", 1, "asynchronous, active low"));
            v.push(i(
                "valid_i",
                1,
                if cfg.handshake {
                    "a sample is accepted at a rising edge with valid_i && ready_o"
                } else {
                    "a sample is accepted every cycle valid_i is high"
                },
            ));
            v.push(i("gx_i", g, "G-bit two's complement"));
            v.push(i("gy_i", g, ""));
            v.push(i("gz_i", g, ""));
            if cfg.color {
                v.push(i("r_i", COLOR_BITS, "sample colour"));
                v.push(i("g_i", COLOR_BITS, ""));
                v.push(i("b_i", COLOR_BITS, ""));
            }
            v.push(i("swap_i", 1, "exchange front and back map buffers"));
            v.push(i("wr_en_i", 1, "host write into the back buffer"));
            v.push(i("wr_axis_i", 2, ""));
            v.push(i(
                "wr_addr_i",
                cfg.map_addr_bits(),
                "{s_max, s_u, i_u, s_v, i_v}",
            ));
            v.push(i("wr_data_i", mb, ""));
            if cfg.handshake {
                v.push(i(
                    "ready_i",
                    1,
                    "the result leaves at a rising edge with valid_o && ready_i",
                ));
                v.push(o(
                    "ready_o",
                    1,
                    "the pipeline accepts a sample (a register; low in reset)",
                ));
            }
            v.push(o(
                "valid_o",
                1,
                if cfg.handshake {
                    "holds, with the outputs, until ready_i"
                } else {
                    ""
                },
            ));
            v.push(o("zero_o", 1, "the sample's gradient was zero"));
            v.push(o("i_o", mb, "intensity (0 when zero_o)"));
            if cfg.color {
                v.push(o("r_o", COLOR_BITS, "colour times intensity"));
                v.push(o("g_o", COLOR_BITS, ""));
                v.push(o("b_o", COLOR_BITS, ""));
            }
        }
    }
    v
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
