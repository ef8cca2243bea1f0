//! The algebraic engine of `rmapgen prove-mult`: proves that two words of a gate netlist are
//! equal modulo 2^m on every input, by backward rewriting of polynomials, without
//! enumerating the inputs. It is what proves the wide interpolate sums `a0 * (S - w) + a1 *
//! w`, whose 2^34 inputs a weight are too many to evaluate and whose SAT cases take minutes.
//!
//! The method (symbolic computer algebra, as in the multiplier verifiers of Ciesielski et
//! al. and Kaufmann, Biere and Kauers): every Boolean function f of n bits has exactly one
//! multilinear polynomial P over the integers modulo 2^m with P(x) = f(x) on {0,1}^n (the
//! Möbius transform is invertible over any ring). Start from
//! `D = sum 2^i got_i - sum 2^i spec_i (mod 2^m)` over the output bits, then replace the
//! latest node by its gate's polynomial (AND: ab, XOR: a + b - 2ab, MUX: a + s(b - a), a
//! complement 1 - x, every x^2 reduced to x), node by node in reverse order, until only
//! inputs are left. The two words agree on every input exactly when what is left is the
//! zero polynomial. When it is not, a monomial of least degree gives a failing input: its
//! variables 1, all others 0, where D equals that monomial's (non-zero) coefficient.
//!
//! Adders keep the polynomial small: a full adder's sum plus twice its carry is exactly a +
//! b + c, so the sums of a tree rewrite into linear forms. A term limit bounds the memory;
//! a circuit that exceeds it is reported, not guessed.

use super::netlist::{Circuit, Lit, Node};
use anyhow::{bail, Result};
use std::collections::BTreeMap;

/// Terms a polynomial may reach before the engine gives up (a few hundred bytes each).
pub const MAX_TERMS: usize = 2_000_000;

/// A monomial: distinct variables, largest first.
type Mono = Vec<u32>;

/// A polynomial modulo 2^m: coefficients kept reduced (wrapping u64, masked).
struct Poly {
    terms: BTreeMap<Mono, u64>,
    mask: u64,
    /// For each variable, the node it can never be 1 with, or 0: `x & y` and `x ^ y` of
    /// the same operands (a half adder's carry and sum). A monomial holding both is the zero
    /// function, so it is dropped at once; rewriting would remove it only once both nodes
    /// and everything between them and their operands were substituted, and in the
    /// carry-save rows of a multiplier Yosys infers such terms pile up first (past 2
    /// million terms on an inferred 9 x 9 constant product without this rule).
    exclusive: Vec<u32>,
}

impl Poly {
    fn vanishes(&self, m: &[u32]) -> bool {
        m.iter().any(|&v| {
            let x = self.exclusive.get(v as usize).copied().unwrap_or(0);
            // Largest first: a binary search with the order reversed.
            x != 0 && m.binary_search_by(|y| x.cmp(y)).is_ok()
        })
    }

    fn add(&mut self, m: Mono, c: u64) {
        let c = c & self.mask;
        if c == 0 || self.vanishes(&m) {
            return;
        }
        let e = self.terms.entry(m);
        match e {
            std::collections::btree_map::Entry::Vacant(v) => {
                v.insert(c);
            }
            std::collections::btree_map::Entry::Occupied(mut o) => {
                let s = o.get().wrapping_add(c) & self.mask;
                if s == 0 {
                    o.remove();
                } else {
                    *o.get_mut() = s;
                }
            }
        }
    }

    /// Adds `c * lit` (a variable, its complement 1 - x, or a constant).
    fn add_lit(&mut self, l: Lit, c: u64) {
        let v = l / 2;
        let neg = l & 1 == 1;
        if v == 0 {
            if neg {
                self.add(Vec::new(), c);
            }
            return;
        }
        if neg {
            self.add(Vec::new(), c);
            self.add(vec![v], c.wrapping_neg());
        } else {
            self.add(vec![v], c);
        }
    }
}

