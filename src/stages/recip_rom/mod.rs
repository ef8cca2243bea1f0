//! The reciprocal ROM that normalise reads: 1/m for every reduced max m, one synchronous
//! read port, initialised from [`init_file`].

pub mod model;

use super::unit::{file_param, Head, Memory, Unit};
use crate::config::Config;
use crate::rtl::ports::{i, o, Port};
use askama::Template;

pub struct RecipRom;

/// Its `$readmemh` file, `<module>.hex`.
pub fn init_file(cfg: &Config) -> String {
    format!("{}.hex", RecipRom.module(cfg))
}

#[derive(Template)]
#[template(path = "recip_rom/recip_rom.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    param: String,
    ice40: bool,
    w: u32,
    entries: u32,
}

impl Unit for RecipRom {
    fn name(&self) -> &'static str {
        "recip_rom"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
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
        )]
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            param: file_param(self.name()),
            ice40: cfg.target.ice40(),
            w: cfg.recip_bits,
            entries: cfg.recip_entries(),
        }
        .render()
    }
}
