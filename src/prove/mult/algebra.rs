//! The algebraic engine of `rmapgen prove-mult`: proves that two words of a gate netlist are
//! equal modulo 2^m on every input, by backward rewriting of polynomials, without
//! enumerating the inputs. It is what proves the wide interpolate sums `a0 * (S - w) + a1 *
//! w`, whose 2^34 inputs a weight are too many to evaluate and whose SAT cases take minutes.
//!
//! The method (symbolic computer algebra, as in the multiplier verifiers of Ciesielski et
//! al. and Kaufmann, Biere and Kauers): every Boolean function f of n bits has exactly one
//! multilinear polynomial P over the integers modulo 2^m with P(x) = f(x) on {0,1}^n (the
//! Möbius transform is invertible over any ring). Start from
//! `D = sum 2^i got_i - spec (mod 2^m)`, `spec` another word's bits or a polynomial given
//! outright (`prove-mult` gives the specification's: [`equals_polynomial`]), then replace the
//! latest node by its gate's polynomial (AND: ab, XOR: a + b - 2ab, MUX: a + s(b - a), a
//! complement 1 - x, every x^2 reduced to x), node by node in reverse order, until only
//! inputs are left. The two words agree on every input exactly when what is left is the
//! zero polynomial. When it is not, a monomial of least degree gives a failing input: its
//! variables 1, all others 0, where D equals that monomial's (non-zero) coefficient.
//!
//! Adders keep the polynomial small: a full adder's sum plus twice its carry is exactly a +
//! b + c, so the sums of a tree rewrite into linear forms, provided a half adder's sum is
//! rewritten as `a + b - 2 carry` with its carry's node (XOR rewriting) and terms that
//! vanish (a carry times its own sum) are dropped as they appear. A term limit bounds the
//! memory; a circuit that exceeds it is reported, not guessed.

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
    /// For each variable, nodes it can never be 1 with. A monomial holding such a pair is
    /// the zero function, so it is dropped at once; rewriting would remove it only once both
    /// nodes and everything between them and their operands were substituted, and in the
    /// carry-save rows and carry chains of a multiplier Yosys infers such terms pile up
    /// first (past 2 million terms on an inferred 9 x 9 constant product without this rule).
    /// The pairs: `x & y` and `x ^ y` of the same operands (a half adder's carry and sum),
    /// and an AND node with whatever one of its (uncomplemented) operands excludes (a
    /// ripple carry's `p & c_in` with the generate `g` of the same `p`).
    exclusive: Vec<Vec<u32>>,
}

/// Exclusions kept per node: the nearest ones. Fewer only drops fewer vanishing terms
/// early; it never changes a verdict.
const MAX_EXCLUSIVE: usize = 8;

