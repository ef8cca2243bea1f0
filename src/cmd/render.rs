//! `rmapgen render`: the sphere test image shaded by the model and by the float reference,
//! the error image and the error statistics.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::output::StagedDir;
use crate::render::{self, Options};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    /// The scene to shade, and how its maps are filled.
    #[command(flatten)]
    pub map: MapArgs,
    /// Image width and height in pixels [1..=4096].
    #[arg(long, value_name = "N", default_value_t = render::DEFAULT_SIZE, value_parser = super::parse::count::<u32>())]
    pub size: u32,
    /// Scale the gradients down by 2^K, to exercise the leading-zero shift [0..=grad-bits - 1].
    #[arg(long, value_name = "K", default_value_t = 0, value_parser = super::parse::at_least::<u32>(0))]
    pub shrink: u32,
    /// Also shade every pixel with the generated RTL (Verilated top) and write rtl.png; fails
    /// unless the RTL image equals the model image pixel for pixel.
    #[arg(long)]
    pub rtl: bool,
    /// Output directory for reference.png, model.png, error50.png, metrics.json and the
    /// pictures highlight.png, error_signed.png, profile.png and histogram.png, and report.html
    /// showing them all (replaced whole on success).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene_for(&cfg)?;
    let options = Options {
        size: a.size,
        shrink: a.shrink,
    };
    options.validate(&cfg)?;
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
    let out = StagedDir::new(&a.out, &policy)?;
    let rtl = if a.rtl {
        Some(crate::sim::verilated::VerilatedTop::build(&cfg, &scene)?)
    } else {
        None
    };
    let r = render::render(
        &cfg,
        &scene,
        options,
        rtl.as_ref()
            .map(|t| t as &dyn crate::model::IntensitySource),
    )?;
    if let Some(n) = r.rtl_mismatches() {
        if n > 0 {
            anyhow::bail!("the RTL image differs from the model image in {n} pixels");
        }
    }
    r.write(&out)?;
    let p = out.commit()?;
    crate::outln!("{} -> {}", r.summary(), p.display())?;
    Ok(())
}
