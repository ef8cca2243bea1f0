//! The formal proof of the multipliers: every adder tree of a generated design (normalise,
//! linear_index, interpolate, color_mul) equals the plain arithmetic its plan says it builds
//! ([`TreeSpec`]: `a * b + c`), on every input, proved with Yosys's SAT solver (`sat -prove`)
//! on the generated module itself.
//!
//! For each tree, one Yosys script step: the stage's generated module is read from the design
//! directory as it is; the tree's input signals are cut (`expose -cut`: every reader of the
//! signal's net reads a new input `<signal>.i`, driven by the proof) and its sum exposed; a miter module (written here from the
//! specification only) instantiates the stage and compares the sum with `a * b + c` in
//! Verilog; registers are made transparent (a techmap of every flip-flop to `Q = D`, see
//! docs/VERIFICATION.md for why that covers the pipelined tree). Then one of two engines
//! ([`Engine`]) shows that the miter's `ok` is 1 on every input:
//! - SAT: `sat -prove ok 1` runs once per value of the split factor
//!   ([`crate::hdl::tree_spec::Split`]); markers in the log (`rmapgen-mult: tree M T`)
//!   attribute every result to its tree;
//! - exhaustive: the miter is written as an and-inverter graph and evaluated on every input
//!   ([`crate::prove::aig`]), case by case;
//! - algebra: the miter is written as a gate netlist ([`netlist`]) and the sum and the
//!   specification are shown equal as polynomials ([`algebra`]), case by case.

pub mod algebra;
pub mod netlist;
pub mod run;

use crate::config::Config;
use crate::hdl::tree_spec::{Factor, TreeSpec};
use crate::prove::aig::{self, Aig};
use crate::stages;
use algebra::Verdict;
use anyhow::{bail, Result};
use netlist::Netlist;
use rayon::prelude::*;

/// How the trees are proved (`prove-mult --engine`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EngineChoice {
    /// Exhaustive where a tree has at most AUTO_EXHAUSTIVE_INPUTS inputs, else algebra.
    Auto,
    /// Yosys `sat -prove` for every tree.
    Sat,
    /// Every input of every tree (a tree above MAX_EXHAUSTIVE_INPUTS is refused).
    Exhaustive,
    /// The sum and the specification shown equal as polynomials, for every tree.
    Algebra,
}

/// The engine one tree is proved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    Sat,
    Exhaustive,
    Algebra,
}

/// Most inputs (cases x values of the other inputs) that `auto` proves exhaustively: 2^34.
/// Measured here, evaluation costs about a nanosecond per input for the widest normalise
/// tree (about 4,000 gates per case), so 2^34 is minutes on two cores; SAT costs per case,
/// from 0.07 s for a 10-bit symbolic factor to 16 s for 20 bits.
pub const AUTO_EXHAUSTIVE_INPUTS: u128 = 1 << 34;

/// Most inputs `--engine exhaustive` takes for one tree: 2^36 (about an hour).
pub const MAX_EXHAUSTIVE_INPUTS: u128 = 1 << 36;

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

/// Maps Yosys's carry lookahead cell (`$lcu`, which `techmap` makes of every `$alu`) to a
/// ripple carry for the algebraic engine, ahead of Yosys's own Brent-Kung map (a techmap
/// module whose name sorts first wins). The cell's function is fixed by Yosys (`CO[i] = G[i]
/// | P[i] & CO[i-1]`, CI below bit 0); only its gates change. Why: rewriting a prefix
/// adder's polynomial goes through terms that vanish only at the inputs (measured on the
/// widest interpolate sum: past 2 million terms after 97 of 1,296 nodes), where a ripple
/// carry stays linear (97 terms at most, 1.5 ms a case).
pub const RIPPLE_LCU: &str = r#"// rmapgen prove-mult (algebraic engine): $lcu as a ripple carry, the function of
// Yosys's simlib $lcu: CO[i] = G[i] | (P[i] & CO[i-1]), with CI before bit 0.
(* techmap_celltype = "$lcu" *)
module _80_rmapgen_ripple_lcu (P, G, CI, CO);
  parameter WIDTH = 2;
  input [WIDTH-1:0] P, G;
  input CI;
  output [WIDTH-1:0] CO;
  genvar i;
  generate
    for (i = 0; i < WIDTH; i = i + 1) begin : bit
      if (i == 0) begin : first
        assign CO[0] = G[0] | (P[0] & CI);
      end else begin : rest
        assign CO[i] = G[i] | (P[i] & CO[i-1]);
      end
    end
  endgenerate
endmodule
"#;

/// The file [`RIPPLE_LCU`] is written to, in the log directory.
pub const RIPPLE_FILE: &str = "ripple_lcu.v";

/// The file [`TRANSPARENT`] is written to, in the log directory.
pub const TRANSPARENT_FILE: &str = "transparent.v";

/// The marker a script logs before a tree's cases.
pub const MARK: &str = "rmapgen-mult: tree";

/// One tree to prove: its stage module and specification.
#[derive(Clone, Debug)]
pub struct Job {
    pub module: String,
    pub spec: TreeSpec,
    /// The stage's input ports: a tree input that is one is driven through it, not cut.
    pub input_ports: Vec<String>,
}

impl Job {
    /// The tree inputs that are not input ports of the stage: [`script`] cuts these.
    pub fn cut(&self) -> Vec<String> {
        self.spec
            .inputs()
            .into_iter()
            .map(|s| s.name)
            .filter(|n| !self.input_ports.contains(n))
            .collect()
    }

    /// `normalise.pa`.
    pub fn name(&self) -> String {
        format!("{}.{}", self.module, self.spec.tree)
    }

    /// The miter module's name.
    pub fn wrapper_name(&self) -> String {
        format!("mult_proof_{}_{}", self.module, self.spec.tree)
    }

