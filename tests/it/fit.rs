//! `rmapgen fit` (src/fit/, src/cmd/fit.rs): the cheapest configuration that meets an error
//! target on the scene's sphere, checked from outside the search — the choice and a sample
//! of the cheaper candidates it rejected are measured again through `render` (the per-stage
//! model, not fit's own measuring code); a scene that needs less gets less (no compensation
//! ROM, fewer index bits, no colour multiplier, and with cost in cells no interpolator), and
//! the written RTL holds no trace of what was left out; bad input is one line, exit 2, and
//! nothing written.

use crate::hdl::require;
use crate::helpers;
use rmapgen::config::{CompTable, Config};
use rmapgen::fit::space;
use rmapgen::model::map_fit::MapFit;
use rmapgen::render::{self, Options};
use rmapgen::scene::Scene;
use serde_json::Value;
use std::path::Path;

fn scene_path(name: &str) -> String {
    helpers::root()
        .join("scenes")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn scene(name: &str) -> Scene {
    Scene::from_toml_file(Path::new(&scene_path(name))).expect("scene loads")
}

/// Runs `fit` on a shipped scene into `out`; returns its fit.json and stdout.
fn fit(scene: &str, out: &Path, extra: &[&str]) -> (Value, String) {
    let s = scene_path(scene);
    let mut args = vec![
        "fit",
        "--scene",
        &s,
        "--out",
        out.to_str().unwrap(),
        "--vectors",
        "1",
    ];
    args.extend_from_slice(extra);
    let o = helpers::run(&args);
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "fit {scene} {extra:?}: {}{stdout}",
        String::from_utf8_lossy(&o.stderr)
    );
    let json = std::fs::read_to_string(out.join("fit.json")).expect("fit.json");
    (
        serde_json::from_str(&json).expect("fit.json is JSON"),
        stdout,
    )
}

fn config(v: &Value) -> Config {
    serde_json::from_value(v["config"].clone()).expect("a Config")
}

/// Max abs error and RMSE of a configuration on the scene's 512 x 512 sphere, by `render`.
fn rendered(cfg: &Config, scene: &Scene) -> (u32, f64) {
    let m = render::render(
        cfg,
        scene,
        Options {
            size: 512,
            shrink: 0,
        },
        None,
    )
    .expect("render")
    .metrics;
    (m.max_abs_error, m.rmse)
}

