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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::CompTable;
    use crate::rng::SplitMix64;

    /// Gradients over the whole range, with the corners where the sort's rules act: zero,
    /// one component, ties, the most negative value.
    fn gradients(cfg: &Config, n: usize, seed: u64) -> Vec<[i32; 3]> {
        let half = 1i32 << (cfg.grad_bits - 1);
        let mut rng = SplitMix64::new(seed);
        let mut v = vec![
            [0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
            [-1, 0, 0],
            [0, 0, -1],
            [-half, -half, -half],
            [half - 1, -half, 3],
            [5, 5, 5],
            [-5, 5, -5],
        ];
        // Small gradients too: most of a face's states are reached only there.
        v.extend((0..n).map(|k| {
            let span = if k % 2 == 0 { 2 * half as u64 } else { 16 };
            [0; 3].map(|_| (rng.next_u64() % span) as i32 - (span / 2) as i32)
        }));
        v
    }

    /// `state` is the zero flag, the max axis, the three signs and the two fraction codes,
    /// packed where its documentation says; and samples of one state shade alike under any
    /// maps and any compensation table (what the information bound of `fit` assumes).
    #[test]
    fn a_state_holds_what_decides_the_output() {
        let configs = [
            Config::default(),
            Config {
                comp_table: CompTable::Ram,
                ..Config::default()
            },
            Config {
                compensation: false,
                interpolation: false,
                interp_bits: 0,
                ..Config::default()
            },
        ];
        for cfg in configs {
            let model = Model::new(&cfg);
            let grads = gradients(&cfg, 20_000, 3);
            let mut rng = SplitMix64::new(11);
            let maps: Vec<Maps> = (0..3)
                .map(|_| {
                    let data = (0..3 * cfg.map_entries())
                        .map(|_| (rng.next_u64() % (cfg.map_max() as u64 + 1)) as u32)
                        .collect();
                    let maps = Maps::from_data(&cfg, data);
                    match maps.table {
                        None => maps,
                        Some(_) => {
                            let table = (0..cfg.atan_entries())
                                .map(|_| (rng.next_u64() % (cfg.pos_max() as u64 + 1)) as u32)
                                .collect();
                            maps.with_table(&cfg, table).unwrap()
                        }
                    }
                })
                .collect();
            let mut seen = std::collections::HashMap::new();
            for &g in &grads {
                let t = model.trace(&maps[0], g, [0; 3]);
                let s = model.state(g);
                let fields = (
                    s >> 53,
                    (s >> 51) & 3,
                    [(s >> 50) & 1, (s >> 49) & 1, (s >> 48) & 1],
                    (s >> 24) & 0xff_ffff,
                    s & 0xff_ffff,
                );
                let want = (
                    t.zero as u64,
                    t.sort.axis as u64,
                    [t.sort.s_max, t.sort.s_u, t.sort.s_v].map(u64::from),
                    t.norm.u as u64,
                    t.norm.v as u64,
                );
                assert_eq!(fields, want, "{g:?} {}", cfg.summary());
                let out: Vec<u32> = maps.iter().map(|m| model.intensity(m, g)).collect();
                let first = seen.entry(s).or_insert((g, out.clone()));
                assert_eq!(first.1, out, "{:?} and {g:?} share state {s:#x}", first.0);
            }
            // The sample covers many states, and states that several gradients share.
            assert!(seen.len() > 5_000, "{} states", seen.len());
            assert!(seen.len() < grads.len() - 1_000, "{} states", seen.len());
        }
    }
}
