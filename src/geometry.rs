//! Direction arithmetic shared by the scene, the float reference, the map builders and the
//! volume camera: a dot product and a normalisation that commute exactly with axis
//! permutations (so mirrored and axis-swapped inputs shade bit-identically), and a
//! normalisation that takes any finite non-zero direction from input; and the two facts of the
//! map's geometry: where the (max, u, v) components of a face sit on the axes, and which
//! tangent a position along a face stands for.

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
