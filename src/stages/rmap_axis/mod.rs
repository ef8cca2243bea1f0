//! The AXI4-Stream top, rmap_axis (`axis`): the handshake top [`RmapTop`] with AXI4-Stream
//! ports. A sample comes in on `s_axis_*` (`tdata` holds the top's input fields), its result
//! leaves on `m_axis_*` (`tdata` holds the top's output fields), and `{tuser, tlast}` ride
//! beside it through the top's `side_i` / `side_o` (one delay line on the pipeline's clock
//! enable and one more entry in each slot of the output queue), so they leave with exactly
//! their own sample. valid/ready are the top's own; nothing is added to the datapath.
//!
//! The `tdata` layouts ([`Packing`]) are defined here once, from the top's vector fields: the
//! template slices `tdata` with them, the manifest carries them (for the cocotb test,
//! tb/cocotb/test_axis.py) and the README prints them.

mod vectors;

use super::rmap_top::{top_latency, RmapTop};
use super::unit::{Head, Memory, Unit, Vectors};
use super::TOP;
use crate::config::Config;
use crate::hdl::ports::{i, o, Dir, Port, Width};
use crate::vectors::field;
use askama::Template;
use serde::Serialize;

pub struct RmapAxis;

/// One field of a `tdata` bus: bits `[offset + bits - 1 : offset]`, the rest of its bytes
/// padding.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Slot {
    /// The field of the top's vector file (`gx`, `i`, `r_o`, ...).
    pub field: &'static str,
    /// The top's port it drives or comes from.
    pub port: String,
    pub bits: u32,
    /// Lowest bit, a multiple of 8.
    pub offset: u32,
    /// Bytes it occupies: bits rounded up to whole bytes.
    pub bytes: u32,
}

impl Slot {
    /// Highest bit of the field.
    pub fn hi(&self) -> u32 {
        self.offset + self.bits - 1
    }
    /// `[hi:lo]` of the field, `[lo]` for one bit.
    pub fn range(&self) -> String {
        if self.bits == 1 {
            format!("[{}]", self.offset)
        } else {
            format!("[{}:{}]", self.hi(), self.offset)
        }
    }
    /// `[hi:lo]` of the padding above the field in its bytes, if any.
    pub fn pad(&self) -> Option<(u32, u32)> {
        let end = self.offset + 8 * self.bytes;
        (self.offset + self.bits < end).then(|| (end - 1, self.offset + self.bits))
    }
}

/// The layout of one `tdata` bus: each field of the top's vector file that has a port, in
/// the file's order from bit 0 up, each starting on a byte boundary and padded to whole
/// bytes.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Packing {
    /// Width of `tdata`: a whole number of bytes.
    pub bits: u32,
    pub slots: Vec<Slot>,
}

/// The layout of `s_axis_tdata` (`dir` In: the top's input fields) or `m_axis_tdata` (Out).
pub fn packing(cfg: &Config, dir: field::Dir) -> Packing {
    let top = TOP.vectors().expect("the top has vectors");
    let mut slots = Vec::new();
    let mut offset = 0;
    for f in top.fields(cfg).into_iter().filter(|f| f.dir == dir) {
        let Some(port) = top.port(&f) else { continue };
        let bytes = f.bits.div_ceil(8);
        slots.push(Slot {
            field: f.name,
            port,
            bits: f.bits,
            offset,
            bytes,
        });
        offset += 8 * bytes;
    }
    Packing {
        bits: offset,
        slots,
    }
}

/// What the manifest says about the AXI4-Stream ports (`axis` only): the two layouts, the
/// `tuser` width, and the vector file whose fields they name.
#[derive(Clone, Debug, Serialize)]
pub struct AxisInfo {
    pub s_tdata: Packing,
    pub m_tdata: Packing,
    /// Width of `tuser` (0: no tuser ports). `tlast` is always there.
    pub tuser_bits: u32,
    /// The top's vector file (`vectors/<module>.hex`): inputs and expected outputs.
    pub vectors: String,
    /// Its fields in order (`map` steers the buffer swap: see docs/ARCHITECTURE.md).
    pub vector_fields: Vec<&'static str>,
}

