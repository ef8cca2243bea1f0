//! `rmapgen prove-mult`: the formal proof that every adder tree of a generated design
//! equals the plain product its plan says it builds (`a * b + c`), on every input, with
//! Yosys's SAT solver or by evaluating the cut miter on every input, on the generated modules
//! ([`crate::prove::mult`]).
//!
//! Exit 0 when every tree is proved, 1 when any is not (each failure names the stage, the
//! tree and the first failing case), 2 for bad input.

use super::force::ForceArg;
use super::parse;
use super::sim::{generate_row, selected_rows};
use crate::design_dir::DesignDir;
use crate::grid::GridRow;
use crate::output::{absolute, Policy, StagedDir};
use crate::prove::mult::{self as mult_proof, Engine, EngineChoice, Job};
use crate::toolchain::{self, yosys};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct ProveMultArgs {
    /// The generated design directory (`rmapgen generate --out DIR`). With --matrix, where
    /// each row's design is generated, as DIR/<row> [default: build/matrix].
    #[arg(value_name = "DIR", required_unless_present = "matrix")]
    pub dir: Option<PathBuf>,
    /// Directory for the Yosys script, the miters and yosys.log (replaced whole, also when
    /// the proof fails, so its log can be read). With --matrix, LOGS/<row>.
    #[arg(long, value_name = "DIR", default_value = "build/prove-mult")]
    pub logs: PathBuf,
    /// Generate every configuration of the parameter grid (src/grid.rs) into DIR/<row> and
    /// prove every tree of each; exit 1 naming each row that fails.
    #[arg(long)]
    pub matrix: bool,
    /// With --matrix: only these rows (repeat the flag or separate with commas).
    #[arg(long, value_name = "NAME", requires = "matrix", value_delimiter = ',')]
    pub row: Vec<String>,
    /// With --matrix: Yosys processes side by side (default: JOBS, else the cores).
    #[arg(long, value_name = "N", requires = "matrix", value_parser = parse::whole::<usize>(1, 64))]
    pub jobs: Option<usize>,
    /// How each tree is proved: sat (Yosys sat -prove, one run per value of the split
    /// factor), exhaustive (the cut miter evaluated on every input), algebra (the sum and the
    /// specification shown equal as polynomials), or auto (exhaustive up to 2^34 inputs, else
    /// algebra).
    #[arg(long, value_enum, default_value = "auto")]
    pub engine: EngineChoice,
    /// Only these trees, by stage and tree name (normalise.pa; repeat the flag or separate
    /// with commas) [default: every tree].
    #[arg(long, value_name = "STAGE.TREE", value_delimiter = ',')]
    pub tree: Vec<String>,
    #[command(flatten)]
    pub force: ForceArg,
}

