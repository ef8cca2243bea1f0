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
            "metrics.json",
            "model.png",
            "reference.png"
        ]
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
        render(&args, &out);
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
    // A scene without a transfer function cannot render a volume.
    let standard = super::helpers::root().join("scenes/standard.toml");
    fails(
        &[
            "--synthetic",
            "--dims",
            "16,16,8",
            "--scene",
            standard.to_str().unwrap(),
        ],
        "no [transfer] section",
    );
}
