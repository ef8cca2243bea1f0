//! Issue 12 §4 and §5: no silent wrong answers, and one line that names the problem.
//!
//! - Directions with huge components are normalised, not dropped: the image equals the one
//!   of the unit direction (and differs from the image without the light); zero and NaN
//!   directions are refused by name.
//! - TOML errors name the file, line:column and key path, also in a 10,000-light scene;
//!   `key =` without a value says so.
//! - Usage errors are one line naming the flag and its range; help still works.
//! - Directories given for TOML files, config values overridden by flags, a transfer
//!   function that covers nothing.
//! - Property tests: mutated scenes and configurations and random bytes never panic the
//!   loaders, and every error is one line.

use super::helpers::{assert_error, root, run, tempdir};
use proptest::prelude::*;
use rmapgen::config::Config;
use rmapgen::scene::Scene;
use std::path::Path;

const MATERIAL: &str =
    "[material]\nambient = 0.1\ndiffuse = 0.6\nspecular = 0.3\nshininess = 20.0\n";

fn scene_with_lights(dir: &Path, name: &str, lights: &[&str]) -> String {
    let mut t = MATERIAL.to_string();
    for l in lights {
        t.push_str(&format!("[[light]]\ndirection = [{l}]\n"));
    }
    let p = dir.join(name);
    std::fs::write(&p, t).unwrap();
    p.display().to_string()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Renders a 32x32 sphere with `scene` into `dir/name`, returning the model and reference
/// images' bytes and the metrics.
fn render_sphere(scene: &str, dir: &Path, name: &str) -> (Vec<u8>, Vec<u8>, serde_json::Value) {
    let out = dir.join(name);
    let o = run(&[
        "render",
        "--scene",
        scene,
        "--size",
        "32",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    (
        std::fs::read(out.join("model.png")).unwrap(),
        std::fs::read(out.join("reference.png")).unwrap(),
        j,
    )
}

#[test]
fn huge_light_directions_give_the_image_of_the_unit_direction() {
    let t = tempdir();
    // No light: the ambient term alone, said as a light of intensity 0 (a scene without any
    // [[light]] is refused).
    let ambient = t.path().join("none.toml");
    std::fs::write(
        &ambient,
        format!("{MATERIAL}[[light]]\ndirection = [0.0, 0.0, 1.0]\nintensity = 0.0\n"),
    )
    .unwrap();
    let none = render_sphere(ambient.to_str().unwrap(), t.path(), "n");
    for (huge, unit) in [
        ("1e200, 0.0, 0.0", "1.0, 0.0, 0.0"),
        ("1e308, 1e308, 1e308", "1.0, 1.0, 1.0"),
        ("-1e300, 0.0, 2e-300", "-1.0, 0.0, 0.0"),
    ] {
        let h = render_sphere(
            &scene_with_lights(t.path(), "h.toml", &[huge]),
            t.path(),
            "h",
        );
        let u = render_sphere(
            &scene_with_lights(t.path(), "u.toml", &[unit]),
            t.path(),
            "u",
        );
        assert!(
            h.0 == u.0 && h.1 == u.1,
            "{huge}: images differ from {unit}'s"
        );
        for k in ["max_abs_error", "rmse", "pixels"] {
            assert_eq!(h.2[k], u.2[k], "{huge}: {k}");
        }
        // The light is there: the image is not the one without any light.
        assert!(
            h.0 != none.0 && h.1 != none.1,
            "{huge}: the light was dropped"
        );
    }
}

#[test]
fn unit_direction_is_exact_and_refuses_what_has_no_direction() {
    use glam::DVec3;
    use rmapgen::geometry::{sym_normalize, unit_direction};
    // Ordinary vectors: bit-identical to plain normalisation.
    for v in [
        [1.0, 1.0, 2.0],
        [-0.3, 0.8, 0.1],
        [1e-3, 5.0, -7.0],
        [3.0, 0.0, 0.0],
    ] {
        let v = DVec3::from_array(v);
        assert_eq!(unit_direction(v), Some(sym_normalize(v)), "{v}");
    }
    // Huge and tiny components: the direction of the scaled-down vector.
    let one = DVec3::new(1.0, 1.0, 1.0);
    assert_eq!(unit_direction(one * 1e308), unit_direction(one));
    assert_eq!(unit_direction(DVec3::X * 1e-320), Some(DVec3::X));
    assert_eq!(
        unit_direction(DVec3::new(f64::MAX, -f64::MAX, 0.0)),
        unit_direction(DVec3::new(1.0, -1.0, 0.0))
    );
    for bad in [
        DVec3::ZERO,
        DVec3::new(f64::NAN, 0.0, 1.0),
        DVec3::new(f64::INFINITY, 0.0, 0.0),
        DVec3::new(0.0, f64::NEG_INFINITY, 1.0),
    ] {
        assert_eq!(unit_direction(bad), None, "{bad}");
    }
}

/// Runs `rmapgen volume` on the small synthetic part with `extra`, writing `out`.
fn volume(extra: &[&str], out: &Path) -> std::process::Output {
    let mut a = vec![
        "volume",
        "--synthetic",
        "--dims",
        "32,32,16",
        "--size",
        "32",
    ];
    a.extend_from_slice(extra);
    a.extend_from_slice(&["--out", out.to_str().unwrap()]);
    run(&a)
}

#[test]
fn huge_volume_view_covers_the_pixels_of_the_unit_view() {
    let t = tempdir();
    let metrics = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("metrics.json")).unwrap()).unwrap()
    };
    for (huge, unit) in [("1e200,0,0", "1,0,0"), ("1e308,-1e308,1e308", "1,-1,1")] {
        let (h, u) = (t.path().join("h"), t.path().join("u"));
        let oh = volume(&["--view", huge], &h);
        let ou = volume(&["--view", unit], &u);
        assert!(
            oh.status.success() && ou.status.success(),
            "{}{}",
            stderr(&oh),
            stderr(&ou)
        );
        let (mh, mu) = (metrics(&h), metrics(&u));
        assert!(mu["pixels"].as_u64().unwrap() > 100, "{}", mu["pixels"]);
        assert_eq!(mh["pixels"], mu["pixels"], "{huge}");
        assert_eq!(
            std::fs::read(h.join("model.png")).unwrap(),
            std::fs::read(u.join("model.png")).unwrap(),
            "{huge}"
        );
    }
}

