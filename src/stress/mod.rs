//! Stress runs of the model: every gradient of a configuration (`exhaustive`, 2^36 for the
//! default 12-bit design) or a seeded sample sweeping every magnitude (`sampled`), reporting
//! the worst angular error of the encoded direction, the worst intensity error against the
//! float reference, and where they lie, per magnitude class.
//!
//! Definitions used throughout:
//! - **magnitude class**: the shift amount of sort & shift, grad_bits - 1 - floor(log2 M) for
//!   the largest magnitude M (class 0 is M = 2^(G-1), the most negative value; the last class
//!   is M = 1).
//! - **encoded direction**: the direction the map entries interpolate to at the positions
//!   (p_u, p_v) the pipeline computes. A position p stands for the tangent
//!   tan(p / pos_max * 45 degrees) with distortion compensation (entries sit at equal angles)
//!   and p / pos_max without (entries sit at equal tangents); the direction is
//!   (±1, ±t(p_u), ±t(p_v)) on the max axis's face, with the sample's signs.
//! - **angular error**: the angle between the encoded direction and the gradient.
//! - **intensity error**: model - reference, in output LSBs, where the reference is
//!   [`Reference::intensity`] (the light model at the float-normalised gradient, quantised).

pub mod exhaustive;
pub mod interval;

use crate::config::Config;
use crate::model::fast::FastShader;
use crate::model::{Maps, Model};
use crate::reference::Reference;
use crate::rng::SplitMix64;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

/// Everything a stress run shades with.
pub struct Setup {
    pub cfg: Config,
    pub model: Model,
    pub maps: Maps,
    pub fast: FastShader,
    pub reference: Reference,
    pub scene: Scene,
    /// The tangent each position of a component stands for ([`position_tangents`]).
    pub tangents: Vec<f64>,
}

impl Setup {
    pub fn new(cfg: &Config, scene: &Scene, maps: Maps) -> Setup {
        let model = Model::new(cfg);
        let fast = FastShader::new(&model, &maps);
        Setup {
            cfg: cfg.clone(),
            reference: Reference::new(cfg, scene),
            tangents: position_tangents(&model, &maps),
            model,
            maps,
            fast,
            scene: scene.clone(),
        }
    }
}

/// The tangent (component / max) each position 0..=pos_max of a component stands for, which
/// the angular error is measured from. With the compensation ROM (or none) it is the
/// encoding's own, [`encoded_tangent`]. A compensation table loaded with the maps
/// (`comp_table = ram`) places the positions where the scene needs them, so a position stands
/// for the tangents the pipeline maps to it through that table: the middle of their range
/// (found by [`MinimaxFit::for_model`](crate::model::map_fit::minimax::MinimaxFit::for_model),
/// as the fit finds it); a position no gradient reaches keeps [`encoded_tangent`] (nothing
/// reads it).
pub fn position_tangents(model: &Model, maps: &Maps) -> Vec<f64> {
    let cfg = &model.cfg;
    let encoded = |p: u32| encoded_tangent(cfg, p);
    let Some(table) = &maps.table else {
        return (0..=cfg.pos_max()).map(encoded).collect();
    };
    let mut loaded = model.clone();
    loaded.atan = Some(table.clone());
    let fit = crate::model::map_fit::minimax::MinimaxFit::for_model(&loaded);
    fit.ranges()
        .iter()
        .zip(0..)
        .map(|(r, p)| r.map_or_else(|| encoded(p), |(lo, hi)| (lo + hi) / 2.0))
        .collect()
}

/// The magnitude class (sort & shift's shift) of a largest magnitude `max` >= 1.
pub fn class_of(cfg: &Config, max: u32) -> u32 {
    debug_assert!(max >= 1 && max <= 1 << (cfg.grad_bits - 1));
    max.leading_zeros() - (32 - cfg.grad_bits)
}

/// Number of magnitude classes: one per shift amount 0..grad_bits - 1.
pub fn classes(cfg: &Config) -> u32 {
    cfg.grad_bits
}

/// Largest magnitudes of a class, inclusive.
pub fn class_range(cfg: &Config, class: u32) -> (u32, u32) {
    let top = cfg.grad_bits - 1 - class;
    if class == 0 {
        (1 << top, 1 << top)
    } else {
        (1 << top, (1 << (top + 1)) - 1)
    }
}

/// The tangent a map position stands for (see the module documentation).
pub fn encoded_tangent(cfg: &Config, p: u32) -> f64 {
    crate::geometry::face_tangent(cfg.compensation, p as f64 / cfg.pos_max() as f64)
}

