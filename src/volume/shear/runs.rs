//! Empty-space skipping at voxel resolution for the shear-warp renderer: for one principal
//! axis, every slice's scanlines as runs of non-transparent cells ([`Runs`]), built once per
//! volume, transfer function and axis ([`Classified`]) and reused by every frame.
//!
//! A slice cell (ca, cb) of slice k spans the four voxels (ca..=ca+1, cb..=cb+1) of that
//! slice; every sample the renderer takes in it is their bilinear interpolation (value and
//! quantised gradient). So, as for [`crate::volume::bricks`]: the sample's value lies in the
//! four voxels' range up to a few f32 ulps (the range is widened by [`WIDEN`]), and its
//! rounded gradient is no longer than the longest of the four plus [`GRAD_MARGIN`]. A cell on
//! which [`Tf::transparent_on`] holds for that range and magnitude holds no visible sample;
//! a run is a maximal stretch of cells along a scanline that are not transparent.
//! Samples between slices k and k + 1 interpolate the 8 voxels of a slab cell; their runs
//! ([`Spans`] with depth 2, built on first use) take the range and gradient over all 8.
//!
//! With the runs, each axis keeps the volume's voxels (value and quantised gradient) in its
//! slice order ([`Runs::voxels`]): a run's samples then read memory in sequence, as
//! VolPack's per-axis copies do, instead of one cache line per sample when the scanline
//! runs across the file's x order.

use super::super::bricks::{GRAD_MARGIN, WIDEN};
use super::super::prepared::Prepared;
use crate::scene::transfer::{Tf, Transfer};
use anyhow::Result;
use rayon::prelude::*;
use std::sync::{Mutex, OnceLock};

