//! A gate-level netlist read from Yosys's `write_json` after `techmap`: the simple gates of
//! Yosys's internal library (`$_AND_`, `$_XOR_`, `$_MUX_`, ...) between the module's input
//! ports and any named net. The algebraic engine of `rmapgen prove-mult`
//! (`mult::algebra`) reads its miters this way rather than as AIGER, because the JSON
//! names every bit of every public wire, constants included: Yosys 0.23's AIGER map leaves
//! constant outputs out and numbers two outputs on one net with one index.
//!
//! Each case of a proof fixes some input bits; [`Netlist::simplify`] propagates those
//! constants through the cone of the nets asked for and returns what is left as a
//! [`Circuit`]: AND, XOR and MUX nodes over literals (a node or its complement), inputs
//! first, every node after its operands.

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::collections::HashMap;

/// A bit of the JSON netlist: a net number or a constant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Bit {
    Net(u64),
    Const(bool),
}

/// A simple gate of Yosys's library, by its operands (bits of the netlist).
#[derive(Clone, Copy, Debug)]
enum Gate {
    Buf(Bit),
    Not(Bit),
    /// `a & b`, each operand complemented when its flag is set, the result too.
    And(Bit, bool, Bit, bool, bool),
    /// `a ^ b`, complemented when the flag is set.
    Xor(Bit, Bit, bool),
    /// `s ? b : a`, complemented when the flag is set.
    Mux(Bit, Bit, Bit, bool),
}

impl Gate {
    fn operands(&self) -> Vec<Bit> {
        match *self {
            Gate::Buf(a) | Gate::Not(a) => vec![a],
            Gate::And(a, _, b, _, _) | Gate::Xor(a, b, _) => vec![a, b],
            Gate::Mux(a, b, s, _) => vec![a, b, s],
        }
    }
}

/// One module of a Yosys JSON netlist, mapped to simple gates.
pub struct Netlist {
    /// Input ports: name and their bits, least significant first.
    inputs: Vec<(String, Vec<Bit>)>,
    /// Every named wire (ports included): its bits, least significant first.
    names: HashMap<String, Vec<Bit>>,
    /// The gate driving each net.
    driver: HashMap<u64, Gate>,
}

fn bits(v: &Value, what: &str) -> Result<Vec<Bit>> {
    v.as_array()
        .with_context(|| format!("{what}: no bits"))?
        .iter()
        .map(|b| match b {
            Value::Number(n) => n
                .as_u64()
                .map(Bit::Net)
                .with_context(|| format!("{what}: bad net {n}")),
            Value::String(s) if s == "0" => Ok(Bit::Const(false)),
            Value::String(s) if s == "1" => Ok(Bit::Const(true)),
            other => bail!("{what}: the bit {other} is undefined (x or z)"),
        })
        .collect()
}

