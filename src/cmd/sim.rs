//! `rmapgen sim`: the self-checking testbenches of a generated design under Icarus Verilog
//! and/or Verilator, the Verilator C++ harness on a long random stream of top vectors, and
//! (`--gate`) the top's testbench on the Yosys `synth_ice40` netlist in Icarus
//! ([`crate::sim`]); with `--matrix`, every configuration of the parameter grid
//! ([`crate::grid`]) generated and simulated in turn.
//!
//! Exit 0 when every run passed, 1 when one failed (each failure printed with its command and
//! the tail of its output), 2 for bad input (one line, nothing written).

use super::force::ForceArg;
use super::parse;
use crate::design_dir::DesignDir;
use crate::grid::{self, GridRow};
use crate::output::{absolute, StagedDir};
use crate::sim::{self, Options, Outcome};
use crate::vectors::MAX_STREAM_VECTORS;
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args, Debug)]
pub struct SimArgs {
    /// The generated design directory (`rmapgen generate --out DIR`). With --matrix, where
    /// each row's design is generated, as DIR/<row> [default: build/matrix].
    #[arg(value_name = "DIR", required_unless_present = "matrix")]
    pub dir: Option<PathBuf>,
    /// Every testbench (DIR/tb/*_tb.v) under Icarus Verilog.
    #[arg(long)]
    pub icarus: bool,
    /// Every testbench under Verilator (--binary).
    #[arg(long)]
    pub verilator: bool,
    /// N random top vectors through the Verilator C++ harness tb/top_stream.cpp
    /// [0..=10000000000; the stream files must fit the free space of the build directory].
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = parse::whole::<u64>(0, MAX_STREAM_VECTORS))]
    pub stream: u64,
    /// Also N random top vectors through the top's testbench (+vectors=FILE) in each
    /// simulator selected, for the Verilog testbench's throughput [0..=10000000000].
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = parse::whole::<u64>(0, MAX_STREAM_VECTORS))]
    pub tb_stream: u64,
    /// Only the testbench of module MODULE (DIR/tb/MODULE_tb.v).
    #[arg(long, value_name = "MODULE")]
    pub only: Option<String>,
    /// Dump a VCD of every Icarus testbench run (+vcd=) into the build directory, for
    /// GTKWave.
    #[arg(long, requires = "icarus")]
    pub vcd: bool,
    /// Gate-level sign-off: synthesise the top with Yosys synth_ice40 (the flow of `rmapgen
    /// fpga`), and run the top's testbench on the netlist (write_verilog) with Yosys's iCE40
    /// cell models in Icarus, on its vectors and the --tb-stream; the netlist and logs go to
    /// BUILD/<name>/gate.
    #[arg(long)]
    pub gate: bool,
    /// With --gate: simulate this netlist instead of synthesising DIR (a write_verilog of
    /// synth_ice40 for DIR's top, such as rmap_top_netlist.v in the logs of `rmapgen fpga`).
    #[arg(
        long,
        value_name = "FILE",
        requires = "gate",
        conflicts_with = "matrix"
    )]
    pub netlist: Option<PathBuf>,
    /// Build products and logs go to BUILD/<name of the design directory> (replaced whole,
    /// also when a simulation fails, so its logs can be read).
    #[arg(long, value_name = "BUILD", default_value = "build/sim")]
    pub build: PathBuf,
    /// Generate every configuration of the parameter grid (src/grid.rs) into DIR/<row> and
    /// run the simulations asked for on each.
    #[arg(long)]
    pub matrix: bool,
    /// With --matrix: only these rows (repeat the flag or separate with commas).
    #[arg(long, value_name = "NAME", requires = "matrix", value_delimiter = ',')]
    pub row: Vec<String>,
    #[command(flatten)]
    pub force: ForceArg,
}

impl SimArgs {
    fn options(&self) -> Options {
        Options {
            icarus: self.icarus,
            verilator: self.verilator,
            stream: self.stream,
            tb_stream: self.tb_stream,
            only: self.only.clone(),
            vcd: self.vcd,
            gate: self.gate,
            netlist: self.netlist.as_deref().map(absolute),
        }
    }
}