/// The two slice axes of principal axis `c`, in memory order (the faster one first): a
/// scanline runs along the first.
pub fn slice_axes(c: usize) -> (usize, usize) {
    match c {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// One voxel in a slice-ordered copy: its value and its quantised gradient.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Voxel {
    pub v: f32,
    pub g: [i16; 3],
}

/// The runs of non-transparent cells of every scanline of every layer: a layer is a slice
/// (cells of 4 voxels, for one sample per slice) or a slab between two consecutive slices
/// (cells of 8 voxels, for samples between the slices).
#[derive(Clone, Debug)]
pub struct Spans {
    /// Scanlines per layer.
    lines: usize,
    /// Scanline (k, cb)'s runs are `spans[start[k * lines + cb]..start[k * lines + cb + 1]]`,
    /// each `[first, end)` in cells, increasing.
    start: Vec<u32>,
    spans: Vec<[u32; 2]>,
    /// Cells per scanline.
    cells: usize,
    /// Cells in runs, over all layers.
    pub visible_cells: u64,
}

impl Spans {
    /// The runs of scanline `cb` of layer `k`.
    #[inline]
    pub fn line(&self, k: usize, cb: usize) -> &[[u32; 2]] {
        let l = k * self.lines + cb;
        &self.spans[self.start[l] as usize..self.start[l + 1] as usize]
    }

    /// Fraction of all cells that are transparent.
    pub fn empty_fraction(&self) -> f64 {
        let n = (self.cells * (self.start.len() - 1)) as f64;
        1.0 - self.visible_cells as f64 / n.max(1.0)
    }

    /// The runs of the `layers` layers of `depth` slices each (1: slice k; 2: slices k and
    /// k + 1) of the slice-ordered `voxels` (`na` x `nb` per slice): `transparent(lo, hi, g)`
    /// says whether a cell whose values lie in `lo..=hi` and whose gradients are at most `g`
    /// long is transparent. `wrong_line` (tests only) plants a wrong skip: that scanline of
    /// every layer is taken as all transparent.
    fn build(
        voxels: &[Voxel],
        [na, nb]: [usize; 2],
        depth: usize,
        transparent: &(dyn Fn(f32, f32, f32) -> bool + Sync),
        wrong_line: Option<usize>,
    ) -> Spans {
        let (cells, lines) = (na - 1, nb - 1);
        let layers = voxels.len() / (na * nb) + 1 - depth;
        let glen = |x: &Voxel| {
            let [gx, gy, gz] = x.g.map(|c| c as f32);
            (gx * gx + gy * gy + gz * gz).sqrt()
        };
        let per_layer: Vec<(Vec<u32>, Vec<[u32; 2]>)> = (0..layers)
            .into_par_iter()
            .map(|k| {
                let layer = &voxels[k * na * nb..(k + depth) * na * nb];
                let mut counts = Vec::with_capacity(lines);
                let mut spans = Vec::new();
                for cb in 0..lines {
                    let before = spans.len();
                    let mut open: Option<u32> = None;
                    for ca in 0..cells {
                        let (mut lo, mut hi, mut g) = (f32::INFINITY, f32::NEG_INFINITY, 0f32);
                        for d in 0..depth {
                            let i = d * na * nb + cb * na + ca;
                            for j in [i, i + 1, i + na, i + na + 1] {
                                lo = lo.min(layer[j].v);
                                hi = hi.max(layer[j].v);
                                g = g.max(glen(&layer[j]));
                            }
                        }
                        let e = lo.abs().max(hi.abs()) * WIDEN + f32::MIN_POSITIVE;
                        let empty =
                            transparent(lo - e, hi + e, g + GRAD_MARGIN) || wrong_line == Some(cb);
                        match (empty, open) {
                            (false, None) => open = Some(ca as u32),
                            (true, Some(s)) => {
                                spans.push([s, ca as u32]);
                                open = None;
                            }
                            _ => {}
                        }
                    }
                    if let Some(s) = open {
                        spans.push([s, cells as u32]);
                    }
                    counts.push((spans.len() - before) as u32);
                }
                (counts, spans)
            })
            .collect();
        let mut start = Vec::with_capacity(layers * lines + 1);
        let mut spans = Vec::new();
        start.push(0u32);
        for (counts, s) in per_layer {
            for n in counts {
                start.push(start.last().unwrap() + n);
            }
            spans.extend(s);
        }
        let visible_cells = spans.iter().map(|s| (s[1] - s[0]) as u64).sum();
        Spans {
            lines,
            start,
            spans,
            cells,
            visible_cells,
        }
    }
}

/// The runs of non-transparent cells of every scanline of every slice (and, when samples
/// between slices are asked for, of every slab between two slices), for one principal axis,
/// and the voxels in slice order.
#[derive(Clone, Debug)]
pub struct Runs {
    /// Voxel (along a, along b, slice k) at `a + na (b + nb k)`.
    pub voxels: Vec<Voxel>,
    /// The principal axis (slices are perpendicular to it).
    pub axis: usize,
    /// Cells per scanline (voxels along the scanline axis minus one).
    pub cells: usize,
    /// Scanlines per slice (voxels along the other slice axis minus one).
    pub lines: usize,
    /// The runs of each slice.
    pub slices: Spans,
    /// The runs of each slab between consecutive slices, built on first use (only a view
    /// with samples between the slices needs them).
    slabs: OnceLock<Spans>,
}

impl Runs {
    /// The runs of scanline `cb` of slice `k`.
    #[inline]
    pub fn line(&self, k: usize, cb: usize) -> &[[u32; 2]] {
        self.slices.line(k, cb)
    }

    /// Fraction of all slice cells that are transparent.
    pub fn empty_fraction(&self) -> f64 {
        self.slices.empty_fraction()
    }

    /// The runs for principal axis `c`: `transparent(lo, hi, g)` says whether a cell whose
    /// values lie in `lo..=hi` and whose gradients are at most `g` long is transparent.
    /// `wrong_line` (tests only) plants a wrong skip: that scanline of every slice is taken
    /// as all transparent.
    fn build(
        p: &Prepared,
        c: usize,
        transparent: &(dyn Fn(f32, f32, f32) -> bool + Sync),
        wrong_line: Option<usize>,
    ) -> Result<Runs> {
        let vol = p.vol;
        let (a, b) = slice_axes(c);
        let d = vol.dims;
        let stride = [1, d[0], d[0] * d[1]];
        let (na, nb) = (d[a], d[b]);
        let (cells, lines) = (na - 1, nb - 1);
        let mut voxels: Vec<Voxel> = Vec::new();
        voxels.try_reserve_exact(vol.data.len()).map_err(|_| {
            anyhow::anyhow!(
                "{}: cannot allocate {} for the shear-warp copy of {} voxels; use --caster ray",
                vol.info.source,
                super::super::human_bytes((std::mem::size_of::<Voxel>() * vol.data.len()) as u64),
                vol.data.len()
            )
        })?;
        voxels.resize(vol.data.len(), Voxel::default());
        voxels
            .par_chunks_mut(na * nb)
            .enumerate()
            .for_each(|(k, slice)| {
                for (jb, row) in slice.chunks_mut(na).enumerate() {
                    let base = k * stride[c] + jb * stride[b];
                    for (ia, o) in row.iter_mut().enumerate() {
                        let i = base + ia * stride[a];
                        *o = Voxel {
                            v: vol.data[i],
                            g: p.grads.data[i],
                        };
                    }
                }
            });
        let slices = Spans::build(&voxels, [na, nb], 1, transparent, wrong_line);
        Ok(Runs {
            voxels,
            axis: c,
            cells,
            lines,
            slices,
            slabs: OnceLock::new(),
        })
    }

    /// The runs of the slabs between consecutive slices (at least two slices), built on
    /// first use with the same classification as the slices'.
    fn slabs(
        &self,
        transparent: &(dyn Fn(f32, f32, f32) -> bool + Sync),
        wrong_line: Option<usize>,
    ) -> &Spans {
        self.slabs.get_or_init(|| {
            Spans::build(
                &self.voxels,
                [self.cells + 1, self.lines + 1],
                2,
                transparent,
                wrong_line,
            )
        })
    }
}

/// A prepared volume classified by one transfer function: its runs for each principal axis,
/// each built the first time a view needs it and kept for every later frame.
pub struct Classified<'a> {
    pub prepared: &'a Prepared<'a>,
    pub transfer: Transfer,
    /// The transfer function for [`Tf::transparent_on`] (which does not depend on the step).
    tf: Tf,
    /// Per axis, the runs or why they could not be built (no memory).
    runs: [OnceLock<std::result::Result<Runs, String>>; 3],
    /// The shear-warp intermediate image's buffer, kept between frames as VolPack's
    /// context keeps its own: a fresh one per frame costs page faults.
    image: Mutex<Vec<[f32; 2]>>,
    /// A deliberately wrong classification for the tests: this scanline of every slice is
    /// marked transparent, to show the skipping tests catch a wrong skip.
    #[cfg(test)]
    pub(crate) plant_wrong_skip: Option<usize>,
    /// A deliberately wrong geometry for the tests ([`super::GeometryFault`]), to show the
    /// geometry test catches one.
    #[cfg(test)]
    pub(crate) plant_geometry: Option<super::GeometryFault>,
}