#[test]
fn zero_and_nan_directions_are_refused_by_name() {
    let t = tempdir();
    let out = t.path().join("o");
    let s = scene_with_lights(t.path(), "z.toml", &["1.0, 0.0, 0.0", "0.0, 0.0, 0.0"]);
    let o = run(&["render", "--scene", &s, "--out", out.to_str().unwrap()]);
    assert_error(
        &o,
        "z.toml:9:13: light[1].direction = [0.0, 0.0, 0.0] has zero length",
    );
    let view = t.path().join("v.toml");
    std::fs::write(
        &view,
        format!("[view]\ndirection = [nan, 0.0, 1.0]\n{MATERIAL}"),
    )
    .unwrap();
    let o = run(&[
        "render",
        "--scene",
        view.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_error(
        &o,
        "v.toml:2:13: view.direction = [NaN, 0.0, 1.0] is not finite",
    );
    assert_error(
        &volume(&["--view", "0,0,0"], &out),
        "--view = [0.0, 0.0, 0.0] has zero length",
    );
    assert_error(
        &volume(&["--view", "nan,0,1"], &out),
        "--view = [NaN, 0.0, 1.0] is not finite",
    );
    assert!(!out.exists());
}

#[test]
fn toml_errors_name_the_key_and_line() {
    let t = tempdir();
    let out = t.path().join("o");
    let o_ = out.to_str().unwrap();
    let p = t.path().join("s.toml");
    let p_ = p.to_str().unwrap();
    std::fs::write(&p, format!("{MATERIAL}[[light]]\ndirection = [1.0, 2.0]\n")).unwrap();
    assert_error(
        &run(&["render", "--scene", p_, "--out", o_]),
        &format!(
            "scene {p_}:7:13: light[0].direction: invalid length 2, expected an array of length 3"
        ),
    );
    std::fs::write(
        &p,
        format!("{MATERIAL}[[light]]\ndirection = [1.0, 2.0, 3.0]\nintensity = \"lots\"\n"),
    )
    .unwrap();
    assert_error(
        &run(&["render", "--scene", p_, "--out", o_]),
        &format!(
            "scene {p_}:8:13: light[0].intensity: invalid type: string \"lots\", expected f64"
        ),
    );
    std::fs::write(&p, MATERIAL.replace("specular = 0.3", "specular = -0.3")).unwrap();
    assert_error(
        &run(&["render", "--scene", p_, "--out", o_]),
        &format!("scene {p_}:4:12: material.specular = -0.3 must be a finite number >= 0"),
    );
    // A configuration key without a value: not "string values must be quoted".
    let c = t.path().join("c.toml");
    let c_ = c.to_str().unwrap();
    std::fs::write(&c, "red_bits = 8\ngrad_bits = \nmap_bits = 8\n").unwrap();
    let o = run(&["render", "--config", c_, "--out", o_]);
    assert_error(&o, &format!("config {c_}:2:12: grad_bits has no value"));
    assert!(!stderr(&o).contains("quoted"));
    std::fs::write(&c, "grad_bits = \"lots\"\n").unwrap();
    assert_error(
        &run(&["render", "--config", c_, "--out", o_]),
        &format!("config {c_}:1:13: grad_bits: invalid type: string \"lots\", expected u32"),
    );
    std::fs::write(&c, "index_bits = 3\nprefix = \"my core\"\n").unwrap();
    assert_error(
        &run(&["generate", "--config", c_, "--out", o_]),
        &format!("config {c_}:2:10: prefix = \"my core\" has ' '"),
    );
    std::fs::write(&c, "index_bits = 3\ngrad_bits = 30\n").unwrap();
    assert_error(
        &run(&["render", "--config", c_, "--out", o_]),
        &format!("config {c_}:2:13: grad_bits = 30 is out of range; allowed 8..=16"),
    );
    assert!(!out.exists());
}

#[test]
fn a_broken_light_among_ten_thousand_is_found() {
    let t = tempdir();
    let out = t.path().join("o");
    let p = t.path().join("s.toml");
    let write = |broken: usize, bad: &str| -> usize {
        let mut text = MATERIAL.to_string();
        let mut line = 0;
        for i in 0..10_000 {
            text.push_str("[[light]]\n");
            if i == broken {
                line = text.lines().count() + 1;
                text.push_str(&format!("direction = {bad}\n"));
            } else {
                text.push_str(&format!("direction = [{}.0, 1.0, 2.0]\n", i % 7));
            }
            text.push_str("intensity = 0.0001\n");
        }
        std::fs::write(&p, text).unwrap();
        line
    };
    let run_it = || {
        run(&[
            "render",
            "--scene",
            p.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let line = write(9999, "[1.0, 2.0]");
    assert_error(
        &run_it(),
        &format!(
            "s.toml:{line}:13: light[9999].direction: invalid length 2, expected an array of length 3"
        ),
    );
    // Found after parsing (validation) too.
    let line = write(6543, "[0.0, 0.0, 0.0]");
    assert_error(
        &run_it(),
        &format!("s.toml:{line}:13: light[6543].direction = [0.0, 0.0, 0.0] has zero length"),
    );
    assert!(!out.exists());
}

#[test]
fn usage_errors_are_one_line_naming_the_flag() {
    let t = tempdir();
    let o = t.path().join("o");
    let o_ = o.to_str().unwrap();
    let s = root().join("scenes/standard.toml");
    let s_ = s.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--grad-bits", "-1", "--out", o_],
            "--grad-bits must be in 8..=16, not -1",
        ),
        (
            &["render", "--grad-bits", "99999999999999", "--out", o_],
            "--grad-bits must be in 8..=16, not 99999999999999",
        ),
        (
            &["generate", "--map-bits", "5", "--out", o_],
            "--map-bits must be in 6..=12, not 5",
        ),
        (
            &["render", "--recip-bits", "x", "--out", o_],
            "--recip-bits must be in 5..=20, not 'x'",
        ),
        (
            &["render", "--pipeline-depth", "3", "--out", o_],
            "--pipeline-depth must be in 0..=2, not 3",
        ),
        (
            &["fit", "--scene", s_, "--max-error", "-1", "--out", o_],
            "--max-error must be a whole number >= 0, not -1",
        ),
        (
            &["fit", "--scene", s_, "--rmse", "-0.5", "--out", o_],
            "--rmse must be a finite number >= 0, not -0.5",
        ),
        (
            &["fpga", "--freq", "-5", "--logs", o_],
            "--freq must be a positive number, not -5",
        ),
        (
            &["render", "--size", "-5", "--out", o_],
            "--size must be a positive whole number, not -5",
        ),
        (
            &["volume", "--synthetic", "--step", "-1", "--out", o_],
            "--step must be a positive number, not -1",
        ),
        (
            &["vectors", "--count", "-5", "--out", o_],
            "--count must not be negative, not -5",
        ),
        (
            &["render", "--grad-bit", "9", "--out", o_],
            "unexpected argument '--grad-bit' found; a similar argument exists: '--grad-bits'",
        ),
        (
            &["render"],
            "the following required arguments were not provided: --out <DIR>",
        ),
        (&[], "give a command: generate, roms, maps, render"),
        (
            &["generate", "--prefix", "9a_", "--out", o_],
            "--prefix \"9a_\" starts with a digit; allowed a letter or _ then letters, digits and _",
        ),
        (
            &["render", "--prefix", "a-b", "--out", o_],
            "--prefix \"a-b\" has '-'",
        ),
    ];
    for (args, needle) in cases {
        assert_error(&run(args), needle);
    }
    assert!(!o.exists());
    // Help and version are not errors.
    let h = run(&["render", "--help"]);
    let text = String::from_utf8_lossy(&h.stdout);
    assert_eq!(h.status.code(), Some(0));
    assert!(
        text.lines().count() > 20
            && text.contains("Usage: rmapgen render")
            && text.contains("--grad-bits"),
        "{text}"
    );
    let h = run(&["--help"]);
    assert_eq!(h.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&h.stdout).contains("Commands:"));
    let v = run(&["--version"]);
    assert_eq!(v.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&v.stdout).starts_with("rmapgen "));
}

/// Issue 14 §1: every command that takes the configuration flags refuses a prefix that is
/// not a Verilog identifier prefix, in one line, and writes nothing.
#[test]
fn a_bad_prefix_is_refused_by_every_command() {
    let t = tempdir();
    let o = t.path().join("o");
    let o_ = o.to_str().unwrap();
    let long = "a".repeat(rmapgen::config::PREFIX_MAX_LEN + 1);
    for (p, why) in [
        ("1x", "starts with a digit"),
        ("a.b", "has '.'"),
        ("a/b", "has '/'"),
        (long.as_str(), "is 33 characters long"),
    ] {
        for cmd in [
            &["generate", "--out", o_][..],
            &["roms", "--out", o_],
            &["render", "--out", o_],
            &["vectors", "--out", o_],
            &["volume", "--synthetic", "--out", o_],
            &["stress"],
            &["fpga", "--logs", o_],
        ] {
            let mut args = cmd.to_vec();
            args.extend(["--prefix", p]);
            assert_error(&run(&args), &format!("--prefix {p:?} {why}"));
        }
    }
    assert!(!o.exists());
}

/// Issue 14 §4: AXI4-Stream needs the handshake (refused, not implied) and tuser needs
/// AXI4-Stream, from flags or from the file; one line, exit 2, nothing written.
#[test]
fn axis_without_the_handshake_is_refused() {
    let t = tempdir();
    let o = t.path().join("o");
    let o_ = o.to_str().unwrap();
    let c = t.path().join("c.toml");
    std::fs::write(&c, "axis = true\n").unwrap();
    let c_ = c.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["generate", "--axis", "--out", o_],
            "axis = true needs handshake = true (AXI4-Stream is a valid/ready interface); add --handshake (axis from --axis, handshake by default)",
        ),
        (
            &["generate", "--handshake", "--axis-user", "4", "--out", o_],
            "axis_user = 4 without axis; tuser exists only on the AXI4-Stream ports (add --axis) (axis_user from --axis-user 4, axis by default)",
        ),
        (
            &["generate", "--handshake", "--axis", "--axis-user", "65", "--out", o_],
            "--axis-user must be in 0..=64, not 65",
        ),
        (
            &["generate", "--config", c_, "--out", o_],
            "axis = true needs handshake = true",
        ),
    ];
    for (args, needle) in cases {
        assert_error(&run(args), needle);
    }
    assert!(!o.exists());
    let ok = run(&["generate", "--config", c_, "--handshake", "--out", o_]);
    assert_eq!(ok.status.code(), Some(0), "{}", stderr(&ok));
    assert!(o.join("rmap_axis.v").is_file());
}

