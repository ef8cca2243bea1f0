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

/// Searched fields the caller fixed (`fit --red-bits 8 --frac-bits 8 ...`): only candidates
/// with those values are searched. A user who has already chosen a front end (or a map size)
/// searches the rest, in seconds where the whole space takes an hour with a slow map fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Fixed {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub red_bits: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frac_bits: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recip_bits: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub index_bits: Option<u32>,
    /// 0 fixes interpolation off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interp_bits: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compensation: Option<bool>,
}

impl Fixed {
    /// Whether `cfg` has every fixed value.
    pub fn admits(&self, cfg: &Config) -> bool {
        let ok = |fixed: Option<u32>, v: u32| fixed.is_none_or(|f| f == v);
        ok(self.red_bits, cfg.red_bits)
            && ok(self.frac_bits, cfg.frac_bits)
            && ok(self.recip_bits, cfg.recip_bits)
            && ok(self.index_bits, cfg.index_bits)
            && ok(self.interp_bits, cfg.interp_bits)
            && self.compensation.is_none_or(|c| c == cfg.compensation)
    }

    /// Whether nothing is fixed.
    pub fn is_empty(&self) -> bool {
        *self == Fixed::default()
    }

    /// The fixed values in the letters of [`Config::summary`] (`R8 W10 F8 comp=1`), or "".
    pub fn describe(&self) -> String {
        let fields = [
            ("R", self.red_bits),
            ("W", self.recip_bits),
            ("F", self.frac_bits),
            ("I", self.index_bits),
            ("P", self.interp_bits),
        ];
        let mut v: Vec<String> = fields
            .iter()
            .filter_map(|(k, f)| f.map(|f| format!("{k}{f}")))
            .collect();
        if let Some(c) = self.compensation {
            v.push(format!("comp={}", c as u32));
        }
        v.join(" ")
    }
}

/// Every valid configuration with `base`'s interface fields (grad_bits, map_bits, color,
/// pipeline_depth, handshake, lanes) and the `fixed` values, in no particular order.
pub fn candidates(base: &Config, fixed: &Fixed) -> Vec<Config> {
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
                            if fixed.admits(&c) && c.validate().is_ok() {
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
pub fn by_bits(base: &Config, fixed: &Fixed) -> Vec<Config> {
    let mut v = candidates(base, fixed);
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
        let v = candidates(&base, &Fixed::default());
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
        let all = Fixed::default();
        assert!(candidates(&g8, &all).iter().all(|c| c.red_bits <= 8));
        assert!(candidates(&g8, &all).contains(&paper(&g8)));
    }

    #[test]
    fn order_is_by_bits_then_stages() {
        let v = by_bits(&Config::default(), &Fixed::default());
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

    /// Fixing fields keeps exactly the candidates with those values, and each field is read
    /// from its own place (a fixed index does not fix the interpolation).
    #[test]
    fn fixed_fields_keep_exactly_the_candidates_with_their_values() {
        let base = Config::default();
        let all = candidates(&base, &Fixed::default());
        let fixes = [
            Fixed {
                red_bits: Some(8),
                ..Fixed::default()
            },
            Fixed {
                frac_bits: Some(5),
                ..Fixed::default()
            },
            Fixed {
                recip_bits: Some(11),
                ..Fixed::default()
            },
            Fixed {
                index_bits: Some(4),
                ..Fixed::default()
            },
            Fixed {
                interp_bits: Some(0),
                ..Fixed::default()
            },
            Fixed {
                compensation: Some(false),
                ..Fixed::default()
            },
            Fixed {
                red_bits: Some(8),
                frac_bits: Some(8),
                recip_bits: Some(10),
                ..Fixed::default()
            },
        ];
        let value = |c: &Config| {
            [
                c.red_bits,
                c.frac_bits,
                c.recip_bits,
                c.index_bits,
                c.interp_bits,
                c.compensation as u32,
            ]
        };
        for f in fixes {
            let want = [
                f.red_bits,
                f.frac_bits,
                f.recip_bits,
                f.index_bits,
                f.interp_bits,
                f.compensation.map(|c| c as u32),
            ];
            let kept = candidates(&base, &f);
            let expect: Vec<&Config> = all
                .iter()
                .filter(|c| {
                    want.iter()
                        .zip(value(c))
                        .all(|(w, v)| w.is_none_or(|w| w == v))
                })
                .collect();
            assert!(!kept.is_empty() && kept.len() < all.len(), "{f:?}");
            assert_eq!(kept.iter().collect::<Vec<_>>(), expect, "{f:?}");
        }
        // The front end of the paper: 5 index widths x 6 interpolation widths x 2.
        let front = fixes[6];
        assert_eq!(candidates(&base, &front).len(), 5 * 6 * 2);
        assert_eq!(front.describe(), "R8 W10 F8");
        assert!(Fixed::default().is_empty() && !front.is_empty());
        assert_eq!(
            Fixed {
                interp_bits: Some(0),
                compensation: Some(true),
                ..Fixed::default()
            }
            .describe(),
            "P0 comp=1"
        );
        // A fixed value no valid configuration has leaves nothing.
        let none = Fixed {
            frac_bits: Some(12),
            recip_bits: Some(12),
            ..Fixed::default()
        };
        assert!(candidates(&base, &none).is_empty());
    }
}
