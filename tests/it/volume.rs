//! `rmapgen volume` from the command line: the synthetic part and the same values from raw,
//! NRRD (gzip, attached) and NRRD (detached) files give the same images; skipping does not
//! change them; bad input fails with exit 2, one line on stderr naming the problem, and
//! nothing written. Volumes are small (64 x 64 x 32, the full-size generator scaled).

use super::helpers::{assert_error, first_difference, run, tempdir};
use rmapgen::volume::load::{nrrd_bytes, VoxelType};
use rmapgen::volume::synthetic;
use std::path::Path;

const SMALL: &str = "64,64,32";

/// Runs `rmapgen volume` with `args` plus `--size 64 --out <dir>`, expecting success.
fn render(args: &[&str], out: &Path) -> String {
    let mut a = vec!["volume"];
    a.extend_from_slice(args);
    a.extend_from_slice(&["--size", "64", "--out", out.to_str().unwrap()]);
    let o = run(&a);
    assert!(
        o.status.success(),
        "{:?}: {}",
        a,
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn small_volume() -> rmapgen::volume::Volume {
    synthetic::engine_block([64, 64, 32], [1.0; 3]).unwrap()
}

#[test]
fn synthetic_writes_images_and_metrics() {
    let tmp = tempdir();
    let out = tmp.path().join("v");
    let stdout = render(&["--synthetic", "--dims", SMALL], &out);
    assert!(
        stdout.contains("max abs error") && stdout.contains("skipped"),
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
            "reference.png"
        ]
    );
    // The sphere render's pictures, of the volume's covered pixels.
    for name in [
        "highlight.png",
        "error_signed.png",
        "profile.png",
        "histogram.png",
    ] {
        let img = image::open(out.join(name)).unwrap();
        assert_eq!(img.color(), image::ColorType::Rgb8, "{name}");
    }
    let highlight = image::open(out.join("highlight.png")).unwrap();
    assert_eq!(
        highlight.width(),
        3 * rmapgen::render::pictures::CROP * rmapgen::render::pictures::ZOOM
            + 2 * rmapgen::render::pictures::GAP
    );
    assert_eq!(
        crate::helpers::entries(tmp.path()),
        ["v"],
        "no staging directory left"
    );
    for name in ["error50.png", "model.png", "reference.png"] {
        let img = image::open(out.join(name)).unwrap();
        assert_eq!(
            (img.width(), img.height(), img.color()),
            (64, 64, image::ColorType::L8)
        );
    }
    let model = image::open(out.join("model.png")).unwrap().to_luma8();
    assert_eq!(model.get_pixel(0, 0).0[0], 0, "background");
    assert!(
        model.pixels().filter(|p| p.0[0] > 50).count() > 64 * 64 / 4,
        "the part is visible"
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    for k in [
        "max_abs_error",
        "rmse",
        "psnr_db",
        "mean_abs_error",
        "pixels",
        "worst",
        "config",
        "scene",
    ] {
        assert!(!j[k].is_null(), "{k}");
    }
    assert_eq!(j["size"], 64);
    assert_eq!(j["volume"]["dims"], serde_json::json!([64, 64, 32]));
    assert_eq!(j["volume"]["voxel_type"], "ushort");
    assert!(j["skipping"]["skipped_fraction"].as_f64().unwrap() > 0.5);
    assert_eq!(j["scene"]["transfer"]["points"][0][0], 1100.0);
}

#[test]
fn raw_and_nrrd_files_give_the_synthetic_images() {
    let tmp = tempdir();
    let vol = small_volume();
    let reference = tmp.path().join("synthetic");
    render(&["--synthetic", "--dims", SMALL], &reference);

    // Attached gzip NRRD.
    let nrrd = tmp.path().join("part.nrrd");
    std::fs::write(&nrrd, nrrd_bytes(&vol, VoxelType::U16, true).unwrap()).unwrap();
    // Detached header with a raw data file.
    let raw: Vec<u8> = vol
        .data
        .iter()
        .flat_map(|&v| (v as u16).to_le_bytes())
        .collect();
    std::fs::write(tmp.path().join("part.raw"), &raw).unwrap();
    let nhdr = tmp.path().join("part.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: unsigned short\ndimension: 3\nsizes: 64 64 32\nendian: little\n\
         encoding: raw\nspacings: 1 1 1\ndata file: part.raw\n",
    )
    .unwrap();

    for (name, args) in [
        ("gz", vec![nrrd.to_str().unwrap()]),
        ("nhdr", vec![nhdr.to_str().unwrap()]),
        (
            "raw",
            vec![
                tmp.path().join("part.raw").to_str().unwrap(),
                "--dims",
                SMALL,
                "--bits",
                "16",
            ],
        ),
    ] {
        let out = tmp.path().join(name);
        // The synthetic part's function: without one, a file gets the data's default.
        render(
            &[&args[..], &["--transfer", "1100:0,1900:1"]].concat(),
            &out,
        );
        for img in ["reference.png", "model.png", "error50.png"] {
            assert_eq!(
                std::fs::read(out.join(img)).unwrap(),
                std::fs::read(reference.join(img)).unwrap(),
                "{name} {img}"
            );
        }
    }
}

#[test]
fn skipping_off_gives_the_same_files_and_timing_reports() {
    let tmp = tempdir();
    let (on, off) = (tmp.path().join("on"), tmp.path().join("off"));
    let args = ["--synthetic", "--dims", SMALL, "--view", "0.3,-0.8,0.5"];
    render(&args, &on);
    render(&[&args[..], &["--no-skip"]].concat(), &off);
    // metrics.json differs only in the skipping statistics and the option itself.
    for img in ["reference.png", "model.png", "error50.png"] {
        assert_eq!(
            std::fs::read(on.join(img)).unwrap(),
            std::fs::read(off.join(img)).unwrap(),
            "{img}"
        );
    }
    let j = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("metrics.json")).unwrap()).unwrap()
    };
    let (a, b) = (j(&on), j(&off));
    assert_eq!(a["rmse"], b["rmse"]);
    assert_eq!(a["skipping"]["samples"], b["skipping"]["samples"]);
    assert_eq!(b["skipping"]["skipped_fraction"], 0.0);
    assert_eq!(
        a["scene"]["view"]["direction"],
        serde_json::json!([0.3, -0.8, 0.5])
    );

    let timed = tmp.path().join("timed");
    let stdout = render(
        &[&args[..], &["--timing", "--repeat", "1"]].concat(),
        &timed,
    );
    assert!(
        stdout.contains("speed-up") && stdout.contains("identical image"),
        "{stdout}"
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(timed.join("timing.json")).unwrap()).unwrap();
    for k in [
        "model_skipping_on",
        "float_skipping_on",
        "model_skipping_off",
    ] {
        assert!(t[k]["median_ms"].as_f64().unwrap() > 0.0, "{k}");
    }
    assert!(t["skipped_fraction"].as_f64().unwrap() > 0.5);
    // The stamps list different files; everything else must agree.
    for d in [&on, &timed] {
        std::fs::remove_file(d.join(".rmapgen-files")).unwrap();
    }
    assert_eq!(
        first_difference(&on, &timed).unwrap(),
        format!(
            "timing.json is in {} but not in {}",
            timed.display(),
            on.display()
        )
    );
}

