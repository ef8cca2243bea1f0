//! A configuration's cost in Yosys cells: its design synthesised for the iCE40. Separate
//! because it is the search's one step that runs an outside tool.

use crate::config::Config;
use crate::scene::Scene;
use anyhow::{Context, Result};

/// Cells of Yosys synthesis for the iCE40 (`synth_ice40` through
/// [`crate::toolchain::yosys::synth_ice40`], as `rmapgen fpga` runs it: `--target ice40`, memories in block RAM,
/// each SB_RAM40_4K one cell) of a configuration's design with the scene's maps. `YOSYS` names
/// the tool.
pub fn cells(cfg: &Config, scene: &Scene) -> Result<u64> {
    let cfg = &cfg.for_target(crate::config::Target::Ice40);
    let tmp = crate::output::Scratch::new()?;
    let out = crate::output::StagedDir::new(&tmp.path().join("design"), &Default::default())?;
    let manifest = crate::rtl::write_design(&crate::design::Design::for_scene(cfg, scene)?, &out)?;
    let dir = out.commit()?;
    let files: Vec<String> = manifest.modules.iter().map(|m| m.file.clone()).collect();
    let stat = crate::toolchain::yosys::synth_ice40(&dir, &manifest.top, &files, tmp.path())
        .with_context(|| format!("--cost cells: synthesis of {}", cfg.summary()))?;
    Ok(stat.cells as u64)
}
