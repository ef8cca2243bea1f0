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
    /// Index strides along c, a and b in the runs' slice-ordered voxels.
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
        // The slice whose shift slice k takes (k itself; the next one for a planted fault).
        #[cfg(not(test))]
        let shifted = |k: usize| k;
        #[cfg(test)]
        let shifted = |k: usize| match cl.plant_geometry {
            Some(GeometryFault::SliceOffByOne) => k + 1,
            _ => k,
        };
        // shift(k) = k s - off lies in [-(nc - 1)|s|, 0], so every intermediate index is >= 0.
        let (oa, ob) = (
            (sa * (nc - 1) as f64).max(0.0),
            (sb * (nc - 1) as f64).max(0.0),
        );
        let slices: Vec<Slice> = (0..nc)
            .map(|k| {
                let k = shifted(k) as f64;
                let (ha, hb) = (k * sa - oa, k * sb - ob);
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
        let forward = dv[c] > 0.0;
        #[cfg(test)]
        let forward = forward != (cl.plant_geometry == Some(GeometryFault::ReversedOrder));
        Ok(ShearWarp {
            cl,
            runs: cl.runs(c)?,
            tf,
            camera,
            opts,
            axes: [c, a, b],
            stride: [d[a] * d[b], 1, d[a]],
            forward,
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
        let nc = self.slices.len();
        let pw = self.width + 2;
        let tf = &self.tf;
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let mut bbox = Bbox::EMPTY;
        // Early ray termination without visiting opaque pixels (VolPack's pixel skip links):
        // `link[p]` is 0 for a pixel still open, else a distance to jump towards the next
        // open pixel of its row (shortened as chains are followed).
        let mut link = vec![0u32; im.len()];
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
                let row = (j - rows.start) * pw + 1 + sl.i0;
                // The row's right border pixel: never opaque, so every chain stops there.
                let row_end = (j - rows.start) * pw + 1 + self.width;
                let base = k * sc + cb * sb;
                let mut visited = 0u64;
                for &[first, end] in spans {
                    visited += (end - first) as u64;
                    let mut ca = first as usize;
                    while ca < end as usize {
                        let px = row + ca;
                        if skip && link[px] != 0 {
                            // Follow the chain to the next open pixel (or the row's end).
                            let mut q = px;
                            while q < row_end && link[q] != 0 {
                                q += link[q] as usize;
                            }
                            // Path compression: every pixel on the chain now points at q,
                            // so a later run starting inside the stretch jumps at once.
                            let mut r = px;
                            while r < q {
                                let next = r + link[r] as usize;
                                link[r] = (q - r) as u32;
                                r = next;
                            }
                            let next = (ca + q - px).min(end as usize);
                            st.terminated += (next - ca) as u64;
                            ca = next;
                            continue;
                        }
                        ca += 1;
                        let before = im[px][1];
                        st.evaluated += 1;
                        let i = base + (ca - 1) * sa;
                        let (q00, q10, q01, q11) =
                            (vox[i], vox[i + sa], vox[i + sb], vox[i + sa + sb]);
                        let v = lerp(lerp(q00.v, q10.v, fa), lerp(q01.v, q11.v, fa), fb);
                        let o = tf.value_opacity(v);
                        if skip && o == 0.0 {
                            continue;
                        }
                        let (g00, g10, g01, g11) = (q00.g, q10.g, q01.g, q11.g);
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
                            im[px][0] += sink(px, w, g);
                        }
                        let after = before + w;
                        if after > 0.0 {
                            bbox.add(sl.i0 + ca - 1, j);
                        }
                        if after >= ert {
                            im[px][1] = 1.0;
                            link[px] = 1;
                        } else {
                            im[px][1] = after;
                        }
                    }
                }
                st.empty_skipped += cells as u64 - visited;
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
                let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
                for x in x0..x1 {
                    let xf = x as f64;
                    // Padded positions.
                    let (pi, pj) = (i0 + m[1] * xf + 1.0, j0 + m[4] * xf + 1.0);
                    if pi <= bi.0 + 1.0 || pj <= bj.0 + 1.0 || pi >= bi.1 + 1.0 || pj >= bj.1 + 1.0
                    {
                        vr[x] = 0.0;
                        ar[x] = 0.0;
                        continue;
                    }
                    let (i, j) = (pi as u32 as usize, pj as u32 as usize);
                    let (ti, tj) = ((pi - i as f64) as f32, (pj - j as f64) as f32);
                    let q = j * pw + i;
                    let (p00, p10, p01, p11) = (im[q], im[q + 1], im[q + pw], im[q + pw + 1]);
                    vr[x] = lerp(lerp(p00[0], p10[0], ti), lerp(p01[0], p11[0], ti), tj);
                    ar[x] = lerp(lerp(p00[1], p10[1], ti), lerp(p01[1], p11[1], ti), tj);
                }
            });
    }
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
            for view in views {
                let o = CastOptions {
                    zoom,
                    up,
                    ert,
                    ..opts(40, true)
                };
                let what = format!("view {view:?} spacing {spacing:?} tf {tf:?}");
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
        for view in views {
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
            let mut wrong = Classified::new(&p, &tf).unwrap();
            wrong.plant_wrong_skip = Some(11);
            let bad = ShearWarp::new(&wrong, view, o).unwrap().render(&model);
            let off = ShearWarp::new(&cl, view, CastOptions { skip: false, ..o })
                .unwrap()
                .render(&model);
            assert_ne!(bad.value, off.value, "{view:?}");
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
        for (view, size) in [
            ([-0.5, -0.7, 0.5], 64),
            ([0.9, 0.1, 0.2], 40),
            ([0.0, 0.0, 1.0], 40),
            ([-0.5, -0.7, 0.5], 48),
        ] {
            let sw = ShearWarp::new(&cl, view, opts(size, true)).unwrap();
            sw.render_into(&model, &mut buf);
            let fresh = Classified::new(&p, &classified_tf()).unwrap();
            let once = ShearWarp::new(&fresh, view, opts(size, true))
                .unwrap()
                .render(&model);
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
        for cfg in [Config::default(), small] {
            let p = Prepared::new(&vol, cfg.grad_bits, 8);
            let cl = Classified::new(&p, &classified_tf()).unwrap();
            let sw = ShearWarp::new(&cl, [-0.4, -0.8, 0.45], opts(40, true)).unwrap();
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
    fn geometry_failures(fault: Option<GeometryFault>) -> Vec<String> {
        let vol = synthetic::engine_block([64, 64, 32], [1.0, 1.0, 1.2]).unwrap();
        let cfg = Config::default();
        let p = Prepared::new(&vol, cfg.grad_bits, 8);
        let tf = Transfer::new(vec![[1100.0, 0.0], [1900.0, 1.0]]);
        let mut cl = Classified::new(&p, &tf).unwrap();
        cl.plant_geometry = fault;
        let model = ModelShader::new(&cfg, &Scene::standard());
        let mut failures = Vec::new();
        for (view, up) in [
            ([-0.5, -0.7, 0.5], None),
            ([0.6, 0.2, -0.75], Some([0.0, 1.0, 0.0])),
            ([0.0, -1.0, 0.1], None),
        ] {
            let o = CastOptions {
                up,
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
            if disagree * 50 >= covered || mean >= GEOMETRY_MEAN {
                failures.push(format!(
                    "{view:?}: {disagree} of {covered} covered pixels disagree, mean |difference| {mean:.2}"
                ));
            }
        }
        failures
    }

    /// The largest mean |difference| to the ray caster's image (8-bit values over its
    /// covered pixels) the geometry test accepts.
    const GEOMETRY_MEAN: f64 = 12.0;

    #[test]
    fn the_image_matches_the_ray_casters() {
        assert_eq!(geometry_failures(None), Vec::<String>::new());
    }

    #[test]
    fn a_planted_geometry_fault_is_caught() {
        for fault in [
            GeometryFault::ShearSign,
            GeometryFault::SliceOffByOne,
            GeometryFault::ReversedOrder,
        ] {
            let f = geometry_failures(Some(fault));
            eprintln!("{fault:?}: {f:?}");
            assert!(!f.is_empty(), "{fault:?} passes the geometry test");
        }
    }
}
