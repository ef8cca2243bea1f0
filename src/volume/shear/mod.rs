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
//! **Finer sampling** (options, both 1 by default; docs/PERFORMANCE.md measures them):
//! - `slice_samples` n: n samples per slice spacing, at c = m / n; a sample between slices k
//!   and k + 1 is the linear interpolation along c of the two slices' bilinear value and
//!   gradient at the same sheared position (trilinear, rounded once), and the runs are those
//!   of the slabs between slices (cells of 8 voxels). The transfer function is corrected
//!   for the shorter step. This removes the slice pattern on oblique surfaces.
//! - `supersample` r: r intermediate pixels per voxel along a and b, the r samples of a cell
//!   at fractions (u + e) / r of it (e the shift's fraction in intermediate pixels), and the
//!   warp reads the finer image: the image's detail below a voxel (pixels are 0.46 voxels on
//!   the MRI head at 256²) is then resampled from closer rays.
//!
//! The work grows as n r²; matching the ray caster's image takes about n = 4, r = 3.
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
use super::cast::options::{CastOptions, MAX_SUPERSAMPLE};
use super::cast::shader::Shader;
use super::cast::MAX_BATCH_SAMPLES;
use crate::scene::transfer::Tf;
use anyhow::{bail, ensure, Result};
use rayon::prelude::*;
pub use runs::{Classified, Runs, Spans, Voxel};

/// Intermediate scanlines per parallel task: small enough that two threads share the work
/// evenly, large enough that each task composites many samples.
const SLAB_ROWS: usize = 4;

/// Where one slice's samples lie in the intermediate image, and between which slices.
#[derive(Clone, Copy, Debug)]
struct Slice {
    /// The layer of the runs and voxels: slice k (one sample per slice), or the slab
    /// between slices k and k + 1 (samples between slices).
    k: usize,
    /// Weight of slice k + 1 (0: the sample lies on slice k, and only its voxels are read).
    t: f32,
    /// Intermediate pixel of cell 0's first sample along a and b.
    i0: usize,
    j0: usize,
    /// Bilinear weights of the slice's samples: the r samples of a cell along a (b) lie at
    /// fractions `fa[0..r]` (`fb[0..r]`) of it (with r = 1, the fraction of the shear).
    fa: [f32; MAX_SUPERSAMPLE as usize],
    fb: [f32; MAX_SUPERSAMPLE as usize],
}

