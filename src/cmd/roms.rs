//! `rmapgen roms`: the ROM and map contents as `$readmemh` files, nothing else.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design::Design;
use crate::output::StagedDir;
use anyhow::Context;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RomsArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    #[command(flatten)]
    pub map: MapArgs,
    /// Output directory (replaced whole on success).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub force: super::force::ForceArg,
    /// Refresh only the hex files of the generated directory DIR, keeping its other files
    /// (`make roms`); DIR must hold only what rmapgen wrote there.
    #[arg(
        long,
        value_name = "DIR",
        conflicts_with = "out",
        required_unless_present = "out"
    )]
    pub update: Option<PathBuf>,
}

pub fn run(a: &RomsArgs) -> Result<()> {
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene()?;
    let target = a
        .out
        .as_ref()
        .or(a.update.as_ref())
        .context("--out or --update")?;
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
    if a.update.is_some() && crate::output::stamp::read(target).is_none() {
        anyhow::bail!(
            "--update {}: not a directory rmapgen generated (it has no {})",
            target.display(),
            crate::output::stamp::NAME
        );
    }
    let out = StagedDir::new(target, &policy)?;
    for (name, text) in crate::rtl::hex_files(&Design::for_scene(&cfg, &scene)?) {
        out.write_text(&name, &text)?;
    }
    if a.update.is_some() {
        out.keep_others()?;
    }
    let p = out.commit()?;
    crate::errln!("rmapgen: wrote ROM and map hex files to {}", p.display());
    Ok(())
}
