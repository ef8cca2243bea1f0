//! Orthographic ray casting with trilinear sampling and front-to-back compositing.
//!
//! **Samples.** Every ray is sampled at the same distances from the image plane, t = m h
//! for integers m (h = `step` times the smallest voxel spacing), inside the volume's box
//! (voxel centres 0..=n-1 along each axis): all rays sample the same planes. At each sample
//! the value is interpolated trilinearly from the cell's eight voxels, its opacity is the
//! transfer function's (corrected for the step), and its gradient is the trilinear
//! interpolation of the eight voxels' quantised gradients ([`super::gradient`]), rounded half
//! away from zero: a G-bit integer vector, the shader's input.
//!
//! **Compositing.** Front to back with a black background: with accumulated opacity A, a
//! sample of opacity a and intensity I (in output LSBs) adds w = (1 - A) a to A and w I to
//! the pixel. When A reaches the termination threshold (`ert`, default 0.99) the pixel is
//! opaque: A becomes 1 and later samples have weight exactly 0. The pixel's value is the
//! composited intensity rounded to an integer in 0..=2^M - 1.
//!
//! **Skipping** (on by default) changes how much work is done, never the image:
//! - empty-space skipping: a sample in a brick whose value range the transfer function
//!   maps to zero opacity ([`super::bricks`]) jumps to the first sample past the brick;
//! - early ray termination: the ray stops once A is 1 (after it, weights are 0);
//! - a sample with zero opacity is not shaded, nor is a zero gradient (the shader's zero
//!   case gives intensity 0 in the model and the reference alike).
//!
//! With skipping off every sample on the ray is interpolated and shaded and composited with
//! its (possibly zero) weight; adding `0 * I` leaves a sum unchanged, so both give identical
//! images, which the tests check.
//!
//! **Shaders.** The fused path ([`Caster::render`]) shades each contributing sample as it
//! is composited, with any [`Shader`] (the float reference, the bit-accurate model). A
//! batch shader (the Verilated RTL, through [`crate::model::IntensitySource`]) uses the
//! two-pass path: [`Caster::collect`] lists every contributing sample's gradient and weight,
//! the batch shader shades the list, and [`Samples::composite`] sums in the same order, so
//! it gives the fused image exactly when the intensities agree.

use super::bricks::Bricks;
use super::camera::Camera;
use super::gradient::Gradients;
use super::Volume;
use crate::config::Config;
use crate::model::fast::FastShader;
use crate::model::{Maps, Model};
use crate::reference::Reference;
use crate::scene::transfer::{Tf, Transfer};
use crate::scene::Scene;
use anyhow::{bail, ensure, Result};
use rayon::prelude::*;
use serde::Serialize;

/// Rounds half away from zero, like `f32::round` for |v| < 2^23, without a libm call on
/// baseline x86-64: adds the largest float below 0.5 with v's sign and truncates.
#[inline]
pub fn round_half_away(v: f32) -> i32 {
    (v + 0.499_999_97f32.copysign(v)) as i32
}

/// Default early-ray-termination threshold.
pub const DEFAULT_ERT: f64 = 0.99;
/// Default sample step, in units of the smallest voxel spacing.
pub const DEFAULT_STEP: f64 = 0.5;
/// Default brick size (cells per side) for empty-space skipping.
pub const DEFAULT_BRICK: usize = 8;
/// Smallest sample step in voxels (`--step`): the samples on a ray, hence the work of a
/// frame, grow as 1 / step.
pub const MIN_STEP: f64 = 0.05;
/// Largest sample step in voxels: beyond it samples skip whole cells.
pub const MAX_STEP: f64 = 4.0;
/// Largest brick side in cells (`--brick`): larger bricks are rarely empty.
pub const MAX_BRICK: usize = 64;
/// Bytes a batch (`--rtl`) render holds per contributing sample: its weight (4) and gradient
/// (12) here, its intensity (4) back from the batch shader, and its line in the simulator's
/// input and output files (about 16).
pub const BATCH_BYTES_PER_SAMPLE: u64 = 36;
/// The most contributing samples a batch render gathers: what fits the volume memory budget.
/// A transparent transfer function at a small step can reach billions, so the render stops
/// with an error once it passes this, instead of running out of memory.
pub const MAX_BATCH_SAMPLES: usize = (super::MEMORY_BUDGET / BATCH_BYTES_PER_SAMPLE) as usize;

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
}

