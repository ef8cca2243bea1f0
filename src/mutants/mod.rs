//! `rmapgen mutants`: mutation testing of the checks that issue verdicts on a design
//! (docs/VERIFICATION.md, "Every verdict can fail"). A check that passes a design whose
//! outputs differ from the model's is unsound; planted faults chosen by the check's own
//! authors did not find the one that mattered, so the faults here are drawn by an existing
//! tool:
//!
//! - **Verilog mutants**: Yosys's `mutate` pass (the engine of YosysHQ's mcy) draws `N`
//!   mutations of the design's netlist after `proc` (`mutate -list N -seed S`). Each is
//!   applied by Yosys to the design, which is written back as Verilog: the top flattened,
//!   the front modules (zero detect, sort & shift) kept as modules of their own, since the
//!   proof reads them by file ([`materialise`]). The same flow with no mutation (the null
//!   mutant) must pass every check, or the flow itself changed the design.
//! - **Memory mutants**: one entry of a memory file changed (a bit within its width), for
//!   every file the top reads with `$readmemh` (both halves of a banked map: both buffers)
//!   and the scene's map files that the model reads.
//!
//! - **Wrapper mutants** (`--truth wrapper`): the same draw of the wrapper around the top
//!   alone (rmap_axis, rmap_lanes), the modules it instantiates read as black boxes; each
//!   mutant is that module as Yosys writes it back ([`materialise`]), judged by the wrapper's
//!   own testbench ([`Method::Wrapper`]) against [`Method::Wiring`], a Yosys miter of the
//!   mutant's wrapper and the design's with the instances cut out.
//!
//! Every mutant is judged by the ground truth, `rmapgen prove --direct` (every gradient
//! through the top, on both map buffers): a mutant it passes is equivalent (no output
//! differs) and set aside. A non-equivalent mutant that the factored `rmapgen prove` passes
//! is a soundness bug: the command exits 1. Each check runs as a child process of this
//! binary (the same build users run), bounded in time, in a process group of its own that
//! an interrupt takes down.

use crate::design_dir::DesignDir;
use crate::prove::front::FRONT;
use crate::rng::SplitMix64;
use crate::stages::unit::file_params;
use crate::stages::TOP;
use anyhow::{bail, ensure, Context, Result};
use serde::{Deserialize, Serialize};

pub mod campaign;
pub mod journal;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The most Verilog mutants one run draws.
pub const MAX_MUTANTS: usize = 10_000;
/// The most memory mutants per memory file.
pub const MAX_PER_MEMORY: usize = 1_000;

/// What a mutant changes.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Change {
    /// The design as Yosys writes it back, unchanged: the control.
    Null,
    /// One `mutate` command of Yosys (`mutate -mode M -module X -cell C ...`).
    Verilog { command: String },
    /// Entry `entry` (0-based, data lines) of `file` XORed with `xor`.
    Memory {
        file: String,
        entry: usize,
        xor: u64,
    },
}

/// One mutant: its number in the run and its change.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Mutant {
    pub id: usize,
    pub change: Change,
}

impl Mutant {
    /// One line for reports: `m7 mutate -mode inv -module sort_shift ...`.
    pub fn describe(&self) -> String {
        match &self.change {
            Change::Null => format!("m{} the null mutant (the flow, no mutation)", self.id),
            Change::Verilog { command } => {
                // The -src attributes are long and repeat the cell; keep the mutation itself.
                let short: Vec<&str> = command
                    .split(" -src ")
                    .next()
                    .unwrap_or(command)
                    .split_whitespace()
                    .collect();
                format!("m{} {}", self.id, short.join(" "))
            }
            Change::Memory { file, entry, xor } => {
                format!("m{} {file} entry {entry} ^ {xor:#x}", self.id)
            }
        }
    }

    /// The module a Verilog mutant changes (a derived module's base name).
    fn module(&self) -> Option<String> {
        let Change::Verilog { command } = &self.change else {
            return None;
        };
        let mut words = command.split_whitespace();
        while let Some(w) = words.next() {
            if w == "-module" {
                let m = words.next()?;
                // `$paramod$<hash>\name` is a parameterised instance of `name`.
                return Some(m.rsplit('\\').next().unwrap_or(m).to_string());
            }
        }
        None
    }
}

/// The wrapper around the top that a `--truth wrapper` run mutates: the design's top (its
/// module, file and the modules it instantiates), when it is not the top itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Wrapper {
    pub module: String,
    pub file: String,
    /// The modules it instantiates, black boxes to the draw and to the miter.
    pub children: Vec<String>,
    /// The design it was drawn from (absolute): the miter compares each mutant with it.
    pub reference: PathBuf,
}

impl Wrapper {
    /// The wrapper of design `d`, or None when its top is the top ([`TOP`]) itself.
    pub fn of(d: &DesignDir) -> Option<Wrapper> {
        let cfg = &d.config;
        let outer = crate::stages::top(cfg);
        (outer.name() != TOP.name()).then(|| Wrapper {
            module: outer.module(cfg),
            file: outer.file(cfg),
            children: outer.children(cfg).iter().map(|c| c.module(cfg)).collect(),
            reference: d.path().to_path_buf(),
        })
    }

    /// The Yosys lines that read the wrapper of the design in `dir` (its other files as black
    /// boxes) and elaborate it after `proc`.
    fn read_script(&self, dir: &Path, files: &[String]) -> String {
        let libs: Vec<String> = files
            .iter()
            .filter(|f| **f != self.file)
            .map(|f| dir.join(f).display().to_string())
            .collect();
        format!(
            "read_verilog -lib {}\nread_verilog {}\nhierarchy -top {}\nproc\n",
            libs.join(" "),
            dir.join(&self.file).display(),
            self.module
        )
    }

