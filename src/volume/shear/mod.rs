//! Shear-warp rendering (Lacroute and Levoy's factorisation, as VolPack): the cost of a frame
//! scales with the volume's visible voxels, not with the image, because compositing happens
//! at voxel resolution and only a final 2D warp touches the image's pixels.
//!
//! **Samples.** The principal axis c is the voxel axis most nearly along the rays (largest
//! |component| of the ray direction in voxel units); the slices are the voxel planes
//! perpendicular to it, the other two axes (a, b; [`runs::slice_axes`]) span the
//! *intermediate image*, one pixel per voxel. Every ray of the intermediate image crosses
//! slice k at the sheared position (i + shift_a(k), j + shift_b(k)); the shift's fraction is
//! the same for the whole slice, so every sample of a slice has the same bilinear weights.
//! A sample's value is the bilinear interpolation of its slice cell's four voxels, its
//! gradient the bilinear interpolation of their quantised gradients rounded half away from
//! zero: a G-bit integer vector, the shader's input, as in the ray caster. Samples lie in
//! the half-open cells `0 <= p < n - 1` along a and b (each cell gives one sample per slice).
//! Consecutive samples of a ray are one slice apart: the transfer function is corrected for
//! that length (in smallest spacings), which depends on the view.
//!
//! **Compositing.** Front to back, slice by slice, per intermediate pixel exactly as the ray
//! caster per ray ([`crate::volume::cast`]): weight (1 - A) a, termination at `ert`, where A
//! becomes 1 and later weights are exactly 0.
//!
//! **Warp.** Each final pixel's ray meets the intermediate image at an affine function of
//! the pixel's position; its value and opacity are the bilinear interpolation of the four
//! intermediate pixels around it (zero outside). The camera and framing are the ray
//! caster's ([`crate::volume::camera`]), so both casters show the same view.
//!
//! **Skipping** (on by default) changes the work, never the image:
//! - empty space: only the runs of non-transparent cells of each scanline are visited
//!   ([`runs`], computed once per volume, transfer function and principal axis);
//! - early ray termination: a sample whose intermediate pixel is opaque (A = 1) is skipped;
//! - a sample with zero opacity, or a zero gradient, is not shaded (it adds nothing).
//!
//! **Threads**: slabs of intermediate scanlines in parallel (rayon); a slab composites all
//! slices front to back.
//!
//! **Shaders**: [`ShearWarp::render`] shades each contributing sample as it is composited
//! (any [`Shader`]); [`ShearWarp::collect`] lists the contributing samples for a batch
//! shader (the Verilated RTL), and [`ShearWarp::composite`] composites their intensities in
//! the same order, so the two paths give the same image when the intensities agree.

pub mod runs;

use super::camera::{Camera, Framing};
use super::cast::frame::{Frame, Stats};
use super::cast::options::CastOptions;
use super::cast::shader::Shader;
use super::cast::MAX_BATCH_SAMPLES;
use crate::scene::transfer::Tf;
use anyhow::{bail, ensure, Result};
use rayon::prelude::*;
pub use runs::{Classified, Runs};

/// Intermediate scanlines per parallel task: small enough that two threads share the work
/// evenly, large enough that each task composites many samples.
const SLAB_ROWS: usize = 4;

/// Where one slice's samples lie in the intermediate image.
#[derive(Clone, Copy, Debug)]
struct Slice {
    /// Intermediate pixel of cell 0 along a and b.
    i0: usize,
    j0: usize,
    /// Bilinear weights of the slice's samples (the fraction of the shear).
    fa: f32,
    fb: f32,
}

/// A shear-warp renderer for one classified volume, view and options.
pub struct ShearWarp<'a> {
    cl: &'a Classified<'a>,
    runs: &'a Runs,
    tf: Tf,
    camera: Camera,
    opts: CastOptions,
    /// Principal axis and the slice axes (a along scanlines).
    axes: [usize; 3],
    /// Voxel index stride along c, a and b.
    stride: [usize; 3],
    /// Whether the rays run towards increasing slice index.
    forward: bool,
    slices: Vec<Slice>,
    /// Intermediate image size (a, b).
    width: usize,
    height: usize,
    /// Intermediate position of final pixel (x, y)'s ray: `i = w[0] + w[1] x + w[2] y`,
    /// `j = w[3] + w[4] x + w[5] y`.
    warp: [f64; 6],
}