/// Every Verilog file in `dir`, concatenated, comments left out (a comment may say what a
/// module stands in for).
fn verilog(dir: &Path) -> String {
    crate::helpers::entries(dir)
        .iter()
        .filter(|f| f.ends_with(".v"))
        .flat_map(|f| {
            std::fs::read_to_string(dir.join(f))
                .unwrap()
                .lines()
                .map(|l| l.split("//").next().unwrap().to_string() + "\n")
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn the_choice_meets_the_target_and_every_cheaper_candidate_misses_it() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("fit");
    // The paper's design gives 16 LSB on the standard scene.
    let (d, stdout) = fit("standard.toml", &out, &["--max-error", "16"]);
    let sc = scene("standard.toml");
    let chosen = config(&d["chosen"]);
    let (max, rmse) = rendered(&chosen, &sc);
    assert!(max <= 16, "{}: {max} LSB", chosen.summary());
    assert_eq!(d["chosen"]["errors"]["max_abs_error"], max);
    assert!((d["chosen"]["errors"]["rmse"].as_f64().unwrap() - rmse).abs() < 1e-9);
    // Cheaper than the paper's, whose own figures are reported.
    let paper = config(&d["paper"]);
    assert_eq!(paper, space::paper(&chosen));
    assert!(space::bits(&chosen) < space::bits(&paper), "{stdout}");
    assert_eq!(d["chosen"]["bits"], space::bits(&chosen));

    // Every candidate before the choice in cost order was measured and rejected.
    let order = space::by_bits(&chosen, &space::Fixed::default());
    let at = order
        .iter()
        .position(|c| *c == chosen)
        .expect("the choice is a candidate");
    assert_eq!(d["cheaper_rejected"], at, "{stdout}");
    assert!(d["measured"].as_u64().unwrap() as usize > at);
    // A sample of them, spread over the whole cheaper range and with the nearest ones, misses
    // the target when measured again by render.
    let step = (at / 12).max(1);
    let sample: Vec<&Config> = order[..at]
        .iter()
        .step_by(step)
        .chain(order[at.saturating_sub(4)..at].iter())
        .collect();
    assert!(sample.len() >= 12);
    for c in sample {
        let (m, _) = rendered(c, &sc);
        assert!(
            m > 16,
            "{} meets the target ({m} LSB) but costs less",
            c.summary()
        );
    }
    // The runners-up pass too, and cost no less than the choice.
    for r in d["runners_up"].as_array().unwrap() {
        let c = config(r);
        assert!(rendered(&c, &sc).0 <= 16, "{}", c.summary());
        assert!(space::bits(&c) >= space::bits(&chosen));
    }
    // The design written is the choice, as generate writes it, and fit says so.
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(config(&m), chosen);
    assert!(out.join("rmap_top.v").is_file() && out.join("tb/rmap_top_tb.v").is_file());
    assert!(
        stdout.contains("chosen") && stdout.contains("runner-up 1") && stdout.contains("paper")
    );
    assert!(stdout.contains(&chosen.summary()), "{stdout}");
    // The interface is generate's: the default pipeline depth, no handshake.
    assert_eq!(chosen.pipeline_depth, Config::default().pipeline_depth);
}

/// The paper's design just meets 16 LSB on the standard scene: the target a user of it has.
const PAPER_STANDARD_MAX: u32 = 16;

#[test]
fn a_diffuse_scene_gets_fewer_map_bits_and_no_compensation_rom() {
    let tmp = helpers::tempdir();
    let sc = scene("diffuse.toml");
    let paper = Config::default();
    assert_eq!(
        rendered(&paper, &scene("standard.toml")).0,
        PAPER_STANDARD_MAX
    );
    // At the standard scene's target, a quarter of the map entries do.
    let t = PAPER_STANDARD_MAX.to_string();
    let (d, stdout) = fit("diffuse.toml", &tmp.path().join("a"), &["--max-error", &t]);
    let c = config(&d["chosen"]);
    assert!(rendered(&c, &sc).0 <= PAPER_STANDARD_MAX);
    assert!(c.map_total_bits() < paper.map_total_bits(), "{stdout}");
    assert!(
        stdout.contains("terms: ambient + diffuse; no specular term"),
        "{stdout}"
    );

    // At the paper's own error on this scene (7 LSB), the map stays but the compensation
    // ROM goes, with nothing of it left in the design.
    let (paper_max, _) = rendered(&paper, &sc);
    assert_eq!(paper_max, 7);
    let out = tmp.path().join("b");
    let (d, stdout) = fit("diffuse.toml", &out, &["--max-error", "7"]);
    let c = config(&d["chosen"]);
    assert!(rendered(&c, &sc).0 <= 7);
    assert!(!c.compensation, "{stdout}");
    assert!(space::bits(&c) < space::bits(&paper), "{stdout}");
    let f = crate::helpers::entries(&out);
    assert!(!f.iter().any(|n| n.starts_with("atan_rom")), "{f:?}");
    assert!(
        !verilog(&out).contains("atan"),
        "atan in the generated Verilog"
    );
    assert!(f.contains(&"linear_index.v".to_string()), "{f:?}");
}

#[test]
fn a_weak_highlight_gets_fewer_index_bits() {
    let tmp = helpers::tempdir();
    let sc = scene("weak_highlight.toml");
    let t = PAPER_STANDARD_MAX.to_string();
    let (d, stdout) = fit(
        "weak_highlight.toml",
        &tmp.path().join("f"),
        &["--max-error", &t],
    );
    let c = config(&d["chosen"]);
    assert!(rendered(&c, &sc).0 <= PAPER_STANDARD_MAX);
    assert!(c.index_bits < Config::default().index_bits, "{stdout}");
    // The standard scene at the same target keeps the paper's index bits.
    let (d, stdout) = fit("standard.toml", &tmp.path().join("s"), &["--max-error", &t]);
    assert_eq!(
        config(&d["chosen"]).index_bits,
        Config::default().index_bits,
        "{stdout}"
    );
}

#[test]
fn the_colour_multiplier_is_there_exactly_when_the_scene_has_a_colour() {
    let tmp = helpers::tempdir();
    let plain = tmp.path().join("plain");
    let (d, _) = fit("standard.toml", &plain, &["--max-error", "20"]);
    assert!(!config(&d["chosen"]).color);
    assert!(!crate::helpers::entries(&plain).contains(&"color_mul.v".to_string()));
    let v = verilog(&plain);
    assert!(
        !v.contains("color_mul") && !v.contains("r_o"),
        "colour in a plain design"
    );

    let colored = tmp.path().join("color");
    let (d, stdout) = fit("color.toml", &colored, &["--max-error", "20"]);
    let c = config(&d["chosen"]);
    assert!(c.color);
    assert!(crate::helpers::entries(&colored).contains(&"color_mul.v".to_string()));
    // The target covers the colour channels too.
    let e = &d["chosen"]["errors"];
    assert!(e["color_max_abs_error"].as_u64().unwrap() <= 20, "{stdout}");
}

#[test]
fn cost_in_cells_leaves_out_the_interpolator_for_a_diffuse_scene() {
    if !require("yosys") {
        return;
    }
    let tmp = helpers::tempdir();
    let (d, stdout) = fit(
        "diffuse.toml",
        &tmp.path().join("f"),
        &[
            "--max-error",
            "8",
            "--cost",
            "cells",
            "--synth-limit",
            "4",
            "--size",
            "128",
        ],
    );
    let c = config(&d["chosen"]);
    assert!(!c.interpolation, "{stdout}");
    let cells = d["chosen"]["cells"].as_u64().expect("cells of the choice");
    assert!(
        cells < d["paper"]["cells"].as_u64().expect("cells of the paper's"),
        "{stdout}"
    );
    assert!(d["synthesised"].as_u64().unwrap() >= 2);
    for r in d["runners_up"].as_array().unwrap() {
        if let Some(rc) = r["cells"].as_u64() {
            assert!(rc >= cells, "{stdout}");
        }
    }
    assert!(!crate::helpers::entries(&tmp.path().join("f")).contains(&"interpolate.v".to_string()));
}

#[test]
fn an_unreachable_target_names_the_best_reachable_and_writes_nothing() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("fit");
    let s = scene_path("standard.toml");
    let o = helpers::run(&[
        "fit",
        "--scene",
        &s,
        "--max-error",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "no configuration meets max abs error <= 0 LSB");
    let err = String::from_utf8_lossy(&o.stderr);
    // "the lowest max error reachable is N LSB (RMSE r) with G12 R.. ..."
    let n: u32 = err
        .split("the lowest max error reachable is ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no best error in {err}"));
    assert!(n >= 1, "{err}");
    assert!(err.contains(" with G12 R"), "{err}");
    assert!(!out.exists());
}

#[test]
fn bad_input_is_one_line_exit_2_and_leaves_the_output_alone() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("fit");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "mine").unwrap();
    let o_ = out.to_str().unwrap();
    let s = scene_path("standard.toml");
    let bad_scene = tmp.path().join("bad.toml");
    std::fs::write(&bad_scene, "[material]\nambient = \"x\"\n").unwrap();
    let nan_scene = tmp.path().join("nan.toml");
    std::fs::write(
        &nan_scene,
        "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n[[light]]\ndirection=[0,0,0]\n",
    )
    .unwrap();
    let cases: [(Vec<&str>, &str); 12] = [
        (
            vec!["--scene", &s, "--max-error", "4", "--grad-bits", "20"],
            "--grad-bits must be in 8..=16, not 20",
        ),
        (
            vec!["--scene", &s, "--max-error", "4", "--map-bits", "5"],
            "--map-bits must be in 6..=12, not 5",
        ),
        (
            vec!["--scene", &s, "--max-error", "4", "--size", "8"],
            "size 8",
        ),
        (
            vec!["--scene", bad_scene.to_str().unwrap(), "--max-error", "4"],
            "bad.toml",
        ),
        (
            vec!["--scene", nan_scene.to_str().unwrap(), "--max-error", "4"],
            "direction",
        ),
        (
            vec!["--scene", &s, "--rmse", "0.0001", "--size", "64"],
            "the lowest RMSE reachable",
        ),
        // A part nextpnr does not know is refused before the search.
        (
            vec!["--scene", &s, "--max-error", "4", "--device", "hx9k"],
            "nextpnr-ice40 --hx9k: ",
        ),
        (
            vec![
                "--scene",
                &s,
                "--max-error",
                "4",
                "--cost",
                "cells",
                "--family",
                "virtex",
            ],
            "invalid value 'virtex' for '--family",
        ),
        (
            vec!["--scene", &s, "--max-error", "4", "--lanes", "9"],
            "--lanes must be in 1..=8, not 9",
        ),
        // A fixed field out of its range, and fixed fields no valid configuration has.
        (
            vec!["--scene", &s, "--max-error", "4", "--red-bits", "13"],
            "--red-bits must be in 6..=12, not 13",
        ),
        (
            vec!["--scene", &s, "--max-error", "4", "--compensation", "maybe"],
            "invalid value 'maybe' for '--compensation",
        ),
        (
            vec![
                "--scene",
                &s,
                "--max-error",
                "4",
                "--frac-bits",
                "12",
                "--recip-bits",
                "12",
            ],
            "no valid configuration has W12 F12 (with --grad-bits 12 and --map-bits 8): fix fewer fields",
        ),
    ];
    for (args, needle) in cases {
        let mut a = vec!["fit", "--out", o_];
        a.extend(args);
        let o = helpers::run(&a);
        helpers::assert_error(&o, needle);
        assert_eq!(
            crate::helpers::entries(&out),
            vec!["keep.txt".to_string()],
            "{a:?}"
        );
    }
}