    /// The Yosys script that proves the wrapper of the design in `mutant` equal to the
    /// reference's, as a function of the wrapper's inputs and its instances' outputs: each
    /// read, its instances cut out (`expose -evert`: their inputs become outputs of the
    /// wrapper, their outputs inputs), and the two compared by a miter under SAT. It fails
    /// with [`Wrapper::DIFFER`] when an output differs for some input.
    fn miter_script(&self, mutant: &Path, files: &[String]) -> String {
        let cut: Vec<String> = self
            .children
            .iter()
            .map(|c| format!("{}/t:{c}", self.module))
            .collect();
        let side = |dir: &Path, name: &str| {
            format!(
                "{}expose -evert {}\nrename {} {name}\ndesign -stash {name}\n",
                self.read_script(dir, files),
                cut.join(" "),
                self.module
            )
        };
        format!(
            "{}{}design -copy-from gold -as gold gold\ndesign -copy-from gate -as gate gate\nmiter -equiv -flatten -make_assert gold gate miter\nhierarchy -top miter\nsat -verify -prove-asserts miter\n",
            side(&self.reference, "gold"),
            side(mutant, "gate")
        )
    }

    /// What Yosys says when the miter finds a difference.
    const DIFFER: &'static str = "proof did fail";
}

/// The Yosys script lines that read design `d` (run in its directory: `$readmemh` paths
/// resolve there) and elaborate its top after `proc`: the wrapper alone when `wrapper` is
/// given (a `--truth wrapper` run), else the top ([`TOP`]) and everything under it.
fn read_script(d: &DesignDir, wrapper: Option<&Wrapper>) -> String {
    match wrapper {
        Some(w) => w.read_script(d.path(), d.file_names()),
        None => format!(
            "read_verilog {}\nhierarchy -top {}\nproc\n",
            d.file_names().join(" "),
            TOP.module(&d.config)
        ),
    }
}

/// Runs Yosys on `script` in `dir`, its log in `log`.
fn yosys(dir: &Path, script: &str, log: &Path) -> Result<()> {
    let file = log.with_extension("ys");
    std::fs::write(&file, script).with_context(|| format!("cannot write {}", file.display()))?;
    let mut c = Command::new(crate::toolchain::yosys::yosys());
    c.args(["-q", "-l"])
        .arg(log)
        .arg("-s")
        .arg(&file)
        .current_dir(dir);
    let ran = crate::toolchain::capture(&mut c)?;
    if !ran.success() {
        bail!(
            "Yosys failed ({}; {}): {}",
            ran.exit(),
            log.display(),
            crate::toolchain::tail(&ran.output, 3).join(" | ")
        );
    }
    Ok(())
}

/// Refuses a `--select` that is not one Yosys selection (it is written into the draw's
/// script).
pub fn check_select(s: &str) -> Result<()> {
    ensure!(
        !s.trim().is_empty() && !s.contains(['\n', ';', '#']),
        "--select {s:?}: one Yosys selection (modules, cells or wires), no commands"
    );
    Ok(())
}

/// Draws `count` Verilog mutants of design `d` with Yosys's `mutate -list` (seed `seed`),
/// working in `work`.
pub fn draw_verilog(
    d: &DesignDir,
    count: usize,
    seed: u64,
    select: Option<&str>,
    wrapper: Option<&Wrapper>,
    work: &Path,
) -> Result<Vec<Change>> {
    ensure!(
        count <= MAX_MUTANTS,
        "--count {count}: at most {MAX_MUTANTS} mutants a run"
    );
    if let Some(s) = select {
        check_select(s)?;
    }
    if count == 0 {
        return Ok(Vec::new());
    }
    crate::disk::create_dir_all(work)?;
    let list = work.join("mutations.ys");
    // A wrapper run draws from the wrapper's own cells only.
    let select = match wrapper {
        Some(w) => Some(w.module.as_str()),
        None => select,
    };
    let script = format!(
        "{}mutate -list {count} -seed {seed} -o {} {}\n",
        read_script(d, wrapper),
        list.display(),
        select.unwrap_or("")
    );
    yosys(d.path(), &script, &work.join("list.log"))?;
    let text = std::fs::read_to_string(&list)
        .with_context(|| format!("cannot read {}", list.display()))?;
    Ok(text
        .lines()
        .filter(|l| l.starts_with("mutate "))
        .map(|l| Change::Verilog {
            command: l.to_string(),
        })
        .collect())
}

/// The memory files of design `d` that a mutant may change, with their entry widths: every
/// `$readmemh` file of the top, and the scene's map files (buffer 0) that the model reads.
pub fn memory_files(d: &DesignDir) -> Vec<(String, u32)> {
    let cfg = &d.config;
    let mut v: Vec<(String, u32)> = file_params(&TOP.memories(cfg))
        .into_iter()
        .map(|p| (p.default, p.width))
        .collect();
    for name in crate::model::map_set::buffer_names(cfg) {
        let f = crate::model::map_set::map_file(cfg, 0, name);
        let bits = if name == crate::model::map_set::TABLE {
            cfg.pos_bits()
        } else {
            cfg.map_bits
        };
        if !v.iter().any(|(n, _)| *n == f) {
            v.push((f, bits));
        }
    }
    v
}

/// The data lines of a `$readmemh` file (not `//` comments or blank lines).
fn data_lines(text: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with("//"))
        .map(|(i, _)| i)
        .collect()
}

