//! Icarus Verilog: `iverilog` compiles a testbench and the design into a vvp program, `vvp`
//! runs it.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The compiler: `IVERILOG`, else `iverilog`.
pub fn iverilog() -> String {
    super::program("IVERILOG", "iverilog")
}

/// The runtime: `VVP`, else `vvp`.
pub fn vvp() -> String {
    super::program("VVP", "vvp")
}

/// `iverilog -g2005 -Wall -Wno-timescale -s TOP -PTOP.NAME="VALUE"... -o OUT FILES`:
/// Verilog-2005 with every warning (the generated design compiles silently); `-Wno-timescale`
/// because the testbenches carry a `` `timescale `` and the design files do not. `strings`
/// sets string parameters of the top (the file paths).
pub fn compile(top: &str, out: &Path, files: &[PathBuf], strings: &[(String, String)]) -> Command {
    let mut c = Command::new(iverilog());
    c.args(["-g2005", "-Wall", "-Wno-timescale", "-s", top]);
    for (name, value) in strings {
        c.arg(format!("-P{top}.{name}={}", super::quoted(value)));
    }
    c.arg("-o").arg(out).args(files);
    c
}

/// `vvp -N PROGRAM PLUSARGS` run from `dir`. `-N` makes `$stop` exit 1 (`-n` would exit 0).
pub fn simulate(dir: &Path, program: &Path, plusargs: &[String]) -> Command {
    let mut c = Command::new(vvp());
    c.arg("-N").arg(program).args(plusargs).current_dir(dir);
    c
}