/// The encoded direction (unit) of a sample with these sort results and positions, each
/// position standing for `tangents[p]` ([`position_tangents`]).
pub fn encoded_direction(
    tangents: &[f64],
    axis: u32,
    signs: (u32, u32, u32),
    p_u: u32,
    p_v: u32,
) -> DVec3 {
    let sg = |s: u32, t: f64| if s == 1 { -t } else { t };
    let [x, y, z] = crate::geometry::place(
        axis,
        sg(signs.0, 1.0),
        sg(signs.1, tangents[p_u as usize]),
        sg(signs.2, tangents[p_v as usize]),
    );
    DVec3::new(x, y, z).normalize()
}

/// Angle between two directions in degrees, accurate for small angles.
pub fn angle_deg(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// The largest angular error found, and where.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WorstAngle {
    pub degrees: f64,
    pub gradient: [i32; 3],
}

/// The largest |model - reference| found, and where.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WorstError {
    /// model - reference, in output LSBs.
    pub error: i64,
    pub gradient: [i32; 3],
    pub model: u32,
    pub reference: u32,
    /// The unquantised reference in output LSBs.
    pub reference_exact: f64,
}

impl WorstError {
    pub fn abs(&self) -> u64 {
        self.error.unsigned_abs()
    }
}

/// Results of one magnitude class.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClassStats {
    /// The shift amount of sort & shift.
    pub shift: u32,
    /// Largest magnitudes in the class, inclusive.
    pub magnitudes: (u32, u32),
    /// Gradients evaluated in the class.
    pub inputs: u64,
    pub worst_angle: Option<WorstAngle>,
    pub worst_error: Option<WorstError>,
    /// Outputs at 0 and at full scale (2^map_bits - 1).
    pub outputs_zero: u64,
    pub outputs_full: u64,
}

/// What a stress run found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// "exhaustive" or "sampled".
    pub mode: String,
    pub config: Config,
    /// How the maps were filled.
    pub map_fit: crate::model::map_fit::MapFit,
    /// Gradients evaluated, the zero gradient included.
    pub inputs: u64,
    /// Inputs on which two bit-exact evaluations disagreed (must be 0): the fast path against
    /// `Model::intensity` (sampled), or the sort & shift stage against the enumeration and the
    /// fast path against the factored model (exhaustive).
    pub mismatches: u64,
    /// The first disagreeing gradient, if any.
    pub first_mismatch: Option<[i32; 3]>,
    /// Whether the run was built with overflow checks (the dev and test profiles).
    pub overflow_checks: bool,
    pub worst_angle: Option<WorstAngle>,
    pub worst_error: Option<WorstError>,
    pub classes: Vec<ClassStats>,
    /// Exhaustive runs only: how the intensity error was found (see [`exhaustive`]).
    pub search: Option<exhaustive::error_search::SearchStats>,
    pub seconds: f64,
}

impl Report {
    /// The largest |model - reference| in LSBs (0 when no input was compared).
    pub fn max_abs_error(&self) -> u64 {
        self.worst_error.map_or(0, |w| w.abs())
    }
    /// The largest angular error in degrees.
    pub fn max_angle_deg(&self) -> f64 {
        self.worst_angle.map_or(0.0, |w| w.degrees)
    }
}

/// Per-class running maxima, merged across threads. Ties keep the smaller `key` so results do
/// not depend on scheduling.
#[derive(Clone, Debug)]
pub(crate) struct ClassAcc {
    pub inputs: u64,
    pub angle: Option<(f64, u64, [i32; 3])>,
    pub error: Option<(u64, u64, WorstError)>,
    pub zero: u64,
    pub full: u64,
}

impl ClassAcc {
    pub fn new() -> ClassAcc {
        ClassAcc {
            inputs: 0,
            angle: None,
            error: None,
            zero: 0,
            full: 0,
        }
    }

    pub fn angle(&mut self, deg: f64, key: u64, g: [i32; 3]) {
        if self
            .angle
            .is_none_or(|(d, k, _)| deg > d || (deg == d && key < k))
        {
            self.angle = Some((deg, key, g));
        }
    }

    pub fn error(&mut self, w: WorstError, key: u64) {
        if self
            .error
            .is_none_or(|(a, k, _)| w.abs() > a || (w.abs() == a && key < k))
        {
            self.error = Some((w.abs(), key, w));
        }
    }

    pub fn merge(mut self, o: ClassAcc) -> ClassAcc {
        self.inputs += o.inputs;
        self.zero += o.zero;
        self.full += o.full;
        if let Some((d, k, g)) = o.angle {
            self.angle(d, k, g);
        }
        if let Some((_, k, w)) = o.error {
            self.error(w, k);
        }
        self
    }
}

/// Per-class accumulators plus the mismatch count.
#[derive(Clone, Debug)]
pub(crate) struct Acc {
    pub classes: Vec<ClassAcc>,
    pub mismatches: u64,
    pub first_mismatch: Option<(u64, [i32; 3])>,
}