impl AxisInfo {
    pub fn new(cfg: &Config) -> Option<AxisInfo> {
        let top = TOP.vectors().expect("the top has vectors");
        cfg.axis.then(|| AxisInfo {
            s_tdata: packing(cfg, field::Dir::In),
            m_tdata: packing(cfg, field::Dir::Out),
            tuser_bits: cfg.axis_user,
            vectors: top.vector_file(cfg),
            vector_fields: top.fields(cfg).iter().map(|f| f.name).collect(),
        })
    }
}

/// The wrapper's own ports, before the top's host ports it passes through.
fn axis_ports(cfg: &Config) -> Vec<Port> {
    let (s, m) = (
        packing(cfg, field::Dir::In).bits,
        packing(cfg, field::Dir::Out).bits,
    );
    let mut v = vec![
        i("clk_i", 1, ""),
        i(
            "rst_ni",
            1,
            "asynchronous, active low (AXI's ARESETn, without its synchronous assertion)",
        ),
        i("s_axis_tvalid", 1, ""),
        o(
            "s_axis_tready",
            1,
            "a register: low in reset, rises at the first clock after it",
        ),
        i("s_axis_tdata", s, "the sample's fields, byte-aligned"),
    ];
    if cfg.axis_user > 0 {
        v.push(i("s_axis_tuser", cfg.axis_user, "passed through"));
    }
    v.push(i("s_axis_tlast", 1, "passed through"));
    v.push(o("m_axis_tvalid", 1, ""));
    v.push(i("m_axis_tready", 1, "reaches no output combinationally"));
    v.push(o("m_axis_tdata", m, "the result's fields, byte-aligned"));
    if cfg.axis_user > 0 {
        v.push(o(
            "m_axis_tuser",
            cfg.axis_user,
            "s_axis_tuser of the sample",
        ));
    }
    v.push(o("m_axis_tlast", 1, "s_axis_tlast of the sample"));
    v
}

/// The expression each port of the top is connected to: a wrapper port, a `tdata` slice, or
/// the same-named wrapper port (the host ports and `swap_i`, passed through), which the
/// second list returns.
fn connections(cfg: &Config) -> (Vec<(&'static str, String)>, Vec<Port>) {
    let (sp, mp) = (packing(cfg, field::Dir::In), packing(cfg, field::Dir::Out));
    let side = |bus: &str| {
        if cfg.axis_user > 0 {
            format!("{{{bus}_tuser, {bus}_tlast}}")
        } else {
            format!("{bus}_tlast")
        }
    };
    let slice = |bus: &str, p: &Packing, port: &str| {
        p.slots
            .iter()
            .find(|s| s.port == port)
            .map(|s| format!("{bus}_tdata{}", s.range()))
    };
    let mut pins = Vec::new();
    let mut through = Vec::new();
    for p in TOP.ports(cfg) {
        let e = match p.name {
            "clk_i" | "rst_ni" => p.name.to_string(),
            "valid_i" => "s_axis_tvalid".into(),
            "ready_o" => "s_axis_tready".into(),
            "valid_o" => "m_axis_tvalid".into(),
            "ready_i" => "m_axis_tready".into(),
            "side_i" => side("s_axis"),
            "side_o" => side("m_axis"),
            n => match slice("s_axis", &sp, n).or_else(|| slice("m_axis", &mp, n)) {
                Some(e) => e,
                None => {
                    through.push(p.clone());
                    n.to_string()
                }
            },
        };
        pins.push((p.name, e));
    }
    (pins, through)
}

/// The top's instance name, `u_rmap_top`.
fn instance() -> String {
    format!("u_{}", RmapTop.name())
}

#[derive(Template)]
#[template(path = "rmap_axis/rmap_axis.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    top: String,
    /// ` #(...)` passing the init-file parameters down to the top.
    top_params: String,
    /// The top's instance, `u_<name>`.
    inst: String,
    s_slots: Vec<Slot>,
    m_slots: Vec<Slot>,
    /// `{s_axis_tdata[15:12], ...}`: the padding of s_axis_tdata, read by nothing.
    s_pad: Option<(u32, String)>,
    /// `[hi:lo]` ranges of m_axis_tdata that are padding, driven with 0.
    m_pads: Vec<(u32, u32)>,
    /// `.port (expr)` lines, names aligned.
    pins: Vec<String>,
    latency: u32,
}