impl<'a> Classified<'a> {
    pub fn new(prepared: &'a Prepared<'a>, transfer: &Transfer) -> Result<Classified<'a>> {
        transfer.validate()?;
        Ok(Classified {
            prepared,
            transfer: transfer.clone(),
            tf: transfer.compile(1.0, prepared.grads.scale),
            runs: Default::default(),
            image: Mutex::new(Vec::new()),
            #[cfg(test)]
            plant_wrong_skip: None,
            #[cfg(test)]
            plant_geometry: None,
        })
    }

    /// An intermediate image of `len` zero pixels, in the kept buffer when no other render
    /// holds it (then a new one).
    pub fn take_image(&self, len: usize) -> Vec<[f32; 2]> {
        let mut v = self
            .image
            .try_lock()
            .map(|mut b| std::mem::take(&mut *b))
            .unwrap_or_default();
        v.clear();
        v.resize(len, [0.0; 2]);
        v
    }

    /// Keeps `v` for the next frame's [`Self::take_image`].
    pub fn give_image(&self, v: Vec<[f32; 2]>) {
        if let Ok(mut b) = self.image.try_lock() {
            *b = v;
        }
    }

    /// The runs for principal axis `c`, built on first use.
    pub fn runs(&self, c: usize) -> Result<&Runs> {
        let wrong = self.wrong_line();
        self.runs[c]
            .get_or_init(|| {
                Runs::build(
                    self.prepared,
                    c,
                    &|lo, hi, g| self.tf.transparent_on(lo, hi, g),
                    wrong,
                )
                .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(|e| anyhow::anyhow!("{e}"))
    }

    /// The runs of the slabs between consecutive slices for principal axis `c` (the volume
    /// has at least two slices along it), built on first use.
    pub fn slab_runs(&self, c: usize) -> Result<&Spans> {
        let wrong = self.wrong_line();
        Ok(self
            .runs(c)?
            .slabs(&|lo, hi, g| self.tf.transparent_on(lo, hi, g), wrong))
    }

    /// The planted wrong skip's scanline (tests only).
    fn wrong_line(&self) -> Option<usize> {
        #[cfg(test)]
        let wrong = self.plant_wrong_skip;
        #[cfg(not(test))]
        let wrong = None;
        wrong
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::{Volume, VolumeInfo};

    #[test]
    fn runs_cover_exactly_the_visible_cells() {
        // 6 x 5 x 4, value = x * 10: with a transfer function rising from 25, cells whose
        // four voxels reach past 25 (x >= 2, i.e. cells 2..5 along x) are visible.
        let mut d = Vec::new();
        for _ in 0..20 {
            d.extend((0..6).map(|x| x as f32 * 10.0));
        }
        let vol = Volume::new(
            [6, 5, 4],
            [1.0; 3],
            d,
            VolumeInfo {
                source: "t".into(),
                voxel_type: "float".into(),
            },
        )
        .unwrap();
        let p = Prepared::new(&vol, 12, 2);
        let c = Classified::new(&p, &Transfer::new(vec![[25.0, 0.0], [50.0, 1.0]])).unwrap();
        // Principal axis z: scanlines along x, 5 cells, 4 lines, 4 slices.
        let r = c.runs(2).unwrap();
        assert_eq!((r.cells, r.lines), (5, 4));
        for k in 0..4 {
            for cb in 0..4 {
                assert_eq!(r.line(k, cb), &[[2, 5]]);
            }
        }
        // Principal axis x: scanlines along y; slice x = 0, 1 and 2 hold values <= 20.
        let r = c.runs(0).unwrap();
        assert_eq!((r.cells, r.lines), (4, 3));
        assert!(r.line(1, 0).is_empty() && r.line(2, 0).is_empty());
        assert_eq!(r.line(3, 2), &[[0, 4]]);
        assert_eq!(r.slices.visible_cells, 3 * 4 * 3);
        // Slabs between slices x = k and k + 1: visible from k = 2 (values 20 and 30) on.
        let slabs = c.slab_runs(0).unwrap();
        assert!(slabs.line(1, 0).is_empty());
        assert_eq!(slabs.line(2, 1), &[[0, 4]]);
        assert_eq!(slabs.visible_cells, 3 * 4 * 3);
        // Along z, every slab is as its slices.
        let slabs = c.slab_runs(2).unwrap();
        assert_eq!(slabs.line(2, 3), &[[2, 5]]);
        assert_eq!(slabs.visible_cells, 3 * 3 * 4);
        // The slice-ordered copy: voxel (y, z) = (2, 3) of slice x = 4.
        let v = r.voxels[2 + 5 * (3 + 4 * 4)];
        assert_eq!((v.v, v.g), (40.0, p.grads.data[vol.index(4, 2, 3)]));
        // Everything transparent: no runs.
        let none = Classified::new(&p, &Transfer::new(vec![[60.0, 0.0], [70.0, 1.0]])).unwrap();
        assert_eq!(none.runs(1).unwrap().slices.visible_cells, 0);
        assert_eq!(none.runs(1).unwrap().empty_fraction(), 1.0);
    }
}
