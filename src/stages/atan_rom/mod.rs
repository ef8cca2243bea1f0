//! The distortion-compensation (atan) ROM: the position stage with compensation on. Each
//! fraction reads the ROM [`init_file`]; the ROM is instantiated twice (u and v), so each
//! copy is a single-port synchronous ROM in its own block RAM.

pub mod model;

use super::position;
use super::testbench::TbData;
use super::unit::{file_param, Head, Memory, Unit, Vectors};
use crate::config::Config;
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::rtl::ports::Port;
use crate::vectors::field::Field;
use askama::Template;

pub struct AtanRom;

/// Its `$readmemh` file, `<module>.hex`.
/// The ROM's arrays: one copy per read port (u, v) for the iCE40, whose block RAM has one read
/// port; one array read through two ports otherwise.
fn arrays(cfg: &Config) -> Vec<&'static str> {
    if cfg.target.ice40() {
        vec!["rom_u", "rom_v"]
    } else {
        vec!["rom"]
    }
}

pub fn init_file(cfg: &Config) -> String {
    format!("{}.hex", AtanRom.module(cfg))
}

/// A fabric register after the ROM's block-RAM output register (pipeline_depth >= 1).
fn out_reg(cfg: &Config) -> bool {
    cfg.pipeline_depth >= 1
}

#[derive(Template)]
#[template(path = "atan_rom/atan_rom.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    latency: u32,
    out_reg: bool,
    param: String,
    ice40: bool,
    /// Block-RAM attributes on the one array (true dual-port targets but generic).
    attrs: bool,
    target: &'static str,
    /// The arrays the u and v ports read: [`arrays`].
    rom_u: &'static str,
    rom_v: &'static str,
    pos: u32,
    entries: u32,
}

crate::tb_template!(Testbench, "atan_rom/atan_rom_tb.v");

impl Unit for AtanRom {
    fn name(&self) -> &'static str {
        "atan_rom"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        position::ports(cfg)
    }

    /// The block RAM's output register and the optional fabric register.
    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(1 + out_reg(cfg) as u32)
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        arrays(cfg)
            .into_iter()
            .map(|rom| {
                Memory::new(
                    rom,
                    self.module(cfg),
                    file_param(self.name()),
                    init_file(cfg),
                    cfg.atan_entries(),
                    cfg.pos_bits(),
                    false,
                )
            })
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            latency: self.latency(cfg).expect("fixed"),
            out_reg: out_reg(cfg),
            param: file_param(self.name()),
            ice40: cfg.target.ice40(),
            attrs: cfg.target.block_attrs(),
            target: cfg.target.name(),
            rom_u: arrays(cfg)[0],
            rom_v: arrays(cfg).last().expect("at least one array"),
            pos: cfg.pos_bits(),
            entries: cfg.atan_entries(),
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

impl Vectors for AtanRom {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        position::fields(cfg)
    }

    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        position::corners(&model.cfg)
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        position::random(cfg, rng)
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        position::expected(model, inp)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