impl Netlist {
    /// Reads module `top` of a `write_json` file.
    pub fn parse(json: &str, top: &str) -> Result<Netlist> {
        let v: Value = serde_json::from_str(json).context("not a Yosys JSON netlist")?;
        let m = v
            .get("modules")
            .and_then(|m| m.get(top))
            .with_context(|| format!("the netlist has no module {top}"))?;
        let mut inputs = Vec::new();
        if let Some(ports) = m.get("ports").and_then(Value::as_object) {
            for (name, p) in ports {
                if p.get("direction").and_then(Value::as_str) == Some("input") {
                    inputs.push((name.clone(), bits(&p["bits"], name)?));
                }
            }
        }
        let mut names = HashMap::new();
        if let Some(nets) = m.get("netnames").and_then(Value::as_object) {
            for (name, n) in nets {
                // A wire with an undefined bit is left out: asking for it is the error.
                if let Ok(b) = bits(&n["bits"], name) {
                    names.insert(name.clone(), b);
                }
            }
        }
        let mut driver = HashMap::new();
        let cells = m.get("cells").and_then(Value::as_object);
        for (name, c) in cells.into_iter().flatten() {
            let ty = c.get("type").and_then(Value::as_str).unwrap_or("");
            let conn = &c["connections"];
            let pin = |p: &str| -> Result<Bit> {
                let b = bits(&conn[p], &format!("{name}.{p}"))?;
                match b[..] {
                    [x] => Ok(x),
                    _ => bail!("{name}.{p}: {} bits, a simple gate has one", b.len()),
                }
            };
            let gate = match ty {
                "$_BUF_" => Gate::Buf(pin("A")?),
                "$_NOT_" => Gate::Not(pin("A")?),
                "$_AND_" => Gate::And(pin("A")?, false, pin("B")?, false, false),
                "$_NAND_" => Gate::And(pin("A")?, false, pin("B")?, false, true),
                "$_OR_" => Gate::And(pin("A")?, true, pin("B")?, true, true),
                "$_NOR_" => Gate::And(pin("A")?, true, pin("B")?, true, false),
                "$_ANDNOT_" => Gate::And(pin("A")?, false, pin("B")?, true, false),
                "$_ORNOT_" => Gate::And(pin("A")?, true, pin("B")?, false, true),
                "$_XOR_" => Gate::Xor(pin("A")?, pin("B")?, false),
                "$_XNOR_" => Gate::Xor(pin("A")?, pin("B")?, true),
                "$_MUX_" => Gate::Mux(pin("A")?, pin("B")?, pin("S")?, false),
                "$_NMUX_" => Gate::Mux(pin("A")?, pin("B")?, pin("S")?, true),
                other => bail!("cell {name} is a {other}, not a simple gate (the miter must be mapped with techmap, its registers made wires)"),
            };
            let Bit::Net(y) = pin("Y")? else {
                bail!("cell {name} drives a constant");
            };
            if driver.insert(y, gate).is_some() {
                bail!("net {y} has two drivers");
            }
        }
        for (name, b) in &inputs {
            for x in b {
                if let Bit::Net(n) = x {
                    if driver.contains_key(n) {
                        bail!("input {name} is driven by a gate");
                    }
                }
            }
        }
        Ok(Netlist {
            inputs,
            names,
            driver,
        })
    }

    /// The bits of the named wire.
    fn wire(&self, name: &str) -> Result<&[Bit]> {
        self.names
            .get(name)
            .map(Vec::as_slice)
            .with_context(|| format!("the netlist has no wire {name} (or it has an undefined bit)"))
    }

    /// The input ports: name and width.
    pub fn input_ports(&self) -> Vec<(String, usize)> {
        self.inputs
            .iter()
            .map(|(n, b)| (n.clone(), b.len()))
            .collect()
    }

    /// The nets of the cone of `outputs`: the driven ones, each after its operands, and
    /// the undriven ones (neither a gate's output nor an input port's bit). Depth-first
    /// without recursion: a carry chain is thousands of gates deep.
    fn cone(&self, outputs: &[&str], port: &HashMap<u64, ()>) -> Result<(Vec<u64>, Vec<u64>)> {
        let (mut order, mut undriven) = (Vec::new(), Vec::new());
        // 1: on the path being explored, 2: done.
        let mut state: HashMap<u64, u8> = HashMap::new();
        for name in outputs {
            for &b in self.wire(name)? {
                let Bit::Net(root) = b else { continue };
                let mut stack = vec![(root, false)];
                while let Some((n, ready)) = stack.pop() {
                    if ready {
                        state.insert(n, 2);
                        order.push(n);
                        continue;
                    }
                    match state.get(&n) {
                        Some(2) => continue,
                        Some(_) => bail!("a combinational loop through net {n} (under {name})"),
                        None => {}
                    }
                    if port.contains_key(&n) {
                        state.insert(n, 2);
                        continue;
                    }
                    let Some(g) = self.driver.get(&n) else {
                        state.insert(n, 2);
                        undriven.push(n);
                        continue;
                    };
                    state.insert(n, 1);
                    stack.push((n, true));
                    for x in g.operands() {
                        if let Bit::Net(m) = x {
                            if state.get(&m) != Some(&2) {
                                stack.push((m, false));
                            }
                        }
                    }
                }
            }
        }
        Ok((order, undriven))
    }

