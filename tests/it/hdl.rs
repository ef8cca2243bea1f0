//! Helpers for the tests that run the simulators, Verilator's lint and Yosys on generated
//! designs: generating a directory, compiling and running its testbenches, reading verdicts.
//! Every tool's command line comes from `rmapgen::toolchain`.
//!
//! The tools are required when CI=true (a missing tool fails the test there); elsewhere a
//! missing tool skips the test with a message on stderr.
#![allow(dead_code)]

use crate::helpers;
use rmapgen::cmd::config_args::ConfigArgs;
use rmapgen::config::Config;
use rmapgen::toolchain::{self, icarus, verilator};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `generate` flags for the narrowest widths every range allows, with interpolation
/// (`rmapgen::grid::narrowest`), and otherwise the defaults.
pub fn narrowest_flags() -> Vec<String> {
    ConfigArgs::flags(&rmapgen::grid::narrowest())
}

/// `flags` as the `&str`s [`generate`] takes.
pub fn strs(flags: &[String]) -> Vec<&str> {
    flags.iter().map(String::as_str).collect()
}

/// Whether `tool` is on PATH; panics when it is not and CI=true.
pub fn require(tool: &str) -> bool {
    let found = toolchain::installed(tool);
    if !found {
        if std::env::var("CI").map(|v| v == "true").unwrap_or(false) {
            panic!("{tool} is not installed and CI=true: run `make tools`");
        }
        eprintln!("skipping: {tool} is not installed (make tools)");
    }
    found
}

