//! `rmapgen stress`: the model over every gradient (`--exhaustive`) or a seeded sample that
//! sweeps every magnitude, against the true direction and the float reference.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::output::StagedFile;
use crate::stress::{self, exhaustive, Report, Setup};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StressArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    /// The maps' scene is also the reference's.
    #[command(flatten)]
    pub map: MapArgs,
    /// Every gradient (2^(3 grad-bits) inputs; grad-bits <= 12).
    #[arg(long, conflicts_with = "samples")]
    pub exhaustive: bool,
    /// Gradients of a sampled run; the largest magnitude sweeps 1..=2^(grad-bits - 1)
    /// [1..=137438953472, 2^37].
    #[arg(long, value_name = "N", default_value_t = 10_000_000)]
    pub samples: u64,
    /// Seed of a sampled run.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write the full report as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

pub fn run(a: &StressArgs) -> Result<()> {
    if !a.exhaustive {
        stress::check_samples(a.samples)?;
    }
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene_for(&cfg)?;
    // Claimed before the run, so a refused path fails at once rather than after it.
    let json = match &a.json {
        Some(p) => Some(StagedFile::new(
            p,
            &a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]),
        )?),
        None => None,
    };
    let setup = Setup::new(&cfg, &scene, scene.maps(&cfg));
    let report = if a.exhaustive {
        let bar = super::progress::Progress::total(
            "stress",
            1u64 << (3 * cfg.grad_bits.min(exhaustive::MAX_GRAD_BITS)),
            "inputs",
        );
        let r = exhaustive::run(&setup, &|n| bar.inc(n));
        drop(bar);
        r?
    } else {
        let bar = super::progress::Progress::total("stress", a.samples, "samples");
        let r = stress::sampled_with_progress(&setup, a.samples, a.seed, &|n| bar.inc(n));
        drop(bar);
        r
    };
    crate::out!("{}", summary(&report))?;
    if let Some(out) = json {
        let text = serde_json::to_string_pretty(&report)?;
        out.write(text + "\n")?;
        out.commit()?;
    }
    anyhow::ensure!(
        report.mismatches == 0,
        "{} inputs disagreed between bit-exact evaluations",
        report.mismatches
    );
    Ok(())
}

/// The report as text: a verdict, the worst cases and a Markdown table per magnitude class.
pub fn summary(r: &Report) -> String {
    let mut s = format!(
        "rmapgen stress ({}): {} inputs of {}, {} map, in {:.1} s on {} threads\n",
        r.mode,
        r.inputs,
        r.config.summary(),
        r.map_fit.name(),
        r.seconds,
        rayon::current_num_threads()
    );
    s += &format!(
        "no panic; {} mismatches between bit-exact evaluations; overflow checks {}\n",
        r.mismatches,
        if r.overflow_checks {
            "on"
        } else {
            "off (release build; a dev build, `cargo test`, runs with them on)"
        }
    );
    if let Some(st) = &r.search {
        s += &format!(
            "phases: positions {:.1} s, every input {:.1} s, error search {:.1} s ({} cells bounded, {} evaluated, {} reference evaluations)\n",
            st.seconds_positions, st.seconds_inputs, st.seconds_search, st.cells, st.cells_evaluated, st.reference_evaluations
        );
    }
    if let Some(w) = r.worst_angle {
        s += &format!(
            "worst angular error: {:.4} deg at {:?}\n",
            w.degrees, w.gradient
        );
    }
    if let Some(w) = r.worst_error {
        s += &format!(
            "worst intensity error: {:+} LSB at {:?}: model {}, reference {} ({:.3})\n",
            w.error, w.gradient, w.model, w.reference, w.reference_exact
        );
    }
    s += "\n| shift | max magnitude | inputs | max angle (deg) | at | max abs error (LSB) | at | model | reference |\n";
    s += "|---:|---|---:|---:|---|---:|---|---:|---:|\n";
    for c in &r.classes {
        let (a, ag) = c.worst_angle.map_or(("-".into(), "-".into()), |w| {
            (format!("{:.4}", w.degrees), format!("{:?}", w.gradient))
        });
        let (e, eg, m, rf) =
            c.worst_error
                .map_or(("-".into(), "-".into(), "-".into(), "-".into()), |w| {
                    (
                        w.abs().to_string(),
                        format!("{:?}", w.gradient),
                        w.model.to_string(),
                        format!("{} ({:.2})", w.reference, w.reference_exact),
                    )
                });
        s += &format!(
            "| {} | {}..={} | {} | {a} | {ag} | {e} | {eg} | {m} | {rf} |\n",
            c.shift, c.magnitudes.0, c.magnitudes.1, c.inputs
        );
    }
    s
}