/// Fields given on the command line are fixed, and the rest searched: with the paper's front
/// end fixed (R8 W10 F8), the search runs over the map and its stages alone, every cheaper
/// candidate of that space is measured and rejected, and fit.json records what was fixed.
#[test]
fn fixed_fields_are_kept_and_the_rest_searched() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("fixed");
    let front = ["--red-bits", "8", "--frac-bits", "8", "--recip-bits", "10"];
    let mut args = vec!["--max-error", "16"];
    args.extend(front);
    let (d, stdout) = fit("standard.toml", &out, &args);
    let chosen = config(&d["chosen"]);
    assert_eq!(
        (chosen.red_bits, chosen.frac_bits, chosen.recip_bits),
        (8, 8, 10),
        "{stdout}"
    );
    assert!(
        stdout.contains("fit: fixed R8 W10 F8; the other fields searched"),
        "{stdout}"
    );
    assert_eq!(
        d["fixed"],
        serde_json::json!({"red_bits": 8, "frac_bits": 8, "recip_bits": 10})
    );
    let fixed = space::Fixed {
        red_bits: Some(8),
        frac_bits: Some(8),
        recip_bits: Some(10),
        ..Default::default()
    };
    let order = space::by_bits(&chosen, &fixed);
    assert_eq!(d["space"], order.len());
    let at = order
        .iter()
        .position(|c| *c == chosen)
        .expect("a candidate");
    assert_eq!(d["cheaper_rejected"], at, "{stdout}");
    let sc = scene("standard.toml");
    assert!(rendered(&chosen, &sc).0 <= 16);
    for c in &order[..at] {
        assert!(rendered(c, &sc).0 > 16, "{} meets the target", c.summary());
    }
    // Searching everything finds no dearer design: the fixed space is a part of it.
    let (all, _) = fit(
        "standard.toml",
        &tmp.path().join("all"),
        &["--max-error", "16"],
    );
    assert!(all["chosen"]["bits"].as_u64() <= d["chosen"]["bits"].as_u64());
    assert!(all.get("fixed").is_none());
}