/// A shear-warp renderer for one classified volume, view and options.
pub struct ShearWarp<'a> {
    cl: &'a Classified<'a>,
    runs: &'a Runs,
    /// The runs of the layers the samples lie in: the slices', or the slabs' between them.
    spans: &'a Spans,
    tf: Tf,
    camera: Camera,
    opts: CastOptions,
    /// Principal axis and the slice axes (a along scanlines).
    axes: [usize; 3],
    /// Index strides along c, a and b in the runs' slice-ordered voxels.
    stride: [usize; 3],
    /// Whether the rays run towards increasing slice index.
    forward: bool,
    /// Samples per slice spacing.
    per_slice: usize,
    /// Intermediate pixels per voxel along a and b.
    sup: usize,
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
    /// The padded intermediate image with the accumulated opacities (values 0).
    pub image: Vec<[f32; 2]>,
    /// Its non-transparent pixels' bounding box.
    pub bbox: Bbox,
    /// Indices into `image`.
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
        #[cfg(test)]
        let (sa, sb) = match cl.plant_geometry {
            Some(GeometryFault::ShearSign) => (-sa, -sb),
            _ => (sa, sb),
        };
        // The position along c whose shift a sample at position s takes (s itself; one
        // slice further for a planted fault).
        #[cfg(not(test))]
        let shifted = |s: f64| s;
        #[cfg(test)]
        let shifted = |s: f64| match cl.plant_geometry {
            Some(GeometryFault::SliceOffByOne) => s + 1.0,
            _ => s,
        };
        // `n` samples per slice spacing: sample m lies at c = m / n, between slices k and
        // k + 1 (the last sample on the last slice). With one, every sample lies on a slice.
        let n = if nc >= 2 {
            opts.slice_samples as usize
        } else {
            1
        };
        // `r` intermediate pixels per voxel along a and b: intermediate pixel p of a slice
        // whose shift is h lies at p / r + h voxels.
        let r = opts.supersample as usize;
        let rf = r as f64;
        // shift(k) = k s - off lies in [-(nc - 1)|s|, 0], so every intermediate index is >= 0.
        let (oa, ob) = (
            (sa * (nc - 1) as f64).max(0.0),
            (sb * (nc - 1) as f64).max(0.0),
        );
        let slices: Vec<Slice> = (0..=(nc - 1) * n)
            .map(|m| {
                let (k, t) = if n == 1 {
                    (m, 0.0)
                } else {
                    let k = (m / n).min(nc - 2);
                    let t = (m as f64 / n as f64 - k as f64) as f32;
                    #[cfg(test)]
                    let t = match cl.plant_geometry {
                        Some(GeometryFault::WeightBetweenSlices) if t != 0.0 => 1.0 - t,
                        _ => t,
                    };
                    (k, t)
                };
                let at = shifted(m as f64 / n as f64);
                // In intermediate pixels; the fraction e of the shift in pixels puts cell
                // sample u at (u + e) / r of the cell.
                let (ha, hb) = (rf * (at * sa - oa), rf * (at * sb - ob));
                let (fa, fb) = (ha.floor(), hb.floor());
                #[cfg(test)]
                let phase = |e: f64| match cl.plant_geometry {
                    Some(GeometryFault::SubpixelPhase) if r > 1 => 0.0,
                    _ => e,
                };
                #[cfg(not(test))]
                let phase = |e: f64| e;
                let sub = |e: f64| {
                    let e = phase(e);
                    let mut w = [0f32; MAX_SUPERSAMPLE as usize];
                    for (u, x) in w.iter_mut().enumerate().take(r) {
                        *x = ((u as f64 + e) / rf) as f32;
                    }
                    w
                };
                Slice {
                    k,
                    t,
                    i0: (-fa) as usize,
                    j0: (-fb) as usize,
                    fa: sub(ha - fa),
                    fb: sub(hb - fb),
                }
            })
            .collect();
        let width = slices.iter().map(|s| s.i0).max().unwrap_or(0) + r * (d[a] - 1);
        let height = slices.iter().map(|s| s.j0).max().unwrap_or(0) + r * (d[b] - 1);
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
        ]
        .map(|w| w * rf);
        // Samples are 1 / n slices apart: (n |dv_c|)^-1 world units along the (unit) ray.
        let step = 1.0 / (dv[c].abs() * vol.unit() * n as f64);
        let tf = cl.transfer.compile(step as f32, cl.prepared.grads.scale);
        let forward = dv[c] > 0.0;
        #[cfg(test)]
        let forward = forward != (cl.plant_geometry == Some(GeometryFault::ReversedOrder));
        let runs = cl.runs(c)?;
        let spans = if n == 1 {
            &runs.slices
        } else {
            cl.slab_runs(c)?
        };
        Ok(ShearWarp {
            cl,
            runs,
            spans,
            tf,
            camera,
            opts,
            axes: [c, a, b],
            stride: [d[a] * d[b], 1, d[a]],
            forward,
            per_slice: n,
            sup: r,
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
        1.0 / (dv.abs() * self.cl.prepared.vol.unit() * self.per_slice as f64)
    }

    /// Fraction of the slice cells that are transparent for the transfer function.
    pub fn empty_cell_fraction(&self) -> f64 {
        self.runs.empty_fraction()
    }

    /// Composites the slab of intermediate rows `rows` into `im` (those rows of the padded
    /// intermediate image, [`Self::padded`]): each sample to be shaded goes to `sink` with
    /// its pixel (index into `im`), weight and gradient, and `sink` returns what it adds to
    /// the pixel's value. Returns the bounding box of the pixels it made non-transparent.
    #[inline]
    fn slab<F: FnMut(usize, f32, [i32; 3]) -> f32>(
        &self,
        rows: std::ops::Range<usize>,
        im: &mut [[f32; 2]],
        st: &mut Stats,
        mut sink: F,
    ) -> Bbox {
        let skip = self.opts.skip;
        let ert = self.opts.ert as f32;
        let vox = &self.runs.voxels[..];
        let [sc, sa, sb] = self.stride;
        let (cells, lines) = (self.runs.cells, self.runs.lines);
        let full = [[0u32, cells as u32]];
        let ns = self.slices.len();
        let pw = self.width + 2;
        let tf = &self.tf;
        let mut bbox = Bbox::EMPTY;
        // Early ray termination without visiting opaque pixels (VolPack's pixel skip links):
        // `link[p]` is 0 for a pixel still open, else a distance to jump towards the next
        // open pixel of its row (shortened as chains are followed).
        let mut link = vec![0u32; im.len()];
        let r = self.sup;
        for step in 0..ns {
            let sl = self.slices[if self.forward { step } else { ns - 1 - step }];
            let (k, t) = (sl.k, sl.t);
            // A sample between slices reads the same cell of slice k + 1 too (trilinear).
            let deep = t != 0.0;
            for j in rows.clone() {
                let Some(qb) = j.checked_sub(sl.j0).filter(|&qb| qb < r * lines) else {
                    continue;
                };
                let (cb, fb) = (qb / r, sl.fb[qb % r]);
                st.samples += (r * cells) as u64;
                let spans = if skip { self.spans.line(k, cb) } else { &full };
                let row = (j - rows.start) * pw + 1 + sl.i0;
                // The row's right border pixel: never opaque, so every chain stops there.
                let row_end = (j - rows.start) * pw + 1 + self.width;
                let base = k * sc + cb * sb;
                let mut visited = 0u64;
                for &[first, end] in spans {
                    // The run's intermediate pixels (r per cell).
                    let (first, end) = (r * first as usize, r * end as usize);
                    visited += (end - first) as u64;
                    let mut q = first;
                    while q < end {
                        let px = row + q;
                        if skip && link[px] != 0 {
                            // Follow the chain to the next open pixel (or the row's end).
                            let mut open = px;
                            while open < row_end && link[open] != 0 {
                                open += link[open] as usize;
                            }
                            // Path compression: every pixel on the chain now points at the
                            // open one, so a later run starting inside the stretch jumps at
                            // once.
                            let mut x = px;
                            while x < open {
                                let next = x + link[x] as usize;
                                link[x] = (open - x) as u32;
                                x = next;
                            }
                            let next = (q + open - px).min(end);
                            st.terminated += (next - q) as u64;
                            q = next;
                            continue;
                        }
                        // The pixel's cell and its sample's weight along a.
                        let (ca, fa) = if r == 1 {
                            (q, sl.fa[0])
                        } else {
                            (q / r, sl.fa[q % r])
                        };
                        q += 1;
                        let before = im[px][1];
                        st.evaluated += 1;
                        let i = base + ca * sa;
                        // The value first: a transparent sample reads no gradient.
                        let v = if deep {
                            lerp(
                                cell_value(vox, i, sa, sb, fa, fb),
                                cell_value(vox, i + sc, sa, sb, fa, fb),
                                t,
                            )
                        } else {
                            cell_value(vox, i, sa, sb, fa, fb)
                        };
                        let o = tf.value_opacity(v);
                        if skip && o == 0.0 {
                            continue;
                        }
                        let gf = if deep {
                            let (n, f) = (
                                cell_gradient(vox, i, sa, sb, fa, fb),
                                cell_gradient(vox, i + sc, sa, sb, fa, fb),
                            );
                            [0, 1, 2].map(|x| lerp(n[x], f[x], t))
                        } else {
                            cell_gradient(vox, i, sa, sb, fa, fb)
                        };
                        let g = gf.map(super::cast::march::round_half_away);
                        // The ramp only lowers the opacity: the value test above skips
                        // nothing visible.
                        let alpha = tf.correct(tf.with_gradient(o, g));
                        if skip && alpha == 0.0 {
                            continue;
                        }
                        let w = (1.0 - before) * alpha;
                        if !skip || g != [0; 3] {
                            st.shaded += 1;
                            im[px][0] += sink(px, w, g);
                        }
                        let after = before + w;
                        if after > 0.0 {
                            bbox.add(sl.i0 + q - 1, j);
                        }
                        if after >= ert {
                            im[px][1] = 1.0;
                            link[px] = 1;
                        } else {
                            im[px][1] = after;
                        }
                    }
                }
                st.empty_skipped += (r * cells) as u64 - visited;
            }
        }
        bbox
    }

    /// Composites every slab of the padded intermediate image `im` in parallel; `slab`
    /// composites one (its first intermediate row, its rows of `im`) and returns its
    /// bounding box and anything else.
    fn slabs<T: Send, F>(&self, im: &mut [[f32; 2]], slab: F) -> Vec<T>
    where
        F: Fn(usize, &mut [[f32; 2]]) -> T + Sync,
    {
        let pw = self.width + 2;
        let inner = &mut im[pw..pw * (self.height + 1)];
        inner
            .par_chunks_mut(pw * SLAB_ROWS)
            .enumerate()
            .map(|(s, rows)| slab(s * SLAB_ROWS, rows))
            .collect()
    }

    /// The image shaded by `shader`: slabs of intermediate scanlines in parallel, then the
    /// warp.
    pub fn render<S: Shader>(&self, shader: &S) -> Frame {
        let mut out = Frame::default();
        self.render_into(shader, &mut out);
        out
    }

    /// [`Self::render`] into `out`, reusing its buffers (as VolPack renders into the image
    /// its caller set once): a fresh 512² frame costs about 1 ms of page faults, as much as
    /// the compositing.
    pub fn render_into<S: Shader>(&self, shader: &S, out: &mut Frame) {
        let pw = self.width + 2;
        let mut im = self.cl.take_image((self.width + 2) * (self.height + 2));
        let parts = self.slabs(&mut im, |j0, rows| {
            let mut st = Stats::default();
            let r = j0..j0 + rows.len() / pw;
            let b = self.slab(r, rows, &mut st, |_, wt, g| wt * shader.intensity(g) as f32);
            (st, b)
        });
        let (stats, bbox) = parts
            .into_iter()
            .fold((Stats::default(), Bbox::EMPTY), |(s, b), (s2, b2)| {
                (s.add(s2), b.union(b2))
            });
        self.warp(&im, bbox, self.with_rays(stats), out);
        self.cl.give_image(im);
    }

    /// Every sample the fused path would shade, for a batch shader; refused once more than
    /// [`MAX_BATCH_SAMPLES`] samples contribute.
    pub fn collect(&self) -> Result<ShearSamples> {
        self.collect_at_most(MAX_BATCH_SAMPLES)
    }

    fn collect_at_most(&self, limit: usize) -> Result<ShearSamples> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let pw = self.width + 2;
        let mut im = vec![[0.0f32; 2]; pw * (self.height + 2)];
        let gathered = AtomicUsize::new(0);
        type Slab = (Vec<u32>, Vec<f32>, Vec<[i32; 3]>, Stats, Bbox);
        let slabs: Result<Vec<Slab>> = self
            .slabs(&mut im, |j0, rows| {
                let mut st = Stats::default();
                let r = j0..j0 + rows.len() / pw;
                let (mut p, mut wt, mut g) = (Vec::new(), Vec::new(), Vec::new());
                // Pixels as indices into the whole padded image (the slab starts at row
                // j0 + 1).
                let at = (j0 + 1) * pw;
                let b = self.slab(r, rows, &mut st, |px, wi, gi| {
                    p.push((at + px) as u32);
                    wt.push(wi);
                    g.push(gi);
                    0.0
                });
                if gathered.fetch_add(p.len(), Ordering::Relaxed) + p.len() > limit {
                    bail!(
                        "the batch (--rtl) render gathers more than {limit} contributing samples, \
                         the limit for {} of memory; use a smaller volume (--crop)",
                        super::human_bytes(super::MEMORY_BUDGET)
                    );
                }
                Ok((p, wt, g, st, b))
            })
            .into_iter()
            .collect();
        let mut out = ShearSamples {
            image: Vec::new(),
            bbox: Bbox::EMPTY,
            pixels: Vec::new(),
            weights: Vec::new(),
            gradients: Vec::new(),
            stats: Stats::default(),
        };
        for (p, wt, g, st, b) in slabs? {
            out.pixels.extend(p);
            out.weights.extend(wt);
            out.gradients.extend(g);
            out.stats = out.stats.add(st);
            out.bbox = out.bbox.union(b);
        }
        out.stats = self.with_rays(out.stats);
        out.image = im;
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
        let mut im = s.image.clone();
        for ((&p, &w), &i) in s.pixels.iter().zip(&s.weights).zip(intensities) {
            im[p as usize][0] += w * i as f32;
        }
        let mut out = Frame::default();
        self.warp(&im, s.bbox, s.stats, &mut out);
        Ok(out)
    }

    /// The work counts with `rays` set: the intermediate image's pixels.
    fn with_rays(&self, mut st: Stats) -> Stats {
        st.rays = (self.width * self.height) as u64;
        st
    }

    /// The final image into `out`: each pixel the bilinear interpolation of the padded
    /// intermediate image `im` (composited values and opacities) where its ray meets it.
    /// Only the pixels whose four intermediate pixels can reach `bbox` (every
    /// non-transparent intermediate pixel) are interpolated; the others are exactly 0 either
    /// way and are written 0 in the same pass (the image's background costs a store).
    fn warp(&self, im: &[[f32; 2]], bbox: Bbox, stats: Stats, out: &mut Frame) {
        let n = self.opts.size as usize;
        let pw = self.width + 2;
        let m = self.warp;
        out.size = self.opts.size;
        out.stats = stats;
        // Every pixel is written below: resizing keeps (and does not clear) a reused buffer.
        out.value.resize(n * n, 0.0);
        out.alpha.resize(n * n, 0.0);
        let Some([ilo, ihi, jlo, jhi]) = bbox.bounds() else {
            out.value.par_iter_mut().for_each(|v| *v = 0.0);
            out.alpha.par_iter_mut().for_each(|v| *v = 0.0);
            return;
        };
        // A position is interpolated when it lies in (ilo - 1, ihi + 1) x (jlo - 1, jhi + 1):
        // outside, its four pixels are all transparent (value and opacity 0). Each row's
        // range of such positions is found from the affine map, so floor is a truncation
        // there (positions > -1), not a libm call.
        let bi = (ilo as f64 - 1.0, ihi as f64 + 1.0);
        let bj = (jlo as f64 - 1.0, jhi as f64 + 1.0);
        out.value
            .par_chunks_mut(n)
            .zip(out.alpha.par_chunks_mut(n))
            .enumerate()
            .for_each(|(y, (vr, ar))| {
                let yf = y as f64;
                let (i0, j0) = (m[0] + m[2] * yf, m[3] + m[5] * yf);
                let (mut lo, mut hi) = (0.0f64, n as f64);
                for (p0, d, (bot, top)) in [(i0, m[1], bi), (j0, m[4], bj)] {
                    if d == 0.0 {
                        if p0 <= bot || p0 >= top {
                            hi = 0.0;
                        }
                    } else {
                        let (a, b) = ((bot - p0) / d, (top - p0) / d);
                        lo = lo.max(a.min(b));
                        hi = hi.min(a.max(b));
                    }
                }
                let x0 = (lo.max(0.0).floor() as usize).min(n);
                let x1 = (hi.ceil().max(0.0) as usize).clamp(x0, n);
                vr[..x0].fill(0.0);
                ar[..x0].fill(0.0);
                vr[x1..].fill(0.0);
                ar[x1..].fill(0.0);
                let rows = vr[x0..x1].iter_mut().zip(&mut ar[x0..x1]);
                for (x, (v, a)) in (x0..x1).zip(rows) {
                    let xf = x as f64;
                    // Padded positions.
                    let (pi, pj) = (i0 + m[1] * xf + 1.0, j0 + m[4] * xf + 1.0);
                    if pi <= bi.0 + 1.0 || pj <= bj.0 + 1.0 || pi >= bi.1 + 1.0 || pj >= bj.1 + 1.0
                    {
                        (*v, *a) = (0.0, 0.0);
                        continue;
                    }
                    let (i, j) = (pi as u32 as usize, pj as u32 as usize);
                    let (ti, tj) = ((pi - i as f64) as f32, (pj - j as f64) as f32);
                    let q = j * pw + i;
                    let (r0, r1) = (&im[q..q + 2], &im[q + pw..q + pw + 2]);
                    let at = |c: usize| {
                        lerp(
                            lerp(r0[0][c], r0[1][c], ti),
                            lerp(r1[0][c], r1[1][c], ti),
                            tj,
                        )
                    };
                    (*v, *a) = (at(0), at(1));
                }
            });
    }
}

