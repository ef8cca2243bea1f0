//! `rmapgen generate`: the Verilog of one configuration, its ROM and map init files, the
//! manifest, the per-stage test vectors and the testbenches, in one directory that appears
//! whole or not at all.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::config::Config;
use crate::design::Design;
use crate::design_dir::DesignDir;
use crate::emit::manifest::VectorsInfo;
use crate::emit::Manifest;
use crate::emit::{self, tb};
use crate::output::{Policy, StagedDir};
use crate::scene::Scene;
use crate::vectors;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct GenerateArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    #[command(flatten)]
    pub map: MapArgs,
    /// Output directory (replaced whole on success).
    #[arg(long, value_name = "DIR", default_value = "rtl_out")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
    /// Seeded random vectors per stage, after the hand-picked corner cases [0..=1000000].
    #[arg(long, value_name = "N", default_value_t = DEFAULT_VECTORS, value_parser = super::parse::count::<usize>())]
    pub vectors: usize,
    /// Seed of the random vectors.
    #[arg(long, value_name = "S", default_value_t = DEFAULT_SEED, value_parser = super::parse::at_least::<u64>(0))]
    pub seed: u64,
}

/// Seeded random vectors per stage by default (`--vectors`).
pub const DEFAULT_VECTORS: usize = 2000;
/// Seed of the random vectors by default (`--seed`).
pub const DEFAULT_SEED: u64 = 1;

pub fn run(a: &GenerateArgs) -> Result<()> {
    vectors::check_stage_vectors(a.vectors, "--vectors")?;
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene_for(&cfg)?;
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
    // A design already there: its configuration, to say what this run changes.
    let before = DesignDir::open(&a.out).ok().map(|d| d.config);
    let vectors = VectorsInfo {
        random: a.vectors,
        seed: a.seed,
    };
    let (p, manifest) = write_dir(&cfg, &scene, &a.out, &policy, vectors, &[], Keep::Nothing)?;
    let replaced = match before {
        Some(old) if old != cfg => format!(" (replacing a design of {})", old.fields()),
        _ => String::new(),
    };
    // The fields by their --config names, spelled out (rmapgen generate --help says each).
    crate::errln!(
        "rmapgen: wrote {}: {} modules, latency {} clocks, {} memory bits{replaced}\n  {}",
        p.display(),
        manifest.modules.len(),
        manifest.latency,
        manifest.memory_bits,
        cfg.fields()
    );
    Ok(())
}

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
    let manifest = emit::write_design(&design, &out, Some(vectors))?;
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
