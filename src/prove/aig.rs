//! The exhaustive engine of `rmapgen prove-mult`: a tree's miter, cut and made combinational
//! by the same Yosys steps as for the SAT engine, is written as an and-inverter graph (Yosys
//! `aigmap; write_aiger -ascii -map`) and evaluated here on every input, 512 at a time
//! (bit-parallel: one bit of a machine word per input).
//!
//! Why: for a product of a wide symbolic factor and a split constant (the widest grid row's
//! normalise tree, 20 x 12 bits), each SAT case takes about 16 s of CPU (both sides are sums
//! of shifted copies of the factor, associated differently, and CDCL reasons through every
//! carry), 8,192 cases a row: over a day. Evaluating the graph on all 2^32 inputs takes
//! minutes. For every input the miter's `ok` must be 1, which is the same statement the SAT
//! engine proves, over the same netlist.
//!
//! Each case of the split fixes some inputs; the graph is first simplified for those
//! constants (constant propagation only: an AND with a 0 input is 0, with a 1 input is its
//! other input), then every value of the remaining inputs is applied.

use anyhow::{bail, Context, Result};
use rayon::prelude::*;

/// Machine words per evaluation block: 8 x 64 = 512 inputs at once.
const WORDS: usize = 8;
/// Inputs per block.
const BLOCK_BITS: u32 = 9;

/// An and-inverter graph with named inputs and outputs.
#[derive(Clone, Debug)]
pub struct Aig {
    /// For each input (in AIGER order): its signal name and bit.
    pub inputs: Vec<(String, u32)>,
    /// For each output (in AIGER order): its signal name and bit. The name is empty when
    /// the map does not list the output: Yosys leaves out an output driven by a constant
    /// (a planted fault can make a miter's `ok` the constant 0).
    pub outputs: Vec<(String, u32)>,
    /// Variable of each input (the AIGER literal / 2).
    input_vars: Vec<u32>,
    /// AND gates in topological order: (lhs variable, rhs literal, rhs literal).
    ands: Vec<(u32, u32, u32)>,
    /// The output literals, in AIGER order.
    output_lits: Vec<u32>,
    max_var: u32,
}

fn num(s: Option<&str>, what: &str) -> Result<u32> {
    s.with_context(|| format!("missing {what}"))?
        .parse::<u32>()
        .with_context(|| format!("bad {what}"))
}

impl Aig {
    /// Parses Yosys's ASCII AIGER (`aag M I L O A`, no latches) and its `-map` file
    /// (`input INDEX BIT NAME`, `output INDEX BIT NAME`).
    pub fn parse(aag: &str, map: &str) -> Result<Aig> {
        let mut lines = aag.lines();
        let head: Vec<&str> = lines
            .next()
            .context("empty AIGER file")?
            .split_whitespace()
            .collect();
        if head.len() != 6 || head[0] != "aag" {
            bail!("not an ASCII AIGER header: {}", head.join(" "));
        }
        let n: Vec<u32> = head[1..]
            .iter()
            .map(|s| s.parse().context("bad AIGER header"))
            .collect::<Result<_>>()?;
        let (max_var, ni, nl, no, na) = (n[0], n[1], n[2], n[3], n[4]);
        if nl != 0 {
            bail!("{nl} latches: the miter must be combinational");
        }
        let mut input_vars = Vec::with_capacity(ni as usize);
        for _ in 0..ni {
            let lit = num(lines.next(), "input literal")?;
            if lit & 1 == 1 || lit == 0 || lit / 2 > max_var {
                bail!("bad input literal {lit}");
            }
            input_vars.push(lit / 2);
        }
        let mut output_lits = Vec::with_capacity(no as usize);
        for _ in 0..no {
            let lit = num(lines.next(), "output literal")?;
            if lit / 2 > max_var {
                bail!("output literal {lit} out of range");
            }
            output_lits.push(lit);
        }
        let mut ands = Vec::with_capacity(na as usize);
        for _ in 0..na {
            let l = lines.next().context("missing AND gate")?;
            let mut it = l.split_whitespace();
            let (lhs, a, b) = (
                num(it.next(), "AND lhs")?,
                num(it.next(), "AND rhs")?,
                num(it.next(), "AND rhs")?,
            );
            // AIGER's ASCII form lists gates after their inputs (lhs > rhs), which the
            // evaluation below relies on.
            if lhs & 1 == 1 || lhs / 2 > max_var || a >= lhs || b >= lhs {
                bail!("AND gate {l} out of order");
            }
            ands.push((lhs / 2, a, b));
        }
        let mut inputs = vec![(String::new(), 0); ni as usize];
        let mut outputs = vec![(String::new(), 0); no as usize];
        let (mut named_in, mut named_out) = (0, 0usize);
        for l in map.lines() {
            let f: Vec<&str> = l.split_whitespace().collect();
            if f.len() != 4 || (f[0] != "input" && f[0] != "output") {
                continue;
            }
            let i: usize = f[1].parse().context("bad map index")?;
            let bit: u32 = f[2].parse().context("bad map bit")?;
            let (list, count) = if f[0] == "input" {
                (&mut inputs, &mut named_in)
            } else {
                (&mut outputs, &mut named_out)
            };
            let total = list.len();
            let slot = list
                .get_mut(i)
                .with_context(|| format!("map names {} {i} of {total}", f[0]))?;
            // Yosys 0.23 numbers two output ports on one net with one index (and skips
            // another): such a map cannot say which literal is which port.
            if !slot.0.is_empty() {
                bail!("the map names {} {i} twice ({} and {})", f[0], slot.0, f[3]);
            }
            *slot = (f[3].to_string(), bit);
            *count += 1;
        }
        if named_in != ni as usize {
            bail!("the map names {named_in} of {ni} inputs");
        }
        Ok(Aig {
            inputs,
            outputs,
            input_vars,
            ands,
            output_lits,
            max_var,
        })
    }