#[inline(always)]
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// The bilinear interpolation (weights `fa` along a, then `fb` along b) of the values of the
/// slice cell whose first voxel is `vox[i]` (strides `sa`, `sb`).
///
/// Scalar reads on purpose: the four voxels built as a tuple were copied through the stack
/// and read back with wider loads, a store-forwarding stall on every sample that cost the
/// compositing about a quarter of its time (docs/PERFORMANCE.md).
#[inline(always)]
fn cell_value(vox: &[Voxel], i: usize, sa: usize, sb: usize, fa: f32, fb: f32) -> f32 {
    let (q00, q10, q01, q11) = (vox[i].v, vox[i + sa].v, vox[i + sb].v, vox[i + sa + sb].v);
    lerp(lerp(q00, q10, fa), lerp(q01, q11, fa), fb)
}

/// [`cell_value`] of the quantised gradients, per component (before rounding).
#[inline(always)]
fn cell_gradient(vox: &[Voxel], i: usize, sa: usize, sb: usize, fa: f32, fb: f32) -> [f32; 3] {
    let (q00, q10, q01, q11) = (vox[i].g, vox[i + sa].g, vox[i + sb].g, vox[i + sa + sb].g);
    [0, 1, 2].map(|x| {
        lerp(
            lerp(q00[x] as f32, q10[x] as f32, fa),
            lerp(q01[x] as f32, q11[x] as f32, fa),
            fb,
        )
    })
}

