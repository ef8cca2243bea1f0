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
//! - empty-space skipping: a sample in a brick the transfer function makes transparent
//!   (its value range maps to zero opacity, or below the minimum opacity once the
//!   gradient-magnitude ramp's largest factor for the brick's gradients is applied;
//!   [`super::bricks`]) jumps to the first sample past the brick;
//! - early ray termination: the ray stops once A is 1 (after it, weights are 0);
//! - a sample with zero opacity (after the ramp and the minimum) is not shaded, nor is a
//!   zero gradient (the shader's zero
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

pub mod frame;
pub mod march;
pub mod options;
pub mod shader;

use super::bricks::Bricks;
use super::camera::{Camera, Framing};
use super::prepared::Prepared;
use super::Volume;
use crate::scene::transfer::{Tf, Transfer};
use anyhow::{bail, ensure, Result};
use frame::{Frame, Samples, Stats};
use options::CastOptions;
use rayon::prelude::*;
use shader::Shader;

/// Bytes a batch (`--rtl`) render holds per contributing sample: its weight (4) and gradient
/// (12) here, its intensity (4) back from the batch shader, and its line in the simulator's
/// input and output files (about 16).
pub const BATCH_BYTES_PER_SAMPLE: u64 = 36;
/// The most contributing samples a batch render gathers: what fits the volume memory budget.
/// A transparent transfer function at a small step can reach billions, so the render stops
/// with an error once it passes this, instead of running out of memory.
pub const MAX_BATCH_SAMPLES: usize = (super::MEMORY_BUDGET / BATCH_BYTES_PER_SAMPLE) as usize;

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
    /// `view` points from the volume towards the viewer, as the scene's view direction (a
    /// world direction; the caster works in the volume's voxel-axis frame).
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
        let tf = transfer.compile(opts.step as f32, p.grads.scale);
        let empty = p.bricks.empty(&tf);
        let s = p.vol.spacing;
        let hi = [0, 1, 2].map(|a| (p.vol.dims[a] - 1) as f64 * s[a]);
        let framing = Framing {
            up: opts.up,
            zoom: opts.zoom,
            axes: p.vol.axes,
        };
        let camera = Camera::new([0.0; 3], hi, view, opts.size, &framing)?;
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
                crate::cancel::point();
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

    /// Pixel (x, y)'s contributing samples front to back, as (weight, gradient), and its
    /// accumulated opacity: the fused render's value there is the sum of weight times
    /// intensity ([`Caster::render`] marches the same ray). `None` when the ray misses the box.
    pub fn pixel(&self, x: u32, y: u32) -> Option<(f32, Vec<(f32, [i32; 3])>)> {
        let r = self.ray(x, y)?;
        let mut samples = Vec::new();
        let alpha = self.march(&r, &mut Stats::default(), |w, g| samples.push((w, g)));
        Some((alpha, samples))
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
    use crate::config::Config;
    use crate::scene::Scene;
    use crate::volume::synthetic;
    use crate::volume::VolumeInfo;
    use options::{DEFAULT_ERT, DEFAULT_STEP};
    use shader::ModelShader;

    fn transfer() -> Transfer {
        Transfer::new(vec![[1100.0, 0.0], [1900.0, 1.0]])
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
        // The value ramp alone, and with a gradient-magnitude ramp and a minimum opacity,
        // zoomed, with an up direction and voxel axes that are not the world's.
        let classified = Transfer {
            points: vec![[900.0, 0.0], [1900.0, 1.0]],
            gradient: Some(vec![[0.0, 0.0], [150.0, 0.0], [700.0, 1.0]]),
            min_opacity: Some(0.2),
        };
        let axes = [[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]];
        let kinds = [
            (transfer(), 1.0, None, crate::volume::camera::IDENTITY),
            (classified, 1.6, Some([0.3, 1.0, 0.2]), axes),
        ];
        for ((spacing, step, ert, brick), (tf, zoom, up, axes)) in cases
            .into_iter()
            .flat_map(|c| kinds.clone().into_iter().map(move |k| (c, k)))
        {
            let mut vol = synthetic::engine_block([64, 64, 32], spacing).unwrap();
            vol.axes = axes;
            let p = Prepared::new(&vol, cfg.grad_bits, brick);
            for view in views {
                let o = CastOptions {
                    size: 48,
                    step,
                    ert,
                    brick,
                    skip: true,
                    zoom,
                    up,
                    caster: options::CasterKind::Ray,
                    ..CastOptions::default()
                };
                let on = Caster::new(&p, &tf, view, o).unwrap().render(&model);
                let off = Caster::new(&p, &tf, view, CastOptions { skip: false, ..o })
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
    fn skipping_on_noise_with_a_gradient_ramp() {
        // Smoothed noise, a ramp on gradient magnitudes around its typical ones and a
        // minimum opacity: many bricks are transparent for the ramp alone, rays see through
        // them (no termination), so a brick wrongly marked empty changes the image.
        let vol = crate::volume::synthetic::smoothed_noise();
        let cfg = Config::default();
        let model = ModelShader::new(&cfg, &Scene::standard());
        let p = Prepared::new(&vol, cfg.grad_bits, 2);
        let tf = Transfer {
            points: vec![[30.0, 0.0], [70.0, 1.0]],
            gradient: Some(vec![[8.0, 0.0], [20.0, 1.0]]),
            min_opacity: Some(0.3),
        };
        let mut empty_by_ramp = 0.0;
        for view in [[0.2, 0.3, 1.0], [-1.0, 0.5, 0.1]] {
            let o = CastOptions {
                size: 40,
                ert: 1.0,
                brick: 2,
                ..CastOptions::default()
            };
            let c = Caster::new(&p, &tf, view, o).unwrap();
            let on = c.render(&model);
            let off = Caster::new(&p, &tf, view, CastOptions { skip: false, ..o })
                .unwrap()
                .render(&model);
            assert_eq!(on.value, off.value, "{view:?}");
            assert_eq!(on.alpha, off.alpha, "{view:?}");
            assert!(
                on.stats.shaded > 1000 && on.stats.empty_skipped > 0,
                "{:?}",
                on.stats
            );
            let no_ramp = Transfer {
                gradient: None,
                ..tf.clone()
            };
            empty_by_ramp = c.empty_brick_fraction()
                - Caster::new(&p, &no_ramp, view, o)
                    .unwrap()
                    .empty_brick_fraction();
        }
        assert!(empty_by_ramp > 0.05, "{empty_by_ramp}");
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
            d.extend(std::iter::repeat_n(
                if z <= 3 { 1000.0 } else { 0.0 },
                n * n,
            ));
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
        let tf = Transfer::new(vec![[400.0, 0.0], [600.0, 1.0]]);
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
}