    /// The one output of a miter (its `ok`).
    fn single_output(&self) -> Result<u32> {
        match self.output_lits[..] {
            [lit] => Ok(lit),
            _ => bail!("{} outputs: the miter has one (ok)", self.output_lits.len()),
        }
    }

    /// AND gates.
    pub fn gates(&self) -> usize {
        self.ands.len()
    }

    /// Whether input `i` drives any gate or output (an unused port, such as the miter's
    /// clock once the registers are wires, cannot change `ok`).
    pub fn used(&self) -> Vec<bool> {
        let mut used = vec![false; self.max_var as usize + 1];
        for &o in &self.output_lits {
            used[(o / 2) as usize] = true;
        }
        for &(_, a, b) in &self.ands {
            used[(a / 2) as usize] = true;
            used[(b / 2) as usize] = true;
        }
        self.input_vars.iter().map(|&v| used[v as usize]).collect()
    }
}

/// Literal of the compiled program: variable * 2 + negation; 0 is false, 1 is true.
type Lit = u32;

/// The graph simplified for one case: free inputs are variables 1..=free, then the gates.
pub struct Program {
    /// (lhs variable, a, b) with a, b literals of earlier variables.
    gates: Vec<(u32, Lit, Lit)>,
    /// Every output of the graph, in AIGER order.
    outputs: Vec<Lit>,
    /// Free inputs (variables 1..=free).
    free: usize,
    vars: usize,
}

/// Simplifies `aig` for the inputs `fixed` gives a value: input `i` with `fixed[i] ==
/// Some(b)` is the constant b, the `k`-th input of `free` becomes the program's free input
/// k; an input in neither drives nothing (see [`Aig::used`]).
pub fn compile(aig: &Aig, fixed: &[Option<bool>], free: &[usize]) -> Program {
    const NONE: Lit = u32::MAX;
    let mut map = vec![NONE; aig.max_var as usize + 1];
    map[0] = 0;
    for (i, &v) in aig.input_vars.iter().enumerate() {
        map[v as usize] = match fixed[i] {
            Some(b) => b as Lit,
            None => 0, // an unused input: it drives nothing
        };
    }
    for (k, &i) in free.iter().enumerate() {
        map[aig.input_vars[i] as usize] = 2 * (k as u32 + 1);
    }
    let lit = |map: &[Lit], l: u32| map[(l / 2) as usize] ^ (l & 1);
    let mut gates = Vec::new();
    let mut next = free.len() as u32 + 1;
    for &(lhs, a, b) in &aig.ands {
        let (x, y) = (lit(&map, a), lit(&map, b));
        map[lhs as usize] = if x == 0 || y == 0 || x == (y ^ 1) {
            0
        } else if x == 1 {
            y
        } else if y == 1 || x == y {
            x
        } else {
            gates.push((next, x, y));
            next += 1;
            2 * (next - 1)
        };
    }
    Program {
        outputs: aig.output_lits.iter().map(|&o| lit(&map, o)).collect(),
        free: free.len(),
        gates,
        vars: next as usize,
    }
}

