//! Testbenches rendered from `templates/tb/` (placeholder until the testbench work lands).

use crate::config::Config;
use crate::output::StagedDir;
use anyhow::Result;

/// Writes `tb/<stage>_tb.v` for every stage present in `cfg`, and the top's testbench.
pub fn write_all(_cfg: &Config, _out: &StagedDir) -> Result<()> {
    Ok(())
}