    /// A name for net `n`: a wire holding it (`u_dut.u_i[3]`), or `net n`.
    fn net_name(&self, n: u64) -> (String, u32) {
        let mut best: Option<(String, u32)> = None;
        for (name, b) in &self.names {
            if let Some(i) = b.iter().position(|x| *x == Bit::Net(n)) {
                let better = match &best {
                    None => true,
                    Some((m, _)) => {
                        (m.starts_with('$'), m.as_str()) > (name.starts_with('$'), name.as_str())
                    }
                };
                if better {
                    best = Some((name.clone(), i as u32));
                }
            }
        }
        best.unwrap_or_else(|| (format!("net {n}"), 0))
    }

    /// The circuit of the wires `outputs` once the input bits `fixed` gives are constants
    /// (`fixed(port, bit)`: `Some(value)` or `None` for a free bit). The free input bits
    /// become the circuit's inputs, in port order then bit order, then the undriven nets of
    /// the cone (a stage input the miter leaves open): free too, so the proof holds
    /// whatever drives them.
    pub fn simplify(
        &self,
        outputs: &[&str],
        fixed: impl Fn(&str, usize) -> Option<bool>,
    ) -> Result<Circuit> {
        let mut c = Circuit {
            inputs: Vec::new(),
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let mut lit: HashMap<u64, Lit> = HashMap::new();
        let mut port: HashMap<u64, ()> = HashMap::new();
        for (name, b) in &self.inputs {
            for (i, x) in b.iter().enumerate() {
                let Bit::Net(n) = *x else { continue };
                port.insert(n, ());
                if lit.contains_key(&n) {
                    // One net on two input bits (never from a port list): the first wins.
                    continue;
                }
                let l = match fixed(name, i) {
                    Some(v) => v as Lit,
                    None => {
                        c.inputs.push((name.clone(), i as u32));
                        2 * c.inputs.len() as Lit
                    }
                };
                lit.insert(n, l);
            }
        }
        let (order, undriven) = self.cone(outputs, &port)?;
        for n in undriven {
            c.inputs.push(self.net_name(n));
            lit.insert(n, 2 * c.inputs.len() as Lit);
        }
        for n in order {
            let get = |x: Bit| match x {
                Bit::Const(v) => v as Lit,
                Bit::Net(m) => lit[&m],
            };
            let l = match self.driver[&n] {
                Gate::Buf(a) => get(a),
                Gate::Not(a) => get(a) ^ 1,
                Gate::And(a, na, b, nb, ny) => {
                    c.and(get(a) ^ na as Lit, get(b) ^ nb as Lit) ^ ny as Lit
                }
                Gate::Xor(a, b, ny) => c.xor(get(a), get(b)) ^ ny as Lit,
                Gate::Mux(a, b, s, ny) => c.mux(get(s), get(a), get(b)) ^ ny as Lit,
            };
            lit.insert(n, l);
        }
        for name in outputs {
            let out = self
                .wire(name)?
                .iter()
                .map(|&b| match b {
                    Bit::Const(v) => v as Lit,
                    Bit::Net(n) => lit[&n],
                })
                .collect();
            c.outputs.push(out);
        }
        Ok(c)
    }
}

/// A literal: node * 2, plus 1 when complemented. Node 0 is the constant false, so literal 0
/// is false and 1 is true; nodes 1..=inputs are the free inputs.
pub type Lit = u32;

/// A node of a [`Circuit`], over literals of earlier nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Node {
    And(Lit, Lit),
    Xor(Lit, Lit),
    /// `s ? b : a`, as (s, a, b).
    Mux(Lit, Lit, Lit),
}