impl Shader for ModelShader {
    #[inline]
    fn intensity(&self, g: [i32; 3]) -> u32 {
        self.fast.shade(g)
    }
}

/// How to cast.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CastOptions {
    /// Image width and height in pixels.
    pub size: u32,
    /// Sample step along a ray, in units of the smallest voxel spacing.
    pub step: f64,
    /// Early-ray-termination threshold on the accumulated opacity, in (0, 1].
    pub ert: f64,
    /// Cells per brick side for empty-space skipping.
    pub brick: usize,
    /// Skip empty space, terminate early and shade only contributing samples.
    pub skip: bool,
}

impl Default for CastOptions {
    fn default() -> Self {
        CastOptions {
            size: 512,
            step: DEFAULT_STEP,
            ert: DEFAULT_ERT,
            brick: DEFAULT_BRICK,
            skip: true,
        }
    }
}

impl CastOptions {
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (1..=crate::render::MAX_SIZE).contains(&self.size),
            "image size {} is out of range; allowed 1..={}",
            self.size,
            crate::render::MAX_SIZE
        );
        ensure!(
            self.step.is_finite() && self.step >= MIN_STEP && self.step <= MAX_STEP,
            "step {} is out of range; allowed {MIN_STEP}..={MAX_STEP} (voxels)",
            self.step
        );
        ensure!(
            self.ert > 0.0 && self.ert <= 1.0,
            "ert {} is out of range; allowed (0, 1]",
            self.ert
        );
        ensure!(
            (2..=MAX_BRICK).contains(&self.brick) && self.brick.is_power_of_two(),
            "brick {} is not allowed; give a power of two in 2..={MAX_BRICK}",
            self.brick
        );
        Ok(())
    }
}

/// A volume prepared for one gradient width and brick size: what does not change with the
/// view, the transfer function or the shading.
pub struct Prepared<'a> {
    pub vol: &'a Volume,
    pub grads: Gradients,
    pub bricks: Bricks,
}

impl<'a> Prepared<'a> {
    pub fn new(vol: &'a Volume, grad_bits: u32, brick: usize) -> Prepared<'a> {
        Prepared {
            vol,
            grads: super::gradient::gradients(vol, grad_bits),
            bricks: Bricks::new(vol, brick),
        }
    }

    /// [`Prepared::new`], refusing with an error a volume whose gradients the machine has no
    /// memory for.
    pub fn try_new(vol: &'a Volume, grad_bits: u32, brick: usize) -> anyhow::Result<Prepared<'a>> {
        Ok(Prepared {
            vol,
            grads: super::gradient::try_gradients(vol, grad_bits)?,
            bricks: Bricks::new(vol, brick),
        })
    }
}

/// Work counts of one image, summed over its rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Stats {
    /// Rays that pass through the volume's box.
    pub rays: u64,
    /// Samples on those rays inside the box: the work without skipping.
    pub samples: u64,
    /// Samples jumped over in empty bricks.
    pub empty_skipped: u64,
    /// Samples after early ray termination.
    pub terminated: u64,
    /// Samples interpolated (value and opacity).
    pub evaluated: u64,
    /// Samples shaded.
    pub shaded: u64,
}

impl Stats {
    fn add(self, o: Stats) -> Stats {
        Stats {
            rays: self.rays + o.rays,
            samples: self.samples + o.samples,
            empty_skipped: self.empty_skipped + o.empty_skipped,
            terminated: self.terminated + o.terminated,
            evaluated: self.evaluated + o.evaluated,
            shaded: self.shaded + o.shaded,
        }
    }

