//! The register block of the bus slave, rmap_regs (a configuration with a `bus`): the
//! identification block, control, status and the write windows of [`regmap`] behind a plain
//! register port (one access at a time, answered with `ack_o` and `err_o`), driving the host
//! write port and the swap of the design's sample top. The bus top, rmap_bus
//! (src/stages/rmap_bus), puts it on Wishbone or AXI4-Lite.
//!
//! Every view of the register map is generated here from [`regmap::regmap`]: the Verilog's
//! addresses and read-back, the C header and driver ([`views`]), the SystemRDL file, the
//! README's table and the Python constants.

pub mod regmap;
pub mod views;

use super::rmap_top::top_latency;
use super::unit::{Head, Unit};
use crate::config::{bit_length, Config};
use crate::hdl::ports::{i, o, Port};
use askama::Template;
pub use regmap::{regmap, RegMap};

pub struct RmapRegs;

/// Bits of the beat counters: the beats in flight are at most the pipeline's latency plus
/// its output queue (with the handshake), well under twice the latency plus 8.
pub fn count_bits(cfg: &Config) -> u32 {
    bit_length(2 * top_latency(cfg) as u64 + 8)
}

#[derive(Template)]
#[template(path = "rmap_regs/rmap_regs.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// The sample top whose write port it drives (for the comments).
    top: String,
    m: RegMap,
    /// Word address bits.
    w: u32,
    /// Map address bits A.
    a: u32,
    /// Map entry bits.
    mb: u32,
    /// Beat counter bits.
    iw: u32,
    /// The windows a write may reach, as a Verilog condition.
    win_ok: String,
    table: bool,
    swap_bit: u32,
    clear_bit: u32,
}

impl Unit for RmapRegs {
    fn name(&self) -> &'static str {
        "rmap_regs"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let m = regmap(cfg);
        vec![
            i("clk_i", 1, ""),
            i("rst_ni", 1, "asynchronous, active low"),
            i("req_i", 1, "an access, held until ack_o"),
            i("we_i", 1, "1: a write"),
            i("addr_i", m.word_bits(), "word address: byte offset / 4"),
            i("wdata_i", 32, ""),
            i("be_i", 4, "byte enables: a write needs all four"),
            o("ack_o", 1, "the access is done (one clock)"),
            o("err_o", 1, "with ack_o: refused"),
            o("ack_we_o", 1, "with ack_o: it was a write"),
            o("rdata_o", 32, "with ack_o: the read data"),
            i("accept_i", 1, "the sample top accepts a beat"),
            i("last_i", 1, "with accept_i: the frame's last beat"),
            i("deliver_i", 1, "a beat of results leaves the sample top"),
            o("wr_en_o", 1, "the host write port of the sample top"),
            o("wr_axis_o", 2, ""),
            o("wr_addr_o", cfg.map_addr_bits(), ""),
            o("wr_data_o", cfg.map_bits, ""),
            o("swap_o", 1, "at a frame boundary"),
        ]
    }

    /// An access is answered at the first clock after it is presented (a window write that
    /// waits for a swap or the pipeline: later).
    fn latency(&self, _cfg: &Config) -> Option<u32> {
        Some(1)
    }

    fn files(&self, cfg: &Config) -> anyhow::Result<Vec<(String, String)>> {
        views::files(cfg)
    }

    fn readme(&self, cfg: &Config) -> Option<String> {
        Some(views::readme_section(cfg))
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let m = regmap(cfg);
        let a = cfg.map_addr_bits();
        let table = m.windows.iter().find(|w| w.axis == 3);
        let win_ok = match table {
            None => "win && axis != 2'd3".to_string(),
            Some(t) if t.entries < 1 << a => {
                format!("win && (axis != 2'd3 || entry < {a}'d{})", t.entries)
            }
            Some(_) => "win".to_string(),
        };
        let control = m.reg("CONTROL");
        let bit = |name: &str| {
            control
                .fields
                .iter()
                .find(|f| f.name == name)
                .expect("a CONTROL field")
                .lsb
        };
        Verilog {
            h,
            top: super::sample_top(cfg).module(cfg),
            w: m.word_bits(),
            a,
            mb: cfg.map_bits,
            iw: count_bits(cfg),
            win_ok,
            table: table.is_some(),
            swap_bit: bit("SWAP"),
            clear_bit: bit("CLEAR_ERRORS"),
            m,
        }
        .render()
    }
}
