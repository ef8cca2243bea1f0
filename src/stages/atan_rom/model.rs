//! Distortion compensation: the atan ROM turns a normalised fraction u (= tan of the angle
//! from the cube axis) into a map position, so that equal steps in position are equal steps
//! in angle rather than in tan. Only 0..45 degrees is needed.
//!
//! A position is `index_bits + interp_bits` wide and runs from 0 (the axis, 0 degrees) to
//! `pos_max = (2^index_bits - 1) * 2^interp_bits` (the face border, 45 degrees): the outer
//! entries sit on the border and the ROM never points past them, which is the "range reduced
//! by one" of the paper's Figure 8b. Without interpolation a position is an entry index.

use crate::config::Config;
use std::f64::consts::FRAC_PI_4;

/// The value of the tangent a fraction code stands for: u / 2^frac_bits, except that the
/// all-ones code (a component equal to the max) stands for exactly 1.
pub fn tangent(cfg: &Config, u: u32) -> f64 {
    if u == cfg.frac_max() {
        1.0
    } else {
        u as f64 / (1u64 << cfg.frac_bits) as f64
    }
}

/// The ideal (unrounded) position of a tangent, in position LSBs.
pub fn ideal_position(cfg: &Config, t: f64) -> f64 {
    t.atan() / FRAC_PI_4 * cfg.pos_max() as f64
}

/// The ROM contents: used by the model and by the hex writer.
pub fn contents(cfg: &Config) -> Vec<u32> {
    (0..=cfg.frac_max())
        .map(|u| (ideal_position(cfg, tangent(cfg, u)).round() as u32).min(cfg.pos_max()))
        .collect()
}

/// The tangent of a map entry's angle from the axis. The outer entry is exactly 1 (tan of
/// FRAC_PI_4 rounds to 1 - 2^-53), so the border entries of two faces are the same direction.
pub fn entry_tangent(cfg: &Config, index: u32) -> f64 {
    crate::geometry::face_tangent(true, index as f64 / (cfg.entries() - 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_monotonic() {
        let c = Config::default();
        let rom = contents(&c);
        assert_eq!(rom.len(), 256);
        assert_eq!(rom[0], 0);
        assert_eq!(*rom.last().unwrap(), c.pos_max());
        assert!(rom.windows(2).all(|w| w[0] <= w[1]));
    }
}
