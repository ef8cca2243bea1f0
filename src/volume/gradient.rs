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
//! zero; computed as the value difference times `-scale / (2 spacing)` in f64), so it
//! always lies in `-(2^(G-1) - 1) ..= 2^(G-1) - 1`. Gradients are **not**
//! normalised: a weak edge or a noisy flat region gives small integers, and the hardware's
//! leading-zero shift has to deal with them, exactly as with gradients from a gradient unit
//! on real data. A gradient that rounds to (0, 0, 0) reaches the shader as the zero case.
//!
//! The ray caster interpolates these integer gradients trilinearly at each sample and rounds
//! again (see `volume::cast`), so a sample's gradient is also a G-bit integer vector; the
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

/// The five rows a row's differences need: itself, its y neighbours and its z neighbours
/// (clamped at the borders), and whether the y and z differences are central.
#[inline]
fn rows(vol: &Volume, y: usize, z: usize) -> ([&[f32]; 5], bool, bool) {
    let [nx, ny, nz] = vol.dims;
    let row = |y: usize, z: usize| {
        let i = vol.index(0, y, z);
        &vol.data[i..i + nx]
    };
    let (y0, y1) = (y.saturating_sub(1), (y + 1).min(ny - 1));
    let (z0, z1) = (z.saturating_sub(1), (z + 1).min(nz - 1));
    (
        [row(y, z), row(y0, z), row(y1, z), row(y, z0), row(y, z1)],
        y1 - y0 == 2,
        z1 - z0 == 2,
    )
}

/// Largest |difference| of one row, as [central, one-sided] for x, y and z.
fn row_max(vol: &Volume, y: usize, z: usize) -> [[f32; 2]; 3] {
    let ([r, ym, yp, zm, zp], cy, cz) = rows(vol, y, z);
    let nx = r.len();
    let mut m = [[0.0f32; 2]; 3];
    let mut mx = 0.0f32;
    for (a, b) in r[2..].iter().zip(&r[..nx - 2]) {
        let d = (a - b).abs();
        mx = if d > mx { d } else { mx };
    }
    m[0] = [mx, (r[1] - r[0]).abs().max((r[nx - 1] - r[nx - 2]).abs())];
    let max_diff = |p: &[f32], q: &[f32]| {
        p.iter().zip(q).fold(
            0.0f32,
            |m, (a, b)| if (a - b).abs() > m { (a - b).abs() } else { m },
        )
    };
    m[1][usize::from(!cy)] = max_diff(yp, ym);
    m[2][usize::from(!cz)] = max_diff(zp, zm);
    m
}

/// Rounds half away from zero, for |v| < 2^52: adds the largest double below 0.5 with v's
/// sign and truncates (the sum rounds up exactly when v's fraction is at least 0.5). No
/// libm call on baseline x86-64, and it vectorises.
#[inline]
pub fn round_half_away(v: f64) -> i64 {
    (v + HALF_BELOW_F64.copysign(v)) as i64
}

const HALF_BELOW_F64: f64 = 0.499_999_999_999_999_94;

/// The quantised outward normal of every voxel for `grad_bits`-wide shader inputs.
///
/// Differences of the f32 values are exact for integer data below 2^24; each is multiplied
/// in f64 by the per-axis factor `scale / (2 spacing)` (or `scale / spacing` one-sided), and
/// the largest component is found from the largest |difference| per axis, which gives the
/// same maximum as comparing every gradient.
pub fn gradients(vol: &Volume, grad_bits: u32) -> Gradients {
    try_gradients(vol, grad_bits).expect("memory for the gradients")
}

/// [`gradients`], with the gradient buffer reserved by `try_reserve_exact`: a volume the
/// machine has no memory for is an error, not an abort.
pub fn try_gradients(vol: &Volume, grad_bits: u32) -> anyhow::Result<Gradients> {
    assert!((2..=16).contains(&grad_bits), "grad_bits {grad_bits}");
    let [nx, ny, _] = vol.dims;
    let inv = vol.spacing.map(|s| [1.0 / (2.0 * s), 1.0 / s]);
    let m = (0..vol.dims[2])
        .into_par_iter()
        .map(|z| {
            let mut m = [[0.0f32; 2]; 3];
            for y in 0..ny {
                let r = row_max(vol, y, z);
                for a in 0..3 {
                    for k in 0..2 {
                        m[a][k] = m[a][k].max(r[a][k]);
                    }
                }
            }
            m
        })
        .reduce(
            || [[0.0f32; 2]; 3],
            |a, b| [0, 1, 2].map(|i| [a[i][0].max(b[i][0]), a[i][1].max(b[i][1])]),
        );
    let max_component = (0..3)
        .flat_map(|a| (0..2).map(move |k| (a, k)))
        .fold(0.0f64, |acc, (a, k)| acc.max(m[a][k] as f64 * inv[a][k]));
    let scale = if max_component > 0.0 {
        limit(grad_bits) as f64 / max_component
    } else {
        0.0
    };
    // Per-axis factors, negated: the shader gets minus the density gradient.
    let f = inv.map(|i| [-i[0] * scale, -i[1] * scale]);
    let l = limit(grad_bits) as f64;
    let q = |d: f32, k: f64| round_half_away((d as f64 * k).clamp(-l, l)) as i16;
    let mut data: Vec<[i16; 3]> = Vec::new();
    data.try_reserve_exact(vol.data.len()).map_err(|_| {
        anyhow::anyhow!(
            "{}: cannot allocate {} for the gradients of {} voxels",
            vol.info.source,
            super::human_bytes(6 * vol.data.len() as u64),
            vol.data.len()
        )
    })?;
    data.resize(vol.data.len(), [0; 3]);
    data.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(z, out)| {
            let mut t = [vec![0i16; nx], vec![0i16; nx], vec![0i16; nx]];
            for y in 0..ny {
                let ([r, ym, yp, zm, zp], cy, cz) = rows(vol, y, z);
                let (ky, kz) = (f[1][usize::from(!cy)], f[2][usize::from(!cz)]);
                // One component at a time, so each loop vectorises.
                t[0][0] = q(r[1] - r[0], f[0][1]);
                t[0][nx - 1] = q(r[nx - 1] - r[nx - 2], f[0][1]);
                for (o, (a, b)) in t[0][1..nx - 1]
                    .iter_mut()
                    .zip(r[2..].iter().zip(&r[..nx - 2]))
                {
                    *o = q(a - b, f[0][0]);
                }
                for (o, (a, b)) in t[1].iter_mut().zip(yp.iter().zip(ym)) {
                    *o = q(a - b, ky);
                }
                for (o, (a, b)) in t[2].iter_mut().zip(zp.iter().zip(zm)) {
                    *o = q(a - b, kz);
                }
                for (x, o) in out[nx * y..nx * (y + 1)].iter_mut().enumerate() {
                    *o = [t[0][x], t[1][x], t[2][x]];
                }
            }
        });
    Ok(Gradients {
        grad_bits,
        data,
        scale,
        max_component,
    })
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
    }

    #[test]
    fn constant_volume_has_zero_gradients() {
        let v = vol([3, 3, 3], [1.0; 3], |_, _, _| 7.0);
        let g = gradients(&v, 12);
        assert!(g.data.iter().all(|&q| q == [0; 3]) && g.scale == 0.0);
    }
}