/// Draws `per_file` memory mutants of every file of [`memory_files`]: an entry and a bit
/// within its width, from `seed`.
pub fn draw_memories(d: &DesignDir, per_file: usize, seed: u64) -> Result<Vec<Change>> {
    ensure!(
        per_file <= MAX_PER_MEMORY,
        "--memories {per_file}: at most {MAX_PER_MEMORY} mutants a file"
    );
    let mut out = Vec::new();
    for (k, (file, width)) in memory_files(d).into_iter().enumerate() {
        let p = d.path().join(&file);
        let text =
            std::fs::read_to_string(&p).with_context(|| format!("cannot read {}", p.display()))?;
        let n = data_lines(&text).len();
        ensure!(n > 0, "{} has no entries", p.display());
        let mut r = SplitMix64::new(seed ^ (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        for _ in 0..per_file {
            let entry = (r.next_u64() % n as u64) as usize;
            let bit = r.next_u64() % width as u64;
            out.push(Change::Memory {
                file: file.clone(),
                entry,
                xor: 1 << bit,
            });
        }
    }
    Ok(out)
}

/// Copies the files of directory `from` into `to` (subdirectories too), both existing.
fn copy_tree(from: &Path, to: &Path) -> Result<()> {
    crate::disk::create_dir_all(to)?;
    for e in std::fs::read_dir(from)? {
        let e = e?;
        let (src, dst) = (e.path(), to.join(e.file_name()));
        let ty = e.file_type()?;
        if ty.is_dir() {
            copy_tree(&src, &dst)?;
        } else if ty.is_file() {
            std::fs::copy(&src, &dst).with_context(|| format!("cannot copy {}", src.display()))?;
        }
    }
    Ok(())
}

/// The modules of a Verilog file Yosys wrote, by name, each from `module` to `endmodule`.
fn split_modules(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut cur: Option<(String, String)> = None;
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("module ") {
            let name = rest
                .split(|c: char| c == '(' || c.is_whitespace() || c == ';')
                .next()
                .unwrap_or("")
                .to_string();
            cur = Some((name, String::new()));
        }
        if let Some((_, body)) = cur.as_mut() {
            body.push_str(line);
            body.push('\n');
            if line.trim_start().starts_with("endmodule") {
                out.push(cur.take().expect("some"));
            }
        }
    }
    out
}

/// Writes mutant `m` of design `d` into the empty directory `to`: a copy of the design with
/// the change applied. A Verilog mutant (and the null mutant) is the design read by Yosys,
/// `proc`, the mutation, every undefined multiplexer input replaced by the other input
/// (`opt_expr -mux_undef`, a refinement of `x`: `proc` writes `x` for defaults no path of
/// the design selects, a mutant may select them, and its meaning must not depend on how a
/// simulator or the front's gates read `x`), then flattened but for the front modules and
/// written back, with nothing removed (no `opt_clean`: a mutant that leaves a signal unused
/// keeps it, so that a harness that probes it by name, the formal one, still finds it): the top's
/// file holds the flat top (its memories' contents written in, its file parameters declared
/// for the harnesses that set them), the front modules' files the front as Yosys wrote it
/// when the mutation is in one of them.
///
/// With `wrapper` (a `--truth wrapper` run) only the wrapper's file changes: the wrapper as
/// Yosys writes it back (the modules it instantiates read as black boxes), its init-file
/// parameters declared again and passed down by name, as the generated wrapper does.
pub fn materialise(d: &DesignDir, m: &Mutant, wrapper: Option<&Wrapper>, to: &Path) -> Result<()> {
    copy_tree(d.path(), to)?;
    if let (Some(w), Change::Null | Change::Verilog { .. }) = (wrapper, &m.change) {
        return materialise_wrapper(d, m, w, to);
    }
    match &m.change {
        Change::Memory { file, entry, xor } => {
            let p = to.join(file);
            let text = std::fs::read_to_string(&p)?;
            let lines = data_lines(&text);
            let at = *lines
                .get(*entry)
                .with_context(|| format!("{file} has no entry {entry}"))?;
            let out: Vec<String> = text
                .lines()
                .enumerate()
                .map(|(i, l)| {
                    if i != at {
                        return l.to_string();
                    }
                    let t = l.trim();
                    let v = u64::from_str_radix(t, 16).unwrap_or(0) ^ xor;
                    format!("{v:0w$x}", w = t.len())
                })
                .collect();
            crate::disk::write(&p, out.join("\n") + "\n")?;
        }
        Change::Null | Change::Verilog { .. } => {
            let cfg = &to_config(d);
            let front: Vec<String> = FRONT.iter().map(|u| u.module(cfg)).collect();
            let mutation = match &m.change {
                Change::Verilog { command } => format!("{command}\n"),
                _ => String::new(),
            };
            let script = format!(
                "{}{mutation}opt_expr -mux_undef\nsetattr -mod -set keep_hierarchy 1 {}\nflatten\nwrite_verilog -noattr mutant.v\n",
                read_script(d, None),
                front.join(" ")
            );
            yosys(to, &script, &to.join("mutant.log"))?;
            let text = std::fs::read_to_string(to.join("mutant.v"))?;
            let modules = split_modules(&text);
            let top = TOP.module(cfg);
            let (_, top_text) = modules
                .iter()
                .find(|(n, _)| *n == top)
                .with_context(|| format!("Yosys wrote no module {top}"))?;
            // The flat top keeps the file parameters the harnesses set (now unused: Yosys
            // wrote the memories' contents into it).
            let params: String = file_params(&TOP.memories(cfg))
                .iter()
                .map(|p| format!("  parameter {} = \"{}\";\n", p.name, p.default))
                .collect();
            let header_end = top_text
                .find(");\n")
                .context("the flat top has no port list")?
                + 3;
            let top_file = format!(
                "{YOSYS_WAIVERS}{}{params}{}",
                &top_text[..header_end],
                &top_text[header_end..]
            );
            crate::disk::write(&to.join(TOP.file(cfg)), top_file)?;
            let changed = m.module();
            for u in FRONT {
                if changed.as_deref() == Some(u.module(cfg).as_str()) {
                    let (_, t) = modules
                        .iter()
                        .find(|(n, _)| *n == u.module(cfg))
                        .with_context(|| format!("Yosys wrote no module {}", u.module(cfg)))?;
                    crate::disk::write(&to.join(u.file(cfg)), format!("{YOSYS_WAIVERS}{t}"))?;
                }
            }
            std::fs::remove_file(to.join("mutant.v")).ok();
        }
    }
    Ok(())
}

/// The wrapper of mutant `m` of design `d` into `to` (a copy of the design): Yosys reads the
/// wrapper with the modules it instantiates as black boxes, applies the mutation and writes
/// the wrapper alone. Yosys writes the init-file parameters it passes down as their default
/// values; they are declared again and passed down by name, so that a testbench run from
/// elsewhere still sets every file (a parameter that is not found is an error, never a file
/// silently read from the working directory).
fn materialise_wrapper(d: &DesignDir, m: &Mutant, w: &Wrapper, to: &Path) -> Result<()> {
    let mutation = match &m.change {
        Change::Verilog { command } => format!("{command}\n"),
        _ => String::new(),
    };
    let script = format!(
        "{}{mutation}write_verilog -noattr mutant.v\n",
        w.read_script(d.path(), d.file_names())
    );
    yosys(to, &script, &to.join("mutant.log"))?;
    let written = to.join("mutant.v");
    let text = std::fs::read_to_string(&written)
        .with_context(|| format!("cannot read {}", written.display()))?;
    std::fs::remove_file(&written).ok();
    let modules = split_modules(&text);
    let (_, mut body) = modules
        .into_iter()
        .find(|(n, _)| *n == w.module)
        .with_context(|| format!("Yosys wrote no module {}", w.module))?;
    let cfg = &d.config;
    let params = file_params(&crate::stages::top(cfg).memories(cfg));
    for p in &params {
        let literal = format!(".{}(\"{}\")", p.name, p.default);
        ensure!(
            body.contains(&literal),
            "Yosys wrote {} without {literal}: the parameter cannot be passed down",
            w.module
        );
        body = body.replace(&literal, &format!(".{0}({0})", p.name));
    }
    let decls: String = params
        .iter()
        .map(|p| format!("  parameter {} = \"{}\";\n", p.name, p.default))
        .collect();
    let header_end = body.find(");\n").context("the wrapper has no port list")? + 3;
    crate::disk::write(
        &to.join(&w.file),
        format!(
            "{YOSYS_WAIVERS}{}{decls}{}",
            &body[..header_end],
            &body[header_end..]
        ),
    )
}

/// Verilator's warnings on Verilog that Yosys writes (its case statements overlap, its
/// logical operators take vectors), which would stop the proof's build: the mutants are
/// judged on what they compute, not on their style.
const YOSYS_WAIVERS: &str = "/* verilator lint_off WIDTH */\n/* verilator lint_off CASEOVERLAP */\n/* verilator lint_off CASEINCOMPLETE */\n/* verilator lint_off UNOPTFLAT */\n/* verilator lint_off LATCH */\n/* verilator lint_off MULTIDRIVEN */\n/* verilator lint_off COMBDLY */\n";

fn to_config(d: &DesignDir) -> crate::config::Config {
    d.config.clone()
}

/// A check run on one mutant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// `rmapgen prove --direct`: the ground truth.
    Direct,
    /// `rmapgen prove`: the factored proof.
    Prove,
    /// `rmapgen sim --verilator --stream`: every testbench and a random stream.
    Sim,
    /// `rmapgen sim --gate`: the top's testbench on the synthesised netlist.
    Gate,
    /// `rmapgen sim --stream N`: N random gradients through the top against the model, and
    /// nothing else: the ground truth where `--direct` cannot drive every gradient (a
    /// sample, so "equivalent" means no difference found).
    Stream,
    /// `formal/run_formal.py`: the SymbiYosys proof of a handshake top's flow control and map
    /// buffers (`make formal`), on the mutant.
    Formal,
    /// `formal/run_formal.py --miter`: the ground truth of [`Method::Formal`], a bounded
    /// search from reset for a difference between the mutant and the design in what the
    /// harness speaks of (ready_o, valid_o, the tag, the map buffers read and written), not
    /// in the datapath's results.
    Flow,
    /// The wrapper's testbench (`rmapgen sim --icarus --only <wrapper>`), on a mutant of the
    /// wrapper around the top.
    Wrapper,
    /// The ground truth of [`Method::Wrapper`]: a Yosys miter of the mutant's wrapper and the
    /// design's, the modules it instantiates cut out ([`Wrapper::miter_script`]), proved by
    /// SAT. A mutant it passes computes the same function of the wrapper's inputs and of its
    /// instances' outputs: the same design.
    Wiring,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Direct => "direct",
            Method::Prove => "prove",
            Method::Sim => "sim",
            Method::Gate => "gate",
            Method::Stream => "stream",
            Method::Formal => "formal",
            Method::Flow => "flow",
            Method::Wrapper => "wrapper",
            Method::Wiring => "wiring",
        }
    }

    /// Whether it can be a run's ground truth (every mutant is judged by it first).
    pub fn is_truth(self) -> bool {
        matches!(
            self,
            Method::Direct | Method::Stream | Method::Flow | Method::Wiring
        )
    }

    /// The proof that ground truth `self` judges: a non-equivalent mutant it passes is a
    /// soundness bug. `prove` for the datapath's truths, the formal harness for the flow's,
    /// the wrapper's testbench for the wiring's (what checks the wrapper: `prove` does not).
    pub fn proof(self) -> Method {
        match self {
            Method::Flow | Method::Formal => Method::Formal,
            Method::Wiring | Method::Wrapper => Method::Wrapper,
            _ => Method::Prove,
        }
    }

    /// The child runs of this check, in order: each runs only if every one before it passed,
    /// and the check passes only if all of them do. One run, but for the factored proof: its
    /// parts in [`crate::prove::STAGED`] order, so that a mutant the states or the structure
    /// kill (about a minute and a half on the default design) is not also driven through the
    /// front's 2^36 gradients (about 16 minutes on 2 cores) before its verdict. The same parts
    /// run on a mutant that passes, so the verdict is the whole proof's.
    fn runs(self, plan: &Plan) -> Vec<Vec<String>> {
        match self {
            Method::Prove => crate::prove::STAGED
                .iter()
                .map(|parts| {
                    let mut v = self.args(plan);
                    v.extend(["--part".to_string(), parts.join(",")]);
                    v
                })
                .collect(),
            _ => vec![self.args(plan)],
        }
    }

    fn args(self, plan: &Plan) -> Vec<String> {
        let v: Vec<&str> = match self {
            Method::Direct => vec!["prove", "--direct"],
            Method::Prove => vec!["prove"],
            Method::Sim => vec!["sim", "--verilator"],
            Method::Gate => vec!["sim", "--gate"],
            Method::Stream => vec!["sim"],
            // run_formal.py's, after its script (see `check`).
            Method::Formal => vec!["--reference"],
            Method::Flow => vec!["--miter"],
            Method::Wrapper => vec!["sim", "--icarus", "--only"],
            // Yosys's script, not arguments (see `check`).
            Method::Wiring => vec![],
        };
        let mut v: Vec<String> = v.into_iter().map(String::from).collect();
        match self {
            Method::Sim => v.extend(["--stream".to_string(), plan.sim_stream.to_string()]),
            Method::Stream => v.extend(["--stream".to_string(), plan.truth_stream.to_string()]),
            Method::Formal | Method::Flow => {
                let f = plan.formal.as_ref().expect("a formal plan names its tools");
                v.push(f.reference.display().to_string());
            }
            Method::Wrapper => {
                let w = plan
                    .wrapper
                    .as_ref()
                    .expect("a wrapper plan names the wrapper");
                v.push(w.module.clone());
            }
            _ => {}
        }
        v
    }
}

