//! The fused batch path (`model::fast`) equals `Model::intensity` on every input: proptest
//! over random configurations, maps and gradients; every gradient of small configurations;
//! and, for the default configuration, every entry of both fused tables reached through the
//! whole model.

use crate::model_stages::any_config;
use proptest::prelude::*;
use rayon::prelude::*;
use rmapgen::config::Config;
use rmapgen::model::fast::{intensity_at, ordered_signs, FastShader};
use rmapgen::model::{reflectance_map, Maps, Model};
use rmapgen::rng::SplitMix64;
use rmapgen::scene::Scene;

/// Maps with pseudo-random entries over the whole output range, so every entry matters.
fn random_maps(cfg: &Config, seed: u64) -> Maps {
    let mut rng = SplitMix64::new(seed);
    let n = 3 * cfg.map_entries() as usize;
    Maps::from_data(cfg, (0..n).map(|_| rng.bits(cfg.map_bits) as u32).collect())
}

/// Gradients mixing full-range values, small values (every shift) and ties.
fn gradients(cfg: &Config, n: usize, seed: u64) -> Vec<[i32; 3]> {
    let mut rng = SplitMix64::new(seed);
    let half = 1i64 << (cfg.grad_bits - 1);
    (0..n)
        .map(|_| {
            let k = rng.below(cfg.grad_bits as u64) as u32;
            let mut g = [(); 3].map(|_| match rng.below(3) {
                0 => rng.range(0, 2 * half as u64 - 1) as i64 - half,
                _ => rng.range(0, 2 << k) as i64 - (1 << k),
            });
            if rng.chance(1, 4) {
                g[rng.below(3) as usize] = g[rng.below(3) as usize].wrapping_neg();
            }
            g.map(|c| c.clamp(-half, half - 1) as i32)
        })
        .collect()
}

fn check_batch(model: &Model, maps: &Maps, fast: &FastShader, grads: &[[i32; 3]]) {
    let mut out = vec![0u16; grads.len()];
    fast.shade_batch(grads, &mut out);
    let mut par = vec![0u16; grads.len()];
    fast.shade_batch_par(grads, &mut par);
    for (k, g) in grads.iter().enumerate() {
        let want = model.intensity(maps, *g);
        assert_eq!(out[k] as u32, want, "{} at {g:?}", model.cfg.summary());
        assert_eq!(par[k], out[k], "parallel at {g:?}");
        assert_eq!(fast.shade(*g), want, "single at {g:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn equals_the_model_on_random_configs(cfg in any_config(), seed in any::<u64>()) {
        let model = Model::new(&cfg);
        let maps = random_maps(&cfg, seed);
        let mut fast = FastShader::new(&model, &maps);
        check_batch(&model, &maps, &fast, &gradients(&cfg, 3000, seed));
        // A new frame: only the intensity table changes.
        let maps2 = random_maps(&cfg, seed ^ 1);
        fast.set_maps(&maps2);
        check_batch(&model, &maps2, &fast, &gradients(&cfg, 500, seed ^ 2));
    }
}

/// Configurations whose tables are too large to fuse take the per-stage paths.
#[test]
fn unfused_stages_equal_the_model() {
    let wide = Config {
        grad_bits: 16,
        red_bits: 12,
        recip_bits: 14,
        frac_bits: 12,
        index_bits: 6,
        interp_bits: 5,
        ..Config::default()
    };
    let half = Config {
        red_bits: 12,
        grad_bits: 12,
        recip_bits: 14,
        frac_bits: 10,
        ..Config::default()
    };
    for (cfg, fused) in [(wide, (false, false)), (half, (false, true))] {
        let model = Model::new(&cfg);
        let maps = random_maps(&cfg, 9);
        let fast = FastShader::new(&model, &maps);
        assert_eq!(fast.fused(), fused, "{}", cfg.summary());
        check_batch(&model, &maps, &fast, &gradients(&cfg, 20_000, 4));
    }
}

/// Every gradient of 8-bit configurations: 2^24 inputs each.
#[test]
fn equals_the_model_on_every_8_bit_gradient() {
    let base = Config {
        grad_bits: 8,
        red_bits: 8,
        ..Config::default()
    };
    let configs = [
        base.clone(),
        Config {
            red_bits: 6,
            recip_bits: 8,
            frac_bits: 6,
            ..base.clone()
        },
        Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            index_bits: 4,
            ..base.clone()
        },
    ];
    for cfg in configs {
        let model = Model::new(&cfg);
        let maps = random_maps(&cfg, 2);
        let fast = FastShader::new(&model, &maps);
        let bad: usize = (-128..128i32)
            .into_par_iter()
            .map(|x| {
                let grads: Vec<[i32; 3]> = (-128..128)
                    .flat_map(|y| (-128..128).map(move |z| [x, y, z]))
                    .collect();
                let mut out = vec![0u16; grads.len()];
                fast.shade_batch(&grads, &mut out);
                grads
                    .iter()
                    .zip(&out)
                    .filter(|(g, o)| model.intensity(&maps, **g) != **o as u32)
                    .count()
            })
            .sum();
        assert_eq!(bad, 0, "{}", cfg.summary());
    }
}

