//! The shader has the symmetry of the cube: mirroring a gradient's signs or permuting its
//! axes, with the scene's light and view directions mirrored or permuted to match, gives the
//! same intensity. All 48 such transforms are checked, for every optional stage, over random
//! gradients, over gradients with two or three equal largest magnitudes (ties), and over
//! corner cases. The most negative value -2^(G-1) is left out: its mirror is not representable.
//!
//! Ties: the tie rule picks the lowest axis, so after an axis swap a tied gradient reads a
//! different face's map than its mirror image would. The results still agree because a
//! component equal to the max saturates to the all-ones fraction, which both index stages
//! send to exactly the outer position, and the outer entries of the two faces stand for the
//! same direction on the 45-degree border.
//!
//! Exactness is a float question: `DVec3::dot` and `normalize` sum x, y, z in a fixed order,
//! and tan(FRAC_PI_4) is 1 - 2^-53. Map building and the reference therefore use
//! `geometry::sym_dot`/`sym_normalize` (products summed in ascending order) and the outer entry's
//! tangent is exactly 1, so transformed maps are bit-identical. The "boundary" scene below is
//! the regression witness: before that change its entry sat at 118.49999999999999 on one side
//! and 118.50000000000001 on the other, and [456, 224, 2047] shaded 118 against 119 for the
//! x-z swapped scene at [2047, 224, 456].

use rmapgen::config::Config;
use rmapgen::model::Model;
use rmapgen::rng::SplitMix64;
use rmapgen::scene::{Light, Material, Scene, View};

/// A transform of the cube: output component i is sign[i] * input component perm[i].
#[derive(Clone, Copy, Debug)]
struct Transform {
    perm: [usize; 3],
    sign: [i32; 3],
}

impl Transform {
    fn all() -> Vec<Transform> {
        let perms = [
            [0, 1, 2],
            [1, 0, 2],
            [0, 2, 1],
            [2, 1, 0],
            [1, 2, 0],
            [2, 0, 1],
        ];
        let mut v = Vec::new();
        for perm in perms {
            for bits in 0..8 {
                let sign = [0, 1, 2].map(|i| if bits >> i & 1 == 1 { -1 } else { 1 });
                v.push(Transform { perm, sign });
            }
        }
        v
    }
    fn gradient(&self, g: [i32; 3]) -> [i32; 3] {
        [0, 1, 2].map(|i| self.sign[i] * g[self.perm[i]])
    }
    fn direction(&self, d: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|i| self.sign[i] as f64 * d[self.perm[i]])
    }
    fn scene(&self, s: &Scene) -> Scene {
        let mut t = s.clone();
        t.view.direction = self.direction(s.view.direction);
        for l in &mut t.lights {
            l.direction = self.direction(l.direction);
        }
        t
    }
}

fn scenes() -> Vec<Scene> {
    let root = super::helpers::root().join("scenes");
    let mut v: Vec<Scene> = ["standard.toml", "diffuse.toml", "two_lights.toml"]
        .iter()
        .map(|n| Scene::from_toml_file(&root.join(n)).unwrap())
        .collect();
    // Tilted views, two-sided lighting and lights in every octant.
    let mut rng = SplitMix64::new(0x5eed);
    let mut dir = || [(); 3].map(|_| rng.below(2001) as f64 / 1000.0 - 1.0);
    for two_sided in [false, true] {
        let mut s = Scene::standard();
        s.view = View {
            direction: dir(),
            two_sided,
        };
        s.material = Material {
            ambient: 0.05,
            diffuse: 0.5,
            specular: 0.45,
            shininess: 33.0,
        };
        s.lights = vec![
            Light {
                direction: dir(),
                intensity: 0.7,
            },
            Light {
                direction: dir(),
                intensity: 0.3,
            },
        ];
        v.push(s);
    }
    // The regression witness: a map entry exactly on a rounding boundary.
    let mut boundary = Scene::standard();
    boundary.material = Material {
        ambient: 0.03425861323340746,
        diffuse: 0.5,
        specular: 0.0,
        shininess: 1.0,
    };
    boundary.lights = vec![Light {
        direction: [0.3, 0.7, 0.9],
        intensity: 1.0,
    }];
    v.push(boundary);
    for s in &v {
        s.validate().unwrap();
    }
    v
}

