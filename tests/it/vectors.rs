//! Vector files (src/vectors): reproducible, corner cases first, and every expected value is
//! the model's, recomputed here by field name from the model's own functions.

use crate::helpers;
use rmapgen::config::Config;
use rmapgen::design::Design;
use rmapgen::model::{color_mul, interpolate, map_lookup, normalise, sort_shift, Model};
use rmapgen::output::StagedDir;
use rmapgen::stages::{self, rmap_top, Vectors};
use rmapgen::vectors::{self, inputs, MapSet};
use std::collections::{BTreeSet, HashMap};
use std::path::Path;

/// The configurations the vector tests run over: default, every optional stage flipped, and
/// the extreme widths.
fn configs() -> Vec<Config> {
    let d = Config::default();
    vec![
        d.clone(),
        Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            color: true,
            ..d.clone()
        },
        Config {
            color: true,
            ..d.clone()
        },
        Config {
            grad_bits: 16,
            red_bits: 12,
            frac_bits: 12,
            recip_bits: 14,
            index_bits: 6,
            interp_bits: 5,
            map_bits: 12,
            ..d.clone()
        },
        Config {
            grad_bits: 8,
            red_bits: 6,
            frac_bits: 4,
            recip_bits: 5,
            index_bits: 2,
            interp_bits: 1,
            map_bits: 6,
            ..d
        },
    ]
}

/// The checked stage named `name` (every one is present in the default configuration or in
/// the one without compensation).
fn by(name: &str) -> &'static dyn Vectors {
    let off = Config {
        compensation: false,
        color: true,
        ..Config::default()
    };
    stages::checked(&Config::default())
        .into_iter()
        .chain(stages::checked(&off))
        .find(|s| s.name() == name)
        .unwrap_or_else(|| panic!("no stage {name}"))
}

/// Writes the vectors of `cfg` into a fresh directory and returns (dir guard, path).
fn write(cfg: &Config, random: usize, seed: u64) -> (tempfile::TempDir, std::path::PathBuf) {
    let tmp = helpers::tempdir();
    let target = tmp.path().join("out");
    let out = StagedDir::new(&target, &Default::default()).unwrap();
    vectors::write_all(&Design::standard(cfg).unwrap(), &out, random, seed).unwrap();
    out.commit().unwrap();
    (tmp, target)
}

/// The stage's vector file in `dir` (written without a prefix).
fn read(dir: &Path, stage: &dyn Vectors) -> String {
    std::fs::read_to_string(dir.join(stage.vector_file(&Config::default()))).unwrap()
}

/// One line as field name -> value.
fn fields(cfg: &Config, stage: &dyn Vectors, line: &str) -> HashMap<&'static str, u64> {
    let f = stage.fields(cfg);
    let vals =
        vectors::parse_line(&f, line).unwrap_or_else(|e| panic!("{}: {line:?}: {e}", stage.name()));
    f.iter().map(|x| x.name).zip(vals).collect()
}

