//! Linear index: the position stage without distortion compensation,
//! p = round(u * POS_MAX / 2^F), the all-ones fraction going to POS_MAX.

pub mod model;
mod plan;

use super::position;
use super::testbench::TbData;
use super::unit::{Head, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::adder_tree::Step;
use crate::hdl::ports::Port;
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use askama::Template;
pub use plan::Plan;

pub struct LinearIndex;

#[derive(Template)]
#[template(path = "linear_index/linear_index.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// `mult = infer`: the comments describe plain products, not adder trees.
    infer: bool,
    depth: u32,
    latency: u32,
    f: u32,
    pos: u32,
    lw: u32,
    pre_reg: bool,
    in_q: String,
    steps: Vec<Step>,
    sum_u: String,
    sum_v: String,
}

crate::tb_template!(Testbench, "linear_index/linear_index_tb.v");

impl Unit for LinearIndex {
    fn name(&self) -> &'static str {
        "linear_index"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        position::ports(cfg)
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).latency)
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let p = Plan::new(cfg);
        let lw = p.sum_u.width();
        Verilog {
            h,
            infer: !cfg.mult.is_tree(),
            depth: cfg.pipeline_depth,
            latency: p.latency,
            f: cfg.frac_bits,
            pos: cfg.pos_bits(),
            lw,
            pre_reg: p.pre_reg,
            in_q: p.in_q.clone(),
            sum_u: p.sum_u.expr(lw),
            sum_v: p.sum_v.expr(lw),
            steps: p.steps,
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }

    fn trees(&self, cfg: &Config) -> Vec<crate::hdl::tree_spec::TreeSpec> {
        Plan::new(cfg).specs
    }
}

impl Vectors for LinearIndex {
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

    fn traced(&self, _cfg: &Config, s: &Traced) -> Vec<u64> {
        let n = s.trace.norm;
        vec![n.u as u64, n.v as u64]
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
