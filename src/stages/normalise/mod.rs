//! Normalise: u = a / m and v = b / m as F-bit fractions, computed as a * (1/m) with the
//! reciprocal ROM and two multipliers (adder trees of partial products), rounded half up and
//! saturated.

pub mod model;
mod plan;

use super::recip_rom::{self, RecipRom};
use super::testbench::TbData;
use super::unit::{param_overrides, Head, Memory, Traced, Unit, Vectors};
use crate::config::Config;
use crate::hdl::adder_tree::Step;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::{MapSet, Model};
use crate::rng::SplitMix64;
use crate::vectors::field::Field;
use askama::Template;
pub use plan::Plan;

pub struct Normalise;

/// The instance name of the reciprocal ROM in normalise.v.
const ROM_INSTANCE: &str = "u_recip_rom";

#[derive(Template)]
#[template(path = "normalise/normalise.v", syntax = "verilog")]
struct Verilog {
    h: Head,
    /// The reciprocal ROM's module.
    rom: String,
    /// Its init-file parameter, passed down to the ROM.
    rom_params: String,
    /// The ROM is shared in rmap_lanes: read through the recip_* ports.
    outside: bool,
    /// `mult = infer`: the comments describe plain products, not adder trees.
    infer: bool,
    depth: u32,
    latency: u32,
    r: u32,
    w: u32,
    f: u32,
    ra: u32,
    sh: u32,
    sw: u32,
    rom_reg: bool,
    tree_q: String,
    steps: Vec<Step>,
    sum_a: String,
    sum_b: String,
    a_max: String,
    b_max: String,
}

crate::tb_template!(Testbench, "normalise/normalise_tb.v");

impl Unit for Normalise {
    fn name(&self) -> &'static str {
        "normalise"
    }

    fn ports(&self, cfg: &Config) -> Vec<Port> {
        let (r, f) = (cfg.red_bits, cfg.frac_bits);
        let mut v = stage_head();
        v.push(i("m_i", r, "reduced max"));
        v.push(i("a_i", r, ""));
        v.push(i("b_i", r, ""));
        v.push(o("valid_o", 1, ""));
        v.push(o("u_o", f, "a / m, all ones for a == m"));
        v.push(o("v_o", f, "b / m"));
        v.extend(recip_rom::reader_ports(cfg));
        v
    }

    fn latency(&self, cfg: &Config) -> Option<u32> {
        Some(Plan::new(cfg).latency)
    }

    /// The ROM, unless it is shared in rmap_lanes (then read through [`recip_rom::READER`]).
    fn children(&self, cfg: &Config) -> Vec<&'static dyn Unit> {
        if recip_rom::dual(cfg) {
            vec![]
        } else {
            vec![&RecipRom]
        }
    }

    fn memories(&self, cfg: &Config) -> Vec<Memory> {
        if recip_rom::dual(cfg) {
            return vec![];
        }
        RecipRom
            .memories(cfg)
            .into_iter()
            .map(|m| m.under(ROM_INSTANCE))
            .collect()
    }

    fn render(&self, cfg: &Config, h: Head) -> askama::Result<String> {
        let p = Plan::new(cfg);
        let sw = p.sum_a.width();
        Verilog {
            h,
            rom: RecipRom.module(cfg),
            rom_params: param_overrides(cfg, &RecipRom),
            outside: recip_rom::dual(cfg),
            infer: !cfg.mult.is_tree(),
            depth: cfg.pipeline_depth,
            latency: p.latency,
            r: cfg.red_bits,
            w: cfg.recip_bits,
            f: cfg.frac_bits,
            ra: cfg.recip_addr_bits(),
            sh: model::norm_shift(cfg),
            sw,
            rom_reg: p.rom_reg,
            tree_q: p.tree_q.clone(),
            sum_a: p.sum_a.expr(sw),
            sum_b: p.sum_b.expr(sw),
            a_max: p.a_max.name,
            b_max: p.b_max.name,
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

impl Vectors for Normalise {
    fn fields(&self, cfg: &Config) -> Vec<Field> {
        let (r, f) = (cfg.red_bits, cfg.frac_bits);
        vec![
            Field::input("m", r),
            Field::input("a", r),
            Field::input("b", r),
            Field::output("u", f),
            Field::output("v", f),
        ]
    }

    fn corners(&self, model: &Model, maps: &MapSet) -> Vec<Vec<u64>> {
        let cfg = &model.cfg;
        let r = cfg.red_bits;
        let (lo, hi) = (1u64 << (r - 1), (1u64 << r) - 1);
        // The zero vector reaches normalise as m = a = b = 0.
        let mut out = vec![vec![0, 0, 0]];
        // Both ends of the reciprocal ROM, with a and b at 0, 1, half, max - 1 and max.
        for m in [lo, lo + 1, hi - 1, hi] {
            let cs = [0, 1, m / 2, m - 1, m];
            for (i, &a) in cs.iter().enumerate() {
                for &b in &cs[i..] {
                    out.push(vec![m, a, b]);
                    if a != b {
                        out.push(vec![m, b, a]);
                    }
                }
            }
        }
        // Every reciprocal-ROM entry once, with a = m - 1 (rounds nearest to 1.0).
        for m in lo..=hi {
            out.push(vec![m, m - 1, m * 3 / 4]);
        }
        for t in crate::vectors::inputs::corner_traces(model, &maps.scene) {
            out.push(self.traced(cfg, &t));
        }
        out
    }

    /// m over the ROM's range (and now and then the zero vector), a and b in 0..=m with
    /// extra weight on 0 and m.
    fn random(&self, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
        let r = cfg.red_bits;
        if rng.chance(1, 64) {
            return vec![0, 0, 0];
        }
        let m = rng.range(1 << (r - 1), (1 << r) - 1);
        let lane = |rng: &mut SplitMix64| match rng.below(16) {
            0 | 1 => m,
            2 => 0,
            _ => rng.range(0, m),
        };
        let a = lane(rng);
        let b = lane(rng);
        vec![m, a, b]
    }

    fn expected(&self, model: &Model, _maps: &MapSet, inp: &[u64]) -> Vec<u64> {
        let u = |k: usize| inp[k] as u32;
        let n = model::eval(&model.cfg, &model.recip, u(0), u(1), u(2));
        vec![n.u as u64, n.v as u64]
    }

    fn traced(&self, _cfg: &Config, s: &Traced) -> Vec<u64> {
        let t = s.trace.sort;
        [t.m, t.a, t.b].map(u64::from).to_vec()
    }

    fn testbench(&self, t: &TbData) -> askama::Result<String> {
        Testbench { t }.render()
    }
}
