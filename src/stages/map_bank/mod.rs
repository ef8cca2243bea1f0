//! A map bank: one RAM of the double-buffered reflectance map, a synchronous read port for
//! the samples and a write port for the host. map_lookup instantiates one (without
//! interpolation) or four (one per index parity pair); [`banks`] says where each logical map
//! entry lives and writes the banks' init files.

pub mod banks;

use super::unit::{Head, Memory, Unit};
use crate::config::Config;
use crate::hdl::ports::{i, o, Port};
use askama::Template;

pub struct MapBank;

/// Its init-file parameter: generic, because map_lookup instantiates it up to four times, each
/// with its own file (map_lookup passes `banks::bank_param` down as it).
pub const INIT_PARAM: &str = "INIT_FILE";

#[derive(Template)]
#[template(path = "map_bank/map_bank.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    param: &'static str,
    /// Block-RAM attributes (every target but generic).
    attrs: bool,
    target: &'static str,
    m: u32,
    entries: u32,
}

impl Unit for MapBank {
    fn name(&self) -> &'static str {
        "map_bank"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (ba, mb) = (cfg.bank_addr_bits(), cfg.map_bits);
        vec![
            i("clk_i", 1, ""),
            i("en_i", 1, "read enable: low holds rd_data_o"),
            i("rd_addr_i", ba, ""),
            i("wr_en_i", 1, ""),
            i("wr_addr_i", ba, ""),
            i("wr_data_i", mb, ""),
            o("rd_data_o", mb, "registered"),
        ]
    }

    /// The block RAM's output register.
    fn latency(&self, _cfg: &Config) -> Option<u32> {
        Some(1)
    }

    /// One bank's array; map_lookup names each instance's init file.
    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        vec![Memory::new(
            "mem",
            self.module(cfg),
            INIT_PARAM.to_string(),
            banks::bank_file(cfg, 0),
            cfg.bank_entries(),
            cfg.map_bits,
            true,
        )]
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            param: INIT_PARAM,
            attrs: cfg.target.block_attrs(),
            target: cfg.target.name(),
            m: cfg.map_bits,
            entries: cfg.bank_entries(),
        }
        .render()
    }
}
