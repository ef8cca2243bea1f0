//! `rmapgen mutants`: mutation testing of rmapgen's own checks on a design
//! ([`crate::mutants`]). Exit 0 when no non-equivalent mutant passed the factored proof, 1
//! when one did (a soundness bug), 2 for bad input or a broken flow (the null mutant failed).

use super::force::ForceArg;
use crate::design_dir::DesignDir;
use crate::mutants::campaign::{self, Judged};
use crate::mutants::journal::{self, Journal};
use crate::mutants::{self, Change, Method, Mutant, Outcome, Plan};
use crate::output::{absolute, StagedDir, StagedFile};
use crate::stages::TOP;
use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct MutantsArgs {
    /// The generated design directory (grad_bits <= 9: the ground truth drives every
    /// gradient through the top).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Verilog mutants to draw with Yosys's `mutate -list` [0..=10000].
    #[arg(long, default_value_t = 60, value_name = "N")]
    pub count: usize,
    /// Draw the Verilog mutants from this Yosys selection only (for example `rmap_top
    /// pipe_delay`, the modules of the flow control, under `--truth flow`); default the
    /// whole design.
    #[arg(long, value_name = "SELECTION")]
    pub select: Option<String>,
    /// The seed of Yosys's draw and of the memory mutants.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Memory mutants per memory file (one entry, one bit) [0..=1000]; default 1, and 0
    /// under `--truth flow` (a memory's contents change no flow signal).
    #[arg(long, value_name = "K")]
    pub memories: Option<usize>,
    /// Checks to judge every mutant by besides the ground truth: prove, sim, gate against
    /// `--truth direct` or `stream` (default prove); formal against `--truth flow` (the
    /// default there). Repeat or separate with commas.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub method: Vec<Method>,
    /// Judge only these mutants of the draw (their numbers, as printed: `m29` or `29`; the
    /// null mutant always runs), again even if the journal has them.
    #[arg(long, value_name = "ID", value_delimiter = ',', allow_hyphen_values = true, value_parser = super::parse::named(parse_id))]
    pub only: Vec<usize>,
    /// Run the ground truth only on the mutants the factored proof passes (enough to show it
    /// sound: the bounded sample of `make test`).
    #[arg(long)]
    pub quick: bool,
    /// Mutants judged side by side.
    #[arg(long, default_value_t = 1, value_name = "J")]
    pub jobs: usize,
    /// Seconds one check of one mutant may take before it is killed (a timeout kills).
    #[arg(long, default_value_t = 900, value_name = "SECONDS")]
    pub timeout: u64,
    /// Random top vectors of `sim`'s C++ stream.
    #[arg(long, default_value_t = 100_000, value_name = "N")]
    pub sim_stream: u64,
    /// The ground truth that classes every mutant: direct (`prove --direct`, every gradient
    /// through the top; grad_bits <= 9) or stream (`sim --stream N`, a random sample of
    /// gradients through the top against the model, for wider designs: a mutant it passes is
    /// "equivalent" only as far as the sample shows).
    #[arg(long, value_enum, default_value = "direct")]
    pub truth: Truth,
    /// Random gradients of the stream ground truth.
    #[arg(long, default_value_t = 10_000_000, value_name = "N")]
    pub truth_stream: u64,
    /// The Python that runs the formal harness (`--truth flow`): the project's venv.
    #[arg(long, default_value = ".venv/bin/python", value_name = "PATH")]
    pub python: PathBuf,
    /// The formal harness's driver (`--truth flow`).
    #[arg(long, default_value = "formal/run_formal.py", value_name = "PATH")]
    pub formal_script: PathBuf,
    /// Every mutant's design, builds and logs go to BUILD/<design name>/m<id> (replaced whole);
    /// the outcomes to the journal BUILD/<design name>.journal, which a later run of the same
    /// binary, design and draw goes on from.
    #[arg(long, default_value = "build/mutants", value_name = "BUILD")]
    pub build: PathBuf,
    /// Write every mutant's verdicts and the tallies as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub force: ForceArg,
}

/// The ground truth of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Truth {
    Direct,
    Stream,
    /// The flow miter (`formal/run_formal.py --miter`): a bounded search from reset for a
    /// difference in ready_o, valid_o, the tag and the map buffers between the mutant and
    /// the design; it judges the formal harness (`--method formal`) on a `--handshake --axis`
    /// design.
    Flow,
    /// The wiring miter (Yosys: the mutant's wrapper equal to the design's, the modules it
    /// instantiates cut out): mutants of the wrapper around the top alone (rmap_axis with
    /// `--axis`, rmap_lanes with `--lanes`), judged by the wrapper's testbench (`--method
    /// wrapper`, `rmapgen sim --icarus --only <wrapper>`), which is what checks it.
    Wrapper,
}