/// The running binary itself: Linux's `/proc/self/exe`, which stays this build even when a
/// rebuild replaces `target/release/rmapgen`; elsewhere the path it was started from.
pub fn own_binary() -> Result<PathBuf> {
    let own = Path::new("/proc/self/exe");
    if own.exists() {
        Ok(own.to_path_buf())
    } else {
        std::env::current_exe().context("cannot find the rmapgen binary")
    }
}

/// What a check said of a mutant.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// It passed the mutant (exit 0).
    Passed,
    /// It failed the mutant (exit 1).
    Failed,
    /// It refused the mutant as bad input (exit 2: for example Verilator could not build it).
    Refused,
    /// It ran past the time limit (killed).
    Timeout,
}

impl Verdict {
    /// Whether the check did not certify the mutant.
    pub fn kills(&self) -> bool {
        *self != Verdict::Passed
    }
}

/// Runs `method` on the mutant design `dir`, as child processes of this binary (its
/// [`Method::runs`], in order, until one does not pass), each in a process group of its own
/// (killed with everything it started on an interrupt or when `plan.timeout`, which bounds
/// them together, runs out), their output in `log`.
pub fn check(method: Method, dir: &Path, build: &Path, log: &Path, plan: &Plan) -> Result<Verdict> {
    let t0 = Instant::now();
    if method == Method::Wiring {
        return wiring(dir, build, log, plan);
    }
    let out =
        std::fs::File::create(log).with_context(|| format!("cannot write {}", log.display()))?;
    for args in method.runs(plan) {
        // The running binary itself (Linux's /proc/self/exe), not its path: a campaign of an
        // hour judges every mutant with the rmapgen it started with, even if a build replaces
        // target/release/rmapgen meanwhile (which once stopped one with "cannot start").
        let mut c = match (method, &plan.formal) {
            (Method::Formal | Method::Flow, Some(f)) => {
                let mut c = Command::new(&f.python);
                c.arg(&f.script);
                c
            }
            (Method::Formal | Method::Flow, None) => {
                bail!("{} needs the formal tools", method.name())
            }
            _ => Command::new(own_binary()?),
        };
        c.args(args)
            .arg("--build")
            .arg(build)
            .arg(dir)
            .stdin(Stdio::null())
            .stdout(out.try_clone()?)
            .stderr(out.try_clone()?);
        let left = plan.timeout.saturating_sub(t0.elapsed());
        let status = crate::toolchain::child::spawn(&mut c)
            .with_context(|| format!("cannot start rmapgen {}", method.name()))?
            .wait_timeout(left)?;
        let verdict = match status.and_then(|s| s.code()) {
            None if status.is_none() => Verdict::Timeout,
            Some(0) => Verdict::Passed,
            Some(1) => Verdict::Failed,
            _ => Verdict::Refused,
        };
        if verdict != Verdict::Passed {
            return Ok(verdict);
        }
    }
    Ok(Verdict::Passed)
}

