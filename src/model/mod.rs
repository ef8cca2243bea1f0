//! The bit-accurate model: one module per pipeline stage, each a pure function on integers
//! of its hardware widths. [`Model::trace`] runs a sample through every stage and keeps every
//! intermediate value (the per-stage test vectors are written from it); [`Model::shade`] is
//! the same computation returning only the output.

pub mod fast;
pub mod map_addr;
pub mod map_fit;
pub mod map_set;
pub mod reflectance_map;

// Each stage's bit-accurate model lives in its stage folder, beside its Verilog template and
// its vectors (src/stages/<stage>/model.rs); these names make it read as one pipeline here.
pub use crate::stages::atan_rom::model as atan_rom;
pub use crate::stages::color_mul::model as color_mul;
pub use crate::stages::interpolate::model as interpolate;
pub use crate::stages::linear_index::model as linear_index;
pub use crate::stages::map_lookup::model as map_lookup;
pub use crate::stages::normalise::model as normalise;
pub use crate::stages::recip_rom::model as recip_rom;
pub use crate::stages::sort_shift::model as sort_shift;
pub use crate::stages::zero_detect::model as zero_detect;

use crate::config::Config;
pub use map_set::MapSet;
pub use reflectance_map::Maps;

/// Another implementation of the shader, asked for the intensities of many gradients in one
/// batch (an RTL simulation streams them through the design); renders compare it with the
/// model pixel for pixel.
pub trait IntensitySource {
    fn intensities(&self, gradients: &[[i32; 3]]) -> anyhow::Result<Vec<u32>>;
}

/// The fixed ROMs of one configuration, built once.
#[derive(Clone, Debug)]
pub struct Model {
    pub cfg: Config,
    pub recip: Vec<u32>,
    /// Present only with distortion compensation.
    pub atan: Option<Vec<u32>>,
}

/// Every intermediate value of one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Trace {
    pub zero: bool,
    pub sort: sort_shift::SortShift,
    pub norm: normalise::Normalise,
    /// Positions after the atan ROM or the linear index.
    pub p_u: u32,
    pub p_v: u32,
    pub lookup: map_lookup::Lookup,
    /// Interpolated (or nearest) intensity before the zero flag is applied.
    pub interp: u32,
    pub out: Output,
}

/// What the pipeline delivers for one sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Output {
    /// Set for an all-zero gradient; intensity and colour are then 0.
    pub zero: bool,
    pub intensity: u32,
    /// Colour times intensity; [0; 3] when colour multiply is off.
    pub rgb: [u32; 3],
}

impl Model {
    /// Builds the ROMs for a configuration; panics if it has not been validated.
    pub fn new(cfg: &Config) -> Model {
        cfg.validate().expect("Model::new needs a validated Config");
        Model {
            cfg: cfg.clone(),
            recip: recip_rom::contents(cfg),
            atan: cfg.compensation.then(|| atan_rom::contents(cfg)),
        }
    }

    /// The position stage: atan ROM, or linear index without compensation. With `comp_table
    /// = ram` this is the table both buffers hold out of reset; [`Model::position_in`] reads
    /// a buffer's own.
    #[inline]
    pub fn position(&self, u: u32) -> u32 {
        match &self.atan {
            Some(rom) => rom[u as usize],
            None => linear_index::eval(&self.cfg, u),
        }
    }

    /// The position stage reading the compensation table of `maps`' buffer when it has one
    /// (`comp_table = ram`), else [`Model::position`].
    #[inline]
    pub fn position_in(&self, maps: &Maps, u: u32) -> u32 {
        match &maps.table {
            Some(t) => t[u as usize],
            None => self.position(u),
        }
    }

    /// What decides a sample's output: the zero flag, the face and quadrant (axis and the
    /// three signs) and the two fraction codes. Every stage after normalise is a function of
    /// it, whatever the tables and maps hold, so samples with one state have one output (the
    /// information bound of `fit` rests on this).
    #[inline]
    pub fn state(&self, g: [i32; 3]) -> u64 {
        let sort = sort_shift::eval(&self.cfg, g);
        let norm = normalise::eval(&self.cfg, &self.recip, sort.m, sort.a, sort.b);
        let head = (zero_detect::eval(g) as u64) << 5
            | (sort.axis as u64) << 3
            | (sort.s_max as u64) << 2
            | (sort.s_u as u64) << 1
            | sort.s_v as u64;
        head << 48 | (norm.u as u64) << 24 | norm.v as u64
    }

    /// Runs one sample through every stage. `rgb` is ignored when colour multiply is off.
    pub fn trace(&self, maps: &Maps, g: [i32; 3], rgb: [u32; 3]) -> Trace {
        let cfg = &self.cfg;
        let zero = zero_detect::eval(g);
        let sort = sort_shift::eval(cfg, g);
        let norm = normalise::eval(cfg, &self.recip, sort.m, sort.a, sort.b);
        let p_u = self.position_in(maps, norm.u);
        let p_v = self.position_in(maps, norm.v);
        let lookup = map_lookup::eval(
            cfg, maps, sort.axis, sort.s_max, sort.s_u, sort.s_v, p_u, p_v,
        );
        let interp = if cfg.interpolation {
            interpolate::eval(cfg, lookup.e, lookup.w_u, lookup.w_v)
        } else {
            lookup.e[0]
        };
        let intensity = if zero { 0 } else { interp };
        let rgb = if cfg.color {
            color_mul::eval(cfg, rgb, intensity)
        } else {
            [0; 3]
        };
        Trace {
            zero,
            sort,
            norm,
            p_u,
            p_v,
            lookup,
            interp,
            out: Output {
                zero,
                intensity,
                rgb,
            },
        }
    }

    /// The output of one sample.
    #[inline]
    pub fn shade(&self, maps: &Maps, g: [i32; 3], rgb: [u32; 3]) -> Output {
        self.trace(maps, g, rgb).out
    }

    /// Intensity only (no colour), the hot path of renders and benchmarks.
    #[inline]
    pub fn intensity(&self, maps: &Maps, g: [i32; 3]) -> u32 {
        self.trace(maps, g, [0; 3]).out.intensity
    }
}