/// A small polynomial (a gate's): terms over at most three variables.
type Small = Vec<(Mono, u64)>;

fn lit_poly(l: Lit) -> Small {
    let v = l / 2;
    match (v, l & 1 == 1) {
        (0, false) => vec![],
        (0, true) => vec![(vec![], 1)],
        (v, false) => vec![(vec![v], 1)],
        (v, true) => vec![(vec![], 1), (vec![v], u64::MAX)],
    }
}

/// The union of two monomials, largest first.
fn union(a: &[u32], b: &[u32]) -> Mono {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Greater => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Less => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

fn mul(a: &Small, b: &Small) -> Small {
    let mut out: Small = Vec::new();
    for (ma, ca) in a {
        for (mb, cb) in b {
            let m = union(ma, mb);
            let c = ca.wrapping_mul(*cb);
            match out.iter_mut().find(|(x, _)| *x == m) {
                Some((_, s)) => *s = s.wrapping_add(c),
                None => out.push((m, c)),
            }
        }
    }
    out
}

fn lin(terms: &[(&Small, u64)]) -> Small {
    let mut out: Small = Vec::new();
    for (p, k) in terms {
        for (m, c) in p.iter() {
            let c = c.wrapping_mul(*k);
            match out.iter_mut().find(|(x, _)| x == m) {
                Some((_, s)) => *s = s.wrapping_add(c),
                None => out.push((m.clone(), c)),
            }
        }
    }
    out
}

/// The polynomial of a node over its operands.
fn node_poly(n: &Node) -> Small {
    match *n {
        Node::And(a, b) => mul(&lit_poly(a), &lit_poly(b)),
        Node::Xor(a, b) => {
            let (pa, pb) = (lit_poly(a), lit_poly(b));
            let ab = mul(&pa, &pb);
            lin(&[(&pa, 1), (&pb, 1), (&ab, 2u64.wrapping_neg())])
        }
        Node::Mux(s, a, b) => {
            let (ps, pa, pb) = (lit_poly(s), lit_poly(a), lit_poly(b));
            let d = lin(&[(&pb, 1), (&pa, u64::MAX)]);
            let sd = mul(&ps, &d);
            lin(&[(&pa, 1), (&sd, 1)])
        }
    }
}

/// What the rewriting found.
#[derive(Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The words agree modulo 2^m on every input.
    Equal,
    /// They differ on this input (the value of each free input of the circuit), where
    /// `got - spec` is `difference` modulo 2^m.
    Differ { input: Vec<bool>, difference: u64 },
}

/// Figures of one rewriting.
#[derive(Debug, Default, Clone, Copy)]
pub struct Stats {
    /// Nodes substituted.
    pub steps: usize,
    /// The most terms the polynomial had.
    pub peak: usize,
}

