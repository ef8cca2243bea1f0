//! The map flags (`cmd::map_args::MapArgs`: `--scene`, `--map-fit`) on every command that
//! builds maps: each takes `--map-fit` and its output follows it, and a bad value is one
//! line and exit 2 on every one.

use super::helpers;
use std::path::Path;

/// Each command that builds maps: its arguments before `--out`, whether `--out` names a file
/// (else a directory), and the output file that holds (or reports) its maps.
fn commands<'a>(scene: &'a str, design: &'a str) -> Vec<(Vec<&'a str>, &'static str)> {
    vec![
        (vec!["generate", "--vectors", "0"], "map_x.hex"),
        (vec!["roms"], "map_y.hex"),
        (vec!["render", "--size", "32"], "model.png"),
        (
            vec![
                "volume",
                "--synthetic",
                "--dims",
                "32,32,16",
                "--size",
                "32",
            ],
            "model.png",
        ),
        (
            vec![
                "bench",
                "--quick",
                "--no-yosys",
                "--size",
                "16",
                "--seconds",
                "0.001",
                "--scene",
                scene,
            ],
            "bench.csv",
        ),
        (
            vec![
                "fit",
                "--scene",
                scene,
                "--max-error",
                "255",
                "--size",
                "16",
                "--vectors",
                "0",
            ],
            "map_z.hex",
        ),
        (vec!["vectors", "--count", "200"], ""),
        (vec!["maps", design], ""),
        (vec!["stress", "--samples", "500"], ""),
    ]
}

/// The flag that names a command's output.
fn out_flag(command: &str) -> &'static str {
    if command == "stress" {
        "--json"
    } else {
        "--out"
    }
}

fn output(o: &std::process::Output, out: &Path, file: &str) -> Vec<u8> {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let p = if file.is_empty() {
        out.to_path_buf()
    } else {
        out.join(file)
    };
    let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    if file == "bench.csv" {
        // The map fits measured (its other figures are timings).
        let text = String::from_utf8(bytes).unwrap();
        let fits: Vec<&str> = text
            .lines()
            .skip(1)
            .filter(|l| !l.contains("octahedral"))
            .map(|l| l.rsplit("\",").next().unwrap().split(',').next().unwrap())
            .collect();
        return fits.join(" ").into_bytes();
    }
    if file.is_empty() && out.to_string_lossy().ends_with(".json") {
        // stress's report: its maps' fit and its results, without the run time.
        let v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        return format!("{} {} {}", v["map_fit"], v["worst_error"], v["classes"]).into_bytes();
    }
    bytes
}

#[test]
fn every_command_that_builds_maps_follows_map_fit() {
    let t = helpers::tempdir();
    let scene = helpers::root().join("scenes/standard.toml");
    let scene = scene.to_str().unwrap();
    let design = helpers::default_design();
    for (k, (args, file)) in commands(scene, &design).into_iter().enumerate() {
        let name = if args[0] == "stress" { "r.json" } else { "o" };
        let (a, b) = (
            t.path().join(format!("{k}a{name}")),
            t.path().join(format!("{k}b{name}")),
        );
        let run = |extra: &[&str], out: &Path| {
            let mut v = args.clone();
            v.extend(extra);
            v.extend([out_flag(args[0]), out.to_str().unwrap()]);
            helpers::run(&v)
        };
        // The standard scene's map_fit is sample.
        let plain = output(&run(&[], &a), &a, file);
        let fitted = output(&run(&["--map-fit", "lsq"], &b), &b, file);
        assert_ne!(plain, fitted, "{}: --map-fit lsq changes nothing", args[0]);
        let again = output(&run(&["--map-fit", "sample", "--force"], &a), &a, file);
        if args[0] == "bench" {
            // bench measures both fits unless told one.
            assert_eq!(
                [plain, fitted, again].map(|b| String::from_utf8(b).unwrap()),
                ["sample lsq", "lsq", "sample"]
            );
        } else {
            assert_eq!(
                plain, again,
                "{}: --map-fit sample is the scene's own",
                args[0]
            );
        }
    }
}

#[test]
fn a_bad_map_fit_or_scene_is_one_line_on_every_command() {
    let t = helpers::tempdir();
    let scene = helpers::root().join("scenes/standard.toml");
    let scene = scene.to_str().unwrap();
    let out = t.path().join("out");
    let design = helpers::default_design();
    for (args, _) in commands(scene, &design) {
        let mut v = args.clone();
        v.extend([
            "--map-fit",
            "cubic",
            out_flag(args[0]),
            out.to_str().unwrap(),
        ]);
        helpers::assert_error(&helpers::run(&v), "invalid value 'cubic' for '--map-fit");
        // A fit of the compensation table, for a design whose table is a ROM (`fit` instead
        // searches the designs that load their table: tests/it/fit.rs).
        if args[0] != "fit" {
            let mut v = args.clone();
            v.extend([
                "--map-fit",
                "table",
                out_flag(args[0]),
                out.to_str().unwrap(),
            ]);
            helpers::assert_error(&helpers::run(&v), "map_fit table");
            assert!(!out.exists(), "{}", args[0]);
        }
        // A missing scene file, named.
        let mut v = Vec::new();
        let mut it = args.iter();
        while let Some(a) = it.next() {
            if *a == "--scene" {
                it.next();
            } else {
                v.push(*a);
            }
        }
        let o = out.to_str().unwrap();
        v.extend(["--scene", "/no/such/scene.toml", out_flag(args[0]), o]);
        helpers::assert_error(&helpers::run(&v), "/no/such/scene.toml");
        assert!(!out.exists(), "{}", args[0]);
    }
}