/// Generates a design into `dir` with `flags` and `vectors` seeded random vectors per stage
/// (after the corner cases).
pub fn generate(dir: &Path, flags: &[&str], vectors: usize) {
    let n = vectors.to_string();
    let mut args = vec![
        "generate",
        "--out",
        dir.to_str().expect("utf-8 path"),
        "--vectors",
        &n,
    ];
    args.extend_from_slice(flags);
    let o = helpers::run(&args);
    assert!(
        o.status.success(),
        "generate {flags:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Generates `cfg`'s design into `dir` (through the `generate` flags that give it), with
/// `vectors` random vectors per stage.
pub fn generate_config(dir: &Path, cfg: &Config, vectors: usize) {
    generate(dir, &strs(&ConfigArgs::flags(cfg)), vectors);
    assert_eq!(&config_of(dir), cfg, "the flags give the configuration");
}

/// The configuration a generated directory was made for, read back from its manifest.
pub fn config_of(dir: &Path) -> Config {
    let text = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest.json");
    let m: serde_json::Value = serde_json::from_str(&text).expect("manifest.json is JSON");
    serde_json::from_value(m["config"].clone()).expect("the manifest's config is a Config")
}

/// The design's .v files (testbenches live in tb/, not here), sorted.
pub fn design_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("output dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "v"))
        .collect();
    v.sort();
    v
}

/// The modules with a testbench in `dir/tb`, sorted.
pub fn testbenches(dir: &Path) -> Vec<String> {
    let mut tbs: Vec<String> = std::fs::read_dir(dir.join("tb"))
        .expect("tb/")
        .filter_map(|e| {
            e.expect("entry")
                .file_name()
                .to_str()?
                .strip_suffix("_tb.v")
                .map(String::from)
        })
        .collect();
    tbs.sort();
    tbs
}

/// Compiles `<dir>/tb/<module>_tb.v` with the design under Icarus into `build`; returns the
/// .vvp path.
pub fn icarus(dir: &Path, module: &str, build: &Path) -> PathBuf {
    let vvp = build.join(format!("{module}_tb.vvp"));
    let mut files = vec![dir.join(format!("tb/{module}_tb.v"))];
    files.extend(design_files(dir));
    let o = icarus::compile(&format!("{module}_tb"), &vvp, &files, &[])
        .output()
        .expect("iverilog runs");
    assert!(
        o.status.success(),
        "iverilog {module}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    vvp
}

/// Builds `<dir>/tb/<module>_tb.v` with the design under Verilator (`--binary`, the verdict
/// kept as the last line by tb/vl_user.cpp) in `build/<module>`; returns the executable.
pub fn verilator(dir: &Path, module: &str, build: &Path) -> PathBuf {
    let mdir = build.join(format!("verilator_{module}"));
    let mut files = vec![dir.join(format!("tb/{module}_tb.v"))];
    files.extend(design_files(dir));
    let o = verilator::binary(&format!("{module}_tb"), &mdir, &files, &[])
        .expect("the build directory is writable")
        .output()
        .expect("verilator runs");
    assert!(
        o.status.success(),
        "verilator {module}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    mdir.join(verilator::BINARY_EXE)
}

/// Runs a command from the generated directory: (exit code, stdout + stderr).
pub fn run_in(dir: &Path, mut cmd: Command) -> (Option<i32>, String) {
    let o = cmd.current_dir(dir).output().expect("simulation runs");
    let mut text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.push_str(&String::from_utf8_lossy(&o.stderr));
    (o.status.code(), text)
}

/// No plusargs, for [`vvp`] and [`sim`].
pub const NO_ARGS: &[&str] = &[];

/// Runs a compiled Icarus testbench from the generated directory.
pub fn vvp<S: AsRef<OsStr>>(dir: &Path, bin: &Path, args: &[S]) -> (Option<i32>, String) {
    let args: Vec<String> = args
        .iter()
        .map(|a| a.as_ref().to_string_lossy().into_owned())
        .collect();
    run_in(dir, icarus::simulate(dir, bin, &args))
}

/// Runs a Verilated testbench from the generated directory.
pub fn sim<S: AsRef<OsStr>>(dir: &Path, bin: &Path, args: &[S]) -> (Option<i32>, String) {
    let mut c = Command::new(bin);
    c.args(args);
    run_in(dir, c)
}

pub fn last_line(text: &str) -> &str {
    text.trim_end().lines().last().unwrap_or("")
}

/// Vectors in `dir/vectors/<module>.hex`.
pub fn vector_count(dir: &Path, module: &str) -> usize {
    std::fs::read_to_string(dir.join(format!("vectors/{module}.hex")))
        .expect("vector file")
        .lines()
        .count()
}

/// Asserts a run passed all `n` vectors: exit 0 and `n passed, 0 failed` as the last line.
pub fn assert_passed(what: &str, (code, out): &(Option<i32>, String), n: usize) {
    assert_eq!(
        (*code, last_line(out)),
        (Some(0), format!("{n} passed, 0 failed").as_str()),
        "{what}: {out}"
    );
}

/// `verilator --lint-only -Wall` over the design: it must exit 0 and print nothing.
pub fn assert_lint_clean(what: &str, dir: &Path) {
    assert_lint_clean_top(what, dir, "rmap_top")
}

/// `verilator --lint-only -Wall --top-module top` over every .v file of `dir`: it must exit 0
/// and print nothing.
pub fn assert_lint_clean_top(what: &str, dir: &Path, top: &str) {
    let o = verilator::lint(dir, top, &design_files(dir))
        .output()
        .expect("verilator runs");
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        o.status.success() && said.trim().is_empty(),
        "verilator -Wall on {what}:\n{said}"
    );
}

/// A long random top-level vector stream for the design in `dir` (`rmapgen vectors`, with
/// the directory's configuration and maps) into `file`; returns its line count.
pub fn stream(dir: &Path, count: usize, file: &Path) -> usize {
    let n = count.to_string();
    let o = helpers::run(&[
        "vectors",
        "--config",
        dir.join("tb/config.toml").to_str().unwrap(),
        "--maps",
        dir.to_str().unwrap(),
        "--count",
        &n,
        "--out",
        file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(file).unwrap().lines().count()
}

/// A copy of `dir` (its files, tb/ and vectors/) in `into`, for sabotage.
pub fn copy_design(dir: &Path, into: &Path) {
    let _ = std::fs::remove_dir_all(into);
    for sub in ["", "tb", "vectors"] {
        std::fs::create_dir_all(into.join(sub)).unwrap();
        for e in std::fs::read_dir(dir.join(sub)).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                std::fs::copy(&p, into.join(sub).join(p.file_name().unwrap())).unwrap();
            }
        }
    }
}

/// Replaces `from` by `to` in `dir/file` (which must contain it).
pub fn sabotage(dir: &Path, file: &str, from: &str, to: &str) {
    let p = dir.join(file);
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains(from), "{file} has no {from:?}");
    std::fs::write(&p, text.replace(from, to)).unwrap();
}
