//! The configurations `rmapgen fit` chooses from, and their order by cost.
//!
//! The interface of the design is fixed by the caller: gradient width (what the source
//! delivers), map width (the output intensity's width: the error target is in its LSBs),
//! colour multiply (on exactly when the scene has a colour: without the multiplier the design
//! has no colour output), pipeline depth and handshake. Every other field runs over its whole
//! range ([`crate::config::RANGES`]) and every valid combination is a candidate: reduced
//! width, fraction width, reciprocal width, index bits, interpolation fraction bits (0 is
//! interpolation off) and distortion compensation on or off.

use crate::config::{Config, RANGES};
use serde::Serialize;

/// What a candidate costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum CostKind {
    /// ROM and map bits: `Config::rom_total_bits` + `Config::map_total_bits`.
    Bits,
    /// Cells of Yosys synthesis of the generated design.
    Cells,
}

fn range(field: &str) -> (u32, u32) {
    let &(_, lo, hi) = RANGES
        .iter()
        .find(|r| r.0 == field)
        .unwrap_or_else(|| panic!("no range for {field}"));
    (lo, hi)
}

/// Every valid configuration with `base`'s interface fields (grad_bits, map_bits, color,
/// pipeline_depth, handshake, lanes), in no particular order.
pub fn candidates(base: &Config) -> Vec<Config> {
    let (r0, r1) = range("red_bits");
    let (f0, f1) = range("frac_bits");
    let (w0, w1) = range("recip_bits");
    let (i0, i1) = range("index_bits");
    let (p0, p1) = range("interp_bits");
    let mut v = Vec::new();
    for red_bits in r0..=r1 {
        for frac_bits in f0..=f1 {
            for recip_bits in w0..=w1 {
                for index_bits in i0..=i1 {
                    for interp_bits in p0..=p1 {
                        for compensation in [false, true] {
                            let c = Config {
                                red_bits,
                                frac_bits,
                                recip_bits,
                                index_bits,
                                interp_bits,
                                interpolation: interp_bits > 0,
                                compensation,
                                ..base.clone()
                            };
                            if c.validate().is_ok() {
                                v.push(c);
                            }
                        }
                    }
                }
            }
        }
    }
    v
}

/// ROM and map bits: the default cost.
pub fn bits(cfg: &Config) -> u64 {
    cfg.rom_total_bits() + cfg.map_total_bits()
}

/// Optional stages present (compensation, interpolation, colour multiply): fewer is cheaper
/// at equal cost.
pub fn stages(cfg: &Config) -> u32 {
    cfg.compensation as u32 + cfg.interpolation as u32 + cfg.color as u32
}

/// The total order of candidates by cost: `cost` first, then fewer optional stages, then
/// fewer datapath bits (red + frac + recip + index + interp), then the fields themselves, so
/// equal costs are ordered the same way on every run.
pub fn order_key(cfg: &Config, cost: u64) -> (u64, u32, u32, [u32; 6]) {
    (
        cost,
        stages(cfg),
        cfg.red_bits + cfg.frac_bits + cfg.recip_bits + cfg.index_bits + cfg.interp_bits,
        [
            cfg.index_bits,
            cfg.interp_bits,
            cfg.red_bits,
            cfg.frac_bits,
            cfg.recip_bits,
            cfg.compensation as u32,
        ],
    )
}

/// [`candidates`] sorted by ROM + map bits ([`order_key`]).
pub fn by_bits(base: &Config) -> Vec<Config> {
    let mut v = candidates(base);
    v.sort_by_cached_key(|c| order_key(c, bits(c)));
    v
}

/// Whether `a` needs no more than `b` in every width and every optional stage (so `a` is
/// no larger a circuit than `b`).
pub fn no_larger(a: &Config, b: &Config) -> bool {
    a.red_bits <= b.red_bits
        && a.frac_bits <= b.frac_bits
        && a.recip_bits <= b.recip_bits
        && a.index_bits <= b.index_bits
        && a.interp_bits <= b.interp_bits
        && a.compensation <= b.compensation
        && a.interpolation <= b.interpolation
}

/// The paper's design with `base`'s interface fields: what `fit` compares its choice with.
/// Its compensation table is held as the candidates hold theirs (a RAM under `--map-fit
/// table`, whose table is then fitted like theirs), so it is one of them.
pub fn paper(base: &Config) -> Config {
    Config {
        comp_table: base.comp_table,
        grad_bits: base.grad_bits,
        map_bits: base.map_bits,
        color: base.color,
        pipeline_depth: base.pipeline_depth,
        handshake: base.handshake,
        lanes: base.lanes,
        ..Config::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_space_is_every_valid_combination() {
        let base = Config::default();
        let v = candidates(&base);
        // red 6..=12, frac 4..=12 with recip frac+1..=20, index 2..=6, interp 0..=5,
        // compensation on and off.
        let recips: u32 = (4..=12).map(|f| 20 - f).sum();
        assert_eq!(v.len() as u32, 7 * recips * 5 * 6 * 2);
        assert!(v.contains(&base));
        assert!(v.iter().all(|c| c.validate().is_ok()
            && c.grad_bits == 12
            && c.map_bits == 8
            && !c.color
            && c.interpolation == (c.interp_bits > 0)));
        // A narrow gradient limits the reduced width.
        let g8 = Config {
            grad_bits: 8,
            ..base.clone()
        };
        assert!(candidates(&g8).iter().all(|c| c.red_bits <= 8));
        assert!(candidates(&g8).contains(&paper(&g8)));
    }

    #[test]
    fn order_is_by_bits_then_stages() {
        let v = by_bits(&Config::default());
        assert!(v.windows(2).all(|w| bits(&w[0]) <= bits(&w[1])));
        let first = &v[0];
        assert_eq!((first.index_bits, first.red_bits), (2, 6));
        assert!(!first.compensation);
        // Equal bits: fewer stages first.
        for w in v.windows(2) {
            if bits(&w[0]) == bits(&w[1]) {
                assert!(stages(&w[0]) <= stages(&w[1]));
            }
        }
    }
}
