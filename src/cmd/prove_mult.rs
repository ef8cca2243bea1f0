//! `rmapgen prove-mult`: the formal proof that every adder tree of a generated design
//! equals the plain product its plan says it builds (`a * b + c`), on every input, with
//! Yosys's SAT solver on the generated modules ([`crate::rtl::mult_proof`]).
//!
//! Exit 0 when every tree is proved, 1 when any is not (each failure names the stage, the
//! tree and the first failing case), 2 for bad input.

use super::force::ForceArg;
use crate::design_dir::DesignDir;
use crate::output::{absolute, StagedDir};
use crate::rtl::mult_proof::{self, Job};
use crate::toolchain::{self, yosys};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::{Command, ExitCode};

#[derive(Args, Debug)]
pub struct ProveMultArgs {
    /// The generated design directory (`rmapgen generate --out DIR`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Directory for the Yosys script, the miters and yosys.log (replaced whole, also when
    /// the proof fails, so its log can be read).
    #[arg(long, value_name = "DIR", default_value = "build/prove-mult")]
    pub logs: PathBuf,
    #[command(flatten)]
    pub force: ForceArg,
}

pub fn run(a: &ProveMultArgs) -> Result<ExitCode> {
    let design = DesignDir::open(&a.dir)?;
    if !toolchain::installed(&yosys::yosys()) {
        bail!("{} not found (make tools installs it)", yosys::yosys());
    }
    let jobs = mult_proof::jobs(&design.config);
    let shown = a.dir.display();
    if jobs.is_empty() {
        println!("prove-mult: {shown} has no adder tree");
        return Ok(ExitCode::SUCCESS);
    }
    let staged = StagedDir::new(&a.logs, &a.force.policy(&[Some(design.path())]))?;
    let logs = absolute(staged.path());
    staged.write_text(mult_proof::TRANSPARENT_FILE, mult_proof::TRANSPARENT)?;
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
    let script = mult_proof::script(&files, &jobs, &wrappers, mult_proof::TRANSPARENT_FILE);
    staged.write_text("mult.ys", &script)?;
    let mut cmd = Command::new(yosys::yosys());
    cmd.args(["-q", "-l"])
        .arg(yosys::LOG)
        .args(["-s", "mult.ys"])
        .current_dir(&logs);
    let ran = toolchain::capture(&mut cmd);
    let log_text = std::fs::read_to_string(logs.join(yosys::LOG)).unwrap_or_default();
    let shown_logs = absolute(&staged.commit()?);
    let ran = ran?;
    let results = mult_proof::results(&jobs, &log_text);
    report(&jobs, &results);
    let log = shown_logs.join(yosys::LOG);
    if !ran.success() {
        eprintln!(
            "prove-mult: {shown}: yosys failed ({}): {} (log: {})",
            ran.exit(),
            toolchain::complaint(&ran.output),
            log.display()
        );
        return Ok(ExitCode::FAILURE);
    }
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.name.as_str())
        .collect();
    let cases: usize = results.iter().map(|r| r.cases).sum();
    if failed.is_empty() {
        println!(
            "prove-mult: {shown}: all {} trees proved equal to their products ({cases} SAT cases, {:.1} s)",
            results.len(),
            ran.seconds
        );
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "prove-mult: {shown}: FAILED: {} (log: {})",
            failed.join(" "),
            log.display()
        );
        Ok(ExitCode::FAILURE)
    }
}

fn report(jobs: &[Job], results: &[mult_proof::TreeResult]) {
    for (j, r) in jobs.iter().zip(results) {
        if r.passed() {
            println!(
                "prove-mult: {} = {}: proved ({} case{})",
                r.name,
                r.title,
                r.cases,
                if r.cases == 1 { "" } else { "s" }
            );
        } else if let Some(case) = &r.failed {
            eprintln!(
                "prove-mult: {} = {}: FAILED: the sum {} differs from the product{}",
                r.name,
                r.title,
                j.spec.sum.sig.name,
                if case.is_empty() {
                    String::new()
                } else {
                    format!(" at {case}")
                }
            );
        } else {
            eprintln!(
                "prove-mult: {} = {}: not proved ({} of {} cases ran)",
                r.name, r.title, r.proved, r.cases
            );
        }
    }
}