pub fn run(a: &MutantsArgs) -> Result<ExitCode> {
    let design = DesignDir::open(&a.dir)?;
    let truth = match a.truth {
        Truth::Direct => Method::Direct,
        Truth::Stream => Method::Stream,
        Truth::Flow => Method::Flow,
        Truth::Wrapper => Method::Wiring,
    };
    let methods = if a.method.is_empty() {
        vec![truth.proof()]
    } else {
        a.method.clone()
    };
    if let Some(m) = methods.iter().find(|m| m.is_truth()) {
        bail!(
            "--method {}: a ground truth runs on every mutant already (--truth)",
            m.name()
        );
    }
    if let Some(s) = &a.select {
        mutants::check_select(s)?;
    }
    if let Some(m) = methods.iter().find(|m| m.proof() != truth.proof()) {
        bail!(
            "--method {}: judged against --truth {}, not --truth {}",
            m.name(),
            match m {
                Method::Formal => "flow",
                Method::Wrapper => "wrapper",
                _ => "direct or stream",
            },
            a.truth
                .to_possible_value()
                .map_or_else(String::new, |v| v.get_name().to_string())
        );
    }
    let memories = match (a.memories, truth) {
        (Some(k), Method::Flow) if k > 0 => {
            bail!("--memories {k}: under --truth flow a memory's contents change no flow signal; give 0")
        }
        (Some(k), Method::Wiring) if k > 0 => {
            bail!("--memories {k}: under --truth wrapper the memories are the top's, not the wrapper's; give 0")
        }
        (Some(k), _) => k,
        (None, Method::Flow | Method::Wiring) => 0,
        (None, _) => 1,
    };
    let wrapper = if truth == Method::Wiring {
        if let Some(s) = &a.select {
            bail!("--select {s}: under --truth wrapper the draw is of the wrapper alone");
        }
        match mutants::Wrapper::of(&design) {
            Some(w) => Some(w),
            None => bail!(
                "--truth wrapper: {} has no wrapper around {} (its top is {}); generate it with --axis or --lanes",
                design.path().display(),
                TOP.module(&design.config),
                design.top
            ),
        }
    } else {
        None
    };
    let formal = if truth == Method::Flow {
        let c = &design.config;
        if !c.handshake || !c.axis || c.color || c.lanes > 1 || !c.prefix.is_empty() {
            bail!("--truth flow: the formal harness takes a --handshake --axis design without --color, --lanes or --prefix; {} is {}", design.path().display(), c.summary());
        }
        for (flag, p) in [
            ("--python", &a.python),
            ("--formal-script", &a.formal_script),
        ] {
            if !p.is_file() {
                bail!("{flag} {}: not found (make venv; run from the project's root, or give --python and --formal-script)", p.display());
            }
        }
        // The venv's python as given, not its symlink resolved: a venv is found from the path
        // its interpreter was started by.
        Some(mutants::FormalTools {
            python: std::path::absolute(&a.python)?,
            script: absolute(&a.formal_script),
            reference: absolute(design.path()),
        })
    } else {
        None
    };
    if truth.proof() == Method::Prove {
        // The factored proof is judged on every mutant, so the design must be one it takes.
        if let Err(e) = crate::prove::check_design(&design, false, 1) {
            bail!("rmapgen mutants judges by rmapgen prove: {e}");
        }
    }
    if truth == Method::Direct {
        if let Err(e) = crate::prove::check_design(&design, true, 1) {
            bail!("the ground truth of rmapgen mutants is prove --direct: {e}; give --truth stream for a sampled one");
        }
    }
    if a.truth_stream == 0 {
        bail!("--truth-stream 0: give a number of gradients");
    }
    if a.jobs == 0 || a.jobs > 64 {
        bail!("--jobs {}: give 1..=64", a.jobs);
    }
    if a.timeout == 0 {
        bail!("--timeout 0: give a number of seconds");
    }
    let policy = a.force.policy(&[Some(design.path())]);
    let out = match &a.report {
        Some(p) => Some(StagedFile::new(p, &policy)?),
        None => None,
    };
    let staged = StagedDir::new(&mutants::work_dir(&a.build, &design), &policy)?;
    let work = absolute(staged.path());

    let mut changes = vec![Change::Null];
    changes.extend(mutants::draw_verilog(
        &design,
        a.count,
        a.seed,
        a.select.as_deref(),
        wrapper.as_ref(),
        &work.join("draw"),
    )?);
    changes.extend(mutants::draw_memories(&design, memories, a.seed)?);
    let n = changes.len();
    if let Some(id) = a.only.iter().find(|&&id| id >= n) {
        bail!("--only m{id}: the draw has m0..m{}", n - 1);
    }
    let draw: Vec<Mutant> = changes
        .into_iter()
        .enumerate()
        .map(|(id, change)| Mutant { id, change })
        .collect();
    let list: Vec<Mutant> = draw
        .iter()
        .filter(|m| m.id == 0 || a.only.is_empty() || a.only.contains(&m.id))
        .cloned()
        .collect();
    let plan = Plan {
        methods: methods.clone(),
        quick: a.quick,
        timeout: Duration::from_secs(a.timeout),
        sim_stream: a.sim_stream,
        truth,
        truth_stream: a.truth_stream,
        formal,
        wrapper,
    };
    let key = journal::Key::new(&design, &plan, &draw)?;
    let journal = Journal::open(
        &mutants::journal_path(&a.build, &design),
        &key,
        &a.only,
        a.force.force,
    )?;
    crate::outln!(
        "mutants of {} ({}): the null mutant, {} Verilog (Yosys mutate, seed {}), {} memory; ground truth {}{}; {} at a time",
        design.path().display(),
        design.config.summary(),
        list.iter().filter(|m| matches!(m.change, Change::Verilog { .. })).count(),
        a.seed,
        list.iter().filter(|m| matches!(m.change, Change::Memory { .. })).count(),
        match truth {
            Method::Stream => format!(
                "sim --stream {} (a sample: equivalent means no difference found)",
                a.truth_stream
            ),
            Method::Flow => "the flow miter (run_formal.py --miter: a bounded search from reset)".to_string(),
            Method::Wiring => "the wiring miter (Yosys: the wrapper equal to the design's, its instances cut out)".to_string(),
            _ => "prove --direct".to_string(),
        },
        if a.quick {
            format!(" on the mutants {} passes", truth.proof().name())
        } else {
            String::new()
        },
        a.jobs
    )?;
    crate::outln!("{}", journal.said)?;
    let t0 = Instant::now();
    let said = |o: &Outcome, from: &str| print_outcome(o, n, from);
    let outcomes = match campaign::run(&design, &list, &plan, &work, &journal, a.jobs, &said)? {
        Judged::All(o) => o,
        Judged::BrokenFlow(broken) => {
            let work = staged.commit()?;
            bail!(
                "the null mutant (the design through Yosys, no mutation) does not pass: {}; logs in {}",
                broken.join(", "),
                work.join("m0").display()
            );
        }
    };
    let mut methods = vec![truth];
    if a.quick {
        methods = vec![truth.proof(), truth];
    } else {
        methods.extend(&plan.methods);
    }
    crate::outln!(
        "{:<8} {:>7} {:>11} {:>15} {:>7} {:>9} {:>17} {:>18}",
        "method",
        "judged",
        "equivalent",
        "non-equivalent",
        "killed",
        "survived",
        "killed unclassed",
        "failed equivalent"
    )?;
    let tallies: Vec<_> = methods
        .iter()
        .map(|&m| mutants::tally(m, &outcomes))
        .collect();
    for t in &tallies {
        crate::outln!(
            "{:<8} {:>7} {:>11} {:>15} {:>7} {:>9} {:>17} {:>18}",
            t.method,
            t.judged,
            t.equivalent,
            t.non_equivalent,
            t.killed,
            t.survived,
            t.killed_unclassed,
            t.failed_equivalent
        )?;
    }
    let unsound: Vec<&Outcome> = outcomes.iter().filter(|o| o.unsound()).collect();
    for o in &unsound {
        crate::outln!(
            "SURVIVED (outputs differ under {}, passed by {}): {}",
            truth.name(),
            truth.proof().name(),
            o.mutant.describe()
        )?;
    }
    crate::outln!(
        "{}: {} mutants in {:.0} s",
        if unsound.is_empty() {
            "SOUND"
        } else {
            "UNSOUND"
        },
        outcomes.len() - 1,
        t0.elapsed().as_secs_f64()
    )?;
    staged.commit()?;
    if let Some(f) = out {
        let json = serde_json::json!({
            "format": "rmapgen-mutants-1",
            "design": design.path().display().to_string(),
            "config": design.config,
            "seed": a.seed,
            "quick": a.quick,
            "truth": truth.name(),
            "tallies": tallies,
            "outcomes": outcomes,
        });
        f.write(serde_json::to_string_pretty(&json)? + "\n")?;
        f.commit()?;
    }
    Ok(if unsound.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn parse_id(text: &str) -> Result<usize, String> {
    text.trim_start_matches('m')
        .parse()
        .map_err(|_| "not a mutant number (m29 or 29)".to_string())
}

fn print_outcome(o: &Outcome, n: usize, from: &str) -> Result<()> {
    let verdicts: Vec<String> = o
        .verdicts
        .iter()
        .map(|(m, v)| format!("{} {}", m.name(), format!("{v:?}").to_lowercase()))
        .collect();
    crate::outln!(
        "  [{}/{}] {:>6.1} s  {}: {}{from}",
        o.mutant.id,
        n - 1,
        o.seconds,
        verdicts.join(", "),
        o.mutant.describe()
    )
}
