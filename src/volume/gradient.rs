//! Gradients on the voxel grid, quantised to the shader's input width.
//!
//! **Differences.** At voxel (x, y, z) the x component is the central difference
//! `(v[x+1] - v[x-1]) / (2 * spacing_x)` in value units per world unit (one-sided,
//! `(v[1] - v[0]) / spacing_x`, on the first and last voxel of a row); likewise y and z.
//!
//! **Sign.** The density gradient points into the material (towards higher values); the
//! shading normal must point out of it, towards the air and a viewer looking at the surface.
//! The shader therefore receives **minus** the density gradient.
//!
//! **Scale.** One scale per volume, `scale = (2^(G-1) - 1) / gmax`, where `gmax` is the
//! largest |component| of any voxel's gradient: the steepest edge of the volume uses the
//! full range of the G-bit input, every component is `round(-scale * g)` (half away from
//! zero), so it always lies in `-(2^(G-1) - 1) ..= 2^(G-1) - 1`. Gradients are **not**
//! normalised: a weak edge or a noisy flat region gives small integers, and the hardware's
//! leading-zero shift has to deal with them, exactly as with gradients from a gradient unit
//! on real data. A gradient that rounds to (0, 0, 0) reaches the shader as the zero case.
//!
//! The ray caster interpolates these integer gradients trilinearly at each sample and rounds
//! again (see [`super::cast`]), so a sample's gradient is also a G-bit integer vector; the
//! float reference and the bit-accurate model shade that same vector.

use super::Volume;
use rayon::prelude::*;

/// Quantised outward normals, one per voxel, in the volume's voxel order.
#[derive(Clone, Debug, PartialEq)]
pub struct Gradients {
    pub grad_bits: u32,
    pub data: Vec<[i16; 3]>,
    /// LSBs per (value unit per world unit).
    pub scale: f64,
    /// The largest |component| of any voxel's float gradient (value units per world unit).
    pub max_component: f64,
}

/// Largest quantised component, 2^(G-1) - 1.
pub fn limit(grad_bits: u32) -> i32 {
    (1 << (grad_bits - 1)) - 1
}

/// Calls `f(x, g)` with the float density gradient g (value units per world unit) of every
/// voxel of row (y, z). `inv[axis]` holds 1 / (2 spacing) for central and 1 / spacing for
/// one-sided differences.
#[inline]
fn row_gradients(
    vol: &Volume,
    y: usize,
    z: usize,
    inv: &[[f64; 2]; 3],
    mut f: impl FnMut(usize, [f64; 3]),
) {
    let [nx, ny, nz] = vol.dims;
    let span = |i: usize, n: usize| (i.saturating_sub(1), (i + 1).min(n - 1));
    let k = |lo: usize, hi: usize| if hi - lo == 2 { 0 } else { 1 };
    let row = |y: usize, z: usize| &vol.data[vol.index(0, y, z)..vol.index(0, y, z) + nx];
    let (y0, y1) = span(y, ny);
    let (z0, z1) = span(z, nz);
    let (r, ym, yp, zm, zp) = (row(y, z), row(y0, z), row(y1, z), row(y, z0), row(y, z1));
    let (iy, iz) = (inv[1][k(y0, y1)], inv[2][k(z0, z1)]);
    let diff = |a: f32, b: f32| a as f64 - b as f64;
    for x in 0..nx {
        let (x0, x1) = span(x, nx);
        f(
            x,
            [
                diff(r[x1], r[x0]) * inv[0][k(x0, x1)],
                diff(yp[x], ym[x]) * iy,
                diff(zp[x], zm[x]) * iz,
            ],
        );
    }
}

/// Rounds half away from zero (without a libm call on baseline x86-64).
#[inline]
pub fn round_half_away(v: f64) -> i64 {
    let t = v as i64;
    let f = v - t as f64;
    if f >= 0.5 {
        t + 1
    } else if f <= -0.5 {
        t - 1
    } else {
        t
    }
}

/// `round(-scale * g)` (half away from zero), clamped to the G-bit range (the clamp only
/// guards rounding of the product for the steepest component).
#[inline]
pub fn quantise(g: f64, scale: f64, grad_bits: u32) -> i32 {
    let l = limit(grad_bits) as i64;
    round_half_away(-g * scale).clamp(-l, l) as i32
}