/// The expected outputs of one line, recomputed from its inputs by name.
fn recompute(
    cfg: &Config,
    model: &Model,
    maps: &MapSet,
    stage: &dyn Vectors,
    v: &HashMap<&str, u64>,
) -> Vec<(&'static str, u64)> {
    let g = |n: &str| inputs::dec_grad(cfg, v[n]);
    let u = |n: &str| v[n] as u32;
    match stage.name() {
        "zero_detect" => {
            let t = model.trace(&maps.scene, [g("gx"), g("gy"), g("gz")], [0; 3]);
            vec![("zero", t.zero as u64)]
        }
        "sort_shift" => {
            let s = model
                .trace(&maps.scene, [g("gx"), g("gy"), g("gz")], [0; 3])
                .sort;
            vec![
                ("axis", s.axis as u64),
                ("s_max", s.s_max as u64),
                ("s_u", s.s_u as u64),
                ("s_v", s.s_v as u64),
                ("m", s.m as u64),
                ("a", s.a as u64),
                ("b", s.b as u64),
            ]
        }
        "normalise" => {
            let n = normalise::eval(cfg, &model.recip, u("m"), u("a"), u("b"));
            vec![("u", n.u as u64), ("v", n.v as u64)]
        }
        "atan_rom" | "linear_index" => {
            vec![
                ("pu", model.position(u("u")) as u64),
                ("pv", model.position(u("v")) as u64),
            ]
        }
        "map_lookup" => {
            let m = if v["buf"] == 0 {
                &maps.scene
            } else {
                &maps.second
            };
            let l = map_lookup::eval(
                cfg,
                m,
                u("axis"),
                u("s_max"),
                u("s_u"),
                u("s_v"),
                u("pu"),
                u("pv"),
            );
            let mut e = vec![("e00", l.e[0] as u64)];
            if cfg.interpolation {
                e.extend([
                    ("e10", l.e[1] as u64),
                    ("e01", l.e[2] as u64),
                    ("e11", l.e[3] as u64),
                ]);
                e.extend([("wu", l.w_u as u64), ("wv", l.w_v as u64)]);
            }
            e
        }
        "interpolate" => {
            let i = interpolate::eval(
                cfg,
                [u("e00"), u("e10"), u("e01"), u("e11")],
                u("wu"),
                u("wv"),
            );
            vec![("i", i as u64)]
        }
        "color_mul" => {
            let c = color_mul::eval(cfg, [u("r"), u("g"), u("b")], u("i"));
            vec![
                ("r_o", c[0] as u64),
                ("g_o", c[1] as u64),
                ("b_o", c[2] as u64),
            ]
        }
        "rmap_top" => {
            let m = if v["map"] == 0 {
                &maps.scene
            } else {
                &maps.second
            };
            let rgb = if cfg.color {
                [u("r"), u("g"), u("b")]
            } else {
                [0; 3]
            };
            let t = model.trace(m, [g("gx"), g("gy"), g("gz")], rgb);
            let mut e = vec![("zero", t.out.zero as u64), ("i", t.out.intensity as u64)];
            if cfg.color {
                e.extend([
                    ("r_o", t.out.rgb[0] as u64),
                    ("g_o", t.out.rgb[1] as u64),
                    ("b_o", t.out.rgb[2] as u64),
                ]);
            }
            e
        }
        other => panic!("no recomputation for {other}"),
    }
}

#[test]
fn every_expected_value_is_the_models() {
    for cfg in configs() {
        let model = Model::new(&cfg);
        let maps = MapSet::standard(&cfg);
        let (_tmp, dir) = write(&cfg, 300, 7);
        for stage in stages::checked(&cfg) {
            let text = read(&dir, stage);
            assert!(text.ends_with('\n'));
            for (n, line) in text.lines().enumerate() {
                let v = fields(&cfg, stage, line);
                for (name, want) in recompute(&cfg, &model, &maps, stage, &v) {
                    assert_eq!(
                        v[name],
                        want,
                        "{} {} line {}: {name} in {line:?}",
                        cfg.summary(),
                        stage.name(),
                        n + 1
                    );
                }
            }
        }
    }
}

#[test]
fn byte_reproducible_for_a_seed() {
    let cfg = Config {
        color: true,
        ..Config::default()
    };
    let (_a, da) = write(&cfg, 500, 42);
    let (_b, db) = write(&cfg, 500, 42);
    let (_c, dc) = write(&cfg, 500, 43);
    for stage in stages::checked(&cfg) {
        let (a, b, c) = (read(&da, stage), read(&db, stage), read(&dc, stage));
        assert_eq!(a, b, "{}", stage.name());
        assert_ne!(
            a,
            c,
            "{}: another seed gives other random vectors",
            stage.name()
        );
    }
    // The stream for the C++ harness is the same file for the same count and seed.
    let p = da.join("stream.hex");
    let n = vectors::write_top_stream(&cfg, &MapSet::standard(&cfg), &p, 500, 42).unwrap();
    assert_eq!(
        std::fs::read_to_string(&p).unwrap(),
        read(&da, by("rmap_top"))
    );
    assert_eq!(n, read(&da, by("rmap_top")).lines().count());
}