/// A planted geometry fault (tests only): each must make the geometry test against the ray
/// caster fail.
#[cfg(test)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum GeometryFault {
    /// The shear's direction reversed.
    ShearSign,
    /// Every slice drawn with the next slice's shift (one slice off).
    SliceOffByOne,
    /// Slices composited back to front.
    ReversedOrder,
    /// A sample between slices weighted towards the wrong slice (1 - t for t).
    WeightBetweenSlices,
    /// A finer intermediate image's samples placed without the shift's sub-pixel fraction.
    SubpixelPhase,
}

/// The bounding box of the non-transparent pixels of an intermediate image (inclusive
/// bounds along a and b), or empty.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bbox {
    lo: [usize; 2],
    hi: [usize; 2],
}

impl Bbox {
    const EMPTY: Bbox = Bbox {
        lo: [usize::MAX; 2],
        hi: [0; 2],
    };

    #[inline]
    fn add(&mut self, i: usize, j: usize) {
        self.lo = [self.lo[0].min(i), self.lo[1].min(j)];
        self.hi = [self.hi[0].max(i), self.hi[1].max(j)];
    }

    fn union(self, o: Bbox) -> Bbox {
        Bbox {
            lo: [self.lo[0].min(o.lo[0]), self.lo[1].min(o.lo[1])],
            hi: [self.hi[0].max(o.hi[0]), self.hi[1].max(o.hi[1])],
        }
    }