/// A netlist's cone after constant propagation: inputs, then nodes in order.
pub struct Circuit {
    /// Each free input: its port and bit.
    pub inputs: Vec<(String, u32)>,
    /// Node `inputs.len() + 1 + k` is `nodes[k]`.
    pub nodes: Vec<Node>,
    /// For each wire asked for, the literal of each bit.
    pub outputs: Vec<Vec<Lit>>,
}

impl Circuit {
    fn push(&mut self, n: Node) -> Lit {
        self.nodes.push(n);
        2 * (self.inputs.len() + self.nodes.len()) as Lit
    }

    pub(crate) fn and(&mut self, a: Lit, b: Lit) -> Lit {
        let (a, b) = (a.min(b), a.max(b));
        if a == 0 || a == b ^ 1 {
            0
        } else if a == 1 || a == b {
            b
        } else {
            self.push(Node::And(a, b))
        }
    }

    pub(crate) fn xor(&mut self, a: Lit, b: Lit) -> Lit {
        // The complements move to the result: a node is an XOR of plain nodes.
        let flip = (a ^ b) & 1;
        let (a, b) = ((a & !1).min(b & !1), (a & !1).max(b & !1));
        if a == b {
            flip
        } else if a == 0 {
            b ^ flip
        } else {
            self.push(Node::Xor(a, b)) ^ flip
        }
    }

    pub(crate) fn mux(&mut self, s: Lit, a: Lit, b: Lit) -> Lit {
        match s {
            0 => a,
            1 => b,
            _ if a == b => a,
            _ if a == 0 => self.and(s, b),
            _ if b == 0 => self.and(s ^ 1, a),
            _ if s & 1 == 1 => self.mux(s ^ 1, b, a),
            _ => self.push(Node::Mux(s, a, b)),
        }
    }

    /// The node's index among the nodes, or None for an input or the constant.
    pub fn node(&self, var: u32) -> Option<&Node> {
        (var as usize)
            .checked_sub(self.inputs.len() + 1)
            .and_then(|k| self.nodes.get(k))
    }

