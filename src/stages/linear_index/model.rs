//! Linear index, used in place of the atan ROM when distortion compensation is off: the
//! position is the fraction scaled to 0..=pos_max, position = round(u * pos_max / 2^frac_bits)
//! (half up), and the all-ones code goes to the border exactly, as with the ROM. Map entries
//! then sit at equal steps in tan rather than in angle (the paper's Figure 4).

use crate::config::Config;

#[inline]
pub fn eval(cfg: &Config, u: u32) -> u32 {
    if u == cfg.frac_max() {
        return cfg.pos_max();
    }
    let f = cfg.frac_bits;
    ((u as u64 * cfg.pos_max() as u64 + (1u64 << (f - 1))) >> f) as u32
}

/// The tangent at a map entry's position.
pub fn entry_tangent(cfg: &Config, index: u32) -> f64 {
    crate::geometry::face_tangent(false, index as f64 / (cfg.entries() - 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends() {
        let c = Config {
            compensation: false,
            ..Config::default()
        };
        assert_eq!(eval(&c, 0), 0);
        assert_eq!(eval(&c, 255), 56);
        assert_eq!(eval(&c, 128), 28);
    }
}
