//! The bus top's vectors are the top's own (`vectors/<rmap_top>.hex`, the model's results
//! with the map swap): the slave adds nothing to the datapath, so its testbench streams the
//! same samples, and does everything a host does over the bus: the register checks
//! ([`checks`]: every register of [`regmap`] against the configuration, the refusals), the
//! second map's load through the windows, and the swap through CONTROL and STATUS.

use super::RmapBus;
use crate::config::{Bus, Config};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::stages::rmap_regs::regmap::{regmap, Access, Source};
use crate::stages::rmap_top::RmapTop;
use crate::stages::testbench::TbData;
use crate::stages::unit::{Traced, Vectors};
use crate::vectors::field::Field;
use anyhow::Result;
use askama::Template;

/// One access of the register checks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Check {
    pub we: bool,
    /// Word address.
    pub word: u32,
    pub data: u32,
    pub be: u32,
    /// It must be refused (an error response).
    pub err: bool,
    /// A read's data under `mask`.
    pub expect: u32,
    pub mask: u32,
    pub what: String,
}

/// The register checks of a design's testbench, in order, from the register map: every
/// readable register's constant fields and its status fields' values out of reset, the
/// write-only register reading 0; then the refusals, each counted; ERRORS' count; its clear.
pub fn checks(cfg: &Config) -> Vec<Check> {
    let m = regmap(cfg);
    let read = |word: u32, expect: u32, mask: u32, what: String| Check {
        we: false,
        word,
        data: 0,
        be: 0xf,
        err: false,
        expect,
        mask,
        what,
    };
    let refuse = |we: bool, word: u32, be: u32, what: &str| Check {
        we,
        word,
        data: 0xffff_ffff,
        be,
        err: true,
        expect: 0,
        mask: 0,
        what: what.to_string(),
    };
    let mut v = Vec::new();
    for r in &m.regs {
        match r.access {
            Access::Ro => {
                let mask = r.fields.iter().fold(0, |a, f| a | f.mask());
                // Out of reset every status register holds 0.
                let expect = r
                    .fields
                    .iter()
                    .fold(0u32, |a, f| a | (f.value().unwrap_or(0) << f.lsb) as u32);
                let consts = r
                    .fields
                    .iter()
                    .all(|f| matches!(f.source, Source::Const(_)));
                v.push(read(
                    r.word(),
                    expect,
                    mask | if consts { !mask } else { 0 },
                    format!("{} reads as the configuration's", r.name),
                ));
            }
            Access::Wo => v.push(read(
                r.word(),
                0,
                0xffff_ffff,
                format!("{} reads 0", r.name),
            )),
        }
    }
    let used: Vec<u32> = m.regs.iter().map(|r| r.word()).collect();
    let hole = (0..m.window_base / 4)
        .rev()
        .find(|w| !used.contains(w))
        .expect("a word no register has");
    let window = m.window_base / 4;
    let control = m.reg("CONTROL");
    let mut refusals = vec![
        refuse(
            true,
            m.reg("ID").word(),
            0xf,
            "a write to a read-only register",
        ),
        refuse(false, hole, 0xf, "a read of an address no register has"),
        refuse(true, hole, 0xf, "a write to an address no register has"),
        refuse(false, window, 0xf, "a read of a window"),
        refuse(true, control.word(), 0x1, "a partial write"),
    ];
    let slot3 = window + 3 * (m.axis_stride / 4);
    match m.windows.iter().find(|w| w.axis == 3) {
        None => refusals.push(refuse(
            true,
            slot3,
            0xf,
            "a write to the table window of a design without a loaded table",
        )),
        Some(t) if t.entries < m.axis_stride / 4 => refusals.push(refuse(
            true,
            slot3 + t.entries,
            0xf,
            "a write past the table",
        )),
        Some(_) => {}
    }
    let n = refusals.len() as u32;
    v.extend(refusals);
    let errors = m.reg("ERRORS");
    let count = errors.fields[0].mask();
    v.push(read(
        errors.word(),
        n,
        count,
        format!("ERRORS counts the {n} refusals"),
    ));
    let clear = control
        .fields
        .iter()
        .find(|f| f.name == "CLEAR_ERRORS")
        .expect("CONTROL.CLEAR_ERRORS");
    v.push(Check {
        we: true,
        word: control.word(),
        data: clear.mask(),
        be: 0xf,
        err: false,
        expect: 0,
        mask: 0,
        what: "CONTROL.CLEAR_ERRORS".into(),
    });
    v.push(read(errors.word(), 0, count, "ERRORS cleared".into()));
    v
}

#[derive(Template)]
#[template(path = "rmap_bus/rmap_bus_tb.v", syntax = "verilog")]
struct Testbench<'a> {
    t: &'a TbData,
    inner: String,
    wishbone: bool,
    table: bool,
    w: u32,
    window_word: u32,
    status_word: u32,
    frames_word: u32,
    control_word: u32,
    swap_mask: u32,
    pending_mask: u32,
    checks: Vec<Check>,
}

impl Vectors for RmapBus {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        RmapTop.fields(cfg)
    }

    fn corners(&self, model: &Model, maps: &MapSet) -> Vec<Vec<u64>> {
        RmapTop.corners(model, maps)
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        RmapTop.random(cfg, rng)
    }

    fn expected(&self, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        RmapTop.expected(model, maps, inp)
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        RmapTop.traced(cfg, s)
    }

    /// The top's stream, vector for vector (the same file).
    fn inputs(
        &self,
        model: &Model,
        maps: &MapSet,
        random: usize,
        seed: u64,
        emit: &mut dyn FnMut(&[u64]) -> Result<()>,
    ) -> Result<()> {
        RmapTop.inputs(model, maps, random, seed, emit)
    }

    fn port(&self, field: &Field) -> Option<String> {
        RmapTop.port(field)
    }

    fn reset_at(&self, cfg: &Config) -> u32 {
        RmapTop.reset_at(cfg)
    }

    /// The top's vector file: the bus top carries the same samples.
    fn vector_file(&self, cfg: &Config) -> String {
        RmapTop.vector_file(cfg)
    }

    /// The fields name rmap_top's ports, which the bus top has under the same names.
    fn inner(&self) -> Option<&'static dyn Vectors> {
        Some(&RmapTop)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        let cfg = &t.cfg;
        let m = regmap(cfg);
        let field_mask = |reg: &str, field: &str| {
            m.reg(reg)
                .fields
                .iter()
                .find(|f| f.name == field)
                .expect("a field of the map")
                .mask()
        };
        Testbench {
            t,
            inner: super::super::sample_top(cfg).module(cfg),
            wishbone: cfg.bus == Bus::Wishbone,
            table: m.windows.iter().any(|w| w.axis == 3),
            w: m.word_bits(),
            window_word: m.window_base / 4,
            status_word: m.reg("STATUS").word(),
            frames_word: m.reg("FRAMES").word(),
            control_word: m.reg("CONTROL").word(),
            swap_mask: field_mask("CONTROL", "SWAP"),
            pending_mask: field_mask("STATUS", "SWAP_PENDING"),
            checks: checks(cfg),
        }
        .render()
    }
}
