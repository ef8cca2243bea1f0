//! The bus top, rmap_bus (a configuration with a `bus`): the design's sample top
//! ([`super::sample_top`]: rmap_top, rmap_lanes or rmap_axis) with its host write port and
//! swap driven by the register block [`RmapRegs`], which a Wishbone B4 classic or an
//! AXI4-Lite slave front puts on a CPU's bus (docs/SOC.md). The sample ports are the sample
//! top's, as they are, plus `last_i` (the frame's last flag) when they carry none of their
//! own; the register block finds the frame boundaries and counts the beats in flight from
//! the sample top's [`Unit::stream`].

use super::rmap_regs::{regmap, RmapRegs};
use super::unit::{param_overrides, Head, Memory, Unit};
use crate::config::{Bus, Config};
use crate::hdl::ports::{i, o, Port};
use askama::Template;

mod vectors;
pub use vectors::{checks, Check};

pub struct RmapBus;

/// The sample top's ports the register block drives: they are not rmap_bus's.
const DRIVEN: [&str; 5] = ["swap_i", "wr_en_i", "wr_axis_i", "wr_addr_i", "wr_data_i"];

/// The bus ports, after `clk_i` and `rst_ni`.
fn bus_ports(cfg: &Config) -> Vec<Port> {
    let m = regmap(cfg);
    match cfg.bus {
        Bus::None => unreachable!("rmap_bus is only the top with a bus"),
        Bus::Wishbone => vec![
            i("wb_cyc_i", 1, ""),
            i("wb_stb_i", 1, ""),
            i("wb_we_i", 1, ""),
            i("wb_adr_i", m.word_bits(), "word address: byte offset / 4"),
            i("wb_dat_i", 32, ""),
            i("wb_sel_i", 4, "all ones for a write"),
            o("wb_ack_o", 1, ""),
            o("wb_err_o", 1, "the access is refused (ERRORS counts it)"),
            o("wb_dat_o", 32, "read data, with wb_ack_o"),
        ],
        Bus::Axi4Lite => vec![
            i("s_axil_awvalid", 1, ""),
            o("s_axil_awready", 1, ""),
            i("s_axil_awaddr", m.addr_bits, "byte address"),
            i("s_axil_awprot", 3, "not interpreted"),
            i("s_axil_wvalid", 1, ""),
            o("s_axil_wready", 1, ""),
            i("s_axil_wdata", 32, ""),
            i("s_axil_wstrb", 4, "all ones"),
            o("s_axil_bvalid", 1, ""),
            i("s_axil_bready", 1, ""),
            o("s_axil_bresp", 2, "OKAY, or SLVERR for a refused write"),
            i("s_axil_arvalid", 1, ""),
            o("s_axil_arready", 1, ""),
            i("s_axil_araddr", m.addr_bits, "byte address"),
            i("s_axil_arprot", 3, "not interpreted"),
            o("s_axil_rvalid", 1, ""),
            i("s_axil_rready", 1, ""),
            o("s_axil_rdata", 32, ""),
            o(
                "s_axil_rresp",
                2,
                "OKAY, or SLVERR (data 0) for a refused read",
            ),
        ],
    }
}

/// What the manifest says about the bus slave (`bus` only): the bus, the register map as
/// data, the files of its views, and the vector file (with its fields) that the testbench
/// streams, for the cocotb test (tb/cocotb/test_bus.py) and the LiteX core.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BusInfo {
    pub kind: &'static str,
    pub regmap: super::rmap_regs::RegMap,
    /// Clocks one access takes at the least through the bus front.
    pub clocks_per_access: u32,
    /// `<prefix>rmap_regs.h`, `.rdl`, `.py`, the driver's `.h` and `.c`.
    pub files: Vec<String>,
    /// The port that marks a frame's last sample (`last_i`, or `s_axis_tlast`).
    pub last: String,
    pub vectors: String,
    pub vector_fields: Vec<&'static str>,
}

