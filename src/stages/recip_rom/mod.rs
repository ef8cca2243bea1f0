//! The reciprocal ROM that normalise reads: 1/m for every reduced max m, initialised from
//! [`init_file`]. One synchronous read port inside normalise; where rmap_lanes shares it
//! ([`dual`]) two, each with its own enable ([`PORTS`]), so
//! a true dual-port block RAM serves two lanes.

pub mod model;

use super::unit::{file_param, Head, Memory, Unit};
use crate::config::Config;
use crate::hdl::ports::{i, o, Port};
use askama::Template;

pub struct RecipRom;

/// The shared ROM's read ports, `(enable, address, data)` of port a and of port b.
pub const PORTS: [(&str, &str, &str); 2] = [
    ("en_a_i", "addr_a_i", "data_a_o"),
    ("en_b_i", "addr_b_i", "data_b_o"),
];

/// The reader's side of a shared ROM, `(enable, address, data)`: normalise and rmap_top have
/// these ports in place of their own ROM, and rmap_lanes wires them to a port of [`PORTS`].
pub const READER: (&str, &str, &str) = ("recip_en_o", "recip_addr_o", "recip_data_i");

/// The reader's ports ([`READER`]) of a normalise or rmap_top whose ROM is in rmap_lanes.
pub fn reader_ports(cfg: &Config) -> Vec<Port> {
    if !dual(cfg) {
        return vec![];
    }
    let (en, addr, data) = READER;
    vec![
        o(
            en,
            1,
            "reciprocal ROM read enable (the ROM is shared, in rmap_lanes)",
        ),
        o(addr, cfg.recip_addr_bits(), "reciprocal ROM address"),
        i(
            data,
            cfg.recip_bits,
            "the ROM's registered data, one clock after the address",
        ),
    ]
}

/// Whether this configuration's ROM has the two read ports of [`PORTS`] (it lives in
/// rmap_lanes, shared by two lanes) rather than one inside normalise: with lanes, on a target
/// whose block RAM is true dual-port (read ports 2: generic and the ECP5). Defined here, below
/// normalise, rmap_top and rmap_lanes, which all ask it.
pub fn dual(cfg: &Config) -> bool {
    cfg.lanes > 1 && cfg.target.read_ports() == 2
}

/// Its `$readmemh` file, `<module>.hex`.
pub fn init_file(cfg: &Config) -> String {
    format!("{}.hex", RecipRom.module(cfg))
}

#[derive(Template)]
#[template(path = "recip_rom/recip_rom.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    param: String,
    /// Block-RAM attributes (every target but generic).
    attrs: bool,
    target: &'static str,
    dual: bool,
    w: u32,
    entries: u32,
}

impl Unit for RecipRom {
    fn name(&self) -> &'static str {
        "recip_rom"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        if dual(cfg) {
            let mut v = vec![i("clk_i", 1, "")];
            for (en, addr, data) in PORTS {
                v.push(i(en, 1, "read enable of this port: low holds its data"));
                v.push(i(
                    addr,
                    cfg.recip_addr_bits(),
                    "reduced max without its MSB",
                ));
                v.push(o(data, cfg.recip_bits, "registered reciprocal"));
            }
            return v;
        }
        vec![
            i("clk_i", 1, ""),
            i("en_i", 1, "read enable: low holds data_o"),
            i(
                "addr_i",
                cfg.recip_addr_bits(),
                "reduced max without its MSB",
            ),
            o("data_o", cfg.recip_bits, "registered reciprocal"),
        ]
    }

    /// The block RAM's output register.
    fn latency(&self, _cfg: &Config) -> Option<u32> {
        Some(1)
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        vec![Memory::new(
            "rom",
            self.module(cfg),
            file_param(self.name()),
            init_file(cfg),
            cfg.recip_entries(),
            cfg.recip_bits,
            false,
        )
        .with_reads(if dual(cfg) { 2 } else { 1 })]
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            param: file_param(self.name()),
            attrs: cfg.target.block_attrs(),
            target: cfg.target.name(),
            dual: dual(cfg),
            w: cfg.recip_bits,
            entries: cfg.recip_entries(),
        }
        .render()
    }
}
