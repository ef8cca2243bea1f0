//! An octahedral-map encoding, in the model only, for comparison with the cube: the float-
//! normalised gradient n is folded onto the octahedron |x| + |y| + |z| = 1 and unfolded onto
//! the square [-1, 1]^2 (the lower half's triangles folded out), where an R x R map of
//! `map_bits` entries, sampled from the light model at the grid points' directions, is
//! interpolated bilinearly and rounded. It needs a float (or wide fixed-point) normaliser and
//! divider, which the cube encoding avoids; the point is the image quality per entry.

use crate::config::Config;
use crate::model::reflectance_map::quantise;
use glam::{DVec2, DVec3};

/// The octahedral map and its side.
#[derive(Clone, Debug)]
pub struct Octahedral {
    pub side: usize,
    pub map_bits: u32,
    pub entries: Vec<f64>,
}

/// Square coordinates in [-1, 1]^2 of a unit normal.
pub fn encode(n: DVec3) -> DVec2 {
    let p = DVec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 {
        p
    } else {
        let s = |v: f64| if v >= 0.0 { 1.0 } else { -1.0 };
        DVec2::new((1.0 - p.y.abs()) * s(p.x), (1.0 - p.x.abs()) * s(p.y))
    }
}

/// The unit normal at square coordinates in [-1, 1]^2.
pub fn decode(e: DVec2) -> DVec3 {
    let z = 1.0 - e.x.abs() - e.y.abs();
    let t = (-z).max(0.0);
    let s = |v: f64| if v >= 0.0 { 1.0 } else { -1.0 };
    DVec3::new(e.x - t * s(e.x), e.y - t * s(e.y), z).normalize()
}

impl Octahedral {
    /// The map of side `side` for a light model, entries quantised to `cfg.map_bits`.
    pub fn new(cfg: &Config, side: usize, shade: impl Fn(DVec3) -> f64) -> Octahedral {
        let at = |k: usize| -1.0 + 2.0 * k as f64 / (side - 1) as f64;
        let entries = (0..side * side)
            .map(|k| quantise(cfg, shade(decode(DVec2::new(at(k / side), at(k % side))))) as f64)
            .collect();
        Octahedral {
            side,
            map_bits: cfg.map_bits,
            entries,
        }
    }

    /// The side whose entry count is closest to `entries`.
    pub fn side_for(entries: u32) -> usize {
        (entries as f64).sqrt().round() as usize
    }

    /// The rounded, bilinearly interpolated intensity of a gradient (0 for the zero vector).
    pub fn intensity(&self, g: [i32; 3]) -> u32 {
        if g == [0, 0, 0] {
            return 0;
        }
        let e = encode(DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64).normalize());
        let s = (self.side - 1) as f64;
        let (x, y) = ((e.x + 1.0) * 0.5 * s, (e.y + 1.0) * 0.5 * s);
        let (i, j) = (
            (x.floor() as usize).min(self.side - 2),
            (y.floor() as usize).min(self.side - 2),
        );
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |a: usize, b: usize| self.entries[a * self.side + b];
        let v = (at(i, j) * (1.0 - fy) + at(i, j + 1) * fy) * (1.0 - fx)
            + (at(i + 1, j) * (1.0 - fy) + at(i + 1, j + 1) * fy) * fx;
        (v + 0.5)
            .floor()
            .clamp(0.0, ((1u64 << self.map_bits) - 1) as f64) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_decode_round_trip() {
        for d in [
            [1.0, 2.0, 3.0],
            [-1.0, 0.5, -2.0],
            [0.0, 0.0, -1.0],
            [0.3, -0.9, 0.0],
            [0.0, 0.0, 1.0],
        ] {
            let n = DVec3::from_array(d).normalize();
            let e = encode(n);
            assert!(e.x.abs() <= 1.0 && e.y.abs() <= 1.0);
            assert!((decode(e) - n).length() < 1e-12, "{d:?}");
        }
    }

    #[test]
    fn constant_model_is_exact() {
        let cfg = Config::default();
        let o = Octahedral::new(&cfg, 39, |_| 0.4);
        assert_eq!(o.intensity([5, -7, -1000]), quantise(&cfg, 0.4));
        assert_eq!(o.intensity([0, 0, 0]), 0);
        assert_eq!(Octahedral::side_for(1536), 39);
    }
}