/// Random gradients, forced ties (two equal magnitudes, possibly with the third equal too,
/// in every position and sign) and corner cases; never -2^(G-1).
fn gradients(cfg: &Config, n: usize) -> Vec<[i32; 3]> {
    let h = (1i64 << (cfg.grad_bits - 1)) - 1;
    let mut rng = SplitMix64::new(0x7e57);
    let mut r = |lo: i64| (rng.range(0, (h - lo) as u64) as i64 + lo) as i32;
    let mut v = Vec::new();
    for _ in 0..n {
        v.push([r(-h), r(-h), r(-h)]);
    }
    for i in 0..n {
        let (a, b) = (r(-h), r(-h));
        let s = if i % 2 == 0 { a } else { -a };
        v.push(match i % 4 {
            0 => [a, s, b],
            1 => [a, b, s],
            2 => [b, a, s],
            _ => [a, s, if i % 8 < 4 { a } else { -a }],
        });
    }
    let h = h as i32;
    for c in [
        [0, 0, 0],
        [h, 0, 0],
        [0, -h, 0],
        [0, 0, 1],
        [h, h, h],
        [-h, h, -h],
        [1, 1, 0],
        [h, h - 1, 0],
        [1, 2, 3],
        [h, 1, -1],
    ] {
        v.push(c);
    }
    v
}

fn check(cfg: &Config, n: usize) {
    let model = Model::new(cfg);
    let gs = gradients(cfg, n);
    for (si, s) in scenes().iter().enumerate() {
        let maps = s.maps(cfg);
        let want: Vec<u32> = gs.iter().map(|&g| model.intensity(&maps, g)).collect();
        for t in Transform::all() {
            let tmaps = t.scene(s).maps(cfg);
            for (&g, &w) in gs.iter().zip(&want) {
                let got = model.intensity(&tmaps, t.gradient(g));
                assert_eq!(
                    got,
                    w,
                    "{} scene {si} {t:?}: {g:?} -> {w}, transformed {:?} -> {got}",
                    cfg.summary(),
                    t.gradient(g)
                );
            }
        }
    }
}

#[test]
fn default_is_symmetric() {
    check(&Config::default(), 4000);
}

#[test]
fn without_compensation_is_symmetric() {
    check(
        &Config {
            compensation: false,
            ..Config::default()
        },
        2000,
    );
}

#[test]
fn without_interpolation_is_symmetric() {
    check(
        &Config {
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        },
        2000,
    );
    check(
        &Config {
            interpolation: false,
            interp_bits: 0,
            compensation: false,
            ..Config::default()
        },
        2000,
    );
}

#[test]
fn wide_configuration_is_symmetric() {
    let cfg = Config {
        grad_bits: 16,
        red_bits: 12,
        recip_bits: 14,
        frac_bits: 12,
        index_bits: 5,
        interp_bits: 4,
        map_bits: 12,
        ..Config::default()
    };
    check(&cfg, 2000);
}

#[test]
fn ties_read_the_border_entry_exactly() {
    // The premise of tie symmetry: an equal component saturates to the outer position.
    for cfg in [
        Config::default(),
        Config {
            compensation: false,
            ..Config::default()
        },
    ] {
        let model = Model::new(&cfg);
        let maps = Scene::standard().maps(&cfg);
        for g in [
            [700, -700, 5],
            [3, 900, 900],
            [-1, 1, 0],
            [2047, 2047, 2047],
        ] {
            let t = model.trace(&maps, g, [0; 3]);
            assert_eq!(t.norm.u.max(t.norm.v), cfg.frac_max(), "{g:?}");
            assert_eq!(t.p_u.max(t.p_v), cfg.pos_max(), "{g:?}");
        }
    }
}

#[test]
fn boundary_witness_agrees_after_an_x_z_swap() {
    let cfg = Config::default();
    let scene = scenes().pop().unwrap();
    let swap = Transform {
        perm: [2, 1, 0],
        sign: [1, 1, 1],
    };
    let model = Model::new(&cfg);
    let a = model.intensity(&scene.maps(&cfg), [456, 224, 2047]);
    let b = model.intensity(&swap.scene(&scene).maps(&cfg), [2047, 224, 456]);
    assert_eq!(a, b);
}

