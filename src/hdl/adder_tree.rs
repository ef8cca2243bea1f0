//! Pipelined adder trees for the multipliers of normalise, linear_index, interpolate and
//! color_mul, built so that each level is one LUT level in front of one carry chain (iCE40:
//! `SB_LUT4` + `SB_CARRY`), and so that `pipeline_depth` decides which levels are registered.
//!
//! A tree sums unsigned terms: a signal shifted left (`x << s`), a gated signal
//! (`sel ? x << s : 0`, a partial product) or a constant. A level adds groups of them: at most
//! three operands per node and at most four LUT inputs per result bit (a gated term counts
//! two, a plain one one, a constant none), so a node is one 3:2 compression (or AND) LUT and
//! one carry chain. The operand with the lowest shift passes its low bits straight through,
//! so each carry chain spans only the bits where operands overlap. Widths follow the largest
//! value of each node, so no node overflows; the final node may be narrowed to a known bound
//! of the whole sum ([`Tree::bound`]), which is exact because the true value fits.
//!
//! Several trees are built side by side, one level per [`Step`]; signals the stage needs later
//! ride along and are registered with each registered level.

/// A signal of a stage: a Verilog name and its width.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sig {
    pub name: String,
    pub width: u32,
}

impl Sig {
    pub fn new(name: impl Into<String>, width: u32) -> Sig {
        Sig {
            name: name.into(),
            width,
        }
    }
}

/// One term of a sum.
#[derive(Clone, Debug)]
pub enum Term {
    /// `x << shift`.
    Plain { x: Sig, shift: u32 },
    /// `sel ? x << shift : 0`, `sel` a one-bit expression.
    Gated { sel: String, x: Sig, shift: u32 },
    /// A constant.
    Const(u128),
}

/// A sum to build: its name (prefix of its nodes), terms and, when the designer knows one,
/// an upper bound of the whole sum that is tighter than the sum of the terms' maxima.
#[derive(Clone, Debug)]
pub struct Tree {
    pub name: String,
    pub terms: Vec<Term>,
    pub bound: Option<u128>,
}

/// One result bit of a level: `name_d = expr` (and `name_q` when the level is registered).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Node {
    pub name: String,
    pub width: u32,
    pub expr: String,
    /// `[w-1:0]` (blank for one bit), padded to the widest of its step.
    pub range: String,
}

/// One level of the trees, with the signals that ride along.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step {
    pub title: String,
    pub registered: bool,
    pub nodes: Vec<Node>,
    /// Bits of earlier results that a bounded sum does not need (they are zero or cancel
    /// modulo its width), collected for the lint.
    pub unused: Vec<String>,
}

/// A registered level `k` carries each rider through a node `<base>_l<k>` of its own; the
/// rider is then read from that node's register. Shared by both builders (this one and
/// `hdl::infer`), so riders line up with the products whichever builds the stage.
pub(super) fn carry_riders(riders: &mut [(&str, Sig)], k: u32, nodes: &mut Vec<Node>) {
    for (base, r) in riders.iter_mut() {
        let name = format!("{base}_l{k}");
        nodes.push(Node {
            name: name.clone(),
            width: r.width,
            expr: r.name.clone(),
            range: String::new(),
        });
        r.name = format!("{name}_q");
    }
}

/// Pads every node's range to the widest of the step, so the declarations line up.
pub(super) fn align_ranges(nodes: &mut [Node]) {
    let rw = nodes
        .iter()
        .map(|n| range(n.width).len())
        .max()
        .unwrap_or(0);
    for n in nodes.iter_mut() {
        n.range = format!("{:rw$}", range(n.width));
    }
}

/// The Verilog range of `width` bits, `[w-1:0]`, or empty for one bit.
pub(super) fn range(width: u32) -> String {
    if width == 1 {
        String::new()
    } else {
        format!("[{}:0]", width - 1)
    }
}

/// A node's value as its parent sees it: `x << shift` with x of `width` bits.
#[derive(Clone, Debug)]
struct Op {
    kind: Kind,
    shift: u32,
    width: u32,
}