impl BusInfo {
    pub fn new(cfg: &Config) -> Option<BusInfo> {
        use super::Vectors;
        if cfg.bus == Bus::None {
            return None;
        }
        let files = super::rmap_regs::views::files(cfg)
            .map(|v| v.into_iter().map(|(n, _)| n).collect())
            .unwrap_or_default();
        Some(BusInfo {
            kind: cfg.bus.name(),
            regmap: regmap(cfg),
            clocks_per_access: super::rmap_regs::views::clocks_per_access(cfg.bus),
            files,
            last: stream(cfg).last.unwrap_or_else(|| "last_i".into()),
            vectors: RmapBus.vector_file(cfg),
            vector_fields: RmapBus.fields(cfg).iter().map(|f| f.name).collect(),
        })
    }
}

/// The sample top's stream ([`Unit::stream`]).
fn stream(cfg: &Config) -> super::Stream {
    let inner = super::sample_top(cfg);
    inner
        .stream(cfg)
        .unwrap_or_else(|| panic!("{} has no sample stream", inner.name()))
}

impl Unit for RmapBus {
    fn name(&self) -> &'static str {
        "rmap_bus"
    }

    /// `clk_i`, `rst_ni`, the bus, `last_i` when the sample top has no last flag, then the
    /// sample top's other ports as they are.
    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let inner = super::sample_top(cfg);
        let all = inner.ports(cfg);
        let mut v: Vec<Port> = all
            .iter()
            .filter(|p| p.name == "clk_i" || p.name == "rst_ni")
            .cloned()
            .collect();
        v.extend(bus_ports(cfg));
        if stream(cfg).last.is_none() {
            v.push(i(
                "last_i",
                1,
                "the accepted sample is its frame's last (a swap waits for it)",
            ));
        }
        v.extend(
            all.into_iter()
                .filter(|p| p.name != "clk_i" && p.name != "rst_ni")
                .filter(|p| !DRIVEN.contains(&p.name)),
        );
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        super::sample_top(cfg).latency(cfg)
    }

    fn children(&self, cfg: &Config) -> Vec<&'static dyn Unit> {
        vec![&RmapRegs, super::sample_top(cfg)]
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        let inner = super::sample_top(cfg);
        inner
            .memories(cfg)
            .into_iter()
            .map(|m| m.under(&super::instance(inner.name())))
            .collect()
    }

    fn stream(&self, cfg: &Config) -> Option<super::Stream> {
        Some(stream(cfg))
    }

    fn vectors(&self) -> Option<&dyn super::Vectors> {
        Some(self)
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let inner = super::sample_top(cfg);
        let m = regmap(cfg);
        let s = stream(cfg);
        let own: Vec<&str> = inner.ports(cfg).iter().map(|p| p.name).collect();
        let nw = own.iter().map(|n| n.len()).max().unwrap_or(0);
        let pins = own
            .iter()
            .map(|&n| {
                let e = match n {
                    "swap_i" => "swap".to_string(),
                    n if DRIVEN.contains(&n) => n.trim_end_matches("_i").to_string(),
                    n => n.to_string(),
                };
                format!(".{n:nw$} ({e})")
            })
            .collect();
        Verilog {
            h,
            wishbone: cfg.bus == Bus::Wishbone,
            inner: inner.module(cfg),
            inner_params: param_overrides(cfg, inner),
            inner_inst: super::instance(inner.name()),
            regs: RmapRegs.module(cfg),
            regs_inst: super::instance(RmapRegs.name()),
            span: m.span(),
            w: m.word_bits(),
            ab: m.addr_bits,
            a: cfg.map_addr_bits(),
            mb: cfg.map_bits,
            own_last: s.last.is_none(),
            last: s.last.unwrap_or_else(|| "last_i".into()),
            accept: s.accept,
            deliver: s.deliver,
            pins,
        }
        .render()
    }
}

#[derive(Template)]
#[template(path = "rmap_bus/rmap_bus.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    wishbone: bool,
    inner: String,
    inner_params: String,
    inner_inst: String,
    regs: String,
    regs_inst: String,
    span: u32,
    /// Word and byte address bits.
    w: u32,
    ab: u32,
    /// Map address and entry bits.
    a: u32,
    mb: u32,
    own_last: bool,
    accept: String,
    last: String,
    deliver: String,
    pins: Vec<String>,
}