    /// Input bits not fixed by a case: enumerated by the exhaustive engine, symbolic in SAT.
    pub fn free_bits(&self) -> u32 {
        let split: u32 = self.spec.split.as_ref().map_or(0, |s| {
            s.sig.width + s.complement.as_ref().map_or(0, |(c, _)| c.width)
        });
        self.spec.inputs().iter().map(|s| s.width).sum::<u32>() - split
    }

    /// Inputs the exhaustive engine evaluates: cases x 2^free bits (saturating).
    pub fn exhaustive_inputs(&self) -> u128 {
        let per_case = 1u128.checked_shl(self.free_bits()).unwrap_or(u128::MAX);
        per_case.saturating_mul(self.cases().len() as u128)
    }

    /// The engine `choice` gives this tree; an exhaustive choice over
    /// [`MAX_EXHAUSTIVE_INPUTS`] is refused.
    pub fn engine(&self, choice: EngineChoice) -> Result<Engine> {
        let n = self.exhaustive_inputs();
        Ok(match choice {
            EngineChoice::Sat => Engine::Sat,
            EngineChoice::Auto if n <= AUTO_EXHAUSTIVE_INPUTS => Engine::Exhaustive,
            EngineChoice::Auto | EngineChoice::Algebra => Engine::Algebra,
            EngineChoice::Exhaustive if n <= MAX_EXHAUSTIVE_INPUTS => Engine::Exhaustive,
            EngineChoice::Exhaustive => bail!(
                "--engine exhaustive: {} has {} inputs, more than {} (use --engine auto or sat)",
                self.name(),
                count(n),
                count(MAX_EXHAUSTIVE_INPUTS)
            ),
        })
    }

    /// The and-inverter graph files the exhaustive engine has Yosys write.
    pub fn aig_files(&self) -> (String, String) {
        let w = self.wrapper_name();
        (format!("{w}.aag"), format!("{w}.map"))
    }

