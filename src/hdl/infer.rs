//! Inferred multipliers (`mult = infer`): each product written as plain Verilog, `a * b`, with
//! explicit widths, and the sum of a stage's products plus its constant in a second level:
//!
//!   level 1: `m_j = a_j * b_j` (one node per product), registered as the plan says;
//!   level 2: `s = (m_0 << s_0) + (m_1 << s_1) + ... + C`.
//!
//! The multiply reads registers of the stage (its inputs) and, when level 1 is registered,
//! writes a register that holds the bare product: the input and output registers of a DSP
//! block (ECP5 MULT18X18D, iCE40 UltraPlus SB_MAC16), so synthesis can put the product and
//! both registers into the block and the adder that follows into the fabric (the MULT18X18D
//! has no adder; Yosys maps `$mul` cells only). A product alone, without a constant, needs no
//! second level.
//!
//! The result has the shape of [`super::adder_tree::build`]'s ([`Built`]: steps, sums,
//! riders), so a stage's template renders either with the same `steps.v`, and the plan counts
//! the registered levels into its latency the same way.

use super::adder_tree::{align_ranges, carry_riders, Built, Node, Sig, Step, Sum};
use super::tree_spec::{Factor, Product};

/// A sum of products to build: its name (prefix of its nodes), products, constant and, when
/// the designer knows one, a bound of the whole sum tighter than the sum of the maxima.
#[derive(Clone, Debug)]
pub struct Mul {
    pub name: String,
    pub products: Vec<Product>,
    pub constant: u128,
    pub bound: Option<u128>,
}

fn bits(v: u128) -> u32 {
    (128 - v.leading_zeros()).max(1)
}

/// `x` zero-extended to `w` bits.
fn extend(x: &str, xw: u32, w: u32) -> String {
    assert!(xw <= w, "{x} is wider than {w} bits");
    if xw == w {
        x.to_string()
    } else {
        format!("{{{{{}{{1'b0}}}}, {x}}}", w - xw)
    }
}

impl Mul {
    /// Levels: the products, then their sum with the constant (absent for a lone product).
    pub fn levels(&self) -> u32 {
        if self.products.len() == 1 && self.constant == 0 {
            1
        } else {
            2
        }
    }

    /// The largest value of product `j` (without its shift), so its width.
    fn product_max(&self, j: usize) -> u128 {
        let p = &self.products[j];
        let b = match &p.b {
            Factor::Sig(s) => (1u128 << s.width) - 1,
            Factor::Const(k) => *k,
        };
        ((1u128 << p.a.width) - 1) * b
    }

    /// Node `j` of level 1: `a * b` in the product's width (a lone product's narrowed to the
    /// bound: exact modulo 2^w, as the true product fits).
    fn product_node(&self, j: usize, name: String) -> Node {
        let p = &self.products[j];
        let max = match self.bound {
            Some(b) if self.levels() == 1 => self.product_max(j).min(b >> p.shift),
            _ => self.product_max(j),
        };
        let w = bits(max);
        let b = match &p.b {
            Factor::Sig(s) => extend(&s.name, s.width, w),
            Factor::Const(k) => format!("{w}'d{k}"),
        };
        Node {
            name,
            width: w,
            expr: format!("{} * {b}", extend(&p.a.name, p.a.width, w)),
            range: String::new(),
        }
    }
}