// Saturation, added with the stress work: the most negative input, fractions that round up
// to all ones without a tie, and outputs clamped at 0 and at full scale.

/// -2^(G-1) has no mirror image in range, but it shades as its half does (sort & shift
/// shifts the leading zero out, and at shift 0 the low bits a halving drops are truncated
/// anyway), and the half has all 48 mirror images: so the most negative value is as symmetric
/// as the rest, ties with it included.
#[test]
fn most_negative_value_shades_as_its_mirrored_half() {
    let cfg = Config::default();
    let full = 1i32 << (cfg.grad_bits - 1);
    let model = Model::new(&cfg);
    let mut rng = SplitMix64::new(0x5a7);
    let mut grads = Vec::new();
    for i in 0..600 {
        let mut r = || rng.range(0, 2 * full as u64 - 1) as i32 - full;
        let (y, z) = match i % 6 {
            0 => (-full, r()),
            1 => (-full, -full),
            2 => (full - 1, r()),
            _ => (r(), r()),
        };
        let mut g = [-full, y, z];
        g.rotate_right(i % 3);
        grads.push(g);
    }
    // Halving: the magnitude >> 1 with the sign kept.
    let half = |g: [i32; 3]| g.map(|c| c.signum() * (c.abs() >> 1));
    for s in scenes() {
        let maps = s.maps(&cfg);
        let transformed: Vec<_> = Transform::all()
            .into_iter()
            .map(|t| (t, t.scene(&s).maps(&cfg)))
            .collect();
        for &g in &grads {
            let want = model.intensity(&maps, g);
            let h = half(g);
            assert_eq!(
                model.intensity(&maps, h),
                want,
                "{g:?} against its half {h:?}"
            );
            for (t, tmaps) in &transformed {
                assert_eq!(
                    model.intensity(tmaps, t.gradient(h)),
                    want,
                    "{g:?} via {t:?}"
                );
            }
        }
    }
}

/// A scene bright enough to clamp at full scale over a wide region and dark enough to give 0
/// elsewhere, with gradients whose fraction rounds up to all ones without a tie (a = m - 1 at
/// the largest m): still symmetric under all 48 transforms, and both clamps are reached.
#[test]
fn saturated_outputs_and_fractions_are_symmetric() {
    let cfg = Config::default();
    let model = Model::new(&cfg);
    let mut s = Scene::standard();
    s.material = Material {
        ambient: 0.0,
        diffuse: 1.3,
        specular: 0.8,
        shininess: 8.0,
    };
    s.lights = vec![Light {
        direction: [0.4, -0.3, 1.0],
        intensity: 1.0,
    }];
    let mut gs = gradients(&cfg, 1500);
    // 2040 and 2032 reduce to m = 255 and a = 254, whose fraction rounds up to all ones.
    for (a, b, c) in [
        (2040, 2032, 700),
        (2040, -2032, -3),
        (-2032, 2040, 0),
        (17, -2032, 2040),
    ] {
        gs.push([a, b, c]);
        gs.push([c, a, b]);
    }
    let near = model.trace(&s.maps(&cfg), [2040, 2032, 700], [0; 3]);
    assert_eq!(
        (near.sort.m, near.sort.a, near.norm.u),
        (255, 254, cfg.frac_max())
    );
    let maps = s.maps(&cfg);
    let want: Vec<u32> = gs.iter().map(|&g| model.intensity(&maps, g)).collect();
    assert!(
        want.iter().filter(|&&w| w == cfg.map_max()).count() > 50,
        "clamps at full scale"
    );
    assert!(want.iter().filter(|&&w| w == 0).count() > 50, "clamps at 0");
    for t in Transform::all() {
        let tmaps = t.scene(&s).maps(&cfg);
        for (&g, &w) in gs.iter().zip(&want) {
            assert_eq!(model.intensity(&tmaps, t.gradient(g)), w, "{t:?}: {g:?}");
        }
    }
}