/// Whether output words `got` and `spec` of `c` (bits least significant first; bits at and
/// above `m` ignored) agree modulo 2^m on every input. `m` is at most 64.
pub fn equal_mod(c: &Circuit, got: usize, spec: usize, m: u32) -> Result<(Verdict, Stats)> {
    if m == 0 || m > 64 {
        bail!("the algebraic engine compares 1 to 64 bits, not {m}");
    }
    let mask = if m == 64 { u64::MAX } else { (1u64 << m) - 1 };
    let base = c.inputs.len() as u32 + 1;
    let mut exclusive = vec![0u32; (base as usize) + c.nodes.len()];
    let mut ands: std::collections::HashMap<(Lit, Lit), u32> = Default::default();
    for (k, n) in c.nodes.iter().enumerate() {
        if let Node::And(a, b) = *n {
            ands.insert((a.min(b), a.max(b)), base + k as u32);
        }
    }
    for (k, n) in c.nodes.iter().enumerate() {
        if let Node::Xor(a, b) = *n {
            if let Some(&g) = ands.get(&(a.min(b), a.max(b))) {
                exclusive[g as usize] = base + k as u32;
                exclusive[(base + k as u32) as usize] = g;
            }
        }
    }
    let mut p = Poly {
        terms: BTreeMap::new(),
        mask,
        exclusive,
    };
    for (k, sign) in [(got, 1u64), (spec, u64::MAX)] {
        for (i, &l) in c.outputs[k].iter().enumerate().take(m as usize) {
            p.add_lit(l, sign.wrapping_mul(1u64 << i));
        }
    }
    let inputs = c.inputs.len() as u32;
    let mut stats = Stats::default();
    loop {
        stats.peak = stats.peak.max(p.terms.len());
        if p.terms.len() > MAX_TERMS {
            bail!(
                "the polynomial grew past {MAX_TERMS} terms after {} of {} nodes: this netlist needs another engine",
                stats.steps,
                c.nodes.len()
            );
        }
        // The largest variable left leads the last monomial (monomials are largest first).
        let Some(v) = p
            .terms
            .last_key_value()
            .and_then(|(m, _)| m.first().copied())
        else {
            break;
        };
        if v <= inputs {
            break;
        }
        let node = c.node(v).expect("a variable above the inputs is a node");
        let g = node_poly(node);
        let with_v = p.terms.split_off(&vec![v]);
        for (m, coeff) in with_v {
            let rest = &m[1..];
            for (gm, gc) in &g {
                p.add(union(rest, gm), coeff.wrapping_mul(*gc));
            }
        }
        stats.steps += 1;
    }
    if p.terms.is_empty() {
        return Ok((Verdict::Equal, stats));
    }
    let (least, &difference) = p
        .terms
        .iter()
        .min_by_key(|(m, _)| m.len())
        .expect("not empty");
    let mut input = vec![false; c.inputs.len()];
    for &v in least {
        input[v as usize - 1] = true;
    }
    Ok((Verdict::Differ { input, difference }, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// A word's value from its bits.
    fn word(b: &[bool]) -> u64 {
        b.iter().enumerate().map(|(i, &v)| (v as u64) << i).sum()
    }

    /// A ripple-carry sum of two words (the sum one bit wider), with the carry of bit
    /// `drop` left out when given.
    fn ripple(c: &mut Circuit, a: &[Lit], b: &[Lit], drop: Option<usize>) -> Vec<Lit> {
        let mut out = Vec::new();
        let mut carry = 0;
        for i in 0..a.len() {
            let x = c.xor(a[i], b[i]);
            out.push(c.xor(x, carry));
            let g = c.and(a[i], b[i]);
            let t = c.and(x, carry);
            // OR as a MUX, to exercise the third node kind.
            carry = if drop == Some(i) { g } else { c.mux(g, t, 1) };
        }
        out.push(carry);
        out
    }

    fn inputs(c: &mut Circuit, name: &str, n: u32) -> Vec<Lit> {
        (0..n)
            .map(|i| {
                c.inputs.push((name.into(), i));
                2 * c.inputs.len() as Lit
            })
            .collect()
    }

    /// got = a * b by shift-and-add rows (partial products accumulated one row at a time),
    /// spec = the same product with the rows added in the other order, plus `extra`.
    fn products(fault: Option<usize>) -> Circuit {
        let mut c = Circuit {
            inputs: Vec::new(),
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let a = inputs(&mut c, "a", 4);
        let b = inputs(&mut c, "b", 3);
        let width = 7;
        let row = |c: &mut Circuit, j: usize| -> Vec<Lit> {
            (0..width)
                .map(|k| {
                    if k >= j && k - j < a.len() {
                        c.and(a[k - j], b[j])
                    } else {
                        0
                    }
                })
                .collect()
        };
        let mut got = vec![0; width];
        for j in 0..b.len() {
            let r = row(&mut c, j);
            got = ripple(&mut c, &got, &r, None)[..width].to_vec();
        }
        let mut spec = vec![0; width];
        for j in (0..b.len()).rev() {
            let r = row(&mut c, j);
            let drop = if j == 1 { fault } else { None };
            spec = ripple(&mut c, &r, &spec, drop)[..width].to_vec();
        }
        c.outputs = vec![got, spec];
        c
    }

    #[test]
    fn a_product_summed_two_ways_is_equal() {
        let c = products(None);
        let (v, s) = equal_mod(&c, 0, 1, 7).unwrap();
        assert_eq!(v, Verdict::Equal);
        assert!(s.steps > 0);
    }

    #[test]
    fn a_dropped_carry_is_found_with_an_input_that_shows_it() {
        for bit in 0..6 {
            let c = products(Some(bit));
            let (v, _) = equal_mod(&c, 0, 1, 7).unwrap();
            let Verdict::Differ { input, difference } = v else {
                // A carry that can never be 1 (the top of the row) changes nothing.
                let any = (0..128u32).any(|x| {
                    let f: Vec<bool> = (0..7).map(|i| (x >> i) & 1 == 1).collect();
                    let o = c.eval(&f);
                    word(&o[0]) != word(&o[1])
                });
                assert!(!any, "carry {bit}: a difference the rewriting missed");
                continue;
            };
            let o = c.eval(&input);
            assert_eq!(
                word(&o[0]).wrapping_sub(word(&o[1])) & 127,
                difference,
                "carry {bit}"
            );
            assert_ne!(difference, 0);
        }
    }

    /// Random circuits of every node kind: the verdict agrees with evaluation on all 2^6
    /// inputs, and a counterexample really differs by the difference reported.
    #[test]
    fn agrees_with_evaluation_on_random_circuits() {
        let mut rng = SplitMix64::new(16);
        let (mut equal, mut differ) = (0, 0);
        for _ in 0..400 {
            let mut c = Circuit {
                inputs: Vec::new(),
                nodes: Vec::new(),
                outputs: Vec::new(),
            };
            let mut pool = inputs(&mut c, "x", 6);
            pool.push(1);
            for _ in 0..rng.range(1, 30) {
                let pick = |rng: &mut SplitMix64| {
                    pool[rng.below(pool.len() as u64) as usize] ^ rng.bits(1) as Lit
                };
                let (x, y, z) = (pick(&mut rng), pick(&mut rng), pick(&mut rng));
                let l = match rng.below(3) {
                    0 => c.and(x, y),
                    1 => c.xor(x, y),
                    _ => c.mux(x, y, z),
                };
                pool.push(l);
            }
            let word_of = |rng: &mut SplitMix64| -> Vec<Lit> {
                (0..3)
                    .map(|_| pool[rng.below(pool.len() as u64) as usize] ^ rng.bits(1) as Lit)
                    .collect()
            };
            let g = word_of(&mut rng);
            // Half the time the specification is the same word rebuilt through other
            // nodes ((g ^ r) ^ r), so that equal words are common too.
            let s = if rng.chance(1, 2) {
                let mut s = Vec::new();
                for &x in &g {
                    let r = pool[rng.below(pool.len() as u64) as usize];
                    let y = c.xor(x, r);
                    s.push(c.xor(y, r));
                }
                s
            } else {
                word_of(&mut rng)
            };
            c.outputs = vec![g, s];
            let truth = (0..64u32).all(|x| {
                let f: Vec<bool> = (0..6).map(|i| (x >> i) & 1 == 1).collect();
                let o = c.eval(&f);
                word(&o[0]) == word(&o[1])
            });
            match equal_mod(&c, 0, 1, 3).unwrap().0 {
                Verdict::Equal => {
                    assert!(truth);
                    equal += 1;
                }
                Verdict::Differ { input, difference } => {
                    assert!(!truth);
                    let o = c.eval(&input);
                    assert_eq!(word(&o[0]).wrapping_sub(word(&o[1])) & 7, difference);
                    differ += 1;
                }
            }
        }
        // Both verdicts were exercised.
        assert!(equal > 10 && differ > 10, "{equal} equal, {differ} differ");
    }
}