impl Acc {
    pub fn new(cfg: &Config) -> Acc {
        Acc {
            classes: vec![ClassAcc::new(); classes(cfg) as usize],
            mismatches: 0,
            first_mismatch: None,
        }
    }

    pub fn mismatch(&mut self, key: u64, g: [i32; 3]) {
        self.mismatches += 1;
        if self.first_mismatch.is_none_or(|(k, _)| key < k) {
            self.first_mismatch = Some((key, g));
        }
    }

    pub fn merge(mut self, o: Acc) -> Acc {
        self.classes = self
            .classes
            .into_iter()
            .zip(o.classes)
            .map(|(a, b)| a.merge(b))
            .collect();
        self.mismatches += o.mismatches;
        if let Some((k, g)) = o.first_mismatch {
            if self.first_mismatch.is_none_or(|(kk, _)| k < kk) {
                self.first_mismatch = Some((k, g));
            }
        }
        self
    }

    /// The report of these accumulators; `extra_inputs` counts inputs outside every class
    /// (the zero gradient).
    pub fn report(self, cfg: &Config, mode: &str, extra_inputs: u64, seconds: f64) -> Report {
        let classes: Vec<ClassStats> = self
            .classes
            .iter()
            .enumerate()
            .map(|(c, a)| ClassStats {
                shift: c as u32,
                magnitudes: class_range(cfg, c as u32),
                inputs: a.inputs,
                worst_angle: a.angle.map(|(d, _, g)| WorstAngle {
                    degrees: d,
                    gradient: g,
                }),
                worst_error: a.error.map(|(_, _, w)| w),
                outputs_zero: a.zero,
                outputs_full: a.full,
            })
            .collect();
        // Overall worst: the largest over classes, ties to the largest magnitudes.
        let worst_angle =
            classes
                .iter()
                .filter_map(|c| c.worst_angle)
                .fold(None, |b: Option<WorstAngle>, w| {
                    if b.is_none_or(|b| w.degrees > b.degrees) {
                        Some(w)
                    } else {
                        b
                    }
                });
        let worst_error =
            classes
                .iter()
                .filter_map(|c| c.worst_error)
                .fold(None, |b: Option<WorstError>, w| {
                    if b.is_none_or(|b| w.abs() > b.abs()) {
                        Some(w)
                    } else {
                        b
                    }
                });
        Report {
            mode: mode.to_string(),
            config: cfg.clone(),
            map_fit: Default::default(),
            inputs: classes.iter().map(|c| c.inputs).sum::<u64>() + extra_inputs,
            mismatches: self.mismatches,
            first_mismatch: self.first_mismatch.map(|(_, g)| g),
            overflow_checks: cfg!(debug_assertions),
            worst_angle,
            worst_error,
            classes,
            search: None,
            seconds,
        }
    }
}

/// The `i`-th gradient of a sampled run. The largest magnitude sweeps 1, 2, ...,
/// 2^(G-1) with `i`, so every magnitude (and so every shift amount) appears once per
/// 2^(G-1) samples; its axis and the two other magnitudes (0..=max, with 0 and max
/// itself, i.e. ties, made likely) and the signs are random. A magnitude of 2^(G-1) is the
/// most negative value and so always negative; a zero component is never negative.
pub fn sample_gradient(cfg: &Config, rng: &mut SplitMix64, i: u64) -> [i32; 3] {
    let full = 1u64 << (cfg.grad_bits - 1);
    let max = 1 + i % full;
    let axis = rng.below(3) as usize;
    let mut g = [0i32; 3];
    for (k, c) in g.iter_mut().enumerate() {
        let mag = if k == axis {
            max
        } else {
            match rng.below(16) {
                0 => 0,
                1 => max,
                _ => rng.range(0, max),
            }
        };
        let negative = mag == full || (mag != 0 && rng.chance(1, 2));
        *c = if negative { -(mag as i32) } else { mag as i32 };
    }
    g
}

/// Samples per parallel task of a sampled run; each task has its own random stream, so the
/// result depends only on (configuration, maps, samples, seed).
const SAMPLE_CHUNK: u64 = 1 << 15;

/// Shades `samples` gradients from [`sample_gradient`] with the model (every stage,
/// `Model::trace`), the fast path and the reference, and measures both errors.
/// Largest sampled run (`stress --samples`): 2^37 = 137 438 953 472 gradients, about 19 hours
/// at the measured 2 million samples/s on 2 cores; twice the 2^36 inputs a 12-bit
/// `--exhaustive` run covers exactly.
pub const MAX_SAMPLES: u64 = 1 << 37;

