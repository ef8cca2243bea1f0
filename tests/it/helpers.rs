//! Small helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The built `rmapgen` binary, with its plain progress lines off (`RMAPGEN_PROGRESS=0`): on a
/// slow machine a long command would otherwise print one every 10 s, and the tests that count
/// the lines of an error or compare a command's output would depend on the machine's speed.
/// The tests of progress itself set the variable again.
pub fn rmapgen() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rmapgen"));
    c.env("RMAPGEN_PROGRESS", "0");
    c
}

/// Runs rmapgen with arguments and returns its output.
pub fn run(args: &[&str]) -> Output {
    rmapgen().args(args).output().expect("rmapgen runs")
}

/// Runs rmapgen with arguments in the working directory `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    rmapgen()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("rmapgen runs")
}

/// A run's standard output, then its standard error.
pub fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed default design (`rtl_out/`, `make golden`), for commands that take a design.
pub fn default_design() -> String {
    root()
        .join("rtl_out")
        .to_str()
        .expect("utf-8 path")
        .to_string()
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
    assert!(
        err.contains(needle),
        "stderr {err:?} should contain {needle:?}"
    );
}

/// The names in a directory, sorted; hidden ones too (stamps, staging directories, partial
/// files).
pub fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    v.sort();
    v
}

/// Whether a directory exists and has entries.
pub fn nonempty(p: &Path) -> bool {
    p.read_dir()
        .map(|mut d| d.next().is_some())
        .unwrap_or(false)
}

/// Every file under `dir`, by path relative to it ('/'-separated), with its bytes.
pub fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    fn walk(base: &Path, d: &Path, out: &mut std::collections::BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(d).unwrap_or_else(|e| panic!("cannot read {}: {e}", d.display()))
        {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                let rel = p.strip_prefix(base).expect("under base");
                let rel = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy())
                    .collect::<Vec<_>>()
                    .join("/");
                out.insert(rel, std::fs::read(&p).expect("readable"));
            }
        }
    }
    let mut out = std::collections::BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The first difference between two directory trees (a file missing on either side, or
/// different bytes, with the first differing line), or None when they are byte-identical.
pub fn first_difference(a: &Path, b: &Path) -> Option<String> {
    let (ta, tb) = (tree(a), tree(b));
    for (name, bytes) in &ta {
        match tb.get(name) {
            None => {
                return Some(format!(
                    "{name} is in {} but not in {}",
                    a.display(),
                    b.display()
                ))
            }
            Some(other) if other != bytes => {
                let (la, lb) = (
                    String::from_utf8_lossy(bytes),
                    String::from_utf8_lossy(other),
                );
                let line = la
                    .lines()
                    .zip(lb.lines())
                    .position(|(x, y)| x != y)
                    .map(|i| i + 1);
                return Some(match line {
                    Some(n) => format!(
                        "{name} differs at line {n}: {:?} vs {:?}",
                        la.lines().nth(n - 1).unwrap_or(""),
                        lb.lines().nth(n - 1).unwrap_or("")
                    ),
                    None => format!(
                        "{name} differs in length ({} vs {} bytes)",
                        bytes.len(),
                        other.len()
                    ),
                });
            }
            Some(_) => {}
        }
    }
    tb.keys()
        .find(|name| !ta.contains_key(*name))
        .map(|name| format!("{name} is in {} but not in {}", b.display(), a.display()))
}

/// rmapgen run with `args` under a pseudo-terminal (util-linux's `script`), as a user at a
/// terminal runs it: what the terminal showed (stdout and stderr together) and whether it
/// succeeded. `None` without `script`.
pub fn on_a_terminal(args: &[&str]) -> Option<(bool, String)> {
    if !rmapgen::toolchain::installed("script") {
        return None;
    }
    let mut command = env!("CARGO_BIN_EXE_rmapgen").to_string();
    for a in args {
        command.push(' ');
        command.push_str(a);
    }
    let o = std::process::Command::new("script")
        .args(["-qec", &command, "/dev/null"])
        .output()
        .expect("script runs");
    Some((
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    ))
}