    /// `[i_lo, i_hi, j_lo, j_hi]`, or `None` when empty.
    fn bounds(self) -> Option<[usize; 4]> {
        (self.lo[0] <= self.hi[0]).then_some([self.lo[0], self.hi[0], self.lo[1], self.hi[1]])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::scene::transfer::Transfer;
    use crate::scene::Scene;
    use crate::volume::cast::options::CasterKind;
    use crate::volume::cast::shader::ModelShader;
    use crate::volume::cast::Caster;
    use crate::volume::prepared::Prepared;
    use crate::volume::{camera, synthetic};

    fn opts(size: u32, skip: bool) -> CastOptions {
        CastOptions {
            size,
            skip,
            caster: CasterKind::ShearWarp,
            ..CastOptions::default()
        }
    }

    fn classified_tf() -> Transfer {
        Transfer {
            points: vec![[900.0, 0.0], [1900.0, 1.0]],
            gradient: Some(vec![[0.0, 0.0], [150.0, 0.0], [700.0, 1.0]]),
            min_opacity: Some(0.2),
        }
    }

    /// On and off give the same bytes; returns the skipping-on frame.
    fn same_on_and_off(cl: &Classified, view: [f64; 3], o: CastOptions, what: &str) -> Frame {
        let model = ModelShader::new(&Config::default(), &Scene::standard());
        let on = ShearWarp::new(cl, view, CastOptions { skip: true, ..o })
            .unwrap()
            .render(&model);
        let off = ShearWarp::new(cl, view, CastOptions { skip: false, ..o })
            .unwrap()
            .render(&model);
        assert_eq!(on.value, off.value, "{what}");
        assert_eq!(on.alpha, off.alpha, "{what}");
        assert_eq!(on.stats.samples, off.stats.samples, "{what}");
        assert_eq!(off.stats.evaluated, off.stats.samples, "{what}");
        let st = on.stats;
        assert_eq!(
            st.empty_skipped + st.terminated + st.evaluated,
            st.samples,
            "{what}"
        );
        on
    }

    #[test]
    fn skipping_does_not_change_the_image() {
        // Views along each principal axis, both ways, and oblique; spacing that is not
        // uniform; the value ramp alone and with a gradient ramp and a minimum opacity,
        // zoomed, with an up direction and voxel axes that are not the world's.
        let views = [
            [-0.5, -0.7, 0.5],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.3, 0.8, -0.6],
            [-0.9, 0.2, -0.3],
        ];
        let axes = [[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]];
        for (spacing, tf, zoom, up, ax, ert) in [
            (
                [1.0; 3],
                Transfer::new(vec![[1100.0, 0.0], [1900.0, 1.0]]),
                1.0,
                None,
                camera::IDENTITY,
                0.99,
            ),
            (
                [1.0, 1.0, 1.5],
                classified_tf(),
                1.6,
                Some([0.3, 1.0, 0.2]),
                axes,
                0.95,
            ),
            (
                [0.8, 1.0, 1.0],
                classified_tf(),
                1.0,
                None,
                camera::IDENTITY,
                1.0,
            ),
        ] {
            let mut vol = synthetic::engine_block([48, 40, 24], spacing).unwrap();
            vol.axes = ax;
            let p = Prepared::new(&vol, 12, 8);
            let cl = Classified::new(&p, &tf).unwrap();
            // One sample per slice and voxel; samples between slices (the slabs' runs) on a
            // finer intermediate image.
            for (view, (slice_samples, supersample)) in
                views.into_iter().flat_map(|v| [(v, (1, 1)), (v, (3, 2))])
            {
                let o = CastOptions {
                    zoom,
                    up,
                    ert,
                    slice_samples,
                    supersample,
                    ..opts(40, true)
                };
                let what = format!(
                    "view {view:?} spacing {spacing:?} tf {tf:?} {slice_samples}/{supersample}"
                );
                let on = same_on_and_off(&cl, view, o, &what);
                assert!(on.stats.skipped_fraction() > 0.3, "{what} {:?}", on.stats);
                assert!(on.stats.shaded > 100, "{what} {:?}", on.stats);
                if ert < 1.0 {
                    assert!(on.stats.terminated > 0, "{what} {:?}", on.stats);
                }
            }
        }
    }