pub fn run(a: &ProveMultArgs) -> Result<ExitCode> {
    // Bad input first (the rows, the directory), then the tool, then the runs.
    let failed = if a.matrix {
        let rows = selected_rows(&a.row)?;
        let mut all = Vec::new();
        for r in &rows {
            let jobs = chosen(&r.config, &a.tree);
            engines(&jobs, a.engine)?;
            all.extend(jobs);
        }
        known_trees(&all, &a.tree)?;
        need_yosys()?;
        matrix(a, &rows)?
    } else {
        let dir = a
            .dir
            .as_deref()
            .expect("clap requires DIR without --matrix");
        let design = DesignDir::open(dir)?;
        let jobs = chosen(&design.config, &a.tree);
        known_trees(&jobs, &a.tree)?;
        engines(&jobs, a.engine)?;
        need_yosys()?;
        let steps = super::progress::Steps::new();
        steps.step(&format!(
            "proving {} multiplier{} of {}",
            jobs.len(),
            if jobs.len() == 1 { "" } else { "s" },
            design.path().display()
        ));
        let proof = prove(
            &design,
            &a.logs,
            &a.force.policy(&[Some(design.path())]),
            a.engine,
            &a.tree,
        )?;
        drop(steps);
        crate::out!("{}", proof.stdout)?;
        crate::err!("{}", proof.stderr);
        !proof.passed
    };
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// The trees of `cfg` that `--tree` names (all without it).
fn chosen(cfg: &crate::config::Config, trees: &[String]) -> Vec<Job> {
    mult_proof::jobs(cfg)
        .into_iter()
        .filter(|j| trees.is_empty() || trees.contains(&j.name()))
        .collect()
}

/// A `--tree` that names no tree of the designs is bad input.
fn known_trees(jobs: &[Job], trees: &[String]) -> Result<()> {
    for t in trees {
        if !jobs.iter().any(|j| &j.name() == t) {
            bail!("--tree {t}: no such tree in the design (names are stage.tree, as prove-mult prints them)");
        }
    }
    Ok(())
}

/// Each job's engine; a tree `--engine exhaustive` cannot take is bad input.
fn engines(jobs: &[Job], choice: EngineChoice) -> Result<Vec<Engine>> {
    jobs.iter().map(|j| j.engine(choice)).collect()
}

fn need_yosys() -> Result<()> {
    if !toolchain::installed(&yosys::yosys()) {
        bail!("{} not found (make tools installs it)", yosys::yosys());
    }
    Ok(())
}

/// One design's proof: whether every tree was proved, what to print, the SAT cases, the
/// inputs evaluated and the seconds Yosys and the evaluation took.
struct Proof {
    passed: bool,
    stdout: String,
    stderr: String,
    cases: usize,
    inputs: u128,
    seconds: f64,
}

/// Proves every tree of `design`, its script, miters and log staged into `logs`.
fn prove(
    design: &DesignDir,
    logs: &Path,
    policy: &Policy,
    choice: EngineChoice,
    trees: &[String],
) -> Result<Proof> {
    let jobs = chosen(&design.config, trees);
    let engines = engines(&jobs, choice)?;
    let shown = design.path().display();
    let mut p = Proof {
        passed: true,
        stdout: String::new(),
        stderr: String::new(),
        cases: 0,
        inputs: 0,
        seconds: 0.0,
    };
    if jobs.is_empty() {
        p.stdout = if trees.is_empty() {
            format!("prove-mult: {shown} has no adder tree\n")
        } else {
            format!("prove-mult: {shown} has none of the trees named\n")
        };
        return Ok(p);
    }
    let staged = StagedDir::new(logs, policy)?;
    let dir = absolute(staged.path());
    staged.write_text(mult_proof::TRANSPARENT_FILE, mult_proof::TRANSPARENT)?;
    staged.write_text(mult_proof::RIPPLE_FILE, mult_proof::RIPPLE_LCU)?;
    let mut wrappers = Vec::new();
    for j in &jobs {
        let f = format!("{}.v", j.wrapper_name());
        staged.write_text(&f, &mult_proof::wrapper(j))?;
        wrappers.push(f);
    }
    // Yosys runs in the log directory (the script's own files by name, so that it can be
    // rerun there); the design's files by absolute path ($readmemh then finds the hex files
    // beside them).
    let files: Vec<String> = design
        .file_names()
        .iter()
        .map(|f| design.path().join(f).display().to_string())
        .collect();
    let script = mult_proof::script(
        &files,
        &jobs,
        &engines,
        &wrappers,
        mult_proof::TRANSPARENT_FILE,
    );
    staged.write_text("mult.ys", &script)?;
    let mut cmd = Command::new(yosys::yosys());
    cmd.args(["-q", "-l"])
        .arg(yosys::LOG)
        .args(["-s", "mult.ys"])
        .current_dir(&dir);
    let ran = toolchain::capture(&mut cmd);
    let log_text = std::fs::read_to_string(dir.join(yosys::LOG)).unwrap_or_default();
    let (shown_logs, ran) = staged.commit_with(ran)?;
    let shown_logs = absolute(&shown_logs);
    let mut results = mult_proof::results(&jobs, &log_text);
    let log = shown_logs.join(yosys::LOG);
    let start = Instant::now();
    if ran.success() {
        for (i, j) in jobs.iter().enumerate() {
            if engines[i] == Engine::Exhaustive {
                let (aag, map) = j.aig_files();
                let read = |f: &str| {
                    let path = shown_logs.join(f);
                    std::fs::read_to_string(&path)
                        .with_context(|| format!("cannot read {}", path.display()))
                };
                results[i] =
                    mult_proof::exhaustive(j, &read(&aag)?, &read(&map)?).with_context(|| {
                        format!("{}: {}", j.name(), shown_logs.join(&aag).display())
                    })?;
                p.inputs += j.exhaustive_inputs();
            }
            if engines[i] == Engine::Algebra {
                let f = j.json_file();
                let path = shown_logs.join(&f);
                let json = std::fs::read_to_string(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                results[i] = mult_proof::algebraic(j, &json)
                    .with_context(|| format!("{}: {}", j.name(), path.display()))?;
            }
        }
    }
    report(&jobs, &results, &mut p);
    p.seconds = ran.seconds + start.elapsed().as_secs_f64();
    p.cases = results
        .iter()
        .filter(|r| r.engine == Engine::Sat)
        .map(|r| r.cases)
        .sum();
    if !ran.success() {
        p.passed = false;
        p.stderr += &format!(
            "prove-mult: {shown}: yosys failed ({}): {} (log: {})\n",
            ran.exit(),
            toolchain::complaint(&ran.output),
            log.display()
        );
        return Ok(p);
    }
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.name.as_str())
        .collect();
    if failed.is_empty() {
        p.stdout += &format!(
            "prove-mult: {shown}: all {} trees proved equal to their products ({} SAT cases, {} inputs evaluated, {:.1} s)\n",
            results.len(),
            p.cases,
            mult_proof::count(p.inputs),
            p.seconds
        );
    } else {
        p.passed = false;
        p.stderr += &format!(
            "prove-mult: {shown}: FAILED: {} (log: {})\n",
            failed.join(" "),
            log.display()
        );
    }
    Ok(p)
}

/// Every selected row of the grid: generated into DIR/<row>, then proved, `--jobs` rows at a
/// time (each row is one Yosys process); each row's report printed whole as it finishes.
/// Whether any failed.
fn matrix(a: &ProveMultArgs, rows: &[GridRow]) -> Result<bool> {
    let root = a.dir.clone().unwrap_or_else(|| "build/matrix".into());
    let policy = a.force.policy(&[]);
    // Generated first, in order, so that a bad directory stops the run before any proof.
    let mut designs = Vec::new();
    for r in rows {
        designs.push(generate_row(r, &root.join(r.name), &policy)?);
    }
    let workers = a
        .jobs
        .unwrap_or_else(toolchain::jobs)
        .min(rows.len())
        .max(1);
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<Result<Proof>>>> =
        Mutex::new((0..rows.len()).map(|_| None).collect());
    let start = Instant::now();
    let steps = super::progress::Steps::new();
    steps.step(&format!("proving the multipliers of {} rows", rows.len()));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(r) = rows.get(i) else { break };
                let proof = prove(
                    &designs[i],
                    &a.logs.join(r.name),
                    &policy,
                    a.engine,
                    &a.tree,
                );
                // One row's lines together, under its name; a failed print is the row's error.
                let proof = proof.and_then(|p| {
                    let mut all =
                        format!("==== {}: {} ({})\n", r.name, r.config.summary(), r.covers);
                    all += &p.stdout;
                    steps.suspend(|| crate::out!("{all}"))?;
                    steps.suspend(|| crate::err!("{}", p.stderr));
                    let k = done.fetch_add(1, Ordering::Relaxed) + 1;
                    steps.step(&format!("{k} of {} rows proved", rows.len()));
                    Ok(p)
                });
                out.lock().expect("no worker panics")[i] = Some(proof);
            });
        }
    });
    drop(steps);
    let mut failed = Vec::new();
    let (mut cases, mut inputs, mut cpu) = (0usize, 0u128, 0.0f64);
    for (r, p) in rows.iter().zip(out.into_inner().expect("no worker panics")) {
        let p = p.expect("every row ran")?;
        cases += p.cases;
        inputs += p.inputs;
        cpu += p.seconds;
        if !p.passed {
            failed.push(r.name);
        }
    }
    if failed.is_empty() {
        crate::outln!(
            "prove-mult: every row proved ({} row{}, {cases} SAT cases, {} inputs evaluated, {:.0} s of Yosys and evaluation in {:.0} s on {workers} job{})",
            rows.len(),
            if rows.len() == 1 { "" } else { "s" },
            mult_proof::count(inputs),
            cpu,
            start.elapsed().as_secs_f64(),
            if workers == 1 { "" } else { "s" }
        )?;
    } else {
        crate::outln!("prove-mult: FAILED: {}", failed.join(" "))?;
    }
    Ok(!failed.is_empty())
}