/// `fit --prefix` writes the chosen design with the prefix, as `generate --prefix` does.
/// `--map-fit table` searches designs whose compensation table the host loads and fits with
/// the maps (`comp_table = ram`): every candidate gets its own fitted table, and every
/// cheaper one is rejected, by its measured errors or by the information bound (its front
/// end cannot meet the target whatever the table and maps hold).
#[test]
fn a_fitted_table_search_chooses_a_ram_table_design_and_rejects_every_cheaper_one() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("t");
    let (d, stdout) = fit(
        "standard.toml",
        &out,
        &[
            "--map-fit",
            "table",
            "--grad-bits",
            "8",
            "--max-error",
            "16",
            "--size",
            "128",
            "--runners-up",
            "1",
        ],
    );
    let chosen = config(&d["chosen"]);
    assert_eq!(chosen.comp_table, CompTable::Ram, "{stdout}");
    assert!(chosen.compensation);
    let mut sc = scene("standard.toml");
    sc.map_fit = MapFit::Table;
    let size = |cfg: &Config| {
        render::render(
            cfg,
            &sc,
            Options {
                size: 128,
                shrink: 0,
            },
            None,
        )
        .expect("render")
        .metrics
    };
    let m = size(&chosen);
    assert!(
        m.max_abs_error <= 16,
        "{}: {}",
        chosen.summary(),
        m.max_abs_error
    );
    assert_eq!(d["chosen"]["errors"]["max_abs_error"], m.max_abs_error);
    // Every cheaper RAM-table design was measured and rejected; the nearest ones miss when
    // rendered with their own fitted tables.
    let order = space::by_bits(&chosen, &space::Fixed::default());
    assert!(order.iter().all(|c| c.comp_table == CompTable::Ram));
    let at = order.iter().position(|c| *c == chosen).unwrap();
    assert_eq!(d["cheaper_rejected"], at, "{stdout}");
    assert!(at >= 4, "{stdout}");
    for c in &order[at - 4..at] {
        assert!(
            size(c).max_abs_error > 16,
            "{} passes but costs less",
            c.summary()
        );
    }
    // The paper's widths are measured as a candidate: with a fitted table.
    assert_eq!(config(&d["paper"]).comp_table, CompTable::Ram);
    // The design written loads its table: the manifest says so.
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(config(&manifest), chosen);
    assert!(stdout.contains("table=ram"), "{stdout}");
}