/// Runs a failing `rmapgen volume` and checks the error and that nothing was written: the
/// output directory, which already holds a file, is unchanged, and no staging directory is
/// left beside it.
fn fails(args: &[&str], needle: &str) {
    let tmp = tempdir();
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "old").unwrap();
    let before = crate::helpers::entries(tmp.path());
    let mut a = vec!["volume"];
    a.extend_from_slice(args);
    a.extend_from_slice(&["--size", "32", "--out", out.to_str().unwrap()]);
    assert_error(&run(&a), needle);
    assert_eq!(
        crate::helpers::entries(tmp.path()),
        before,
        "no staging directory"
    );
    assert_eq!(
        crate::helpers::entries(&out),
        ["keep.txt"],
        "output untouched"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("keep.txt")).unwrap(),
        "old"
    );
}

#[test]
fn raw_file_of_the_wrong_size() {
    let tmp = tempdir();
    let p = tmp.path().join("v.raw");
    std::fs::write(&p, vec![0u8; 1000]).unwrap();
    let path = p.to_str().unwrap();
    fails(
        &[path, "--dims", "10,10,10", "--bits", "16"],
        "is 1000 bytes but --dims 10,10,10 with 16-bit voxels need 2000 bytes",
    );
    fails(&[path, "--dims", "10,10,11"], "need 1100 bytes");
    fails(&[path], "needs --dims");
}

#[test]
fn zero_or_negative_dims() {
    let tmp = tempdir();
    let p = tmp.path().join("v.raw");
    std::fs::write(&p, vec![0u8; 1000]).unwrap();
    let path = p.to_str().unwrap();
    fails(
        &[path, "--dims", "10,0,10"],
        "size 0 along y is not positive",
    );
    fails(
        &[path, "--dims", "-10,10,10"],
        "size -10 along x is not positive",
    );
    fails(
        &["--synthetic", "--dims", "64,64,0"],
        "size 0 along z is not positive",
    );
    fails(&[path, "--dims", "10,10"], "three comma-separated values");
    let nrrd = tmp.path().join("v.nrrd");
    std::fs::write(
        &nrrd,
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 0 10\nencoding: raw\n\n",
    )
    .unwrap();
    fails(&[nrrd.to_str().unwrap()], "size 0 along y is not positive");
}