    fn fraction(&self, n: u64) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            n as f64 / self.samples as f64
        }
    }

    /// Fraction of the samples never interpolated (empty space and after termination).
    pub fn skipped_fraction(&self) -> f64 {
        self.fraction(self.empty_skipped + self.terminated)
    }

    /// Fraction of the samples not shaded.
    pub fn unshaded_fraction(&self) -> f64 {
        self.fraction(self.samples - self.shaded)
    }
}

/// One ray in voxel coordinates: sample k (0..count) at start + delta * k.
#[derive(Clone, Copy, Debug)]
struct Ray {
    start: [f32; 3],
    delta: [f32; 3],
    count: u32,
}

/// A rendered image before quantisation.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub size: u32,
    /// Composited intensity per pixel, in output LSBs (row 0 at the top).
    pub value: Vec<f32>,
    /// Accumulated opacity per pixel.
    pub alpha: Vec<f32>,
    pub stats: Stats,
}

impl Frame {
    /// Pixel values: the composited intensity rounded (half up) and clamped to 0..=max.
    pub fn pixels(&self, max: u32) -> Vec<u32> {
        self.value
            .iter()
            .map(|&c| (c.round().max(0.0) as u32).min(max))
            .collect()
    }
}

/// Every contributing sample of an image, for a batch shader.
#[derive(Clone, Debug)]
pub struct Samples {
    pub size: u32,
    /// Accumulated opacity per pixel.
    pub alpha: Vec<f32>,
    /// Pixel p's samples are `start[p]..start[p + 1]`, front to back.
    pub start: Vec<usize>,
    pub weights: Vec<f32>,
    pub gradients: Vec<[i32; 3]>,
    pub stats: Stats,
}

impl Samples {
    /// Composites intensities given for [`Samples::gradients`] in order: the frame the fused
    /// path gives with a shader that returns them.
    pub fn composite(&self, intensities: &[u32]) -> Result<Frame> {
        if intensities.len() != self.gradients.len() {
            bail!(
                "{} intensities for {} samples",
                intensities.len(),
                self.gradients.len()
            );
        }
        let value = (0..self.alpha.len())
            .into_par_iter()
            .map(|p| {
                let range = self.start[p]..self.start[p + 1];
                let mut c = 0.0f32;
                for (w, &i) in self.weights[range.clone()].iter().zip(&intensities[range]) {
                    c += w * i as f32;
                }
                c
            })
            .collect();
        Ok(Frame {
            size: self.size,
            value,
            alpha: self.alpha.clone(),
            stats: self.stats,
        })
    }
}

/// A ray caster for one prepared volume, transfer function, view and options.
pub struct Caster<'a> {
    vol: &'a Volume,
    grads: &'a [[i16; 3]],
    bricks: &'a Bricks,
    empty: Vec<bool>,
    tf: Tf,
    camera: Camera,
    opts: CastOptions,
}

impl<'a> Caster<'a> {
    /// `view` points from the volume towards the viewer, as the scene's view direction.
    pub fn new(
        p: &'a Prepared,
        transfer: &Transfer,
        view: [f64; 3],
        opts: CastOptions,
    ) -> Result<Caster<'a>> {
        opts.validate()?;
        transfer.validate()?;
        ensure!(
            p.bricks.size == opts.brick,
            "the volume was prepared with bricks of {} cells, not {}",
            p.bricks.size,
            opts.brick
        );
        let tf = transfer.compile(opts.step as f32);
        let empty = p.bricks.empty(&tf);
        let s = p.vol.spacing;
        let hi = [0, 1, 2].map(|a| (p.vol.dims[a] - 1) as f64 * s[a]);
        let camera = Camera::new([0.0; 3], hi, view, opts.size)?;
        Ok(Caster {
            vol: p.vol,
            grads: &p.grads.data,
            bricks: &p.bricks,
            empty,
            tf,
            camera,
            opts,
        })
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    pub fn options(&self) -> &CastOptions {
        &self.opts
    }

    /// Fraction of bricks that are empty for the transfer function.
    pub fn empty_brick_fraction(&self) -> f64 {
        self.empty.iter().filter(|&&e| e).count() as f64 / self.empty.len() as f64
    }

