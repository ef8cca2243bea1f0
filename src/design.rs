//! A design's data, built once: the validated configuration with its ROM tables (the
//! [`Model`]) and the two map buffers ([`MapSet`]: the scene's map, which the design holds
//! from configuration, and the second map the testbenches load through the host port). The
//! Verilog, the init files, the vectors and the testbenches are all written from this one
//! value, so none of them recomputes a table or a map.

use crate::config::Config;
use crate::model::{MapSet, Model};
use crate::scene::Scene;
use anyhow::Result;

pub struct Design {
    pub model: Model,
    pub maps: MapSet,
    /// The scene of buffer 0 (its name and light model, with the `map_fit` that filled the
    /// map), for the generated README.
    pub scene: Scene,
}

impl Design {
    /// `scene`'s map in buffer 0, the alternate scene's in buffer 1.
    pub fn for_scene(cfg: &Config, scene: &Scene) -> Result<Design> {
        cfg.validate()?;
        scene.map_fit.check(cfg)?;
        Ok(Design {
            model: Model::new(cfg),
            maps: MapSet::from_scenes(cfg, scene, &Scene::alternate()),
            scene: scene.clone(),
        })
    }

    /// The standard scene's design.
    pub fn standard(cfg: &Config) -> Result<Design> {
        Design::for_scene(cfg, &Scene::standard())
    }

    pub fn cfg(&self) -> &Config {
        &self.model.cfg
    }
}
