//! Where each module's registers sit for a configuration's `pipeline_depth`: the one place
//! that decides it. The templates render these plans and [`super::latency`] counts their
//! registers, so the Verilog and every latency figure (manifest, testbenches, sideband
//! delays) cannot disagree.
//!
//! | depth | what is registered |
//! |---|---|
//! | 0 compact | each stage's legacy registers: a multiplier is one or two clocks |
//! | 1 | + the output of every ROM and RAM read (a fabric register after the block RAM's own), the sort & shift magnitudes, every second adder level |
//! | 2 | + every adder level (one LUT level and one carry chain per clock) |

use super::adder_tree::{self, registered_at, Built, Sig, Step, Sum, Term, Tree};
use crate::config::{Config, COLOR_BITS};
use crate::model::color_mul;

/// A sum used as a signal: its value must start at bit 0.
fn plain(s: &Sum) -> Sig {
    assert_eq!(s.shift, 0, "{} is shifted", s.sig.name);
    s.sig.clone()
}

/// Registered adder levels among `steps`.
fn regs(steps: &[Step]) -> u32 {
    steps.iter().filter(|s| s.registered).count() as u32
}

/// sort_shift: magnitudes registered before the compare (depth >= 1).
pub fn sort_shift_mag_reg(cfg: &Config) -> bool {
    cfg.pipeline_depth >= 1
}

/// sort_shift: compare results registered before the select (depth 2).
pub fn sort_shift_cmp_reg(cfg: &Config) -> bool {
    cfg.pipeline_depth >= 2
}

/// sort_shift's latency: select and shift, plus the optional magnitude and compare registers.
pub fn sort_shift_latency(cfg: &Config) -> u32 {
    2 + sort_shift_mag_reg(cfg) as u32 + sort_shift_cmp_reg(cfg) as u32
}

/// atan_rom: a fabric register after the ROM's block-RAM output register (depth >= 1).
pub fn atan_out_reg(cfg: &Config) -> bool {
    cfg.pipeline_depth >= 1
}

/// map_lookup: a fabric register after the banks' block-RAM output registers (depth >= 1).
pub fn bank_out_reg(cfg: &Config) -> bool {
    cfg.pipeline_depth >= 1
}

/// Normalise: ROM read and compares (a clock), the ROM output registered again (depth >= 1),
/// then a * recip + HALF and b * recip + HALF as adder trees of the partial products, then
/// rounding and saturation into the output register.
pub struct NormalisePlan {
    pub rom_reg: bool,
    pub steps: Vec<Step>,
    /// The sums a * recip + HALF and b * recip + HALF.
    pub sum_a: Sum,
    pub sum_b: Sum,
    /// a == m and b == m, delayed to the saturation.
    pub a_max: Sig,
    pub b_max: Sig,
    pub latency: u32,
}

pub fn normalise(cfg: &Config) -> NormalisePlan {
    let d = cfg.pipeline_depth;
    let rom_reg = d >= 1;
    let q = if rom_reg { "q2" } else { "q1" };
    let recip = Sig::new(format!("recip_{q}"), cfg.recip_bits);
    let tree = |name: &str, x: &str| Tree {
        name: name.into(),
        terms: (0..cfg.red_bits)
            .map(|j| Term::Gated {
                sel: format!("{x}_{q}[{j}]"),
                x: recip.clone(),
                shift: j,
            })
            .chain([Term::Const(cfg.norm_half() as u128)])
            .collect(),
        bound: None,
    };
    let trees = [tree("pa", "a"), tree("pb", "b")];
    let n = adder_tree::levels(&trees[0]);
    // The last level and the saturation share a clock, except at depth 2.
    let anchor = if d >= 2 { n } else { n - 1 };
    let Built {
        steps,
        sums,
        riders,
    } = adder_tree::build(
        "a * recip and b * recip",
        &trees,
        &[
            ("a_max", Sig::new(format!("a_max_{q}"), 1)),
            ("b_max", Sig::new(format!("b_max_{q}"), 1)),
        ],
        &|k, _| registered_at(d, anchor, k),
    );
    let latency = 1 + rom_reg as u32 + regs(&steps) + 1;
    NormalisePlan {
        rom_reg,
        sum_a: sums[0].clone(),
        sum_b: sums[1].clone(),
        a_max: riders[0].clone(),
        b_max: riders[1].clone(),
        steps,
        latency,
    }
}

