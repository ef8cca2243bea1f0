//! Each model stage against a plain reference of that stage: hand-picked corners, then
//! proptest over random inputs and random valid configurations.

use proptest::prelude::*;
use rmapgen::config::Config;
use rmapgen::model::{
    atan_rom, interpolate, linear_index, map_lookup, normalise, recip_rom, reflectance_map,
    sort_shift, zero_detect, Maps, Model,
};

/// Random valid configurations across every range.
pub fn any_config() -> impl Strategy<Value = Config> {
    (
        8u32..=16,
        6u32..=12,
        4u32..=12,
        0u32..=8,
        2u32..=6,
        0u32..=5,
        6u32..=12,
        any::<bool>(),
        any::<bool>(),
    )
        .prop_filter_map("valid", |(g, r, f, wextra, i, p, m, comp, color)| {
            let c = Config {
                grad_bits: g,
                red_bits: r.min(g),
                recip_bits: (f + 1 + wextra).min(20),
                frac_bits: f,
                index_bits: i,
                interp_bits: p,
                map_bits: m,
                compensation: comp,
                interpolation: p > 0,
                color,
                ..Config::default()
            };
            c.validate().ok().map(|_| c)
        })
}

fn any_grad(cfg: &Config) -> impl Strategy<Value = [i32; 3]> {
    let half = 1i32 << (cfg.grad_bits - 1);
    // Mix full-range values with small ones so every shift amount is exercised.
    let comp = prop_oneof![
        -half..half,
        (0u32..cfg.grad_bits).prop_flat_map(|k| -(1i32 << k)..=(1i32 << k))
    ];
    [comp.clone(), comp.clone(), comp].prop_map(move |g| g.map(|v| v.clamp(-half, half - 1)))
}

/// Plain sort & shift: max by explicit comparison list, shift by a loop.
fn sort_shift_ref(cfg: &Config, g: [i32; 3]) -> sort_shift::SortShift {
    let mags: Vec<u32> = g.iter().map(|v| v.unsigned_abs()).collect();
    let signs: Vec<u32> = g.iter().map(|&v| (v < 0) as u32).collect();
    let mut axis = 0;
    for k in 1..3 {
        if mags[k] > mags[axis] {
            axis = k;
        }
    }
    let others: Vec<usize> = (0..3).filter(|&k| k != axis).collect();
    let max = mags[axis];
    let mut shift = 0;
    if max != 0 {
        while max << shift < 1 << (cfg.grad_bits - 1) {
            shift += 1;
        }
    }
    let red = |v: u32| (v << shift) / (1 << (cfg.grad_bits - cfg.red_bits));
    sort_shift::SortShift {
        axis: axis as u32,
        s_max: signs[axis],
        s_u: signs[others[0]],
        s_v: signs[others[1]],
        shift,
        m: red(max),
        a: red(mags[others[0]]),
        b: red(mags[others[1]]),
    }
}

#[test]
fn sort_shift_corners() {
    let c = Config::default();
    let cases: &[[i32; 3]] = &[
        [0, 0, 0],
        [7, 7, 7],
        [-300, 300, 5],
        [5, -300, 300],
        [300, 5, -300],
        [-2048, -2048, -2048],
        [-2048, 2047, 0],
        [1, 0, 0],
        [0, -1, 0],
        [0, 0, 1],
        [2047, 2047, 2047],
        [2047, -1, 1],
        [100, 100, 0],
    ];
    for &g in cases {
        assert_eq!(sort_shift::eval(&c, g), sort_shift_ref(&c, g), "{g:?}");
    }
    // Tie rule: lowest axis wins.
    assert_eq!(sort_shift::eval(&c, [9, 9, 9]).axis, 0);
    assert_eq!(sort_shift::eval(&c, [1, 9, 9]).axis, 1);
    assert_eq!(sort_shift::eval(&c, [9, 1, -9]).axis, 0);
}

#[test]
fn zero_detect_corners() {
    assert!(zero_detect::eval([0, 0, 0]));
    for g in [[1, 0, 0], [0, -1, 0], [0, 0, 1], [-2048, 0, 0]] {
        assert!(!zero_detect::eval(g));
    }
}

#[test]
fn normalise_corners() {
    for cfg in [
        Config::default(),
        Config {
            red_bits: 12,
            grad_bits: 16,
            frac_bits: 12,
            recip_bits: 13,
            ..Config::default()
        },
    ] {
        let rom = recip_rom::contents(&cfg);
        let top = (1u32 << cfg.red_bits) - 1;
        let low = 1u32 << (cfg.red_bits - 1);
        for m in [low, low + 1, top - 1, top] {
            for a in [0, 1, m / 2, m - 1, m] {
                let n = normalise::eval(&cfg, &rom, m, a, 0);
                check_fraction(&cfg, m, a, n.u);
                assert_eq!(n.v, 0);
            }
        }
    }
}