    /// The samples of pixel (x, y), or `None` when its ray misses the box.
    fn ray(&self, x: u32, y: u32) -> Option<Ray> {
        let (o, d) = self.camera.ray(x, y);
        let s = self.vol.spacing;
        let (o, d) = (
            [o.x / s[0], o.y / s[1], o.z / s[2]],
            [d.x / s[0], d.y / s[1], d.z / s[2]],
        );
        let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
        for a in 0..3 {
            let hi = (self.vol.dims[a] - 1) as f64;
            if d[a] == 0.0 {
                if o[a] < 0.0 || o[a] > hi {
                    return None;
                }
            } else {
                let (t0, t1) = ((0.0 - o[a]) / d[a], (hi - o[a]) / d[a]);
                near = near.max(t0.min(t1));
                far = far.min(t0.max(t1));
            }
        }
        if near > far {
            return None;
        }
        let h = self.opts.step * self.vol.unit();
        let (m0, m1) = ((near / h).ceil(), (far / h).floor());
        let count = if m1 >= m0 { (m1 - m0) as u32 + 1 } else { 0 };
        let t0 = m0 * h;
        Some(Ray {
            start: [0, 1, 2].map(|a| (o[a] + d[a] * t0) as f32),
            delta: [0, 1, 2].map(|a| (d[a] * h) as f32),
            count,
        })
    }

    /// The cell holding a position (clamped to the volume) and the position within it.
    #[inline]
    fn locate(&self, p: [f32; 3]) -> ([usize; 3], [f32; 3]) {
        let mut c = [0usize; 3];
        let mut f = [0f32; 3];
        for a in 0..3 {
            // Truncation equals floor for p > -1, and both clamp to 0 below that (NaN too).
            let ci = (p[a] as i32).clamp(0, self.vol.dims[a] as i32 - 2);
            c[a] = ci as usize;
            f[a] = (p[a] - ci as f32).clamp(0.0, 1.0);
        }
        (c, f)
    }

    /// First sample index at or after where the ray leaves the box of brick `cell / size`.
    #[inline]
    fn brick_exit(&self, r: &Ray, cell: [usize; 3]) -> u32 {
        let b = self.bricks.size;
        let mut exit = f32::INFINITY;
        for (a, &c) in cell.iter().enumerate() {
            let lo = (c & !(b - 1)) as f32;
            let face = if r.delta[a] > 0.0 {
                lo + b as f32
            } else if r.delta[a] < 0.0 {
                lo
            } else {
                continue;
            };
            exit = exit.min((face - r.start[a]) / r.delta[a]);
        }
        // Ceiling; `as` saturates: a huge or NaN exit gives u32::MAX or 0, both clamped by
        // the caller.
        let e = exit as u32;
        if (e as f32) < exit {
            e + 1
        } else {
            e
        }
    }

