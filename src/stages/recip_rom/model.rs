//! Reciprocal ROM: 1/m for every reduced max m. After sort & shift the max has its MSB set,
//! so the ROM is indexed by the `red_bits - 1` bits below it.
//!
//! Entry i holds round(2^(red_bits - 1 + recip_bits) / m) for m = 2^(red_bits - 1) + i,
//! clipped to `recip_bits` (i = 0, exactly 2^recip_bits, and any entry rounding up to it).

use crate::config::Config;

/// The exact value the entry for index `i` approximates.
pub fn exact(cfg: &Config, i: u32) -> f64 {
    let m = (cfg.recip_entries() + i) as f64;
    (2f64).powi((cfg.red_bits - 1 + cfg.recip_bits) as i32) / m
}

/// Stated rounding bound of an entry against [`exact`], in entry LSBs: half an LSB, or one
/// LSB for the few entries at the top that are clipped to fit `recip_bits`.
pub fn bound(cfg: &Config, i: u32) -> f64 {
    if exact(cfg, i) > ((1u64 << cfg.recip_bits) - 1) as f64 {
        1.0
    } else {
        0.5
    }
}

/// The ROM contents: used by the model and by the hex writer.
pub fn contents(cfg: &Config) -> Vec<u32> {
    let num = 1u64 << (cfg.red_bits - 1 + cfg.recip_bits);
    let top = (1u64 << cfg.recip_bits) - 1;
    (0..cfg.recip_entries())
        .map(|i| {
            let m = (cfg.recip_entries() + i) as u64;
            ((num + m / 2) / m).min(top) as u32
        })
        .collect()
}

/// ROM address of a reduced max: its bits below the MSB.
#[inline]
pub fn addr(cfg: &Config, m: u32) -> u32 {
    m & (cfg.recip_entries() - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_within_bound() {
        for red_bits in 6..=12 {
            for recip_bits in [8, 10, 14, 20] {
                let c = crate::config::Config {
                    red_bits,
                    recip_bits,
                    frac_bits: 7,
                    ..Default::default()
                };
                for (i, &r) in contents(&c).iter().enumerate() {
                    let i = i as u32;
                    assert!(r < 1 << recip_bits);
                    assert!(
                        (r as f64 - exact(&c, i)).abs() <= bound(&c, i),
                        "R{red_bits} W{recip_bits} i{i}"
                    );
                }
            }
        }
    }
}