/// The fraction is within one LSB of a / m, and all ones exactly when a == m or when
/// a / m rounds up to 1.
fn check_fraction(cfg: &Config, m: u32, a: u32, u: u32) {
    let exact = a as f64 / m as f64 * (1u64 << cfg.frac_bits) as f64;
    if a == m {
        assert_eq!(u, cfg.frac_max());
    } else {
        assert!(
            (u as f64 - exact.min(cfg.frac_max() as f64)).abs() <= 1.0,
            "m{m} a{a} u{u} exact{exact}"
        );
        assert!(u <= cfg.frac_max());
    }
}

#[test]
fn recip_rom_within_stated_bound() {
    for red_bits in 6..=12 {
        for recip_bits in [5, 9, 13, 20] {
            let cfg = Config {
                red_bits,
                recip_bits,
                frac_bits: 4,
                ..Config::default()
            };
            let rom = recip_rom::contents(&cfg);
            assert_eq!(rom.len() as u32, cfg.recip_entries());
            for (i, &r) in rom.iter().enumerate() {
                let i = i as u32;
                assert!(r < 1 << recip_bits);
                assert!((r as f64 - recip_rom::exact(&cfg, i)).abs() <= recip_rom::bound(&cfg, i));
            }
        }
    }
}

#[test]
fn atan_rom_monotonic_in_range_and_rounded() {
    for frac_bits in 4..=12 {
        for (index_bits, interp_bits) in [(2, 0), (2, 5), (3, 3), (6, 5), (6, 0)] {
            let cfg = Config {
                frac_bits,
                recip_bits: frac_bits + 2,
                index_bits,
                interp_bits,
                interpolation: interp_bits > 0,
                ..Config::default()
            };
            let rom = atan_rom::contents(&cfg);
            assert_eq!(rom.len(), 1 << frac_bits);
            assert_eq!(rom[0], 0);
            assert_eq!(
                *rom.last().unwrap(),
                cfg.pos_max(),
                "all ones is the border"
            );
            assert!(rom.windows(2).all(|w| w[0] <= w[1]), "monotonic");
            for (u, &p) in rom.iter().enumerate() {
                assert!(p < 1 << cfg.pos_bits());
                let ideal = atan_rom::ideal_position(&cfg, atan_rom::tangent(&cfg, u as u32));
                assert!((p as f64 - ideal).abs() <= 0.5 + 1e-9, "u{u}");
            }
        }
    }
}

#[test]
fn linear_index_is_rounded_scale() {
    for frac_bits in 4..=12 {
        let cfg = Config {
            frac_bits,
            recip_bits: frac_bits + 1,
            compensation: false,
            ..Config::default()
        };
        for u in 0..=cfg.frac_max() {
            let p = linear_index::eval(&cfg, u);
            let want = if u == cfg.frac_max() {
                cfg.pos_max()
            } else {
                (u as f64 * cfg.pos_max() as f64 / (1u64 << frac_bits) as f64 + 0.5).floor() as u32
            };
            assert_eq!(p, want, "u{u}");
        }
    }
}

#[test]
fn lookup_never_bases_on_the_outer_entry() {
    for (index_bits, interp_bits) in [(2, 1), (3, 3), (6, 5)] {
        let cfg = Config {
            index_bits,
            interp_bits,
            ..Config::default()
        };
        for p in 0..=cfg.pos_max() {
            let (base, w) = map_lookup::split(&cfg, p);
            assert!(base <= cfg.entries() - 2);
            assert!(w <= cfg.step());
            assert_eq!(base * cfg.step() + w, p);
        }
    }
}

fn numbered_maps(cfg: &Config) -> Maps {
    let n = 3 * cfg.map_entries() as usize;
    Maps::from_data(
        cfg,
        (0..n)
            .map(|k| ((k as u32).wrapping_mul(2654435761u32) >> 7) & cfg.map_max())
            .collect(),
    )
}

#[test]
fn interpolate_corners() {
    let cfg = Config::default();
    let s = cfg.step();
    let top = cfg.map_max();
    for e in [
        [0, 0, 0, 0],
        [top; 4],
        [0, top, 0, top],
        [top, 0, 0, top],
        [1, 2, 3, 4],
    ] {
        for (wu, wv) in [(0, 0), (s, 0), (0, s), (s, s), (1, s - 1)] {
            assert_eq!(
                interpolate::eval(&cfg, e, wu, wv),
                interp_ref(&cfg, e, wu, wv)
            );
        }
    }
}

