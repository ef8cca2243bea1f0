//! `rmapgen generate`: the Verilog of one configuration, its ROM and map init files, the
//! manifest, the per-stage test vectors and the testbenches, in one directory that appears
//! whole or not at all.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design_dir::DesignDir;
use crate::emit::dir::{write_dir, Keep, DEFAULT_SEED, DEFAULT_VECTORS};
use crate::emit::manifest::VectorsInfo;
use crate::vectors;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

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
