//! Direction arithmetic shared by the scene, the float reference, the map builders and the
//! volume camera: a dot product and a normalisation that commute exactly with axis
//! permutations (so mirrored and axis-swapped inputs shade bit-identically), and a
//! normalisation that takes any finite non-zero direction from input; and the two facts of the
//! map's geometry: where the (max, u, v) components of a face sit on the axes, and which
//! tangent a position along a face stands for; and how a float direction becomes an integer
//! gradient.

use crate::config::Config;
use glam::DVec3;

/// A dot product whose three products are added in ascending order, so that permuting the
/// axes of both vectors gives the identical float result. Map entries and the reference use it
/// so that an axis-swapped gradient under an axis-swapped scene shades bit-identically.
#[inline]
pub fn sym_dot(a: DVec3, b: DVec3) -> f64 {
    let (mut p, mut q, mut r) = (a.x * b.x, a.y * b.y, a.z * b.z);
    if p > q {
        std::mem::swap(&mut p, &mut q);
    }
    if q > r {
        std::mem::swap(&mut q, &mut r);
    }
    if p > q {
        std::mem::swap(&mut p, &mut q);
    }
    (p + q) + r
}

/// Normalisation with [`sym_dot`]: axis permutations commute with it exactly. Overflows
/// (to a zero vector) for components beyond about 1e154; directions from input go through
/// [`unit_direction`].
#[inline]
pub fn sym_normalize(v: DVec3) -> DVec3 {
    v / sym_dot(v, v).sqrt()
}

