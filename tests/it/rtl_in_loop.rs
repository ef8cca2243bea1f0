//! The generated RTL in the loop: the sphere and a volume shaded by the Verilated top give
//! images identical pixel for pixel to the model's (`--rtl`). Needs Verilator, which
//! `make test` installs; a missing tool is a failure, not a skip.

use super::helpers::{run, tempdir};

fn metrics(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap()
}

#[test]
fn sphere_through_the_rtl_equals_the_model() {
    for flags in [
        &[][..],
        &["--no-compensation", "--no-interpolation"][..],
        &["--index-bits", "5", "--map-bits", "10"][..],
    ] {
        let t = tempdir();
        let out = t.path().join("sphere");
        let mut args = vec![
            "render",
            "--rtl",
            "--size",
            "96",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(flags);
        let o = run(&args);
        assert!(
            o.status.success(),
            "{flags:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let m = metrics(&out);
        assert_eq!(m["rtl_equals_model"], true, "{flags:?}");
        assert_eq!(m["rtl_mismatches"], 0);
        assert!(out.join("rtl.png").is_file());
        assert_eq!(
            std::fs::read(out.join("rtl.png")).unwrap(),
            std::fs::read(out.join("model.png")).unwrap()
        );
    }
}

#[test]
fn volume_through_the_rtl_equals_the_model() {
    let t = tempdir();
    let out = t.path().join("vol");
    let o = run(&[
        "volume",
        "--synthetic",
        "--dims",
        "64,64,32",
        "--size",
        "96",
        "--rtl",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(metrics(&out)["rtl_equals_model"], true);
    assert_eq!(
        std::fs::read(out.join("rtl.png")).unwrap(),
        std::fs::read(out.join("model.png")).unwrap()
    );
}
