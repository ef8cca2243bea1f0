//! `rmapgen prove`: the generated RTL equals the model on every gradient ([`crate::prove`]),
//! one shard at a time (`--shard K/N`), and `--merge` of the shards' reports; `--build-only`
//! and `--reuse` share one build between shards, and `--slurm` runs the shards as jobs of a
//! Slurm cluster ([`crate::prove::slurm`]).
//!
//! Exit 0 when the run (or the merged run) passed, 1 when an input failed, 2 for bad input.

use super::force::ForceArg;
use crate::design_dir::DesignDir;
use crate::output::{absolute, StagedDir, StagedFile};
use crate::prove::{self, report, FrontEngine, Options, Shard};
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args, Debug)]
pub struct ProveArgs {
    /// The generated design directory (`rmapgen generate --out DIR`).
    #[arg(
        value_name = "DIR",
        required_unless_present = "merge",
        conflicts_with = "merge"
    )]
    pub dir: Option<PathBuf>,
    /// Run shard K of N: each part's inputs split into N contiguous ranges, this run the
    /// K-th; merge the N reports with --merge [N in 1..=1048576].
    #[arg(long, value_name = "K/N", allow_hyphen_values = true, value_parser = super::parse::named(Shard::parse))]
    pub shard: Option<Shard>,
    /// Every gradient through the top instead of the factored proof (grad_bits <= 9 in one
    /// run; wider in shards of at most as many samples: --shard K/512 for grad_bits 12).
    #[arg(long)]
    pub direct: bool,
    /// Only this part (repeat the flag or separate with commas): structure, states, zero,
    /// front; with --direct: structure, direct. Such a report does not merge.
    #[arg(long, value_name = "NAME", value_delimiter = ',')]
    pub part: Vec<String>,
    /// What evaluates the front on every gradient: gates (Yosys's gates of the generated
    /// front, its registers made wires, bit-parallel on all cores) or verilator (the front
    /// Verilated and clocked). Both read the generated files.
    #[arg(long, value_name = "ENGINE", value_enum, default_value = "gates")]
    pub front_engine: FrontEngine,
    /// Write the shard's report (JSON) to FILE, for --merge.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Combine these shard reports of one run into one verdict.
    #[arg(long, value_name = "REPORT", num_args = 1.., conflicts_with_all = ["shard", "direct", "report", "part", "front_engine", "build_only", "reuse", "slurm"])]
    pub merge: Vec<PathBuf>,
    /// Only build what the run simulates (the Verilated top, the front's gates) into
    /// BUILD/<name of the design directory>-build, for shards to --reuse; proves nothing.
    #[arg(long, conflicts_with_all = ["shard", "report", "reuse", "slurm"])]
    pub build_only: bool,
    /// Load what a --build-only run built in DIR (for the same design files, checked by
    /// SHA-256) instead of building it again.
    #[arg(long, value_name = "DIR", conflicts_with = "slurm")]
    pub reuse: Option<PathBuf>,
    /// Run the proof as jobs of a Slurm cluster (sbatch): a build job, an array job of
    /// --shards tasks that reuse its build, and a merge job after them; wait, and print the
    /// merged verdict. Scripts, logs and reports in BUILD/<name of the design directory>-slurm
    /// (replaced whole), which every node must see at the same path.
    #[arg(long, conflicts_with_all = ["shard", "report", "part"])]
    pub slurm: bool,
    /// With --slurm: the number of shards (array tasks) [1..=1000].
    #[arg(long, value_name = "N", default_value_t = 4, requires = "slurm")]
    pub shards: u64,
    /// With --slurm: the partition of every job (else the cluster's default).
    #[arg(long, value_name = "P", requires = "slurm")]
    pub partition: Option<String>,
    /// With --slurm: one more sbatch option for every job (repeat the flag), e.g.
    /// --sbatch-arg=--time=30 --sbatch-arg=--cpus-per-task=8.
    #[arg(
        long,
        value_name = "ARG",
        allow_hyphen_values = true,
        requires = "slurm"
    )]
    pub sbatch_arg: Vec<String>,
    /// Build products and logs go to BUILD/<name of the design directory>-<K>of<N> (replaced
    /// whole).
    #[arg(long, value_name = "BUILD", default_value = "build/prove")]
    pub build: PathBuf,
    #[command(flatten)]
    pub force: ForceArg,
}

