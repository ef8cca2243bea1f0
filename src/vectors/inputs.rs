//! The inputs of every stage's vectors: hand-picked corner cases first (FloPoCo's standard
//! test cases: never remove one, add new ones at the end), then seeded random draws from the
//! stage's input domain. Expected outputs come from the model (`Vectors::expected`).
//!
//! These are the generators the stages share (gradients, positions, colours); each stage's
//! own corners and random draws are in its folder (`Vectors::corners`, `Vectors::random`).

use crate::config::{Config, COLOR_BITS};
use crate::model::{Maps, Model, Trace};
use crate::rng::SplitMix64;

/// A gradient component as G-bit two's complement.
pub fn enc_grad(cfg: &Config, v: i32) -> u64 {
    (v as u32 as u64) & ((1u64 << cfg.grad_bits) - 1)
}

/// The inverse of [`enc_grad`]: sign-extends a G-bit field.
pub fn dec_grad(cfg: &Config, x: u64) -> i32 {
    let sh = 32 - cfg.grad_bits;
    ((x as u32) << sh) as i32 >> sh
}

/// Hand-picked gradients: the zero vector, equal components, ties between each pair of axes,
/// the most negative value in each position, components equal to the max, magnitude 1,
/// full-range maxima, every shift amount, and every sign combination with each axis as max.
pub fn gradient_corners(cfg: &Config) -> Vec<[i32; 3]> {
    let gb = cfg.grad_bits;
    let h = 1i32 << (gb - 1);
    let (maxp, minn) = (h - 1, -h);
    let mut v: Vec<[i32; 3]> = vec![[0, 0, 0]];
    // Three equal components.
    for k in [1, h / 3, maxp] {
        v.extend([[k, k, k], [k, -k, k], [-k, -k, -k], [-k, k, -k]]);
    }
    v.push([minn; 3]);
    // Two equal maxima in each pair of axes (the tie rule picks the lower axis).
    let (a, b) = (h / 2 + 3, h / 6);
    for (i, j, k) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
        for (si, sj) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
            let mut g = [0; 3];
            g[i] = si * a;
            g[j] = sj * a;
            g[k] = b;
            v.push(g);
        }
        let mut g = [0; 3];
        g[i] = minn;
        g[j] = minn;
        v.push(g);
    }
    // The most negative value in each position (its magnitude needs all G bits).
    for p in 0..3 {
        for others in [(0, 0), (1, 0), (maxp, maxp), (-maxp, 1), (minn + 1, -1)] {
            let mut g = [others.0, others.0, others.0];
            g[p] = minn;
            g[(p + 1) % 3] = others.0;
            g[(p + 2) % 3] = others.1;
            v.push(g);
        }
    }
    // A non-max component equal to the max, or equal after truncation to red_bits.
    v.extend([
        [maxp, maxp - 1, 0],
        [h / 2, h / 2 - 1, 1],
        [-3, 2, 3],
        [5, -5, 4],
        [0, 7, -7],
    ]);
    // Magnitude 1.
    v.extend([
        [1, 0, 0],
        [0, 1, 0],
        [0, 0, 1],
        [-1, 0, 0],
        [0, -1, 0],
        [0, 0, -1],
        [1, -1, 0],
        [-1, 1, -1],
    ]);
    // Full-range maxima.
    v.extend([
        [maxp, 0, 0],
        [0, maxp, 0],
        [0, 0, maxp],
        [maxp, maxp, 0],
        [-maxp, maxp - 1, 1],
        [maxp, -maxp, maxp],
    ]);
    // Every shift amount: a max with s leading zeros, at both ends of its range.
    for s in 0..gb {
        let axis = (s % 3) as usize;
        let lo = 1i32 << (gb - 1 - s);
        let hi = (1i32 << (gb - s)) - 1;
        let mut g = [lo / 2, -(lo / 3), lo / 5];
        g[axis] = if s == 0 { minn } else { lo };
        v.push(g);
        if s > 0 {
            let mut g = [-(hi / 2 + 1), hi / 3, -hi];
            g[axis] = -hi;
            g[(axis + 1) % 3] = hi - 1;
            v.push(g);
        }
    }
    // Every sign combination, each axis as the max.
    let (big, mid, small) = (h * 3 / 4, h / 3 + 1, h / 7 + 2);
    for axis in 0..3 {
        for signs in 0..8u32 {
            let sg = |bit: u32| if signs >> bit & 1 == 1 { -1 } else { 1 };
            let mut g = [0; 3];
            g[axis] = sg(0) * big;
            g[(axis + 1) % 3] = sg(1) * mid;
            g[(axis + 2) % 3] = sg(2) * small;
            v.push(g);
        }
    }
    debug_assert!(v.iter().flatten().all(|&c| (minn..=maxp).contains(&c)));
    v
}