    /// Evaluates every output on one input (`free[k]` is input k's value): for tests and
    /// to confirm a counterexample.
    pub fn eval(&self, free: &[bool]) -> Vec<Vec<bool>> {
        let mut v = vec![false; 1 + self.inputs.len() + self.nodes.len()];
        v[1..=self.inputs.len()].copy_from_slice(free);
        let l = |v: &[bool], x: Lit| v[(x / 2) as usize] ^ (x & 1 == 1);
        for (k, n) in self.nodes.iter().enumerate() {
            v[self.inputs.len() + 1 + k] = match *n {
                Node::And(a, b) => l(&v, a) && l(&v, b),
                Node::Xor(a, b) => l(&v, a) ^ l(&v, b),
                Node::Mux(s, a, b) => {
                    if l(&v, s) {
                        l(&v, b)
                    } else {
                        l(&v, a)
                    }
                }
            };
        }
        self.outputs
            .iter()
            .map(|o| o.iter().map(|&x| l(&v, x)).collect())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-written netlist: y = (a & !b) ^ c, z = s ? a : c, k constant 1.
    const JSON: &str = r#"{"modules": {"t": {
      "ports": {"a": {"direction": "input", "bits": [2]}, "b": {"direction": "input", "bits": [3]},
                "c": {"direction": "input", "bits": [4]}, "s": {"direction": "input", "bits": [5]}},
      "cells": {
        "g1": {"type": "$_ANDNOT_", "connections": {"A": [2], "B": [3], "Y": [6]}},
        "g2": {"type": "$_XOR_", "connections": {"A": [6], "B": [4], "Y": [7]}},
        "g3": {"type": "$_MUX_", "connections": {"A": [4], "B": [2], "S": [5], "Y": [8]}}},
      "netnames": {"y": {"bits": [7]}, "z": {"bits": [8]}, "k": {"bits": ["1", 7]},
                   "u": {"bits": ["x"]}}}}}"#;

    #[test]
    fn reads_gates_and_evaluates_them() {
        let n = Netlist::parse(JSON, "t").unwrap();
        let c = n.simplify(&["y", "z", "k"], |_, _| None).unwrap();
        assert_eq!(c.inputs.len(), 4);
        for x in 0..16u32 {
            let f: Vec<bool> = (0..4).map(|i| (x >> i) & 1 == 1).collect();
            // Inputs in port order: a, b, c, s.
            let (a, b, cc, s) = (f[0], f[1], f[2], f[3]);
            let o = c.eval(&f);
            assert_eq!(o[0], vec![(a && !b) ^ cc]);
            assert_eq!(o[1], vec![if s { a } else { cc }]);
            assert_eq!(o[2], vec![true, (a && !b) ^ cc]);
        }
        // k's bit 0 is the constant 1 as read (literal 1), its bit 1 a node.
        assert_eq!(c.outputs[2][0], 1);
        assert!(c.outputs[2][1] > 1);
    }

    #[test]
    fn constants_fold_away() {
        let n = Netlist::parse(JSON, "t").unwrap();
        // b = 1 makes a & !b false, so y = c; s = 0 makes z = c.
        let c = n
            .simplify(&["y", "z"], |p, _| match p {
                "b" => Some(true),
                "s" => Some(false),
                _ => None,
            })
            .unwrap();
        assert!(c.nodes.is_empty(), "{:?}", c.nodes);
        assert_eq!(c.outputs, vec![vec![4], vec![4]]);
    }

    /// [`JSON`] without the input port c: its net 4 is driven by nothing. `wires` are more
    /// net names (`, "w": {"bits": [4]}`).
    fn without_port_c(wires: &str) -> String {
        JSON.replace(r#""c": {"direction": "input", "bits": [4]}, "#, "")
            .replace(
                r#""y": {"bits": [7]}"#,
                &format!(r#""y": {{"bits": [7]}}{wires}"#),
            )
    }

    /// A net nothing drives (a stage input the miter leaves open) is a free input, named by
    /// a wire that holds it.
    #[test]
    fn an_undriven_net_is_a_free_input() {
        let open = without_port_c(r#", "u_dut.c": {"bits": [4]}"#);
        let n = Netlist::parse(&open, "t").unwrap();
        let c = n.simplify(&["y"], |_, _| None).unwrap();
        let names: Vec<&str> = c.inputs.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["a", "b", "s", "u_dut.c"]);
        for x in 0..16u32 {
            let f: Vec<bool> = (0..4).map(|i| (x >> i) & 1 == 1).collect();
            assert_eq!(c.eval(&f)[0], vec![(f[0] && !f[1]) ^ f[3]]);
        }
    }

    #[test]
    fn refuses_undefined_wires_and_unknown_cells() {
        let n = Netlist::parse(JSON, "t").unwrap();
        assert!(n.simplify(&["u"], |_, _| None).is_err());
        assert!(Netlist::parse(JSON, "other").is_err());
        let bad = JSON.replace("$_XOR_", "$dff");
        let e = Netlist::parse(&bad, "t").err().unwrap().to_string();
        assert!(e.contains("g2") && e.contains("$dff"), "{e}");
    }

    /// How [`one_cell`]'s cell reads the ports a, b and s (nets 2, 3, 4).
    #[derive(Clone, Copy, Debug)]
    enum Wiring {
        /// A, B and S are the ports.
        Plain,
        /// Each through a NOT cell (nets 6, 7, 8): the cell's operands are complemented
        /// literals.
        Inverted,
        /// A through a NOT (net 6), B and S the ports: one operand complemented.
        OneInverted,
        /// A and B both !a, S the port s.
        SameInverted,
    }

    /// A netlist of one cell of type `ty` reading the input ports a, b and s as `wiring`
    /// says, driving the wire y (net 5).
    fn one_cell(ty: &str, wiring: Wiring) -> Netlist {
        let (a, b, s) = match wiring {
            Wiring::Plain => (2, 3, 4),
            Wiring::Inverted => (6, 7, 8),
            Wiring::OneInverted => (6, 3, 4),
            Wiring::SameInverted => (6, 6, 4),
        };
        let pins = match ty {
            "$_BUF_" | "$_NOT_" => format!(r#""A": [{a}]"#),
            "$_MUX_" | "$_NMUX_" => format!(r#""A": [{a}], "B": [{b}], "S": [{s}]"#),
            _ => format!(r#""A": [{a}], "B": [{b}]"#),
        };
        let json = format!(
            r#"{{"modules": {{"t": {{
              "ports": {{"a": {{"direction": "input", "bits": [2]}},
                        "b": {{"direction": "input", "bits": [3]}},
                        "s": {{"direction": "input", "bits": [4]}}}},
              "cells": {{"g": {{"type": "{ty}", "connections": {{{pins}, "Y": [5]}}}},
                        "na": {{"type": "$_NOT_", "connections": {{"A": [2], "Y": [6]}}}},
                        "nb": {{"type": "$_NOT_", "connections": {{"A": [3], "Y": [7]}}}},
                        "ns": {{"type": "$_NOT_", "connections": {{"A": [4], "Y": [8]}}}}}},
              "netnames": {{"y": {{"bits": [5]}}}}}}}}}}"#
        );
        Netlist::parse(&json, "t").unwrap()
    }

    /// Every simple gate of Yosys's library computes the function Yosys's simcells.v gives
    /// it, on all eight values of its inputs: read from the ports, from complemented
    /// literals (each operand through a NOT, or only the first), and with both data operands one complemented
    /// net (where the builders fold and the gate's own complement applies to a literal that
    /// is already complemented).
    #[test]
    fn every_simple_gate_computes_its_yosys_function() {
        type F = fn(bool, bool, bool) -> bool;
        let gates: [(&str, F); 12] = [
            ("$_BUF_", |a, _, _| a),
            ("$_NOT_", |a, _, _| !a),
            ("$_AND_", |a, b, _| a & b),
            ("$_NAND_", |a, b, _| !(a & b)),
            ("$_OR_", |a, b, _| a | b),
            ("$_NOR_", |a, b, _| !(a | b)),
            ("$_XOR_", |a, b, _| a ^ b),
            ("$_XNOR_", |a, b, _| !(a ^ b)),
            ("$_ANDNOT_", |a, b, _| a & !b),
            ("$_ORNOT_", |a, b, _| a | !b),
            ("$_MUX_", |a, b, s| if s { b } else { a }),
            ("$_NMUX_", |a, b, s| !(if s { b } else { a })),
        ];
        let wirings = [
            Wiring::Plain,
            Wiring::Inverted,
            Wiring::OneInverted,
            Wiring::SameInverted,
        ];
        for wiring in wirings {
            for (ty, f) in gates {
                let c = one_cell(ty, wiring).simplify(&["y"], |_, _| None).unwrap();
                assert_eq!(c.inputs.len(), 3, "{ty}");
                for x in 0..8u32 {
                    let v: Vec<bool> = (0..3).map(|i| (x >> i) & 1 == 1).collect();
                    let (a, b, s) = (v[0], v[1], v[2]);
                    let want = match wiring {
                        Wiring::Plain => f(a, b, s),
                        Wiring::Inverted => f(!a, !b, !s),
                        Wiring::OneInverted => f(!a, b, s),
                        Wiring::SameInverted => f(!a, !a, s),
                    };
                    assert_eq!(c.eval(&v)[0], vec![want], "{ty} {wiring:?} on {v:?}");
                }
            }
        }
    }

    /// The builders fold exactly the trivial cases (a constant operand, one variable twice)
    /// and keep every node they make canonical: an AND's operands in order, an XOR's plain
    /// (the complement on the result), a MUX's select plain, and none of them constant. On
    /// every pair and triple of the literals of two inputs, the result evaluates to the
    /// operation.
    #[test]
    fn the_builders_fold_the_trivial_cases_and_keep_nodes_canonical() {
        let fresh = || Circuit {
            inputs: vec![("a".into(), 0), ("b".into(), 0)],
            nodes: Vec::new(),
            outputs: Vec::new(),
        };
        let value = |c: &mut Circuit, l: Lit, v: &[bool]| {
            c.outputs = vec![vec![l]];
            c.eval(v)[0][0]
        };
        let lits: Vec<Lit> = (0..6).collect();
        let same_var = |a: Lit, b: Lit| a / 2 == b / 2;
        let assignments = [[false, false], [true, false], [false, true], [true, true]];
        for &a in &lits {
            for &b in &lits {
                let trivial = a < 2 || b < 2 || same_var(a, b);
                let mut c = fresh();
                let l = c.and(a, b);
                assert_eq!(c.nodes.len(), usize::from(!trivial), "and({a}, {b})");
                if let Some(&Node::And(x, y)) = c.nodes.first() {
                    assert!(1 < x && x < y, "and({a}, {b}) made And({x}, {y})");
                }
                for v in &assignments {
                    let (va, vb) = (value(&mut c, a, v), value(&mut c, b, v));
                    assert_eq!(value(&mut c, l, v), va & vb, "and({a}, {b}) on {v:?}");
                }
                let mut c = fresh();
                let l = c.xor(a, b);
                assert_eq!(c.nodes.len(), usize::from(!trivial), "xor({a}, {b})");
                if let Some(&Node::Xor(x, y)) = c.nodes.first() {
                    assert!(
                        x % 2 == 0 && y % 2 == 0 && 0 < x && x < y,
                        "xor made Xor({x}, {y})"
                    );
                }
                for v in &assignments {
                    let (va, vb) = (value(&mut c, a, v), value(&mut c, b, v));
                    assert_eq!(value(&mut c, l, v), va ^ vb, "xor({a}, {b}) on {v:?}");
                }
                for &s in &lits {
                    let mut c = fresh();
                    let l = c.mux(s, a, b);
                    if s < 2 || a == b {
                        assert!(c.nodes.is_empty(), "mux({s}, {a}, {b}): {:?}", c.nodes);
                    } else if a == 0 || b == 0 {
                        assert!(
                            c.nodes.iter().all(|n| matches!(n, Node::And(..))),
                            "mux({s}, {a}, {b})"
                        );
                    } else {
                        assert_eq!(c.nodes.len(), 1, "mux({s}, {a}, {b})");
                        let Node::Mux(x, y, z) = c.nodes[0] else {
                            panic!("mux({s}, {a}, {b}): {:?}", c.nodes)
                        };
                        assert!(x % 2 == 0 && x > 1 && y != z, "mux made Mux({x}, {y}, {z})");
                    }
                    for v in &assignments {
                        let (vs, va, vb) = (
                            value(&mut c, s, v),
                            value(&mut c, a, v),
                            value(&mut c, b, v),
                        );
                        let want = if vs { vb } else { va };
                        assert_eq!(value(&mut c, l, v), want, "mux({s}, {a}, {b}) on {v:?}");
                    }
                }
            }
        }
        // node() numbers the nodes after the constant and the inputs.
        let mut c = fresh();
        let l = c.and(2, 4);
        assert_eq!(l, 6);
        assert_eq!(c.node(0), None);
        assert_eq!(c.node(2), None);
        assert_eq!(c.node(3), Some(&Node::And(2, 4)));
        assert_eq!(c.node(4), None);
    }

    /// Structural faults of a netlist are refused, each naming what is wrong.
    #[test]
    fn refuses_loops_second_drivers_driven_inputs_and_wide_pins() {
        let refused = |from: &str, to: &str, want: &str| {
            let bad = JSON.replace(from, to);
            assert_ne!(bad, JSON, "{from}");
            let e = Netlist::parse(&bad, "t")
                .and_then(|n| n.simplify(&["y", "z"], |_, _| None).map(|_| ()))
                .err()
                .unwrap_or_else(|| panic!("{to}: accepted"))
                .to_string();
            assert!(e.contains(want), "{to}: {e}");
        };
        // (what the good netlist says, what the bad one says instead, what the error names)
        let cases = [
            // g1 reads g2's output: y = ((y & !b) ^ c).
            (
                r#""A": [2], "B": [3], "Y": [6]"#,
                r#""A": [7], "B": [3], "Y": [6]"#,
                "combinational loop through net",
            ),
            (
                r#""A": [4], "B": [2], "S": [5], "Y": [8]"#,
                r#""A": [4], "B": [2], "S": [5], "Y": [7]"#,
                "net 7 has two drivers",
            ),
            (
                r#""A": [4], "B": [2], "S": [5], "Y": [8]"#,
                r#""A": [4], "B": [2], "S": [5], "Y": [3]"#,
                "input b is driven by a gate",
            ),
            (
                r#""A": [4], "B": [2], "S": [5], "Y": [8]"#,
                r#""A": [4], "B": [2], "S": [5], "Y": ["0"]"#,
                "cell g3 drives a constant",
            ),
            (
                r#""A": [4], "B": [2], "S": [5]"#,
                r#""A": [4, 2], "B": [2], "S": [5]"#,
                "g3.A: 2 bits, a simple gate has one",
            ),
            (
                r#""A": [4], "B": [2], "S": [5]"#,
                r#""A": ["z"], "B": [2], "S": [5]"#,
                "g3.A: the bit \"z\" is undefined",
            ),
            (
                r#""A": [4], "B": [2], "S": [5]"#,
                r#""A": [-4], "B": [2], "S": [5]"#,
                "g3.A: bad net -4",
            ),
            (
                r#""s": {"direction": "input", "bits": [5]}"#,
                r#""s": {"direction": "input", "bits": ["x"]}"#,
                "s: the bit",
            ),
        ];
        for (from, to, want) in cases {
            refused(from, to, want);
        }
    }

    /// A net held by several wires is named by the one a user would look for: a public name
    /// (not Yosys's `$...`) before a generated one, then the first in order; the bit is its
    /// place in that wire.
    #[test]
    fn an_undriven_net_is_named_by_its_plainest_wire() {
        let open = without_port_c(
            r#", "$auto$c": {"bits": [4]}, "u_dut.d": {"bits": [9, 4]}, "u_dut.e": {"bits": [4]}"#,
        );
        let n = Netlist::parse(&open, "t").unwrap();
        let c = n.simplify(&["y"], |_, _| None).unwrap();
        assert_eq!(c.inputs.last(), Some(&("u_dut.d".to_string(), 1)));
        // Held by no wire at all: `net N`.
        let nameless =
            without_port_c("").replace(r#""A": [6], "B": [4]"#, r#""A": [6], "B": [11]"#);
        let c = Netlist::parse(&nameless, "t")
            .unwrap()
            .simplify(&["y"], |_, _| None)
            .unwrap();
        assert_eq!(c.inputs.last(), Some(&("net 11".to_string(), 0)));
        assert_eq!(
            n.input_ports(),
            [
                ("a".to_string(), 1),
                ("b".to_string(), 1),
                ("s".to_string(), 1)
            ]
        );
    }
}