#[test]
fn corner_cases_come_first() {
    let cfg = Config::default();
    let model = Model::new(&cfg);
    let maps = MapSet::standard(&cfg);
    let (_a, da) = write(&cfg, 200, 1);
    let (_b, db) = write(&cfg, 200, 2);
    for stage in stages::checked(&cfg) {
        let ncorners = if stage.name() == "rmap_top" {
            rmap_top::corners_for_map(&cfg, 0).len()
        } else {
            stage.corners(&model, &maps).len()
        };
        let (a, b) = (read(&da, stage), read(&db, stage));
        let (la, lb): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
        // The seed changes nothing before the random part and (almost) every line after it.
        assert_eq!(la[..ncorners], lb[..ncorners], "{}", stage.name());
        let differ = la[ncorners..]
            .iter()
            .zip(&lb[ncorners..])
            .filter(|(x, y)| x != y)
            .count();
        assert!(
            differ * 10 > 9 * 200,
            "{}: {differ} of 200 random lines differ",
            stage.name()
        );
        // The top has each corner once per map and the swap witness once more.
        let want = if stage.name() == "rmap_top" {
            2 * ncorners + 1 + 200
        } else {
            ncorners + 200
        };
        assert_eq!(la.len(), want, "{}", stage.name());
    }
    // The first corner of the gradient stages is the zero vector.
    for stage in [by("zero_detect"), by("sort_shift")] {
        assert!(
            read(&da, stage).starts_with("000 000 000 "),
            "{}",
            stage.name()
        );
    }
    assert!(read(&da, by("rmap_top")).starts_with("0 000 000 000 1 00\n"));
    assert!(read(&da, by("normalise")).starts_with("00 00 00 ff ff\n"));
    // The position stage is exhaustive first: u = 0..=255 in order.
    let atan = read(&da, by("atan_rom"));
    for (u, line) in atan.lines().take(256).enumerate() {
        assert!(
            line.starts_with(&format!("{u:02x} {:02x} ", 255 - u)),
            "{line}"
        );
    }
}

#[test]
fn corners_cover_the_listed_cases() {
    let cfg = Config::default();
    let c = inputs::gradient_corners(&cfg);
    let has = |g: [i32; 3]| c.contains(&g);
    assert!(has([0, 0, 0]));
    assert!(has([1, 1, 1]) && has([2047, 2047, 2047]) && has([-2048, -2048, -2048]));
    for p in 0..3 {
        assert!(
            c.iter()
                .any(|g| g[p] == -2048 && g.iter().filter(|&&x| x == -2048).count() == 1),
            "min at {p}"
        );
        let mut one = [0; 3];
        one[p] = 1;
        assert!(has(one), "magnitude 1 at {p}");
    }
    // Ties between each pair of axes, and a non-max component equal to the max.
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        assert!(c.iter().any(|g| g[i].abs() == g[j].abs()
            && g[i] != 0
            && (0..3).all(|k| g[k].abs() <= g[i].abs())));
    }
    // Every shift amount and every axis with every sign pattern.
    let traces: Vec<_> = c.iter().map(|&g| sort_shift::eval(&cfg, g)).collect();
    let shifts: BTreeSet<u32> = traces.iter().map(|s| s.shift).collect();
    assert_eq!(shifts, (0..cfg.grad_bits).collect());
    let patterns: BTreeSet<(u32, u32, u32, u32)> = traces
        .iter()
        .map(|s| (s.axis, s.s_max, s.s_u, s.s_v))
        .collect();
    assert_eq!(patterns.len(), 24);
    // Positions: 0, POS_MAX and both sides of every base boundary.
    let p = inputs::position_corners(&cfg);
    for x in [0, 7, 8, 9, 47, 48, 49, 55, 56] {
        assert!(p.contains(&x), "{x} in {p:?}");
    }
}