pub fn run(a: &ProveArgs) -> Result<ExitCode> {
    if !a.merge.is_empty() {
        let m = report::merge(&a.merge)?;
        crate::out!("{}", m.text)?;
        return Ok(if m.passed {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(1)
        });
    }
    let dir = a.dir.as_ref().expect("clap requires DIR without --merge");
    let design = DesignDir::open(dir)?;
    let opts = Options {
        shard: a.shard.unwrap_or(Shard::WHOLE),
        direct: a.direct,
        front_engine: a.front_engine,
        parts: a.part.clone(),
        reuse: a.reuse.as_deref().map(absolute),
    };
    // Under --slurm the run is split into its --shards array tasks.
    let shards = if a.slurm { a.shards } else { opts.shard.count };
    prove::check_design(&design, opts.direct, shards)?;
    // Refused before the build directory or the report is claimed: bad input makes nothing.
    prove::check_options(&opts)?;
    let policy = a.force.policy(&[Some(design.path())]);
    if a.slurm {
        return slurm(a, &design, &policy);
    }
    if a.build_only {
        let staged = StagedDir::new(&a.build.join(format!("{}-build", design.name())), &policy)?;
        let build = absolute(staged.path());
        let t = std::time::Instant::now();
        let result = prove::build_only(&design, &build, &opts);
        let (dir, built) = staged.commit_with(result)?;
        crate::outln!(
            "built {}{} for {} in {:.1} s: {} (give it to --reuse)",
            if built.top { "the Verilated top" } else { "" },
            match &built.front_engine {
                Some(e) if built.top => format!(" and the front ({e})"),
                Some(e) => format!("the front ({e})"),
                None => String::new(),
            },
            design.path().display(),
            t.elapsed().as_secs_f64(),
            dir.display()
        )?;
        return Ok(ExitCode::SUCCESS);
    }
    // Claimed before the run, so a refused path fails at once rather than after it.
    let out = match &a.report {
        Some(p) => Some(StagedFile::new(p, &policy)?),
        None => None,
    };
    let target = a.build.join(format!(
        "{}-{}of{}",
        design.name(),
        opts.shard.index,
        opts.shard.count
    ));
    let staged = StagedDir::new(&target, &policy)?;
    let build = absolute(staged.path());
    let bar = super::progress::Progress::count("prove", "inputs");
    let result = prove::run(&design, &build, &opts, &|n| bar.inc(n));
    drop(bar);
    let (_, r) = staged.commit_with(result)?;
    crate::out!("{}", r.summary())?;
    if let Some(f) = out {
        f.write(serde_json::to_string_pretty(&r)? + "\n")?;
        f.commit()?;
    }
    Ok(if r.passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// `--slurm`: the run as jobs of a Slurm cluster, in BUILD/<design>-slurm.
fn slurm(a: &ProveArgs, design: &DesignDir, policy: &crate::output::Policy) -> Result<ExitCode> {
    let o = prove::slurm::Options {
        shards: a.shards,
        partition: a.partition.clone(),
        sbatch_args: a.sbatch_arg.clone(),
        direct: a.direct,
        front_engine: a.front_engine,
    };
    prove::slurm::check(&o)?;
    prove::slurm::check_tools()?;
    let exe = std::env::current_exe().context("the path of rmapgen itself, for the jobs")?;
    // The job directory is put in place at once: the jobs write into it at its final path.
    // It is provisional until the jobs are submitted: nothing is left if they cannot be.
    let shown = a.build.join(format!("{}-slurm", design.name()));
    let job_dir = StagedDir::new(&shown, policy)?.commit_in_place()?;
    let steps = super::progress::Progress::steps("prove");
    let outcome = prove::slurm::run(
        design,
        job_dir,
        &shown,
        &exe,
        &o,
        &|line| steps.suspend(|| crate::outln!("{line}")),
        &|line| steps.step(line),
    )?;
    drop(steps);
    crate::outln!("{}", outcome.text)?;
    Ok(if outcome.passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