/// The default configuration's fused tables, entry by entry, through the whole model: every
/// reachable (m, a) of the position table, every (m, a, b) triple, and every
/// (axis, signs, p_u, p_v) of the intensity table.
#[test]
fn default_tables_are_exact_over_their_domains() {
    let cfg = Config::default();
    let model = Model::new(&cfg);
    let scene = Scene::standard().prepared();
    let maps = reflectance_map::contents(&cfg, |n| scene.shade(n));
    let fast = FastShader::new(&model, &maps);
    assert_eq!(fast.fused(), (true, true));
    let half = 1u32 << (cfg.red_bits - 1);
    // A magnitude of c << 3 has shift 1 and reduces to exactly c (12 bits down to 8).
    let up = cfg.grad_bits - cfg.red_bits - 1;
    let mags = |m: u32, a: u32, b: u32| [m << up, a << up, b << up];

    // Position table: every m with its MSB set and every a <= m.
    for m in half..2 * half {
        for a in 0..=m {
            let g = mags(m, a, 0).map(|c| c as i32);
            let t = model.trace(&maps, g, [0; 3]);
            assert_eq!((t.sort.m, t.sort.a), (m, a));
            assert_eq!(fast.position(m, a), t.p_u, "m{m} a{a}");
        }
    }

    // Every (m, a, b), each under a different (axis, signs), through the batch path.
    let bad: usize = (half..2 * half)
        .into_par_iter()
        .map(|m| {
            let mut grads = Vec::new();
            for a in 0..=m {
                for b in 0..=m {
                    let k = (m + 3 * a + 7 * b) % 24;
                    let (axis, code) = (k / 8, k % 8);
                    let [mx, mu, mv] = mags(m, a, b);
                    // Keep the max axis: the lower axes must stay strictly below m.
                    if (axis >= 1 && a == m) || (axis == 2 && b == m) {
                        continue;
                    }
                    let mut g = rmapgen::geometry::place(axis, mx, mu, mv).map(|c| c as i32);
                    for (j, c) in g.iter_mut().enumerate() {
                        if (code >> j) & 1 == 1 {
                            *c = -*c;
                        }
                    }
                    grads.push(g);
                }
            }
            let mut out = vec![0u16; grads.len()];
            fast.shade_batch(&grads, &mut out);
            grads
                .iter()
                .zip(&out)
                .filter(|(g, o)| model.intensity(&maps, **g) != **o as u32)
                .count()
        })
        .sum();
    assert_eq!(bad, 0);

    // Intensity table: every entry equals the look-up and interpolation stages.
    for axis in 0..3 {
        for code in 0..8 {
            for p_u in 0..=cfg.pos_max() {
                for p_v in 0..=cfg.pos_max() {
                    let want = intensity_at(&cfg, &maps, axis, ordered_signs(axis, code), p_u, p_v);
                    assert_eq!(fast.intensity_at(axis, code, p_u, p_v), want);
                }
            }
        }
    }
    // ... and every (axis, signs) with every (a, b) at the largest m, through the model.
    let m = 2 * half - 1;
    let bad: usize = (0..24u32)
        .into_par_iter()
        .map(|k| {
            let (axis, code) = (k / 8, k % 8);
            let mut grads = Vec::new();
            for a in 0..=m {
                for b in 0..=m {
                    if (axis >= 1 && a == m) || (axis == 2 && b == m) {
                        continue;
                    }
                    let [mx, mu, mv] = mags(m, a, b).map(|c| c as i32);
                    let mut g = rmapgen::geometry::place(axis, mx, mu, mv);
                    for (j, c) in g.iter_mut().enumerate() {
                        if (code >> j) & 1 == 1 {
                            *c = -*c;
                        }
                    }
                    grads.push(g);
                }
            }
            let mut out = vec![0u16; grads.len()];
            fast.shade_batch(&grads, &mut out);
            grads
                .iter()
                .zip(&out)
                .filter(|(g, o)| model.intensity(&maps, **g) != **o as u32)
                .count()
        })
        .sum();
    assert_eq!(bad, 0);
}
