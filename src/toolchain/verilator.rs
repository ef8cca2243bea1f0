//! Verilator: lint, a self-checking testbench built into an executable (`--binary`), and the
//! design's top as a fast C++ model linked with a harness of our own (`--cc --exe`).

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `$finish` and `$stop` for the testbenches (tb/vl_user.cpp): silent `$finish`, so the
/// verdict stays the last line, and `$stop` (and `$fatal`) exiting 1 as vvp -N does.
const VL_USER: &str = include_str!("../../tb/vl_user.cpp");

/// `-GNAME="VALUE"`: a string parameter of the top module.
fn param(name: &str, value: &str) -> String {
    format!("-G{name}={}", super::quoted(value))
}

/// The executable [`binary`] builds in its Mdir.
pub const BINARY_EXE: &str = "sim";

/// `VERILATOR`, else `verilator`.
pub fn verilator() -> String {
    super::program("VERILATOR", "verilator")
}

/// `verilator --lint-only -Wall --top-module TOP FILES` from `dir`: every warning class on;
/// the design must make it print nothing.
pub fn lint(dir: &Path, top: &str, files: &[PathBuf]) -> Command {
    let mut c = Command::new(verilator());
    c.args(["--lint-only", "-Wall", "--top-module", top])
        .args(files)
        .current_dir(dir);
    c
}

/// A self-checking testbench (`top`, its file among `files`) as the executable
/// `MDIR/`[`BINARY_EXE`]: `verilator --binary -j JOBS --top-module TOP --Mdir MDIR -o sim
/// FILES MDIR/vl_user.cpp -CFLAGS -DVL_USER_FINISH -CFLAGS -DVL_USER_STOP`. Writes
/// vl_user.cpp into `mdir` (made if missing) first.
/// `strings` sets string parameters of the top (`-GNAME="VALUE"`, the file paths).
pub fn binary(
    top: &str,
    mdir: &Path,
    files: &[PathBuf],
    strings: &[(String, String)],
) -> Result<Command> {
    std::fs::create_dir_all(mdir).with_context(|| format!("cannot create {}", mdir.display()))?;
    let user = mdir.join("vl_user.cpp");
    std::fs::write(&user, VL_USER).with_context(|| format!("cannot write {}", user.display()))?;
    let mut c = Command::new(verilator());
    c.args([
        "--binary",
        "-j",
        &super::jobs().to_string(),
        "--top-module",
        top,
    ])
    .arg("--Mdir")
    .arg(mdir)
    .args(["-o", BINARY_EXE])
    .args(strings.iter().map(|(n, v)| param(n, v)))
    .args(files)
    .arg(&user)
    .args(["-CFLAGS", "-DVL_USER_FINISH", "-CFLAGS", "-DVL_USER_STOP"]);
    Ok(c)
}

/// The design's `top` as an optimised C++ model linked with the C++ `harness` (its `main`) into
/// `MDIR/EXE`: `verilator --cc --exe --build -j JOBS -O3 --x-assign fast --x-initial fast
/// --noassert --top-module TOP --Mdir MDIR -o EXE FILES HARNESS -CFLAGS "-O2 -IINCLUDE"`, where
/// `include` holds the headers the harness includes (the generated `tb/`).
pub fn harness(
    top: &str,
    mdir: &Path,
    exe: &str,
    files: &[PathBuf],
    harness: &Path,
    include: &Path,
    strings: &[(String, String)],
) -> Command {
    let mut c = Command::new(verilator());
    c.args(["--cc", "--exe", "--build", "-j", &super::jobs().to_string()])
        .args([
            "-O3",
            "--x-assign",
            "fast",
            "--x-initial",
            "fast",
            "--noassert",
        ])
        // The C++ harnesses include Vrmap_top.h whatever the design's prefix.
        .args(["--top-module", top, "--prefix", "Vrmap_top"])
        .arg("--Mdir")
        .arg(mdir)
        .args(["-o", exe])
        .args(strings.iter().map(|(n, v)| param(n, v)))
        .args(files)
        .arg(harness)
        .arg("-CFLAGS")
        .arg(format!("-O2 -I{}", include.display()));
    c
}

/// The module `top` linked with the C++ `harness` (no `main`: it exports C functions) into
/// the shared object `MDIR/LIB`, for a program to load: [`harness`]'s flags with `--prefix
/// PREFIX`, every object compiled `-fPIC -O3` and linked `-shared`.
///
/// `-O3` goes in through the Makefile's OPT_FAST, OPT_SLOW and OPT_GLOBAL, not CFLAGS: Verilator's
/// Makefile puts those (`-Os` by default) after CFLAGS on every compile line, so an `-O3` in
/// CFLAGS is overridden and the model and the harness are built `-Os` (the prove front ran
/// about 15% slower so, docs/VERIFICATION.md "Figures").
#[allow(clippy::too_many_arguments)]
pub fn shared(
    top: &str,
    prefix: &str,
    mdir: &Path,
    lib: &str,
    files: &[PathBuf],
    harness: &Path,
    include: &Path,
    strings: &[(String, String)],
) -> Command {
    let mut c = Command::new(verilator());
    c.args(["--cc", "--exe", "--build", "-j", &super::jobs().to_string()])
        .args([
            "-O3",
            "--x-assign",
            "fast",
            "--x-initial",
            "fast",
            "--noassert",
        ])
        .args(["--top-module", top, "--prefix", prefix])
        .arg("--Mdir")
        .arg(mdir)
        .args(["-o", lib])
        .args(strings.iter().map(|(n, v)| param(n, v)))
        .args(files)
        .arg(harness)
        .arg("-CFLAGS")
        .arg(format!("-fPIC -I{}", include.display()))
        .args(
            ["OPT_FAST", "OPT_SLOW", "OPT_GLOBAL"]
                .iter()
                .flat_map(|v| ["-MAKEFLAGS".to_string(), format!("{v}=-O3")]),
        )
        .args(["-LDFLAGS", "-shared"]);
    c
}
