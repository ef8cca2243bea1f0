//! How one sample is shaded ([`Shader`]): the float reference, or the bit-accurate model
//! with a scene's maps ([`ModelShader`]). Separate from the caster, which takes any shader.

use crate::config::Config;
use crate::model::fast::FastShader;
use crate::model::{Maps, Model};
use crate::reference::Reference;
use crate::scene::Scene;

/// One sample's shading: a G-bit gradient in, an M-bit intensity out.
pub trait Shader: Sync {
    fn intensity(&self, g: [i32; 3]) -> u32;
}

impl Shader for Reference {
    #[inline]
    fn intensity(&self, g: [i32; 3]) -> u32 {
        Reference::intensity(self, g)
    }
}

/// The bit-accurate model with a scene's maps. Shades through the model's fused-table path
/// ([`FastShader`], equal to [`Model::intensity`] by construction and by its tests; the
/// tests here check it again on rendered samples through the batch path).
pub struct ModelShader {
    pub model: Model,
    pub maps: Maps,
    fast: FastShader,
}

impl ModelShader {
    pub fn new(cfg: &Config, scene: &Scene) -> ModelShader {
        let model = Model::new(cfg);
        let maps = scene.maps(cfg);
        let fast = FastShader::new(&model, &maps);
        ModelShader { model, maps, fast }
    }

    /// The shader for another scene (a new frame): its maps and the fused intensity table,
    /// keeping the configuration's model and position table (they do not depend on the
    /// scene). Equal to `ModelShader::new(cfg, scene)`.
    pub fn set_scene(&mut self, scene: &Scene) {
        self.set_scene_for(scene, usize::MAX);
    }

    /// [`ModelShader::set_scene`] for a frame of about `samples` shaded samples (e.g. the
    /// previous frame's): the fused intensity table is built only when it is no larger than
    /// that ([`FastShader::set_maps_for`]); the intensities are the same either way.
    pub fn set_scene_for(&mut self, scene: &Scene, samples: usize) {
        self.maps = scene.maps(&self.model.cfg);
        self.fast.set_maps_for(&self.maps, samples);
    }
}

impl Shader for ModelShader {
    #[inline]
    fn intensity(&self, g: [i32; 3]) -> u32 {
        self.fast.shade(g)
    }
}