/// Linear index: u' = u, or 2^F for the all-ones code (so that the border comes out exactly
/// as POS_MAX), registered at depth >= 1; then p = (u' * POS_MAX + 2^(F-1)) >> F with the
/// constant POS_MAX = (2^I - 1) * 2^P as I shifted copies of u'.
pub struct LinearPlan {
    pub pre_reg: bool,
    pub steps: Vec<Step>,
    pub sum_u: Sum,
    pub sum_v: Sum,
    pub latency: u32,
}

pub fn linear_index(cfg: &Config) -> LinearPlan {
    let d = cfg.pipeline_depth;
    let pre_reg = d >= 1;
    let sfx = if pre_reg { "q1" } else { "d" };
    let tree = |name: &str, x: &str| Tree {
        name: name.into(),
        terms: (0..cfg.index_bits)
            .map(|b| Term::Plain {
                x: Sig::new(format!("{x}_{sfx}"), cfg.frac_bits + 1),
                shift: cfg.interp_bits + b,
            })
            .chain([Term::Const(cfg.frac_half() as u128)])
            .collect(),
        bound: Some((cfg.pos_max() as u128) << cfg.frac_bits | cfg.frac_half() as u128),
    };
    let trees = [tree("su", "ux"), tree("sv", "vx")];
    let n = adder_tree::levels(&trees[0]);
    let b = adder_tree::build("u' * POS_MAX and v' * POS_MAX", &trees, &[], &|k, _| {
        registered_at(d, n, k)
    });
    let latency = pre_reg as u32 + regs(&b.steps);
    LinearPlan {
        pre_reg,
        sum_u: b.sums[0].clone(),
        sum_v: b.sums[1].clone(),
        steps: b.steps,
        latency,
    }
}

/// Interpolate: the weights' complements S - w (registered with the inputs at depth >= 1),
/// then the u pass a0 = e00 (S - wu) + e10 wu + S/2 and a1 likewise, then the v pass
/// r = a0 (S - wv) + a1 wv, which carries the rounding constant S^2/2 in from the u pass;
/// i = r >> 2P. Every pass is an adder tree of weight-gated partial products.
pub struct InterpolatePlan {
    pub in_reg: bool,
    pub steps: Vec<Step>,
    pub sum_r: Sum,
    pub latency: u32,
}

pub fn interpolate(cfg: &Config) -> InterpolatePlan {
    let d = cfg.pipeline_depth;
    let in_reg = d >= 1;
    let p = cfg.interp_bits;
    let m = cfg.map_bits;
    let s = cfg.step() as u128;
    let sfx = |n: &str| {
        if in_reg {
            format!("{n}_q1")
        } else if n.starts_with('w') && n.ends_with('c') {
            format!("{n}_d")
        } else {
            format!("{n}_i")
        }
    };
    let pass = |name: &str, lo: Sig, hi: Sig, w: &str, wc: &str, c: u128, bound: u128| Tree {
        name: name.into(),
        terms: (0..=p)
            .flat_map(|j| {
                [
                    Term::Gated {
                        sel: format!("{}[{j}]", sfx(wc)),
                        x: lo.clone(),
                        shift: j,
                    },
                    Term::Gated {
                        sel: format!("{}[{j}]", sfx(w)),
                        x: hi.clone(),
                        shift: j,
                    },
                ]
            })
            .chain((c > 0).then_some(Term::Const(c)))
            .collect(),
        bound: Some(bound),
    };
    let e = |n: &str| Sig::new(sfx(n), m);
    let a_max = ((1u128 << m) - 1) * s + s / 2;
    let u = [
        pass("a0", e("e00"), e("e10"), "wu", "wuc", s / 2, a_max),
        pass("a1", e("e01"), e("e11"), "wu", "wuc", s / 2, a_max),
    ];
    let nu = adder_tree::levels(&u[0]);
    let bu = adder_tree::build(
        "u pass",
        &u,
        &[
            ("wv", Sig::new(sfx("wv"), p + 1)),
            ("wvc", Sig::new(sfx("wvc"), p + 1)),
        ],
        &|k, _| registered_at(d, nu, k),
    );
    // The v pass gates a0 and a1 with the weights that rode along.
    let (wv, wvc) = (&bu.riders[0], &bu.riders[1]);
    let r_max = ((1u128 << m) - 1) * s * s + s * s / 2;
    let v_terms = (0..=p)
        .flat_map(|j| {
            [
                Term::Gated {
                    sel: format!("{}[{j}]", wvc.name),
                    x: plain(&bu.sums[0]),
                    shift: j,
                },
                Term::Gated {
                    sel: format!("{}[{j}]", wv.name),
                    x: plain(&bu.sums[1]),
                    shift: j,
                },
            ]
        })
        .collect();
    let v = [Tree {
        name: "r".into(),
        terms: v_terms,
        bound: Some(r_max),
    }];
    let nv = adder_tree::levels(&v[0]);
    let bv = adder_tree::build("v pass", &v, &[], &|k, _| registered_at(d, nv, k));
    let mut steps = bu.steps;
    steps.extend(bv.steps);
    let latency = in_reg as u32 + regs(&steps);
    InterpolatePlan {
        in_reg,
        sum_r: bv.sums[0].clone(),
        steps,
        latency,
    }
}

