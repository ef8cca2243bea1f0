//! The sphere test image of the paper's Figures 4-7: an orthographic view of a unit sphere
//! filling an N x N image, so every visible normal direction appears once and slowly varying
//! normals show each map entry and every interpolation artefact.
//!
//! Pixel (x, y) has its centre at sx = (2x + 1 - N) / N (right) and sy = (N - 1 - 2y) / N
//! (up; row 0 is the top of the image). It is inside when sx² + sy² <= 1, with the normal
//! (sx, sy, sqrt(1 - sx² - sy²)) facing the default viewer on +z.

use crate::config::Config;
use glam::DVec3;

/// One inside pixel: column, row (from the top) and its gradient.
pub type Pixel = (u32, u32, [i32; 3]);

/// Largest shrink for a configuration: at k = grad_bits - 1 every normal still has a
/// component of at least 1/sqrt(3) * (2^(G-1) - 1) / 2^(G-1) > 0.5, so no gradient rounds
/// to zero; one more halving would leave only 0 and 1.
pub fn max_shrink(cfg: &Config) -> u32 {
    cfg.grad_bits - 1
}

/// The unit normal at the centre of pixel (x, y), or `None` outside the sphere.
pub fn normal(n: u32, x: u32, y: u32) -> Option<DVec3> {
    // Integer numerators and one division: mirrored pixels get exactly negated coordinates.
    let sx = (2.0 * x as f64 + 1.0 - n as f64) / n as f64;
    let sy = (n as f64 - 1.0 - 2.0 * y as f64) / n as f64;
    let r2 = sx * sx + sy * sy;
    (r2 <= 1.0).then(|| DVec3::new(sx, sy, (1.0 - r2).sqrt()))
}

/// A unit normal as a gradient: scaled to the full positive range 2^(G-1) - 1, then by 2^-k,
/// rounded once (half away from zero, so mirrored normals give mirrored gradients). Rounding
/// once rather than rounding the full-range gradient and then halving it k times keeps the
/// shrunk gradient the nearest integer vector to the normal at that scale.
pub fn gradient(cfg: &Config, n: DVec3, shrink: u32) -> [i32; 3] {
    let scale = *cfg.grad_range().end() as f64 / (1u64 << shrink) as f64;
    crate::geometry::round_gradient(n, scale)
}

/// Every inside pixel of an `n` x `n` sphere image in raster order (top row first, left to
/// right), with its gradient. Panics if `shrink` exceeds [`max_shrink`].
pub fn sphere_gradients(cfg: &Config, n: u32, shrink: u32) -> Vec<Pixel> {
    let mut v = Vec::with_capacity((n as usize * n as usize) * 4 / 5);
    v.extend(pixels(cfg, n, shrink));
    v
}

/// [`sphere_gradients`] one pixel at a time, for a caller that holds them its own way.
pub fn pixels(cfg: &Config, n: u32, shrink: u32) -> impl Iterator<Item = Pixel> + '_ {
    assert!(
        shrink <= max_shrink(cfg),
        "shrink {shrink} exceeds {}",
        max_shrink(cfg)
    );
    (0..n).flat_map(move |y| {
        (0..n).filter_map(move |x| normal(n, x, y).map(|nv| (x, y, gradient(cfg, nv, shrink))))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::sort_shift;

    #[test]
    fn geometry_and_orientation() {
        let c = Config::default();
        let px = sphere_gradients(&c, 512, 0);
        // Close to the disc's area, pi/4 of the image.
        let frac = px.len() as f64 / (512.0 * 512.0);
        assert!((frac - std::f64::consts::FRAC_PI_4).abs() < 0.002, "{frac}");
        // Centre faces the viewer; upper right has +x, +y.
        let centre = px.iter().find(|p| p.0 == 256 && p.1 == 256).unwrap();
        assert_eq!(centre.2[2], 2047);
        let ur = px.iter().find(|p| p.0 == 400 && p.1 == 100).unwrap();
        assert!(ur.2[0] > 0 && ur.2[1] > 0);
        // Corners are outside.
        assert!(normal(512, 0, 0).is_none() && normal(512, 511, 511).is_none());
    }

    #[test]
    fn shrink_keeps_gradients_in_range_and_nonzero() {
        for grad_bits in [8, 12, 16] {
            let c = Config {
                grad_bits,
                ..Config::default()
            };
            for k in 0..=max_shrink(&c) {
                let full = 1 << (grad_bits - 1 - k);
                for (_, _, g) in sphere_gradients(&c, 64, k) {
                    assert!(
                        g.iter()
                            .all(|&v| sort_shift::in_range(&c, v) && v.abs() <= full),
                        "G{grad_bits} k{k} {g:?}"
                    );
                    assert_ne!(g, [0, 0, 0]);
                }
            }
        }
    }

    #[test]
    fn left_right_mirror() {
        let c = Config::default();
        let px = sphere_gradients(&c, 100, 3);
        for &(x, y, g) in &px {
            let m = px.iter().find(|p| p.0 == 99 - x && p.1 == y).unwrap();
            assert_eq!(m.2, [-g[0], g[1], g[2]]);
        }
    }
}