impl Unit for RmapAxis {
    fn name(&self) -> &'static str {
        "rmap_axis"
    }

    /// The AXI4-Stream ports, then the top's host ports (`swap_i`, `wr_*`) as they are.
    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let mut v = axis_ports(cfg);
        v.extend(connections(cfg).1);
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(top_latency(cfg))
    }

    fn children(&self, _cfg: &Config) -> Vec<&'static dyn Unit> {
        vec![&RmapTop]
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        RmapTop
            .memories(cfg)
            .into_iter()
            .map(|m| m.under(&instance()))
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let (sp, mp) = (packing(cfg, field::Dir::In), packing(cfg, field::Dir::Out));
        let s_pads: Vec<(u32, u32)> = sp.slots.iter().filter_map(Slot::pad).collect();
        let s_pad = (!s_pads.is_empty()).then(|| {
            let bits = s_pads.iter().map(|(h, l)| h - l + 1).sum();
            let parts: Vec<String> = s_pads
                .iter()
                .rev()
                .map(|(h, l)| {
                    if h == l {
                        format!("s_axis_tdata[{h}]")
                    } else {
                        format!("s_axis_tdata[{h}:{l}]")
                    }
                })
                .collect();
            (bits, format!("{{{}}}", parts.join(", ")))
        });
        let (pins, _) = connections(cfg);
        let nw = pins.iter().map(|(n, _)| n.len()).max().unwrap_or(0);
        let pins = pins
            .iter()
            .map(|(n, e)| format!(".{n:nw$} ({e})"))
            .collect();
        Verilog {
            h,
            top: RmapTop.module(cfg),
            top_params: super::unit::param_overrides(cfg, &RmapTop),
            inst: instance(),
            m_pads: mp.slots.iter().filter_map(Slot::pad).collect(),
            s_slots: sp.slots,
            m_slots: mp.slots,
            s_pad,
            pins,
            latency: top_latency(cfg),
        }
        .render()
    }

    /// A beat each way with its `tvalid && tready`; a frame ends with `s_axis_tlast`.
    fn stream(&self, _cfg: &Config) -> Option<super::unit::Stream> {
        Some(super::unit::Stream {
            accept: "s_axis_tvalid && s_axis_tready".into(),
            deliver: "m_axis_tvalid && m_axis_tready".into(),
            last: Some("s_axis_tlast".into()),
        })
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

/// The wrapper's port list with the width of each `Width::Bits` (for the README table).
pub fn port_rows(cfg: &Config) -> Vec<(String, &'static str, u32, &'static str)> {
    RmapAxis
        .ports(cfg)
        .into_iter()
        .map(|p| {
            let w = match p.width {
                Width::Bits(b) => b,
                Width::Param(_) => unreachable!("the wrapper's ports have fixed widths"),
            };
            let d = match p.dir {
                Dir::Input => "in",
                Dir::Output => "out",
            };
            (p.name.to_string(), d, w, p.note)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::COLOR_BITS;

    fn axis(color: bool, user: u32) -> Config {
        Config {
            handshake: true,
            axis: true,
            axis_user: user,
            color,
            ..Config::default()
        }
    }

    #[test]
    fn fields_start_on_bytes_in_vector_order() {
        let cfg = axis(true, 0);
        let s = packing(&cfg, field::Dir::In);
        let got: Vec<(&str, u32, u32)> = s
            .slots
            .iter()
            .map(|x| (x.field, x.offset, x.bits))
            .collect();
        assert_eq!(
            got,
            [
                ("gx", 0, 12),
                ("gy", 16, 12),
                ("gz", 32, 12),
                ("r", 48, COLOR_BITS),
                ("g", 56, 8),
                ("b", 64, 8)
            ]
        );
        assert_eq!(s.bits, 72);
        assert_eq!(s.slots[0].pad(), Some((15, 12)));
        assert_eq!(s.slots[3].pad(), None);
        let m = packing(&cfg, field::Dir::Out);
        let got: Vec<(&str, &str, u32)> = m
            .slots
            .iter()
            .map(|x| (x.field, x.port.as_str(), x.offset))
            .collect();
        assert_eq!(
            got,
            [
                ("zero", "zero_o", 0),
                ("i", "i_o", 8),
                ("r_o", "r_o", 16),
                ("g_o", "g_o", 24),
                ("b_o", "b_o", 32)
            ]
        );
        assert_eq!(m.bits, 40);
        let wide = Config {
            grad_bits: 16,
            map_bits: 12,
            ..axis(false, 0)
        };
        assert_eq!(packing(&wide, field::Dir::In).bits, 48);
        assert_eq!(packing(&wide, field::Dir::Out).bits, 24);
    }

    #[test]
    fn ports_are_axis_then_the_host_ports() {
        let names: Vec<&str> = RmapAxis
            .ports(&axis(false, 4))
            .iter()
            .map(|p| p.name)
            .collect();
        assert_eq!(
            names.join(" "),
            "clk_i rst_ni s_axis_tvalid s_axis_tready s_axis_tdata s_axis_tuser s_axis_tlast \
             m_axis_tvalid m_axis_tready m_axis_tdata m_axis_tuser m_axis_tlast \
             swap_i wr_en_i wr_axis_i wr_addr_i wr_data_i"
        );
        let names: Vec<&str> = RmapAxis
            .ports(&axis(false, 0))
            .iter()
            .map(|p| p.name)
            .collect();
        assert!(!names.iter().any(|n| n.ends_with("tuser")), "{names:?}");
    }

    #[test]
    fn the_readme_prints_the_packing_only_with_axis() {
        let cfg = axis(true, 3);
        let text =
            crate::emit::package::readme(&crate::design::Design::standard(&cfg).unwrap()).unwrap();
        assert!(text.contains("## AXI4-Stream"), "{text}");
        for (bus, p) in [
            ("s_axis_tdata", packing(&cfg, field::Dir::In)),
            ("m_axis_tdata", packing(&cfg, field::Dir::Out)),
        ] {
            for s in &p.slots {
                let row = format!(
                    "| `{bus}` ({} bits) | `{}` | {} | {} |",
                    p.bits,
                    s.field,
                    s.bits,
                    s.range()
                );
                assert!(text.contains(&row), "{row}");
            }
        }
        assert!(text.contains("| `s_axis_tuser` | in | 3 |"));
        let plain = crate::emit::package::readme(
            &crate::design::Design::standard(&Config::default()).unwrap(),
        )
        .unwrap();
        assert!(!plain.contains("AXI4-Stream ports"));
    }

    #[test]
    fn the_testbench_packs_every_field_of_the_tops_vectors_at_its_slot() {
        for (color, user) in [(false, 0), (true, 3), (false, 64)] {
            let cfg = axis(color, user);
            let text = crate::emit::tb::render(&cfg, &RmapAxis).unwrap();
            assert!(text.contains("module rmap_axis_tb;"));
            assert!(text.contains("  rmap_axis #("), "{text}");
            for (bus, dir) in [("nx_tdata", field::Dir::In), ("exp_tdata", field::Dir::Out)] {
                for s in &packing(&cfg, dir).slots {
                    let want = format!("{bus}{} = v_{}[", s.range(), s.field);
                    assert!(text.contains(&want), "{want}");
                }
            }
            // Every top field the vectors carry with a port has a slot: none is left unchecked.
            let top = TOP.vectors().unwrap();
            let slotted = packing(&cfg, field::Dir::In).slots.len()
                + packing(&cfg, field::Dir::Out).slots.len();
            let ported = top
                .fields(&cfg)
                .iter()
                .filter(|f| top.port(f).is_some())
                .count();
            assert_eq!(slotted, ported);
            assert_eq!(text.contains("m_axis_tuser"), user > 0);
            // Between host writes the write port carries random values (wr_en_i must gate it).
            for p in ["wr_axis_i", "wr_addr_i", "wr_data_i"] {
                assert!(text.contains(&format!("      {p} = rnd[")), "{p}");
            }
            assert!(text.contains("      if (!wr_en_i) host_garbage;"));
        }
    }

    #[test]
    fn the_design_top_is_the_wrapper_with_axis() {
        let cfg = axis(false, 2);
        assert_eq!(super::super::top(&cfg).name(), "rmap_axis");
        assert_eq!(super::super::top(&Config::default()).name(), "rmap_top");
        assert_eq!(RmapAxis.latency(&cfg), RmapTop.latency(&cfg));
        let mems = RmapAxis.memories(&cfg);
        assert!(mems.iter().all(|m| m.instance.starts_with("u_rmap_top.")));
        assert_eq!(mems.len(), RmapTop.memories(&cfg).len());
    }
}
