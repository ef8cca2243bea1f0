//! The formal proof of the multipliers: every adder tree of a generated design (normalise,
//! linear_index, interpolate, color_mul) equals the plain arithmetic its plan says it builds
//! ([`TreeSpec`]: `a * b + c`), on every input, proved with Yosys's SAT solver (`sat -prove`)
//! on the generated module itself.
//!
//! For each tree, one Yosys script step: the stage's generated module is read from the design
//! directory as it is; the tree's input signals are cut (`expose -input`: driven by the proof,
//! their drivers disconnected) and its sum exposed; a miter module (written here from the
//! specification only) instantiates the stage and compares the sum with `a * b + c` in
//! Verilog; registers are made transparent (a techmap of every flip-flop to `Q = D`, see
//! docs/VERIFICATION.md for why that covers the pipelined tree), and `sat -prove ok 1` runs
//! once per value of the split factor ([`crate::rtl::tree_spec::Split`]). Markers in the log
//! (`rmapgen-mult: tree M T`) attribute every result to its tree.

use super::tree_spec::{Factor, TreeSpec};
use crate::config::Config;
use crate::stages;

/// Maps every flip-flop kind `proc` and `opt` leave to a wire from D to Q: the registers of a
/// pipelined tree become transparent, and the tree one combinational sum.
pub const TRANSPARENT: &str = r#"// rmapgen prove-mult: every flip-flop becomes a wire from D to Q: the value it would
// take at an enabled clock edge with no reset (a synchronous reset that opt_dff found in
// the logic in front of it is kept: it is part of that value).
(* techmap_celltype = "$dff $dffe $adff $adffe $aldff $aldffe $dffsr $dffsre" *)
module _90_transparent (CLK, EN, ARST, ALOAD, AD, SET, CLR, D, Q);
  parameter WIDTH = 1;
  parameter CLK_POLARITY = 1;
  parameter EN_POLARITY = 1;
  parameter ARST_POLARITY = 1;
  parameter ARST_VALUE = 0;
  parameter SET_POLARITY = 1;
  parameter CLR_POLARITY = 1;
  parameter ALOAD_POLARITY = 1;
  parameter SRST_POLARITY = 1;
  parameter SRST_VALUE = 0;
  input CLK, EN, ARST, ALOAD;
  input [WIDTH-1:0] AD, SET, CLR, D;
  output [WIDTH-1:0] Q;
  assign Q = D;
endmodule

(* techmap_celltype = "$sdff $sdffe $sdffce" *)
module _90_transparent_srst (CLK, EN, SRST, D, Q);
  parameter WIDTH = 1;
  parameter CLK_POLARITY = 1;
  parameter EN_POLARITY = 1;
  parameter ARST_POLARITY = 1;
  parameter ARST_VALUE = 0;
  parameter SET_POLARITY = 1;
  parameter CLR_POLARITY = 1;
  parameter ALOAD_POLARITY = 1;
  parameter SRST_POLARITY = 1;
  parameter SRST_VALUE = 0;
  input CLK, EN, SRST;
  input [WIDTH-1:0] D;
  output [WIDTH-1:0] Q;
  assign Q = (SRST == SRST_POLARITY) ? SRST_VALUE : D;
endmodule
"#;

/// The file [`TRANSPARENT`] is written to, in the log directory.
pub const TRANSPARENT_FILE: &str = "transparent.v";

/// The marker a script logs before a tree's cases.
pub const MARK: &str = "rmapgen-mult: tree";

/// One tree to prove: its stage module and specification.
#[derive(Clone, Debug)]
pub struct Job {
    pub module: String,
    pub spec: TreeSpec,
}

impl Job {
    /// `normalise.pa`.
    pub fn name(&self) -> String {
        format!("{}.{}", self.module, self.spec.tree)
    }

    /// The miter module's name.
    pub fn wrapper_name(&self) -> String {
        format!("mult_proof_{}_{}", self.module, self.spec.tree)
    }

