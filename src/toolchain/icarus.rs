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
    iverilog_command(top, out, &[], strings, files)
}

/// The define that turns off the default values Yosys's iCE40 cell models give their inputs
/// (`input I0 = 1'b0`): a SystemVerilog form Icarus 11 rejects (a syntax error also with
/// -g2012). `-Wall` includes `-Wportbind`, which warns about an input left unconnected, and a
/// netlist of `synth_ice40` connects every one, so compiling it is silent.
pub const NO_ICE40_DEFAULTS: &str = "-DNO_ICE40_DEFAULT_ASSIGNMENTS";

/// [`compile`] of a testbench with a Yosys iCE40 netlist and the cell models
/// (`toolchain::yosys::ice40_cell_models`) in place of the design: `iverilog -g2005 -Wall
/// -Wno-timescale -DNO_ICE40_DEFAULT_ASSIGNMENTS -s TOP -o OUT TESTBENCH NETLIST CELLS`. None
/// of ICE40_HX, ICE40_LP, ICE40_U is defined, so the models' `specify` blocks are left out: a
/// zero-delay functional simulation (timing is nextpnr's, `rmapgen fpga`). The models' flip-flops
/// start at 0 (`initial Q = 0`, as the iCE40's do at configuration) and SB_RAM40_4K starts from
/// its INIT_0..INIT_F parameters and returns the old word when a port reads the address the
/// other writes in the same clock. `strings` sets the testbench's file parameters.
pub fn compile_gate(
    top: &str,
    out: &Path,
    testbench: &Path,
    netlist: &Path,
    cell_models: &Path,
    strings: &[(String, String)],
) -> Command {
    let files = [testbench, netlist, cell_models].map(Path::to_path_buf);
    iverilog_command(top, out, &[NO_ICE40_DEFAULTS], strings, &files)
}

fn iverilog_command(
    top: &str,
    out: &Path,
    defines: &[&str],
    strings: &[(String, String)],
    files: &[PathBuf],
) -> Command {
    let mut c = Command::new(iverilog());
    c.args(["-g2005", "-Wall", "-Wno-timescale"])
        .args(defines)
        .args(["-s", top]);
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