/// Issue 15 §1: lanes out of range, and lanes with the AXI4-Stream top (not supported yet),
/// from flags or from the file; one line, exit 2, nothing written.
#[test]
fn bad_lanes_are_refused() {
    let t = tempdir();
    let o = t.path().join("o");
    let o_ = o.to_str().unwrap();
    let c = t.path().join("c.toml");
    std::fs::write(&c, "lanes = 9\n").unwrap();
    let c_ = c.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["generate", "--lanes", "9", "--out", o_],
            "--lanes must be in 1..=8, not 9",
        ),
        (
            &["generate", "--lanes", "0", "--out", o_],
            "--lanes must be in 1..=8, not 0",
        ),
        (
            &[
                "generate",
                "--lanes",
                "2",
                "--handshake",
                "--axis",
                "--out",
                o_,
            ],
            "lanes = 2 with axis: the AXI4-Stream top has one lane",
        ),
        (
            &["generate", "--config", c_, "--out", o_],
            "lanes = 9 is out of range; allowed 1..=8",
        ),
    ];
    for (args, needle) in cases {
        assert_error(&run(args), needle);
    }
    assert!(!o.exists());
}

#[test]
fn a_directory_is_not_a_toml_file() {
    let t = tempdir();
    let d = t.path().join("dir.toml");
    std::fs::create_dir(&d).unwrap();
    let d_ = d.to_str().unwrap();
    let out = t.path().join("o");
    let o_ = out.to_str().unwrap();
    assert_error(
        &run(&["render", "--scene", d_, "--out", o_]),
        &format!("scene {d_} is a directory, not a TOML file"),
    );
    assert_error(
        &run(&["generate", "--config", d_, "--out", o_]),
        &format!("config {d_} is a directory, not a TOML file"),
    );
    assert!(!out.exists());
}