    /// Smoothed noise with a flat lower half, and a gradient-magnitude ramp around its
    /// typical gradients: much of it is transparent by the ramp alone and rays see through
    /// (no termination), so a cell wrongly skipped changes the image.
    #[test]
    fn skipping_on_noise_and_a_planted_wrong_skip_is_caught() {
        let vol = synthetic::smoothed_noise();
        let p = Prepared::new(&vol, 12, 2);
        let tf = Transfer {
            points: vec![[30.0, 0.0], [70.0, 1.0]],
            gradient: Some(vec![[8.0, 0.0], [20.0, 1.0]]),
            min_opacity: Some(0.3),
        };
        let o = CastOptions {
            ert: 1.0,
            ..opts(40, true)
        };
        let views = [[0.2, 0.3, 1.0], [-1.0, 0.5, 0.1], [0.1, -1.0, 0.4]];
        let cl = Classified::new(&p, &tf).unwrap();
        // Samples between slices use the slabs' runs: the same checks for them.
        let between = CastOptions {
            slice_samples: 2,
            supersample: 2,
            ..o
        };
        for view in views {
            let b = same_on_and_off(&cl, view, between, &format!("{view:?} between"));
            assert!(
                b.stats.shaded > 1000 && b.stats.empty_skipped > 0,
                "{:?}",
                b.stats
            );
            let on = same_on_and_off(&cl, view, o, &format!("{view:?}"));
            assert!(
                on.stats.shaded > 1000 && on.stats.empty_skipped > 0,
                "{:?}",
                on.stats
            );
            // The ramp makes cells transparent that the values alone would not.
            let no_ramp = Transfer {
                gradient: None,
                ..tf.clone()
            };
            let plain = Classified::new(&p, &no_ramp).unwrap();
            let sw = ShearWarp::new(&cl, view, o).unwrap();
            let sw_plain = ShearWarp::new(&plain, view, o).unwrap();
            assert!(
                sw.empty_cell_fraction() > sw_plain.empty_cell_fraction() + 0.05,
                "{} {}",
                sw.empty_cell_fraction(),
                sw_plain.empty_cell_fraction()
            );
        }
        // A wrong skip (one scanline of every slice taken as transparent) changes the
        // image, so the comparison above would catch it.
        let model = ModelShader::new(&Config::default(), &Scene::standard());
        for view in views {
            for o in [o, between] {
                let mut wrong = Classified::new(&p, &tf).unwrap();
                wrong.plant_wrong_skip = Some(11);
                let bad = ShearWarp::new(&wrong, view, o).unwrap().render(&model);
                let off = ShearWarp::new(&cl, view, CastOptions { skip: false, ..o })
                    .unwrap()
                    .render(&model);
                assert_ne!(bad.value, off.value, "{view:?} {o:?}");
            }
        }
    }