#[test]
fn nrrd_with_unsupported_encoding_or_type() {
    let tmp = tempdir();
    let p = tmp.path().join("v.nrrd");
    let write = |t: &str, enc: &str, body: &[u8]| {
        let mut b = format!(
            "NRRD0004\ntype: {t}\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: {enc}\n\n"
        )
        .into_bytes();
        b.extend_from_slice(body);
        std::fs::write(&p, b).unwrap();
    };
    let path = p.to_str().unwrap();
    write("uchar", "bzip2", &[0; 64]);
    fails(
        &[path],
        "unsupported NRRD encoding 'bzip2' (supported: raw, gzip)",
    );
    write("uchar", "hex", &[b'0'; 128]);
    fails(&[path], "unsupported NRRD encoding 'hex'");
    write("int64", "raw", &[0; 512]);
    fails(&[path], "unsupported NRRD type 'int64'");
    write("block", "raw", &[0; 64]);
    fails(&[path], "unsupported NRRD type 'block'");
    write("ushort", "raw", &[0; 100]);
    fails(
        &[path],
        "holds 100 bytes of voxel data but sizes 4 4 4 of ushort need 128 bytes",
    );
    write("uchar", "gzip", &[1, 2, 3]);
    fails(&[path], "cannot decompress");
}

#[test]
fn non_monotonic_transfer_function() {
    let tmp = tempdir();
    let scene = tmp.path().join("s.toml");
    let text = std::fs::read_to_string(super::helpers::root().join("scenes/engine.toml"))
        .unwrap()
        .replace(
            "points = [[1100.0, 0.0], [1900.0, 1.0]]",
            "points = [[1100.0, 0.0], [1900.0, 1.0], [1500.0, 0.5]]",
        );
    assert!(text.contains("[1500.0, 0.5]"));
    std::fs::write(&scene, text).unwrap();
    fails(
        &[
            "--synthetic",
            "--dims",
            "16,16,8",
            "--scene",
            scene.to_str().unwrap(),
        ],
        "transfer function is not monotonic in its breakpoints: breakpoint 3 (value 1500)",
    );
    fails(
        &[
            "--synthetic",
            "--dims",
            "16,16,8",
            "--transfer",
            "1100:0,1000:1",
        ],
        "not monotonic",
    );
}

#[test]
fn a_scene_without_transfer_gets_one_from_the_histogram() {
    let tmp = tempdir();
    let nrrd = tmp.path().join("part.nrrd");
    std::fs::write(
        &nrrd,
        nrrd_bytes(&small_volume(), VoxelType::U16, false).unwrap(),
    )
    .unwrap();
    let standard = super::helpers::root().join("scenes/standard.toml");
    let nrrd = nrrd.to_str().unwrap();
    for (name, extra) in [
        ("file", vec![]),
        ("scene", vec!["--scene", standard.to_str().unwrap()]),
    ] {
        let out = tmp.path().join(name);
        let stdout = render(&[&[nrrd][..], &extra[..]].concat(), &out);
        assert!(stdout.contains("from the data's histogram"), "{stdout}");
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap())
                .unwrap();
        // The threshold lies between air (~80) and metal (~2900), and the part is seen.
        let t = j["scene"]["transfer"]["points"][0][0].as_f64().unwrap();
        assert!(t > 500.0 && t < 2500.0, "{t}");
        assert!(
            j["pixels"].as_u64().unwrap() > 64 * 64 / 4,
            "{}",
            j["pixels"]
        );
    }
}

/// The model image's pixels and size.
fn model_png(dir: &Path) -> image::DynamicImage {
    image::open(dir.join("model.png")).unwrap()
}

