//! One design's multiplier proof, as `rmapgen prove-mult` runs it: the trees chosen, each
//! tree's engine, the Yosys script and miters staged into the log directory, Yosys run, the
//! exhaustive and algebraic engines on its output, and the report of every tree.

use super::{Engine, EngineChoice, Job};
use crate::config::Config;
use crate::design_dir::DesignDir;
use crate::output::{absolute, Policy, StagedDir};
use crate::toolchain::{self, yosys};
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// The trees of `cfg` that `--tree` names (all without it).
pub fn chosen(cfg: &Config, trees: &[String]) -> Vec<Job> {
    super::jobs(cfg)
        .into_iter()
        .filter(|j| trees.is_empty() || trees.contains(&j.name()))
        .collect()
}

/// A `--tree` that names no tree of the designs is bad input.
pub fn known_trees(jobs: &[Job], trees: &[String]) -> Result<()> {
    for t in trees {
        if !jobs.iter().any(|j| &j.name() == t) {
            bail!("--tree {t}: no such tree in the design (names are stage.tree, as prove-mult prints them)");
        }
    }
    Ok(())
}

/// Each job's engine; a tree `--engine exhaustive` cannot take is bad input.
pub fn engines(jobs: &[Job], choice: EngineChoice) -> Result<Vec<Engine>> {
    jobs.iter().map(|j| j.engine(choice)).collect()
}

pub fn need_yosys() -> Result<()> {
    if !toolchain::installed(&yosys::yosys()) {
        bail!("{} not found (make tools installs it)", yosys::yosys());
    }
    Ok(())
}

/// One design's proof: whether every tree was proved, what to print, the SAT cases, the
/// inputs evaluated and the seconds Yosys and the evaluation took.
pub struct Proof {
    pub passed: bool,
    pub stdout: String,
    pub stderr: String,
    pub cases: usize,
    pub inputs: u128,
    pub seconds: f64,
}

/// Proves every tree of `design`, its script, miters and log staged into `logs`.
pub fn prove(
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
    staged.write_text(super::TRANSPARENT_FILE, super::TRANSPARENT)?;
    staged.write_text(super::RIPPLE_FILE, super::RIPPLE_LCU)?;
    let mut wrappers = Vec::new();
    for j in &jobs {
        let f = format!("{}.v", j.wrapper_name());
        staged.write_text(&f, &super::wrapper(j))?;
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
    let script = super::script(&files, &jobs, &engines, &wrappers, super::TRANSPARENT_FILE);
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
    let mut results = super::results(&jobs, &log_text);
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
                    super::exhaustive(j, &read(&aag)?, &read(&map)?).with_context(|| {
                        format!("{}: {}", j.name(), shown_logs.join(&aag).display())
                    })?;
                p.inputs += j.exhaustive_inputs();
            }
            if engines[i] == Engine::Algebra {
                let f = j.json_file();
                let path = shown_logs.join(&f);
                let json = std::fs::read_to_string(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                results[i] = super::algebraic(j, &json)
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
            super::count(p.inputs),
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

fn report(jobs: &[Job], results: &[super::TreeResult], p: &mut Proof) {
    for (j, r) in jobs.iter().zip(results) {
        if r.passed() {
            let how = match r.engine {
                Engine::Sat => format!(
                    "{} SAT case{}",
                    r.cases,
                    if r.cases == 1 { "" } else { "s" }
                ),
                Engine::Exhaustive => {
                    format!("every input: {}", super::count(j.exhaustive_inputs()))
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