#[test]
fn flags_override_the_config_file_before_it_is_validated() {
    let t = tempdir();
    let c = t.path().join("c.toml");
    let c_ = c.to_str().unwrap();
    std::fs::write(&c, "map_bits = 10\ninterp_bits = 0\n").unwrap();
    let out = t.path().join("o");
    let o_ = out.to_str().unwrap();
    // Invalid alone (interpolation on with 0 bits), and it says where the value is.
    assert_error(
        &run(&["render", "--config", c_, "--size", "16", "--out", o_]),
        &format!("config {c_}:2:15: interp_bits = 0 with interpolation on"),
    );
    assert!(!out.exists());
    // Valid with the flag the help says overrides it.
    let o = run(&[
        "render",
        "--config",
        c_,
        "--no-interpolation",
        "--size",
        "16",
        "--out",
        o_,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["config"]["interpolation"], false);
    assert_eq!(j["config"]["interp_bits"], 0);
    assert_eq!(j["config"]["map_bits"], 10);
    // A conflict between the file and a flag names both sources.
    std::fs::write(&c, "grad_bits = 10\n").unwrap();
    let out2 = t.path().join("o2");
    assert_error(
        &run(&["render", "--config", c_, "--red-bits", "12", "--out", out2.to_str().unwrap()]),
        &format!("red_bits = 12 exceeds grad_bits = 10; the reduced magnitude cannot be wider than the gradient (red_bits from --red-bits 12, grad_bits from config {c_}:1:13)"),
    );
    assert!(!out2.exists());
}

#[test]
fn a_transfer_function_that_covers_nothing_is_refused() {
    let t = tempdir();
    let out = t.path().join("out");
    // An earlier output, which the refused run must leave as it was.
    let earlier = run(&["render", "--size", "16", "--out", out.to_str().unwrap()]);
    assert!(earlier.status.success(), "{}", stderr(&earlier));
    let before = crate::helpers::tree(&out);
    let o = volume(&["--transfer", "5000:0,6000:1"], &out);
    assert_error(
        &o,
        "nothing covered: the transfer function makes every sample of the volume transparent",
    );
    let e = stderr(&o);
    // The data's distribution (the engine block's values run from about 50 to 2930) and the
    // breakpoints.
    let v = rmapgen::volume::synthetic::engine_block([32, 32, 16], [1.0; 3]).unwrap();
    let [min, p1, p50, p99, max] = rmapgen::volume::report::percentiles(&v);
    assert!(
        min <= p1 && p1 < p50 && p50 < p99 && p99 <= max,
        "{min} {p1} {p50} {p99} {max}"
    );
    assert!(
        e.contains(&format!(
            "min {min}, p1 {p1}, p50 {p50}, p99 {p99}, max {max}"
        )) && e.contains("breakpoints (value:opacity) are 5000:0,6000:1"),
        "{e}"
    );
    let mut left: Vec<_> = std::fs::read_dir(t.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["out"], "no staging directory");
    assert_eq!(crate::helpers::tree(&out), before, "output untouched");
    // A transfer function inside the data's range renders.
    let o = volume(
        &["--transfer", &format!("{}:0,{}:1", p50, p99)],
        &t.path().join("ok"),
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

// Property tests: the loaders never panic, and every error is one line.

fn sources() -> Vec<(String, bool)> {
    let mut v: Vec<(String, bool)> = std::fs::read_dir(root().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| (std::fs::read_to_string(p).unwrap(), true))
        .collect();
    v.sort();
    let cfg = std::fs::read_to_string(root().join("rtl_out/tb/config.toml"))
        .unwrap_or_else(|_| toml::to_string(&Config::default()).unwrap());
    v.push((cfg, false));
    v
}

#[derive(Clone, Debug)]
enum Mutation {
    Flip(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    /// Replace the value of the n-th `key = value` line.
    Value(usize, &'static str),
    /// Duplicate the n-th line.
    Duplicate(usize),
    /// Replace the value of the n-th `key = value` line with an array of n numbers.
    HugeArray(usize, usize),
}

const VALUES: &[&str] = &[
    "1e308",
    "-1e308",
    "1e200",
    "-1",
    "0",
    "99999999999999999999",
    "-99999999999999",
    "nan",
    "-inf",
    "inf",
    "\"lots\"",
    "\"\"",
    "true",
    "[]",
    "[1e308, 1e308, 1e308]",
    "[0, 0, 0]",
    "[nan, 0, 1]",
    "[1.0, 2.0]",
    "[[1, 0], [0, 1]]",
    "{}",
    "",
    "1979-05-27",
    "'\u{7f}'",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Flip(p, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Insert(p, b)),
        any::<usize>().prop_map(Mutation::Delete),
        (any::<usize>(), prop::sample::select(VALUES)).prop_map(|(n, v)| Mutation::Value(n, v)),
        any::<usize>().prop_map(Mutation::Duplicate),
        (any::<usize>(), 0usize..5000).prop_map(|(n, k)| Mutation::HugeArray(n, k)),
    ]
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut b = text.as_bytes().to_vec();
    let lines: Vec<&str> = text.lines().collect();
    let assignments: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].contains('='))
        .collect();
    let set_value = |n: usize, v: String| -> String {
        if assignments.is_empty() {
            return text.to_string();
        }
        let i = assignments[n % assignments.len()];
        let key = lines[i].split('=').next().unwrap();
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        out[i] = format!("{key}= {v}");
        out.join("\n") + "\n"
    };
    match *m {
        Mutation::Flip(p, x) if !b.is_empty() => {
            let n = b.len();
            b[p % n] ^= x.max(1);
        }
        Mutation::Insert(p, x) => b.insert(p % (b.len() + 1), x),
        Mutation::Delete(p) if !b.is_empty() => {
            let n = b.len();
            b.remove(p % n);
        }
        Mutation::Value(n, v) => return set_value(n, v.to_string()),
        Mutation::HugeArray(n, k) => {
            let items: Vec<String> = (0..k).map(|i| format!("{}.5", i)).collect();
            return set_value(n, format!("[{}]", items.join(", ")));
        }
        Mutation::Duplicate(n) if !lines.is_empty() => {
            let mut out: Vec<&str> = lines.clone();
            let i = n % lines.len();
            out.insert(i, lines[i]);
            return out.join("\n") + "\n";
        }
        _ => {}
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// Loads `text` as a scene and as a configuration; errors must be one line.
/// Memory a load may take beyond its text: parsing holds a few copies of it, and nothing it
/// builds may grow with the values it reads (a count or size in a file is no allocation).
const LOAD_BUDGET: usize = 4 << 20;

fn load_both(text: &str) -> Result<(), TestCaseError> {
    let budget = LOAD_BUDGET + 64 * text.len();
    let (scene, peak) = crate::alloc::peak_during(|| Scene::from_toml_named(text, "scene s.toml"));
    prop_assert!(peak < budget, "scene load peaked at {peak} bytes");
    if let Err(e) = scene {
        let m = format!("{e:#}");
        prop_assert!(!m.contains('\n') && m.starts_with("scene s.toml"), "{m:?}");
    }
    let (config, peak) =
        crate::alloc::peak_during(|| Config::from_toml_named(text, "config c.toml"));
    prop_assert!(peak < budget, "config load peaked at {peak} bytes");
    if let Err(e) = config {
        let m = format!("{e:#}");
        prop_assert!(!m.contains('\n') && m.starts_with("config c.toml"), "{m:?}");
    }
    Ok(())
}

#[test]
fn a_toml_input_over_its_size_limit_is_refused_unread() {
    let t = tempdir();
    let big = t.path().join("big.toml");
    let mut text = String::from("[material]\nambient = 0.1\n");
    while (text.len() as u64) <= rmapgen::toml_input::MAX_BYTES {
        text.push_str("# padding padding padding padding padding padding padding padding\n");
    }
    std::fs::write(&big, text).unwrap();
    let out = t.path().join("o");
    for flag in ["--scene", "--config"] {
        let o = run(&[
            "render",
            flag,
            big.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_error(&o, "is larger than 16 MiB, the limit for a TOML input");
    }
    assert!(!out.exists());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn mutated_inputs_never_panic_and_errors_are_one_line(
        which in any::<usize>(),
        ms in prop::collection::vec(mutation(), 1..4),
    ) {
        let src = sources();
        let (text, is_scene) = &src[which % src.len()];
        // The unmutated source loads as what it is.
        if *is_scene {
            prop_assert!(Scene::from_toml_str(text).is_ok());
        } else {
            prop_assert!(Config::from_toml_named(text, "config").is_ok());
        }
        let mut t = text.clone();
        for m in &ms {
            t = apply(&t, m);
        }
        load_both(&t)?;
    }

    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        load_both(&String::from_utf8_lossy(&bytes))?;
    }
}

/// Issue 15 §3: an unknown multiplier style, from the flag or from the file; one line, exit 2,
/// nothing written.
#[test]
fn an_unknown_multiplier_style_is_refused() {
    let t = tempdir();
    let o = t.path().join("o");
    let o_ = o.to_str().unwrap();
    let c = t.path().join("c.toml");
    std::fs::write(&c, "mult = \"dsp\"\n").unwrap();
    let c_ = c.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["generate", "--mult", "dsp", "--out", o_],
            "invalid value 'dsp' for '--mult <M>'",
        ),
        (
            &["generate", "--config", c_, "--out", o_],
            "mult: unknown variant `dsp`",
        ),
    ];
    for (args, needle) in cases {
        assert_error(&run(args), needle);
    }
    assert!(!o.exists());
}
