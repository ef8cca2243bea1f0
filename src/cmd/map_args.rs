//! The map flags shared by every command that builds maps (generate, roms, render, volume,
//! stress, bench, fit, vectors, maps): which scene's light model fills the maps (`--scene`)
//! and how (`--map-fit`). Defined once here and applied in one function, [`MapArgs::scene`],
//! so a flag means the same on every command.

use crate::model::map_fit::MapFit;
use crate::scene::Scene;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Clone, Default)]
pub struct MapArgs {
    /// Scene (TOML) whose light model fills the maps [default: the standard scene
    /// (scenes/standard.toml); volume: the engine block scene (scenes/engine.toml)].
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// How the maps are filled from the light model: sample (the light model at each entry's
    /// direction), lsq (least squares over a dense grid, with peak refinement), lsq-plain
    /// (without it), minimax (the smallest largest error over every direction; a third of a
    /// second a frame), table (the compensation table fitted with minimax maps; needs
    /// --comp-table ram; seconds a frame) [default: the scene's `map_fit`, else sample].
    #[arg(long, value_enum, value_name = "FIT")]
    pub map_fit: Option<MapFit>,
}

impl MapArgs {
    /// The scene these flags select, `--scene` or else `default()`, with `--map-fit` applied.
    pub fn scene_or(&self, default: impl FnOnce() -> Result<Scene>) -> Result<Scene> {
        let mut scene = match &self.scene {
            Some(p) => Scene::from_toml_file(p)?,
            None => default()?,
        };
        self.apply(&mut scene);
        Ok(scene)
    }

    /// [`MapArgs::scene_or`] with the standard scene as the default.
    pub fn scene(&self) -> Result<Scene> {
        self.scene_or(|| Ok(Scene::standard()))
    }

    /// [`MapArgs::scene`] for the design `cfg`: refused when its `map_fit` makes what the
    /// design cannot hold (`table` without `comp_table = ram`).
    pub fn scene_for(&self, cfg: &crate::config::Config) -> Result<Scene> {
        let scene = self.scene()?;
        scene.map_fit.check(cfg)?;
        Ok(scene)
    }

    /// Applies `--map-fit` to a scene the command chose itself (`bench`'s own scenes).
    pub fn apply(&self, scene: &mut Scene) {
        if let Some(f) = self.map_fit {
            scene.map_fit = f;
        }
    }

    /// The scene file, an input of the command (its output may not replace it).
    pub fn input(&self) -> Option<&Path> {
        self.scene.as_deref()
    }
}
