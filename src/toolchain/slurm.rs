//! Slurm's client commands, as `rmapgen prove --slurm` runs them: `sbatch` submits a batch
//! script (`--parsable`: it prints the job id), `squeue` tells which jobs are still queued or
//! running, `scancel` cancels. Each is the program its environment variable names (`SBATCH`,
//! `SQUEUE`, `SCANCEL`), else its name on PATH; `SLURM_CONF` and the rest of Slurm's
//! environment pass through to them.

use super::child;
use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::Command;

pub fn sbatch() -> String {
    super::program("SBATCH", "sbatch")
}

pub fn squeue() -> String {
    super::program("SQUEUE", "squeue")
}

pub fn scancel() -> String {
    super::program("SCANCEL", "scancel")
}

/// Submits `script` with the options `args` (before the script); the job id Slurm gave it.
/// A refusal is an error naming the job as `what` and quoting sbatch's complaint.
pub fn submit(args: &[String], script: &Path, what: &str) -> Result<String> {
    let mut cmd = Command::new(sbatch());
    cmd.arg("--parsable").args(args).arg(script);
    let out = child::output(&mut cmd).with_context(|| super::shell_line(&cmd))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        bail!(
            "sbatch refused {what}: {}",
            super::complaint(&format!("{stdout}{stderr}"))
        );
    }
    job_id(&stdout).with_context(|| {
        format!(
            "sbatch --parsable printed no job id for {what}: {:?}",
            stdout.trim()
        )
    })
}

/// The job id of `sbatch --parsable`'s output: `ID` or `ID;CLUSTER` on its last line.
pub fn job_id(stdout: &str) -> Option<String> {
    let line = stdout.lines().rev().find(|l| !l.trim().is_empty())?;
    let id = line.split(';').next()?.trim();
    (!id.is_empty() && id.bytes().all(|b| b.is_ascii_digit())).then(|| id.to_string())
}

/// How many of the jobs `ids` (an array job counts each task) Slurm still has queued or
/// running. A job Slurm has forgotten (finished long ago) is not; squeue's other failures
/// are errors.
pub fn live(ids: &[String]) -> Result<usize> {
    let mut cmd = Command::new(squeue());
    cmd.args(["--noheader", "--format", "%i", "--jobs", &ids.join(",")]);
    let out = child::output(&mut cmd).with_context(|| super::shell_line(&cmd))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        if stderr.contains("Invalid job id") {
            return Ok(0);
        }
        bail!("squeue failed: {}", super::complaint(&stderr));
    }
    Ok(String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .count())
}

/// `scancel IDS`, as words: what undoes a submission when rmapgen is interrupted.
pub fn cancel_words(ids: &[String]) -> Vec<String> {
    std::iter::once(scancel())
        .chain(ids.iter().cloned())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_job_id_is_the_number_sbatch_parsable_prints() {
        assert_eq!(job_id("42\n").as_deref(), Some("42"));
        assert_eq!(job_id("42;cluster\n").as_deref(), Some("42"));
        assert_eq!(job_id("warning: x\n17\n\n").as_deref(), Some("17"));
        assert_eq!(job_id(""), None);
        assert_eq!(job_id("Submitted batch job 5\n"), None);
        assert_eq!(job_id(";c\n"), None);
    }
}
