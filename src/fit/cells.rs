//! A configuration's cost in Yosys cells: its design synthesised for the iCE40 or the ECP5.
//! Separate because it is the search's one step that runs an outside tool.

use crate::config::Config;
use crate::rtl::fpga::Family;
use crate::scene::Scene;
use anyhow::{Context, Result};

/// Cells of Yosys synthesis for `family` (`synth_ice40` through
/// [`crate::toolchain::yosys::synth_ice40`], or `synth_ecp5` through
/// [`crate::toolchain::yosys::synth_ecp5`], as `rmapgen fpga` runs them: `--target ice40`,
/// memories in block RAM, each SB_RAM40_4K or DP16KD one cell, each MULT18X18D one cell) of a
/// configuration's design (all its lanes) with the scene's maps. `YOSYS` or `YOSYS_ECP5` names
/// the tool.
pub fn cells(cfg: &Config, scene: &Scene, family: Family) -> Result<u64> {
    let cfg = &cfg.for_target(crate::config::Target::Ice40);
    let tmp = crate::output::Scratch::new()?;
    let out = crate::output::StagedDir::new(&tmp.path().join("design"), &Default::default())?;
    let manifest =
        crate::rtl::write_design(&crate::design::Design::for_scene(cfg, scene)?, &out, None)?;
    let dir = out.commit()?;
    let files: Vec<String> = manifest.modules.iter().map(|m| m.file.clone()).collect();
    let synth = match family {
        Family::Ice40 => crate::toolchain::yosys::synth_ice40,
        Family::Ecp5 => crate::toolchain::yosys::synth_ecp5,
    };
    let stat = synth(&dir, &manifest.top, &files, tmp.path()).with_context(|| {
        format!(
            "--cost cells: {} synthesis of {}",
            family.title(),
            cfg.summary()
        )
    })?;
    Ok(stat.cells as u64)
}