#[test]
fn space_directions_turn_the_volume() {
    // The same voxels seen from world +z, once as stored and once turned 90 degrees about z
    // by the NRRD's space directions (voxel x along world +y, voxel y along world -x): the
    // second image's silhouette is the first's turned a quarter in the image plane (the
    // light stays in the world, so the shading differs).
    let tmp = tempdir();
    let vol = small_volume();
    let plain = tmp.path().join("plain.nrrd");
    std::fs::write(&plain, nrrd_bytes(&vol, VoxelType::U16, false).unwrap()).unwrap();
    let bytes = nrrd_bytes(&vol, VoxelType::U16, false).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    let spacings = text.lines().find(|l| l.starts_with("spacings")).unwrap();
    let turned_text = text.replacen(spacings, "space directions: (0,1,0) (-1,0,0) (0,0,1)", 1);
    let turned = tmp.path().join("turned.nrrd");
    // Replace the header line in the bytes (the data after the header is unchanged).
    let head = bytes.len() - vol.data.len() * 2;
    let mut b = turned_text.as_bytes()[..turned_text.len() - (text.len() - head)].to_vec();
    b.extend_from_slice(&bytes[head..]);
    std::fs::write(&turned, b).unwrap();
    let args = ["--view", "0,0,1", "--transfer", "1100:0,1900:1"];
    let (a, t) = (tmp.path().join("a"), tmp.path().join("t"));
    render(&[&[plain.to_str().unwrap()][..], &args[..]].concat(), &a);
    render(&[&[turned.to_str().unwrap()][..], &args[..]].concat(), &t);
    let (a, t) = (model_png(&a).to_luma8(), model_png(&t).to_luma8());
    assert_ne!(a, t);
    let n = a.width();
    let same = |f: &dyn Fn(u32, u32) -> (u32, u32)| {
        (0..n * n)
            .filter(|&i| {
                let (x, y) = (i % n, i / n);
                let (u, v) = f(x, y);
                (a.get_pixel(x, y).0[0] > 0) == (t.get_pixel(u, v).0[0] > 0)
            })
            .count()
    };
    // Voxel (x, y) lands at world (-y, x): a quarter turn anticlockwise in the image.
    let quarter = same(&|x, y| (y, n - 1 - x));
    let other = same(&|x, y| (n - 1 - y, x));
    let unturned = same(&|x, y| (x, y));
    // The part is nearly symmetric: the other quarter turn matches 99.3% (measured), the
    // right one all but a rounding pixel or two.
    assert!(quarter + 4 >= (n * n) as usize, "{quarter} of {}", n * n);
    assert!(
        other < quarter && unturned < quarter,
        "{other} {unturned} {quarter}"
    );
}

#[test]
fn framing_model_only_and_pixel_formats() {
    let tmp = tempdir();
    let base = ["--synthetic", "--dims", SMALL];
    let dir = |s: &str| tmp.path().join(s);
    // --model-only: the model image and metrics, no reference, no error image.
    let stdout = render(
        &[&base[..], &["--model-only", "--png", "gray16"]].concat(),
        &dir("m"),
    );
    assert!(stdout.contains("model only"), "{stdout}");
    assert_eq!(
        crate::helpers::entries(&dir("m")),
        [".rmapgen-files", "metrics.json", "model.png"]
    );
    let m16 = model_png(&dir("m"));
    assert_eq!(m16.color(), image::ColorType::L16);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir("m").join("metrics.json")).unwrap())
            .unwrap();
    assert_eq!(j["model_only"], true);
    assert!(j["rmse"].is_null());
    // The 8-bit image is the 16-bit one rounded.
    render(&base, &dir("g8"));
    let g8 = model_png(&dir("g8")).to_luma8();
    for (p8, p16) in g8.pixels().zip(m16.to_luma16().pixels()) {
        assert_eq!(p8.0[0] as u32, (p16.0[0] as u32 * 255 + 32767) / 65535);
    }
    // RGBA: the background is transparent, the part opaque.
    render(&[&base[..], &["--png", "rgba"]].concat(), &dir("c"));
    let c = model_png(&dir("c"));
    assert_eq!(c.color(), image::ColorType::Rgba8);
    let c = c.to_rgba8();
    assert_eq!(c.get_pixel(0, 0).0[3], 0);
    assert!(c.pixels().filter(|p| p.0[3] == 255).count() > 64 * 64 / 4);
    // Zoom 2 shows the middle half larger: more covered pixels; --up turns the image.
    let pixels = |d: &Path| -> u64 {
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("metrics.json")).unwrap())
                .unwrap();
        j["pixels"].as_u64().unwrap()
    };
    render(&[&base[..], &["--zoom", "2"]].concat(), &dir("z"));
    assert!(pixels(&dir("z")) > pixels(&dir("g8")) * 3 / 2);
    render(&[&base[..], &["--up", "1,0,0"]].concat(), &dir("u"));
    assert_ne!(model_png(&dir("u")).to_luma8(), g8);
    // A crop renders a part of the volume (framed as a whole volume).
    let stdout = render(
        &[&base[..], &["--crop", "0:31,0:63,0:31"]].concat(),
        &dir("k"),
    );
    assert!(stdout.contains("32x64x32 volume"), "{stdout}");
}