#[test]
fn random_sort_shift_vectors_cover_every_shift() {
    let cfg = Config {
        grad_bits: 16,
        red_bits: 12,
        frac_bits: 12,
        recip_bits: 14,
        ..Config::default()
    };
    let model = Model::new(&cfg);
    let maps = MapSet::standard(&cfg);
    let ncorners = by("sort_shift").corners(&model, &maps).len();
    let text = vectors::stage_text(by("sort_shift"), &model, &maps, 2000, 5);
    let mut count = vec![0u32; 17];
    for line in text.lines().skip(ncorners) {
        let v = fields(&cfg, by("sort_shift"), line);
        let g = [v["gx"], v["gy"], v["gz"]].map(|x| inputs::dec_grad(&cfg, x));
        if g != [0; 3] {
            count[sort_shift::eval(&cfg, g).shift as usize] += 1;
        }
    }
    assert!(count[..16].iter().all(|&n| n >= 60), "{count:?}");
}

#[test]
fn top_vectors_are_map_0_then_map_1() {
    let cfg = Config::default();
    let (_t, dir) = write(&cfg, 1001, 3);
    let maps: Vec<u64> = read(&dir, by("rmap_top"))
        .lines()
        .map(|l| fields(&cfg, by("rmap_top"), l)["map"])
        .collect();
    let first1 = maps.iter().position(|&m| m == 1).expect("a map-1 part");
    assert!(maps[..first1].iter().all(|&m| m == 0) && maps[first1..].iter().all(|&m| m == 1));
    let nc = rmap_top::corners_for_map(&cfg, 0).len();
    assert_eq!((first1, maps.len() - first1), (nc + 501 + 1, nc + 500));
    // The vectors on both sides of the swap are the same gradient with different results, so
    // a swap one sample early or late cannot pass.
    let text = read(&dir, by("rmap_top"));
    let lines: Vec<&str> = text.lines().collect();
    let (a, b) = (
        fields(&cfg, by("rmap_top"), lines[first1 - 1]),
        fields(&cfg, by("rmap_top"), lines[first1]),
    );
    for g in ["gx", "gy", "gz"] {
        assert_eq!(a[g], b[g]);
    }
    assert_ne!(a["i"], b["i"], "{} / {}", lines[first1 - 1], lines[first1]);
}

#[test]
fn maps_read_back_from_a_generated_directory() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("d");
    let scene_file = helpers::root().join("scenes/diffuse.toml");
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--vectors",
        "10",
        "--scene",
        scene_file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cfg = Config::default();
    let m = MapSet::from_dir(&cfg, &out).unwrap();
    let scene = rmapgen::scene::Scene::from_toml_file(&scene_file).unwrap();
    assert_eq!(
        m,
        MapSet::from_scenes(&cfg, &scene, &rmapgen::scene::Scene::alternate())
    );
    // The generated top vectors use that scene's map.
    let model = Model::new(&cfg);
    for line in std::fs::read_to_string(out.join(by("rmap_top").vector_file(&cfg)))
        .unwrap()
        .lines()
    {
        let v = fields(&cfg, by("rmap_top"), line);
        for (name, want) in recompute(&cfg, &model, &m, by("rmap_top"), &v) {
            assert_eq!(v[name], want, "{name} in {line}");
        }
    }
}

#[test]
fn cli_writes_a_top_stream() {
    let tmp = helpers::tempdir();
    let f = tmp.path().join("s.hex");
    let o = helpers::run(&[
        "vectors",
        "--count",
        "100",
        "--seed",
        "9",
        "--color",
        "--out",
        f.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let cfg = Config {
        color: true,
        ..Config::default()
    };
    let text = std::fs::read_to_string(&f).unwrap();
    assert_eq!(
        text,
        vectors::stage_text(
            by("rmap_top"),
            &Model::new(&cfg),
            &MapSet::standard(&cfg),
            100,
            9
        )
    );
    // Bad flags fail with one line and leave no file.
    let g = tmp.path().join("bad.hex");
    let o = helpers::run(&[
        "vectors",
        "--count",
        "10",
        "--grad-bits",
        "30",
        "--out",
        g.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "--grad-bits must be in 8..=16, not 30");
    assert!(!g.exists());
    let o = helpers::run(&[
        "vectors",
        "--count",
        "10",
        "--maps",
        tmp.path().to_str().unwrap(),
        "--out",
        g.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "map_x.hex");
    assert!(!g.exists());
}