/// [`Method::Wiring`] on the mutant design `dir`: Yosys runs the wrapper's miter
/// ([`Wrapper::miter_script`], written into `build`), bounded by `plan.timeout`, its output in
/// `log`. It passes when the miter is proved, fails when SAT finds an input on which they
/// differ ([`Wrapper::DIFFER`]); anything else (a script Yosys cannot run) refuses.
fn wiring(dir: &Path, build: &Path, log: &Path, plan: &Plan) -> Result<Verdict> {
    let w = plan
        .wrapper
        .as_ref()
        .context("the wiring truth needs the wrapper")?;
    let d = DesignDir::open(dir)?;
    crate::disk::create_dir_all(build)?;
    let script = build.join("miter.ys");
    crate::disk::write(&script, w.miter_script(dir, d.file_names()))?;
    let out =
        std::fs::File::create(log).with_context(|| format!("cannot write {}", log.display()))?;
    let mut c = Command::new(crate::toolchain::yosys::yosys());
    c.arg("-q")
        .arg("-s")
        .arg(&script)
        .current_dir(build)
        .stdin(Stdio::null())
        .stdout(out.try_clone()?)
        .stderr(out);
    let status = crate::toolchain::child::spawn(&mut c)
        .context("cannot start yosys for the wiring miter")?
        .wait_timeout(plan.timeout)?;
    let said = std::fs::read_to_string(log).unwrap_or_default();
    Ok(match status.and_then(|s| s.code()) {
        None if status.is_none() => Verdict::Timeout,
        Some(0) => Verdict::Passed,
        _ if said.contains(Wrapper::DIFFER) => Verdict::Failed,
        _ => Verdict::Refused,
    })
}

