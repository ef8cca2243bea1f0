//! Sort & shift: split off the signs, find the largest magnitude, and shift every magnitude
//! left by the max's leading zeros before truncating to `red_bits`, so that small gradients
//! keep their precision.
//!
//! Tie rule: among equal largest magnitudes the lowest axis wins (x before y before z).
//! The two other components leave in axis order: max x gives (u, v) = (y, z), max y gives
//! (x, z), max z gives (x, y).

use crate::config::Config;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct SortShift {
    /// Axis of the largest magnitude: 0 = x, 1 = y, 2 = z.
    pub axis: u32,
    /// Sign bits (1 = negative) of the max component and of u and v.
    pub s_max: u32,
    pub s_u: u32,
    pub s_v: u32,
    /// The common left shift (leading zeros of the max in `grad_bits`; 0 for a zero vector).
    pub shift: u32,
    /// Reduced magnitudes, `red_bits` wide; `m` has its MSB set unless the vector is zero.
    pub m: u32,
    pub a: u32,
    pub b: u32,
}

/// Sign and magnitude of a `grad_bits` two's-complement value. The magnitude needs all
/// `grad_bits` bits only for the most negative value.
#[inline]
pub fn sign_mag(cfg: &Config, v: i32) -> (u32, u32) {
    debug_assert!(in_range(cfg, v), "gradient component {v} out of range");
    ((v < 0) as u32, v.unsigned_abs())
}

/// Whether `v` is a valid `grad_bits` two's-complement value.
pub fn in_range(cfg: &Config, v: i32) -> bool {
    cfg.grad_range().contains(&v)
}

/// Index of the max axis under the tie rule, from the three magnitudes.
#[inline]
pub fn max_axis(mx: u32, my: u32, mz: u32) -> u32 {
    if mx >= my && mx >= mz {
        0
    } else if my >= mz {
        1
    } else {
        2
    }
}

#[inline]
pub fn eval(cfg: &Config, g: [i32; 3]) -> SortShift {
    let (sx, mx) = sign_mag(cfg, g[0]);
    let (sy, my) = sign_mag(cfg, g[1]);
    let (sz, mz) = sign_mag(cfg, g[2]);
    let axis = max_axis(mx, my, mz);
    let (s_max, max, s_u, mu, s_v, mv) = match axis {
        0 => (sx, mx, sy, my, sz, mz),
        1 => (sy, my, sx, mx, sz, mz),
        _ => (sz, mz, sx, mx, sy, my),
    };
    let gbits = cfg.grad_bits;
    // Leading zeros of the max inside grad_bits; a zero vector is not shifted.
    let shift = if max == 0 {
        0
    } else {
        max.leading_zeros() - (32 - gbits)
    };
    let drop = gbits - cfg.red_bits;
    let reduce = |v: u32| (v << shift) >> drop;
    SortShift {
        axis,
        s_max,
        s_u,
        s_v,
        shift,
        m: reduce(max),
        a: reduce(mu),
        b: reduce(mv),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners() {
        let c = Config::default();
        let z = eval(&c, [0, 0, 0]);
        assert_eq!((z.m, z.a, z.b, z.shift), (0, 0, 0, 0));
        // Three equal components: x wins, all reduce to the same value.
        let e = eval(&c, [100, -100, 100]);
        assert_eq!((e.axis, e.s_u, e.m, e.a, e.b), (0, 1, e.m, e.m, e.m));
        // Two equal maxima in y and z: y wins.
        assert_eq!(eval(&c, [5, -700, 700]).axis, 1);
        // The most negative value needs the full 12-bit magnitude, shift 0.
        let n = eval(&c, [-2048, 1, 0]);
        assert_eq!((n.axis, n.s_max, n.shift, n.m), (0, 1, 0, 0x80));
        // Magnitude 1 is shifted all the way up.
        let one = eval(&c, [0, 0, 1]);
        assert_eq!((one.axis, one.shift, one.m, one.a), (2, 11, 0x80, 0));
        // Full-range positive max.
        let f = eval(&c, [2047, 2047, -2047]);
        assert_eq!(
            (f.axis, f.shift, f.m, f.a, f.b, f.s_v),
            (0, 1, 0xff, 0xff, 0xff, 1)
        );
    }
}
