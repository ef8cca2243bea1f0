//! The built-in dataset: a machined, engine-block-like part, 256 x 256 x 128 voxels (z up),
//! 16-bit values like a 12-bit CT scan. So the README demo and the tests need no download.
//!
//! The part is a signed distance function (in "part units": the full-size grid, 256 x 256 x
//! 128) built from solids: a rounded block on a wider base flange, joined by a fillet (a
//! smooth union); four cylinder bores through the deck with rounded edges; a crank tunnel
//! along x that the bores open into; six ribs on each long side, filleted to the wall; a
//! bored boss on each end; head-bolt holes in the deck and bolt holes through the flange.
//! A voxel's value is `AIR + (METAL - AIR) * smoothstep(0.5 - d / BAND)` (partial volume
//! over about two voxels, like a scanner's blur) plus uniform integer noise in
//! `-NOISE..=NOISE` from a hash of the voxel's coordinates, rounded and clamped to 0..=4095.
//!
//! Deterministic: only `+ - * /`, `sqrt`, `min`, `max` and `abs` in f64 (all exactly rounded
//! by IEEE 754, so every platform computes the same bits) and an integer hash; parallel
//! work writes disjoint slices. Other sizes scale the same part onto their grid (the tests
//! use 64 x 64 x 32).
//!
//! Fast: the distance function is Lipschitz-continuous with constant 1 (every operation
//! used keeps that), so a block whose centre is farther from the surface than the block's
//! half diagonal plus half the band is entirely air or entirely metal, and only its noise is
//! computed: 8³ blocks first, then 2³ blocks inside the rest, then single voxels. The result
//! is bit-identical to evaluating every voxel (a test checks it).

use super::{Volume, VolumeInfo};
use rayon::prelude::*;

/// Full-size dimensions.
pub const DIMS: [usize; 3] = [256, 256, 128];
/// Value of air and of metal, before noise.
pub const AIR: f64 = 80.0;
pub const METAL: f64 = 2900.0;
/// Noise amplitude (uniform integers in -NOISE..=NOISE).
pub const NOISE: i64 = 30;
/// Width of the partial-volume band, in voxels.
pub const BAND: f64 = 2.0;
/// Largest value (12-bit data).
pub const MAX_VALUE: f64 = 4095.0;

type V3 = [f64; 3];

#[inline]
fn len2(a: f64, b: f64) -> f64 {
    (a * a + b * b).sqrt()
}

#[inline]
fn len3(a: f64, b: f64, c: f64) -> f64 {
    (a * a + b * b + c * c).sqrt()
}

/// Box centred at `c` with half sizes `h`, edges rounded by `r` (exact distance).
#[inline]
fn rbox(p: V3, c: V3, h: V3, r: f64) -> f64 {
    let q = [
        (p[0] - c[0]).abs() - (h[0] - r),
        (p[1] - c[1]).abs() - (h[1] - r),
        (p[2] - c[2]).abs() - (h[2] - r),
    ];
    len3(q[0].max(0.0), q[1].max(0.0), q[2].max(0.0)) + q[0].max(q[1]).max(q[2]).min(0.0) - r
}

/// Capped cylinder: radial distance `radial` from the axis, radius `r`, axial coordinate
/// `a` within `a0..a1` (exact distance).
#[inline]
fn cyl(radial: f64, r: f64, a: f64, a0: f64, a1: f64) -> f64 {
    let dr = radial - r;
    let da = (a - 0.5 * (a0 + a1)).abs() - 0.5 * (a1 - a0);
    dr.max(da).min(0.0) + len2(dr.max(0.0), da.max(0.0))
}

/// Cylinder along z through (cx, cy).
#[inline]
fn cyl_z(p: V3, cx: f64, cy: f64, r: f64, z0: f64, z1: f64) -> f64 {
    cyl(len2(p[0] - cx, p[1] - cy), r, p[2], z0, z1)
}

/// Cylinder along x through (cy, cz).
#[inline]
fn cyl_x(p: V3, cy: f64, cz: f64, r: f64, x0: f64, x1: f64) -> f64 {
    cyl(len2(p[1] - cy, p[2] - cz), r, p[0], x0, x1)
}

