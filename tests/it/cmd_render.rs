//! `rmapgen render` from the command line: what it writes, and how it fails (exit 2, one
//! line on stderr naming the problem, no output or staging directory left behind).

use super::helpers::{assert_error, run, tempdir};
use std::path::Path;

const MATERIAL: &str =
    "[material]\nambient = 0.1\ndiffuse = 0.6\nspecular = 0.3\nshininess = 20.0\n";

#[test]
fn writes_images_and_metrics() {
    let tmp = tempdir();
    let out = tmp.path().join("sphere");
    let o = run(&[
        "render",
        "--size",
        "96",
        "--shrink",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(
        stdout.contains("max abs error") && stdout.contains("RMSE") && stdout.contains("PSNR"),
        "{stdout}"
    );
    assert_eq!(
        crate::helpers::entries(&out),
        [
            ".rmapgen-files",
            "error50.png",
            "error_signed.png",
            "highlight.png",
            "histogram.png",
            "metrics.json",
            "model.png",
            "profile.png",
            "reference.png",
            "report.html"
        ]
    );
    assert_eq!(
        crate::helpers::entries(tmp.path()),
        ["sphere"],
        "no staging directory left"
    );
    for name in ["error50.png", "model.png", "reference.png"] {
        let img = image::open(out.join(name)).unwrap();
        assert_eq!((img.width(), img.height()), (96, 96), "{name}");
        assert_eq!(img.color(), image::ColorType::L8, "{name}");
    }
    let model = image::open(out.join("model.png")).unwrap().to_luma8();
    assert_eq!(model.get_pixel(0, 0).0[0], 0, "background");
    // The highlight is upper right: brighter than the mirrored lower-left point.
    assert!(model.get_pixel(58, 38).0[0] > model.get_pixel(37, 57).0[0] + 50);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["size"], 96);
    assert_eq!(j["shrink"], 2);
    assert_eq!(j["config"]["grad_bits"], 12);
    assert_eq!(j["scene"]["material"]["shininess"], 20.0);
    assert!(j["max_abs_error"].as_u64().unwrap() > 0 && j["rmse"].as_f64().unwrap() > 0.0);
}

#[test]
fn config_flags_and_scene_apply() {
    let tmp = tempdir();
    let scene = tmp.path().join("diffuse.toml");
    std::fs::copy(super::helpers::root().join("scenes/diffuse.toml"), &scene).unwrap();
    let out = tmp.path().join("o");
    let o = run(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--size",
        "40",
        "--no-interpolation",
        "--map-bits",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["config"]["interpolation"], false);
    assert_eq!(j["peak"], 1023);
    assert_eq!(j["scene"]["material"]["specular"], 0.0);
}

/// Runs a failing render whose output would go to a fresh directory, and checks the error
/// and that nothing was left in that directory.
fn fails(scene_text: Option<&str>, extra: &[&str], needle: &str) {
    let inputs = tempdir();
    let outs = tempdir();
    let out = outs.path().join("out");
    let mut args = vec![
        "render".to_string(),
        "--out".into(),
        out.display().to_string(),
    ];
    if !extra.contains(&"--size") {
        args.extend(["--size".into(), "32".into()]);
    }
    if let Some(t) = scene_text {
        let p = inputs.path().join("scene.toml");
        std::fs::write(&p, t).unwrap();
        args.extend(["--scene".into(), p.display().to_string()]);
    }
    args.extend(extra.iter().map(|s| s.to_string()));
    let o = run(&args.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    assert_error(&o, needle);
    assert!(
        crate::helpers::entries(outs.path()).is_empty(),
        "left behind: {:?}",
        crate::helpers::entries(outs.path())
    );
}

#[test]
fn malformed_scene() {
    fails(Some("[material\nambient = 0.1\n"), &[], "unclosed table");
}

#[test]
fn nan_light_direction() {
    fails(
        Some(&format!(
            "{MATERIAL}[[light]]\ndirection = [nan, 0.0, 1.0]\n"
        )),
        &[],
        "scene.toml:7:13: light[0].direction = [NaN, 0.0, 1.0] is not finite",
    );
}

#[test]
fn zero_light_direction() {
    fails(
        Some(&format!(
            "{MATERIAL}[[light]]\ndirection = [0.0, 0.0, 0.0]\n"
        )),
        &[],
        "scene.toml:7:13: light[0].direction = [0.0, 0.0, 0.0] has zero length",
    );
}

#[test]
fn negative_shininess() {
    fails(
        Some(&MATERIAL.replace("shininess = 20.0", "shininess = -2.0")),
        &[],
        "shininess = -2 must be a finite number >= 0",
    );
}

#[test]
fn out_of_range_width() {
    fails(
        None,
        &["--grad-bits", "30"],
        "--grad-bits must be in 8..=16, not 30",
    );
}

#[test]
fn out_of_range_size_and_shrink() {
    fails(None, &["--size", "0"], "image size 0 is out of range");
    fails(
        None,
        &["--shrink", "12"],
        "shrink 12 is out of range; allowed 0..=11",
    );
}

#[test]
fn unwritable_output() {
    let o = run(&["render", "--size", "32", "--out", "/proc/nonexistent/out"]);
    assert_error(&o, "cannot write output directory /proc/nonexistent/out");
    assert!(!Path::new("/proc/nonexistent").exists());
}

#[test]
fn failure_keeps_an_existing_output() {
    // A failing run must not touch what an earlier run wrote.
    let tmp = tempdir();
    let out = tmp.path().join("o");
    assert!(
        run(&["render", "--size", "16", "--out", out.to_str().unwrap()])
            .status
            .success()
    );
    let before = std::fs::read(out.join("metrics.json")).unwrap();
    assert_error(
        &run(&[
            "render",
            "--size",
            "16",
            "--red-bits",
            "12",
            "--grad-bits",
            "10",
            "--out",
            out.to_str().unwrap(),
        ]),
        "red_bits = 12 exceeds grad_bits = 10",
    );
    assert_eq!(std::fs::read(out.join("metrics.json")).unwrap(), before);
    assert_eq!(crate::helpers::entries(tmp.path()), ["o"]);
}

/// Standard base64 decoding (the test's own, against the report's encoder).
fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    } as u32;
    let mut out = Vec::new();
    for q in s.as_bytes().chunks(4) {
        let pad = q.iter().filter(|&&c| c == b'=').count();
        let n = q
            .iter()
            .map(|&c| if c == b'=' { 0 } else { val(c) })
            .fold(0u32, |n, v| n << 6 | v);
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// report.html shows every image the render wrote, byte for byte, and the figures of
/// metrics.json.
#[test]
fn the_report_embeds_every_image_and_the_figures() {
    let tmp = tempdir();
    let out = tmp.path().join("sphere");
    let o = run(&["render", "--size", "64", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let names: Vec<&str> = metrics["images"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 7, "{names:?}");
    let mut shown = 0;
    for part in page.split("<img alt=\"").skip(1) {
        let (name, rest) = part.split_once('"').unwrap();
        let data = rest
            .split_once("src=\"data:image/png;base64,")
            .unwrap()
            .1
            .split('"')
            .next()
            .unwrap();
        let bytes = unbase64(data);
        assert_eq!(bytes, std::fs::read(out.join(name)).unwrap(), "{name}");
        image::load_from_memory(&bytes).expect("a PNG");
        assert!(names.contains(&name));
        shown += 1;
    }
    assert_eq!(shown, names.len());
    let max = metrics["max_abs_error"].as_u64().unwrap();
    assert!(
        page.contains(&format!("<th>largest error</th><td>{max} LSB</td>")),
        "{page}"
    );
    assert!(page.starts_with("<!DOCTYPE html>") && page.ends_with("</html>\n"));
}

/// A `--color` design renders in colour: the reference, the design and their error as RGB
/// images, the colour figures in metrics.json and on the page; a scene's colour is used
/// uniformly.
#[test]
fn a_colour_design_renders_in_colour() {
    let tmp = tempdir();
    let out = tmp.path().join("sphere");
    let o = run(&[
        "render",
        "--color",
        "--size",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("colour (ramp): max abs error"));
    for name in [
        "color_reference.png",
        "color_model.png",
        "color_error50.png",
    ] {
        let img = image::open(out.join(name)).unwrap();
        assert_eq!(img.color(), image::ColorType::Rgb8, "{name}");
        assert_eq!((img.width(), img.height()), (64, 64), "{name}");
    }
    let model = image::open(out.join("color_model.png")).unwrap().to_rgb8();
    assert!(model.pixels().any(|p| p[0] != p[2]), "a ramp of colours");
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["color"]["source"], "ramp");
    let cmax = j["color"]["max_abs_error"].as_u64().unwrap();
    assert!(
        cmax > 0 && cmax <= j["max_abs_error"].as_u64().unwrap() + 1,
        "{j}"
    );
    assert!(j["images"]
        .as_array()
        .unwrap()
        .iter()
        .any(|v| v == "color_model.png"));
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(page.contains("<img alt=\"color_model.png\""));
    assert!(
        page.contains(&format!("largest error {cmax} LSB")),
        "{page}"
    );

    // A scene's colour: every pixel of the sphere carries it.
    let scene = tmp.path().join("orange.toml");
    std::fs::write(
        &scene,
        format!("color = [1.0, 0.5, 0.0]\n{MATERIAL}[[light]]\ndirection = [0.0, 0.0, 1.0]\n"),
    )
    .unwrap();
    let out = tmp.path().join("orange");
    let o = run(&[
        "render",
        "--color",
        "--scene",
        scene.to_str().unwrap(),
        "--size",
        "32",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let reference = image::open(out.join("color_reference.png"))
        .unwrap()
        .to_rgb8();
    let lit: Vec<_> = reference.pixels().filter(|p| p[0] > 0).collect();
    assert!(!lit.is_empty());
    for p in lit {
        assert_eq!(p[2], 0, "no blue in an orange scene");
        assert!(p[1].abs_diff(p[0] / 2) <= 1, "green half of red: {p:?}");
    }
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["color"]["source"], "scene");
}

/// The README's pictures are what `render` writes today (`make docs-images` writes them):
/// byte for byte where no text is drawn, the same size where a system font draws labels.
#[test]
fn the_readme_pictures_are_what_render_writes() {
    let tmp = tempdir();
    let out = tmp.path().join("s");
    let o = run(&[
        "render",
        "--color",
        "--scene",
        crate::helpers::root()
            .join("scenes/standard.toml")
            .to_str()
            .unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let docs = crate::helpers::root().join("docs/images");
    for name in ["reference", "model", "error50", "highlight", "color_model"] {
        let fresh = std::fs::read(out.join(format!("{name}.png"))).unwrap();
        let committed = std::fs::read(docs.join(format!("sphere_{name}.png"))).unwrap();
        assert!(
            fresh == committed,
            "docs/images/sphere_{name}.png is not what render writes: run make docs-images"
        );
    }
    for name in ["error_signed", "profile", "histogram"] {
        let fresh = image::open(out.join(format!("{name}.png"))).unwrap();
        let committed = image::open(docs.join(format!("sphere_{name}.png"))).unwrap();
        assert_eq!(
            (fresh.width(), fresh.height()),
            (committed.width(), committed.height()),
            "docs/images/sphere_{name}.png: run make docs-images"
        );
    }
}
