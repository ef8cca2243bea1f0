//! Interpolate: the bilinear blend of the four neighbours with the weights (wu, wv), rounded
//! half up, as two passes of adder trees of weight-gated partial products.

pub mod model;
mod plan;

use super::testbench::TbData;
use super::unit::{Head, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::adder_tree::Step;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use crate::vectors::inputs::corner_traces;
use askama::Template;
pub use plan::Plan;

pub struct Interpolate;

#[derive(Template)]
#[template(path = "interpolate/interpolate.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// `mult = infer`: the comments describe plain products, not adder trees.
    infer: bool,
    depth: u32,
    latency: u32,
    m: u32,
    p: u32,
    s: u32,
    rw: u32,
    in_reg: bool,
    in_q: String,
    steps: Vec<Step>,
    sum_r: String,
}

crate::tb_template!(Testbench, "interpolate/interpolate_tb.v");

/// Width of the second pass r (before rounding), 0..=map_max * step^2, plus half.
pub fn r_bits(cfg: &Config) -> u32 {
    cfg.map_bits + 2 * cfg.interp_bits
}

impl Unit for Interpolate {
    fn name(&self) -> &'static str {
        "interpolate"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (mb, w) = (cfg.map_bits, cfg.weight_bits());
        let mut v = stage_head();
        v.push(i("e00_i", mb, ""));
        v.push(i("e10_i", mb, ""));
        v.push(i("e01_i", mb, ""));
        v.push(i("e11_i", mb, ""));
        v.push(i("wu_i", w, "0..S"));
        v.push(i("wv_i", w, "0..S"));
        v.push(o("valid_o", 1, ""));
        v.push(o("i_o", mb, "bilinear intensity, rounded half up"));
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).latency)
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let p = Plan::new(cfg);
        Verilog {
            h,
            infer: !cfg.mult.is_tree(),
            depth: cfg.pipeline_depth,
            latency: p.latency,
            m: cfg.map_bits,
            p: cfg.interp_bits,
            s: cfg.step(),
            rw: r_bits(cfg),
            in_reg: p.in_reg,
            in_q: p.in_q.clone(),
            sum_r: p.sum_r.expr(r_bits(cfg)),
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

impl Vectors for Interpolate {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let (m, w) = (cfg.map_bits, cfg.weight_bits());
        vec![
            Field::input("e00", m),
            Field::input("e10", m),
            Field::input("e01", m),
            Field::input("e11", m),
            Field::input("wu", w),
            Field::input("wv", w),
            Field::output("i", m),
        ]
    }

    /// Ten entry patterns (flat, each edge and diagonal at the extremes, small and middle
    /// values) at every pair of the weights 0, 1, S/2, S - 1 and S, then the gradient
    /// corners' look-ups.
    fn corners(&self, model: &Model, maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        let s = cfg.step() as u64;
        let mx = cfg.map_max() as u64;
        let mut ws = vec![0, 1, s / 2, s - 1, s];
        ws.sort_unstable();
        ws.dedup();
        let patterns: [[u64; 4]; 10] = [
            [0, 0, 0, 0],
            [mx, mx, mx, mx],
            [0, mx, 0, mx],
            [mx, 0, mx, 0],
            [0, 0, mx, mx],
            [mx, mx, 0, 0],
            [0, mx, mx, 0],
            [mx, 0, 0, mx],
            [1, 2, 3, 4],
            [mx / 2, mx / 2 + 1, mx / 2 - 1, mx / 3],
        ];
        let mut out = Vec::new();
        for e in patterns {
            for &wu in &ws {
                for &wv in &ws {
                    out.push(vec![e[0], e[1], e[2], e[3], wu, wv]);
                }
            }
        }
        for t in corner_traces(model, &maps.scene) {
            out.push(self.traced(cfg, &t));
        }
        out
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        let s = cfg.step() as u64;
        let mut v: Vec<u64> = (0..4).map(|_| rng.bits(cfg.map_bits)).collect();
        v.push(rng.range(0, s));
        v.push(rng.range(0, s));
        v
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let u = |k: usize| inp[k] as u32;
        vec![model::eval(&model.cfg, [u(0), u(1), u(2), u(3)], u(4), u(5)) as u64]
    }

    fn traced(&self, _cfg: &Config, s: &Traced) -> Vec<u64> {
        let l = s.trace.lookup;
        [l.e[0], l.e[1], l.e[2], l.e[3], l.w_u, l.w_v]
            .map(u64::from)
            .to_vec()
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
