//! Numerical stability: the error does not grow as the gradient magnitude shrinks, for every
//! shift amount down to magnitude 1.
//!
//! The argument: sort & shift shifts out the max's leading zeros before reducing, so a
//! gradient and its double reduce to the same (m, a, b) and shade identically; the reference
//! normalises, so it gives the same value for both too. Every gradient of shift amount s + 1
//! doubles into one of shift amount s (s >= 1; shift 0 is the lone most negative magnitude),
//! so each class's errors are a subset of the next larger class's. The tests check the premise
//! exhaustively for small magnitudes and at random elsewhere, and the consequence exactly on
//! every gradient of a 9-bit configuration.

use rayon::prelude::*;
use rmapgen::config::Config;
use rmapgen::model::{sort_shift, Model};
use rmapgen::reference::Reference;
use rmapgen::rng::SplitMix64;
use rmapgen::scene::Scene;
use rmapgen::stress::{exhaustive, Setup};

/// g * 2^k when every component stays in range.
fn scaled(cfg: &Config, g: [i32; 3], k: u32) -> Option<[i32; 3]> {
    let s = g.map(|c| c.checked_mul(1 << k));
    s.iter()
        .all(|c| c.is_some_and(|c| sort_shift::in_range(cfg, c)))
        .then(|| s.map(|c| c.unwrap()))
}

fn check_scaling(cfg: &Config, scene: &Scene, grads: &[[i32; 3]]) -> usize {
    let model = Model::new(cfg);
    let maps = scene.maps(cfg);
    let reference = Reference::new(cfg, scene);
    grads
        .par_iter()
        .map(|&g| {
            let (want, want_ref) = (model.trace(&maps, g, [0; 3]), reference.exact(g));
            let mut n = 0;
            for k in 1..cfg.grad_bits {
                let Some(h) = scaled(cfg, g, k) else { break };
                let t = model.trace(&maps, h, [0; 3]);
                assert_eq!(t.sort.shift + k, want.sort.shift, "{g:?} * 2^{k}");
                assert_eq!(
                    (t.sort.m, t.sort.a, t.sort.b, t.out),
                    (want.sort.m, want.sort.a, want.sort.b, want.out),
                    "{g:?} * 2^{k}"
                );
                assert_eq!(reference.exact(h), want_ref, "reference of {g:?} * 2^{k}");
                n += 1;
            }
            n
        })
        .sum()
}

/// Every gradient with components in -64..=64 (magnitudes 1 to 64, shift amounts 5 to 11),
/// doubled up to the full range: the same output and the same reference at every scale.
#[test]
fn small_gradients_shade_as_their_doubles() {
    let cfg = Config::default();
    let grads: Vec<[i32; 3]> = (-64..=64)
        .flat_map(|x| (-64..=64).flat_map(move |y| (-64..=64).map(move |z| [x, y, z])))
        .filter(|&g| g != [0, 0, 0])
        .collect();
    let checked = check_scaling(&cfg, &Scene::standard(), &grads);
    assert!(checked > 4 * grads.len(), "{checked} scaled copies checked");
}

/// Random gradients of every magnitude, in other configurations and scenes.
#[test]
fn gradients_of_every_magnitude_shade_as_their_doubles() {
    let configs = [
        Config::default(),
        Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        },
        Config {
            grad_bits: 16,
            red_bits: 10,
            recip_bits: 12,
            frac_bits: 10,
            index_bits: 4,
            ..Config::default()
        },
    ];
    for cfg in configs {
        let mut rng = SplitMix64::new(11);
        let grads: Vec<[i32; 3]> = (0..20_000u64)
            .map(|i| {
                // Largest magnitude 2^k .. 2^(k+1) - 1 for every k below the top bit.
                let k = (i % (cfg.grad_bits as u64 - 1)) as u32;
                let top = (1u64 << (k + 1)) - 1;
                let mut g = [(); 3].map(|_| rng.range(0, top) as i32);
                g[(i % 3) as usize] = rng.range(1 << k, top) as i32;
                g.map(|c| if rng.chance(1, 2) { -c } else { c })
            })
            .collect();
        let checked = check_scaling(&cfg, &Scene::alternate(), &grads);
        assert!(checked > grads.len(), "{}: {checked}", cfg.summary());
    }
}

/// The consequence, exactly: over every gradient of a 9-bit configuration, the worst
/// intensity error and the worst angular error never grow from one shift amount to the next
/// smaller magnitudes, down to magnitude 1.
#[test]
fn worst_errors_never_grow_as_magnitude_shrinks() {
    let cfg = Config {
        grad_bits: 9,
        ..Config::default()
    };
    for scene in [Scene::standard(), Scene::alternate()] {
        let setup = Setup::new(&cfg, &scene, scene.maps(&cfg));
        let r = exhaustive::run(&setup, &|_| {}).unwrap();
        assert_eq!(r.mismatches, 0);
        let err: Vec<u64> = r
            .classes
            .iter()
            .map(|c| c.worst_error.unwrap().abs())
            .collect();
        let ang: Vec<f64> = r
            .classes
            .iter()
            .map(|c| c.worst_angle.unwrap().degrees)
            .collect();
        for s in 1..err.len() - 1 {
            assert!(
                err[s + 1] <= err[s],
                "shift {} error {} > shift {s} error {}: {err:?}",
                s + 1,
                err[s + 1],
                err[s]
            );
            assert!(
                ang[s + 1] <= ang[s] + 1e-12,
                "shift {} angle: {ang:?}",
                s + 1
            );
        }
        // Magnitude 1 (the last class) hits the axes and the cube's diagonals exactly.
        assert!(ang[err.len() - 1] < 1e-6, "{ang:?}");
    }
}