impl Program {
    /// AND gates left after the constants.
    pub fn gates(&self) -> usize {
        self.gates.len()
    }

    /// Evaluates the program on `W * 64` inputs at once (bit-parallel: one bit of each word
    /// per input): free input `j` takes the words `free(j)`; `out[o]` receives output o's
    /// words. `vals` is scratch space, reused between calls.
    pub fn eval<const W: usize>(
        &self,
        vals: &mut Vec<[u64; W]>,
        free: impl Fn(usize) -> [u64; W],
        out: &mut [[u64; W]],
    ) {
        vals.resize(self.vars, [0; W]);
        vals[0] = [0; W];
        for j in 0..self.free {
            vals[j + 1] = free(j);
        }
        for &(v, a, b) in &self.gates {
            let (x, y) = (word(vals, a), word(vals, b));
            vals[v as usize] = std::array::from_fn(|k| x[k] & y[k]);
        }
        for (o, &l) in out.iter_mut().zip(&self.outputs) {
            *o = word(vals, l);
        }
    }
}

/// The words of literal `l`: its variable's, complemented when `l` is odd. Variable 0 is
/// the constant false (its words stay 0).
#[inline(always)]
fn word<const W: usize>(vals: &[[u64; W]], l: Lit) -> [u64; W] {
    let m = if l & 1 == 1 { !0 } else { 0 };
    let v = &vals[(l / 2) as usize];
    std::array::from_fn(|k| v[k] ^ m)
}

/// The words of bit `b` of the input number, for the `W * 64` inputs numbered `first + w * 64
/// + lane` (word w, bit lane): laying consecutive input numbers out one per bit.
pub fn number_bit<const W: usize>(b: u32, first: u64) -> [u64; W] {
    const LANE: [u64; 6] = [
        0xAAAA_AAAA_AAAA_AAAA,
        0xCCCC_CCCC_CCCC_CCCC,
        0xF0F0_F0F0_F0F0_F0F0,
        0xFF00_FF00_FF00_FF00,
        0xFFFF_0000_FFFF_0000,
        0xFFFF_FFFF_0000_0000,
    ];
    debug_assert_eq!(first % 64, 0, "inputs start at a word");
    std::array::from_fn(|w| {
        if b < 6 {
            LANE[b as usize]
        } else {
            0u64.wrapping_sub(((first + 64 * w as u64) >> b) & 1)
        }
    })
}

/// Runs `p` on every value of its free inputs; the first input number (block * 512 + lane)
/// where the output is 0, if any.
fn sweep(p: &Program, free: usize) -> Option<u64> {
    let mut vals = vec![[0u64; WORDS]; p.vars];
    let blocks = 1u64 << free.saturating_sub(BLOCK_BITS as usize);
    // Fewer than 512 inputs: only the first 2^free lanes of the one block are inputs.
    let valid = if free >= BLOCK_BITS as usize {
        [!0u64; WORDS]
    } else {
        let n = 1usize << free;
        std::array::from_fn(|w| {
            let lanes = n.saturating_sub(w * 64).min(64);
            if lanes == 64 {
                !0
            } else {
                (1u64 << lanes) - 1
            }
        })
    };
    let mut out = [[0u64; WORDS]];
    for block in 0..blocks {
        p.eval(
            &mut vals,
            |j| number_bit(j as u32, block << BLOCK_BITS),
            &mut out,
        );
        let out = out[0];
        for w in 0..WORDS {
            let bad = !out[w] & valid[w];
            if bad != 0 {
                return Some((block << BLOCK_BITS) + (w as u64) * 64 + bad.trailing_zeros() as u64);
            }
        }
    }
    None
}

/// A failing input: each signal's value.
pub type Assignment = Vec<(String, u128)>;