/// One mutant's verdicts, method by method, in the order they ran.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Outcome {
    pub mutant: Mutant,
    pub verdicts: Vec<(Method, Verdict)>,
    pub seconds: f64,
}

impl Outcome {
    pub fn verdict(&self, m: Method) -> Option<&Verdict> {
        self.verdicts.iter().find(|(k, _)| *k == m).map(|(_, v)| v)
    }

    /// The ground truth's class (`--direct`, or the stream where it was the truth): `None`
    /// when no ground truth ran on it.
    pub fn equivalent(&self) -> Option<bool> {
        self.verdicts
            .iter()
            .find(|(m, _)| m.is_truth())
            .map(|(_, v)| *v == Verdict::Passed)
    }

    /// The ground truth that ran on it.
    pub fn truth(&self) -> Option<Method> {
        self.verdicts.iter().map(|(m, _)| *m).find(|m| m.is_truth())
    }

    /// A non-equivalent mutant that the proof its ground truth judges passed (the factored
    /// proof; the formal harness under the flow truth): a soundness bug.
    pub fn unsound(&self) -> bool {
        let Some(truth) = self.truth() else {
            return false;
        };
        self.equivalent() == Some(false) && self.verdict(truth.proof()) == Some(&Verdict::Passed)
    }
}

/// How a run judges its mutants.
pub struct Plan {
    /// The checks after the ground truth, in order.
    pub methods: Vec<Method>,
    /// Run the ground truth only on mutants the factored proof passes (the bounded sample
    /// of `make test`: a killed mutant needs no class to show the proof sound).
    pub quick: bool,
    pub timeout: Duration,
    pub sim_stream: u64,
    /// The ground truth: [`Method::Direct`] (every gradient), or [`Method::Stream`] (a
    /// sample of `truth_stream` random gradients) for designs `--direct` cannot take.
    pub truth: Method,
    pub truth_stream: u64,
    /// The formal tools, for [`Method::Formal`] and [`Method::Flow`].
    pub formal: Option<FormalTools>,
    /// The wrapper mutated, for [`Method::Wrapper`] and [`Method::Wiring`]: the draw and every
    /// mutant are of it alone.
    pub wrapper: Option<Wrapper>,
}

/// How the formal harness runs on a mutant: `python script --reference REF|--miter REF
/// --build B MUTANT` (`formal/run_formal.py` with the project venv's Python).
pub struct FormalTools {
    pub python: PathBuf,
    pub script: PathBuf,
    /// The design the mutants are drawn from (absolute): the harness reads its parameters
    /// there, and the flow miter compares each mutant with it.
    pub reference: PathBuf,
}

