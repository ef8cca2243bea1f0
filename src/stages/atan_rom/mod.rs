//! The distortion-compensation table: the position stage with compensation on. Each fraction
//! reads the table [`init_file`]. With `comp_table = rom` (the paper's) it is the atan ROM;
//! with `comp_table = ram` a double-buffered RAM the host writes through the map write port
//! (axis slot 3, address u, data the position), each sample reading the buffer it was
//! accepted with, so that a frame's table changes with its maps.

pub mod model;

use super::position;
use super::testbench::TbData;
use super::unit::{file_param, Head, Memory, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::ports::{i, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use askama::Template;

pub struct AtanRom;

/// The table's arrays: one copy per read port (u, v) for a target whose block RAM has one
/// read port, and for the RAM (two reads and a write are more ports than a block RAM has);
/// one ROM array read through two ports otherwise.
fn arrays(cfg: &Config) -> Vec<&'static str> {
    if ram(cfg) {
        vec!["ram_u", "ram_v"]
    } else if cfg.target.read_ports() == 1 {
        vec!["rom_u", "rom_v"]
    } else {
        vec!["rom"]
    }
}

/// A RAM the host loads (`comp_table = ram`), not a ROM.
fn ram(cfg: &Config) -> bool {
    !cfg.comp_table.is_rom()
}

/// Entries of one array: both buffers of the RAM, {buf, u}.
fn array_entries(cfg: &Config) -> u32 {
    cfg.atan_entries() << ram(cfg) as u32
}

/// Its `$readmemh` file, `<module>.hex`.
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
    /// One ROM copy per read port (a block RAM with one read port).
    copies: bool,
    /// Block-RAM attributes on the one array (true dual-port targets but generic).
    attrs: bool,
    target: &'static str,
    /// The arrays the u and v ports read: [`arrays`].
    rom_u: &'static str,
    rom_v: &'static str,
    pos: u32,
    entries: u32,
    /// The RAM's write port (`comp_table = ram`): map address and data widths, and the
    /// fraction width of a table address.
    ram: bool,
    a: u32,
    m: u32,
    f: u32,
}

crate::tb_template!(Testbench, "atan_rom/atan_rom_tb.v");

impl Unit for AtanRom {
    fn name(&self) -> &'static str {
        "atan_rom"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let mut v = position::ports(cfg);
        if ram(cfg) {
            // After valid_i, u_i, v_i; before the outputs.
            let at = v
                .iter()
                .position(|p| p.name == "valid_o")
                .expect("an output");
            let mut tail = v.split_off(at);
            v.push(i("rd_buf_i", 1, "buffer this sample reads"));
            v.extend(crate::hdl::ports::host_write(cfg));
            v.append(&mut tail);
        }
        v
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
                    array_entries(cfg),
                    cfg.pos_bits(),
                    ram(cfg),
                )
                // u and v: one array read twice, or a copy each.
                .with_reads(2 / arrays(cfg).len() as u32)
            })
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            latency: self.latency(cfg).expect("fixed"),
            out_reg: out_reg(cfg),
            param: file_param(self.name()),
            copies: cfg.target.read_ports() == 1,
            attrs: cfg.target.block_attrs(),
            target: cfg.target.name(),
            rom_u: arrays(cfg)[0],
            rom_v: arrays(cfg).last().expect("at least one array"),
            pos: cfg.pos_bits(),
            entries: cfg.atan_entries(),
            ram: ram(cfg),
            a: cfg.map_addr_bits(),
            m: cfg.map_bits,
            f: cfg.frac_bits,
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

/// With the RAM the vectors carry the buffer a sample reads, after u and v: the testbench
/// loads the second buffer's table first, and every vector is checked against its buffer's.
impl Vectors for AtanRom {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let mut v = position::fields(cfg);
        if ram(cfg) {
            v.insert(2, Field::input("buf", 1));
        }
        v
    }

    /// Every code in both lanes, in each buffer with the RAM.
    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        let c = position::corners(cfg);
        if !ram(cfg) {
            return c;
        }
        (0..2)
            .flat_map(|buf| c.iter().map(move |uv| vec![uv[0], uv[1], buf]))
            .collect()
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        let mut v = position::random(cfg, rng);
        if ram(cfg) {
            v.push(rng.bits(1));
        }
        v
    }

    fn expected(&self, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        if !ram(&model.cfg) {
            return position::expected(model, inp);
        }
        let m = maps.buffer(inp[2]);
        [inp[0], inp[1]]
            .map(|u| model.position_in(m, u as u32) as u64)
            .to_vec()
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        let n = s.trace.norm;
        let mut v = vec![n.u as u64, n.v as u64];
        if ram(cfg) {
            v.push(s.buf);
        }
        v
    }

    /// The buffer field drives rd_buf_i.
    fn port(&self, field: &Field) -> Option<String> {
        Some(match field.name {
            "buf" => "rd_buf_i".to_string(),
            _ => super::unit::port_of(field),
        })
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
