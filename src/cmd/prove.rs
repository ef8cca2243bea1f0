//! `rmapgen prove`: the generated RTL equals the model on every gradient ([`crate::prove`]),
//! one shard at a time (`--shard K/N`), and `--merge` of the shards' reports.
//!
//! Exit 0 when the run (or the merged run) passed, 1 when an input failed, 2 for bad input.

use super::force::ForceArg;
use crate::design_dir::DesignDir;
use crate::output::{absolute, StagedDir, StagedFile};
use crate::prove::{self, report, FrontEngine, Options, Shard};
use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
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
    /// Every gradient through the top instead of the factored proof (grad_bits <= 9).
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
    #[arg(long, value_name = "REPORT", num_args = 1.., conflicts_with_all = ["shard", "direct", "report", "part", "front_engine"])]
    pub merge: Vec<PathBuf>,
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
    };
    prove::check_design(&design, opts.direct)?;
    // Refused before the build directory or the report is claimed: bad input makes nothing.
    prove::check_options(&opts)?;
    let policy = a.force.policy(&[Some(design.path())]);
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
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} {human_pos} inputs ({per_sec})")
            .expect("valid template"),
    );
    let result = prove::run(&design, &build, &opts, &|n| bar.inc(n));
    bar.finish_and_clear();
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