    /// The gate netlist the algebraic engine has Yosys write.
    pub fn json_file(&self) -> String {
        format!("{}.json", self.wrapper_name())
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

/// An input count for messages: `2^32` when a power of two, else the number.
pub fn count(n: u128) -> String {
    if n.is_power_of_two() {
        format!("2^{}", n.trailing_zeros())
    } else {
        n.to_string()
    }
}

/// Every tree of the design of `cfg`, stage by stage in pipeline order.
pub fn jobs(cfg: &Config) -> Vec<Job> {
    stages::modules(cfg)
        .into_iter()
        .flat_map(|u| {
            let module = u.module(cfg);
            let input_ports: Vec<String> = u
                .ports(cfg)
                .iter()
                .filter(|p| p.dir == crate::hdl::Dir::Input)
                .map(|p| p.name.to_string())
                .collect();
            u.trees(cfg).into_iter().map(move |spec| Job {
                module: module.clone(),
                spec,
                input_ports: input_ports.clone(),
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
        // `expose -cut` names the input that replaces a cut signal `<signal>.i` (an escaped
        // identifier, ended by the space); an input port is driven as it is.
        if job.input_ports.contains(&s.name) {
            v.push_str(&format!("    .{0} ({0}),\n", s.name));
        } else {
            v.push_str(&format!("    .\\{0}.i ({0}),\n", s.name));
        }
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
/// `wrappers` the miter files and `engines` the engines (one per job, same order),
/// `transparent` the techmap file. A SAT job runs its cases; an exhaustive job has its miter
/// mapped to AND and NOT gates and written as ASCII AIGER ([`Job::aig_files`]).
pub fn script(
    files: &[String],
    jobs: &[Job],
    engines: &[Engine],
    wrappers: &[String],
    transparent: &str,
) -> String {
    let mut s = String::new();
    s.push_str(&format!("read_verilog {}\n", files.join(" ")));
    s.push_str("proc\ndesign -save rmapgen_base\n");
    for ((job, file), engine) in jobs.iter().zip(wrappers).zip(engines) {
        let m = &job.module;
        let cut: Vec<String> = job.cut().iter().map(|x| format!("{m}/{x}")).collect();
        s.push_str("design -load rmapgen_base\n");
        // -cut, not -input: -input disconnects the wire's driver only, and a reader that
        // names the same net otherwise (a stage input port the signal is an alias of, as
        // `recip_q1` of `recip_data_i` at pipeline depth 0, or the output of the cell that
        // drives it) would go on reading the stage's own logic. -cut replaces the net for
        // every reader.
        if !cut.is_empty() {
            s.push_str(&format!("expose -cut {}\n", cut.join(" ")));
        }
        s.push_str(&format!("expose {m}/{}\n", job.spec.sum.sig.name));
        s.push_str(&format!("read_verilog {file}\n"));
        s.push_str(&format!(
            "hierarchy -top {0}\nproc\nflatten\nopt_clean\nopt_dff\ntechmap -map {transparent}\nopt -fast\n",
            job.wrapper_name()
        ));
        if *engine == Engine::Exhaustive {
            let (aag, map) = job.aig_files();
            s.push_str(&format!(
                "techmap\nopt -fast\naigmap\nopt_clean\nwrite_aiger -ascii -map {map} {aag}\n"
            ));
            continue;
        }
        if *engine == Engine::Algebra {
            s.push_str(&format!(
                "techmap -map +/techmap.v -map {RIPPLE_FILE}\nopt -fast\nopt_clean\nwrite_json {}\n",
                job.json_file()
            ));
            continue;
        }
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
    pub engine: Engine,
    pub cases: usize,
    pub proved: usize,
    /// The first failing case's assignments, as `sig = value` text (empty: no split).
    pub failed: Option<String>,
    /// Why an engine could not decide (the tree is then not proved, and not failed).
    pub undecided: Option<String>,
    /// The algebraic engine's largest polynomial, in terms.
    pub peak_terms: usize,
}

impl TreeResult {
    pub fn passed(&self) -> bool {
        self.failed.is_none() && self.undecided.is_none() && self.proved == self.cases
    }
}

/// The exhaustive engine's result for `job`, from the AIGER file and map Yosys wrote: every
/// case, every value of the other inputs; the first failing input named.
pub fn exhaustive(job: &Job, aag: &str, map: &str) -> Result<TreeResult> {
    let graph = Aig::parse(aag, map)?;
    let cases = job.cases();
    let failed = aig::exhaustive(&graph, &cases)?;
    Ok(TreeResult {
        name: job.name(),
        title: job.spec.title.clone(),
        engine: Engine::Exhaustive,
        cases: cases.len(),
        proved: if failed.is_some() { 0 } else { cases.len() },
        failed: failed.map(|sigs| assignment_text(&sigs)),
        undecided: None,
        peak_terms: 0,
    })
}

/// One case of the algebraic engine: the verdict, its figures and the free inputs (port,
/// bit) the verdict's input gives values to.
type CaseOutcome = (Verdict, algebra::Stats, Vec<(String, u32)>);

fn assignment_text(sigs: &[(String, u128)]) -> String {
    sigs.iter()
        .map(|(x, v)| format!("{x} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The specification `sum of a * b << shift, plus c` as a polynomial over the free input
/// bits `free` of a case's circuit (variable k + 1 is `free[k]`), the other bits being the
/// constants `fixed` gives them: each word is `sum 2^i x_i`, and the products are multiplied
/// out, coefficients modulo 2^64 (the engine reduces them modulo 2^m <= 2^64); with its
/// largest value in the case under the premises (an upper bound: exact but for a signal in
/// two products). It is the same [`TreeSpec`] the miter's Verilog `spec` is written from
/// ([`wrapper`]), stated as arithmetic, not gates.
fn spec_polynomial(
    t: &TreeSpec,
    free: &[(String, u32)],
    fixed: &impl Fn(&str, usize) -> Option<bool>,
) -> Result<(Vec<algebra::Term>, u128)> {
    // A word's bits that are not the constant 0: (its variable, or None for a constant
    // 1, and the bit's position).
    let word = |name: &str, width: u32| -> Result<Vec<(Option<u32>, u32)>> {
        let mut out = Vec::new();
        for i in 0..width {
            match fixed(name, i as usize) {
                Some(false) => {}
                Some(true) => out.push((None, i)),
                None => match free.iter().position(|(p, b)| p == name && *b == i) {
                    Some(k) => out.push((Some(k as u32 + 1), i)),
                    None => bail!("input bit {name}[{i}] is neither free nor fixed in the netlist"),
                },
            }
        }
        Ok(out)
    };
    // 2^e modulo 2^64.
    let pow = |e: u32| if e < 64 { 1u64 << e } else { 0 };
    // A word's largest value here under the premises: every bit that is not the constant 0
    // set, or the premise's bound if that is less.
    let top = |name: &str, w: &[(Option<u32>, u32)]| {
        let all = w.iter().map(|&(_, i)| 1u128 << i).sum::<u128>();
        t.at_most
            .iter()
            .filter(|(s, _)| s.name == name)
            .fold(all, |m, &(_, b)| m.min(b))
    };
    let (mut terms, mut max) = (Vec::new(), t.constant);
    for p in &t.products {
        let a = word(&p.a.name, p.a.width)?;
        match &p.b {
            Factor::Sig(sig) => {
                let b = word(&sig.name, sig.width)?;
                max += (top(&p.a.name, &a) * top(&sig.name, &b)) << p.shift;
                for &(x, i) in &a {
                    for &(y, j) in &b {
                        terms.push((x.into_iter().chain(y).collect(), pow(i + j + p.shift)));
                    }
                }
            }
            Factor::Const(k) => {
                max += (top(&p.a.name, &a) * k) << p.shift;
                for &(x, i) in &a {
                    terms.push((
                        x.into_iter().collect(),
                        (*k as u64).wrapping_mul(pow(i + p.shift)),
                    ));
                }
            }
        }
    }
    terms.push((Vec::new(), t.constant as u64));
    Ok((terms, max))
}

/// The algebraic engine's result for `job`, from the gate netlist Yosys wrote
/// ([`Job::json_file`]). For each case the miter's `got` word is shown equal to the
/// specification modulo 2^m as polynomials over the free input bits, the specification's
/// polynomial computed from the [`TreeSpec`] ([`spec_polynomial`]) rather than rewritten
/// from the miter's gates (docs/VERIFICATION.md, "The algebraic engine", gives why that is
/// the miter's `ok` on every input):
/// - m, per case, is the least with both words below 2^m: at least the bit length of the
///   specification's largest value in the case, and above the sum's highest bit that is
///   not the constant 0 in the case's circuit; so equal modulo 2^m is equal;
/// - an input bounded by a premise (`x <= bound`) has its bits at and above the bound's
///   length fixed at 0: an input with one of them set breaks the premise.
pub fn algebraic(job: &Job, json: &str) -> Result<TreeResult> {
    let t = &job.spec;
    let net = Netlist::parse(json, &job.wrapper_name())?;
    let cases = job.cases();
    let ports = net.input_ports();
    aig::cases_name_inputs(&cases, |s| ports.iter().any(|(p, _)| p == s))?;
    let bound_bits: Vec<(String, u32)> = t
        .at_most
        .iter()
        .map(|(s, b)| (s.name.clone(), bits(*b)))
        .collect();
    let outcomes: Vec<Result<CaseOutcome>> = cases
        .par_iter()
        .map(|case| {
            let fixed = |p: &str, i: usize| {
                if let Some((_, v)) = case.iter().find(|(s, _)| s == p) {
                    return Some((v >> i) & 1 == 1);
                }
                bound_bits
                    .iter()
                    .any(|(s, b)| s == p && i as u32 >= *b)
                    .then_some(false)
            };
            let c = net.simplify(&["got"], fixed)?;
            let (spec, max) = spec_polynomial(t, &c.inputs, &fixed)?;
            // Compared modulo 2^m, m the least with both words below 2^m in this case: the
            // specification's largest value here has m bits at most, and the sum's bits
            // from m up are the constant 0 in this case's circuit. Then equal modulo 2^m is
            // equal. The least m matters: a sum narrower than the miter's word (a0's 17
            // bits of 19) is a truncated adder, whose dropped carries only cancel modulo
            // 2^17, after the polynomial passed 2 million terms modulo 2^19.
            let top = c.outputs[0]
                .iter()
                .rposition(|&l| l != 0)
                .map_or(0, |i| i + 1);
            let m = bits(max).max(top as u32);
            if m > 64 {
                bail!("its words have {m} bits, over the engine's 64");
            }
            let (v, stats) = algebra::equals_polynomial(&c, 0, &spec, m)?;
            Ok((v, stats, c.inputs))
        })
        .collect();
    let mut r = TreeResult {
        name: job.name(),
        title: t.title.clone(),
        engine: Engine::Algebra,
        cases: cases.len(),
        proved: 0,
        failed: None,
        undecided: None,
        peak_terms: 0,
    };
    for (case, o) in cases.iter().zip(outcomes) {
        let (v, stats, free) = match o {
            Ok(x) => x,
            Err(e) => {
                r.undecided = Some(format!("{e:#}"));
                break;
            }
        };
        r.peak_terms = r.peak_terms.max(stats.peak);
        let Verdict::Differ { input, .. } = v else {
            r.proved += 1;
            continue;
        };
        // The failing input: the case's values, the free bits, 0 elsewhere.
        let mut sigs: Vec<(String, u128)> =
            t.inputs().iter().map(|s| (s.name.clone(), 0)).collect();
        for (s, v) in case {
            if let Some(x) = sigs.iter_mut().find(|(n, _)| n == s) {
                x.1 = *v;
            }
        }
        // Free inputs beyond the specification's (a stage input the miter leaves open) are
        // named too.
        for ((p, bit), &on) in free.iter().zip(&input) {
            match sigs.iter_mut().find(|(n, _)| n == p) {
                Some(x) => x.1 |= (on as u128) << bit,
                None => sigs.push((p.clone(), (on as u128) << bit)),
            }
        }
        let broken = t
            .at_most
            .iter()
            .find(|(s, b)| sigs.iter().any(|(n, v)| *n == s.name && v > b));
        match broken {
            None => r.failed = Some(assignment_text(&sigs)),
            Some((s, b)) => {
                r.undecided = Some(format!(
                    "the sum and the specification differ at {}, where the premise {} <= {b} does not hold (the polynomial identity is needed on every input below the bound's bit length)",
                    assignment_text(&sigs),
                    s.name
                ))
            }
        }
        break;
    }
    Ok(r)
}

/// Reads the results of the SAT jobs out of the Yosys log of [`script`] (an exhaustive job's
/// entry is a placeholder, proved nothing, for [`exhaustive`] to replace).
pub fn results(jobs: &[Job], log: &str) -> Vec<TreeResult> {
    let mut out: Vec<TreeResult> = jobs
        .iter()
        .map(|j| TreeResult {
            name: j.name(),
            title: j.spec.title.clone(),
            engine: Engine::Sat,
            cases: j.cases().len(),
            proved: 0,
            failed: None,
            undecided: None,
            peak_terms: 0,
        })
        .collect();
    // The tree whose cases the log is in, and its cases finished so far: a FAIL is the case
    // after those.
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
                    out[i].failed = Some(assignment_text(&case));
                }
                // The tree has failed: what follows in it is not read, so no count.
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid;
    use crate::hdl::adder_tree::{Sig, Sum};
    use crate::hdl::tree_spec::{Product, Split};

    /// A tree of every kind of term: `((a * w) << 1) + b * 3 + 2` into the 6-bit node
    /// `t_l2_s0` that holds the sum shifted right once, `b <= 9`, split on `w` in 0..=5 with
    /// `v = 5 - w`; `a` and `v` are input ports of the stage `m`, `w` and `b` are not.
    fn example() -> Job {
        Job {
            module: "m".into(),
            spec: TreeSpec {
                tree: "t".into(),
                title: "a w 2 + 3 b + 2".into(),
                products: vec![
                    Product {
                        a: Sig::new("a", 4),
                        b: Factor::Sig(Sig::new("w", 3)),
                        shift: 1,
                    },
                    Product {
                        a: Sig::new("b", 4),
                        b: Factor::Const(3),
                        shift: 0,
                    },
                ],
                constant: 2,
                sum: Sum {
                    sig: Sig::new("t_l2_s0", 6),
                    shift: 1,
                },
                at_most: vec![(Sig::new("b", 4), 9)],
                split: Some(Split {
                    sig: Sig::new("w", 3),
                    last: 5,
                    complement: Some((Sig::new("v", 3), 5)),
                }),
            },
            input_ports: vec!["clk_i".into(), "a".into(), "v".into()],
        }
    }

    /// A job of one product `a * b` of `wa` and `wb` bits, unsplit: 2^(wa + wb) inputs.
    fn unsplit(wa: u32, wb: u32) -> Job {
        let mut j = example();
        j.spec.products = vec![Product {
            a: Sig::new("a", wa),
            b: Factor::Sig(Sig::new("b", wb)),
            shift: 0,
        }];
        j.spec.split = None;
        j.spec.at_most.clear();
        j
    }

    /// A job's names, inputs, cut and cases follow from its specification alone.
    #[test]
    fn a_job_is_named_counted_and_split_from_its_specification() {
        let j = example();
        assert_eq!(j.name(), "m.t");
        assert_eq!(j.wrapper_name(), "mult_proof_m_t");
        assert_eq!(
            j.aig_files(),
            ("mult_proof_m_t.aag".into(), "mult_proof_m_t.map".into())
        );
        assert_eq!(j.json_file(), "mult_proof_m_t.json");
        assert_eq!(j.cut(), ["w", "b"]);
        // a, w, b, v: 14 bits, of which the split fixes w and v.
        assert_eq!(j.free_bits(), 8);
        let cases = j.cases();
        assert_eq!(cases.len(), 6);
        for (k, c) in cases.iter().enumerate() {
            assert_eq!(
                *c,
                [
                    ("w".to_string(), k as u128),
                    ("v".to_string(), 5 - k as u128)
                ]
            );
        }
        assert_eq!(j.exhaustive_inputs(), 6 << 8);
        // Unsplit: one case, every bit free.
        let u = unsplit(5, 4);
        assert_eq!(u.cases(), vec![Vec::new()]);
        assert_eq!((u.free_bits(), u.exhaustive_inputs()), (9, 512));
        // Past 128 free bits the count saturates rather than wrapping.
        assert_eq!(unsplit(100, 40).exhaustive_inputs(), u128::MAX);
        assert_eq!(count(1 << 32), "2^32");
        assert_eq!(count(1), "2^0");
        assert_eq!(count(1536), "1536");
        assert_eq!(count(u128::MAX), u128::MAX.to_string());
        // A failing input as the messages give it.
        assert_eq!(assignment_text(&cases[2]), "w = 2, v = 3");
        assert_eq!(assignment_text(&[]), "");
    }

    /// `auto` is exhaustive up to AUTO_EXHAUSTIVE_INPUTS inclusive, `exhaustive` up to
    /// MAX_EXHAUSTIVE_INPUTS inclusive; `algebra` and `sat` are what they say whatever the
    /// size.
    #[test]
    fn the_engine_bounds_are_inclusive() {
        let at_auto = unsplit(17, 17);
        assert_eq!(at_auto.exhaustive_inputs(), AUTO_EXHAUSTIVE_INPUTS);
        assert_eq!(
            at_auto.engine(EngineChoice::Auto).unwrap(),
            Engine::Exhaustive
        );
        let above_auto = unsplit(17, 18);
        assert_eq!(
            above_auto.engine(EngineChoice::Auto).unwrap(),
            Engine::Algebra
        );
        assert_eq!(
            above_auto.engine(EngineChoice::Exhaustive).unwrap(),
            Engine::Exhaustive
        );
        let at_max = unsplit(18, 18);
        assert_eq!(at_max.exhaustive_inputs(), MAX_EXHAUSTIVE_INPUTS);
        assert_eq!(
            at_max.engine(EngineChoice::Exhaustive).unwrap(),
            Engine::Exhaustive
        );
        let e = unsplit(18, 19)
            .engine(EngineChoice::Exhaustive)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "--engine exhaustive: m.t has 2^37 inputs, more than 2^36 (use --engine auto or sat)"
        );
        let small = unsplit(2, 2);
        assert_eq!(
            small.engine(EngineChoice::Algebra).unwrap(),
            Engine::Algebra
        );
        assert_eq!(small.engine(EngineChoice::Sat).unwrap(), Engine::Sat);
        assert_eq!(
            small.engine(EngineChoice::Auto).unwrap(),
            Engine::Exhaustive
        );
    }

    /// The miter of the example, whole: the cut inputs driven through `expose -cut`'s
    /// escaped names, the ports as they are, the specification as Verilog arithmetic in the
    /// bits of its largest value (2 * 15 * 7 + 3 * 9 + 2 = 239: 8 bits, above the sum's
    /// 6), the sum widened and shifted back, and the premise.
    #[test]
    fn the_miter_states_the_specification_as_arithmetic() {
        let want = "\
// rmapgen prove-mult: m.t = a w 2 + 3 b + 2 (generated from the plan's specification)
module mult_proof_m_t (
  input wire clk_i,
  input wire [3:0] a,
  input wire [2:0] w,
  input wire [3:0] b,
  input wire [2:0] v,
  output wire ok
);
  wire [5:0] sum;
  m u_dut (
    .clk_i (clk_i),
    .a (a),
    .\\w.i (w),
    .\\b.i (b),
    .v (v),
    .t_l2_s0 (sum)
  );
  // The plain arithmetic, evaluated in 8 bits (no overflow: the largest value fits).
  wire [7:0] spec;
  assign spec = ((a * w) << 1) + (b * 8'd3) + 8'd2;
  wire [7:0] got;
  assign got = {{2{1'b0}}, sum} << 1;
  assign ok = !((b <= 4'd9)) || (got == spec);
endmodule
";
        assert_eq!(wrapper(&example()), want);
        // No premise, no constant, a sum as wide as the arithmetic.
        let mut u = unsplit(3, 2);
        u.spec.constant = 0;
        u.spec.sum.shift = 0;
        u.spec.sum.sig.width = 5;
        let w = wrapper(&u);
        assert!(w.contains("  assign spec = (a * b);\n"), "{w}");
        assert!(w.contains("  assign got = {{0{1'b0}}, sum} << 0;\n"), "{w}");
        assert!(
            w.contains("  assign ok = !(1'b1) || (got == spec);\n"),
            "{w}"
        );
        // A premise's bound wider than its signal is compared in the bound's bits.
        let mut p = example();
        p.spec.at_most = vec![(Sig::new("b", 4), 40)];
        assert!(wrapper(&p).contains("!((b <= 6'd40))"));
    }

    /// The script of three jobs, one per engine: the design read once and saved, each job
    /// from the saved design with its cut, its sum exposed and its miter; the exhaustive
    /// job's AIGER, the algebraic job's gate netlist (the ripple carry map), the SAT job's
    /// marker and one `sat` per case.
    #[test]
    fn the_script_proves_each_job_with_its_engine() {
        let mut k = unsplit(3, 2);
        k.module = "n".into();
        k.spec.tree = "u".into();
        let jobs = vec![example(), k, example()];
        let s = script(
            &["d1.v".into(), "d2.v".into()],
            &jobs,
            &[Engine::Exhaustive, Engine::Algebra, Engine::Sat],
            &["w1.v".into(), "w2.v".into(), "w3.v".into()],
            "tr.v",
        );
        let common = |cut: &str, m: &str, file: &str, top: &str| {
            format!(
                "design -load rmapgen_base\nexpose -cut {cut}\nexpose {m}/t_l2_s0\nread_verilog {file}\n\
                 hierarchy -top {top}\nproc\nflatten\nopt_clean\nopt_dff\ntechmap -map tr.v\nopt -fast\n"
            )
        };
        let want = format!(
            "read_verilog d1.v d2.v\nproc\ndesign -save rmapgen_base\n\
             {}techmap\nopt -fast\naigmap\nopt_clean\n\
             write_aiger -ascii -map mult_proof_m_t.map mult_proof_m_t.aag\n\
             {}techmap -map +/techmap.v -map ripple_lcu.v\nopt -fast\nopt_clean\n\
             write_json mult_proof_n_u.json\n\
             {}log rmapgen-mult: tree m t\n{}",
            common("m/w m/b", "m", "w1.v", "mult_proof_m_t"),
            common("n/b", "n", "w2.v", "mult_proof_n_u"),
            common("m/w m/b", "m", "w3.v", "mult_proof_m_t"),
            (0..=5)
                .map(|w| format!(
                    "sat -set w {w} -set v {} -prove ok 1 mult_proof_m_t\n",
                    5 - w
                ))
                .collect::<String>()
        );
        assert_eq!(s, want);
        // A job whose inputs are all ports is cut nowhere.
        let mut all_ports = unsplit(3, 2);
        all_ports.input_ports = vec!["a".into(), "b".into()];
        let s = script(
            &["d.v".into()],
            &[all_ports],
            &[Engine::Sat],
            &["w.v".into()],
            "t.v",
        );
        assert!(!s.contains("expose -cut"), "{s}");
        assert!(s.contains("\nsat -prove ok 1 mult_proof_m_t\n"), "{s}");
    }

    /// The SAT results are read from the log by tree: each SUCCESS after a tree's marker is
    /// one case proved, the first FAIL names its case by its place among the tree's cases; a
    /// result before any marker or after an unknown tree's counts for no tree.
    #[test]
    fn the_sat_log_is_read_tree_by_tree() {
        let mut k = unsplit(3, 2);
        k.spec.tree = "u".into();
        let jobs = vec![example(), k];
        let ok = "SAT proof finished - no model found: SUCCESS!";
        let fail = "SAT proof finished - model found: FAIL!";
        let log = [
            ok,
            "  rmapgen-mult: tree m t",
            ok,
            ok,
            fail,
            ok,
            fail,
            "rmapgen-mult: tree m nosuch",
            ok,
            "rmapgen-mult: tree m u",
            ok,
        ]
        .join("\n");
        let r = results(&jobs, &log);
        assert_eq!(r.len(), 2);
        assert_eq!(
            (r[0].name.as_str(), r[0].engine, r[0].cases),
            ("m.t", Engine::Sat, 6)
        );
        assert_eq!(r[0].proved, 3);
        assert_eq!(r[0].failed.as_deref(), Some("w = 2, v = 3"));
        assert!(!r[0].passed());
        assert_eq!((r[1].name.as_str(), r[1].cases, r[1].proved), ("m.u", 1, 1));
        assert_eq!(r[1].failed, None);
        assert!(r[1].passed());
        // A tree never reached proved nothing, and did not pass.
        let r = results(&jobs, "");
        assert_eq!((r[1].proved, r[1].failed.as_deref()), (0, None));
        assert!(!r[1].passed());
        // Undecided is not passed, whatever the count.
        let mut t = results(&jobs, &log).remove(1);
        t.undecided = Some("why".into());
        assert!(!t.passed());
    }

    /// The specification's polynomial, evaluated on every value of the example's free bits
    /// in every case, is the specification's arithmetic (modulo 2^64), and its bound is the
    /// largest value under the premises: 2 * 15 * w + 3 * 9 + 2 in case w.
    #[test]
    fn the_specification_polynomial_is_the_arithmetic() {
        let j = example();
        let t = &j.spec;
        for case in j.cases() {
            let w = case[0].1;
            // b's bits from 4 up are fixed by the premise only in the engine; here b is
            // free in all of its 4 bits, a in its 4; w and v fixed by the case.
            let fixed = |p: &str, i: usize| -> Option<bool> {
                case.iter()
                    .find(|(s, _)| s == p)
                    .map(|(_, v)| (v >> i) & 1 == 1)
            };
            let free: Vec<(String, u32)> = (0..4)
                .map(|i| ("a".to_string(), i))
                .chain((0..4).map(|i| ("b".to_string(), i)))
                .collect();
            let (terms, max) = spec_polynomial(t, &free, &fixed).unwrap();
            assert_eq!(max, 2 * 15 * w + 3 * 9 + 2, "w = {w}");
            for x in 0..256u64 {
                let (a, b) = (x & 15, x >> 4);
                let value = terms.iter().fold(0u64, |acc, (vars, k)| {
                    let on = vars.iter().all(|&v| (x >> (v - 1)) & 1 == 1);
                    acc.wrapping_add(if on { *k } else { 0 })
                });
                assert_eq!(
                    value,
                    2 * a * w as u64 + 3 * b + 2,
                    "w = {w}, a = {a}, b = {b}"
                );
            }
        }
        // A bit neither fixed nor free is an error naming it.
        let e = spec_polynomial(t, &[], &|_: &str, _| None)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "input bit a[0] is neither free nor fixed in the netlist");
        // Past 2^64 the coefficients wrap: (3 a) << 63 is a[0] 2^63 (3 * 2^63 modulo 2^64), and
        // a[1]'s 3 * 2^64 vanishes.
        let mut wide = unsplit(2, 1);
        wide.spec.products = vec![Product {
            a: Sig::new("a", 2),
            b: Factor::Const(3),
            shift: 63,
        }];
        let free = [("a".to_string(), 0), ("a".to_string(), 1)];
        let (terms, max) = spec_polynomial(&wide.spec, &free, &|_: &str, _| None).unwrap();
        assert_eq!(
            max,
            (9 << 63) + 2,
            "the bound (constant 2 included) is exact, in 128 bits"
        );
        assert_eq!(terms[0], (vec![1], 1u64 << 63));
        assert_eq!(terms[1], (vec![2], 0));
    }

    /// The gates of `got = a * w`, a 3-bit `a` by a 2-bit `w` (shift-and-add: six partial
    /// products, then a row of half and full adders), as Yosys writes a miter's netlist
    /// (`write_json`): module `mult_proof_m_t`, input ports `a` (nets 2 to 4) and `w` (5 and
    /// 6), the wire `got` widened by a constant 0. The tests below edit it to plant faults.
    fn product_netlist() -> serde_json::Value {
        use serde_json::json;
        let mut cells = serde_json::Map::new();
        let mut next = 10u64;
        let mut gate = |name: &str, ty: &str, a: u64, b: u64| -> u64 {
            next += 1;
            let conn = json!({"A": [a], "B": [b], "Y": [next]});
            cells.insert(name.into(), json!({"type": ty, "connections": conn}));
            next
        };
        let (a, w) = ([2u64, 3, 4], [5u64, 6]);
        let p0: Vec<u64> = (0..3)
            .map(|i| gate(&format!("p0_{i}"), "$_AND_", a[i], w[0]))
            .collect();
        let p1: Vec<u64> = (0..3)
            .map(|i| gate(&format!("p1_{i}"), "$_AND_", a[i], w[1]))
            .collect();
        let s1 = gate("s1", "$_XOR_", p0[1], p1[0]);
        let c1 = gate("c1", "$_AND_", p0[1], p1[0]);
        let t2 = gate("t2", "$_XOR_", p0[2], p1[1]);
        let s2 = gate("s2", "$_XOR_", t2, c1);
        let g2 = gate("g2", "$_AND_", p0[2], p1[1]);
        let u2 = gate("u2", "$_AND_", t2, c1);
        let c2 = gate("c2", "$_OR_", g2, u2);
        let s3 = gate("s3", "$_XOR_", p1[2], c2);
        let c3 = gate("c3", "$_AND_", p1[2], c2);
        json!({"modules": {"mult_proof_m_t": {
            "ports": {"a": {"direction": "input", "bits": a},
                      "w": {"direction": "input", "bits": w}},
            "cells": cells,
            "netnames": {"got": {"bits": [p0[0], s1, s2, s3, c3, "0"]}}
        }}})
    }

    /// The job of [`product_netlist`]: `a * w`, split on `w`, `a <= bound` when given.
    fn product_job(bound: Option<u128>) -> Job {
        let mut j = example();
        j.spec.products = vec![Product {
            a: Sig::new("a", 3),
            b: Factor::Sig(Sig::new("w", 2)),
            shift: 0,
        }];
        j.spec.constant = 0;
        j.spec.at_most = bound.map(|b| (Sig::new("a", 3), b)).into_iter().collect();
        j.spec.split = Some(Split {
            sig: Sig::new("w", 2),
            last: 3,
            complement: None,
        });
        j
    }

    /// The algebraic engine on a netlist: the product proved in each of its four cases; a
    /// planted fault failed with the input that shows it (the case's values, the free bits,
    /// an open net by its wire); a premise fixes the input bits above its bound's length,
    /// and a difference only where a premise does not hold is undecided, not failed; a sum
    /// bit above the specification's width is compared too; words past 64 bits and a case
    /// signal the netlist lacks are refused.
    #[test]
    fn the_algebraic_engine_proves_fails_and_respects_premises() {
        let run = |job: &Job, edit: &dyn Fn(&mut serde_json::Value)| {
            let mut v = product_netlist();
            edit(&mut v["modules"]["mult_proof_m_t"]);
            algebraic(job, &v.to_string()).unwrap()
        };
        let cell = |name: &'static str, ty: &'static str, a: Option<u64>| {
            move |m: &mut serde_json::Value| {
                m["cells"][name]["type"] = ty.into();
                if let Some(a) = a {
                    m["cells"][name]["connections"]["B"] = serde_json::json!([a]);
                }
            }
        };
        let r = run(&product_job(None), &|_| {});
        assert_eq!((r.name.as_str(), r.engine), ("m.t", Engine::Algebra));
        assert_eq!((r.cases, r.proved), (4, 4));
        assert!(r.passed() && r.peak_terms > 0, "{r:?}");
        // a1 & w1 made an XOR: with w = 0 it is a1.
        let r = run(&product_job(None), &cell("p1_1", "$_XOR_", None));
        assert_eq!(r.failed.as_deref(), Some("a = 2, w = 0"), "{r:?}");
        assert_eq!((r.proved, r.undecided.as_deref()), (0, None));
        // The half adder of bit 1 reads an open net (a stage input the miter leaves open),
        // bit 1 of the wire that names it.
        let r = run(&product_job(None), &|m| {
            m["cells"]["s1"]["connections"]["B"] = serde_json::json!([77]);
            m["netnames"]["u_dut.open"] = serde_json::json!({"bits": [76, 77]});
        });
        assert_eq!(
            r.failed.as_deref(),
            Some("a = 0, w = 0, u_dut.open = 2"),
            "{r:?}"
        );
        // a2 & w0 made a2 alone: wrong wherever a >= 4 and w is even.
        let buf = cell("p0_2", "$_BUF_", None);
        let r = run(&product_job(None), &buf);
        assert_eq!(r.failed.as_deref(), Some("a = 4, w = 0"), "{r:?}");
        let r = run(&product_job(Some(4)), &buf);
        assert_eq!(r.failed.as_deref(), Some("a = 4, w = 0"), "{r:?}");
        // Under a <= 3, a2 is fixed at 0 and the tree is right.
        let r = run(&product_job(Some(3)), &buf);
        assert!(r.passed(), "{r:?}");
        // a1 & w0 made a1 & a2: wrong only at a = 6 or 7, beyond a <= 5.
        let and_a2 = cell("p0_1", "$_AND_", Some(4));
        let r = run(&product_job(Some(6)), &and_a2);
        assert_eq!(r.failed.as_deref(), Some("a = 6, w = 0"), "{r:?}");
        let r = run(&product_job(Some(5)), &and_a2);
        assert_eq!(r.failed, None);
        assert_eq!(
            r.undecided.as_deref(),
            Some("the sum and the specification differ at a = 6, w = 0, where the premise a <= 5 does not hold (the polynomial identity is needed on every input below the bound's bit length)")
        );
        assert!(!r.passed());
        // got's top bit, a constant 0 of the miter, driven by a0 & w0: 32 too many at a = 1,
        // w = 1, above the 3 bits of the case's largest value (7).
        let r = run(&product_job(None), &|m| {
            let p = m["cells"]["p0_0"]["connections"]["Y"][0].clone();
            m["netnames"]["got"]["bits"][5] = p;
        });
        assert_eq!(
            (r.proved, r.failed.as_deref()),
            (1, Some("a = 1, w = 1")),
            "{r:?}"
        );
        // A specification past 64 bits: 0 in case w = 0 (proved), 7 << 62 in case w = 1.
        let mut wide = product_job(None);
        wide.spec.products[0].shift = 62;
        let r = run(&wide, &|_| {});
        assert_eq!(
            (r.proved, r.undecided.as_deref()),
            (1, Some("its words have 65 bits, over the engine's 64"))
        );
        // Exactly 64 bits (7 << 61) are compared, and differ: a against a << 61.
        wide.spec.products[0].shift = 61;
        let r = run(&wide, &|_| {});
        assert_eq!(
            (r.undecided, r.failed.as_deref()),
            (None, Some("a = 1, w = 1"))
        );
        // A case on a signal the netlist does not have.
        let mut other = product_job(None);
        other.spec.split.as_mut().unwrap().sig = Sig::new("v", 2);
        let e = algebraic(&other, &product_netlist().to_string()).unwrap_err();
        assert!(e.to_string().contains("v"), "{e}");
    }

    /// `auto` takes every tree of every row of the grid, exhaustive where it is cheap: the
    /// widest normalise tree (2^32 inputs) is exhaustive, the widest interpolate sum algebra;
    /// `--engine exhaustive` refuses that one, naming it.
    #[test]
    fn engines_follow_the_input_counts() {
        for r in grid::rows() {
            for j in jobs(&r.config) {
                let e = j.engine(EngineChoice::Auto).unwrap();
                assert_eq!(
                    e == Engine::Exhaustive,
                    j.exhaustive_inputs() <= AUTO_EXHAUSTIVE_INPUTS,
                    "{}: {}",
                    r.name,
                    j.name()
                );
                assert_eq!(j.engine(EngineChoice::Sat).unwrap(), Engine::Sat);
            }
        }
        let widest = jobs(&grid::row("widest").unwrap().config);
        let pa = widest.iter().find(|j| j.name() == "normalise.pa").unwrap();
        assert_eq!(pa.exhaustive_inputs(), 1 << 32);
        assert_eq!(pa.engine(EngineChoice::Auto).unwrap(), Engine::Exhaustive);
        let r = widest.iter().find(|j| j.name() == "interpolate.r").unwrap();
        assert_eq!(r.engine(EngineChoice::Auto).unwrap(), Engine::Algebra);
        let e = r.engine(EngineChoice::Exhaustive).unwrap_err().to_string();
        assert!(e.contains("interpolate.r") && e.contains("2^36"), "{e}");
    }

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

    /// A job's ports are its stage's input ports (lowRISC: `_i`, `_ni`), the clock the miter drives
    /// among them, and no output port.
    #[test]
    fn a_jobs_ports_are_its_stages_inputs() {
        for r in grid::rows() {
            for j in jobs(&r.config) {
                let p = &j.input_ports;
                assert!(p.iter().any(|x| x == "clk_i"), "{}: {p:?}", j.name());
                assert!(
                    p.iter().all(|x| x.ends_with("_i") || x.ends_with("_ni")),
                    "{}: {p:?}",
                    j.name()
                );
            }
        }
    }

    /// The proof is for every value of a tree's inputs, not only those its drivers give it:
    /// the script frees every tree input that is not an input port of the stage (`expose
    /// -cut`, one net per name, each a real signal of the tree), and some trees have such
    /// inputs (registers inside the stage). A cut list of one empty name (cargo-mutants'
    /// `Job::cut` -> `vec![String::new()]`) cut nothing and narrowed the claim.
    #[test]
    fn every_tree_input_that_is_not_a_port_is_cut() {
        let mut cut_somewhere = 0;
        for r in grid::rows() {
            let jobs = jobs(&r.config);
            let engines = vec![Engine::Sat; jobs.len()];
            let wrappers: Vec<String> = jobs.iter().map(|j| format!("{}.v", j.name())).collect();
            let s = script(&["d.v".into()], &jobs, &engines, &wrappers, "t.v");
            let mut exposes = s.lines().filter(|l| l.starts_with("expose -cut "));
            for j in &jobs {
                let inputs: Vec<String> = j.spec.inputs().into_iter().map(|x| x.name).collect();
                let free: Vec<&String> = inputs
                    .iter()
                    .filter(|n| !j.input_ports.contains(n))
                    .collect();
                if free.is_empty() {
                    continue;
                }
                cut_somewhere += 1;
                let line = exposes
                    .next()
                    .unwrap_or_else(|| panic!("{}: no cut", j.name()));
                let names: Vec<&str> = line["expose -cut ".len()..].split(' ').collect();
                assert_eq!(names.len(), free.len(), "{}: {line}", j.name());
                for n in free {
                    let want = format!("{}/{n}", j.module);
                    assert!(names.contains(&want.as_str()), "{}: {line}", j.name());
                }
            }
            assert!(exposes.next().is_none(), "{}", r.name);
        }
        assert!(cut_somewhere > 0);
    }
}