/// Exact bilinear value rounded half up, in rationals.
fn interp_ref(cfg: &Config, e: [u32; 4], wu: u32, wv: u32) -> u32 {
    let s = cfg.step() as u64;
    let (wu, wv) = (wu as u64, wv as u64);
    let num = e[0] as u64 * (s - wu) * (s - wv)
        + e[1] as u64 * wu * (s - wv)
        + e[2] as u64 * (s - wu) * wv
        + e[3] as u64 * wu * wv;
    let den = s * s;
    ((2 * num + den) / (2 * den)) as u32
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn sort_shift_matches_reference((cfg, g) in any_config().prop_flat_map(|c| { let g = any_grad(&c); (Just(c), g) })) {
        let s = sort_shift::eval(&cfg, g);
        prop_assert_eq!(s, sort_shift_ref(&cfg, g));
        if g != [0, 0, 0] {
            prop_assert!(s.m >> (cfg.red_bits - 1) == 1, "max MSB set");
        }
        prop_assert!(s.a <= s.m && s.b <= s.m);
    }

    #[test]
    fn normalise_within_one_lsb((cfg, m, a, b) in any_config().prop_flat_map(|c| {
        let low = 1u32 << (c.red_bits - 1);
        let top = (1u32 << c.red_bits) - 1;
        (Just(c), low..=top).prop_flat_map(|(c, m)| (Just(c), Just(m), 0..=m, 0..=m))
    })) {
        let rom = recip_rom::contents(&cfg);
        let n = normalise::eval(&cfg, &rom, m, a, b);
        check_fraction(&cfg, m, a, n.u);
        check_fraction(&cfg, m, b, n.v);
    }

    #[test]
    fn interpolate_matches_exact_bilinear((cfg, e, wu, wv) in any_config().prop_filter("interp", |c| c.interpolation).prop_flat_map(|c| {
        let top = c.map_max();
        let s = c.step();
        (Just(c), [0..=top, 0..=top, 0..=top, 0..=top], 0..=s, 0..=s)
    })) {
        let out = interpolate::eval(&cfg, e, wu, wv);
        prop_assert_eq!(out, interp_ref(&cfg, e, wu, wv));
        prop_assert!(out >= *e.iter().min().unwrap() && out <= *e.iter().max().unwrap());
    }

    #[test]
    fn lookup_reads_the_four_neighbours((cfg, axis, signs, pu, pv) in any_config().prop_flat_map(|c| {
        let pm = c.pos_max();
        (Just(c), 0u32..3, [0u32..2, 0u32..2, 0u32..2], 0..=pm, 0..=pm)
    })) {
        let maps = numbered_maps(&cfg);
        let l = map_lookup::eval(&cfg, &maps, axis, signs[0], signs[1], signs[2], pu, pv);
        let i = cfg.index_bits;
        // The address as a bit string {s_max, s_u, i_u, s_v, i_v}.
        let at = |iu: u32, iv: u32| {
            let bits = format!("{}{}{:0w$b}{}{:0w$b}", signs[0], signs[1], iu, signs[2], iv, w = i as usize);
            maps.get(axis, u32::from_str_radix(&bits, 2).unwrap())
        };
        if cfg.interpolation {
            prop_assert_eq!(l.e, [at(l.base_u, l.base_v), at(l.base_u + 1, l.base_v), at(l.base_u, l.base_v + 1), at(l.base_u + 1, l.base_v + 1)]);
        } else {
            prop_assert_eq!(l.e[0], at(pu, pv));
        }
    }

    #[test]
    fn whole_model_never_panics_and_stays_in_range((cfg, g, rgb) in any_config().prop_flat_map(|c| {
        let g = any_grad(&c);
        (Just(c), g, [0u32..256, 0u32..256, 0u32..256])
    })) {
        let model = Model::new(&cfg);
        let scene = rmapgen::scene::Scene::standard().prepared();
        let maps = reflectance_map::contents(&cfg, |n| scene.shade(n));
        let t = model.trace(&maps, g, rgb);
        prop_assert!(t.out.intensity <= cfg.map_max());
        prop_assert!(t.p_u <= cfg.pos_max() && t.p_v <= cfg.pos_max());
        prop_assert_eq!(t.out.zero, g == [0, 0, 0]);
        if cfg.color {
            prop_assert!(t.out.rgb.iter().zip(rgb).all(|(&o, c)| o <= c));
        }
    }
}
