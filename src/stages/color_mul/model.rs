//! Colour multiply: each 8-bit channel of the sample colour times the intensity, scaled so
//! that full intensity keeps the colour: round(c * i / d), half up, with d = 2^map_bits - 1.
//! Hardware divides by the constant 2d with a multiply and a shift:
//! out = ((2 c i + d) * K) >> S, K = ceil(2^S / 2d), where S is the smallest shift with
//! 2^S >= N * 2d over the N possible numerators, which makes the quotient exact (tests check
//! it exhaustively for every map width).

use crate::config::{Config, COLOR_BITS};

/// The constant K and the shift S of the division by 2 * (2^map_bits - 1).
pub fn constants(cfg: &Config) -> (u64, u32) {
    let d = cfg.map_max() as u64;
    let n = 2 * ((1u64 << COLOR_BITS) - 1) * d + d + 1;
    let s = 64 - (n * 2 * d - 1).leading_zeros();
    let k = (1u64 << s).div_ceil(2 * d);
    (k, s)
}

/// Width of the product numerator * K: the quotient (at most 255) sits above the shift S, so
/// nothing wider is ever non-zero.
pub fn product_bits(cfg: &Config) -> u32 {
    constants(cfg).1 + COLOR_BITS
}

/// Width of the numerator 2 c i + d.
pub fn numerator_bits(cfg: &Config) -> u32 {
    COLOR_BITS + cfg.map_bits + 1
}

#[inline]
pub fn channel(cfg: &Config, k: u64, s: u32, c: u32, i: u32) -> u32 {
    let num = 2 * c as u64 * i as u64 + cfg.map_max() as u64;
    ((num * k) >> s) as u32
}

#[inline]
pub fn eval(cfg: &Config, rgb: [u32; 3], i: u32) -> [u32; 3] {
    let (k, s) = constants(cfg);
    rgb.map(|c| channel(cfg, k, s, c, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equals_rounded_quotient_everywhere() {
        for map_bits in 6..=12 {
            let cfg = Config {
                map_bits,
                ..Config::default()
            };
            let d = cfg.map_max() as u64;
            let (k, s) = constants(&cfg);
            for c in 0..256u32 {
                for i in 0..=cfg.map_max() {
                    let x = c as u64 * i as u64;
                    let exact = (2 * x + d) / (2 * d);
                    assert_eq!(
                        channel(&cfg, k, s, c, i) as u64,
                        exact,
                        "M{map_bits} c{c} i{i}"
                    );
                }
            }
            assert_eq!(channel(&cfg, k, s, 255, cfg.map_max()), 255);
        }
    }
}
