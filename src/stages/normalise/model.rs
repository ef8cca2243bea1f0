//! Normalise: u = a / m and v = b / m as `frac_bits` fractions, computed as a * recip(m)
//! with the reciprocal ROM and two multipliers, rounded half up. A component equal to the
//! max saturates to all ones (which the index stages read as exactly 1) instead of needing
//! an extra bit; any product that would round up to 1.0 saturates the same way.

use crate::config::Config;
use crate::stages::recip_rom::model as recip_rom;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
pub struct Normalise {
    /// The reciprocal-ROM entry read for m.
    pub recip: u32,
    pub u: u32,
    pub v: u32,
}

/// Right shift that turns a * recip into a frac_bits fraction.
pub fn norm_shift(cfg: &Config) -> u32 {
    cfg.red_bits - 1 + cfg.recip_bits - cfg.frac_bits
}

/// The rounding constant, half an LSB of the fraction: 2^(norm_shift - 1).
pub fn norm_half(cfg: &Config) -> u64 {
    1 << (norm_shift(cfg) - 1)
}

/// One multiplier lane: the fraction for component `c` given the max `m` and its reciprocal.
#[inline]
pub fn lane(cfg: &Config, c: u32, m: u32, recip: u32) -> u32 {
    let all_ones = cfg.frac_max();
    if c == m {
        return all_ones;
    }
    let sh = norm_shift(cfg);
    let q = ((c as u64 * recip as u64 + (1u64 << (sh - 1))) >> sh) as u32;
    q.min(all_ones)
}

#[inline]
pub fn eval(cfg: &Config, recip_rom: &[u32], m: u32, a: u32, b: u32) -> Normalise {
    let recip = recip_rom[recip_rom::addr(cfg, m) as usize];
    Normalise {
        recip,
        u: lane(cfg, a, m, recip),
        v: lane(cfg, b, m, recip),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners() {
        let c = Config::default();
        let rom = recip_rom::contents(&c);
        // Equal to the max: all ones.
        assert_eq!(eval(&c, &rom, 200, 200, 0).u, 255);
        // Zero stays zero.
        assert_eq!(eval(&c, &rom, 128, 0, 0).u, 0);
        // Half: 64/128 = 0.5 -> 128.
        assert_eq!(eval(&c, &rom, 128, 64, 0).u, 128);
        // Just below the max with the smallest max: 127/128 * 256 = 254.
        assert_eq!(eval(&c, &rom, 128, 127, 1).u, 254);
    }
}