#[test]
fn bad_framing_and_classification() {
    let s = ["--synthetic", "--dims", "16,16,8"];
    fn with<'a>(s: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [s, extra].concat()
    }
    fails(&with(&s, &["--up", "0,0,0"]), "has zero length");
    fails(&with(&s, &["--up", "nan,0,1"]), "is not finite");
    fails(&with(&s, &["--up", "inf,0,1"]), "is not finite");
    fails(
        &with(&s, &["--view", "0,0,1", "--up", "0,0,-2"]),
        "is parallel to the view direction",
    );
    fails(&with(&s, &["--zoom", "0"]), "zoom 0 is out of range");
    fails(&with(&s, &["--zoom", "-1.5"]), "zoom -1.5 is out of range");
    fails(&with(&s, &["--zoom", "nan"]), "zoom NaN is out of range");
    fails(
        &with(&s, &["--gradient-ramp", "0:0,20:1,10:1"]),
        "gradient-magnitude ramp is not increasing: breakpoint 3 (magnitude 10)",
    );
    fails(
        &with(&s, &["--gradient-ramp", "5:0,5:1"]),
        "gradient-magnitude ramp is not increasing",
    );
    fails(&with(&s, &["--gradient-ramp", "5:0"]), "at least two");
    fails(
        &with(&s, &["--min-opacity", "1.5"]),
        "--min-opacity 1.5 is out of range",
    );
    fails(
        &with(&s, &["--crop", "0:20,0:15,0:7"]),
        "ends outside the volume",
    );
    fails(
        &with(&s, &["--crop", "3:3,0:15,0:7"]),
        "fewer than 2 voxels",
    );
    fails(&with(&s, &["--crop", "0:3,0:15"]), "three ranges");
}

#[test]
fn shear_warp_caster_skips_without_changing_the_files() {
    // The shear-warp renderer from the command line: the images, the same files with
    // skipping off, the caster named in metrics.json, and --timing with its classification.
    let tmp = tempdir();
    let (on, off) = (tmp.path().join("on"), tmp.path().join("off"));
    let args = [
        "--synthetic",
        "--dims",
        SMALL,
        "--view",
        "0.3,-0.8,0.5",
        "--caster",
        "shear-warp",
    ];
    let stdout = render(&args, &on);
    assert!(stdout.contains("max abs error"), "{stdout}");
    render(&[&args[..], &["--no-skip"]].concat(), &off);
    for img in ["reference.png", "model.png", "error50.png"] {
        assert_eq!(
            std::fs::read(on.join(img)).unwrap(),
            std::fs::read(off.join(img)).unwrap(),
            "{img}"
        );
    }
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(on.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["cast"]["caster"], "shear-warp");
    assert!(j["skipping"]["skipped_fraction"].as_f64().unwrap() > 0.5);
    let model = model_png(&on).to_luma8();
    assert!(
        model.pixels().filter(|p| p.0[0] > 50).count() > 64 * 64 / 4,
        "the part is visible"
    );
    let timed = tmp.path().join("timed");
    let stdout = render(
        &[&args[..], &["--timing", "--repeat", "1", "--model-only"]].concat(),
        &timed,
    );
    assert!(
        stdout.contains("identical image") && stdout.contains("slice cells"),
        "{stdout}"
    );
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(timed.join("timing.json")).unwrap()).unwrap();
    assert_eq!(t["caster"], "shear-warp");
    assert!(t["classify_ms"].as_f64().unwrap() > 0.0);
    // The default is the ray caster.
    let ray = tmp.path().join("ray");
    render(&args[..5], &ray);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ray.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(j["cast"]["caster"], "ray");
}

#[test]
fn bad_shear_warp_sampling_is_refused() {
    let s = ["--synthetic", "--dims", "16,16,8", "--caster", "shear-warp"];
    for (flag, v, needle) in [
        (
            "--slice-samples",
            "0",
            "slice samples 0 is out of range; allowed 1..=8",
        ),
        ("--slice-samples", "9", "slice samples 9 is out of range"),
        (
            "--supersample",
            "0",
            "supersample 0 is out of range; allowed 1..=4",
        ),
        ("--supersample", "5", "supersample 5 is out of range"),
        ("--supersample", "-1", "--supersample"),
    ] {
        fails(&[&s[..], &[flag, v]].concat(), needle);
    }
}

#[test]
fn unknown_caster_is_refused() {
    fails(
        &["--synthetic", "--dims", "16,16,8", "--caster", "fan"],
        "invalid value 'fan' for '--caster",
    );
}
