//! Stress runs (`rmapgen::stress`): the sampled run of `make test` against the bounds the
//! exhaustive run measured, and the exhaustive run's factored search against brute force.

use rayon::prelude::*;
use rmapgen::config::Config;
use rmapgen::rng::SplitMix64;
use rmapgen::scene::Scene;
use rmapgen::stress::{self, exhaustive, Setup};

/// The exact worst |model - reference| per shift amount (0..=11) of the default configuration
/// on the standard scene with the sampled map, from `rmapgen stress --exhaustive` over all
/// 2^36 gradients (docs/PERFORMANCE.md). A sampled run can only find these or less.
const EXHAUSTIVE_MAX_ERROR: [u64; 12] = [5, 18, 17, 17, 15, 15, 15, 14, 12, 11, 3, 0];
/// The exact worst angular error (degrees) per shift amount, same run, rounded up.
const EXHAUSTIVE_MAX_ANGLE: [f64; 12] = [
    1.0986, 1.1934, 1.1180, 0.9693, 0.7196, 0.7084, 0.7084, 0.7084, 0.5941, 0.5024, 0.0653, 0.0,
];

/// At least 10^7 gradients sweeping every magnitude 1..=2048 (so every shift amount), through
/// every stage of the model (with overflow checks on in the dev profile), against the fast
/// path, the float reference and the true direction.
#[test]
fn sampled_run_stays_within_the_exhaustive_bounds() {
    let cfg = Config::default();
    let scene = Scene::standard();
    let setup = Setup::new(&cfg, &scene, scene.maps(&cfg));
    let r = stress::sampled(&setup, 10_000_000, 1);
    assert_eq!(r.inputs, 10_000_000);
    assert_eq!(
        r.mismatches, 0,
        "fast path against the model: first at {:?}",
        r.first_mismatch
    );
    // The report says whether this build checks overflows: on under `cargo test` (the dev
    // profile), off under make test (the release build users run).
    assert_eq!(r.overflow_checks, cfg!(debug_assertions));
    assert_eq!(r.classes.len(), 12);
    for c in &r.classes {
        let s = c.shift as usize;
        assert!(c.inputs > 0, "shift {s} sampled");
        let e = c.worst_error.expect("errors measured");
        let a = c.worst_angle.expect("angles measured");
        assert!(e.abs() <= EXHAUSTIVE_MAX_ERROR[s], "shift {s}: {e:?}");
        assert!(a.degrees <= EXHAUSTIVE_MAX_ANGLE[s], "shift {s}: {a:?}");
    }
    // The sample finds the worst cases' neighbourhood: within 2 LSB of the exact maximum.
    assert!(
        r.max_abs_error() + 2 >= EXHAUSTIVE_MAX_ERROR[1],
        "{:?}",
        r.worst_error
    );
    assert!(r.max_angle_deg() > 1.0);
}

/// Brute force over every gradient: per class, the worst error and angle, and the output
/// counts at 0 and full scale.
fn brute_force(setup: &Setup) -> Vec<(u64, u64, f64, u64, u64)> {
    let cfg = &setup.cfg;
    let half = 1i32 << (cfg.grad_bits - 1);
    let classes = stress::classes(cfg) as usize;
    (-half..half)
        .into_par_iter()
        .map(|x| {
            let mut acc = vec![(0u64, 0u64, 0f64, 0u64, 0u64); classes];
            for y in -half..half {
                for z in -half..half {
                    let g = [x, y, z];
                    if g == [0, 0, 0] {
                        continue;
                    }
                    let t = setup.model.trace(&setup.maps, g, [0; 3]);
                    let s = t.sort;
                    let out = t.out.intensity;
                    let e = (out as i64 - setup.reference.intensity(g) as i64).unsigned_abs();
                    let d = stress::encoded_direction(
                        &setup.tangents,
                        s.axis,
                        (s.s_max, s.s_u, s.s_v),
                        t.p_u,
                        t.p_v,
                    );
                    let gv = glam::DVec3::new(x as f64, y as f64, z as f64).normalize();
                    let a = &mut acc[s.shift as usize];
                    a.0 += 1;
                    a.1 = a.1.max(e);
                    a.2 = a.2.max(stress::angle_deg(d, gv));
                    a.3 += (out == 0) as u64;
                    a.4 += (out == cfg.map_max()) as u64;
                }
            }
            acc
        })
        .reduce(
            || vec![(0, 0, 0.0, 0, 0); classes],
            |a, b| {
                a.iter()
                    .zip(&b)
                    .map(|(p, q)| (p.0 + q.0, p.1.max(q.1), p.2.max(q.2), p.3 + q.3, p.4 + q.4))
                    .collect()
            },
        )
}