pub fn run(a: &SimArgs) -> Result<ExitCode> {
    let opts = a.options();
    if !opts.runs_something() {
        bail!("nothing to run: give --icarus, --verilator, --gate or --stream N");
    }
    // Bad input first, then the tools, then the runs.
    let failed = if a.matrix {
        let rows = grid::selected(&a.row)?;
        need_tools(&opts)?;
        matrix(a, &opts, &rows)?
    } else {
        let dir = a
            .dir
            .as_deref()
            .expect("clap requires DIR without --matrix");
        let design = DesignDir::open(dir)?;
        check_only(&design, &opts)?;
        if let Some(n) = &a.netlist {
            anyhow::ensure!(n.is_file(), "--netlist {}: no such file", n.display());
        }
        need_tools(&opts)?;
        !simulate(&design, a, &opts)?.failed.is_empty()
    };
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

fn need_tools(opts: &Options) -> Result<()> {
    if let Some(tool) = opts.missing_tools().first() {
        bail!("{tool} not found (make tools installs it)");
    }
    if opts.gate {
        crate::toolchain::yosys::ice40_cell_models()?;
    }
    Ok(())
}

/// `--only MODULE` names a testbench of the design, and the top's with `--gate`.
/// `--stream` drives one rmap_top: refused for a lanes design, whose rmap_tops share ROMs.
fn check_only(design: &DesignDir, opts: &Options) -> Result<()> {
    let cfg = &design.config;
    anyhow::ensure!(
        opts.stream == 0 || cfg.lanes == 1,
        "--stream drives one rmap_top through the C++ harness; {} has lanes = {} ({}, ROMs shared between lanes): stream its lanes testbench with --verilator --tb-stream N",
        design.path().display(),
        cfg.lanes,
        crate::stages::top(cfg).module(cfg)
    );
    if let Some(m) = opts.only.as_deref() {
        anyhow::ensure!(
            design.testbench(m).is_file(),
            "--only {m}: no testbench {} in {}",
            design.testbench(m).display(),
            design.path().display()
        );
        anyhow::ensure!(
            !opts.gate || m == design.top,
            "--only {m}: --gate simulates the top's netlist; give --only {} or leave it out",
            design.top
        );
    }
    Ok(())
}

/// The runs on one design, its build products staged into BUILD/<name>; prints as it goes
/// and the summary at the end.
fn simulate(design: &DesignDir, a: &SimArgs, opts: &Options) -> Result<Outcome> {
    check_only(design, opts)?;
    let target = a.build.join(design.name());
    let staged = StagedDir::new(&target, &a.force.policy(&[Some(design.path())]))?;
    let build = absolute(staged.path());
    crate::disk::check_space(
        &build,
        opts.stream_bytes(design),
        &format!(
            "the vector streams (--stream, --tb-stream) in {}",
            target.display()
        ),
    )?;
    // The first line that cannot be printed stops nothing of the run, but is its error.
    let mut report = Lines {
        steps: super::progress::Progress::steps("sim"),
        printed: Ok(()),
    };
    let result = sim::run(design, &build, &absolute(&target), opts, &mut report);
    let Lines { steps, printed } = report;
    drop(steps);
    printed?;
    let (_, outcome) = staged.commit_with(result)?;
    crate::out!("{}", outcome.summary(design))?;
    Ok(outcome)
}

/// The run's lines on stdout, and the step under way on a terminal's stderr.
struct Lines {
    steps: super::progress::Progress,
    printed: Result<()>,
}

impl sim::Report for Lines {
    fn say(&mut self, line: &str) {
        if self.printed.is_ok() {
            self.printed = self.steps.suspend(|| crate::outln!("{line}"));
        }
    }

    fn starting(&mut self, step: &str) {
        self.steps.step(step);
    }
}

/// Every selected row of the grid: generated into DIR/<row>, then simulated. Whether any
/// failed.
fn matrix(a: &SimArgs, opts: &Options, rows: &[GridRow]) -> Result<bool> {
    let root = a.dir.clone().unwrap_or_else(|| "build/matrix".into());
    let mut failed = Vec::new();
    for r in rows {
        crate::outln!("==== {}: {} ({})", r.name, r.config.summary(), r.covers)?;
        let design = crate::emit::dir::write_row(r, &root.join(r.name), &a.force.policy(&[]))?;
        if !simulate(&design, a, opts)?.failed.is_empty() {
            failed.push(r.name);
        }
    }
    if failed.is_empty() {
        crate::outln!("sim: every configuration passed ({} rows)", rows.len())?;
    } else {
        crate::outln!("sim: FAILED: {}", failed.join(" "))?;
    }
    Ok(!failed.is_empty())
}
