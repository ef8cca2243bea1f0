//! `rmapgen vectors`: a large top-level vector stream (`vectors/rmap_top.hex` format) for the
//! Verilator C++ harness `tb/top_stream.cpp`, which checks millions of samples per run.

use super::config_args::ConfigArgs;
use crate::output::StagedFile;
use crate::scene::Scene;
use crate::vectors::{self, MapSet};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct VectorsArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    /// Random vectors after the corner cases: the first half shaded with map 0, the rest with
    /// map 1 (the corner cases come again before the map-1 part).
    #[arg(long, value_name = "N", default_value_t = 1_000_000)]
    pub count: usize,
    /// Seed of the random vectors.
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Take the maps from a generated directory (map_<axis>.hex and map2_<axis>.hex), so the
    /// vectors match the scene it was generated with.
    #[arg(long, value_name = "DIR", conflicts_with = "scene")]
    pub maps: Option<PathBuf>,
    /// Scene of map 0 [default: the standard scene]; map 1 is always the alternate scene.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Vector file to write (replaced only when complete).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

pub fn run(a: &VectorsArgs) -> Result<()> {
    let cfg = a.cfg.resolve()?;
    let maps = match (&a.maps, &a.scene) {
        (Some(dir), _) => MapSet::from_dir(&cfg, dir)?,
        (None, Some(p)) => {
            MapSet::from_scenes(&cfg, &Scene::from_toml_file(p)?, &Scene::alternate())
        }
        (None, None) => MapSet::standard(&cfg),
    };
    let policy = a.force.policy(&[
        a.cfg.config.as_deref(),
        a.scene.as_deref(),
        a.maps.as_deref(),
    ]);
    let out = StagedFile::new(&a.out, &policy, vectors::is_vector_stream)?;
    let n = vectors::write_top_stream(&cfg, &maps, out.path(), a.count, a.seed)?;
    out.commit()?;
    eprintln!(
        "rmapgen: wrote {n} top vectors ({}) to {}",
        cfg.summary(),
        a.out.display()
    );
    Ok(())
}