    /// The cases: for each, the `-set` pairs (signal, value).
    pub fn cases(&self) -> Vec<Vec<(String, u128)>> {
        match &self.spec.split {
            None => vec![Vec::new()],
            Some(s) => (0..=s.last)
                .map(|v| {
                    let mut c = vec![(s.sig.name.clone(), v)];
                    if let Some((x, total)) = &s.complement {
                        c.push((x.name.clone(), total - v));
                    }
                    c
                })
                .collect(),
        }
    }
}

/// Every tree of the design of `cfg`, stage by stage in pipeline order.
pub fn jobs(cfg: &Config) -> Vec<Job> {
    stages::modules(cfg)
        .into_iter()
        .flat_map(|u| {
            let module = u.module(cfg);
            u.trees(cfg).into_iter().map(move |spec| Job {
                module: module.clone(),
                spec,
            })
        })
        .collect()
}

fn bits(v: u128) -> u32 {
    (128 - v.leading_zeros()).max(1)
}

/// The miter: the stage with the tree's inputs cut and its sum exposed, against the
/// specification `sum of a * b << s, plus c` written as Verilog arithmetic; `ok` is 1 when
/// they agree or a premise of the tree (an input above its bound) does not hold.
pub fn wrapper(job: &Job) -> String {
    let t = &job.spec;
    let w = bits(t.max()).max(t.sum.width());
    let inputs = t.inputs();
    let mut v = String::new();
    v.push_str(&format!(
        "// rmapgen prove-mult: {} = {} (generated from the plan's specification)\n",
        job.name(),
        t.title
    ));
    v.push_str(&format!(
        "module {} (\n  input wire clk_i,\n",
        job.wrapper_name()
    ));
    for s in &inputs {
        v.push_str(&format!("  input wire [{}:0] {},\n", s.width - 1, s.name));
    }
    v.push_str("  output wire ok\n);\n");
    let sw = t.sum.sig.width;
    v.push_str(&format!("  wire [{}:0] sum;\n", sw - 1));
    v.push_str(&format!("  {} u_dut (\n    .clk_i (clk_i),\n", job.module));
    for s in &inputs {
        v.push_str(&format!("    .{0} ({0}),\n", s.name));
    }
    v.push_str(&format!("    .{} (sum)\n  );\n", t.sum.sig.name));
    let terms: Vec<String> = t
        .products
        .iter()
        .map(|p| {
            let b = match &p.b {
                Factor::Sig(s) => s.name.clone(),
                Factor::Const(k) => format!("{w}'d{k}"),
            };
            if p.shift > 0 {
                format!("(({} * {b}) << {})", p.a.name, p.shift)
            } else {
                format!("({} * {b})", p.a.name)
            }
        })
        .chain((t.constant > 0).then(|| format!("{w}'d{}", t.constant)))
        .collect();
    v.push_str(&format!(
        "  // The plain arithmetic, evaluated in {w} bits (no overflow: the largest value fits).\n  wire [{0}:0] spec;\n  assign spec = {1};\n",
        w - 1,
        terms.join(" + ")
    ));
    v.push_str(&format!(
        "  wire [{0}:0] got;\n  assign got = {{{{{1}{{1'b0}}}}, sum}} << {2};\n",
        w - 1,
        w - sw,
        t.sum.shift
    ));
    let premises: Vec<String> = t
        .at_most
        .iter()
        .map(|(s, m)| format!("({} <= {}'d{m})", s.name, s.width.max(bits(*m))))
        .collect();
    let premise = if premises.is_empty() {
        "1'b1".to_string()
    } else {
        premises.join(" && ")
    };
    v.push_str(&format!(
        "  assign ok = !({premise}) || (got == spec);\nendmodule\n"
    ));
    v
}

