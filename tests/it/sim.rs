//! The generated testbenches against the generated RTL: they pass on the model's vectors,
//! and they CAN fail: one corrupted expected value gives `N passed, 1 failed` as the last line
//! and a non-zero exit, a missing hex file is fatal, a wrong latency is caught.
//!
//! The simulators are required when CI=true (a missing tool fails the test there); elsewhere
//! a missing tool skips with a message on stderr.

use crate::hdl::{self, icarus as icarus_compile, last_line, require, run_in, vector_count, vvp};
use crate::helpers;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Generates a design into `dir` with `flags` and 300 random vectors per stage.
fn generate(dir: &Path, flags: &[&str]) {
    hdl::generate(dir, flags, 300)
}

/// A copy of a vector file with the last field (an expected output) of line `line` (1-based)
/// changed; returns the copy's path.
fn corrupt(dir: &Path, module: &str, line: usize, into: &Path) -> PathBuf {
    let text = std::fs::read_to_string(dir.join(format!("vectors/{module}.hex"))).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut f: Vec<String> = lines[line - 1].split(' ').map(String::from).collect();
    let last = f.last_mut().unwrap();
    let w = last.len();
    let v = u64::from_str_radix(last, 16).unwrap() ^ 1;
    *last = format!("{v:0w$x}");
    lines[line - 1] = f.join(" ");
    let p = into.join(format!("{module}_corrupt.hex"));
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
    p
}

#[test]
fn every_testbench_passes_under_icarus() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let narrowest = hdl::narrowest_flags();
    let configs: [&[&str]; 3] = [
        &[],
        &["--no-compensation", "--no-interpolation", "--color"],
        &hdl::strs(&narrowest),
    ];
    for flags in configs {
        let tmp = helpers::tempdir();
        let dir = tmp.path().join("d");
        generate(&dir, flags);
        let tbs = hdl::testbenches(&dir);
        assert!(
            tbs.contains(&"rmap_top".to_string()) && tbs.len() >= 7,
            "{tbs:?}"
        );
        for m in &tbs {
            let bin = icarus_compile(&dir, m, tmp.path());
            let (code, out) = vvp(&dir, &bin, hdl::NO_ARGS);
            let want = format!("{} passed, 0 failed", vector_count(&dir, m));
            assert_eq!(last_line(&out), want, "{flags:?} {m}: {out}");
            assert_eq!(code, Some(0), "{flags:?} {m}: {out}");
        }
    }
}

#[test]
fn a_corrupted_vector_fails_under_icarus() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    generate(&dir, &[]);
    for (m, line) in [
        ("rmap_top", vector_count(&dir, "rmap_top") - 5),
        ("sort_shift", 3),
        ("map_lookup", 400),
    ] {
        let bin = icarus_compile(&dir, m, tmp.path());
        let bad = corrupt(&dir, m, line, tmp.path());
        let (code, out) = vvp(&dir, &bin, &[&format!("+vectors={}", bad.display())]);
        let n = vector_count(&dir, m);
        assert_eq!(
            last_line(&out),
            format!("{} passed, 1 failed", n - 1),
            "{m}: {out}"
        );
        assert_eq!(code, Some(1), "{m}: {out}");
        assert!(
            out.contains(&format!("MISMATCH line {line}: in ")),
            "{m}: {out}"
        );
        assert!(
            out.contains("  expected ") && out.contains("  got      "),
            "{m}: {out}"
        );
    }
}

#[test]
fn a_missing_hex_file_is_fatal() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    generate(&dir, &[]);
    let bin = icarus_compile(&dir, "rmap_top", tmp.path());
    for f in [
        "map_bank_01.hex",
        "map2_y.hex",
        "recip_rom.hex",
        "atan_rom.hex",
        "vectors/rmap_top.hex",
    ] {
        let p = dir.join(f);
        let keep = tmp.path().join("kept");
        std::fs::rename(&p, &keep).unwrap();
        let (code, out) = vvp(&dir, &bin, hdl::NO_ARGS);
        std::fs::rename(&keep, &p).unwrap();
        assert_eq!(code, Some(1), "{f}: {out}");
        assert!(out.contains(&format!("cannot open {f}")), "{f}: {out}");
        assert!(!out.contains(" passed, 0 failed"), "{f}: {out}");
    }
}

#[test]
fn a_wrong_latency_or_a_short_map_is_caught() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    generate(&dir, &[]);
    // A testbench expecting one clock more than the design has: every vector fails.
    let tb = dir.join("tb/zero_detect_tb.v");
    let text = std::fs::read_to_string(&tb).unwrap();
    assert!(text.contains("localparam LATENCY    = 1;"));
    std::fs::write(
        &tb,
        text.replace("localparam LATENCY    = 1;", "localparam LATENCY    = 2;"),
    )
    .unwrap();
    let bin = icarus_compile(&dir, "zero_detect", tmp.path());
    let (code, out) = vvp(&dir, &bin, hdl::NO_ARGS);
    let n = vector_count(&dir, "zero_detect");
    // The run gives up after 100 failures rather than flood the log.
    assert!(n > 100);
    assert_eq!(last_line(&out), "0 passed, 100 failed", "{out}");
    assert!(out.contains("stopped after 100 failures"), "{out}");
    assert_eq!(code, Some(1));
    assert!(
        out.contains("LATENCY line 1: output after 1 enabled clocks, expected 2"),
        "{out}"
    );
    // A second map with an entry missing is fatal before any vector.
    let m2 = dir.join("map2_z.hex");
    let t = std::fs::read_to_string(&m2).unwrap();
    std::fs::write(&m2, &t[..t.trim_end().rfind('\n').unwrap() + 1]).unwrap();
    let bin = icarus_compile(&dir, "map_lookup", tmp.path());
    let (code, out) = vvp(&dir, &bin, hdl::NO_ARGS);
    assert_eq!(code, Some(1), "{out}");
    assert!(out.contains("map2_*.hex: entry"), "{out}");
}

#[test]
fn verilator_passes_and_fails_the_same_way() {
    if !require("verilator") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    generate(&dir, &["--color"]);
    let sim = hdl::verilator(&dir, "rmap_top", tmp.path());
    let n = vector_count(&dir, "rmap_top");
    let (code, out) = run_in(&dir, Command::new(&sim));
    assert_eq!(
        (code, last_line(&out)),
        (Some(0), format!("{n} passed, 0 failed").as_str()),
        "{out}"
    );
    let bad = corrupt(&dir, "rmap_top", 2, tmp.path());
    let mut c = Command::new(&sim);
    c.arg(format!("+vectors={}", bad.display()));
    let (code, out) = run_in(&dir, c);
    assert_eq!(
        (code, last_line(&out)),
        (Some(1), format!("{} passed, 1 failed", n - 1).as_str()),
        "{out}"
    );
}