    #[inline]
    fn value(&self, i: usize, f: [f32; 3]) -> f32 {
        let d = &self.vol.data;
        let (sy, sz) = (self.vol.dims[0], self.vol.dims[0] * self.vol.dims[1]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let c00 = lerp(d[i], d[i + 1], f[0]);
        let c10 = lerp(d[i + sy], d[i + sy + 1], f[0]);
        let c01 = lerp(d[i + sz], d[i + sz + 1], f[0]);
        let c11 = lerp(d[i + sy + sz], d[i + sy + sz + 1], f[0]);
        lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2])
    }

    #[inline]
    fn gradient(&self, i: usize, f: [f32; 3]) -> [i32; 3] {
        let g = self.grads;
        let (sy, sz) = (self.vol.dims[0], self.vol.dims[0] * self.vol.dims[1]);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let mut out = [0i32; 3];
        for (c, o) in out.iter_mut().enumerate() {
            let v = |j: usize| g[j][c] as f32;
            let c00 = lerp(v(i), v(i + 1), f[0]);
            let c10 = lerp(v(i + sy), v(i + sy + 1), f[0]);
            let c01 = lerp(v(i + sz), v(i + sz + 1), f[0]);
            let c11 = lerp(v(i + sy + sz), v(i + sy + sz + 1), f[0]);
            *o = round_half_away(lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]));
        }
        out
    }

    /// Marches one ray front to back, handing each sample to be shaded to `sink` with its
    /// weight; returns the accumulated opacity.
    #[inline]
    fn march<F: FnMut(f32, [i32; 3])>(&self, r: &Ray, st: &mut Stats, mut sink: F) -> f32 {
        let skip = self.opts.skip;
        let ert = self.opts.ert as f32;
        let mut acc = 0.0f32;
        let mut k = 0u32;
        st.rays += 1;
        st.samples += r.count as u64;
        while k < r.count {
            let kf = k as f32;
            let p = [
                r.start[0] + r.delta[0] * kf,
                r.start[1] + r.delta[1] * kf,
                r.start[2] + r.delta[2] * kf,
            ];
            let (cell, f) = self.locate(p);
            if skip && self.empty[self.bricks.of_cell(cell)] {
                let next = self.brick_exit(r, cell).clamp(k + 1, r.count);
                st.empty_skipped += (next - k) as u64;
                k = next;
                continue;
            }
            st.evaluated += 1;
            let i = self.vol.index(cell[0], cell[1], cell[2]);
            let a = self.tf.alpha(self.value(i, f));
            if skip && a == 0.0 {
                k += 1;
                continue;
            }
            let g = self.gradient(i, f);
            let w = (1.0 - acc) * a;
            if !skip || g != [0; 3] {
                st.shaded += 1;
                sink(w, g);
            }
            acc += w;
            if acc >= ert {
                acc = 1.0;
                if skip {
                    st.terminated += (r.count - k - 1) as u64;
                    break;
                }
            }
            k += 1;
        }
        acc
    }

    /// The image shaded by `shader`, rows in parallel.
    pub fn render<S: Shader>(&self, shader: &S) -> Frame {
        let n = self.opts.size as usize;
        let mut value = vec![0.0f32; n * n];
        let mut alpha = vec![0.0f32; n * n];
        let stats = value
            .par_chunks_mut(n)
            .zip(alpha.par_chunks_mut(n))
            .enumerate()
            .map(|(y, (vrow, arow))| {
                let mut st = Stats::default();
                for x in 0..n {
                    if let Some(r) = self.ray(x as u32, y as u32) {
                        let mut c = 0.0f32;
                        arow[x] =
                            self.march(&r, &mut st, |w, g| c += w * shader.intensity(g) as f32);
                        vrow[x] = c;
                    }
                }
                st
            })
            .reduce(Stats::default, Stats::add);
        Frame {
            size: self.opts.size,
            value,
            alpha,
            stats,
        }
    }

    /// Every sample the fused path would shade, for a batch shader; refused once more than
    /// [`MAX_BATCH_SAMPLES`] samples contribute.
    pub fn collect(&self) -> Result<Samples> {
        self.collect_at_most(MAX_BATCH_SAMPLES)
    }

    /// [`Caster::collect`] with the sample limit given.
    fn collect_at_most(&self, limit: usize) -> Result<Samples> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let n = self.opts.size as usize;
        // Samples gathered so far over all rows: the image's sample count is only known
        // once every ray is marched, so the limit is checked as rows fill.
        let gathered = AtomicUsize::new(0);
        // Per row: opacities, sample counts per pixel, weights, gradients, work.
        type Row = (Vec<f32>, Vec<usize>, Vec<f32>, Vec<[i32; 3]>, Stats);
        let rows: Result<Vec<Row>> = (0..n)
            .into_par_iter()
            .map(|y| {
                let mut st = Stats::default();
                let (mut alpha, mut counts, mut w, mut g) =
                    (vec![0.0; n], vec![0; n], Vec::new(), Vec::new());
                for x in 0..n {
                    if let Some(r) = self.ray(x as u32, y as u32) {
                        let before = w.len();
                        alpha[x] = self.march(&r, &mut st, |wi, gi| {
                            w.push(wi);
                            g.push(gi);
                        });
                        counts[x] = w.len() - before;
                        if gathered.fetch_add(counts[x], Ordering::Relaxed) + counts[x] > limit {
                            bail!(
                                "the batch (--rtl) render gathers more than {limit} contributing \
                                 samples, the limit for {} of memory; use a smaller --size or a \
                                 larger --step",
                                super::human_bytes(super::MEMORY_BUDGET)
                            );
                        }
                    }
                }
                Ok((alpha, counts, w, g, st))
            })
            .collect();
        let rows = rows?;
        let mut s = Samples {
            size: self.opts.size,
            alpha: Vec::with_capacity(n * n),
            start: Vec::with_capacity(n * n + 1),
            weights: Vec::new(),
            gradients: Vec::new(),
            stats: Stats::default(),
        };
        s.start.push(0);
        for (alpha, counts, w, g, st) in rows {
            s.alpha.extend(alpha);
            for c in counts {
                let last = *s.start.last().unwrap();
                s.start.push(last + c);
            }
            s.weights.extend(w);
            s.gradients.extend(g);
            s.stats = s.stats.add(st);
        }
        Ok(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::synthetic;
    use crate::volume::VolumeInfo;

    fn transfer() -> Transfer {
        Transfer {
            points: vec![[1100.0, 0.0], [1900.0, 1.0]],
        }
    }

    fn opts(size: u32, skip: bool) -> CastOptions {
        CastOptions {
            size,
            skip,
            ..CastOptions::default()
        }
    }

    #[test]
    fn skipping_does_not_change_the_image() {
        let cfg = Config::default();
        let model = ModelShader::new(&cfg, &Scene::standard());
        let views = [
            [-0.5, -0.7, 0.5],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.3, 0.8, -0.6],
        ];
        // (spacing, step, ert, brick) per case; each case with every view.
        let cases = [
            ([1.0; 3], DEFAULT_STEP, DEFAULT_ERT, 4),
            ([1.0, 1.0, 1.5], 0.37, 0.95, 2),
            ([0.8, 1.0, 1.0], 1.0, 1.0, 16),
        ];
        for (spacing, step, ert, brick) in cases {
            let vol = synthetic::engine_block([64, 64, 32], spacing).unwrap();
            let p = Prepared::new(&vol, cfg.grad_bits, brick);
            for view in views {
                let o = CastOptions {
                    size: 48,
                    step,
                    ert,
                    brick,
                    skip: true,
                };
                let on = Caster::new(&p, &transfer(), view, o)
                    .unwrap()
                    .render(&model);
                let off = Caster::new(&p, &transfer(), view, CastOptions { skip: false, ..o })
                    .unwrap()
                    .render(&model);
                let what = format!("view {view:?} options {o:?}");
                assert_eq!(on.value, off.value, "{what}");
                assert_eq!(on.alpha, off.alpha, "{what}");
                // Skipping did skip, and the image is not empty.
                assert!(on.stats.skipped_fraction() > 0.3, "{what} {:?}", on.stats);
                assert_eq!(off.stats.evaluated, off.stats.samples);
                assert_eq!(on.stats.samples, off.stats.samples);
                assert!(
                    on.alpha.iter().filter(|&&a| a >= 0.95).count() > 200,
                    "{what}"
                );
            }
        }
    }

    #[test]
    fn batch_path_equals_fused_path() {
        // The batch path is shaded by `Model::intensity` (the definition), the fused path by
        // the model's fast tables: equal images also check the two agree on real samples.
        let vol = synthetic::engine_block([64, 64, 32], [1.0, 1.0, 1.5]).unwrap();
        let small = Config {
            grad_bits: 10,
            red_bits: 7,
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        };
        for cfg in [Config::default(), small] {
            let p = Prepared::new(&vol, cfg.grad_bits, 8);
            let c = Caster::new(&p, &transfer(), [-0.4, -0.8, 0.45], opts(40, true)).unwrap();
            let model = ModelShader::new(&cfg, &Scene::standard());
            let fused = c.render(&model);
            let samples = c.collect().unwrap();
            assert_eq!(samples.stats, fused.stats);
            assert!(samples.gradients.len() > 1000);
            let shaded: Vec<u32> = samples
                .gradients
                .iter()
                .map(|&g| model.model.intensity(&model.maps, g))
                .collect();
            assert_eq!(
                samples.composite(&shaded).unwrap(),
                fused,
                "{}",
                cfg.summary()
            );
            assert!(samples.composite(&shaded[1..]).is_err());
            // A limit below the image's sample count stops the gathering with an error.
            let e = c.collect_at_most(samples.gradients.len() - 1).unwrap_err();
            assert!(e.to_string().contains("more than"), "{e}");
            assert_eq!(
                c.collect_at_most(samples.gradients.len())
                    .unwrap()
                    .gradients,
                samples.gradients
            );
            // A batch that differs in one sample changes the image.
            let mut off = shaded.clone();
            let i = samples.weights.iter().position(|&w| w > 0.2).unwrap();
            off[i] = off[i].wrapping_add(9) % 256;
            assert_ne!(samples.composite(&off).unwrap().value, fused.value);
        }
    }

    #[test]
    fn an_opaque_slab_seen_head_on() {
        // Value 1000 for z <= 3, 0 above: seen from +z, every ray stops in the slab, and the
        // gradient there points up (out of the material), so the shader sees +z.
        let (n, m) = (8, 8);
        let mut d = Vec::new();
        for z in 0..m {
            d.extend(std::iter::repeat(if z <= 3 { 1000.0 } else { 0.0 }).take(n * n));
        }
        let vol = Volume::new(
            [n, n, m],
            [1.0; 3],
            d,
            VolumeInfo {
                source: "slab".into(),
                voxel_type: "float".into(),
            },
        )
        .unwrap();
        let p = Prepared::new(&vol, 12, 2);
        let tf = Transfer {
            points: vec![[400.0, 0.0], [600.0, 1.0]],
        };
        let c = Caster::new(
            &p,
            &tf,
            [0.0, 0.0, 1.0],
            CastOptions {
                size: 8,
                brick: 2,
                ..CastOptions::default()
            },
        )
        .unwrap();
        let s = c.collect().unwrap();
        assert!(s.alpha.iter().all(|&a| a == 1.0), "{:?}", s.alpha);
        for g in &s.gradients {
            assert!(g[2] > 0 && g[0] == 0 && g[1] == 0, "{g:?}");
        }
        // The whole pixel is shaded with the head-on intensity.
        struct Const;
        impl Shader for Const {
            fn intensity(&self, _: [i32; 3]) -> u32 {
                200
            }
        }
        let f = c.render(&Const);
        assert!(
            f.pixels(255).iter().all(|&v| v == 200),
            "{:?}",
            f.pixels(255)
        );
        // Samples in the empty half are skipped, and rays terminate in the slab.
        assert!(
            f.stats.empty_skipped > 0 && f.stats.terminated > 0,
            "{:?}",
            f.stats
        );
    }

    #[test]
    fn rounding() {
        for v in [
            0.5f32,
            -0.5,
            0.49999997,
            -0.49999997,
            1.5,
            -2.5,
            3.2,
            -3.7,
            2047.0,
            -2046.5,
            0.0,
        ] {
            assert_eq!(round_half_away(v), v.round() as i32, "{v}");
        }
    }

    #[test]
    fn options_are_checked() {
        let bad = |o: CastOptions| o.validate().unwrap_err().to_string();
        assert!(bad(CastOptions {
            size: 0,
            ..CastOptions::default()
        })
        .contains("size 0"));
        assert!(bad(CastOptions {
            step: 0.0,
            ..CastOptions::default()
        })
        .contains("step"));
        assert!(bad(CastOptions {
            ert: 1.5,
            ..CastOptions::default()
        })
        .contains("ert"));
        assert!(bad(CastOptions {
            brick: 1,
            ..CastOptions::default()
        })
        .contains("brick"));
        assert!(bad(CastOptions {
            brick: 12,
            ..CastOptions::default()
        })
        .contains("power of two"));
        CastOptions {
            brick: 16,
            ..CastOptions::default()
        }
        .validate()
        .unwrap();
    }
}