/// The unit vector along `v` for any finite non-zero `v`, however large or small its
/// components (`[1e308, 1e308, 1e308]`, `[1e-320, 0, 0]`); `None` for a zero, NaN or
/// infinite vector. `v` is first scaled by the power of two that brings its largest
/// |component| into 1..2, so the squared length can neither overflow nor underflow; the
/// scaling is exact, so the result is bit-identical to [`sym_normalize`] wherever that one
/// is finite, and directions that differ by a power of two give the same unit vector. Axis
/// permutations commute with it exactly. Every direction normalised from input (scene lights
/// and view, the volume camera, the reference's gradients) goes through it.
#[inline]
pub fn unit_direction(v: DVec3) -> Option<DVec3> {
    if !v.is_finite() {
        return None;
    }
    let m = v.abs().max_element();
    if m == 0.0 {
        return None;
    }
    // m = 2^e * 1.f (e from the exponent bits; subnormals have e = -1023 and stay below 2).
    let e = ((m.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let u = sym_normalize(v * pow2(-e));
    debug_assert!(u.is_finite() && u != DVec3::ZERO, "{v} -> {u}");
    Some(u)
}

/// `v` times `scale`, each component rounded to the nearest integer, halves away from zero
/// (`f64::round`, so mirrored directions give mirrored gradients): how a float direction
/// becomes a gradient, for the sphere image and [`full_scale_gradient`]. Each |component| of
/// `v * scale` must be below 2^31.
pub fn round_gradient(v: DVec3, scale: f64) -> [i32; 3] {
    (v * scale).round().to_array().map(|c| c as i32)
}

/// The gradient along a float direction at full scale: `v` divided by its largest |component|
/// m, times 2^(G-1) - 1, rounded by [`round_gradient`]; each component is
/// `round((c / m) * (2^(G-1) - 1))` in f64, halves away from zero. The largest component
/// becomes ±(2^(G-1) - 1) exactly and the others lie between, so the gradient is in range and
/// never zero, and the sort & shift stage keeps G - 1 bits of every direction. Unit or not,
/// `v` and `2^k v` give the same gradient (where `2^k v` is exact: no component subnormal);
/// mirrored and axis-permuted directions give the mirrored and permuted gradient. `None` for a zero, NaN or infinite `v`: it has no
/// direction. The Python package's `rmapgen.quantize`.
pub fn full_scale_gradient(cfg: &Config, v: DVec3) -> Option<[i32; 3]> {
    if !v.is_finite() {
        return None;
    }
    let m = v.abs().max_element();
    if m == 0.0 {
        return None;
    }
    Some(round_gradient(v / m, *cfg.grad_range().end() as f64))
}

/// 2^k exactly, for k in -1074..=1023.
fn pow2(k: i32) -> f64 {
    if k >= -1022 {
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (k + 1074))
    }
}

/// Places (max, u, v) components on the axes: the max component on `axis` (0 x, 1 y, 2 z) and
/// the other two in axis order, so max x gives (max, u, v), max y (u, max, v), max z
/// (u, v, max). The sort & shift stage sorts a gradient this way; the map entries, the map
/// fit and the stress tests place their directions back with it.
pub fn place<T>(axis: u32, max: T, u: T, v: T) -> [T; 3] {
    match axis {
        0 => [max, u, v],
        1 => [u, max, v],
        _ => [u, v, max],
    }
}

/// The tangent (u / max) that a point at fraction `r` (0..=1) of a face's width stands for:
/// `tan(r pi/4)` with distortion compensation (positions are angles), `r` without (positions
/// are tangents). The border (`r` = 1) is exactly 1, since tan(pi/4) rounds below 1, so the
/// border entries of two faces are the same direction. Map entries sit at `r = i / (E - 1)`,
/// pipeline positions at `r = p / pos_max`.
pub fn face_tangent(compensation: bool, r: f64) -> f64 {
    if r >= 1.0 {
        1.0
    } else if compensation {
        (r * std::f64::consts::FRAC_PI_4).tan()
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(grad_bits: u32, v: [f64; 3]) -> Option<[i32; 3]> {
        let cfg = Config {
            grad_bits,
            ..Config::default()
        };
        full_scale_gradient(&cfg, DVec3::from_array(v))
    }

    #[test]
    fn the_full_scale_gradient_rounds_halves_away_from_zero() {
        // G = 8: 2^(G-1) - 1 = 127. 0.5 * 127 = 63.5 and 0.25 * 127 = 31.75 exactly.
        assert_eq!(g(8, [2.0, 1.0, 0.0]), Some([127, 64, 0]));
        assert_eq!(g(8, [-2.0, -1.0, 0.0]), Some([-127, -64, 0]));
        assert_eq!(g(8, [4.0, -1.0, 0.5]), Some([127, -32, 16]));
        // 1/3 * 127 = 42.33 down, 2/3 * 127 = 84.67 up.
        assert_eq!(g(8, [0.0, 1.0, -3.0]), Some([0, 42, -127]));
        assert_eq!(g(8, [0.0, 2.0, 3.0]), Some([0, 85, 127]));
        // 0.375 * 127 = 47.625 and -0.125 * 127 = -15.875: nearest, not truncated.
        assert_eq!(g(8, [8.0, 3.0, -1.0]), Some([127, 48, -16]));
        assert_eq!(g(16, [0.0, 0.0, -1.0]), Some([0, 0, -32767]));
        assert_eq!(g(12, [1.0, 1.0, 1.0]), Some([2047, 2047, 2047]));
    }

    #[test]
    fn the_full_scale_gradient_ignores_length_and_keeps_symmetry() {
        let unit = DVec3::new(0.3, -0.5, 0.8).normalize();
        let want = g(12, unit.to_array()).unwrap();
        for k in [-1000, -30, -1, 1, 30, 1000] {
            assert_eq!(g(12, (unit * 2f64.powi(k)).to_array()), Some(want), "2^{k}");
        }
        // Subnormal and huge components: no overflow, no underflow of the largest.
        assert_eq!(g(8, [1e-320, 0.0, -5e-321]), Some([127, 0, -64]));
        assert_eq!(g(8, [f64::MAX, f64::MAX / 2.0, 0.0]), Some([127, 64, 0]));
        let [x, y, z] = want;
        assert_eq!(g(12, (-unit).to_array()), Some([-x, -y, -z]));
        assert_eq!(g(12, [unit.z, unit.x, unit.y]), Some([z, x, y]));
    }

    #[test]
    fn the_full_scale_gradient_is_in_range_and_never_zero() {
        let mut rng = crate::rng::SplitMix64::new(60);
        for grad_bits in [8, 12, 16] {
            let cfg = Config {
                grad_bits,
                ..Config::default()
            };
            let top = *cfg.grad_range().end();
            for _ in 0..2000 {
                let mut c = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let v = DVec3::new(c(), c(), c());
                let q = full_scale_gradient(&cfg, v).unwrap();
                assert_eq!(q.iter().map(|c| c.abs()).max(), Some(top), "{v} {q:?}");
                assert!(q.iter().all(|c| cfg.grad_range().contains(c)), "{q:?}");
                // Each component is within half an LSB of the exact scaled value.
                let m = v.abs().max_element();
                for (c, e) in q.iter().zip((v / m * top as f64).to_array()) {
                    assert!((*c as f64 - e).abs() <= 0.5, "{v} {q:?}");
                }
            }
        }
    }

    #[test]
    fn a_vector_without_a_direction_has_no_gradient() {
        for v in [
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [f64::NAN, 1.0, 0.0],
            [1.0, f64::INFINITY, 0.0],
            [0.0, 0.0, f64::NEG_INFINITY],
        ] {
            assert_eq!(g(12, v), None, "{v:?}");
        }
    }
}
