//! Where interpolate's registers sit: the weights' complements S - w (registered with the
//! inputs at depth >= 1), then the u pass a0 = e00 (S - wu) + e10 wu + S/2 and a1 likewise,
//! then the v pass r = a0 (S - wv) + a1 wv, which carries the rounding constant S^2/2 in
//! from the u pass; i = r >> 2P. Every pass is an adder tree of weight-gated partial
//! products (`mult = tree`), or inferred products and their sum (`mult = infer`).

use crate::config::{Config, Mult};
use crate::hdl::adder_tree::{
    self, clock_q, registered, registered_at, Sig, Step, Sum, Term, Tree,
};
use crate::hdl::infer::{self, Mul};
use crate::hdl::tree_spec::{Factor, Product, Split, TreeSpec};

pub struct Plan {
    pub in_reg: bool,
    /// The suffix of the registered inputs and complements (with `in_reg`).
    pub in_q: String,
    pub steps: Vec<Step>,
    pub sum_r: Sum,
    pub latency: u32,
    /// What each tree computes: a0 = e00 (S - wu) + e10 wu + S/2, a1 likewise, r = a0 (S - wv)
    /// + a1 wv (the formal proof's specification).
    pub specs: Vec<TreeSpec>,
}

impl Plan {
    pub fn new(cfg: &Config) -> Plan {
        let d = cfg.pipeline_depth;
        let in_reg = d >= 1;
        let p = cfg.interp_bits;
        let m = cfg.map_bits;
        let s = cfg.step() as u128;
        let in_q = clock_q(1);
        let sfx = |n: &str| {
            if in_reg {
                format!("{n}_{in_q}")
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
        let w = |n: &str| Sig::new(sfx(n), p + 1);
        let blend_mul =
            |name: &str, lo: Sig, hi: Sig, wt: Sig, wc: Sig, c: u128, bound: u128| Mul {
                name: name.into(),
                products: vec![
                    Product {
                        a: lo,
                        b: Factor::Sig(wc),
                        shift: 0,
                    },
                    Product {
                        a: hi,
                        b: Factor::Sig(wt),
                        shift: 0,
                    },
                ],
                constant: c,
                bound: Some(bound),
            };
        let u_riders = [
            ("wv", Sig::new(sfx("wv"), p + 1)),
            ("wvc", Sig::new(sfx("wvc"), p + 1)),
        ];
        let bu = match cfg.mult {
            Mult::Tree => {
                let nu = adder_tree::levels(&u[0]);
                adder_tree::build("u pass", &u, &u_riders, &|k, _| registered_at(d, nu, k))
            }
            Mult::Infer => {
                let mu = [
                    blend_mul("a0", e("e00"), e("e10"), w("wu"), w("wuc"), s / 2, a_max),
                    blend_mul("a1", e("e01"), e("e11"), w("wu"), w("wuc"), s / 2, a_max),
                ];
                let nu = mu[0].levels();
                infer::build("u pass", &mu, &u_riders, &|k, _| registered_at(d, nu, k))
            }
        };
        // The v pass gates a0 and a1 with the weights that rode along.
        let (wv, wvc) = (&bu.riders[0], &bu.riders[1]);
        let r_max = ((1u128 << m) - 1) * s * s + s * s / 2;
        let v_terms = (0..=p)
            .flat_map(|j| {
                [
                    Term::Gated {
                        sel: format!("{}[{j}]", wvc.name),
                        x: bu.sums[0].plain(),
                        shift: j,
                    },
                    Term::Gated {
                        sel: format!("{}[{j}]", wv.name),
                        x: bu.sums[1].plain(),
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
        let bv = match cfg.mult {
            Mult::Tree => {
                let nv = adder_tree::levels(&v[0]);
                adder_tree::build("v pass", &v, &[], &|k, _| registered_at(d, nv, k))
            }
            Mult::Infer => {
                let (a0, a1) = (bu.sums[0].plain(), bu.sums[1].plain());
                let mv = [blend_mul("r", a0, a1, wv.clone(), wvc.clone(), 0, r_max)];
                let nv = mv[0].levels();
                infer::build("v pass", &mv, &[], &|k, _| registered_at(d, nv, k))
            }
        };
        let mut steps = bu.steps;
        steps.extend(bv.steps);
        let latency = in_reg as u32 + registered(&steps);
        let blend = |tree: &str, lo: Sig, hi: Sig, wt: Sig, wc: Sig, c: u128, sum: &Sum| TreeSpec {
            tree: tree.into(),
            title: format!("{} * (S - w) + {} * w + {c}", lo.name, hi.name),
            products: vec![
                Product {
                    a: lo,
                    b: Factor::Sig(wc.clone()),
                    shift: 0,
                },
                Product {
                    a: hi,
                    b: Factor::Sig(wt.clone()),
                    shift: 0,
                },
            ],
            constant: c,
            sum: sum.clone(),
            at_most: vec![(wt.clone(), s)],
            split: Some(Split {
                sig: wt,
                last: s,
                complement: Some((wc, s)),
            }),
        };
        let mut specs = vec![
            blend(
                "a0",
                e("e00"),
                e("e10"),
                w("wu"),
                w("wuc"),
                s / 2,
                &bu.sums[0],
            ),
            blend(
                "a1",
                e("e01"),
                e("e11"),
                w("wu"),
                w("wuc"),
                s / 2,
                &bu.sums[1],
            ),
        ];
        let (a0, a1) = (bu.sums[0].plain(), bu.sums[1].plain());
        let mut r = blend(
            "r",
            a0.clone(),
            a1.clone(),
            wv.clone(),
            wvc.clone(),
            0,
            &bv.sums[0],
        );
        // a0 and a1 are the u pass's sums, proved above to stay within their bound.
        r.at_most.extend([(a0, a_max), (a1, a_max)]);
        specs.push(r);
        Plan {
            specs,
            in_reg,
            in_q: in_q.clone(),
            sum_r: bv.sums[0].clone(),
            steps,
            latency,
        }
    }
}
