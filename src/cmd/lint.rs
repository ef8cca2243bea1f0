//! `rmapgen lint`: Verilator's lint of a generated design with every warning class on
//! (`--lint-only -Wall`, no waivers). The design passes when Verilator exits 0 and prints
//! nothing.
//!
//! Exit 0 when clean, 1 on any warning (Verilator's output on stderr), 2 for bad input.

use crate::design_dir::DesignDir;
use crate::toolchain::{self, verilator};
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args, Debug)]
pub struct LintArgs {
    /// The generated design directory (`rmapgen generate --out DIR`).
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

pub fn run(a: &LintArgs) -> Result<ExitCode> {
    let design = DesignDir::open(&a.dir)?;
    if !toolchain::installed(&verilator::verilator()) {
        bail!(
            "{} not found (make tools installs it)",
            verilator::verilator()
        );
    }
    let mut cmd = verilator::lint(design.path(), &design.top, &design.files());
    let ran = toolchain::capture(&mut cmd)?;
    let shown = a.dir.display();
    if ran.success() && ran.output.trim().is_empty() {
        crate::outln!("lint: {shown} is clean (verilator -Wall, no warnings)")?;
        return Ok(ExitCode::SUCCESS);
    }
    crate::err!("{}", ran.output);
    crate::errln!(
        "lint: {shown}: verilator -Wall is not silent ({}; {})",
        ran.exit(),
        toolchain::shell_line(&cmd)
    );
    Ok(ExitCode::FAILURE)
}
