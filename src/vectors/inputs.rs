//! The inputs of every stage's vectors: hand-picked corner cases first (FloPoCo's standard
//! test cases: never remove one, add new ones at the end), then seeded random draws from the
//! stage's input domain. Expected outputs are added by the model in `super::eval`.
//!
//! Each input vector is a list of field values in the order of `Stage::fields`, inputs only.

use super::Stage;
use crate::config::{Config, COLOR_BITS};
use crate::model::{Maps, Model};
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

fn grads(cfg: &Config, g: [i32; 3]) -> Vec<u64> {
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

/// The hand-picked inputs of a stage. `model` and `maps` supply the trace-derived cases (the
/// intermediate values of the gradient corners as they reach this stage).
pub fn corners(stage: Stage, model: &Model, maps: &Maps) -> Vec<Vec<u64>> {
    let cfg = &model.cfg;
    let traces = || {
        gradient_corners(cfg)
            .into_iter()
            .map(move |g| model.trace(maps, g, [0; 3]))
    };
    let mut out: Vec<Vec<u64>> = Vec::new();
    match stage {
        Stage::ZeroDetect => {
            let h = 1i32 << (cfg.grad_bits - 1);
            out.push(grads(cfg, [0, 0, 0]));
            for p in 0..3 {
                for c in [1, -1, -h, h - 1] {
                    let mut g = [0; 3];
                    g[p] = c;
                    out.push(grads(cfg, g));
                }
            }
            for g in gradient_corners(cfg) {
                out.push(grads(cfg, g));
            }
        }
        Stage::SortShift => {
            for g in gradient_corners(cfg) {
                out.push(grads(cfg, g));
            }
        }
        Stage::Normalise => {
            let r = cfg.red_bits;
            let (lo, hi) = (1u64 << (r - 1), (1u64 << r) - 1);
            // The zero vector reaches normalise as m = a = b = 0.
            out.push(vec![0, 0, 0]);
            // Both ends of the reciprocal ROM, with a and b at 0, 1, half, max - 1 and max.
            for m in [lo, lo + 1, hi - 1, hi] {
                let cs = [0, 1, m / 2, m - 1, m];
                for (i, &a) in cs.iter().enumerate() {
                    for &b in &cs[i..] {
                        out.push(vec![m, a, b]);
                        if a != b {
                            out.push(vec![m, b, a]);
                        }
                    }
                }
            }
            // Every reciprocal-ROM entry once, with a = m - 1 (rounds nearest to 1.0).
            for m in lo..=hi {
                out.push(vec![m, m - 1, m * 3 / 4]);
            }
            for t in traces() {
                out.push(vec![t.sort.m as u64, t.sort.a as u64, t.sort.b as u64]);
            }
        }
        Stage::AtanRom | Stage::LinearIndex => {
            // Exhaustive: every fraction code in both lanes, which covers 0, all ones and
            // every point where the position steps.
            let fmax = cfg.frac_max() as u64;
            for u in 0..=fmax {
                out.push(vec![u, fmax - u]);
            }
        }
        Stage::MapLookup => {
            let p = position_corners(cfg);
            let pmax = cfg.pos_max() as u64;
            let n = p.len();
            // Every position corner in each lane, axes, signs and buffers cycling.
            for (j, &pc) in p.iter().enumerate() {
                let other = p[(j * 7 + 3) % n] as u64;
                let k = j as u64;
                out.push(vec![
                    k % 3,
                    k & 1,
                    (k >> 1) & 1,
                    (k >> 2) & 1,
                    pc as u64,
                    other,
                    (k >> 3) & 1,
                ]);
                out.push(vec![
                    (k + 1) % 3,
                    (k >> 2) & 1,
                    k & 1,
                    (k >> 1) & 1,
                    other,
                    pc as u64,
                    !(k >> 3) & 1,
                ]);
            }
            // Every axis, sign combination and buffer at the two extreme corners.
            for buf in 0..2 {
                for axis in 0..3 {
                    for signs in 0..8u64 {
                        for (pu, pv) in [(0, 0), (pmax, pmax), (0, pmax)] {
                            out.push(vec![
                                axis,
                                signs & 1,
                                (signs >> 1) & 1,
                                signs >> 2,
                                pu,
                                pv,
                                buf,
                            ]);
                        }
                    }
                }
            }
            for (i, t) in traces().enumerate() {
                let s = t.sort;
                out.push(vec![
                    s.axis as u64,
                    s.s_max as u64,
                    s.s_u as u64,
                    s.s_v as u64,
                    t.p_u as u64,
                    t.p_v as u64,
                    (i & 1) as u64,
                ]);
            }
        }
        Stage::Interpolate => {
            let s = cfg.step() as u64;
            let mx = cfg.map_max() as u64;
            let mut ws = vec![0, 1, s / 2, s - 1, s];
            ws.sort_unstable();
            ws.dedup();
            let patterns: [[u64; 4]; 10] = [
                [0, 0, 0, 0],
                [mx, mx, mx, mx],
                [0, mx, 0, mx],
                [mx, 0, mx, 0],
                [0, 0, mx, mx],
                [mx, mx, 0, 0],
                [0, mx, mx, 0],
                [mx, 0, 0, mx],
                [1, 2, 3, 4],
                [mx / 2, mx / 2 + 1, mx / 2 - 1, mx / 3],
            ];
            for e in patterns {
                for &wu in &ws {
                    for &wv in &ws {
                        out.push(vec![e[0], e[1], e[2], e[3], wu, wv]);
                    }
                }
            }
            for t in traces() {
                let l = t.lookup;
                out.push(vec![
                    l.e[0] as u64,
                    l.e[1] as u64,
                    l.e[2] as u64,
                    l.e[3] as u64,
                    l.w_u as u64,
                    l.w_v as u64,
                ]);
            }
        }
        Stage::ColorMul => {
            let mx = cfg.map_max() as u64;
            for i in [0, 1, mx / 2, mx - 1, mx] {
                for c in COLOR_CORNERS {
                    out.push(vec![i, c[0] as u64, c[1] as u64, c[2] as u64]);
                }
            }
            // Every intensity once, with a full, a middle and a minimal channel.
            for i in 0..=mx {
                out.push(vec![i, 255, 128, 1]);
            }
        }
        Stage::Top => unreachable!("top corners depend on the map part; see top_corners"),
    }
    out
}

/// The top's hand-picked inputs for one map: every gradient corner, colours cycling.
pub fn top_corners(cfg: &Config, map: u64) -> Vec<Vec<u64>> {
    gradient_corners(cfg)
        .into_iter()
        .enumerate()
        .map(|(i, g)| {
            let mut v = vec![map];
            v.extend(grads(cfg, g));
            if cfg.color {
                v.extend(
                    COLOR_CORNERS[i % COLOR_CORNERS.len()]
                        .iter()
                        .map(|&c| c as u64),
                );
            }
            v
        })
        .collect()
}

/// One random input of the top for one map.
pub fn top_random(cfg: &Config, rng: &mut SplitMix64, map: u64) -> Vec<u64> {
    let mut v = vec![map];
    v.extend(grads(cfg, random_top_gradient(cfg, rng)));
    if cfg.color {
        for _ in 0..3 {
            v.push(rng.bits(COLOR_BITS));
        }
    }
    v
}

/// A channel value that hits 0 and 255 more often than uniform draws would.
fn color_channel(rng: &mut SplitMix64) -> u64 {
    match rng.below(16) {
        0 => 0,
        1 => 255,
        _ => rng.bits(COLOR_BITS),
    }
}

/// One random input of a (non-top) stage, drawn from the values the stage can receive.
pub fn random(stage: Stage, cfg: &Config, rng: &mut SplitMix64) -> Vec<u64> {
    match stage {
        Stage::ZeroDetect => (0..3)
            .map(|_| {
                if rng.chance(1, 2) {
                    0
                } else {
                    rng.bits(cfg.grad_bits)
                }
            })
            .collect(),
        Stage::SortShift => grads(cfg, gradient_by_shift(cfg, rng, cfg.grad_bits)),
        Stage::Normalise => {
            let r = cfg.red_bits;
            if rng.chance(1, 64) {
                return vec![0, 0, 0];
            }
            let m = rng.range(1 << (r - 1), (1 << r) - 1);
            let lane = |rng: &mut SplitMix64| match rng.below(16) {
                0 | 1 => m,
                2 => 0,
                _ => rng.range(0, m),
            };
            let a = lane(rng);
            let b = lane(rng);
            vec![m, a, b]
        }
        Stage::AtanRom | Stage::LinearIndex => {
            vec![rng.bits(cfg.frac_bits), rng.bits(cfg.frac_bits)]
        }
        Stage::MapLookup => {
            let pmax = cfg.pos_max() as u64;
            vec![
                rng.below(3),
                rng.bits(1),
                rng.bits(1),
                rng.bits(1),
                rng.range(0, pmax),
                rng.range(0, pmax),
                rng.bits(1),
            ]
        }
        Stage::Interpolate => {
            let s = cfg.step() as u64;
            let mut v: Vec<u64> = (0..4).map(|_| rng.bits(cfg.map_bits)).collect();
            v.push(rng.range(0, s));
            v.push(rng.range(0, s));
            v
        }
        Stage::ColorMul => {
            let mx = cfg.map_max() as u64;
            let i = match rng.below(16) {
                0 => 0,
                1 => mx,
                _ => rng.range(0, mx),
            };
            vec![
                i,
                color_channel(rng),
                color_channel(rng),
                color_channel(rng),
            ]
        }
        Stage::Top => unreachable!("top inputs carry a map part; see top_random"),
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