/// Smooth union (polynomial smooth minimum, radius k): a fillet of about k where two
/// solids meet. Its gradient is a convex combination of theirs, so it stays 1-Lipschitz.
#[inline]
fn smin(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// Smooth subtraction of `b` from `a`: a rounded edge of about k.
#[inline]
fn ssub(a: f64, b: f64, k: f64) -> f64 {
    -smin(-a, b, k)
}

/// The value in `values` nearest to `x`.
#[inline]
fn nearest(x: f64, values: &[f64]) -> f64 {
    let mut best = values[0];
    for &v in &values[1..] {
        if (x - v).abs() < (x - best).abs() {
            best = v;
        }
    }
    best
}

const RIB_X: [f64; 6] = [48.0, 80.0, 112.0, 144.0, 176.0, 208.0];
const BORE_X: [f64; 4] = [62.0, 106.0, 150.0, 194.0];
const HEAD_BOLT_X: [f64; 5] = [40.0, 84.0, 128.0, 172.0, 216.0];
const FLANGE_BOLT_X: [f64; 5] = [22.0, 70.0, 128.0, 186.0, 234.0];

/// Signed distance to the part (negative inside), in part units.
pub fn distance(p: V3) -> f64 {
    // The part is symmetric about y = 128: fold y onto the low side for the repeated
    // features (ribs, bolt holes) and evaluate only the nearest copy of each.
    let fy = 128.0 - (p[1] - 128.0).abs();
    let pf = [p[0], fy, p[2]];

    let body = rbox(p, [128.0, 128.0, 62.0], [100.0, 84.0, 40.0], 5.0);
    let flange = rbox(p, [128.0, 128.0, 19.0], [112.0, 98.0, 6.0], 3.0);
    let mut d = smin(body, flange, 8.0);

    let rib = rbox(
        pf,
        [nearest(p[0], &RIB_X), 40.0, 60.0],
        [2.5, 5.0, 34.0],
        1.0,
    );
    d = smin(d, rib, 4.0);
    let front_boss = cyl_x(p, 128.0, 64.0, 22.0, 14.0, 40.0);
    d = smin(d, front_boss, 6.0);
    let rear_boss = cyl_x(p, 100.0, 70.0, 16.0, 216.0, 242.0);
    d = smin(d, rear_boss, 5.0);

    let bore = cyl_z(p, nearest(p[0], &BORE_X), 128.0, 19.0, 40.0, 140.0);
    d = ssub(d, bore, 3.0);
    let tunnel = cyl_x(p, 128.0, 30.0, 28.0, 34.0, 222.0);
    d = d.max(-tunnel);
    let front_bore = cyl_x(p, 128.0, 64.0, 10.0, 0.0, 40.0);
    d = ssub(d, front_bore, 2.0);
    let rear_bore = cyl_x(p, 100.0, 70.0, 7.0, 210.0, 256.0);
    d = ssub(d, rear_bore, 2.0);
    let head_bolt = cyl_z(pf, nearest(p[0], &HEAD_BOLT_X), 96.0, 3.5, 74.0, 110.0);
    d = d.max(-head_bolt);
    let flange_bolt = cyl_z(pf, nearest(p[0], &FLANGE_BOLT_X), 36.0, 3.0, 0.0, 40.0);
    d.max(-flange_bolt)
}

/// SplitMix64 finaliser.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The noise of voxel (x, y, z): a uniform integer in -NOISE..=NOISE.
#[inline]
pub fn noise(x: usize, y: usize, z: usize) -> i64 {
    let h = mix((x as u64) | (y as u64) << 21 | (z as u64) << 42);
    (h % (2 * NOISE as u64 + 1)) as i64 - NOISE
}

/// The grid's mapping onto the part: voxel i along an axis sits at part coordinate
/// (i + 0.5) * scale.
struct Grid {
    scale: V3,
    /// Band width in part units.
    band: f64,
}

impl Grid {
    fn new(dims: [usize; 3]) -> Grid {
        let scale = [0, 1, 2].map(|a| DIMS[a] as f64 / dims[a] as f64);
        Grid {
            scale,
            band: BAND * scale[0].max(scale[1]).max(scale[2]),
        }
    }

    #[inline]
    fn point(&self, x: usize, y: usize, z: usize) -> V3 {
        [
            (x as f64 + 0.5) * self.scale[0],
            (y as f64 + 0.5) * self.scale[1],
            (z as f64 + 0.5) * self.scale[2],
        ]
    }

    /// Metal fraction at a distance: smoothstep over the band.
    #[inline]
    fn fraction(&self, d: f64) -> f64 {
        let s = (0.5 - d / self.band).clamp(0.0, 1.0);
        s * s * (3.0 - 2.0 * s)
    }

    #[inline]
    fn value(&self, fraction: f64, x: usize, y: usize, z: usize) -> u16 {
        let v = AIR + (METAL - AIR) * fraction + noise(x, y, z) as f64;
        super::gradient::round_half_away(v).clamp(0, MAX_VALUE as i64) as u16
    }
}

/// The part on a `dims` grid, every voxel evaluated (the definition; slow).
pub fn values_direct(dims: [usize; 3]) -> Vec<u16> {
    let g = Grid::new(dims);
    let [nx, ny, nz] = dims;
    let mut out = vec![0u16; nx * ny * nz];
    out.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(z, slice)| {
            for y in 0..ny {
                for x in 0..nx {
                    slice[x + nx * y] = g.value(g.fraction(distance(g.point(x, y, z))), x, y, z);
                }
            }
        });
    out
}

