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
}

impl Design {
    /// Validates `cfg` and builds its tables; `maps` are the two buffers.
    pub fn new(cfg: &Config, maps: MapSet) -> Result<Design> {
        cfg.validate()?;
        Ok(Design {
            model: Model::new(cfg),
            maps,
        })
    }

    /// `scene`'s map in buffer 0, the alternate scene's in buffer 1.
    pub fn for_scene(cfg: &Config, scene: &Scene) -> Result<Design> {
        cfg.validate()?;
        Design::new(cfg, MapSet::from_scenes(cfg, scene, &Scene::alternate()))
    }

    /// The standard scene's design.
    pub fn standard(cfg: &Config) -> Result<Design> {
        Design::for_scene(cfg, &Scene::standard())
    }

    pub fn cfg(&self) -> &Config {
        &self.model.cfg
    }
}
