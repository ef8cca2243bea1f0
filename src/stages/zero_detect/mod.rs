//! Zero detect: flags a gradient whose three components are all zero (it has no direction).
//! It runs beside sort & shift; the top forces such a sample's intensity and colour to zero.

pub mod model;

use super::testbench::TbData;
use super::unit::{Head, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use crate::vectors::inputs::{dec_grad, gradient_corners, grads};
use askama::Template;

pub struct ZeroDetect;

#[derive(Template)]
#[template(path = "zero_detect/zero_detect.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    g: u32,
}

crate::tb_template!(Testbench, "zero_detect/zero_detect_tb.v");

impl Unit for ZeroDetect {
    fn name(&self) -> &'static str {
        "zero_detect"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let g = cfg.grad_bits;
        let mut v = stage_head();
        v.push(i("gx_i", g, "G-bit two's complement"));
        v.push(i("gy_i", g, ""));
        v.push(i("gz_i", g, ""));
        v.push(o("valid_o", 1, ""));
        v.push(o("zero_o", 1, "all three components are zero"));
        v
    }

    /// One register: the compare.
    fn latency(&self, _cfg: &Config) -> Option<u32> {
        Some(1)
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog {
            h,
            g: cfg.grad_bits,
        }
        .render()
    }

    fn vectors(&self) -> Option<&dyn Vectors> {
        Some(self)
    }
}

impl Vectors for ZeroDetect {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let g = cfg.grad_bits;
        vec![
            Field::input("gx", g),
            Field::input("gy", g),
            Field::input("gz", g),
            Field::output("zero", 1),
        ]
    }

    /// Zero, each component alone at 1, -1 and both ends of its range, then the gradient
    /// corners.
    fn corners(&self, model: &Model, _maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        let h = 1i32 << (cfg.grad_bits - 1);
        let mut out = vec![grads(cfg, [0, 0, 0])];
        for p in 0..3 {
            for c in [1, -1, -h, h - 1] {
                let mut g = [0; 3];
                g[p] = c;
                out.push(grads(cfg, g));
            }
        }
        for g in gradient_corners(cfg) {
            out.push(grads(cfg, g));
        }
        out
    }

    /// Each component zero half the time, so all-zero gradients are common.
    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        (0..3)
            .map(|_| {
                if rng.chance(1, 2) {
                    0
                } else {
                    rng.bits(cfg.grad_bits)
                }
            })
            .collect()
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let g = |k: usize| dec_grad(&model.cfg, inp[k]);
        vec![model::eval([g(0), g(1), g(2)]) as u64]
    }

    fn traced(&self, cfg: &Config, s: &Traced) -> Vec<u64> {
        grads(cfg, s.g)
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