/// The quantised outward normal of every voxel for `grad_bits`-wide shader inputs.
pub fn gradients(vol: &Volume, grad_bits: u32) -> Gradients {
    assert!((2..=16).contains(&grad_bits), "grad_bits {grad_bits}");
    let [nx, ny, _] = vol.dims;
    let inv = vol.spacing.map(|s| [1.0 / (2.0 * s), 1.0 / s]);
    let max_component = (0..vol.dims[2])
        .into_par_iter()
        .map(|z| {
            let mut m = 0.0f64;
            for y in 0..ny {
                row_gradients(vol, y, z, &inv, |_, g| {
                    m = m.max(g[0].abs()).max(g[1].abs()).max(g[2].abs())
                });
            }
            m
        })
        .reduce(|| 0.0, f64::max);
    let scale = if max_component > 0.0 {
        limit(grad_bits) as f64 / max_component
    } else {
        0.0
    };
    let mut data = vec![[0i16; 3]; vol.data.len()];
    data.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(z, out)| {
            for y in 0..ny {
                let o = &mut out[nx * y..nx * (y + 1)];
                row_gradients(vol, y, z, &inv, |x, g| {
                    o[x] = g.map(|c| quantise(c, scale, grad_bits) as i16)
                });
            }
        });
    Gradients {
        grad_bits,
        data,
        scale,
        max_component,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::VolumeInfo;

    fn vol(dims: [usize; 3], spacing: [f64; 3], f: impl Fn(usize, usize, usize) -> f32) -> Volume {
        let mut d = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    d.push(f(x, y, z));
                }
            }
        }
        Volume::new(
            dims,
            spacing,
            d,
            VolumeInfo {
                source: "t".into(),
                voxel_type: "float".into(),
            },
        )
        .unwrap()
    }

    #[test]
    fn linear_ramp_full_scale_and_outward() {
        // Density rises along +x: the outward normal points along -x.
        let v = vol([5, 4, 3], [1.0; 3], |x, y, z| {
            (300 * x + 200 * y) as f32 - 100.0 * z as f32
        });
        let g = gradients(&v, 12);
        assert_eq!(g.max_component, 300.0);
        // Interior and border voxels alike (one-sided differences are exact on a ramp).
        for i in [0, v.index(2, 1, 1), v.index(4, 3, 2)] {
            assert_eq!(g.data[i], [-2047, -1365, 682], "voxel {i}");
        }
    }

    #[test]
    fn spacing_scales_the_components() {
        // The same index ramp along x and y, but y voxels are four times as far apart.
        let v = vol([4, 4, 4], [1.0, 4.0, 1.0], |x, y, _| (x + y) as f32 * 8.0);
        let g = gradients(&v, 12);
        assert_eq!(g.data[v.index(1, 1, 1)], [-2047, -512, 0]);
        assert_eq!(g.scale, 2047.0 / 8.0);
    }

    #[test]
    fn weak_edges_keep_small_magnitudes() {
        // A strong step at x = 4 and a weak one (1/100 of it) at y = 4.
        let v = vol(
            [8, 8, 8],
            [1.0; 3],
            |x, y, _| if x >= 4 { 1000.0 } else { 0.0 } + if y >= 4 { 10.0 } else { 0.0 },
        );
        let g = gradients(&v, 12);
        assert_eq!(g.data[v.index(4, 1, 2)], [-2047, 0, 0]);
        // Not normalised: the weak edge stays small (20 LSB), with its own direction.
        assert_eq!(g.data[v.index(1, 4, 2)], [0, -20, 0]);
        // Flat regions are the zero case.
        assert_eq!(g.data[v.index(1, 1, 2)], [0, 0, 0]);
    }

    #[test]
    fn ball_normals_point_out() {
        let v = vol([16, 16, 16], [1.0; 3], |x, y, z| {
            let d =
                ((x as f32 - 7.5).powi(2) + (y as f32 - 7.5).powi(2) + (z as f32 - 7.5).powi(2))
                    .sqrt();
            (6.0 - d).clamp(0.0, 1.0) * 1000.0
        });
        let g = gradients(&v, 12);
        let gx = g.data[v.index(13, 8, 8)];
        assert!(gx[0] > 0 && gx[0] > gx[1].abs() * 3, "{gx:?}");
        let gz = g.data[v.index(8, 8, 2)];
        assert!(gz[2] < 0 && -gz[2] > gz[0].abs() * 3, "{gz:?}");
    }

    #[test]
    fn rounding_is_half_away_from_zero() {
        for (v, r) in [
            (0.5, 1),
            (-0.5, -1),
            (0.49999999, 0),
            (-1.5, -2),
            (2.4, 2),
            (-2.6, -3),
            (0.0, 0),
        ] {
            assert_eq!(round_half_away(v), r, "{v}");
            assert_eq!(round_half_away(v), v.round() as i64, "{v}");
        }
        assert_eq!(quantise(-300.0, 2047.0 / 300.0, 12), 2047);
        assert_eq!(quantise(1e9, 1.0, 12), -2047);
    }

    #[test]
    fn constant_volume_has_zero_gradients() {
        let v = vol([3, 3, 3], [1.0; 3], |_, _, _| 7.0);
        let g = gradients(&v, 12);
        assert!(g.data.iter().all(|&q| q == [0; 3]) && g.scale == 0.0);
    }
}
