//! `rmapgen prove-mult`: the formal proof that every adder tree of a generated design
//! equals the plain product its plan says it builds (`a * b + c`), on every input, with
//! Yosys's SAT solver or by evaluating the cut miter on every input, on the generated modules
//! ([`crate::prove::mult`]).
//!
//! Exit 0 when every tree is proved, 1 when any is not (each failure names the stage, the
//! tree and the first failing case), 2 for bad input.

use super::force::ForceArg;
use super::parse;
use crate::design_dir::DesignDir;
use crate::grid::GridRow;

use crate::prove::mult::run::{chosen, engines, known_trees, need_yosys, prove, Proof};
use crate::prove::mult::{self as mult_proof, EngineChoice};
use crate::toolchain;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
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
        let rows = crate::grid::selected(&a.row)?;
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
        let steps = super::progress::Progress::steps("prove-mult");
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

/// Every selected row of the grid: generated into DIR/<row>, then proved, `--jobs` rows at a
/// time (each row is one Yosys process); each row's report printed whole as it finishes.
/// Whether any failed.
fn matrix(a: &ProveMultArgs, rows: &[GridRow]) -> Result<bool> {
    let root = a.dir.clone().unwrap_or_else(|| "build/matrix".into());
    let policy = a.force.policy(&[]);
    // Generated first, in order, so that a bad directory stops the run before any proof.
    let mut designs = Vec::new();
    for r in rows {
        designs.push(crate::emit::dir::write_row(r, &root.join(r.name), &policy)?);
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
    let steps = super::progress::Progress::steps("prove-mult");
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
