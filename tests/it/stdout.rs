//! Standard output that cannot be written (issue 32 §5): a reader that closed the pipe ends
//! the command quietly with exit 0; a full device is one line naming standard output, exit 2.
//! Never a panic (exit 101), for every kind of command that prints.

use crate::helpers::{self, tempdir};
use image::{ImageBuffer, Luma};
use std::path::Path;
use std::process::{Output, Stdio};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs rmapgen with its standard output the write end of a pipe whose read end is already
/// closed: its first write fails with EPIPE, deterministically.
fn to_closed_pipe(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    helpers::rmapgen()
        .args(args)
        .stdout(Stdio::from(writer))
        .output()
        .expect("rmapgen runs")
}

/// Runs rmapgen with its standard output on /dev/full (every write fails with ENOSPC).
fn to_full_device(args: &[&str]) -> Output {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full (Linux)");
    helpers::rmapgen()
        .args(args)
        .stdout(Stdio::from(full))
        .output()
        .expect("rmapgen runs")
}

fn closed_pipe_is_quiet(args: &[&str]) {
    let out = to_closed_pipe(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?} to a closed pipe: {err}"
    );
    assert!(
        !err.contains("panicked") && !err.contains("error"),
        "{args:?} to a closed pipe should say nothing on stderr: {err}"
    );
}

fn full_device_is_one_line(args: &[&str]) {
    let out = to_full_device(args);
    helpers::assert_error(
        &out,
        "cannot write to standard output: No space left on device",
    );
}

/// Two small images that differ.
fn images(dir: &Path) -> (String, String) {
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    ImageBuffer::from_fn(8, 4, |x, _| Luma([x as u8]))
        .save(&a)
        .unwrap();
    ImageBuffer::from_fn(8, 4, |x, y| Luma([(x + y) as u8]))
        .save(&b)
        .unwrap();
    (s(&a).to_string(), s(&b).to_string())
}

#[test]
fn compare_to_a_closed_pipe_and_to_a_full_device() {
    let d = tempdir();
    let (a, b) = images(d.path());
    for json in [false, true] {
        let mut args = vec!["compare", &a, &b];
        if json {
            args.insert(1, "--json");
        }
        closed_pipe_is_quiet(&args);
        full_device_is_one_line(&args);
    }
}

#[test]
fn render_and_stress_to_a_closed_pipe_and_to_a_full_device() {
    let d = tempdir();
    let out = d.path().join("r");
    let render = ["render", "--size", "16", "--force", "--out", s(&out)];
    closed_pipe_is_quiet(&render);
    full_device_is_one_line(&render);
    let stress = ["stress", "--samples", "1000"];
    closed_pipe_is_quiet(&stress);
    full_device_is_one_line(&stress);
}

#[test]
fn help_to_a_closed_pipe_and_to_a_full_device_is_no_panic() {
    for args in [
        &["--help"][..],
        &["compare", "--help"][..],
        &["--version"][..],
    ] {
        for out in [to_closed_pipe(args), to_full_device(args)] {
            let err = String::from_utf8_lossy(&out.stderr);
            assert_ne!(out.status.code(), Some(101), "{args:?}: {err}");
            assert!(!err.contains("panicked"), "{args:?}: {err}");
        }
    }
}

#[test]
fn volume_and_lint_to_a_closed_pipe_and_to_a_full_device() {
    let d = tempdir();
    let v = d.path().join("v");
    let volume = [
        "volume",
        "--synthetic",
        "--dims",
        "16,16,16",
        "--size",
        "16",
        "--force",
        "--out",
        s(&v),
    ];
    closed_pipe_is_quiet(&volume);
    full_device_is_one_line(&volume);
    if !crate::hdl::require("verilator") {
        return;
    }
    let g = d.path().join("g");
    let flags = crate::hdl::narrowest_flags();
    let mut args = vec!["generate", "--vectors", "10", "--out", s(&g)];
    args.extend(crate::hdl::strs(&flags));
    assert!(helpers::run(&args).status.success());
    let lint = ["lint", s(&g)];
    closed_pipe_is_quiet(&lint);
    full_device_is_one_line(&lint);
}

/// Messages on standard error are best effort: a standard error on a full device is no
/// panic, and the command's result stands.
#[test]
fn a_full_standard_error_is_no_panic() {
    let d = tempdir();
    let g = d.path().join("g");
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full (Linux)");
    let o = helpers::rmapgen()
        .args(["generate", "--vectors", "10", "--out", s(&g)])
        .stderr(Stdio::from(full))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(helpers::nonempty(&g));
    // A failing command still fails with exit 2 (its one line lost).
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = helpers::rmapgen()
        .args(["generate", "--grad-bits", "99", "--out", s(&g)])
        .stderr(Stdio::from(full))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}