impl Poly {
    fn vanishes(&self, m: &[u32]) -> bool {
        m.iter().any(|&v| {
            self.exclusive.get(v as usize).is_some_and(|xs| {
                // Largest first: a binary search with the order reversed.
                xs.iter().any(|x| m.binary_search_by(|y| x.cmp(y)).is_ok())
            })
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
    rewrite(c, got, Spec::Word(spec), m, MAX_TERMS)
}

/// Whether output word `got` of `c` equals the polynomial `spec` over the circuit's inputs
/// (monomials of input variables `1..=inputs`, with their coefficients) modulo 2^m on every
/// input. This is how a word-level specification (`a * b + c`) is given without gates: the
/// gates of an inferred product are what made the polynomial blow up (the carry-save rows of
/// Yosys's `$macc` map), and the specification's own polynomial is known outright.
pub fn equals_polynomial(
    c: &Circuit,
    got: usize,
    spec: &[Term],
    m: u32,
) -> Result<(Verdict, Stats)> {
    rewrite(c, got, Spec::Polynomial(spec), m, MAX_TERMS)
}

/// A half adder's carry node, with its two operand literals.
type Carry = (u32, Lit, Lit);

/// A term of a polynomial: its variables (in any order, each at most once) and coefficient.
pub type Term = (Vec<u32>, u64);

/// What `got` is compared with.
enum Spec<'a> {
    Word(usize),
    Polynomial(&'a [Term]),
}

/// Each XOR node's half-adder carry (None: no AND of the same two variables), and for each
/// variable the nodes it can never be 1 with (see [`Poly::exclusive`]), nearest first, at
/// most [`MAX_EXCLUSIVE`] inherited.
fn exclusions(c: &Circuit) -> (Vec<Option<Carry>>, Vec<Vec<u32>>) {
    let base = c.inputs.len() as u32 + 1;
    // For each XOR node, an AND node of the same two variables, either complemented: the
    // half adder it belongs to (Yosys's ripple carries are ORs, so the carry a sum bit
    // reads is often the complement of a node). Of several, the one complemented alike
    // nearest to the XOR: another AND of the same operands elsewhere in the netlist would
    // bring an unrelated node into the polynomial.
    let mut ands: std::collections::HashMap<(u32, u32), Vec<Carry>> = Default::default();
    for (k, n) in c.nodes.iter().enumerate() {
        if let Node::And(a, b) = *n {
            ands.entry((a / 2, b / 2))
                .or_default()
                .push((base + k as u32, a, b));
        }
    }
    let mut carry_of = vec![None; c.nodes.len()];
    let mut exclusive = vec![Vec::new(); (base as usize) + c.nodes.len()];
    for (k, n) in c.nodes.iter().enumerate() {
        if let Node::Xor(a, b) = *n {
            let x = base + k as u32;
            let best = ands.get(&(a / 2, b / 2)).and_then(|v| {
                v.iter()
                    .min_by_key(|(g, la, lb)| ((la ^ lb) & 1, g.abs_diff(x)))
                    .copied()
            });
            if let Some((g, la, lb)) = best {
                carry_of[k] = Some((g, la, lb));
                // `la & lb` and `la ^ lb` are never both 1, and the node is `la ^ lb` when
                // both literals are complemented alike (else it is its complement).
                if la & 1 == lb & 1 {
                    exclusive[g as usize].push(x);
                    exclusive[x as usize].push(g);
                }
            }
        }
    }
    // An AND node is 1 only where its operands are, so it excludes what they exclude.
    for (k, n) in c.nodes.iter().enumerate() {
        if let Node::And(a, b) = *n {
            let x = base + k as u32;
            let mut inherited: Vec<u32> = [a, b]
                .iter()
                .filter(|&&l| l & 1 == 0)
                .flat_map(|&l| exclusive[(l / 2) as usize].clone())
                .filter(|&y| y != x)
                .collect();
            inherited.sort_unstable_by_key(|&y| std::cmp::Reverse(y));
            let own = &mut exclusive[x as usize];
            for y in inherited {
                if own.len() >= MAX_EXCLUSIVE {
                    break;
                }
                if !own.contains(&y) {
                    own.push(y);
                }
            }
        }
    }
    (carry_of, exclusive)
}

/// Rewrites `sum 2^i got_i - spec` down to the inputs (the module documentation), giving up
/// when the polynomial holds more than `max_terms` terms ([`MAX_TERMS`]).
fn rewrite(
    c: &Circuit,
    got: usize,
    spec: Spec,
    m: u32,
    max_terms: usize,
) -> Result<(Verdict, Stats)> {
    if m == 0 || m > 64 {
        bail!("the algebraic engine compares 1 to 64 bits, not {m}");
    }
    let mask = if m == 64 { u64::MAX } else { (1u64 << m) - 1 };
    let base = c.inputs.len() as u32 + 1;
    let (carry_of, exclusive) = exclusions(c);
    let mut p = Poly {
        terms: BTreeMap::new(),
        mask,
        exclusive,
    };
    let mut words = vec![(got, 1u64)];
    match spec {
        Spec::Word(w) => words.push((w, u64::MAX)),
        Spec::Polynomial(terms) => {
            for (vars, coeff) in terms {
                if let Some(v) = vars.iter().find(|&&v| v == 0 || v > c.inputs.len() as u32) {
                    bail!("the specification names variable {v}, not an input of the circuit");
                }
                let mut mono = vars.clone();
                mono.sort_unstable_by(|a, b| b.cmp(a));
                mono.dedup();
                p.add(mono, coeff.wrapping_neg());
            }
        }
    }
    for (k, sign) in words {
        for (i, &l) in c.outputs[k].iter().enumerate().take(m as usize) {
            p.add_lit(l, sign.wrapping_mul(1u64 << i));
        }
    }
    let inputs = c.inputs.len() as u32;
    let mut stats = Stats::default();
    loop {
        stats.peak = stats.peak.max(p.terms.len());
        if p.terms.len() > max_terms {
            bail!(
                "the polynomial grew past {max_terms} terms after {} of {} nodes: this netlist needs another engine",
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
        let g = match carry_of[(v - base) as usize] {
            // A half adder's sum is la + lb - 2 * carry, its carry's own node standing for
            // la * lb (or the complement, 1 - la - lb + 2 * carry, when the node is the
            // complement of the sum). That keeps the rewriting linear through the adders of
            // a correct multiplier, where each carry then cancels against the next
            // column's sum (XOR rewriting, after Kaufmann, Biere and Kauers). Either form
            // is exact on {0,1}; with la * lb instead, every row multiplied its operands out
            // and the polynomials of inferred products grew past the term limit. The
            // carry, if it is a later node, is the largest variable left and is
            // substituted next.
            Some((carry, la, lb)) => {
                let (pa, pb) = (lit_poly(la), lit_poly(lb));
                let t: Small = vec![(vec![carry], 1)];
                if la & 1 == lb & 1 {
                    lin(&[(&pa, 1), (&pb, 1), (&t, 2u64.wrapping_neg())])
                } else {
                    let one: Small = vec![(vec![], 1)];
                    lin(&[(&one, 1), (&pa, u64::MAX), (&pb, u64::MAX), (&t, 2)])
                }
            }
            None => node_poly(node),
        };
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

    /// The exclusions as documented, read directly (a wrong choice here only slows the
    /// rewriting, so the verdict tests cannot see it): a sum's carry is the AND of its
    /// operands complemented alike, the nearest of those, even where an AND complemented
    /// otherwise is nearer; the pair excludes each other; an AND node inherits what its
    /// uncomplemented operands exclude, each node once, the nearest [`MAX_EXCLUSIVE`].
    #[test]
    fn exclusions_pair_sums_with_carries_and_pass_on_to_ands() {
        let mut c = Circuit {
            inputs: Vec::new(),
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let ab = inputs(&mut c, "a", 2);
        let z = inputs(&mut c, "z", 1)[0];
        let (a, b) = (ab[0], ab[1]);
        let x = c.xor(a, b);
        let mixed = c.and(a, b ^ 1);
        let _other = c.and(a, z);
        let k = c.and(a ^ 1, b ^ 1);
        let n = c.and(k, z);
        let nc = c.and(k ^ 1, z);
        let nn = c.and(n, k);
        let far = c.and(a, b);
        let (carry, ex) = exclusions(&c);
        let node = |l: Lit| l / 2;
        let idx = |l: Lit| (node(l) - 4) as usize;
        // Among the alike ANDs (a & b, !a & !b) the nearest, not the nearer mixed one.
        assert_eq!(carry[idx(x)], Some((node(k), a ^ 1, b ^ 1)));
        assert!(ex[node(far) as usize].is_empty());
        assert!(ex[node(x) as usize].contains(&node(k)));
        assert_eq!(ex[node(k) as usize], vec![node(x)]);
        assert!(!ex[node(mixed) as usize].contains(&node(x)));
        assert_eq!(ex[node(n) as usize], vec![node(x)]);
        assert!(
            ex[node(nc) as usize].is_empty(),
            "{:?}",
            ex[node(nc) as usize]
        );
        // From both operands, once.
        assert_eq!(ex[node(nn) as usize], vec![node(x)]);

        // Ten half adders, and an AND of all their carries: it keeps the nearest eight.
        let mut c = Circuit {
            inputs: Vec::new(),
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let v = inputs(&mut c, "v", 20);
        let mut sums = Vec::new();
        let mut acc = 1;
        for i in 0..10 {
            sums.push(c.xor(v[2 * i], v[2 * i + 1]));
            let k = c.and(v[2 * i], v[2 * i + 1]);
            acc = c.and(acc, k);
        }
        let (_, ex) = exclusions(&c);
        let mut want: Vec<u32> = sums
            .iter()
            .map(|&s| s / 2)
            .rev()
            .take(MAX_EXCLUSIVE)
            .collect();
        want.sort_unstable_by(|p, q| q.cmp(p));
        assert_eq!(ex[(acc / 2) as usize], want);
    }

    /// The term limit: a rewriting whose polynomial peaks at P terms passes with a limit of
    /// P and is refused, in one message naming the limit, with any limit below it.
    #[test]
    fn the_term_limit_is_the_largest_polynomial_allowed() {
        let c = products(None);
        let (v, s) = rewrite(&c, 0, Spec::Word(1), 7, MAX_TERMS).unwrap();
        assert_eq!(v, Verdict::Equal);
        assert_eq!(
            rewrite(&c, 0, Spec::Word(1), 7, s.peak).unwrap().0,
            Verdict::Equal
        );
        for limit in 1..s.peak {
            let e = rewrite(&c, 0, Spec::Word(1), 7, limit).unwrap_err();
            assert!(
                e.to_string()
                    .contains(&format!("the polynomial grew past {limit} terms")),
                "{e}"
            );
        }
    }

    /// An AND node inherits the exclusions of its uncomplemented operands only. With the
    /// half adder k = a & b, s = a ^ b (never both 1), n = !k & x can be 1 with s (a = 1,
    /// b = 0, x = 1): the term n * s of y = n & s must stay, and y differs from 0.
    #[test]
    fn a_complemented_operand_passes_on_no_exclusions() {
        let mut c = Circuit {
            inputs: Vec::new(),
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let ab = inputs(&mut c, "a", 2);
        let x = inputs(&mut c, "x", 1)[0];
        let s = c.xor(ab[0], ab[1]);
        let k = c.and(ab[0], ab[1]);
        let n = c.and(k ^ 1, x);
        let y = c.and(n, s);
        c.outputs = vec![vec![y], vec![0]];
        let (v, _) = equal_mod(&c, 0, 1, 1).unwrap();
        let Verdict::Differ { input, .. } = v else {
            panic!("y is 1 at a = 1, b = 0, x = 1, and the rewriting said {v:?}");
        };
        assert!(c.eval(&input)[0][0], "{input:?}");
    }

    /// Widths outside 1..=64 are refused (64 is taken); and the half adders' exclusions
    /// drop the terms that vanish as they appear, so the polynomial of the 4 x 3 product
    /// never holds more than 24 terms (without the rule it holds more: the rule is what
    /// keeps inferred multipliers tractable, src/prove/mult/algebra.rs `Poly::vanishes`).
    #[test]
    fn widths_are_bounded_and_vanishing_terms_are_dropped_early() {
        let c = products(None);
        for m in [0, 65] {
            let e = equal_mod(&c, 0, 1, m).unwrap_err();
            assert!(e.to_string().contains("1 to 64 bits"), "{e}");
        }
        assert_eq!(equal_mod(&c, 0, 1, 64).unwrap().0, Verdict::Equal);
        // 24 with the rule, 26 without (measured).
        let (_, s) = equal_mod(&c, 0, 1, 7).unwrap();
        assert!(s.peak <= 24, "peak {}", s.peak);
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

    /// `a * b` (vars 1..=4 and 5..=7 of [`products`]) as a polynomial.
    fn product_polynomial() -> Vec<Term> {
        let mut t = Vec::new();
        for i in 0..4u32 {
            for j in 0..3u32 {
                t.push((vec![i + 1, 5 + j], 1u64 << (i + j)));
            }
        }
        t
    }

    #[test]
    fn a_product_equals_its_polynomial_and_a_dropped_carry_does_not() {
        // Word 1 of `products` is the one with the fault: compare it with the polynomial.
        let (v, _) = equals_polynomial(&products(None), 1, &product_polynomial(), 7).unwrap();
        assert_eq!(v, Verdict::Equal);
        let mut caught = 0;
        for bit in 0..6 {
            let c = products(Some(bit));
            let (v, _) = equals_polynomial(&c, 1, &product_polynomial(), 7).unwrap();
            let truth = |f: &[bool]| {
                let (a, b) = (word(&f[..4]), word(&f[4..]));
                (a * b) & 127
            };
            match v {
                Verdict::Equal => assert!((0..128u32).all(|x| {
                    let f: Vec<bool> = (0..7).map(|i| (x >> i) & 1 == 1).collect();
                    word(&c.eval(&f)[1]) == truth(&f)
                })),
                Verdict::Differ { input, difference } => {
                    let got = word(&c.eval(&input)[1]);
                    assert_eq!(
                        got.wrapping_sub(truth(&input)) & 127,
                        difference,
                        "carry {bit}"
                    );
                    caught += 1;
                }
            }
        }
        // The others are carries that cannot be 1 there (shown harmless by evaluation above).
        assert!(caught >= 3, "only {caught} dropped carries caught");
        // A wrong specification is caught too: one coefficient off.
        let mut wrong = product_polynomial();
        wrong[5].1 += 1;
        let (v, _) = equals_polynomial(&products(None), 0, &wrong, 7).unwrap();
        assert!(matches!(v, Verdict::Differ { .. }));
        // A variable that is not an input is refused, not treated as a node.
        assert!(equals_polynomial(&products(None), 0, &[(vec![8], 1)], 7).is_err());
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
                let l = match rng.below(4) {
                    0 => c.and(x, y),
                    1 => c.xor(x, y),
                    2 => c.mux(x, y, z),
                    _ => {
                        // A half adder, its AND's operands complemented alike or not (the
                        // XOR rewriting's and the exclusion's cases): both nodes kept.
                        let n = rng.bits(2) as Lit;
                        let carry = c.and(x ^ (n & 1), y ^ (n >> 1));
                        pool.push(carry);
                        c.xor(x, y)
                    }
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