/// Colour corners cycled through the top's corner vectors: black, white, one channel off,
/// just inside both ends, mid grey.
pub const COLOR_CORNERS: [[u32; 3]; 5] = [
    [0, 0, 0],
    [255, 255, 255],
    [255, 0, 128],
    [1, 254, 127],
    [128, 128, 128],
];

/// A magnitude with exactly `lz` leading zeros in `bits` bits (0 for lz = bits).
fn mag_with_lz(rng: &mut SplitMix64, bits: u32, lz: u32) -> u64 {
    if lz >= bits {
        0
    } else {
        rng.range(1 << (bits - 1 - lz), (1 << (bits - lz)) - 1)
    }
}

/// A random gradient whose max has a uniformly drawn number of leading zeros in
/// `0..=max_lz`, so every shift amount is well covered, with occasional ties.
pub fn gradient_by_shift(cfg: &Config, rng: &mut SplitMix64, max_lz: u32) -> [i32; 3] {
    let gb = cfg.grad_bits;
    let h = 1i64 << (gb - 1);
    let s = rng.range(0, max_lz as u64) as u32;
    // Signed component from a magnitude: 2^(G-1) exists only as the most negative value.
    let signed = |rng: &mut SplitMix64, mag: u64| -> i32 {
        if mag as i64 == h || rng.chance(1, 2) {
            -(mag as i64) as i32
        } else {
            mag as i32
        }
    };
    let axis = rng.below(3) as usize;
    let mut g = [0i32; 3];
    // No leading zero: the magnitude 2^(G-1) of the most negative value is the only one.
    let max_mag = if s == 0 {
        h as u64
    } else {
        mag_with_lz(rng, gb, s)
    };
    g[axis] = signed(rng, max_mag);
    for k in 1..3 {
        let p = (axis + k) % 3;
        let mag = if rng.chance(1, 8) {
            max_mag
        } else {
            // At least as many leading zeros as the max: never a larger shift.
            let lz = rng.range(s.max(1) as u64, gb as u64) as u32;
            mag_with_lz(rng, gb, lz)
        };
        g[p] = signed(rng, mag);
    }
    g
}

/// A uniform G-bit two's-complement component.
fn uniform_grad(cfg: &Config, rng: &mut SplitMix64) -> i32 {
    dec_grad(cfg, rng.bits(cfg.grad_bits))
}

/// Gradients for the top: uniform over the whole range, or by shift amount, and rarely zero.
pub fn random_top_gradient(cfg: &Config, rng: &mut SplitMix64) -> [i32; 3] {
    match rng.below(64) {
        0 => [0, 0, 0],
        1..=31 => [
            uniform_grad(cfg, rng),
            uniform_grad(cfg, rng),
            uniform_grad(cfg, rng),
        ],
        _ => gradient_by_shift(cfg, rng, cfg.grad_bits - 1),
    }
}

/// A gradient as its three vector fields.
pub fn grads(cfg: &Config, g: [i32; 3]) -> Vec<u64> {
    g.iter().map(|&c| enc_grad(cfg, c)).collect()
}

