//! Where linear_index's registers sit: u' = u, or 2^F for the all-ones code (so that the
//! border comes out exactly as POS_MAX), registered at depth >= 1; then
//! p = (u' * POS_MAX + 2^(F-1)) >> F with the constant POS_MAX = (2^I - 1) * 2^P as an adder
//! tree of I shifted copies of u' (`mult = tree`), or an inferred product and its sum
//! (`mult = infer`).

use crate::config::{Config, Mult};
use crate::hdl::adder_tree::{
    self, clock_q, registered, registered_at, Sig, Step, Sum, Term, Tree,
};
use crate::hdl::infer::{self, Mul};
use crate::hdl::tree_spec::{Factor, Product, TreeSpec};

/// The rounding constant, half a fraction LSB scaled: 2^(frac_bits - 1).
pub fn frac_half(cfg: &Config) -> u64 {
    1 << (cfg.frac_bits - 1)
}

pub struct Plan {
    pub pre_reg: bool,
    /// The suffix of u' and v' registered (with `pre_reg`); the trees read `_d` without.
    pub in_q: String,
    pub steps: Vec<Step>,
    pub sum_u: Sum,
    pub sum_v: Sum,
    pub latency: u32,
    /// What each tree computes: x' * POS_MAX + 2^(F-1) with x' <= 2^F.
    pub specs: Vec<TreeSpec>,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        let d = cfg.pipeline_depth;
        let pre_reg = d >= 1;
        let in_q = clock_q(1);
        let sfx = if pre_reg { in_q.as_str() } else { "d" };
        let title = "u' * POS_MAX and v' * POS_MAX";
        let bound = (cfg.pos_max() as u128) << cfg.frac_bits | frac_half(cfg) as u128;
        let b = match cfg.mult {
            Mult::Tree => {
                let tree = |name: &str, x: &str| Tree {
                    name: name.into(),
                    terms: (0..cfg.index_bits)
                        .map(|b| Term::Plain {
                            x: Sig::new(format!("{x}_{sfx}"), cfg.frac_bits + 1),
                            shift: cfg.interp_bits + b,
                        })
                        .chain([Term::Const(frac_half(cfg) as u128)])
                        .collect(),
                    bound: Some(bound),
                };
                let trees = [tree("su", "ux"), tree("sv", "vx")];
                let n = adder_tree::levels(&trees[0]);
                adder_tree::build(title, &trees, &[], &|k, _| registered_at(d, n, k))
            }
            Mult::Infer => {
                let mul = |name: &str, x: &str| Mul {
                    name: name.into(),
                    products: vec![Product {
                        a: Sig::new(format!("{x}_{sfx}"), cfg.frac_bits + 1),
                        b: Factor::Const(cfg.pos_max() as u128),
                        shift: 0,
                    }],
                    constant: frac_half(cfg) as u128,
                    bound: Some(bound),
                };
                let muls = [mul("su", "ux"), mul("sv", "vx")];
                let n = muls[0].levels();
                infer::build(title, &muls, &[], &|k, _| registered_at(d, n, k))
            }
        };
        let latency = pre_reg as u32 + registered(&b.steps);
        let spec = |t: &str, x: &str, sum: &Sum| {
            let x = Sig::new(format!("{x}_{sfx}"), cfg.frac_bits + 1);
            TreeSpec {
                tree: t.into(),
                title: format!("{} * POS_MAX + 2^(F-1)", x.name),
                products: vec![Product {
                    a: x.clone(),
                    b: Factor::Const(cfg.pos_max() as u128),
                    shift: 0,
                }],
                constant: frac_half(cfg) as u128,
                sum: sum.clone(),
                // u' is u, or 2^F for the all-ones code.
                at_most: vec![(x, 1u128 << cfg.frac_bits)],
                split: None,
            }
        };
        let specs = vec![spec("su", "ux", &b.sums[0]), spec("sv", "vx", &b.sums[1])];
        Plan {
            specs,
            pre_reg,
            in_q: in_q.clone(),
            sum_u: b.sums[0].clone(),
            sum_v: b.sums[1].clone(),
            steps: b.steps,
            latency,
        }
    }
}
