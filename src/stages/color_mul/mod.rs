//! Colour multiply: each 8-bit sample colour channel times the intensity, divided by the
//! largest intensity, rounded: ((2 c i + D) * K) >> S with (K, S) from
//! [`model::constants`].

pub mod model;
mod plan;

use super::testbench::TbData;
use super::unit::{Head, Traced, Unit, Vectors};
use crate::config::{Config, COLOR_BITS};
use crate::hdl::adder_tree::Step;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use crate::vectors::inputs::{color_channel, COLOR_CORNERS};
use askama::Template;
pub use plan::Plan;

pub struct ColorMul;

#[derive(Template)]
#[template(path = "color_mul/color_mul.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// `mult = infer`: the comments describe plain products, not adder trees.
    infer: bool,
    depth: u32,
    latency: u32,
    s: u32,
    pw: u32,
    d: u32,
    k: u64,
    steps: Vec<Step>,
    pr: String,
    pg: String,
    pb: String,
}

crate::tb_template!(Testbench, "color_mul/color_mul_tb.v");

impl Unit for ColorMul {
    fn name(&self) -> &'static str {
        "color_mul"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let mut v = stage_head();
        v.push(i("i_i", cfg.map_bits, "intensity"));
        v.push(i("r_i", COLOR_BITS, ""));
        v.push(i("g_i", COLOR_BITS, ""));
        v.push(i("b_i", COLOR_BITS, ""));
        v.push(o("valid_o", 1, ""));
        v.push(o("r_o", COLOR_BITS, "round(r * i / (2^M - 1))"));
        v.push(o("g_o", COLOR_BITS, ""));
        v.push(o("b_o", COLOR_BITS, ""));
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).latency)
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let (k, s) = model::constants(cfg);
        let p = Plan::new(cfg);
        let pw = model::product_bits(cfg);
        Verilog {
            h,
            infer: !cfg.mult.is_tree(),
            depth: cfg.pipeline_depth,
            latency: p.latency,
            s,
            pw,
            d: cfg.map_max(),
            k,
            pr: p.products[0].expr(pw),
            pg: p.products[1].expr(pw),
            pb: p.products[2].expr(pw),
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

impl Vectors for ColorMul {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let c = COLOR_BITS;
        vec![
            Field::input("i", cfg.map_bits),
            Field::input("r", c),
            Field::input("g", c),
            Field::input("b", c),
            Field::output("r_o", c),
            Field::output("g_o", c),
            Field::output("b_o", c),
        ]
    }

    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        let mx = model.cfg.map_max() as u64;
        let mut out = Vec::new();
        for i in [0, 1, mx / 2, mx - 1, mx] {
            for c in COLOR_CORNERS {
                out.push(vec![i, c[0] as u64, c[1] as u64, c[2] as u64]);
            }
        }
        // Every intensity once, with a full, a middle and a minimal channel.
        for i in 0..=mx {
            out.push(vec![i, 255, 128, 1]);
        }
        out
    }

    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        let mx = cfg.map_max() as u64;
        let i = match rng.below(16) {
            0 => 0,
            1 => mx,
            _ => rng.range(0, mx),
        };
        vec![
            i,
            color_channel(rng),
            color_channel(rng),
            color_channel(rng),
        ]
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let u = |k: usize| inp[k] as u32;
        model::eval(&model.cfg, [u(1), u(2), u(3)], u(0))
            .map(u64::from)
            .to_vec()
    }

    fn traced(&self, _cfg: &Config, s: &Traced) -> Vec<u64> {
        let c = s.rgb;
        [s.trace.out.intensity, c[0], c[1], c[2]]
            .map(u64::from)
            .to_vec()
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
