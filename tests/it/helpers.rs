//! Small helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The built `rmapgen` binary.
pub fn rmapgen() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rmapgen"))
}

/// Runs rmapgen with arguments and returns its output.
pub fn run(args: &[&str]) -> Output {
    rmapgen().args(args).output().expect("rmapgen runs")
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh temporary directory.
pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// Asserts a failed run: exit code 2, one line of stderr containing `needle`.
pub fn assert_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "exit code; stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(needle), "stderr {err:?} should contain {needle:?}");
}

/// Whether a directory exists and has entries.
pub fn nonempty(p: &Path) -> bool {
    p.read_dir().map(|mut d| d.next().is_some()).unwrap_or(false)
}
