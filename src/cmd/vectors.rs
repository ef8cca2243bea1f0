//! `rmapgen vectors`: a large top-level vector stream (`vectors/rmap_top.hex` format) for the
//! Verilator C++ harness `tb/top_stream.cpp`, which checks millions of samples per run.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design_dir::DesignDir;
use crate::output::StagedFile;
use crate::scene::Scene;
use crate::vectors::{self, MapSet};
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct VectorsArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    /// Random vectors after the corner cases: the first half shaded with map 0, the rest with
    /// map 1 (the corner cases come again before the map-1 part) [0..=10000000000; the file
    /// must also fit the free space of its filesystem].
    #[arg(long, value_name = "N", default_value_t = 1_000_000)]
    pub count: usize,
    /// Seed of the random vectors.
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Take the maps from a directory (`<prefix>map_<axis>.hex` and `<prefix>map2_<axis>.hex`),
    /// so the vectors match the scene it was generated with. A generated design's
    /// configuration comes from its manifest.json (configuration flags may only agree with
    /// it); a directory of map files alone takes the configuration of the flags.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "map_fit"])]
    pub maps: Option<PathBuf>,
    /// The scene and fit of map 0; map 1 is always the alternate scene's
    /// (scenes/two_lights.toml).
    #[command(flatten)]
    pub map: MapArgs,
    /// Vector file to write (replaced only when complete).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

pub fn run(a: &VectorsArgs) -> Result<()> {
    // With --maps DIR of a generated design (it has a manifest) the design's configuration,
    // which the flags may only agree with; a directory of map files alone takes the flags'.
    let cfg = match &a.maps {
        Some(dir) if dir.join(crate::emit::manifest::FILE).is_file() => {
            a.cfg.for_design(&DesignDir::open(dir)?.config, dir)?
        }
        _ => a.cfg.resolve()?,
    };
    vectors::check_stream_vectors(a.count as u64)?;
    let maps = match &a.maps {
        Some(dir) => MapSet::from_dir(&cfg, dir)?,
        None => MapSet::from_scenes(&cfg, &a.map.scene_for(&cfg)?, &Scene::alternate()),
    };
    let policy = a
        .force
        .policy(&[a.cfg.config.as_deref(), a.map.input(), a.maps.as_deref()]);
    let out = StagedFile::new(&a.out, &policy)?;
    // The whole file must fit before the first byte is written (its size is exact: every
    // line has the same length).
    let need = vectors::top_stream_bytes(&cfg, a.count as u64);
    crate::disk::check_space(
        out.path().parent().unwrap_or(Path::new(".")),
        need,
        &format!("--count {}: {}", a.count, a.out.display()),
    )?;
    let bar = super::progress::Progress::total(
        "vectors",
        vectors::top_stream_lines(&cfg, a.count as u64),
        "vectors",
    );
    let written =
        vectors::write_top_stream_with_progress(&cfg, &maps, out.path(), a.count, a.seed, &|k| {
            bar.inc(k)
        });
    drop(bar);
    let n = written.map_err(|e| out.name_target(e))?;
    out.commit()?;
    crate::errln!(
        "rmapgen: wrote {n} top vectors ({}) to {}",
        cfg.summary(),
        a.out.display()
    );
    Ok(())
}