#[derive(Clone, Debug)]
enum Kind {
    Plain(String),
    Gated(String, String),
    /// The constant's bits from `shift` up.
    Const(u128),
}

impl Op {
    fn max(&self) -> u128 {
        match self.kind {
            Kind::Const(v) => v << self.shift,
            _ => ((1u128 << self.width) - 1) << self.shift,
        }
    }
    fn cost(&self) -> u32 {
        match self.kind {
            Kind::Plain(_) => 1,
            Kind::Gated(..) => 2,
            Kind::Const(_) => 0,
        }
    }
    fn is_const(&self) -> bool {
        matches!(self.kind, Kind::Const(_))
    }

    /// Bits [lo, lo + n) of x, shifted left by `k` and zero-extended to `w` bits.
    fn render(&self, lo: u32, n: u32, k: u32, w: u32) -> String {
        assert!(
            n > 0 && lo + n <= self.width && n + k <= w,
            "operand does not fit"
        );
        if let Kind::Const(v) = self.kind {
            return format!("{w}'d{}", ((v >> lo) & ((1u128 << n) - 1)) << k);
        }
        let name = match &self.kind {
            Kind::Plain(x) | Kind::Gated(_, x) => x,
            Kind::Const(_) => unreachable!(),
        };
        let bits = if lo == 0 && n == self.width {
            name.clone()
        } else if n == 1 {
            format!("{name}[{lo}]")
        } else {
            format!("{name}[{}:{lo}]", lo + n - 1)
        };
        let mut parts = Vec::new();
        if w > n + k {
            parts.push(format!("{{{}{{1'b0}}}}", w - n - k));
        }
        parts.push(bits);
        if k > 0 {
            parts.push(format!("{{{k}{{1'b0}}}}"));
        }
        let v = if parts.len() == 1 {
            parts.pop().expect("one part")
        } else {
            format!("{{{}}}", parts.join(", "))
        };
        match &self.kind {
            Kind::Gated(sel, _) => format!("({sel} ? {v} : {w}'d0)"),
            _ => v,
        }
    }
}

fn leaf(t: &Term) -> Op {
    match t {
        Term::Plain { x, shift } => Op {
            kind: Kind::Plain(x.name.clone()),
            shift: *shift,
            width: x.width,
        },
        Term::Gated { sel, x, shift } => Op {
            kind: Kind::Gated(sel.clone(), x.name.clone()),
            shift: *shift,
            width: x.width,
        },
        Term::Const(v) => {
            assert!(*v > 0, "a zero constant is not a term");
            let s = v.trailing_zeros();
            Op {
                kind: Kind::Const(v >> s),
                shift: s,
                width: bits128(v >> s),
            }
        }
    }
}

/// Splits one level's operands into nodes: sorted by shift (so neighbours overlap least), at
/// most three operands and four LUT inputs per node, at most one constant per node.
fn group(mut ops: Vec<Op>) -> Vec<Vec<Op>> {
    let mut consts: Vec<Op> = ops.iter().filter(|o| o.is_const()).cloned().collect();
    ops.retain(|o| !o.is_const());
    ops.sort_by_key(|o| o.shift);
    let mut nodes: Vec<Vec<Op>> = Vec::new();
    for op in ops {
        match nodes.last_mut() {
            Some(n) if n.len() < 3 && n.iter().map(Op::cost).sum::<u32>() + op.cost() <= 4 => {
                n.push(op)
            }
            _ => nodes.push(vec![op]),
        }
    }
    // A constant joins a node with room (fewest operands first), else waits for the next
    // level; with nothing else left it gets a node of its own with the last operand.
    consts.sort_by_key(|o| o.shift);
    for c in consts {
        if let Some(n) = nodes
            .iter_mut()
            .filter(|n| n.len() < 3)
            .min_by_key(|n| n.len())
        {
            n.push(c);
        } else {
            nodes.push(vec![c]);
        }
    }
    nodes
}

