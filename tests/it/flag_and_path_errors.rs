//! Issue 32 §6: one line that names the flag, or the path.
//!
//! - A value starting with '-' (a negative number inside a range, a shard, a list) reaches
//!   the flag's own parser, which names the flag, instead of clap's `unexpected argument
//!   '-1' found`.
//! - A write that fails names the path the user gave (a bare `Read-only file system (os
//!   error 30)` names nothing), and fails before the command's work.
//! - A failure that names a log names it where it is after the command ends, not in the
//!   staging directory that is gone.

use crate::hdl::require;
use crate::helpers::{self, assert_error, run, tempdir};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The narrowest design (grad-bits 8), generated into `dir` with `extra` flags.
fn narrow(dir: &Path, extra: &[&str]) {
    let flags = crate::hdl::narrowest_flags();
    let mut args = vec!["generate", "--vectors", "10", "--out", s(dir)];
    args.extend(crate::hdl::strs(&flags));
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn values_starting_with_a_minus_name_their_flag() {
    let t = tempdir();
    let d = t.path().join("d");
    narrow(&d, &[]);
    let out = t.path().join("o");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "volume",
                "--synthetic",
                "--crop",
                "-1:5,0:3,0:3",
                "--out",
                s(&out),
            ],
            "--crop -1:5,0:3,0:3: '-1:5' is not first:last (voxel indices >= 0)",
        ),
        (
            vec![
                "volume",
                "--synthetic",
                "--crop",
                "0:5,-2:3,0:3",
                "--out",
                s(&out),
            ],
            "--crop 0:5,-2:3,0:3: '-2:3' is not first:last",
        ),
        (
            vec!["prove", s(&d), "--shard", "-1/2"],
            "--shard -1/2: K is not a whole number",
        ),
        (
            vec!["prove", s(&d), "--shard", "1/-2"],
            "--shard 1/-2: N is not a whole number",
        ),
        (
            vec!["bench", "--lanes", "-1,2", "--out", s(&out)],
            "--lanes must be in 1..=8, not -1",
        ),
        (
            vec!["mutants", s(&d), "--only", "-3,4"],
            "--only -3: not a mutant number (m29 or 29)",
        ),
        (
            vec!["generate", "--grad-bits", "-1/2", "--out", s(&out)],
            "--grad-bits must be in 8..=16, not '-1/2'",
        ),
        (
            vec!["fpga", "--freq", "-5MHz", "--logs", s(&out)],
            "--freq must be a positive number, not -5MHz",
        ),
        // A flag of several values keeps them all (a negative number among them too).
        (
            vec!["prove", "--merge", "-1", "x.json"],
            "cannot read -1: No such file",
        ),
    ];
    for (args, want) in cases {
        let o = run(&args);
        assert_error(&o, want);
        assert!(
            !String::from_utf8_lossy(&o.stderr).contains("unexpected argument"),
            "{args:?}"
        );
    }
    assert!(!out.exists());
}

/// Every command's output path, where nothing may be created (sysfs refuses new files even
/// to root): the error names the path given, at once, and nothing is left.
#[test]
fn an_unwritable_output_names_its_path() {
    let t = tempdir();
    let d = t.path().join("d");
    narrow(&d, &[]);
    let build = t.path().join("build");
    let cases: Vec<Vec<&str>> = vec![
        vec![
            "prove",
            s(&d),
            "--report",
            "/sys/rmapgen-r.json",
            "--build",
            s(&build),
        ],
        vec!["maps", s(&d), "--out", "/sys/rmapgen-m.hex"],
        vec!["vectors", "--count", "10", "--out", "/sys/rmapgen-v.hex"],
        vec!["stress", "--samples", "10", "--json", "/sys/rmapgen-s.json"],
        vec!["generate", "--out", "/sys/rmapgen-g"],
        vec!["render", "--size", "16", "--out", "/sys/rmapgen-r"],
        vec!["fpga", "--dir", s(&d), "--logs", "/sys/rmapgen-f"],
        vec!["synth", s(&d), "--logs", "/sys/rmapgen-s"],
        vec!["prove-mult", s(&d), "--logs", "/sys/rmapgen-p"],
    ];
    for args in cases {
        let path = args
            .iter()
            .find(|a| a.starts_with("/sys/"))
            .expect("a path under /sys");
        let started = std::time::Instant::now();
        let o = run(&args);
        assert_error(&o, path);
        assert!(
            started.elapsed().as_secs() < 20,
            "{args:?}: refused before its work"
        );
    }
    assert!(!build.exists(), "prove's build directory was not started");
}