/// Refuses a case that sets a signal the miter does not have as an input (`is_input`): the
/// engines would otherwise prove the miter with that signal left free or unset, not the case.
pub fn cases_name_inputs(
    cases: &[Vec<(String, u128)>],
    is_input: impl Fn(&str) -> bool,
) -> Result<()> {
    for case in cases {
        for (s, _) in case {
            if !is_input(s) {
                bail!("the case signal {s} is not an input of the miter");
            }
        }
    }
    Ok(())
}

/// Evaluates `aig` on every input: for each case (values of some signals, the rest
/// enumerated). Returns the first failing input (cases in order, then input order), or None
/// when `ok` is 1 everywhere. Signals named in a case must be inputs of the graph.
pub fn exhaustive(aig: &Aig, cases: &[Vec<(String, u128)>]) -> Result<Option<Assignment>> {
    aig.single_output()?;
    let used = aig.used();
    cases_name_inputs(cases, |s| aig.inputs.iter().any(|(n, _)| n == s))?;
    let failure = cases
        .par_iter()
        .map(|case| {
            let fixed: Vec<Option<bool>> = aig
                .inputs
                .iter()
                .map(|(n, bit)| {
                    case.iter()
                        .find(|(s, _)| s == n)
                        .map(|&(_, v)| (v >> bit) & 1 == 1)
                })
                .collect();
            let free: Vec<usize> = (0..aig.inputs.len())
                .filter(|&i| fixed[i].is_none() && used[i])
                .collect();
            let p = compile(aig, &fixed, &free);
            sweep(&p, free.len()).map(|n| {
                // The failing input's value of every signal.
                let mut sigs: Assignment = Vec::new();
                for (i, (name, bit)) in aig.inputs.iter().enumerate() {
                    let b = match fixed[i] {
                        Some(b) => b,
                        None => free
                            .iter()
                            .position(|&f| f == i)
                            .is_some_and(|k| (n >> k) & 1 == 1),
                    };
                    match sigs.iter_mut().find(|(s, _)| s == name) {
                        Some((_, v)) => *v |= (b as u128) << bit,
                        None => sigs.push((name.clone(), (b as u128) << bit)),
                    }
                }
                sigs
            })
        })
        .find_map_first(|f| f);
    Ok(failure)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_case_naming_a_signal_the_miter_lacks_is_refused() {
        let cases = vec![vec![("w".to_string(), 3)], vec![("wc".to_string(), 1)]];
        let err = cases_name_inputs(&cases, |s| s == "w").unwrap_err();
        assert!(err.to_string().contains("case signal wc"), "{err}");
        cases_name_inputs(&cases, |s| s == "w" || s == "wc").unwrap();
    }

    /// `ok = x XOR y`, built by hand: false at x = y.
    fn xor_aig() -> (String, String) {
        // ok = x XOR y over two inputs: 1 = x (var 1), 2 = y (var 2);
        // 3 = x & !y, 4 = !x & y, 5 = !3 & !4 (XNOR), output !5.
        let aag = "aag 5 2 0 1 3\n2\n4\n11\n6 2 5\n8 3 4\n10 7 9\n";
        let map = "input 0 0 x\ninput 1 0 y\noutput 0 0 ok\n";
        (aag.into(), map.into())
    }

    #[test]
    fn finds_the_one_failing_input_and_names_it() {
        let (aag, map) = xor_aig();
        let g = Aig::parse(&aag, &map).unwrap();
        assert_eq!(g.gates(), 3);
        // XOR fails only at x = y: the first input in order is x = 0, y = 0.
        let f = exhaustive(&g, &[Vec::new()]).unwrap().unwrap();
        assert_eq!(f, vec![("x".into(), 0), ("y".into(), 0)]);
        // With x = 1 fixed, y = 1 fails.
        let f = exhaustive(&g, &[vec![("x".into(), 1)]]).unwrap().unwrap();
        assert_eq!(f, vec![("x".into(), 1), ("y".into(), 1)]);
    }

    #[test]
    fn a_tautology_over_many_inputs_passes_and_one_wrong_minterm_fails() {
        // ok = !(AND of the twelve bits of x): false only at x = 4095, in the last block of
        // eight (so the sweep must reach blocks past the first).
        let (aag, map) = nand_of(12);
        let g = Aig::parse(&aag, &map).unwrap();
        let f = exhaustive(&g, &[Vec::new()]).unwrap().unwrap();
        assert_eq!(f, vec![("x".into(), 4095)]);
        // A case fixing x = 0 leaves nothing to enumerate, and ok is 1 there.
        let none = exhaustive(&g, &[vec![("x".into(), 0)]]).unwrap();
        assert_eq!(none, None);
    }

    /// With 6 to 8 free inputs the one block is filled a whole 64-lane word at a time: the
    /// failure at the last input, in the last full word, is found (cargo-mutants: `lanes ==
    /// 64` inverted, or `!0` made 0, left full words unchecked: a false pass in a release
    /// build, where the shift by 64 wraps).
    #[test]
    fn a_failure_in_the_last_full_word_of_a_small_block_is_found() {
        for n in [6u32, 7, 8] {
            let (aag, map) = nand_of(n);
            let g = Aig::parse(&aag, &map).unwrap();
            let f = exhaustive(&g, &[Vec::new()]).unwrap();
            assert_eq!(f, Some(vec![("x".into(), (1u128 << n) - 1)]), "{n} inputs");
        }
    }

    /// ok = !(AND of the n bits of x), input x: false only at x = 2^n - 1.
    fn nand_of(n: u32) -> (String, String) {
        let mut aag = format!("aag {} {n} 0 1 {}\n", 2 * n - 1, n - 1);
        for i in 1..=n {
            aag += &format!("{}\n", 2 * i);
        }
        aag += &format!("{}\n", 2 * (2 * n - 1) + 1);
        let mut prev = 2;
        for k in 0..n - 1 {
            let lhs = 2 * (n + 1 + k);
            aag += &format!("{lhs} {} {prev}\n", 2 * (k + 2));
            prev = lhs;
        }
        let mut map: String = (0..n).map(|i| format!("input {i} {i} x\n")).collect();
        map += "output 0 0 ok\n";
        (aag, map)
    }

    /// Each check of an AND gate refuses on its own: an odd (negated) left side, a variable
    /// past the header's maximum, and an input that is not an earlier literal (either side).
    #[test]
    fn refuses_each_malformed_and_gate() {
        let head = "aag 3 2 0 1 1\n2\n4\n6\n";
        let map = "input 0 0 x\ninput 1 0 y\noutput 0 0 ok\n";
        Aig::parse(&format!("{head}6 2 4\n"), map).unwrap();
        for gate in ["7 2 4", "8 2 4", "6 6 4", "6 2 7"] {
            let e = Aig::parse(&format!("{head}{gate}\n"), map).err();
            let e = e.unwrap_or_else(|| panic!("{gate} was taken"));
            assert!(e.to_string().contains("out of order"), "{gate}: {e}");
        }
    }

    /// Each check of the parser refuses what it exists for, with its message, and takes the
    /// limits it allows (an output literal of the last variable, a map line of another kind).
    /// The file comes from Yosys, but an engine that reads a wrong literal proves the wrong
    /// circuit.
    #[test]
    fn refuses_each_malformed_header_literal_and_map() {
        let body = "2\n4\n6\n6 2 4\n";
        let head = "aag 3 2 0 1 1\n";
        let map = "input 0 0 x\ninput 1 0 y\noutput 0 0 ok\n";
        let take = |aag: &str, map: &str| Aig::parse(aag, map).unwrap();
        take(&format!("{head}{body}"), map);
        // Output 7 is !var 3, the last variable; lines of another kind or length are skipped.
        take(&format!("{head}2\n4\n7\n6 2 4\n"), map);
        take(
            &format!("{head}{body}"),
            &format!("wire 0 0 q\ninput 0 0\n{map}"),
        );
        let refused = [
            (
                "aag 3 2 0 1\n".to_string() + body,
                map,
                "not an ASCII AIGER header",
            ),
            (
                "aag 3 2 0 1 1 1\n".to_string() + body,
                map,
                "not an ASCII AIGER header",
            ),
            (
                "aig 3 2 0 1 1\n".to_string() + body,
                map,
                "not an ASCII AIGER header",
            ),
            (
                "aag 3 x 0 1 1\n".to_string() + body,
                map,
                "bad AIGER header",
            ),
            (
                format!("{head}3\n4\n6\n6 2 4\n"),
                map,
                "bad input literal 3",
            ),
            (
                format!("{head}0\n4\n6\n6 2 4\n"),
                map,
                "bad input literal 0",
            ),
            (
                format!("{head}2\n8\n6\n6 2 4\n"),
                map,
                "bad input literal 8",
            ),
            (
                format!("{head}2\n4\n8\n6 2 4\n"),
                map,
                "output literal 8 out of range",
            ),
            (format!("{head}2\n4\n"), map, "missing output literal"),
            (format!("{head}2\n4\n6\n6 2\n"), map, "missing AND rhs"),
            (
                format!("{head}{body}"),
                "input 0 0 x\noutput 0 0 ok\n",
                "names 1 of 2 inputs",
            ),
            (
                format!("{head}{body}"),
                "input 0 0 x\ninput 0 0 y\n",
                "names input 0 twice",
            ),
            (
                format!("{head}{body}"),
                "input 0 0 x\ninput 2 0 y\n",
                "map names input 2 of 2",
            ),
            (
                format!("{head}{body}"),
                "input 0 0 x\ninput 1 0 y\noutput 0 0 a\noutput 0 0 b\n",
                "names output 0 twice",
            ),
            (
                format!("{head}{body}"),
                "input 0 0 x\ninput z 0 y\n",
                "bad map index",
            ),
            (
                format!("{head}{body}"),
                "input 0 0 x\ninput 1 z y\n",
                "bad map bit",
            ),
        ];
        for (aag, map, want) in refused {
            let e = Aig::parse(&aag, map).err();
            let e = e.unwrap_or_else(|| panic!("taken: {aag} / {map}"));
            assert!(format!("{e:#}").contains(want), "{want}: {e:#}");
        }
    }

    /// A miter has one output (its `ok`); two are refused before any evaluation.
    #[test]
    fn a_miter_with_two_outputs_is_refused() {
        let aag = "aag 3 2 0 2 1\n2\n4\n6\n7\n6 2 4\n";
        let map = "input 0 0 x\ninput 1 0 y\noutput 0 0 ok\noutput 1 0 ok2\n";
        let g = Aig::parse(aag, map).unwrap();
        let e = exhaustive(&g, &[Vec::new()]).unwrap_err();
        assert!(e.to_string().contains("2 outputs"), "{e}");
    }

    /// An input is used when a gate reads it on either side or an output is it; the others
    /// (z here) are not.
    #[test]
    fn used_inputs_are_those_a_gate_or_output_reads() {
        let map = "input 0 0 x\ninput 1 0 y\ninput 2 0 z\noutput 0 0 ok\n";
        // y only as the first operand, x only as the second.
        let g = Aig::parse("aag 4 3 0 1 1\n2\n4\n6\n8\n8 4 2\n", map).unwrap();
        assert_eq!(g.used(), vec![true, true, false]);
        // x only as the second operand, y only as the first (the other order).
        let g = Aig::parse("aag 4 3 0 1 1\n2\n4\n6\n8\n8 2 4\n", map).unwrap();
        assert_eq!(g.used(), vec![true, true, false]);
        // z only as the output.
        let g = Aig::parse("aag 3 3 0 1 0\n2\n4\n6\n6\n", map).unwrap();
        assert_eq!(g.used(), vec![false, false, true]);
    }

    /// Compiling folds constants: an AND with a fixed 0, x AND NOT x (0), NOT a AND NOT a
    /// (NOT a); a gate of two free inputs stays. The folded program computes the same values.
    #[test]
    fn compile_folds_constants_and_keeps_the_values() {
        // a = var 1, b = var 2; 6 = !a & !a, 8 = a & !a, 10 = a & b; outputs 6, 8, 10.
        let aag = "aag 5 2 0 3 3\n2\n4\n6\n8\n10\n6 3 3\n8 2 3\n10 2 4\n";
        let map = "input 0 0 a\ninput 1 0 b\noutput 0 0 o1\noutput 1 0 o2\noutput 2 0 o3\n";
        let g = Aig::parse(aag, map).unwrap();
        let run = |p: &Program, free: &[u64]| {
            let mut vals = Vec::new();
            let mut out = [[0u64; 1]; 3];
            p.eval(&mut vals, |j| [free[j]], &mut out);
            out.map(|o| o[0])
        };
        // b fixed to 0: every gate folds.
        let p = compile(&g, &[None, Some(false)], &[0]);
        assert_eq!(p.gates(), 0);
        let [o1, o2, o3] = run(&p, &[0b10]);
        assert_eq!((o1 & 0b11, o2 & 0b11, o3 & 0b11), (0b01, 0, 0));
        // Both free: a & b stays a gate.
        let p = compile(&g, &[None, None], &[0, 1]);
        assert_eq!(p.gates(), 1);
        let [o1, o2, o3] = run(&p, &[0b1010, 0b1100]);
        assert_eq!((o1 & 0xf, o2 & 0xf, o3 & 0xf), (0b0101, 0, 0b1000));
        // A complemented reference to a folded literal is its complement: a fixed to 1 makes
        // !a the constant 0 (so 8 = a & !a and 10's twin below fold to 0), and a gate folded to
        // !b read complemented is b. (cargo-mutants: `^` -> `|` in `lit` kept !1 as 1 and
        // !!b as !b.)
        // 6 = !a & b, 8 = 1-of-a & !b = !b with a = 1, 10 = !8 & b = b & b.
        let aag = "aag 5 2 0 2 3\n2\n4\n6\n10\n6 3 4\n8 2 5\n10 9 4\n";
        let map = "input 0 0 a\ninput 1 0 b\noutput 0 0 o1\noutput 1 0 o2\n";
        let g = Aig::parse(aag, map).unwrap();
        let p = compile(&g, &[Some(true), None], &[1]);
        let mut vals = Vec::new();
        let mut out = [[0u64; 1]; 2];
        p.eval(&mut vals, |_| [0b10], &mut out);
        assert_eq!((out[0][0] & 0b11, out[1][0] & 0b11), (0, 0b10));
    }

    /// With fewer free inputs than a block holds, every input counts, the last one too:
    /// ok = NOT (x AND y) fails only at input 3.
    #[test]
    fn a_failure_at_the_last_of_a_few_inputs_is_found() {
        let aag = "aag 3 2 0 1 1\n2\n4\n7\n6 2 4\n";
        let map = "input 0 0 x\ninput 1 0 y\noutput 0 0 ok\n";
        let g = Aig::parse(aag, map).unwrap();
        let f = exhaustive(&g, &[Vec::new()]).unwrap();
        assert_eq!(f, Some(vec![("x".into(), 1), ("y".into(), 1)]));
    }

    /// A case fixes every bit of a wide signal: ok = NOT (s[1] AND x) fails with s = 2 fixed
    /// and passes with s = 1 fixed.
    #[test]
    fn a_case_fixes_the_high_bits_of_a_signal() {
        let aag = "aag 4 3 0 1 1\n2\n4\n6\n9\n8 4 6\n";
        let map = "input 0 0 s\ninput 1 1 s\ninput 2 0 x\noutput 0 0 ok\n";
        let g = Aig::parse(aag, map).unwrap();
        let f = exhaustive(&g, &[vec![("s".into(), 2)]]).unwrap();
        assert_eq!(f, Some(vec![("s".into(), 2), ("x".into(), 1)]));
        assert_eq!(exhaustive(&g, &[vec![("s".into(), 1)]]).unwrap(), None);
        // A signal whose first input bit is not bit 0 is reported at its own bit: s = 2, not
        // 0 (cargo-mutants: `<<` -> `>>` where a signal's first bit is placed).
        let aag = "aag 3 2 0 1 1\n2\n4\n7\n6 2 4\n";
        let map = "input 0 0 x\ninput 1 1 s\noutput 0 0 ok\n";
        let g = Aig::parse(aag, map).unwrap();
        let f = exhaustive(&g, &[Vec::new()]).unwrap();
        assert_eq!(f, Some(vec![("x".into(), 1), ("s".into(), 2)]));
    }

    #[test]
    fn refuses_latches_and_unknown_case_signals() {
        assert!(Aig::parse("aag 1 0 1 1 0\n2 3\n2\n", "").is_err());
        let (aag, map) = xor_aig();
        let g = Aig::parse(&aag, &map).unwrap();
        assert!(exhaustive(&g, &[vec![("z".into(), 1)]]).is_err());
    }
}