/// Builds `muls` side by side, one level per step, as [`super::adder_tree::build`] does:
/// `riders` ride along, `registered(k, n)` says whether level k (1-based) of n is registered,
/// and a sum that finishes early rides.
pub fn build(
    title: &str,
    muls: &[Mul],
    riders: &[(&str, Sig)],
    registered: &dyn Fn(u32, u32) -> bool,
) -> Built {
    let n = muls.iter().map(Mul::levels).max().unwrap_or(0);
    let mut riders: Vec<(&str, Sig)> = riders.to_vec();
    // Each mul's current value: its product signals after level 1, its sum after level 2.
    let mut cur: Vec<Vec<Sum>> = vec![Vec::new(); muls.len()];
    let mut steps = Vec::new();
    for k in 1..=n {
        let reg = registered(k, n);
        let sfx = if reg { "q" } else { "d" };
        let mut nodes = Vec::new();
        let mut unused = Vec::new();
        for (m, vals) in muls.iter().zip(cur.iter_mut()) {
            let last = k == m.levels();
            if k > m.levels() {
                // Finished: the sum rides as one node.
                if reg {
                    let s = &vals[0];
                    let name = format!("{}_l{k}", m.name);
                    nodes.push(Node {
                        name: name.clone(),
                        width: s.sig.width,
                        expr: s.sig.name.clone(),
                        range: String::new(),
                    });
                    vals[0].sig.name = format!("{name}_q");
                }
                continue;
            }
            if k == 1 {
                for j in 0..m.products.len() {
                    let name = if last {
                        format!("{}_l1", m.name)
                    } else {
                        format!("{}_l1_{j}", m.name)
                    };
                    let node = m.product_node(j, name);
                    vals.push(Sum {
                        sig: Sig::new(format!("{}_{sfx}", node.name), node.width),
                        shift: m.products[j].shift,
                    });
                    nodes.push(node);
                }
                continue;
            }
            // Level 2: the products, shifted into place, and the constant, in the width of
            // the sum's bound; the true sum fits, so it is exact modulo 2^w and a product's
            // bits above w cannot contribute.
            let full: u128 = (0..m.products.len())
                .map(|j| m.product_max(j) << m.products[j].shift)
                .sum::<u128>()
                + m.constant;
            let w = bits(m.bound.map_or(full, |b| b.min(full)));
            let mut terms: Vec<String> = vals
                .iter()
                .map(|v| {
                    let keep = w - v.shift;
                    let x = if v.sig.width > keep {
                        unused.push(if v.sig.width == keep + 1 {
                            format!("{}[{keep}]", v.sig.name)
                        } else {
                            format!("{}[{}:{keep}]", v.sig.name, v.sig.width - 1)
                        });
                        Sum {
                            sig: Sig::new(format!("{}[{}:0]", v.sig.name, keep - 1), keep),
                            shift: v.shift,
                        }
                    } else {
                        v.clone()
                    };
                    x.expr(w)
                })
                .collect();
            if m.constant > 0 {
                terms.push(format!("{w}'d{}", m.constant));
            }
            let name = format!("{}_l2", m.name);
            *vals = vec![Sum {
                sig: Sig::new(format!("{name}_{sfx}"), w),
                shift: 0,
            }];
            nodes.push(Node {
                name,
                width: w,
                expr: terms.join(" + "),
                range: String::new(),
            });
        }
        if reg {
            carry_riders(&mut riders, k, &mut nodes);
        }
        align_ranges(&mut nodes);
        let what = if k == 1 { "products" } else { "sums" };
        steps.push(Step {
            title: format!(
                "{title}: {what}, level {k} of {n}{}",
                if reg { "" } else { " (no register)" }
            ),
            registered: reg,
            nodes,
            unused,
        });
    }
    let sums = cur
        .into_iter()
        .map(|mut v| {
            assert_eq!(v.len(), 1, "a sum did not finish");
            v.pop().expect("one value")
        })
        .collect();
    Built {
        steps,
        sums,
        riders: riders.into_iter().map(|(_, r)| r).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mul(products: Vec<Product>, constant: u128) -> Mul {
        Mul {
            name: "p".into(),
            products,
            constant,
            bound: None,
        }
    }

    fn prod(a: &str, aw: u32, b: Factor, shift: u32) -> Product {
        Product {
            a: Sig::new(a, aw),
            b,
            shift,
        }
    }

    #[test]
    fn a_product_and_a_constant_take_two_levels_with_explicit_widths() {
        let m = mul(vec![prod("a", 8, Factor::Sig(Sig::new("x", 10)), 0)], 256);
        let b = build("t", &[m], &[("f", Sig::new("f_q", 1))], &|_, _| true);
        assert_eq!(b.steps.len(), 2);
        let p = &b.steps[0].nodes[0];
        assert_eq!((p.name.as_str(), p.width), ("p_l1_0", 18));
        assert_eq!(p.expr, "{{10{1'b0}}, a} * {{8{1'b0}}, x}");
        let s = &b.steps[1].nodes[0];
        assert_eq!(s.expr, "p_l1_0_q + 18'd256");
        assert_eq!(b.sums[0].sig.name, "p_l2_q");
        assert_eq!(b.riders[0].name, "f_l2_q");
    }

    #[test]
    fn a_bounded_sum_drops_the_product_bits_it_cannot_need() {
        let w = |n: &str| Factor::Sig(Sig::new(n, 4));
        let mut m = mul(vec![prod("e0", 8, w("wc"), 0), prod("e1", 8, w("w"), 0)], 4);
        m.bound = Some(255 * 8 + 4);
        let b = build("t", &[m], &[], &|k, _| k == 2);
        assert!(!b.steps[0].registered);
        let s = &b.steps[1];
        assert_eq!(s.nodes[0].width, 11);
        assert_eq!(s.nodes[0].expr, "p_l1_0_d[10:0] + p_l1_1_d[10:0] + 11'd4");
        assert_eq!(s.unused, ["p_l1_0_d[11]", "p_l1_1_d[11]"]);
    }

    #[test]
    fn a_lone_product_rides_while_another_sums() {
        let lone = Mul {
            name: "q".into(),
            ..mul(vec![prod("n", 9, Factor::Const(5), 0)], 0)
        };
        let two = mul(vec![prod("a", 4, Factor::Sig(Sig::new("b", 4)), 1)], 3);
        let b = build("t", &[lone, two], &[], &|_, _| true);
        assert_eq!(b.steps[0].nodes[0].expr, "{{3{1'b0}}, n} * 12'd5");
        assert_eq!(b.sums[0].sig.name, "q_l2_q");
        assert_eq!(b.steps[1].nodes[1].expr, "{p_l1_0_q, {1{1'b0}}} + 9'd3");
    }
}