/// An output below a file, or below a symbolic link to nothing, names that path: `create_dir`
/// alone would say `Not a directory` or `File exists` and name nothing, and a link that
/// `exists()` does not see must not be taken for a directory someone else made.
#[test]
fn an_output_below_a_file_or_a_dangling_link_names_it() {
    let t = tempdir();
    let file = t.path().join("file");
    std::fs::write(&file, "mine\n").unwrap();
    let link = t.path().join("link");
    std::os::unix::fs::symlink(t.path().join("nowhere"), &link).unwrap();
    for blocker in [&file, &link] {
        for below in [blocker.clone(), blocker.join("sub")] {
            let (hex, dir) = (below.join("m.hex"), below.join("d"));
            for args in [
                ["maps", "--prefix", "p", "--out", s(&hex)],
                ["generate", "--prefix", "p", "--out", s(&dir)],
            ] {
                let o = run(&args);
                assert_error(&o, &format!("{} is not a directory", blocker.display()));
                assert_eq!(helpers::entries(t.path()), ["file", "link"], "{args:?}");
            }
        }
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"mine\n");
    // Any other failure to make a parent names the parent and the system's reason.
    for args in [
        ["maps", "--prefix", "p", "--out", "/sys/rmapgen-x/sub/m.hex"],
        ["generate", "--prefix", "p", "--out", "/sys/rmapgen-x/d"],
    ] {
        let o = run(&args);
        assert_error(&o, "/sys/rmapgen-x: Operation not permitted");
    }
}

/// `fpga` on a design whose memories fall back to logic (generated for --target generic)
/// fails naming the Yosys log: in the --logs directory, where it is after the command, not
/// in the staging directory beside it that is gone.
#[test]
fn a_failed_fpga_names_a_log_that_exists() {
    if !(require("yosys") && require("nextpnr-ice40")) {
        return;
    }
    let t = tempdir();
    let d = t.path().join("g");
    narrow(&d, &["--target", "generic"]);
    let logs = t.path().join("logs");
    let o = run(&["fpga", "--dir", s(&d), "--logs", s(&logs)]);
    assert_error(&o, "fell back to logic");
    let err = String::from_utf8_lossy(&o.stderr);
    let named = err
        .split("(log: ")
        .nth(1)
        .and_then(|r| r.split(')').next())
        .unwrap_or_else(|| panic!("no log named: {err}"));
    assert!(Path::new(named).is_file(), "{named} does not exist: {err}");
    assert_eq!(
        Path::new(named),
        logs.canonicalize().unwrap().join("yosys.log")
    );
    assert_eq!(helpers::entries(t.path()), ["g", "logs"]);
}

/// Every flag of every command that takes a value, given a value starting with '-' and a
/// digit that is no number (`-1/2,3`): the value reaches the flag (its error names the flag
/// or the value, or it is taken as the path it could be), never clap's `unexpected argument
/// '-1' found`. Flags are read from each command's --help; every run ends in `--help`, so
/// nothing runs, in a fresh directory that stays empty.
#[test]
fn every_value_flag_takes_a_value_starting_with_a_minus() {
    let t = tempdir();
    let commands = [
        "generate",
        "roms",
        "maps",
        "render",
        "vectors",
        "volume",
        "compare",
        "stress",
        "bench",
        "fpga",
        "fit",
        "sim",
        "synth",
        "prove-mult",
        "lint",
        "prove",
        "mutants",
    ];
    let mut checked = 0;
    for c in commands {
        let help = String::from_utf8(run(&[c, "--help"]).stdout).unwrap();
        let flags: Vec<&str> = help
            .lines()
            .filter_map(|l| {
                let l = l.trim_start();
                let l = l.strip_prefix("-h, ").unwrap_or(l);
                let (flag, rest) = l.split_once(' ')?;
                (flag.starts_with("--") && rest.starts_with('<')).then_some(flag)
            })
            .collect();
        for flag in flags {
            // `--help` with the value first: the value is parsed, nothing runs.
            let o = helpers::rmapgen()
                .current_dir(t.path())
                .args([c, flag, "-1/2,3", "--help"])
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(
                !err.contains("unexpected argument"),
                "{c} {flag} -1/2,3: {err}"
            );
            checked += 1;
        }
    }
    assert!(checked > 150, "only {checked} flags found in the help");
    assert_eq!(helpers::entries(t.path()), Vec::<String>::new());
}

/// `fpga --dir` of something that is no design is bad input: refused before the log
/// directory is made (it was left behind, empty).
#[test]
fn fpga_of_no_design_writes_nothing() {
    let t = tempdir();
    let logs = t.path().join("build").join("fpga");
    let missing = t.path().join("missing");
    let o = run(&["fpga", "--dir", s(&missing), "--logs", s(&logs)]);
    assert_error(&o, &format!("no manifest.json in {}", missing.display()));
    assert_eq!(helpers::entries(t.path()), Vec::<String>::new());
}
