//! Empty-space skipping: the voxel values are split into bricks of `size`³ cells, and each
//! brick keeps the smallest and largest value any sample inside it can interpolate from,
//! with a margin. A brick on which the transfer function is zero over that whole range
//! holds no sample with a non-zero opacity, and the ray caster jumps over it.
//!
//! The brick size is a power of two, so a sample's brick is found with shifts.
//!
//! Brick (bx, by, bz) covers the cells `b * size .. (b + 1) * size` along each axis (cell c
//! spans voxels c and c + 1). Its range is taken over the voxels `b * size - 1 ..= (b + 1) *
//! size + 1` (clipped to the volume): one voxel more on each side than the cells need, so a
//! sample whose position rounding puts it a little outside the brick's box is still covered.
//! Trilinear interpolation is a convex combination, so every sample's value lies in the
//! range up to the rounding of the caster's nested `a + (b - a) * t` (a few f32 ulps); the
//! range is widened by 2^-18 of its largest magnitude (32 ulps) to cover that.
//!
//! For a transfer function with a gradient-magnitude ramp, each brick also keeps the largest
//! magnitude of its voxels' quantised gradients (same voxels), plus [`GRAD_MARGIN`]: a
//! sample's gradient is a convex combination of eight of them (no longer than the longest)
//! rounded per component (at most 0.5 each, sqrt(3)/2 in all). A brick whose largest value
//! opacity times the ramp's largest factor up to that magnitude is below the minimum opacity
//! (or zero) holds no visible sample either.

use super::Volume;
use crate::scene::transfer::Tf;
use rayon::prelude::*;

/// Relative widening of a brick's range.
pub const WIDEN: f32 = 1.0 / (1 << 18) as f32;

/// Added to a brick's largest gradient magnitude (LSBs): the rounding of an interpolated
/// gradient (sqrt(3)/2) and of the f32 magnitude, with room to spare.
pub const GRAD_MARGIN: f32 = 1.0;

#[derive(Clone, Debug)]
pub struct Bricks {
    /// Cells per brick along each axis.
    pub size: usize,
    /// Bricks along each axis: ceil(cells / size), cells = voxels - 1.
    pub counts: [usize; 3],
    /// (min, max) of each brick, x fastest.
    pub ranges: Vec<(f32, f32)>,
    /// Largest quantised gradient magnitude of each brick's voxels plus [`GRAD_MARGIN`].
    pub grad_max: Vec<f32>,
}

impl Bricks {
    /// Brick ranges for bricks of `size` cells per side, a power of two; `grads` are the
    /// volume's quantised gradients, one per voxel.
    pub fn new(vol: &Volume, size: usize, grads: &[[i16; 3]]) -> Bricks {
        assert_eq!(grads.len(), vol.data.len(), "one gradient per voxel");
        assert!(size.is_power_of_two(), "brick size {size}");
        let counts = vol.dims.map(|n| (n - 1).div_ceil(size));
        let [cx, cy, cz] = counts;
        let span = |b: usize, n: usize| {
            (
                (b * size).saturating_sub(1),
                ((b + 1) * size + 1).min(n - 1),
            )
        };
        let both: Vec<((f32, f32), f32)> = (0..cx * cy * cz)
            .into_par_iter()
            .map(|i| {
                let (bx, by, bz) = (i % cx, (i / cx) % cy, i / (cx * cy));
                let (x0, x1) = span(bx, vol.dims[0]);
                let (y0, y1) = span(by, vol.dims[1]);
                let (z0, z1) = span(bz, vol.dims[2]);
                let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                let mut g2 = 0i64;
                for z in z0..=z1 {
                    for y in y0..=y1 {
                        let row = vol.index(0, y, z);
                        for &v in &vol.data[row + x0..=row + x1] {
                            lo = lo.min(v);
                            hi = hi.max(v);
                        }
                        for g in &grads[row + x0..=row + x1] {
                            let [a, b, c] = g.map(|c| c as i64);
                            g2 = g2.max(a * a + b * b + c * c);
                        }
                    }
                }
                let e = lo.abs().max(hi.abs()) * WIDEN + f32::MIN_POSITIVE;
                ((lo - e, hi + e), (g2 as f64).sqrt() as f32 + GRAD_MARGIN)
            })
            .collect();
        let (ranges, grad_max) = both.into_iter().unzip();
        Bricks {
            size,
            counts,
            ranges,
            grad_max,
        }
    }

    /// The brick holding cell (cx, cy, cz).
    #[inline]
    pub fn of_cell(&self, c: [usize; 3]) -> usize {
        let shift = self.size.trailing_zeros();
        let b = c.map(|v| v >> shift);
        b[0] + self.counts[0] * (b[1] + self.counts[1] * b[2])
    }

    /// For each brick, whether the transfer function is transparent over its whole range.
    pub fn empty(&self, tf: &Tf) -> Vec<bool> {
        self.ranges
            .iter()
            .zip(&self.grad_max)
            .map(|(&(lo, hi), &g)| tf.transparent_on(lo, hi, g))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::transfer::Transfer;
    use crate::volume::VolumeInfo;

    #[test]
    fn ranges_include_the_margin() {
        // 10 x 4 x 4, value = x; bricks of 4 cells along x: cells 0..4, 4..8, 8..9.
        let mut d = Vec::new();
        for _ in 0..16 {
            d.extend((0..10).map(|x| x as f32));
        }
        let v = Volume::new(
            [10, 4, 4],
            [1.0; 3],
            d,
            VolumeInfo {
                source: "t".into(),
                voxel_type: "u8".into(),
            },
        )
        .unwrap();
        let b = Bricks::new(&v, 4, &vec![[0; 3]; v.data.len()]);
        assert_eq!(b.counts, [3, 1, 1]);
        let want = [(0.0, 5.0), (3.0, 9.0), (7.0, 9.0)];
        for (&(lo, hi), (wlo, whi)) in b.ranges.iter().zip(want) {
            assert!(
                lo < wlo && lo > wlo - 1e-4 && hi > whi && hi < whi + 1e-4,
                "{lo} {hi}"
            );
        }
        assert_eq!(b.of_cell([5, 2, 2]), 1);
        assert_eq!(b.of_cell([8, 0, 0]), 2);
        let tf = Transfer::new(vec![[5.5, 0.0], [6.0, 1.0]]).compile(1.0, 1.0);
        assert_eq!(b.empty(&tf), vec![true, false, false]);
    }

    #[test]
    fn a_breakpoint_at_the_brick_maximum_is_not_skipped_wrongly() {
        // Values 0..=1100 and a transfer function that starts rising at 1100: rounding in
        // interpolation may give 1100 + 1 ulp, where the opacity is not zero.
        let d: Vec<f32> = (0..8).map(|i| if i == 7 { 1100.0 } else { 0.0 }).collect();
        let v = Volume::new(
            [2, 2, 2],
            [1.0; 3],
            d,
            VolumeInfo {
                source: "t".into(),
                voxel_type: "float".into(),
            },
        )
        .unwrap();
        let b = Bricks::new(&v, 8, &vec![[0; 3]; v.data.len()]);
        let tf = Transfer::new(vec![[1100.0, 0.0], [1200.0, 1.0]]).compile(1.0, 1.0);
        assert!(tf.opacity(f32::from_bits(1100.0f32.to_bits() + 1)) > 0.0);
        assert_eq!(b.empty(&tf), vec![false]);
        let below = Transfer::new(vec![[1101.0, 0.0], [1200.0, 1.0]]).compile(1.0, 1.0);
        assert_eq!(b.empty(&below), vec![true]);
    }
}
