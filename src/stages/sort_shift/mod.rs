//! Sort & shift: the max axis (ties: lowest), the signs, and the three magnitudes shifted by
//! the max's leading zeros and truncated to red_bits.

pub mod model;

use super::testbench::TbData;
use super::unit::{Head, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use crate::vectors::inputs::{dec_grad, gradient_by_shift, gradient_corners, grads};
use askama::Template;

pub struct SortShift;

/// Where sort & shift's registers sit for a `pipeline_depth`: select and shift always take a
/// clock each; the magnitudes are registered before the compare at depth >= 1, the compare
/// results before the select at depth 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    pub mag_reg: bool,
    pub cmp_reg: bool,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        Plan {
            mag_reg: cfg.pipeline_depth >= 1,
            cmp_reg: cfg.pipeline_depth >= 2,
        }
    }

    /// Select and shift, plus the optional magnitude and compare registers.
    pub fn latency(self) -> u32 {
        2 + self.mag_reg as u32 + self.cmp_reg as u32
    }
}

#[derive(Template)]
#[template(path = "sort_shift/sort_shift.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    latency: u32,
    mag_reg: bool,
    cmp_reg: bool,
    g: u32,
    r: u32,
    shw: u32,
    comps: [&'static str; 3],
    /// (bit, leading zeros if it is the highest set bit), highest bit first.
    lz_table: Vec<(u32, u32)>,
    truncates: bool,
}

crate::tb_template!(Testbench, "sort_shift/sort_shift_tb.v");

impl Unit for SortShift {
    fn name(&self) -> &'static str {
        "sort_shift"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (g, r) = (cfg.grad_bits, cfg.red_bits);
        let mut v = stage_head();
        v.push(i("gx_i", g, "G-bit two's complement"));
        v.push(i("gy_i", g, ""));
        v.push(i("gz_i", g, ""));
        v.push(o("valid_o", 1, ""));
        v.push(o("axis_o", 2, "max axis: 0 x, 1 y, 2 z (ties: lowest)"));
        v.push(o("s_max_o", 1, "sign of the max component (1 = negative)"));
        v.push(o("s_u_o", 1, "sign of u"));
        v.push(o("s_v_o", 1, "sign of v"));
        v.push(o("m_o", r, "reduced max magnitude (MSB set unless zero)"));
        v.push(o("a_o", r, "reduced u magnitude"));
        v.push(o("b_o", r, "reduced v magnitude"));
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).latency())
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let g = cfg.grad_bits;
        let plan = Plan::new(cfg);
        Verilog {
            h,
            latency: plan.latency(),
            mag_reg: plan.mag_reg,
            cmp_reg: plan.cmp_reg,
            g,
            r: cfg.red_bits,
            shw: shift_bits(cfg),
            comps: ["x", "y", "z"],
            lz_table: (0..g).rev().map(|bit| (bit, g - 1 - bit)).collect(),
            truncates: cfg.grad_bits > cfg.red_bits,
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

/// The module's outputs for the model's result, in the order of the output fields
/// ([`Vectors::fields`]); `rmapgen prove` packs them without allocating (src/prove/front.rs).
/// Width of the left-shift count, which runs 0..grad_bits-1.
pub fn shift_bits(cfg: &Config) -> u32 {
    crate::config::bit_length(cfg.grad_bits as u64 - 1)
}

#[inline]
pub fn outputs(s: &model::SortShift) -> [u64; 7] {
    [s.axis, s.s_max, s.s_u, s.s_v, s.m, s.a, s.b].map(u64::from)
}

impl Vectors for SortShift {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let (g, r) = (cfg.grad_bits, cfg.red_bits);
        vec![
            Field::input("gx", g),
            Field::input("gy", g),
            Field::input("gz", g),
            Field::output("axis", 2),
            Field::output("s_max", 1),
            Field::output("s_u", 1),
            Field::output("s_v", 1),
            Field::output("m", r),
            Field::output("a", r),
            Field::output("b", r),
        ]
    }

    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        gradient_corners(cfg)
            .into_iter()
            .map(|g| grads(cfg, g))
            .collect()
    }

    /// The max's leading zeros drawn uniformly, so every shift amount is well covered.
    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        grads(cfg, gradient_by_shift(cfg, rng, cfg.grad_bits))
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let g = |k: usize| dec_grad(&model.cfg, inp[k]);
        outputs(&model::eval(&model.cfg, [g(0), g(1), g(2)])).to_vec()
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        grads(cfg, s.g)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