/// Refuses a sample count of 0 (no input checked is not a clean run) or above
/// [`MAX_SAMPLES`].
pub fn check_samples(samples: u64) -> anyhow::Result<()> {
    anyhow::ensure!(
        samples > 0,
        "--samples 0 checks nothing; give 1..={MAX_SAMPLES} (or --exhaustive)"
    );
    anyhow::ensure!(
        samples <= MAX_SAMPLES,
        "--samples {samples} is more than the limit of {MAX_SAMPLES} (about 19 hours at 2 million a second); use --exhaustive for every input of grad-bits <= 12"
    );
    Ok(())
}

pub fn sampled(setup: &Setup, samples: u64, seed: u64) -> Report {
    sampled_with_progress(setup, samples, seed, &|_| {})
}

/// [`sampled`], calling `progress(n)` as every `n` more samples are done.
pub fn sampled_with_progress(
    setup: &Setup,
    samples: u64,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Report {
    assert!(
        samples <= MAX_SAMPLES,
        "sample count checked by check_samples"
    );
    let start = std::time::Instant::now();
    let cfg = &setup.cfg;
    let tasks = samples.div_ceil(SAMPLE_CHUNK);
    let acc = (0..tasks)
        .into_par_iter()
        .map(|t| {
            let mut rng = SplitMix64::for_stream(seed, &format!("stress sample task {t}"));
            let mut acc = Acc::new(cfg);
            for i in t * SAMPLE_CHUNK..samples.min((t + 1) * SAMPLE_CHUNK) {
                let g = sample_gradient(cfg, &mut rng, i);
                let tr = setup.model.trace(&setup.maps, g, [0; 3]);
                let out = tr.out.intensity;
                if setup.fast.shade(g) != out || out > cfg.map_max() {
                    acc.mismatch(i, g);
                }
                let s = &tr.sort;
                let class = &mut acc.classes[s.shift as usize];
                class.inputs += 1;
                class.zero += (out == 0) as u64;
                class.full += (out == cfg.map_max()) as u64;
                let dir = encoded_direction(
                    &setup.tangents,
                    s.axis,
                    (s.s_max, s.s_u, s.s_v),
                    tr.p_u,
                    tr.p_v,
                );
                let gv = DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64).normalize();
                class.angle(angle_deg(dir, gv), i, g);
                let exact = setup
                    .reference
                    .exact(g)
                    .expect("sampled gradients are never zero");
                // Reference::intensity is exactly this quantisation of Reference::exact.
                let reference = crate::model::reflectance_map::quantise(cfg, exact);
                let w = WorstError {
                    error: out as i64 - reference as i64,
                    gradient: g,
                    model: out,
                    reference,
                    reference_exact: exact * cfg.map_max() as f64,
                };
                class.error(w, i);
            }
            progress(samples.min((t + 1) * SAMPLE_CHUNK) - t * SAMPLE_CHUNK);
            acc
        })
        .reduce(|| Acc::new(cfg), Acc::merge);
    let mut r = acc.report(cfg, "sampled", 0, start.elapsed().as_secs_f64());
    r.map_fit = setup.scene.map_fit;
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_cover_every_magnitude_once() {
        let cfg = Config::default();
        let mut next = 1;
        for c in (0..classes(&cfg)).rev() {
            let (lo, hi) = class_range(&cfg, c);
            assert_eq!(lo, next);
            for m in lo..=hi {
                assert_eq!(class_of(&cfg, m), c);
                assert_eq!(
                    crate::model::sort_shift::eval(&cfg, [-(m as i32), 0, 0]).shift,
                    c
                );
            }
            next = hi + 1;
        }
        assert_eq!(next, 2049);
    }

    #[test]
    fn encoded_tangents_hit_the_entries() {
        for cfg in [
            Config::default(),
            Config {
                compensation: false,
                ..Config::default()
            },
        ] {
            for i in 0..cfg.entries() {
                let t = encoded_tangent(&cfg, i * cfg.step());
                let e = crate::model::reflectance_map::entry_tangent(&cfg, i);
                assert!((t - e).abs() < 1e-12, "{i}: {t} {e}");
            }
        }
    }

    #[test]
    fn samples_sweep_every_magnitude_in_range() {
        let cfg = Config {
            grad_bits: 9,
            red_bits: 8,
            ..Config::default()
        };
        let mut rng = SplitMix64::new(3);
        let mut seen = vec![false; 257];
        for i in 0..512 {
            let g = sample_gradient(&cfg, &mut rng, i);
            assert!(
                g.iter()
                    .all(|&c| crate::model::sort_shift::in_range(&cfg, c)),
                "{g:?}"
            );
            seen[g.iter().map(|c| c.unsigned_abs()).max().unwrap() as usize] = true;
        }
        assert!(seen[1..].iter().all(|&s| s));
    }
}
