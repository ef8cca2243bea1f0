//! The position stage's interface, which its two implementations share: `atan_rom` (with
//! distortion compensation) and `linear_index` (without) both map the fractions u, v to map
//! positions 0..POS_MAX, so they have the same ports and the same vectors; only their
//! arithmetic and register plans differ.

use crate::config::Config;
use crate::hdl::ports::{i, o, stage_head, Port};
use crate::model::Model;
use crate::rng::SplitMix64;
use crate::vectors::field::Field;

pub fn ports(cfg: &Config) -> Vec<Port> {
    let (f, pos) = (cfg.frac_bits, cfg.pos_bits());
    let mut v = stage_head();
    v.push(i("u_i", f, "normalised fraction"));
    v.push(i("v_i", f, ""));
    v.push(o("valid_o", 1, ""));
    v.push(o("pu_o", pos, "map position, 0..POS_MAX"));
    v.push(o("pv_o", pos, ""));
    v
}

pub fn fields(cfg: &Config) -> Vec<Field> {
    let (f, pos) = (cfg.frac_bits, cfg.pos_bits());
    vec![
        Field::input("u", f),
        Field::input("v", f),
        Field::output("pu", pos),
        Field::output("pv", pos),
    ]
}

/// Exhaustive: every fraction code in both lanes, which covers 0, all ones and every point
/// where the position steps.
pub fn corners(cfg: &Config) -> Vec<Vec<u64>> {
    let fmax = cfg.frac_max() as u64;
    (0..=fmax).map(|u| vec![u, fmax - u]).collect()
}

pub fn random(cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
    vec![rng.bits(cfg.frac_bits), rng.bits(cfg.frac_bits)]
}

/// The model's position stage, whichever the configuration has.
pub fn expected(model: &Model, inp: &[u64]) -> Vec<u64> {
    vec![
        model.position(inp[0] as u32) as u64,
        model.position(inp[1] as u32) as u64,
    ]
}
