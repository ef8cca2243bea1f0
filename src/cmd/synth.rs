//! `rmapgen synth`: Yosys synthesis of a generated design's top as a check: no latch, every
//! memory inferred, the cells and memory bits reported; for the iCE40 (`synth_ice40`, block
//! RAMs counted) or, with `--generic`, to generic gates with the memories kept as memories.
//!
//! Exit 0 when the design passes, 1 when Yosys fails on it (a latch, an error; the log's
//! complaints on stderr), 2 for bad input.

use super::force::ForceArg;
use crate::design_dir::DesignDir;
use crate::output::{absolute, StagedDir};
use crate::toolchain::yosys::{self, Flow};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// The generated design directory (`rmapgen generate --out DIR`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Yosys's generic gate-level synthesis with every memory kept as a memory cell, as an
    /// ASIC flow maps them to SRAM macros: any width, also designs far larger than an FPGA
    /// (default: synth_ice40).
    #[arg(long)]
    pub generic: bool,
    /// Directory for yosys.log, the statistics and the netlist (replaced whole, also when the
    /// synthesis fails, so its log can be read).
    #[arg(long, value_name = "DIR", default_value = "build/synth")]
    pub logs: PathBuf,
    #[command(flatten)]
    pub force: ForceArg,
}

pub fn run(a: &SynthArgs) -> Result<ExitCode> {
    let design = DesignDir::open(&a.dir)?;
    if !crate::toolchain::installed(&yosys::yosys()) {
        bail!("{} not found (make tools installs it)", yosys::yosys());
    }
    let flow = if a.generic {
        Flow::Generic
    } else {
        Flow::Ice40
    };
    let staged = StagedDir::new(&a.logs, &a.force.policy(&[Some(design.path())]))?;
    let logs = absolute(staged.path());
    let steps = super::progress::Progress::steps("synth");
    steps.step(&format!(
        "synthesising {} with Yosys {}",
        design.top,
        match flow {
            Flow::Ice40 => "synth_ice40",
            Flow::Generic => "synth (generic)",
        }
    ));
    let result = yosys::check(design.path(), &design.top, design.file_names(), &logs, flow);
    drop(steps);
    let (logs_shown, check) = staged.commit_with(result)?;
    let logs_shown = absolute(&logs_shown);
    let log = logs_shown.join(yosys::LOG);
    let what = format!("{} in {}", design.top, a.dir.display());
    if !check.passed {
        for p in &check.problems {
            crate::errln!("{p}");
        }
        crate::errln!("synth: {what}: FAILED (log: {})", log.display());
        return Ok(ExitCode::FAILURE);
    }
    crate::out!("{}", check.cells_report)?;
    match flow {
        Flow::Ice40 => crate::outln!(
            "synth: {what}: no latches, {} cells, {} memory bits, {} SB_RAM40_4K",
            check.cells,
            check.memory_bits,
            check.memories
        )?,
        Flow::Generic => crate::outln!(
            "synth: {what} (generic): no latches, {} cells, {} memory bits in {} memories",
            check.cells,
            check.memory_bits,
            check.memories
        )?,
    }
    Ok(ExitCode::SUCCESS)
}