/// Positions worth testing: the ends, and both sides of every base boundary.
pub fn position_corners(cfg: &Config) -> Vec<u32> {
    let (s, pmax) = (cfg.step(), cfg.pos_max());
    let mut p = vec![0, 1, pmax.saturating_sub(1), pmax];
    for k in 1..cfg.entries() {
        p.extend([k * s - 1, k * s, k * s + 1]);
    }
    p.retain(|&x| x <= pmax);
    p.sort_unstable();
    p.dedup();
    p
}

/// One sample of the whole pipeline: what the top is given (the gradient, the colour, the
/// map buffer it reads) and every value the model computes for it on the way.
#[derive(Clone, Copy, Debug)]
pub struct Traced {
    pub g: [i32; 3],
    pub rgb: [u32; 3],
    pub buf: u64,
    pub trace: Trace,
}

impl Traced {
    /// `g` and `rgb` through the model, reading `maps` as buffer `buf`.
    pub fn new(model: &Model, maps: &Maps, buf: u64, g: [i32; 3], rgb: [u32; 3]) -> Traced {
        Traced {
            g,
            rgb,
            buf,
            trace: model.trace(maps, g, rgb),
        }
    }
}

/// The gradient corners traced through the model with `maps` (buffer 0, no colour): the
/// values they bring to each stage, which the stages' corner cases include.
pub fn corner_traces<'a>(model: &'a Model, maps: &'a Maps) -> impl Iterator<Item = Traced> + 'a {
    gradient_corners(&model.cfg)
        .into_iter()
        .map(move |g| Traced::new(model, maps, 0, g, [0; 3]))
}

/// A channel value that hits 0 and 255 more often than uniform draws would.
pub fn color_channel(rng: &mut SplitMix64) -> u64 {
    match rng.below(16) {
        0 => 0,
        1 => 255,
        _ => rng.bits(COLOR_BITS),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::sort_shift;

    #[test]
    fn grad_codec_round_trips() {
        for gb in [8, 12, 16] {
            let cfg = Config {
                grad_bits: gb,
                red_bits: 6,
                ..Config::default()
            };
            let h = 1i32 << (gb - 1);
            for v in [-h, -h + 1, -1, 0, 1, h - 1] {
                assert_eq!(dec_grad(&cfg, enc_grad(&cfg, v)), v);
                assert!(enc_grad(&cfg, v) < 1 << gb);
            }
        }
    }

    #[test]
    fn corners_are_in_range_and_cover_every_shift() {
        for gb in [8, 12, 16] {
            let cfg = Config {
                grad_bits: gb,
                red_bits: 6,
                ..Config::default()
            };
            let c = gradient_corners(&cfg);
            assert!(c.iter().flatten().all(|&v| sort_shift::in_range(&cfg, v)));
            let shifts: std::collections::BTreeSet<u32> = c
                .iter()
                .filter(|g| **g != [0; 3])
                .map(|&g| sort_shift::eval(&cfg, g).shift)
                .collect();
            assert_eq!(shifts.len() as u32, gb, "G{gb}: {shifts:?}");
        }
    }

    #[test]
    fn random_gradients_cover_every_shift() {
        let cfg = Config::default();
        let mut rng = SplitMix64::new(1);
        let mut seen = vec![0u32; cfg.grad_bits as usize + 1];
        for _ in 0..2000 {
            let g = gradient_by_shift(&cfg, &mut rng, cfg.grad_bits);
            assert!(g.iter().all(|&v| sort_shift::in_range(&cfg, v)), "{g:?}");
            if g != [0; 3] {
                seen[sort_shift::eval(&cfg, g).shift as usize] += 1;
            }
        }
        assert!(
            seen[..cfg.grad_bits as usize].iter().all(|&n| n > 50),
            "{seen:?}"
        );
    }
}
