//! The float reference every error is measured against: the scene's light model evaluated
//! directly at the float-normalised gradient (f64), with no cube, ROM or map in between, then
//! quantised to `map_bits` by the same [`reflectance_map::quantise`] that fills the maps, so
//! the model and the reference differ only by what the pipeline does.
//!
//! A zero gradient has no direction: like the model, the reference gives intensity 0 and sets
//! the zero flag.

use crate::config::Config;
use crate::model::reflectance_map;
use crate::scene::{PreparedScene, Scene};
use glam::DVec3;
use rayon::prelude::*;

/// One reference sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Sample {
    /// Set for an all-zero gradient; the intensity is then 0.
    pub zero: bool,
    /// The light model quantised to `map_bits`.
    pub intensity: u32,
}

/// The float reference of one configuration (for its output width) and one scene.
#[derive(Clone, Debug)]
pub struct Reference {
    cfg: Config,
    scene: PreparedScene,
}

impl Reference {
    pub fn new(cfg: &Config, scene: &Scene) -> Reference {
        Reference {
            cfg: cfg.clone(),
            scene: scene.prepared(),
        }
    }

    /// The unquantised, unclamped light model at the gradient's direction; `None` for a zero
    /// gradient.
    #[inline]
    pub fn exact(&self, g: [i32; 3]) -> Option<f64> {
        let n = crate::geometry::unit_direction(DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64))?;
        Some(self.scene.shade(n))
    }

    /// The reference output of one gradient.
    #[inline]
    pub fn shade(&self, g: [i32; 3]) -> Sample {
        match self.exact(g) {
            None => Sample {
                zero: true,
                intensity: 0,
            },
            Some(i) => Sample {
                zero: false,
                intensity: reflectance_map::quantise(&self.cfg, i),
            },
        }
    }

    /// The reference intensity of one gradient.
    #[inline]
    pub fn intensity(&self, g: [i32; 3]) -> u32 {
        self.shade(g).intensity
    }

    /// Intensities of many gradients, in order, in parallel.
    pub fn intensities(&self, gradients: &[[i32; 3]]) -> Vec<u32> {
        gradients.par_iter().map(|&g| self.intensity(g)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_gradient_is_flagged_and_dark() {
        let r = Reference::new(&Config::default(), &Scene::standard());
        assert_eq!(
            r.shade([0, 0, 0]),
            Sample {
                zero: true,
                intensity: 0
            }
        );
        assert_eq!(r.exact([0, 0, 0]), None);
    }

    #[test]
    fn length_does_not_matter_and_matches_the_scene() {
        let cfg = Config::default();
        let scene = Scene::standard();
        let r = Reference::new(&cfg, &scene);
        // Facing the light: the scene's own model, quantised once.
        let want =
            reflectance_map::quantise(&cfg, scene.shade(DVec3::new(1.0, 1.0, 2.0).normalize()));
        for k in [1, 3, 100, 1000] {
            assert_eq!(r.intensity([k, k, 2 * k]), want, "length {k}");
        }
        // Facing away: ambient only.
        assert_eq!(
            r.intensity([-5, -5, -10]),
            reflectance_map::quantise(&cfg, scene.material.ambient)
        );
    }

    #[test]
    fn batch_equals_single() {
        let cfg = Config {
            map_bits: 10,
            ..Config::default()
        };
        let r = Reference::new(&cfg, &Scene::alternate());
        let gs: Vec<[i32; 3]> = (-40..40)
            .map(|i| [i * 37 % 2048, -i * 11, 1000 - i * i])
            .collect();
        let batch = r.intensities(&gs);
        assert!(gs.iter().zip(&batch).all(|(&g, &b)| r.intensity(g) == b));
        assert!(
            batch.iter().any(|&b| b > 255),
            "10-bit output range is used"
        );
    }
}