/// Every contributing sample of an intermediate image, for a batch shader: the pixel each
/// adds to, its weight and gradient, in compositing order.
#[derive(Clone, Debug)]
pub struct ShearSamples {
    /// Accumulated opacity per intermediate pixel.
    pub alpha: Vec<f32>,
    pub pixels: Vec<u32>,
    pub weights: Vec<f32>,
    pub gradients: Vec<[i32; 3]>,
    pub stats: Stats,
}

impl<'a> ShearWarp<'a> {
    /// `view` points from the volume towards the viewer (a world direction), as for the ray
    /// caster.
    pub fn new(cl: &'a Classified<'a>, view: [f64; 3], opts: CastOptions) -> Result<Self> {
        opts.validate()?;
        let vol = cl.prepared.vol;
        let s = vol.spacing;
        let hi = [0, 1, 2].map(|a| (vol.dims[a] - 1) as f64 * s[a]);
        let framing = Framing {
            up: opts.up,
            zoom: opts.zoom,
            axes: vol.axes,
        };
        let camera = Camera::new([0.0; 3], hi, view, opts.size, &framing)?;
        // Ray direction in voxel units.
        let dv = [0, 1, 2].map(|a| -camera.view.to_array()[a] / s[a]);
        let c = (0..3)
            .max_by(|&x, &y| dv[x].abs().total_cmp(&dv[y].abs()))
            .expect("three axes");
        ensure!(dv[c] != 0.0, "the view direction has no component");
        let (a, b) = runs::slice_axes(c);
        let d = vol.dims;
        let nc = d[c];
        let (sa, sb) = (dv[a] / dv[c], dv[b] / dv[c]);
        // shift(k) = k s - off lies in [-(nc - 1)|s|, 0], so every intermediate index is >= 0.
        let (oa, ob) = (
            (sa * (nc - 1) as f64).max(0.0),
            (sb * (nc - 1) as f64).max(0.0),
        );
        let slices: Vec<Slice> = (0..nc)
            .map(|k| {
                let (ha, hb) = (k as f64 * sa - oa, k as f64 * sb - ob);
                let (fa, fb) = (ha.floor(), hb.floor());
                Slice {
                    i0: (-fa) as usize,
                    j0: (-fb) as usize,
                    fa: (ha - fa) as f32,
                    fb: (hb - fb) as f32,
                }
            })
            .collect();
        let width = slices.iter().map(|s| s.i0).max().unwrap_or(0) + d[a] - 1;
        let height = slices.iter().map(|s| s.j0).max().unwrap_or(0) + d[b] - 1;
        // The ray of a final pixel with voxel-unit origin o meets slice k at p_a = o_a + (k -
        // o_c) sa, the intermediate pixel p_a - shift_a(k) = o_a - o_c sa + oa for every k.
        let meet = |x: u32, y: u32| {
            let (o, _) = camera.ray(x, y);
            let o = [o.x / s[0], o.y / s[1], o.z / s[2]];
            (o[a] - o[c] * sa + oa, o[b] - o[c] * sb + ob)
        };
        let (p00, p10, p01) = (meet(0, 0), meet(1, 0), meet(0, 1));
        let warp = [
            p00.0,
            p10.0 - p00.0,
            p01.0 - p00.0,
            p00.1,
            p10.1 - p00.1,
            p01.1 - p00.1,
        ];
        // Samples are one slice apart: |dv_c|^-1 world units along the (unit) ray.
        let step = 1.0 / (dv[c].abs() * vol.unit());
        let tf = cl.transfer.compile(step as f32, cl.prepared.grads.scale);
        Ok(ShearWarp {
            cl,
            runs: cl.runs(c),
            tf,
            camera,
            opts,
            axes: [c, a, b],
            stride: [c, a, b].map(|x| [1, d[0], d[0] * d[1]][x]),
            forward: dv[c] > 0.0,
            slices,
            width,
            height,
            warp,
        })
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The principal axis (0, 1 or 2 for voxel x, y, z).
    pub fn principal_axis(&self) -> usize {
        self.axes[0]
    }

    /// Intermediate image width and height.
    pub fn intermediate(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Distance between consecutive samples of a ray, in smallest voxel spacings.
    pub fn sample_step(&self) -> f64 {
        let s = self.cl.prepared.vol.spacing[self.axes[0]];
        let dv = -self.camera.view.to_array()[self.axes[0]] / s;
        1.0 / (dv.abs() * self.cl.prepared.vol.unit())
    }

    /// Fraction of the slice cells that are transparent for the transfer function.
    pub fn empty_cell_fraction(&self) -> f64 {
        self.runs.empty_fraction()
    }

    /// Composites the slab of intermediate rows `rows` (opacities `acc`, row-major, width
    /// [`Self::width`]), handing each sample to be shaded to `sink` with its pixel (within
    /// the slab) and weight.
    #[inline]
    fn slab<F: FnMut(usize, f32, [i32; 3])>(
        &self,
        rows: std::ops::Range<usize>,
        acc: &mut [f32],
        st: &mut Stats,
        mut sink: F,
    ) {
        let skip = self.opts.skip;
        let ert = self.opts.ert as f32;
        let vol = self.cl.prepared.vol;
        let data = &vol.data[..];
        let grads = &self.cl.prepared.grads.data[..];
        let [sc, sa, sb] = self.stride;
        let (cells, lines) = (self.runs.cells, self.runs.lines);
        let full = [[0u32, cells as u32]];
        let nc = self.slices.len();
        let tf = &self.tf;
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        for step in 0..nc {
            let k = if self.forward { step } else { nc - 1 - step };
            let sl = self.slices[k];
            let (fa, fb) = (sl.fa, sl.fb);
            for j in rows.clone() {
                let Some(cb) = j.checked_sub(sl.j0).filter(|&cb| cb < lines) else {
                    continue;
                };
                st.samples += cells as u64;
                let spans = if skip { self.runs.line(k, cb) } else { &full };
                let row = (j - rows.start) * self.width + sl.i0;
                let base = k * sc + cb * sb;
                let mut visited = 0u64;
                for &[first, end] in spans {
                    visited += (end - first) as u64;
                    for ca in first as usize..end as usize {
                        let px = row + ca;
                        let before = acc[px];
                        if skip && before >= 1.0 {
                            st.terminated += 1;
                            continue;
                        }
                        st.evaluated += 1;
                        let i = base + ca * sa;
                        let v = lerp(
                            lerp(data[i], data[i + sa], fa),
                            lerp(data[i + sb], data[i + sa + sb], fa),
                            fb,
                        );
                        let o = tf.value_opacity(v);
                        if skip && o == 0.0 {
                            continue;
                        }
                        let (g00, g10, g01, g11) =
                            (grads[i], grads[i + sa], grads[i + sb], grads[i + sa + sb]);
                        let g = [0, 1, 2].map(|x| {
                            super::cast::march::round_half_away(lerp(
                                lerp(g00[x] as f32, g10[x] as f32, fa),
                                lerp(g01[x] as f32, g11[x] as f32, fa),
                                fb,
                            ))
                        });
                        // The ramp only lowers the opacity: the value test above skips
                        // nothing visible.
                        let alpha = tf.correct(tf.with_gradient(o, g));
                        if skip && alpha == 0.0 {
                            continue;
                        }
                        let w = (1.0 - before) * alpha;
                        if !skip || g != [0; 3] {
                            st.shaded += 1;
                            sink(px, w, g);
                        }
                        let after = before + w;
                        acc[px] = if after >= ert { 1.0 } else { after };
                    }
                }
                st.empty_skipped += cells as u64 - visited;
            }
        }
    }

    /// The image shaded by `shader`: slabs of intermediate scanlines in parallel, then the
    /// warp.
    pub fn render<S: Shader>(&self, shader: &S) -> Frame {
        let w = self.width;
        let mut value = vec![0.0f32; w * self.height];
        let mut acc = vec![0.0f32; w * self.height];
        let stats = value
            .par_chunks_mut(w * SLAB_ROWS)
            .zip(acc.par_chunks_mut(w * SLAB_ROWS))
            .enumerate()
            .map(|(s, (vslab, aslab))| {
                let mut st = Stats::default();
                let j0 = s * SLAB_ROWS;
                let rows = j0..j0 + aslab.len() / w;
                self.slab(rows, aslab, &mut st, |px, wt, g| {
                    vslab[px] += wt * shader.intensity(g) as f32
                });
                st
            })
            .reduce(Stats::default, Stats::add);
        self.warp(&value, &acc, self.with_rays(stats))
    }

    /// Every sample the fused path would shade, for a batch shader; refused once more than
    /// [`MAX_BATCH_SAMPLES`] samples contribute.
    pub fn collect(&self) -> Result<ShearSamples> {
        self.collect_at_most(MAX_BATCH_SAMPLES)
    }

    fn collect_at_most(&self, limit: usize) -> Result<ShearSamples> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let w = self.width;
        let mut acc = vec![0.0f32; w * self.height];
        let gathered = AtomicUsize::new(0);
        type Slab = (Vec<u32>, Vec<f32>, Vec<[i32; 3]>, Stats);
        let slabs: Result<Vec<Slab>> = acc
            .par_chunks_mut(w * SLAB_ROWS)
            .enumerate()
            .map(|(s, aslab)| {
                let mut st = Stats::default();
                let j0 = s * SLAB_ROWS;
                let rows = j0..j0 + aslab.len() / w;
                let (mut p, mut wt, mut g) = (Vec::new(), Vec::new(), Vec::new());
                self.slab(rows, aslab, &mut st, |px, wi, gi| {
                    p.push((j0 * w + px) as u32);
                    wt.push(wi);
                    g.push(gi);
                });
                if gathered.fetch_add(p.len(), Ordering::Relaxed) + p.len() > limit {
                    bail!(
                        "the batch (--rtl) render gathers more than {limit} contributing samples, \
                         the limit for {} of memory; use a smaller volume (--crop)",
                        super::human_bytes(super::MEMORY_BUDGET)
                    );
                }
                Ok((p, wt, g, st))
            })
            .collect();
        let mut out = ShearSamples {
            alpha: Vec::new(),
            pixels: Vec::new(),
            weights: Vec::new(),
            gradients: Vec::new(),
            stats: Stats::default(),
        };
        for (p, wt, g, st) in slabs? {
            out.pixels.extend(p);
            out.weights.extend(wt);
            out.gradients.extend(g);
            out.stats = out.stats.add(st);
        }
        out.stats = self.with_rays(out.stats);
        out.alpha = acc;
        Ok(out)
    }

    /// Composites intensities given for [`ShearSamples::gradients`] in order and warps: the
    /// frame the fused path gives with a shader that returns them.
    pub fn composite(&self, s: &ShearSamples, intensities: &[u32]) -> Result<Frame> {
        if intensities.len() != s.gradients.len() {
            bail!(
                "{} intensities for {} samples",
                intensities.len(),
                s.gradients.len()
            );
        }
        let mut value = vec![0.0f32; s.alpha.len()];
        for ((&p, &w), &i) in s.pixels.iter().zip(&s.weights).zip(intensities) {
            value[p as usize] += w * i as f32;
        }
        Ok(self.warp(&value, &s.alpha, s.stats))
    }

    /// The work counts with `rays` set: the intermediate image's pixels.
    fn with_rays(&self, mut st: Stats) -> Stats {
        st.rays = (self.width * self.height) as u64;
        st
    }

    /// The final image: each pixel the bilinear interpolation of the intermediate image
    /// (composited values and opacities) where its ray meets it.
    fn warp(&self, value: &[f32], acc: &[f32], stats: Stats) -> Frame {
        let n = self.opts.size as usize;
        let (w, h) = (self.width as isize, self.height as isize);
        let m = self.warp;
        let mut out_v = vec![0.0f32; n * n];
        let mut out_a = vec![0.0f32; n * n];
        out_v
            .par_chunks_mut(n)
            .zip(out_a.par_chunks_mut(n))
            .enumerate()
            .for_each(|(y, (vr, ar))| {
                let yf = y as f64;
                for x in 0..n {
                    let xf = x as f64;
                    let (pi, pj) = (m[0] + m[1] * xf + m[2] * yf, m[3] + m[4] * xf + m[5] * yf);
                    let (fi, fj) = (pi.floor(), pj.floor());
                    let (i, j) = (fi as isize, fj as isize);
                    if i < -1 || j < -1 || i >= w || j >= h {
                        continue;
                    }
                    let (ti, tj) = ((pi - fi) as f32, (pj - fj) as f32);
                    let at = |ii: isize, jj: isize| {
                        if ii < 0 || jj < 0 || ii >= w || jj >= h {
                            (0.0, 0.0)
                        } else {
                            let q = (jj * w + ii) as usize;
                            (value[q], acc[q])
                        }
                    };
                    let (v00, a00) = at(i, j);
                    let (v10, a10) = at(i + 1, j);
                    let (v01, a01) = at(i, j + 1);
                    let (v11, a11) = at(i + 1, j + 1);
                    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
                    vr[x] = lerp(lerp(v00, v10, ti), lerp(v01, v11, ti), tj);
                    ar[x] = lerp(lerp(a00, a10, ti), lerp(a01, a11, ti), tj);
                }
            });
        Frame {
            size: self.opts.size,
            value: out_v,
            alpha: out_a,
            stats,
        }
    }
}
