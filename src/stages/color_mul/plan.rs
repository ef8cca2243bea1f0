//! Where color_mul's registers sit: the numerators 2 c i + D as adder trees of
//! colour-bit-gated copies of the intensity, then n * K as a tree of shifted copies of n (one
//! per set bit of K); every registered level is a clock.

use super::model::constants;
use crate::config::{Config, COLOR_BITS};
use crate::rtl::adder_tree::{self, registered, registered_at, Sig, Step, Sum, Term, Tree};

pub struct Plan {
    pub steps: Vec<Step>,
    /// n * K per channel r, g, b.
    pub products: Vec<Sum>,
    pub latency: u32,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        let d = cfg.pipeline_depth;
        let (k, _s) = constants(cfg);
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
                        x: n.plain(),
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
        let latency = registered(&steps);
        Plan {
            products: b2.sums,
            steps,
            latency,
        }
    }
}
