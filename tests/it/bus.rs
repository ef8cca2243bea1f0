//! Issue 61, the bus slave (`--bus wishbone|axi4-lite`, src/stages/rmap_bus and rmap_regs): the
//! bus top's own testbench (`tb/rmap_bus_tb.v`: the register checks from the register map, the
//! second map loaded through the windows, the swap through CONTROL and STATUS, the top's vectors
//! compared exactly) passes in Icarus on both buses, and fails on each planted fault of the
//! register block and of the bus fronts with the line that shows it; the combinations the slave
//! does not take yet are refused in one line. The cocotb tests with the ecosystem's bus masters
//! and the register views' checks are `make bus-test` (tb/cocotb/run_bus.py,
//! tb/regs/check_regs.py).
//!
//! The tools are required when CI=true; elsewhere a missing tool skips.

use crate::hdl::{self, last_line, require, vector_count};
use crate::helpers::{self, tempdir};
use std::path::Path;

/// Runs the bus top's testbench under Icarus; (passed, the output).
fn run_icarus(dir: &Path, build: &Path) -> (bool, String) {
    let bin = hdl::icarus(dir, "rmap_bus", build);
    let (code, out) = hdl::vvp(dir, &bin, hdl::NO_ARGS);
    let want = format!("{} passed, 0 failed", vector_count(dir, "rmap_top"));
    (code == Some(0) && last_line(&out) == want, out)
}

/// A planted fault: the file, what it is, the text replaced, its replacement, and what the
/// testbench must print.
type Fault = (
    &'static str,
    &'static str,
    &'static str,
    &'static str,
    &'static str,
);

/// The register block's faults (both buses).
const REGS: [Fault; 5] = [
    (
        "rmap_regs.v",
        "the magic off by one",
        "{32'h524d4150}",
        "{32'h524d4151}",
        "REGISTER check 0: read word 0",
    ),
    (
        "rmap_regs.v",
        "a refused access not refused",
        "err_q    <= done && bad;",
        "err_q    <= 1'b0;",
        "REGISTER check",
    ),
    (
        "rmap_regs.v",
        "a map entry's low bit flipped",
        "wr_data_q <= wdata_i[5:0];",
        "wr_data_q <= wdata_i[5:0] ^ 6'd1;",
        "MISMATCH line ",
    ),
    (
        "rmap_regs.v",
        "the swap never",
        "wire swap     = pending_q && !in_frame_q && !wr_en_q;",
        "wire swap     = 1'b0;",
        "the swap did not happen",
    ),
    (
        "rmap_regs.v",
        "FRAMES not counting",
        "frames_q <= frames_q + 32'd1;",
        "frames_q <= frames_q;",
        "FRAMES is not 1 after the swap",
    ),
];

#[test]
fn the_bus_testbench_passes_and_fails_on_each_planted_fault() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let fronts: [(&str, Fault); 2] = [
        (
            "wishbone",
            (
                "rmap_bus.v",
                "an error answered as an ack",
                "assign wb_err_o = ack && err;",
                "assign wb_err_o = 1'b0;",
                "a bus access not answered",
            ),
        ),
        (
            "axi4-lite",
            (
                "rmap_bus.v",
                "SLVERR answered OKAY",
                "bresp_q <= err ? 2'b10 : 2'b00;",
                "bresp_q <= 2'b00;",
                "REGISTER check",
            ),
        ),
    ];
    for (bus, front) in fronts {
        let tmp = tempdir();
        let dir = tmp.path().join("d");
        // Narrow: 8-bit gradients, 6-bit map entries.
        hdl::generate(
            &dir,
            &[
                "--grad-bits",
                "8",
                "--red-bits",
                "6",
                "--map-bits",
                "6",
                "--bus",
                bus,
            ],
            100,
        );
        let (ok, out) = run_icarus(&dir, tmp.path());
        assert!(ok, "{bus}: the clean design: {out}");
        assert!(out.contains("swap with line"), "{out}");
        for (file, what, from, to, want) in REGS.into_iter().chain([front]) {
            let bad = tmp.path().join("bad");
            hdl::copy_design(&dir, &bad);
            hdl::sabotage(&bad, file, from, to);
            let (ok, out) = run_icarus(&bad, tmp.path());
            assert!(
                !ok,
                "{bus}, {what}: the testbench passed: {}",
                last_line(&out)
            );
            assert!(out.contains(want), "{bus}, {what}: no {want:?} in {out}");
        }
    }
}

#[test]
fn what_the_slave_does_not_take_is_refused_in_one_line() {
    let t = tempdir();
    let out = t.path().join("d");
    let o = |flags: &[&str]| {
        let mut a = vec!["generate", "--out", out.to_str().unwrap()];
        a.extend_from_slice(flags);
        helpers::run(&a)
    };
    helpers::assert_error(
        &o(&["--bus", "wishbone", "--lanes", "2"]),
        "bus = wishbone with lanes = 2: the bus slave is in front of one rmap_top so far",
    );
    helpers::assert_error(
        &o(&["--bus", "axi4-lite", "--handshake", "--axis"]),
        "bus = axi4-lite with axis",
    );
    helpers::assert_error(&o(&["--bus", "pci"]), "pci");
    assert!(!out.exists(), "a refused generate writes nothing");
}
