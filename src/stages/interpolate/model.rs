//! Bilinear interpolation of the four neighbours with weights in 0..=step:
//! first along u, a0 = e00 * step + (e10 - e00) * w_u (exact, no rounding), the same for a1,
//! then along v, r = a0 * step + (a1 - a0) * w_v, and one rounding at the end:
//! out = (r + step^2 / 2) >> (2 * interp_bits), half up. The result equals the exact
//! bilinear value rounded half up, and never leaves the range of its four inputs.

use crate::config::Config;

#[inline]
pub fn eval(cfg: &Config, e: [u32; 4], w_u: u32, w_v: u32) -> u32 {
    let p = cfg.interp_bits;
    let s = cfg.step() as i64;
    let [e00, e10, e01, e11] = e.map(|x| x as i64);
    let a0 = e00 * s + (e10 - e00) * w_u as i64;
    let a1 = e01 * s + (e11 - e01) * w_u as i64;
    let r = a0 * s + (a1 - a0) * w_v as i64;
    ((r + (1i64 << (2 * p - 1))) >> (2 * p)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_pick_entries() {
        let c = Config::default();
        let e = [10, 20, 30, 40];
        assert_eq!(eval(&c, e, 0, 0), 10);
        assert_eq!(eval(&c, e, 8, 0), 20);
        assert_eq!(eval(&c, e, 0, 8), 30);
        assert_eq!(eval(&c, e, 8, 8), 40);
        assert_eq!(eval(&c, e, 4, 4), 25);
        assert_eq!(eval(&c, [255; 4], 3, 5), 255);
    }
}
