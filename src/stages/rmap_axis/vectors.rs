//! The AXI4-Stream top's vectors are the top's own (`vectors/<rmap_top>.hex`, the model's
//! results with the map swap): the wrapper adds nothing to the datapath, so its testbench
//! sends each vector as one beat, its input fields packed into `s_axis_tdata` at their
//! [`Packing`] slots, and compares every beat on `m_axis` with the expected fields at theirs,
//! the padding 0, and with the tuser and tlast it gave the sample.

use super::{packing, Packing, RmapAxis};
use crate::config::Config;
use crate::hdl::ports::Width;
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::stages::rmap_top::RmapTop;
use crate::stages::testbench::TbData;
use crate::stages::unit::{Traced, Unit, Vectors};
use crate::vectors::field::{self, Field};
use anyhow::Result;
use askama::Template;

/// One field of the testbench's rings in a `tdata` bus: the ring `v_<field>`, and the bus's
/// `[hi:lo]` that carries it.
pub struct TbSlot {
    pub field: &'static str,
    pub range: String,
}

#[derive(Template)]
#[template(path = "rmap_axis/rmap_axis_tb.v", syntax = "verilog")]
struct Testbench<'a> {
    t: &'a TbData,
    s_bits: u32,
    m_bits: u32,
    /// Width of tuser (0: no tuser ports).
    user_bits: u32,
    /// The input fields' slots in `s_axis_tdata`, the output fields' in `m_axis_tdata`.
    s_slots: Vec<TbSlot>,
    m_slots: Vec<TbSlot>,
    /// The input fields, `map` included (the mismatch line prints them).
    in_all: Vec<&'static str>,
    /// `{m_axis_tvalid, m_axis_tdata, m_axis_tuser, m_axis_tlast}`'s width: what must hold
    /// under backpressure.
    held_bits: u32,
    /// `(hi, lo)` pieces of `s_axis_tdata` and of tuser, each filled by one `$random`.
    s_fill: Vec<(u32, u32)>,
    user_fill: Vec<(u32, u32)>,
    /// The host write port's address and data inputs with their widths: random while
    /// `wr_en_i` is low.
    host_data: Vec<(&'static str, u32)>,
}

/// The host write port's inputs besides its enable, which the testbench drives with random
/// values between writes.
const HOST_DATA: [&str; 3] = ["wr_axis_i", "wr_addr_i", "wr_data_i"];

/// The `(hi, lo)` pieces of a `bits`-wide bus, 32 bits at most each (one `$random`), from bit 0.
fn pieces(bits: u32) -> Vec<(u32, u32)> {
    (0..bits)
        .step_by(32)
        .map(|lo| ((lo + 31).min(bits - 1), lo))
        .collect()
}

fn slots(p: &Packing) -> Vec<TbSlot> {
    p.slots
        .iter()
        .map(|s| TbSlot {
            field: s.field,
            range: s.range(),
        })
        .collect()
}

impl Vectors for RmapAxis {
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

    /// The top's vector file: the wrapper carries the same samples.
    fn vector_file(&self, cfg: &Config) -> String {
        RmapTop.vector_file(cfg)
    }

    /// The fields name rmap_top's ports; the wrapper carries them in `tdata`.
    fn inner(&self) -> Option<&'static dyn Vectors> {
        Some(&RmapTop)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        let cfg = &t.cfg;
        let (s, m) = (packing(cfg, field::Dir::In), packing(cfg, field::Dir::Out));
        let user_bits = cfg.axis_user;
        let in_all = self
            .fields(cfg)
            .iter()
            .filter(|f| f.dir == field::Dir::In)
            .map(|f| f.name)
            .collect();
        Testbench {
            t,
            s_bits: s.bits,
            m_bits: m.bits,
            user_bits,
            s_slots: slots(&s),
            m_slots: slots(&m),
            in_all,
            held_bits: 1 + m.bits + user_bits + 1,
            s_fill: pieces(s.bits),
            user_fill: pieces(user_bits),
            host_data: self
                .ports(cfg)
                .into_iter()
                .filter(|p| HOST_DATA.contains(&p.name))
                .map(|p| match p.width {
                    Width::Bits(b) => (p.name, b),
                    Width::Param(_) => unreachable!("the wrapper's ports have fixed widths"),
                })
                .collect(),
        }
        .render()
    }
}