    #[test]
    fn a_reused_frame_and_intermediate_image_give_the_same_image() {
        // Frames rendered into one buffer (and one kept intermediate image) after other
        // views and sizes: nothing of the earlier frame shows (the warp writes every pixel,
        // the intermediate image is cleared).
        let vol = synthetic::engine_block([48, 40, 24], [1.0, 1.0, 1.5]).unwrap();
        let p = Prepared::new(&vol, 12, 8);
        let cl = Classified::new(&p, &classified_tf()).unwrap();
        let model = ModelShader::new(&Config::default(), &Scene::standard());
        let mut buf = Frame::default();
        for (view, size, supersample) in [
            ([-0.5, -0.7, 0.5], 64, 1),
            ([0.9, 0.1, 0.2], 40, 3),
            ([0.0, 0.0, 1.0], 40, 1),
            ([-0.5, -0.7, 0.5], 48, 2),
        ] {
            let o = CastOptions {
                supersample,
                ..opts(size, true)
            };
            let sw = ShearWarp::new(&cl, view, o).unwrap();
            sw.render_into(&model, &mut buf);
            let fresh = Classified::new(&p, &classified_tf()).unwrap();
            let once = ShearWarp::new(&fresh, view, o).unwrap().render(&model);
            assert!(once.alpha.iter().any(|&a| a > 0.0), "{view:?}");
            assert_eq!(buf, once, "{view:?} {size}");
        }
    }

    #[test]
    fn batch_path_equals_fused_path() {
        let vol = synthetic::engine_block([48, 40, 24], [1.0, 1.0, 1.5]).unwrap();
        let small = Config {
            grad_bits: 10,
            red_bits: 7,
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        };
        // The default design with one sample per slice and voxel; the small one with samples
        // between slices on a finer intermediate image.
        for (cfg, slice_samples, supersample) in [(Config::default(), 1, 1), (small, 2, 2)] {
            let p = Prepared::new(&vol, cfg.grad_bits, 8);
            let cl = Classified::new(&p, &classified_tf()).unwrap();
            let o = CastOptions {
                slice_samples,
                supersample,
                ..opts(40, true)
            };
            let sw = ShearWarp::new(&cl, [-0.4, -0.8, 0.45], o).unwrap();
            let model = ModelShader::new(&cfg, &Scene::standard());
            let fused = sw.render(&model);
            let s = sw.collect().unwrap();
            assert_eq!(s.stats, fused.stats);
            assert!(s.gradients.len() > 1000);
            let shaded: Vec<u32> = s
                .gradients
                .iter()
                .map(|&g| model.model.intensity(&model.maps, g))
                .collect();
            assert_eq!(
                sw.composite(&s, &shaded).unwrap(),
                fused,
                "{}",
                cfg.summary()
            );
            assert!(sw.composite(&s, &shaded[1..]).is_err());
            let e = sw.collect_at_most(s.gradients.len() - 1).unwrap_err();
            assert!(e.to_string().contains("more than"), "{e}");
            // A batch that differs in one sample changes the image.
            let mut off = shaded.clone();
            let i = s.weights.iter().position(|&w| w > 0.2).unwrap();
            off[i] = off[i].wrapping_add(9) % 256;
            assert_ne!(sw.composite(&s, &off).unwrap().value, fused.value);
        }
    }

    /// Whether shear-warp's image of the engine block is close to the ray caster's on
    /// three views (same camera, same shading): the two renderers sample differently
    /// (slices against half-voxel steps, bilinear against trilinear, a warp), so the images
    /// differ a little, but a wrong shear, slice or order differs by more. Returns the
    /// failures, one line each.
    fn geometry_failures(fault: Option<GeometryFault>, sampling: (u32, u32)) -> Vec<String> {
        geometry(fault, sampling).0
    }