fn report(jobs: &[Job], results: &[mult_proof::TreeResult], p: &mut Proof) {
    for (j, r) in jobs.iter().zip(results) {
        if r.passed() {
            let how = match r.engine {
                Engine::Sat => format!(
                    "{} SAT case{}",
                    r.cases,
                    if r.cases == 1 { "" } else { "s" }
                ),
                Engine::Exhaustive => {
                    format!("every input: {}", mult_proof::count(j.exhaustive_inputs()))
                }
                Engine::Algebra => format!(
                    "as polynomials: {} case{}, at most {} terms",
                    r.cases,
                    if r.cases == 1 { "" } else { "s" },
                    r.peak_terms
                ),
            };
            p.stdout += &format!("prove-mult: {} = {}: proved ({how})\n", r.name, r.title);
        } else if let Some(case) = &r.failed {
            p.stderr += &format!(
                "prove-mult: {} = {}: FAILED: the sum {} differs from the product{}\n",
                r.name,
                r.title,
                j.spec.sum.sig.name,
                if case.is_empty() {
                    String::new()
                } else {
                    format!(" at {case}")
                }
            );
        } else if let Some(why) = &r.undecided {
            p.stderr += &format!(
                "prove-mult: {} = {}: not proved by the algebraic engine: {why}\n",
                r.name, r.title
            );
        } else {
            p.stderr += &format!(
                "prove-mult: {} = {}: not proved ({} of {} cases ran)\n",
                r.name, r.title, r.proved, r.cases
            );
        }
    }
}