/// The Yosys script proving every job of one design: `files` are the design's Verilog files,
/// `wrappers` the miter files (one per job, same order), `transparent` the techmap file.
pub fn script(files: &[String], jobs: &[Job], wrappers: &[String], transparent: &str) -> String {
    let mut s = String::new();
    s.push_str(&format!("read_verilog {}\n", files.join(" ")));
    s.push_str("proc\ndesign -save rmapgen_base\n");
    for (job, file) in jobs.iter().zip(wrappers) {
        let m = &job.module;
        let cut: Vec<String> = job
            .spec
            .inputs()
            .iter()
            .map(|x| format!("{m}/{}", x.name))
            .collect();
        s.push_str("design -load rmapgen_base\n");
        s.push_str(&format!("expose -input {}\n", cut.join(" ")));
        s.push_str(&format!("expose {m}/{}\n", job.spec.sum.sig.name));
        s.push_str(&format!("read_verilog {file}\n"));
        s.push_str(&format!(
            "hierarchy -top {0}\nproc\nflatten\nopt_clean\nopt_dff\ntechmap -map {transparent}\nopt -fast\n",
            job.wrapper_name()
        ));
        s.push_str(&format!("log {MARK} {m} {}\n", job.spec.tree));
        for case in job.cases() {
            let sets: String = case.iter().map(|(x, v)| format!(" -set {x} {v}")).collect();
            s.push_str(&format!("sat{sets} -prove ok 1 {}\n", job.wrapper_name()));
        }
    }
    s
}

/// The outcome for one tree.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeResult {
    pub name: String,
    pub title: String,
    pub cases: usize,
    pub proved: usize,
    /// The first failing case's assignments, as `sig = value` text (empty: no split).
    pub failed: Option<String>,
}

impl TreeResult {
    pub fn passed(&self) -> bool {
        self.failed.is_none() && self.proved == self.cases
    }
}

/// Reads the results out of the Yosys log of [`script`].
pub fn results(jobs: &[Job], log: &str) -> Vec<TreeResult> {
    let mut out: Vec<TreeResult> = jobs
        .iter()
        .map(|j| TreeResult {
            name: j.name(),
            title: j.spec.title.clone(),
            cases: j.cases().len(),
            proved: 0,
            failed: None,
        })
        .collect();
    let mut cur: Option<usize> = None;
    let mut seen = 0usize;
    for line in log.lines() {
        if let Some(rest) = line.trim().strip_prefix(MARK) {
            let mut it = rest.split_whitespace();
            let (m, t) = (it.next().unwrap_or(""), it.next().unwrap_or(""));
            cur = jobs.iter().position(|j| j.module == m && j.spec.tree == t);
            seen = 0;
        } else if line.contains("SAT proof finished - no model found: SUCCESS!") {
            if let Some(i) = cur {
                out[i].proved += 1;
                seen += 1;
            }
        } else if line.contains("SAT proof finished - model found: FAIL!") {
            if let Some(i) = cur {
                if out[i].failed.is_none() {
                    let case = jobs[i].cases().into_iter().nth(seen).unwrap_or_default();
                    out[i].failed = Some(
                        case.iter()
                            .map(|(x, v)| format!("{x} = {v}"))
                            .collect::<Vec<_>>()
                            .join(", "),
                    );
                }
                seen += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid;

    /// Every row of the grid has its trees stated: two in normalise, two in linear_index (no
    /// compensation), three in interpolate, six in color_mul; each specification's sum is a
    /// tree node of its own name and its miter names no node but that sum.
    #[test]
    fn every_tree_of_every_row_has_a_specification() {
        for r in grid::rows() {
            let c = &r.config;
            let want = 2
                + 2 * !c.compensation as usize
                + 3 * c.interpolation as usize
                + 6 * c.color as usize;
            let jobs = jobs(c);
            assert_eq!(jobs.len(), want, "{}", r.name);
            for j in &jobs {
                let t = &j.spec.tree;
                assert!(
                    j.spec.sum.sig.name.starts_with(&format!("{t}_l")),
                    "{}",
                    j.name()
                );
                let w = wrapper(j);
                // The tree's nodes are `<tree>_l<k>...`: only the sum may appear.
                let nodes = w.matches(&format!("{t}_l")).count();
                let own = w.matches(&j.spec.sum.sig.name).count();
                assert_eq!(nodes, own, "{}: {w}", j.name());
                assert!(!j.cases().is_empty());
            }
        }
    }
}