/// Colour multiply: the numerators 2 c i + D as adder trees of colour-bit-gated copies of
/// the intensity, then n * K as a tree of shifted copies of n (one per set bit of K).
pub struct ColorPlan {
    pub steps: Vec<Step>,
    /// n * K per channel r, g, b.
    pub products: Vec<Sum>,
    pub latency: u32,
}

pub fn color_mul(cfg: &Config) -> ColorPlan {
    let d = cfg.pipeline_depth;
    let (k, _s) = color_mul::constants(cfg);
    let dd = cfg.map_max() as u128;
    let n_max = 2 * ((1u128 << COLOR_BITS) - 1) * dd + dd;
    let chans = ["r", "g", "b"];
    let num: Vec<Tree> = chans
        .iter()
        .map(|c| Tree {
            name: format!("n{c}"),
            terms: (0..COLOR_BITS)
                .map(|j| Term::Gated {
                    sel: format!("{c}_i[{j}]"),
                    x: Sig::new("i_i", cfg.map_bits),
                    shift: j + 1,
                })
                .chain([Term::Const(dd)])
                .collect(),
            bound: Some(n_max),
        })
        .collect();
    let n1 = adder_tree::levels(&num[0]);
    let b1 = adder_tree::build("numerators 2 c i + D", &num, &[], &|kk, _| {
        registered_at(d, n1, kk)
    });
    let prod: Vec<Tree> = chans
        .iter()
        .zip(&b1.sums)
        .map(|(c, n)| Tree {
            name: format!("p{c}"),
            terms: (0..64)
                .filter(|b| k >> b & 1 == 1)
                .map(|b| Term::Plain {
                    x: plain(n),
                    shift: b,
                })
                .collect(),
            bound: Some(n_max * k as u128),
        })
        .collect();
    let n2 = adder_tree::levels(&prod[0]);
    let b2 = adder_tree::build("products n * K", &prod, &[], &|kk, _| {
        registered_at(d, n2, kk)
    });
    let mut steps = b1.steps;
    steps.extend(b2.steps);
    let latency = regs(&steps);
    ColorPlan {
        products: b2.sums,
        steps,
        latency,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compact_keeps_the_legacy_latencies() {
        let cfg = Config {
            color: true,
            ..Config::default()
        };
        let cfg = Config {
            pipeline_depth: 0,
            ..cfg
        };
        assert_eq!(normalise(&cfg).latency, 3);
        assert_eq!(interpolate(&cfg).latency, 2);
        assert_eq!(color_mul(&cfg).latency, 2);
        let lin = Config {
            compensation: false,
            ..cfg
        };
        assert_eq!(linear_index(&lin).latency, 1);
    }

    #[test]
    fn deeper_is_never_shorter() {
        for depth in 0..2 {
            let a = Config {
                color: true,
                pipeline_depth: depth,
                ..Config::default()
            };
            let b = Config {
                pipeline_depth: depth + 1,
                ..a.clone()
            };
            assert!(normalise(&a).latency <= normalise(&b).latency);
            assert!(interpolate(&a).latency <= interpolate(&b).latency);
            assert!(color_mul(&a).latency <= color_mul(&b).latency);
            assert!(linear_index(&a).latency <= linear_index(&b).latency);
        }
    }
}