/// The Verilog of one node summing `ops`: (expression, width, shift of the result, bits of
/// operands that a bounded node leaves unused).
fn node(ops: &[Op], bound: Option<u128>) -> (String, u32, u32, Vec<String>) {
    let mut ops = ops.to_vec();
    ops.sort_by_key(|o| o.shift);
    let s = ops[0].shift;
    let mut max: u128 = ops.iter().map(Op::max).sum();
    if let Some(b) = bound {
        max = max.min(b);
    }
    assert!(max >> s < 1u128 << 100, "sum too wide");
    let width = bits128(max >> s);
    if ops.len() == 1 {
        let o = &ops[0];
        return (o.render(0, o.width, 0, width), width, s, Vec::new());
    }
    let mut unused = Vec::new();
    // The bits below the second operand's shift come from the first operand alone.
    let p = (ops[1].shift - s).min(ops[0].width).min(width);
    let hw = width - p;
    let narrowed = max < ops.iter().map(Op::max).sum::<u128>();
    // Each operand's bits above the pass-through, shifted into place; a bounded node keeps
    // only what fits (the sum is exact modulo 2^width because the true sum is below it).
    let terms: Vec<String> = ops
        .iter()
        .enumerate()
        .filter_map(|(k, o)| {
            let lo = if k == 0 { p } else { 0 };
            let shift = o.shift + lo - s - p;
            let mut n = o.width.saturating_sub(lo);
            if n + shift > hw {
                assert!(narrowed, "an operand is wider than its node");
                let keep = hw.saturating_sub(shift);
                if let Kind::Plain(x) | Kind::Gated(_, x) = &o.kind {
                    unused.push(if lo + keep + 1 == o.width {
                        format!("{x}[{}]", lo + keep)
                    } else {
                        format!("{x}[{}:{}]", o.width - 1, lo + keep)
                    });
                }
                n = keep;
            }
            (n > 0).then(|| o.render(lo, n, shift, hw))
        })
        .collect();
    let expr = if p == 0 {
        terms.join(" + ")
    } else {
        let low = ops[0].render(0, p, 0, p);
        match terms.len() {
            0 => low,
            1 => format!("{{{}, {low}}}", terms[0]),
            _ => format!("{{({}), {low}}}", terms.join(" + ")),
        }
    };
    (expr, width, s, unused)
}

/// Bits needed for `v` (at least 1).
fn bits128(v: u128) -> u32 {
    (128 - v.leading_zeros()).max(1)
}

/// A tree's result: the value is `sig << shift`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sum {
    pub sig: Sig,
    pub shift: u32,
}

impl Sum {
    /// The value as a term of another tree.
    pub fn term(&self) -> Term {
        Term::Plain {
            x: self.sig.clone(),
            shift: self.shift,
        }
    }

    /// The value as a Verilog expression of exactly `w` bits (zero-extended; `w` must hold it).
    pub fn expr(&self, w: u32) -> String {
        let used = self.sig.width + self.shift;
        assert!(used <= w, "{} needs {used} bits, not {w}", self.sig.name);
        let mut parts = Vec::new();
        if w > used {
            parts.push(format!("{{{}{{1'b0}}}}", w - used));
        }
        parts.push(self.sig.name.clone());
        if self.shift > 0 {
            parts.push(format!("{{{}{{1'b0}}}}", self.shift));
        }
        if parts.len() == 1 {
            parts.pop().expect("one part")
        } else {
            format!("{{{}}}", parts.join(", "))
        }
    }

    /// Bits of the value.
    pub fn width(&self) -> u32 {
        self.sig.width + self.shift
    }

    /// The sum used as a signal: its value must start at bit 0.
    pub fn plain(&self) -> Sig {
        assert_eq!(self.shift, 0, "{} is shifted", self.sig.name);
        self.sig.clone()
    }
}

/// The suffix of a stage's registers at the end of its clock `clock`: `q<clock>` (`a_q2` is
/// `a` registered in the second clock). A plan names the registers its trees read with it and
/// hands the suffix to the template, which declares them under that name, so no register
/// name is spelled in both places.
pub fn clock_q(clock: u32) -> String {
    format!("q{clock}")
}