/// The exhaustive run's factored evaluation and bounded error search give exactly what
/// evaluating every 8-bit gradient one by one gives, for scenes with a highlight, two lights
/// and two-sided lighting, with and without compensation and interpolation, and with a
/// compensation table loaded with the maps (`comp_table = ram`, a table bunched toward small
/// tangents): its angles measured from the positions' own tangent ranges.
#[test]
fn exhaustive_equals_brute_force_on_8_bit_gradients() {
    let base = Config {
        grad_bits: 8,
        red_bits: 8,
        ..Config::default()
    };
    let mut two_sided = Scene::alternate();
    two_sided.view.two_sided = true;
    two_sided.view.direction = [0.3, -0.2, 1.0];
    let cases = [
        (base.clone(), Scene::standard()),
        (
            Config {
                red_bits: 6,
                recip_bits: 8,
                frac_bits: 6,
                compensation: false,
                ..base.clone()
            },
            Scene::alternate(),
        ),
        (
            Config {
                interpolation: false,
                interp_bits: 0,
                ..base.clone()
            },
            two_sided,
        ),
    ];
    let loaded = Config {
        comp_table: rmapgen::config::CompTable::Ram,
        ..base.clone()
    };
    let squashed: Vec<u32> = (0..loaded.atan_entries())
        .map(|u| {
            let x = u as f64 / (loaded.atan_entries() - 1) as f64;
            (x.sqrt() * loaded.pos_max() as f64).round() as u32
        })
        .collect();
    let mut setups: Vec<(Config, Setup)> = cases
        .into_iter()
        .map(|(cfg, scene)| {
            let s = Setup::new(&cfg, &scene, scene.maps(&cfg));
            (cfg, s)
        })
        .collect();
    let scene = Scene::standard();
    let maps = scene.maps(&loaded).with_table(&loaded, squashed).unwrap();
    let table_setup = Setup::new(&loaded, &scene, maps);
    // The table is honoured: its positions stand for other tangents than the atan ROM's.
    let rom = Setup::new(&base, &scene, scene.maps(&base));
    assert!(table_setup
        .tangents
        .iter()
        .zip(&rom.tangents)
        .any(|(t, r)| (t - r).abs() > 0.01));
    setups.push((loaded, table_setup));
    for (cfg, setup) in setups {
        let r = exhaustive::run(&setup, &|_| {}).unwrap();
        assert_eq!(r.inputs, 1 << 24);
        assert_eq!(r.mismatches, 0);
        let want = brute_force(&setup);
        for (c, w) in r.classes.iter().zip(&want) {
            let what = format!("{} shift {}", cfg.summary(), c.shift);
            assert_eq!(c.inputs, w.0, "{what}");
            assert_eq!(c.worst_error.map_or(0, |e| e.abs()), w.1, "{what}");
            let a = c.worst_angle.map_or(0.0, |a| a.degrees);
            assert!((a - w.2).abs() < 1e-9, "{what}: {a} against {}", w.2);
            assert_eq!((c.outputs_zero, c.outputs_full), (w.3, w.4), "{what}");
        }
        // Every witness is what it claims.
        for c in &r.classes {
            if let Some(e) = c.worst_error {
                assert_eq!(setup.model.intensity(&setup.maps, e.gradient), e.model);
                assert_eq!(setup.reference.intensity(e.gradient), e.reference);
            }
        }
    }
}

#[test]
fn exhaustive_refuses_wide_gradients() {
    let cfg = Config {
        grad_bits: 13,
        ..Config::default()
    };
    let scene = Scene::standard();
    let setup = Setup::new(&cfg, &scene, scene.maps(&cfg));
    let e = exhaustive::run(&setup, &|_| {}).unwrap_err().to_string();
    assert!(
        e.contains("grad_bits = 13") && e.contains("--samples"),
        "{e}"
    );
}

#[test]
fn sampled_run_is_reproducible() {
    let cfg = Config {
        grad_bits: 10,
        ..Config::default()
    };
    let scene = Scene::alternate();
    let setup = Setup::new(&cfg, &scene, scene.maps(&cfg));
    let mut a = stress::sampled(&setup, 200_000, 7);
    let mut b = stress::sampled(&setup, 200_000, 7);
    a.seconds = 0.0;
    b.seconds = 0.0;
    assert_eq!(a, b);
    let mut rng = SplitMix64::new(1);
    assert!((0..100).all(|i| stress::sample_gradient(&cfg, &mut rng, i) != [0, 0, 0]));
}
