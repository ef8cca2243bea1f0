//! Where color_mul's registers sit: the numerators 2 c i + D as adder trees of
//! colour-bit-gated copies of the intensity, then n * K as a tree of shifted copies of n (one
//! per set bit of K) (`mult = tree`), or inferred products (`mult = infer`); every registered
//! level is a clock.

use super::model::constants;
use crate::config::{Config, Mult, COLOR_BITS};
use crate::hdl::adder_tree::{self, registered, registered_at, Sig, Step, Sum, Term, Tree};
use crate::hdl::infer::{self, Mul};
use crate::hdl::tree_spec::{Factor, Product, TreeSpec};

pub struct Plan {
    pub steps: Vec<Step>,
    /// n * K per channel r, g, b.
    pub products: Vec<Sum>,
    pub latency: u32,
    /// What each tree computes: n = 2 c i + D, then n * K (the formal proof's specification).
    pub specs: Vec<TreeSpec>,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        let d = cfg.pipeline_depth;
        let (k, _s) = constants(cfg);
        let dd = cfg.map_max() as u128;
        let n_max = 2 * ((1u128 << COLOR_BITS) - 1) * dd + dd;
        let chans = ["r", "g", "b"];
        let (title1, title2) = ("numerators 2 c i + D", "products n * K");
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
        let b1 = match cfg.mult {
            Mult::Tree => {
                let n1 = adder_tree::levels(&num[0]);
                adder_tree::build(title1, &num, &[], &|kk, _| registered_at(d, n1, kk))
            }
            Mult::Infer => {
                let muls: Vec<Mul> = chans
                    .iter()
                    .map(|c| Mul {
                        name: format!("n{c}"),
                        products: vec![Product {
                            a: Sig::new("i_i", cfg.map_bits),
                            b: Factor::Sig(Sig::new(format!("{c}_i"), COLOR_BITS)),
                            shift: 1,
                        }],
                        constant: dd,
                        bound: Some(n_max),
                    })
                    .collect();
                let n1 = muls[0].levels();
                infer::build(title1, &muls, &[], &|kk, _| registered_at(d, n1, kk))
            }
        };
        let prod: Vec<Tree> = chans
            .iter()
            .zip(&b1.sums)
            .map(|(c, n)| Tree {
                name: format!("p{c}"),
                terms: (0..64)
                    .filter(|b| k >> b & 1 == 1)
                    .map(|b| Term::Plain {
                        x: n.plain(),
                        shift: b,
                    })
                    .collect(),
                bound: Some(n_max * k as u128),
            })
            .collect();
        let b2 = match cfg.mult {
            Mult::Tree => {
                let n2 = adder_tree::levels(&prod[0]);
                adder_tree::build(title2, &prod, &[], &|kk, _| registered_at(d, n2, kk))
            }
            Mult::Infer => {
                let muls: Vec<Mul> = chans
                    .iter()
                    .zip(&b1.sums)
                    .map(|(c, n)| Mul {
                        name: format!("p{c}"),
                        products: vec![Product {
                            a: n.plain(),
                            b: Factor::Const(k as u128),
                            shift: 0,
                        }],
                        constant: 0,
                        bound: Some(n_max * k as u128),
                    })
                    .collect();
                let n2 = muls[0].levels();
                infer::build(title2, &muls, &[], &|kk, _| registered_at(d, n2, kk))
            }
        };
        let mut steps = b1.steps;
        steps.extend(b2.steps);
        let latency = registered(&steps);
        let mut specs = Vec::new();
        for (j, c) in chans.iter().enumerate() {
            let i = Sig::new("i_i", cfg.map_bits);
            let ch = Sig::new(format!("{c}_i"), COLOR_BITS);
            let mut t =
                TreeSpec::product(&format!("n{c}"), "2 c i + D", i, ch, dd, b1.sums[j].clone());
            t.products[0].shift = 1;
            specs.push(t);
        }
        for (j, c) in chans.iter().enumerate() {
            let n = b1.sums[j].plain();
            specs.push(TreeSpec {
                tree: format!("p{c}"),
                title: "n * K".into(),
                products: vec![Product {
                    a: n.clone(),
                    b: Factor::Const(k as u128),
                    shift: 0,
                }],
                constant: 0,
                sum: b2.sums[j].clone(),
                // n is the numerator tree's sum, proved above to be 2 c i + D <= n_max.
                at_most: vec![(n, n_max)],
                split: None,
            });
        }
        Plan {
            specs,
            products: b2.sums,
            steps,
            latency,
        }
    }
}
