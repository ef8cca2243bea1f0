//! A whole design directory: everything `generate` writes for one configuration and scene
//! (the design of [`super::write_design`], the vectors and the testbenches), staged and
//! committed whole. `generate`, `fit`, `roms --update` and the grid runs write through here.

use super::manifest::VectorsInfo;
use super::{tb, Manifest};
use crate::config::Config;
use crate::design::Design;
use crate::design_dir::DesignDir;
use crate::grid::GridRow;
use crate::output::{Policy, StagedDir};
use crate::scene::Scene;
use crate::vectors;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Seeded random vectors per stage by default (`--vectors`).
pub const DEFAULT_VECTORS: usize = 2000;
/// Seed of the random vectors by default (`--seed`).
pub const DEFAULT_SEED: u64 = 1;

/// What [`write_dir`] keeps of an existing directory it replaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// The directory is replaced whole.
    Nothing,
    /// The files rmapgen wrote there before and does not write now (`fit.json` of a design
    /// `fit` chose) are kept: `roms --update`.
    Others,
}

/// Everything `generate` writes for one validated configuration and scene, into `out`
/// (replaced as `policy` allows, keeping what `keep` says; untouched on failure), plus
/// `extra` files (relative name, text) beside them. `rmapgen fit` writes its chosen design
/// through this too, and `roms --update` writes a design again for new maps. Returns the
/// directory and the manifest.
pub fn write_dir(
    cfg: &Config,
    scene: &Scene,
    out: &Path,
    policy: &Policy,
    vectors: VectorsInfo,
    extra: &[(String, String)],
    keep: Keep,
) -> Result<(PathBuf, Manifest)> {
    let out = StagedDir::new(out, policy)?;
    // Built once: the design's init files and the vectors see the same maps, this scene's
    // and the alternate scene's that testbenches load through the host port.
    let design = Design::for_scene(cfg, scene)?;
    let manifest = super::write_design(&design, &out, Some(vectors))?;
    vectors::write_all(&design, &out, vectors.random, vectors.seed)?;
    tb::write_all(&design, &out)?;
    for (name, text) in extra {
        out.write_text(name, text)?;
    }
    if keep == Keep::Others {
        out.keep_others()?;
    }
    Ok((out.commit()?, manifest))
}

/// A grid row's design (the standard scene, `generate`'s default vectors) written into `dir`.
pub fn write_row(r: &GridRow, dir: &Path, policy: &Policy) -> Result<DesignDir> {
    let (dir, _) = write_dir(
        &r.config,
        &Scene::standard(),
        dir,
        policy,
        VectorsInfo {
            random: DEFAULT_VECTORS,
            seed: DEFAULT_SEED,
        },
        &[],
        Keep::Nothing,
    )?;
    DesignDir::open(&dir)
}
