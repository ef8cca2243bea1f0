//! `rmapgen roms`: the ROM and map contents as `$readmemh` files, nothing else.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design::Design;
use crate::design_dir::DesignDir;
use crate::emit::manifest;
use crate::output::StagedDir;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};

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
    /// Write the generated design DIR again for new maps (`--scene`, `--map-fit`; else its
    /// own scene): its ROM and map files, README and test vectors change together, with
    /// its own configuration (configuration flags may only agree with its manifest.json)
    /// and vector count and seed (`make roms`). DIR must hold only what rmapgen wrote there.
    #[arg(
        long,
        value_name = "DIR",
        conflicts_with = "out",
        required_unless_present = "out"
    )]
    pub update: Option<PathBuf>,
}

pub fn run(a: &RomsArgs) -> Result<()> {
    if let Some(dir) = &a.update {
        return update(a, dir);
    }
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene_for(&cfg)?;
    let target = a.out.as_ref().context("--out or --update")?;
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
    let out = StagedDir::new(target, &policy)?;
    for (name, text) in crate::emit::hex_files(&Design::for_scene(&cfg, &scene)?) {
        out.write_text(&name, &text)?;
    }
    let p = out.commit()?;
    crate::errln!("rmapgen: wrote ROM and map hex files to {}", p.display());
    Ok(())
}

/// `--update DIR`: the design in DIR written again for new maps, with its own configuration
/// (flags may only agree with it), its own test vectors' count and seed, and the scene given
/// (else its own, with `--map-fit` applied): the maps, the README and the vectors change
/// together, so the design passes its own testbenches; nothing changes if anything fails.
fn update(a: &RomsArgs, dir: &Path) -> Result<()> {
    let shown = dir.display();
    if crate::output::stamp::read(dir).is_none() {
        bail!(
            "--update {shown}: not a directory rmapgen generated (it has no {})",
            crate::output::stamp::NAME
        );
    }
    let design = DesignDir::open(dir)?;
    let cfg = a.cfg.for_design(&design.config, dir)?;
    let scene = a.map.scene_or(|| {
        design.scene.clone().with_context(|| {
            format!("--update {shown}: its {} records no scene (written by an older rmapgen): give --scene", manifest::FILE)
        })
    })?;
    let vectors = design.vectors.with_context(|| {
        format!(
            "--update {shown}: its {} records no test vectors (written by an older rmapgen): generate it again",
            manifest::FILE
        )
    })?;
    let before = crate::output::stamp::read(dir).unwrap_or_default();
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
    let (p, _) = crate::emit::dir::write_dir(
        &cfg,
        &scene,
        dir,
        &policy,
        vectors,
        &[],
        crate::emit::dir::Keep::Others,
    )?;
    let after = crate::output::stamp::read(&p).unwrap_or_default();
    let changed: Vec<&String> = after
        .iter()
        .filter(|(f, h)| before.get(*f) != Some(h))
        .map(|(f, _)| f)
        .collect();
    const SHOWN: usize = 8;
    let mut list: Vec<String> = changed.iter().take(SHOWN).map(|f| f.to_string()).collect();
    if changed.len() > SHOWN {
        list.push(format!("and {} more", changed.len() - SHOWN));
    }
    crate::errln!(
        "rmapgen: updated {} ({}) to the maps of scene {} (map_fit {}): {} files changed{}",
        p.display(),
        cfg.summary_full(),
        if scene.name.is_empty() {
            "(unnamed)"
        } else {
            &scene.name
        },
        scene.map_fit.name(),
        changed.len(),
        if list.is_empty() {
            String::new()
        } else {
            format!(" ({})", list.join(", "))
        }
    );
    Ok(())
}