/// Registered adder levels among `steps`: the clocks the trees add to a stage's latency.
pub fn registered(steps: &[Step]) -> u32 {
    steps.iter().filter(|s| s.registered).count() as u32
}

/// The result of [`build`]: the steps, each tree's sum, and the riders after the last step.
#[derive(Clone, Debug)]
pub struct Built {
    pub steps: Vec<Step>,
    pub sums: Vec<Sum>,
    pub riders: Vec<Sig>,
}

/// A tree is summed when one named signal is left.
fn done(ops: &[Op]) -> bool {
    ops.len() == 1 && matches!(ops[0].kind, Kind::Plain(_))
}

/// Levels each tree needs.
pub fn levels(tree: &Tree) -> u32 {
    let mut ops: Vec<Op> = tree.terms.iter().map(leaf).collect();
    let mut n = 0;
    while !done(&ops) {
        ops = group(ops)
            .into_iter()
            .map(|g| Op {
                kind: Kind::Plain(String::new()),
                shift: g.iter().map(|o| o.shift).min().expect("non-empty"),
                width: 1,
            })
            .collect();
        n += 1;
    }
    n
}

/// Builds `trees` side by side, one level per step; `riders` ride along. `registered(k, n)`
/// says whether level k (1-based) of n is registered. A tree that finishes early rides.
pub fn build(
    title: &str,
    trees: &[Tree],
    riders: &[(&str, Sig)],
    registered: &dyn Fn(u32, u32) -> bool,
) -> Built {
    let n = trees.iter().map(levels).max().unwrap_or(0);
    let mut cur: Vec<Vec<Op>> = trees
        .iter()
        .map(|t| t.terms.iter().map(leaf).collect())
        .collect();
    let mut riders: Vec<(&str, Sig)> = riders.to_vec();
    let mut steps = Vec::new();
    for k in 1..=n {
        let reg = registered(k, n);
        let mut nodes = Vec::new();
        let mut unused = Vec::new();
        for (t, ops) in trees.iter().zip(cur.iter_mut()) {
            if done(ops) {
                // Finished: the sum rides as its one operand.
                let o = &ops[0];
                if reg {
                    let name = format!("{}_l{k}", t.name);
                    nodes.push(Node {
                        name: name.clone(),
                        width: o.width,
                        expr: o.render(0, o.width, 0, o.width),
                        range: String::new(),
                    });
                    ops[0] = Op {
                        kind: Kind::Plain(format!("{name}_q")),
                        shift: o.shift,
                        width: o.width,
                    };
                }
                continue;
            }
            let groups = group(std::mem::take(ops));
            let last = groups.len() == 1;
            for (j, g) in groups.iter().enumerate() {
                let (expr, width, shift, u) = node(g, if last { t.bound } else { None });
                unused.extend(u);
                let name = if last {
                    format!("{}_l{k}", t.name)
                } else {
                    format!("{}_l{k}_{j}", t.name)
                };
                let out = format!("{name}_{}", if reg { "q" } else { "d" });
                nodes.push(Node {
                    name,
                    width,
                    expr,
                    range: String::new(),
                });
                ops.push(Op {
                    kind: Kind::Plain(out),
                    shift,
                    width,
                });
            }
        }
        if reg {
            carry_riders(&mut riders, k, &mut nodes);
        }
        align_ranges(&mut nodes);
        steps.push(Step {
            title: format!(
                "{title}, level {k} of {n}{}",
                if reg { "" } else { " (no register)" }
            ),
            registered: reg,
            nodes,
            unused,
        });
    }
    let sums = cur
        .iter()
        .map(|ops| {
            assert_eq!(ops.len(), 1, "a tree did not finish");
            let o = &ops[0];
            let name = match &o.kind {
                Kind::Plain(x) => x.clone(),
                _ => panic!("a tree of one term is not a sum"),
            };
            Sum {
                sig: Sig::new(name, o.width),
                shift: o.shift,
            }
        })
        .collect();
    Built {
        steps,
        sums,
        riders: riders.into_iter().map(|(_, r)| r).collect(),
    }
}