/// Judges mutant `m` of design `d` in `work/m<id>` (design, builds, logs).
pub fn judge(d: &DesignDir, m: &Mutant, plan: &Plan, work: &Path) -> Result<Outcome> {
    let t0 = Instant::now();
    // `work` is the run's own fresh staging directory (cmd/mutants.rs) and each id is judged
    // once, so this directory is new: refused, never replaced, if anything is there.
    let dir = work.join(format!("m{}", m.id));
    ensure!(
        !dir.exists(),
        "{} exists; rmapgen mutants writes only new directories",
        dir.display()
    );
    let design = dir.join("design");
    crate::disk::create_dir_all(&design)?;
    materialise(d, m, plan.wrapper.as_ref(), &design)?;
    let mut verdicts = Vec::new();
    let mut run = |method: Method| -> Result<Verdict> {
        let v = check(
            method,
            &design,
            &dir.join(format!("build-{}", method.name())),
            &dir.join(format!("{}.log", method.name())),
            plan,
        )?;
        verdicts.push((method, v.clone()));
        Ok(v)
    };
    if plan.quick {
        if run(plan.truth.proof())? == Verdict::Passed {
            run(plan.truth)?;
        }
    } else {
        run(plan.truth)?;
        for &method in &plan.methods {
            run(method)?;
        }
    }
    Ok(Outcome {
        mutant: m.clone(),
        verdicts,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Per method: mutants judged, equivalent, non-equivalent, killed among the non-equivalent,
/// survived (non-equivalent and passed), and kills of mutants the ground truth did not class.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Tally {
    pub method: String,
    pub judged: usize,
    pub equivalent: usize,
    pub non_equivalent: usize,
    pub killed: usize,
    pub survived: usize,
    /// Killed without a ground-truth class (the quick plan's kills).
    pub killed_unclassed: usize,
    /// Failed (or refused) though the ground truth passed it: under `--direct`, a check
    /// stricter than the top's outputs or a false alarm; under a sampled truth (the stream),
    /// most often a difference the sample missed, which the check's failure names (a
    /// gradient to confirm by `prove --direct --shard`, docs/VERIFICATION.md).
    pub failed_equivalent: usize,
}

/// The tally of `method` over `outcomes` (the null mutant left out).
pub fn tally(method: Method, outcomes: &[Outcome]) -> Tally {
    let mut t = Tally {
        method: method.name().to_string(),
        ..Tally::default()
    };
    for o in outcomes.iter().filter(|o| o.mutant.change != Change::Null) {
        let Some(v) = o.verdict(method) else {
            continue;
        };
        t.judged += 1;
        match o.equivalent() {
            Some(true) => {
                t.equivalent += 1;
                if v.kills() {
                    t.failed_equivalent += 1;
                }
            }
            Some(false) => {
                t.non_equivalent += 1;
                if v.kills() {
                    t.killed += 1;
                } else {
                    t.survived += 1;
                }
            }
            None => {
                if v.kills() {
                    t.killed_unclassed += 1;
                }
            }
        }
    }
    t
}

/// The journal of the runs on design `d` in `build` (beside their work directory, which a
/// run replaces whole): `build/mutants/<design name>.journal`.
pub fn journal_path(build: &Path, d: &DesignDir) -> PathBuf {
    build.join(format!("{}.journal", d.name()))
}

/// Where a run's mutants, builds and logs go: `build/mutants/<design name>`.
pub fn work_dir(build: &Path, d: &DesignDir) -> PathBuf {
    build.join(d.name())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(id: usize, verdicts: &[(Method, Verdict)]) -> Outcome {
        Outcome {
            mutant: Mutant {
                id,
                change: if id == 0 {
                    Change::Null
                } else {
                    Change::Memory {
                        file: "recip_rom.hex".into(),
                        entry: id,
                        xor: 1,
                    }
                },
            },
            verdicts: verdicts.to_vec(),
            seconds: 0.0,
        }
    }

    #[test]
    fn a_non_equivalent_mutant_that_prove_passes_is_unsound_and_nothing_else_is() {
        use Method::*;
        use Verdict::*;
        let killed = outcome(1, &[(Direct, Failed), (Prove, Failed)]);
        let refused = outcome(2, &[(Direct, Failed), (Prove, Refused)]);
        let equivalent = outcome(3, &[(Direct, Passed), (Prove, Passed)]);
        let unsound = outcome(4, &[(Direct, Failed), (Prove, Passed)]);
        let quick_kill = outcome(5, &[(Prove, Failed)]);
        let timeout = outcome(6, &[(Direct, Timeout), (Prove, Passed)]);
        assert!(!killed.unsound() && !refused.unsound() && !equivalent.unsound());
        assert!(!quick_kill.unsound());
        assert!(unsound.unsound());
        // A ground truth that timed out is no "equivalent": the mutant counts as different.
        assert!(timeout.unsound());
        let all = [
            outcome(0, &[(Direct, Passed), (Prove, Passed)]),
            killed,
            refused,
            equivalent,
            unsound,
            quick_kill,
            timeout,
        ];
        let t = tally(Prove, &all);
        assert_eq!(
            (
                t.judged,
                t.equivalent,
                t.non_equivalent,
                t.killed,
                t.survived,
                t.killed_unclassed
            ),
            (6, 1, 4, 2, 2, 1),
            "{t:?}"
        );
        // The sampled ground truth classes the same way: a difference the stream found that
        // prove passed is a soundness bug; what it passed is equivalent as far as it shows.
        let sampled = [
            outcome(0, &[(Stream, Passed), (Prove, Passed)]),
            outcome(1, &[(Stream, Failed), (Prove, Passed)]),
            outcome(2, &[(Stream, Passed), (Prove, Failed)]),
            outcome(3, &[(Stream, Failed), (Prove, Failed)]),
        ];
        assert!(sampled[1].unsound() && !sampled[2].unsound() && !sampled[3].unsound());
        let t = tally(Prove, &sampled);
        assert_eq!(
            (
                t.judged,
                t.equivalent,
                t.non_equivalent,
                t.killed,
                t.survived
            ),
            (3, 1, 2, 1, 1)
        );
        // m2: the stream passed it, prove failed it (a difference the sample missed, or a
        // false alarm): counted apart, never as a kill; a truth never fails what it passed.
        assert_eq!(t.failed_equivalent, 1);
        assert_eq!(tally(Stream, &sampled).judged, 3);
        assert_eq!(tally(Stream, &sampled).failed_equivalent, 0);
        assert!(Stream.is_truth() && Direct.is_truth() && !Prove.is_truth());
        let d = tally(Direct, &all);
        assert_eq!(
            (d.judged, d.equivalent, d.non_equivalent, d.killed),
            (5, 1, 4, 4)
        );
    }

    #[test]
    fn under_the_flow_truth_the_formal_harness_is_the_proof_judged() {
        use Method::*;
        use Verdict::*;
        assert_eq!(
            [Direct, Stream, Flow].map(Method::proof),
            [Prove, Prove, Formal]
        );
        assert!(Flow.is_truth() && !Formal.is_truth());
        // A flow difference the harness passed is a soundness bug of the harness; prove
        // passing it says nothing (the flow truth does not judge prove).
        let unsound = outcome(1, &[(Flow, Failed), (Formal, Passed)]);
        let killed = outcome(2, &[(Flow, Failed), (Formal, Refused)]);
        let equivalent = outcome(3, &[(Flow, Passed), (Formal, Passed)]);
        let not_judged = outcome(4, &[(Flow, Failed), (Prove, Passed)]);
        assert!(unsound.unsound());
        assert!(!killed.unsound() && !equivalent.unsound() && !not_judged.unsound());
        assert_eq!(unsound.truth(), Some(Flow));
        assert!(!outcome(5, &[(Formal, Failed)]).unsound());
        let t = tally(Formal, &[unsound, killed, equivalent]);
        assert_eq!(
            (
                t.judged,
                t.equivalent,
                t.non_equivalent,
                t.killed,
                t.survived
            ),
            (3, 1, 2, 1, 1)
        );
        assert!(check_select("rmap_top pipe_delay").is_ok());
        for bad in ["", " ", "a; shell rm", "a\nshell", "a # b"] {
            assert!(check_select(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn under_the_wiring_truth_the_wrappers_testbench_is_the_check_judged() {
        use Method::*;
        use Verdict::*;
        assert_eq!([Wiring, Wrapper].map(Method::proof), [Wrapper, Wrapper]);
        assert!(Wiring.is_truth() && !Wrapper.is_truth());
        assert_eq!((Wiring.name(), Wrapper.name()), ("wiring", "wrapper"));
        // A wiring difference the testbench passed is what the run exists to find.
        let survived = outcome(1, &[(Wiring, Failed), (Wrapper, Passed)]);
        let killed = outcome(2, &[(Wiring, Failed), (Wrapper, Failed)]);
        let equivalent = outcome(3, &[(Wiring, Passed), (Wrapper, Passed)]);
        assert!(survived.unsound() && !killed.unsound() && !equivalent.unsound());
        assert_eq!(survived.truth(), Some(Wiring));
        let t = tally(Wrapper, &[survived, killed, equivalent]);
        assert_eq!(
            (
                t.judged,
                t.equivalent,
                t.non_equivalent,
                t.killed,
                t.survived
            ),
            (3, 1, 2, 1, 1)
        );
        let plan = Plan {
            methods: vec![Wrapper],
            quick: false,
            timeout: Duration::from_secs(60),
            sim_stream: 7,
            truth: Wiring,
            truth_stream: 9,
            formal: None,
            wrapper: Some(super::Wrapper {
                module: "p_rmap_axis".into(),
                file: "p_rmap_axis.v".into(),
                children: vec!["p_rmap_top".into()],
                reference: PathBuf::from("/ref"),
            }),
        };
        let runs: Vec<String> = Wrapper.runs(&plan).iter().map(|r| r.join(" ")).collect();
        assert_eq!(runs, ["sim --icarus --only p_rmap_axis"]);
    }

    #[test]
    fn the_wiring_miter_cuts_the_instances_out_of_both_wrappers() {
        let w = Wrapper {
            module: "rmap_lanes".into(),
            file: "rmap_lanes.v".into(),
            children: vec!["rmap_top".into(), "recip_rom".into()],
            reference: PathBuf::from("/ref"),
        };
        let files = ["rmap_lanes.v", "rmap_top.v", "recip_rom.v"].map(String::from);
        let script = w.miter_script(Path::new("/mut"), &files);
        let lines: Vec<&str> = script.lines().collect();
        for side in ["/ref", "/mut"] {
            // The wrapper read as itself, the rest as black boxes.
            let lib = format!("read_verilog -lib {side}/rmap_top.v {side}/recip_rom.v");
            assert!(lines.contains(&lib.as_str()), "{script}");
            let own = format!("read_verilog {side}/rmap_lanes.v");
            assert!(lines.contains(&own.as_str()), "{script}");
        }
        assert_eq!(
            lines
                .iter()
                .filter(|l| **l == "expose -evert rmap_lanes/t:rmap_top rmap_lanes/t:recip_rom")
                .count(),
            2,
            "{script}"
        );
        let at = |l: &str| lines.iter().position(|x| *x == l).unwrap_or(usize::MAX);
        assert!(at("rename rmap_lanes gold") < at("design -stash gold"));
        assert!(at("design -stash gold") < at("read_verilog /mut/rmap_lanes.v"));
        assert!(at("rename rmap_lanes gate") < at("design -stash gate"));
        assert_eq!(lines.last(), Some(&"sat -verify -prove-asserts miter"));
        assert!(lines.contains(&"miter -equiv -flatten -make_assert gold gate miter"));
    }

    #[test]
    fn the_proof_runs_its_cheap_parts_first_and_every_other_check_runs_once() {
        let plan = Plan {
            methods: vec![Method::Prove],
            quick: false,
            timeout: Duration::from_secs(60),
            sim_stream: 7,
            truth: Method::Stream,
            truth_stream: 9,
            formal: None,
            wrapper: None,
        };
        let line =
            |m: Method| -> Vec<String> { m.runs(&plan).iter().map(|r| r.join(" ")).collect() };
        assert_eq!(
            line(Method::Prove),
            ["prove --part structure,states,zero", "prove --part front"]
        );
        assert_eq!(line(Method::Direct), ["prove --direct"]);
        assert_eq!(line(Method::Sim), ["sim --verilator --stream 7"]);
        assert_eq!(line(Method::Stream), ["sim --stream 9"]);
        assert_eq!(line(Method::Gate), ["sim --gate"]);
    }

    #[test]
    fn a_mutation_names_its_module_and_yosys_output_splits_into_modules() {
        let m = Mutant {
            id: 3,
            change: Change::Verilog {
                command: r"mutate -mode inv -module $paramod$86c2\normalise -cell $x -port A -portbit 1 -src n.v:1.2-3.4".into(),
            },
        };
        assert_eq!(m.module().as_deref(), Some("normalise"));
        assert_eq!(
            m.describe(),
            r"m3 mutate -mode inv -module $paramod$86c2\normalise -cell $x -port A -portbit 1"
        );
        let text = "/* head */\nmodule a(x);\n  input x;\nendmodule\n\nmodule b (y);\nendmodule\n";
        let v = split_modules(text);
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].0, "a");
        assert_eq!(
            v[1],
            ("b".to_string(), "module b (y);\nendmodule\n".to_string())
        );
        assert_eq!(data_lines("// c\n0a\n\n ff\n"), vec![1, 3]);
    }
}