#[test]
fn fit_writes_its_design_with_a_prefix() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("f");
    let (v, _) = fit(
        "standard.toml",
        &out,
        &["--max-error", "24", "--size", "64", "--prefix", "vr_"],
    );
    assert_eq!(config(&v["chosen"]).prefix, "vr_");
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["top"], "vr_rmap_top");
    assert!(out.join("vr_rmap_top.v").is_file());
    assert!(out.join("vr_map_x.hex").is_file());
}

/// `fit --device` chooses only what fits the part: every passing configuration it lists is
/// synthesised and packed into the part, and fits; the paper's G8 design, which needs more
/// logic cells than the iCE40 HX1K has, is shown as not fitting. When none of those
/// synthesised fits, the one line names the first and what it needs, and nothing is written.
#[test]
fn fit_with_a_part_chooses_only_what_fits_it() {
    if !require("yosys") || !require("nextpnr-ice40") {
        return;
    }
    let tmp = helpers::tempdir();
    let g8 = [
        "--grad-bits",
        "8",
        "--map-bits",
        "6",
        "--size",
        "32",
        "--device",
        "hx1k",
    ];
    let mut args = vec!["--max-error", "4", "--runners-up", "1"];
    args.extend(g8);
    let (d, stdout) = fit("standard.toml", &tmp.path().join("f"), &args);
    assert_eq!(d["part"]["device"], "hx1k", "{stdout}");
    // A device alone takes nextpnr's package for it.
    assert_eq!(d["part"]["package"], "tq144", "{stdout}");
    assert_eq!(d["chosen"]["fits"], true, "{stdout}");
    for r in d["runners_up"].as_array().unwrap() {
        assert_eq!(r["fits"], true, "{stdout}");
    }
    assert_eq!(d["paper"]["fits"], false, "{stdout}");
    assert!(
        d["paper"]["shortage"]
            .as_str()
            .unwrap()
            .contains("ICESTORM_LC (logic cells), the part has 1280"),
        "{stdout}"
    );
    assert!(stdout.contains("(does not fit)"), "{stdout}");
    assert!(stdout.contains("fit: the iCE40 hx1k (tq144): "), "{stdout}");

    // A tighter target: only designs with the interpolator's multipliers meet it, and none of
    // the two synthesised fits.
    let out = tmp.path().join("g");
    let mut a = vec![
        "fit",
        "--scene",
        &scene_path("standard.toml"),
        "--out",
        out.to_str().unwrap(),
        "--max-error",
        "2",
        "--synth-limit",
        "2",
    ]
    .into_iter()
    .map(String::from)
    .collect::<Vec<_>>();
    a.extend(g8.iter().map(|x| x.to_string()));
    let a: Vec<&str> = a.iter().map(|x| x.as_str()).collect();
    let o = helpers::run(&a);
    helpers::assert_error(
        &o,
        "none of the 2 configurations that meet max abs error <= 2 LSB and were synthesised fits the iCE40 hx1k (--synth-limit 2): the first, G8 ",
    );
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("ICESTORM_LC (logic cells), the part has 1280"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!out.exists());
}