/// Sides of the blocks classified at once: 8³ blocks, then 2³ blocks inside those that are
/// not uniform, then single voxels.
const LEVELS: [usize; 2] = [8, 2];

/// A box of voxels, [lo, hi) along each axis.
type Span = [[usize; 2]; 3];

impl Grid {
    /// Whether every voxel of `s` is farther than half the band from the surface: `Some`
    /// metal fraction (0 or 1) if so. The distance function is 1-Lipschitz, so every voxel's
    /// distance is within the half diagonal of the box's centre's; the margin of 1e-6 part
    /// units covers rounding in the distance function.
    fn uniform(&self, s: &Span) -> Option<f64> {
        let mid = |a: usize| (s[a][0] + s[a][1] - 1) as f64 * 0.5 + 0.5;
        let half = |a: usize| (s[a][1] - 1 - s[a][0]) as f64 * 0.5 * self.scale[a];
        let dc = distance([
            mid(0) * self.scale[0],
            mid(1) * self.scale[1],
            mid(2) * self.scale[2],
        ]);
        let r = len3(half(0), half(1), half(2)) + 0.5 * self.band + 1e-6;
        if dc >= r {
            Some(0.0)
        } else if dc <= -r {
            Some(1.0)
        } else {
            None
        }
    }

    /// Fills the voxels of `s` into `slab` (whose first z-slice is `z0`), classifying blocks
    /// of the sizes in `levels` first.
    fn fill(&self, s: Span, levels: &[usize], slab: &mut [u16], z0: usize, nx: usize, ny: usize) {
        let put = |slab: &mut [u16], x: usize, y: usize, z: usize, f: f64| {
            slab[x + nx * (y + ny * (z - z0))] = self.value(f, x, y, z);
        };
        match levels.split_first() {
            None => {
                for z in s[2][0]..s[2][1] {
                    for y in s[1][0]..s[1][1] {
                        for x in s[0][0]..s[0][1] {
                            put(slab, x, y, z, self.fraction(distance(self.point(x, y, z))));
                        }
                    }
                }
            }
            Some((&b, rest)) => {
                for bz in (s[2][0]..s[2][1]).step_by(b) {
                    for by in (s[1][0]..s[1][1]).step_by(b) {
                        for bx in (s[0][0]..s[0][1]).step_by(b) {
                            let sub = [
                                [bx, (bx + b).min(s[0][1])],
                                [by, (by + b).min(s[1][1])],
                                [bz, (bz + b).min(s[2][1])],
                            ];
                            match self.uniform(&sub) {
                                Some(f) => {
                                    for z in sub[2][0]..sub[2][1] {
                                        for y in sub[1][0]..sub[1][1] {
                                            for x in sub[0][0]..sub[0][1] {
                                                put(slab, x, y, z, f);
                                            }
                                        }
                                    }
                                }
                                None => self.fill(sub, rest, slab, z0, nx, ny),
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The part on a `dims` grid, with uniform blocks of air or metal classified from their
/// centre's distance. Bit-identical to [`values_direct`].
pub fn values(dims: [usize; 3]) -> Vec<u16> {
    let g = Grid::new(dims);
    let [nx, ny, nz] = dims;
    let slab = LEVELS[0];
    let mut out = vec![0u16; nx * ny * nz];
    out.par_chunks_mut(nx * ny * slab)
        .enumerate()
        .for_each(|(bz, part)| {
            let z0 = bz * slab;
            g.fill(
                [[0, nx], [0, ny], [z0, (z0 + slab).min(nz)]],
                &LEVELS,
                part,
                z0,
                nx,
                ny,
            );
        });
    out
}

/// The synthetic part as a volume (unit spacing unless given).
pub fn engine_block(dims: [usize; 3], spacing: [f64; 3]) -> anyhow::Result<Volume> {
    super::check_dims(dims.map(|n| n as i64), "synthetic volume")?;
    let data = values(dims).into_iter().map(|v| v as f32).collect();
    let info = VolumeInfo {
        source: format!("synthetic engine block {}x{}x{}", dims[0], dims[1], dims[2]),
        voxel_type: "ushort".into(),
    };
    Volume::new(dims, spacing, data, info)
}

/// FNV-1a of the little-endian bytes: a fingerprint of a volume's values.
pub fn fingerprint(values: &[u16]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for v in values {
        for b in v.to_le_bytes() {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// Test volume shared by the casters' skipping tests: 24^3 smoothed noise (two box blurs along
/// x give gradients of all sizes) with a flat lower half (opaque by value, transparent by a
/// gradient-magnitude ramp), so much of it is transparent by the ramp alone and rays see
/// through: a cell or brick wrongly skipped changes the image.
#[cfg(test)]
pub(crate) fn smoothed_noise() -> super::Volume {
    let n = 24;
    let mut seed = 12345u64;
    let mut d: Vec<f32> = (0..n * n * n)
        .map(|_| {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32 * 100.0
        })
        .collect();
    for _ in 0..2 {
        let c = d.clone();
        for i in 1..d.len() - 1 {
            d[i] = (c[i - 1] + c[i] + c[i + 1]) / 3.0;
        }
    }
    for v in &mut d[..n * n * n / 2] {
        *v = 60.0;
    }
    let info = super::VolumeInfo {
        source: "noise".into(),
        voxel_type: "float".into(),
    };
    super::Volume::new([n, n, n], [1.0; 3], d, info).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_classification_is_exact() {
        for dims in [[64, 64, 32], [50, 37, 21]] {
            assert_eq!(values(dims), values_direct(dims), "{dims:?}");
        }
    }

    #[test]
    fn deterministic_and_pinned() {
        let a = values([64, 64, 32]);
        assert_eq!(a, values([64, 64, 32]));
        // Pinned so an accidental change to the part (or a platform computing different
        // bits) is caught; update deliberately when the part is changed.
        assert_eq!(
            fingerprint(&a),
            PINNED_64_64_32,
            "fingerprint {:#x}",
            fingerprint(&a)
        );
    }

    const PINNED_64_64_32: u64 = 0x9bf9_32d5_96be_c73e;

    #[test]
    fn shape_is_an_engine_block() {
        let p = |x: f64, y: f64, z: f64| distance([x, y, z]);
        assert!(p(128.0, 60.0, 60.0) < 0.0, "solid wall beside the bores");
        assert!(p(62.0, 128.0, 80.0) > 0.0, "inside a bore");
        assert!(p(128.0, 128.0, 30.0) > 0.0, "crank tunnel");
        assert!(p(128.0, 128.0, 5.0) > 0.0, "below the flange");
        assert!(p(20.0, 128.0, 20.0) < 0.0, "flange");
        assert!(
            p(80.0, 38.0, 60.0) < 0.0 && p(64.0, 38.0, 60.0) > 0.0,
            "rib and the gap beside it"
        );
        assert!(
            p(84.0, 96.0, 95.0) > 0.0 && p(84.0, 160.0, 95.0) > 0.0,
            "head bolt holes"
        );
        assert!(
            p(70.0, 36.0, 20.0) > 0.0 && p(70.0, 220.0, 20.0) > 0.0,
            "flange bolt holes"
        );
        assert!(
            p(20.0, 128.0, 64.0) > 0.0 && p(20.0, 128.0, 80.0) < 0.0,
            "bored front boss"
        );
        assert!(
            p(128.0, 128.0, 120.0) > 0.0 && p(2.0, 2.0, 2.0) > 0.0,
            "air"
        );
        // Fillet: inside the concave corner of body and flange the smooth union adds metal.
        assert!(p(27.0, 100.0, 26.5) < 0.0);
    }

    #[test]
    fn values_and_noise() {
        let v = values([64, 64, 32]);
        let (lo, hi) = (v.iter().min().unwrap(), v.iter().max().unwrap());
        assert!(
            *lo as f64 >= AIR - NOISE as f64 && *hi as f64 <= METAL + NOISE as f64,
            "{lo} {hi}"
        );
        // Both ends of the noise occur, and air is noisy.
        let air: Vec<i64> = (0..100).map(|i| noise(i, 3, 1)).collect();
        assert!(air.contains(&NOISE) || air.iter().any(|&n| n > NOISE - 3));
        assert!(air.iter().all(|n| n.abs() <= NOISE) && air.iter().any(|&n| n != air[0]));
    }
}