    /// [`geometry_failures`] and the mean |difference| on each view.
    fn geometry(fault: Option<GeometryFault>, (n, r): (u32, u32)) -> (Vec<String>, Vec<f64>) {
        let vol = synthetic::engine_block([64, 64, 32], [1.0, 1.0, 1.2]).unwrap();
        let cfg = Config::default();
        let p = Prepared::new(&vol, cfg.grad_bits, 8);
        let tf = Transfer::new(vec![[1100.0, 0.0], [1900.0, 1.0]]);
        let mut cl = Classified::new(&p, &tf).unwrap();
        cl.plant_geometry = fault;
        let model = ModelShader::new(&cfg, &Scene::standard());
        let mut failures = Vec::new();
        let mut means = Vec::new();
        for (view, up) in [
            ([-0.5, -0.7, 0.5], None),
            ([0.6, 0.2, -0.75], Some([0.0, 1.0, 0.0])),
            ([0.0, -1.0, 0.1], None),
        ] {
            let o = CastOptions {
                up,
                slice_samples: n,
                supersample: r,
                ..opts(96, true)
            };
            let sw = ShearWarp::new(&cl, view, o).unwrap().render(&model);
            let ray = Caster::new(&p, &tf, view, o).unwrap().render(&model);
            let (a, b) = (sw.pixels(255), ray.pixels(255));
            let covered = ray.alpha.iter().filter(|&&x| x > 0.5).count();
            let mean = a
                .iter()
                .zip(&b)
                .map(|(&x, &y)| x.abs_diff(y) as f64)
                .sum::<f64>()
                / covered as f64;
            // Opacity masks agree on nearly every pixel.
            let disagree = sw
                .alpha
                .iter()
                .zip(&ray.alpha)
                .filter(|(&x, &y)| (x > 0.5) != (y > 0.5))
                .count();
            assert!(covered > 96 * 96 / 5, "{view:?} {covered}");
            means.push(mean);
            if disagree * 50 >= covered || mean >= GEOMETRY_MEAN {
                failures.push(format!(
                    "{view:?}: {disagree} of {covered} covered pixels disagree, mean |difference| {mean:.2}"
                ));
            }
        }
        (failures, means)
    }

    /// The largest mean |difference| to the ray caster's image (8-bit values over its
    /// covered pixels) the geometry test accepts.
    const GEOMETRY_MEAN: f64 = 12.0;

    #[test]
    fn the_image_matches_the_ray_casters() {
        assert_eq!(geometry_failures(None, (1, 1)), Vec::<String>::new());
    }

    /// The largest ratio of the mean |difference| to the ray caster's image with 4 samples
    /// per slice spacing and 2 intermediate pixels per voxel to the one with 1 and 1 (it is
    /// 0.27 to 0.34 on the three views; a planted sampling fault gives 0.6 or more on some).
    const FINER: f64 = 0.5;

    /// Samples between slices and a finer intermediate image bring the image closer to the
    /// ray caster's on every view (the resampling error shrinks); a sampling that moved the
    /// samples (a wrong weight between slices, a wrong sub-pixel position) would not.
    #[test]
    fn finer_sampling_comes_closer_to_the_ray_casters() {
        let (f, coarse) = geometry(None, (1, 1));
        assert!(f.is_empty(), "{f:?}");
        let (f, fine) = geometry(None, (4, 2));
        assert!(f.is_empty(), "{f:?}");
        eprintln!("coarse {coarse:?} fine {fine:?}");
        for (c, x) in coarse.iter().zip(&fine) {
            assert!(x < &(FINER * c), "coarse {coarse:?}, fine {fine:?}");
        }
    }

    #[test]
    fn a_planted_sampling_fault_is_caught() {
        let (_, coarse) = geometry(None, (1, 1));
        for fault in [
            GeometryFault::WeightBetweenSlices,
            GeometryFault::SubpixelPhase,
        ] {
            let (f, fine) = geometry(Some(fault), (4, 2));
            eprintln!("{fault:?}: {f:?} coarse {coarse:?} fine {fine:?}");
            assert!(
                !f.is_empty() || coarse.iter().zip(&fine).any(|(c, x)| x >= &(FINER * c)),
                "{fault:?} passes"
            );
        }
    }

    #[test]
    fn a_planted_geometry_fault_is_caught() {
        for fault in [
            GeometryFault::ShearSign,
            GeometryFault::SliceOffByOne,
            GeometryFault::ReversedOrder,
        ] {
            for sampling in [(1, 1), (2, 2)] {
                let f = geometry_failures(Some(fault), sampling);
                eprintln!("{fault:?} {sampling:?}: {f:?}");
                assert!(
                    !f.is_empty(),
                    "{fault:?} {sampling:?} passes the geometry test"
                );
            }
        }
    }
}