/// Which levels of an n-level tree are registered at `depth`, counting back from `anchor`
/// (the level whose output is always registered): depth 0 only the anchor, depth 1 every
/// second level down from it, depth 2 every level up to it. Levels above the anchor are
/// never registered (what follows them is registered by the stage).
pub fn registered_at(depth: u32, anchor: u32, k: u32) -> bool {
    if k > anchor {
        return false;
    }
    match depth {
        0 => k == anchor,
        1 => (anchor - k).is_multiple_of(2),
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluates a built tree's Verilog by a tiny interpreter: enough of the expression
    /// grammar the builder emits (concatenation, part select, `? :`, `+`, sized literals).
    struct Eval<'a> {
        env: &'a std::collections::HashMap<String, (u128, u32)>,
    }

    impl Eval<'_> {
        fn expr(&self, s: &str) -> (u128, u32) {
            let s = s.trim();
            // Top-level '+' (outside braces and parentheses).
            let mut depth = 0;
            let mut parts = Vec::new();
            let mut start = 0;
            for (i, c) in s.char_indices() {
                match c {
                    '(' | '{' | '[' => depth += 1,
                    ')' | '}' | ']' => depth -= 1,
                    '+' if depth == 0 => {
                        parts.push(&s[start..i]);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            parts.push(&s[start..]);
            if parts.len() > 1 {
                let vals: Vec<(u128, u32)> = parts.iter().map(|p| self.expr(p)).collect();
                let w = vals.iter().map(|v| v.1).max().unwrap();
                let sum: u128 = vals.iter().map(|v| v.0).sum();
                return (sum & ((1u128 << w) - 1), w);
            }
            if let Some(inner) = s.strip_prefix('(').and_then(|r| r.strip_suffix(')')) {
                if let Some(q) = top_level(inner, '?') {
                    let c = top_level(inner, ':').unwrap();
                    let (sel, _) = self.expr(&inner[..q]);
                    let (a, wa) = self.expr(&inner[q + 1..c]);
                    let (b, wb) = self.expr(&inner[c + 1..]);
                    return (if sel != 0 { a } else { b }, wa.max(wb));
                }
                return self.expr(inner);
            }
            if let Some(inner) = s.strip_prefix('{').and_then(|r| r.strip_suffix('}')) {
                // Replication {n{1'b0}} or concatenation.
                if let Some(b) = inner.find('{') {
                    if !inner[..b].contains(',') && inner[..b].trim().parse::<u32>().is_ok() {
                        let n: u32 = inner[..b].trim().parse().unwrap();
                        return (0, n);
                    }
                }
                let mut depth = 0;
                let mut items = Vec::new();
                let mut start = 0;
                for (i, c) in inner.char_indices() {
                    match c {
                        '(' | '{' | '[' => depth += 1,
                        ')' | '}' | ']' => depth -= 1,
                        ',' if depth == 0 => {
                            items.push(&inner[start..i]);
                            start = i + 1;
                        }
                        _ => {}
                    }
                }
                items.push(&inner[start..]);
                let mut v = 0u128;
                let mut w = 0;
                for it in items {
                    let (x, xw) = self.expr(it);
                    v = (v << xw) | x;
                    w += xw;
                }
                return (v, w);
            }
            if let Some((w, v)) = s.split_once("'d") {
                return (v.parse().unwrap(), w.parse().unwrap());
            }
            if let Some((w, v)) = s.split_once("'b") {
                return (u128::from_str_radix(v, 2).unwrap(), w.parse().unwrap());
            }
            if let Some((name, sel)) = s.strip_suffix(']').and_then(|r| r.split_once('[')) {
                let v = self.env[name].0;
                let (hi, lo) = match sel.split_once(':') {
                    Some((h, l)) => (h.parse::<u32>().unwrap(), l.parse::<u32>().unwrap()),
                    None => {
                        let b = sel.parse::<u32>().unwrap();
                        (b, b)
                    }
                };
                return ((v >> lo) & ((1u128 << (hi - lo + 1)) - 1), hi - lo + 1);
            }
            self.env[s]
        }
    }

    fn top_level(s: &str, ch: char) -> Option<usize> {
        let mut depth = 0;
        for (i, c) in s.char_indices() {
            match c {
                '(' | '{' | '[' => depth += 1,
                ')' | '}' | ']' => depth -= 1,
                c if c == ch && depth == 0 => return Some(i),
                _ => {}
            }
        }
        None
    }

    /// Runs the built steps on inputs and returns each tree's sum.
    fn run(b: &Built, inputs: &[(&str, u128, u32)]) -> Vec<u128> {
        let mut env: std::collections::HashMap<String, (u128, u32)> = inputs
            .iter()
            .map(|(k, v, w)| (k.to_string(), (*v, *w)))
            .collect();
        for s in &b.steps {
            for n in &s.nodes {
                let (v, _) = Eval { env: &env }.expr(&n.expr);
                let _ = &s.unused;
                assert!(
                    v < 1u128 << n.width,
                    "{} = {v} overflows {}",
                    n.name,
                    n.width
                );
                env.insert(format!("{}_d", n.name), (v, n.width));
                env.insert(format!("{}_q", n.name), (v, n.width));
            }
        }
        b.sums
            .iter()
            .map(|s| Eval { env: &env }.expr(&s.expr(s.width())).0)
            .collect()
    }

    fn product_tree(name: &str, a: &str, aw: u32, x: &str, xw: u32, c: u128) -> Tree {
        let mut terms: Vec<Term> = (0..aw)
            .map(|j| Term::Gated {
                sel: format!("{a}[{j}]"),
                x: Sig::new(x, xw),
                shift: j,
            })
            .collect();
        if c > 0 {
            terms.push(Term::Const(c));
        }
        Tree {
            name: name.into(),
            terms,
            bound: None,
        }
    }

    #[test]
    fn products_are_exact_at_every_depth() {
        for (aw, xw, c) in [
            (8, 10, 256),
            (6, 5, 16),
            (12, 20, 1 << 22),
            (1, 4, 0),
            (3, 3, 7),
        ] {
            for depth in 0..=2 {
                let t = product_tree("p", "a", aw, "x", xw, c);
                let n = levels(&t);
                let b = build("t", &[t], &[("f", Sig::new("f_q", 1))], &|k, n| {
                    registered_at(depth, n, k)
                });
                assert_eq!(b.steps.len() as u32, n);
                for (a, x) in [
                    (0, 0),
                    (1, 1),
                    ((1 << aw) - 1, (1 << xw) - 1),
                    (5 % (1 << aw), 3),
                ] {
                    let got = run(&b, &[("a", a, aw), ("x", x, xw), ("f_q", 1, 1)]);
                    assert_eq!(got[0], a * x + c, "a{aw} x{xw} c{c} depth {depth}");
                }
            }
        }
    }

    #[test]
    fn every_level_is_one_lut_deep() {
        let t = product_tree("p", "a", 8, "x", 10, 256);
        let b = build("t", &[t], &[], &|_, _| true);
        for s in &b.steps {
            for n in &s.nodes {
                // The sum, without the low bits that pass through.
                let sum = match n.expr.strip_prefix("{(") {
                    Some(r) => &r[..r.rfind("), ").unwrap()],
                    None => n.expr.as_str(),
                };
                let ops = sum.matches(" + ").count() + 1;
                let gated = sum.matches(" ? ").count();
                assert!(ops <= 3 && gated <= 2, "{}: {}", n.name, n.expr);
            }
        }
        assert_eq!(b.steps.len(), 3);
    }

    #[test]
    fn depth_rule() {
        let regs = |d, a, n| (1..=n).filter(|&k| registered_at(d, a, k)).count();
        assert_eq!(regs(0, 3, 3), 1);
        assert_eq!(regs(1, 3, 3), 2);
        assert_eq!(regs(2, 3, 3), 3);
        assert_eq!(regs(2, 2, 3), 2);
        assert_eq!(regs(1, 4, 4), 2);
    }
}
