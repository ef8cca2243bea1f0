//! Where normalise's registers sit for a `pipeline_depth`: the ROM read and the compares
//! take a clock, the ROM output is registered again at depth >= 1, then a * recip + HALF and
//! b * recip + HALF are adder trees of the partial products (`mult = tree`) or inferred
//! products and their sums (`mult = infer`), then rounding and saturation go into the output
//! register. The template renders this plan and the latency counts it.

use crate::config::{Config, Mult};
use crate::hdl::adder_tree::{
    self, clock_q, registered, registered_at, Built, Sig, Step, Sum, Term, Tree,
};
use crate::hdl::infer::{self, Mul};
use crate::hdl::tree_spec::{Factor, Product, TreeSpec};

pub struct Plan {
    pub rom_reg: bool,
    /// The suffix of the registers the trees read: the ROM read's (`q1`), or the ROM output
    /// register's (`q2`) with `rom_reg`.
    pub tree_q: String,
    pub steps: Vec<Step>,
    /// The sums a * recip + HALF and b * recip + HALF.
    pub sum_a: Sum,
    pub sum_b: Sum,
    /// a == m and b == m, delayed to the saturation.
    pub a_max: Sig,
    pub b_max: Sig,
    pub latency: u32,
    /// What each tree computes: x * recip + HALF (the formal proof's specification).
    pub specs: Vec<TreeSpec>,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        let d = cfg.pipeline_depth;
        let rom_reg = d >= 1;
        let tree_q = clock_q(1 + rom_reg as u32);
        let q = &tree_q;
        let recip = Sig::new(format!("recip_{q}"), cfg.recip_bits);
        let riders = [
            ("a_max", Sig::new(format!("a_max_{q}"), 1)),
            ("b_max", Sig::new(format!("b_max_{q}"), 1)),
        ];
        let title = "a * recip and b * recip";
        let half = super::model::norm_half(cfg) as u128;
        let Built {
            steps,
            sums,
            riders,
        } = match cfg.mult {
            Mult::Tree => {
                let tree = |name: &str, x: &str| Tree {
                    name: name.into(),
                    terms: (0..cfg.red_bits)
                        .map(|j| Term::Gated {
                            sel: format!("{x}_{q}[{j}]"),
                            x: recip.clone(),
                            shift: j,
                        })
                        .chain([Term::Const(half)])
                        .collect(),
                    bound: None,
                };
                let trees = [tree("pa", "a"), tree("pb", "b")];
                let n = adder_tree::levels(&trees[0]);
                // The last level and the saturation share a clock, except at depth 2.
                let anchor = if d >= 2 { n } else { n - 1 };
                adder_tree::build(title, &trees, &riders, &|k, _| registered_at(d, anchor, k))
            }
            Mult::Infer => {
                let mul = |name: &str, x: &str| Mul {
                    name: name.into(),
                    products: vec![Product {
                        a: Sig::new(format!("{x}_{q}"), cfg.red_bits),
                        b: Factor::Sig(recip.clone()),
                        shift: 0,
                    }],
                    constant: half,
                    bound: None,
                };
                let muls = [mul("pa", "a"), mul("pb", "b")];
                let n = muls[0].levels();
                // As the tree: the sum and the saturation share a clock, except at depth 2;
                // the product is registered at every depth (the DSP's output register).
                let anchor = if d >= 2 { n } else { n - 1 };
                infer::build(title, &muls, &riders, &|k, _| registered_at(d, anchor, k))
            }
        };
        let latency = 1 + rom_reg as u32 + registered(&steps) + 1;
        let spec = |t: &str, x: &str, sum: &Sum| {
            let title = format!("{x} * recip + HALF");
            let x = Sig::new(format!("{x}_{q}"), cfg.red_bits);
            TreeSpec::product(t, &title, x, recip.clone(), half, sum.clone())
        };
        let specs = vec![spec("pa", "a", &sums[0]), spec("pb", "b", &sums[1])];
        Plan {
            specs,
            rom_reg,
            tree_q: tree_q.clone(),
            sum_a: sums[0].clone(),
            sum_b: sums[1].clone(),
            a_max: riders[0].clone(),
            b_max: riders[1].clone(),
            steps,
            latency,
        }
    }
}
