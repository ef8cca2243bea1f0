//! Issue 60, the AXI4-Stream top (`--axis`, src/stages/rmap_axis): the wrapper users
//! instantiate has a testbench of its own (`tb/rmap_axis_tb.v`), and it CAN fail: each planted
//! fault below in the generated `rmap_axis.v` (two input fields swapped in `s_axis_tdata`, an
//! output padding bit set, `tuser` and `tlast` crossed, `m_axis_tready` ignored, `swap_i` never
//! passed on) makes it fail with the line that shows it; and `rmapgen mutants --truth wrapper`
//! draws Yosys mutants of the wrapper alone and judges the testbench against a miter of the
//! wiring. The grid rows `axis_color` and `axis_table_narrow` (tests/it/grid.rs) run the
//! testbench in Verilator on a long stream, `design_matrix::an_axis_design` through `rmapgen
//! sim` with a prefix.
//!
//! The tools are required when CI=true; elsewhere a missing tool skips.

use crate::hdl::{self, last_line, require, vector_count};
use crate::helpers::{self, text};
use std::path::Path;

/// A small AXI4-Stream design: 8-bit gradients (no input padding), colour, a 2-bit tuser.
const FLAGS: [&str; 9] = [
    "--grad-bits",
    "8",
    "--red-bits",
    "6",
    "--handshake",
    "--axis",
    "--axis-user",
    "2",
    "--color",
];

/// Runs the wrapper's testbench under Icarus; (passed, the output).
fn run_icarus(dir: &Path, build: &Path) -> (bool, String) {
    let bin = hdl::icarus(dir, "rmap_axis", build);
    let (code, out) = hdl::vvp(dir, &bin, hdl::NO_ARGS);
    let want = format!("{} passed, 0 failed", vector_count(dir, "rmap_top"));
    (code == Some(0) && last_line(&out) == want, out)
}

#[test]
fn the_wrappers_testbench_passes_and_fails_on_each_planted_fault() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &FLAGS, 100);
    let (ok, out) = run_icarus(&dir, tmp.path());
    assert!(ok, "the clean design: {out}");
    assert!(out.contains("swap with line"), "{out}");
    for (what, from, to, want) in [
        (
            "gx and gy swapped in s_axis_tdata",
            ".gx_i      (s_axis_tdata[7:0]),\n    .gy_i      (s_axis_tdata[15:8]),",
            ".gx_i      (s_axis_tdata[15:8]),\n    .gy_i      (s_axis_tdata[7:0]),",
            "MISMATCH line ",
        ),
        (
            "an output padding bit set",
            "assign m_axis_tdata[7:1] = 7'd0;",
            "assign m_axis_tdata[7:1] = 7'd2;",
            "MISMATCH line ",
        ),
        (
            "tuser and tlast crossed",
            ".side_o    ({m_axis_tuser, m_axis_tlast})",
            ".side_o    ({m_axis_tlast, m_axis_tuser})",
            "MISMATCH line ",
        ),
        (
            "m_axis_tready ignored",
            ".ready_i   (m_axis_tready),",
            ".ready_i   (1'b1),",
            "an m_axis signal changed while m_axis_tready was low",
        ),
        (
            "swap_i never passed on",
            ".swap_i    (swap_i),",
            ".swap_i    (1'b0),",
            "MISMATCH line ",
        ),
    ] {
        let bad = tmp.path().join("bad");
        hdl::copy_design(&dir, &bad);
        hdl::sabotage(&bad, "rmap_axis.v", from, to);
        let (ok, out) = run_icarus(&bad, tmp.path());
        assert!(!ok, "{what}: the testbench passed: {}", last_line(&out));
        assert!(out.contains(want), "{what}: no {want:?} in {out}");
    }
    // A mismatch prints the line's inputs, the expected and the got, field by field.
    let bad = tmp.path().join("bad");
    hdl::copy_design(&dir, &bad);
    hdl::sabotage(
        &bad,
        "rmap_axis.v",
        "assign m_axis_tdata[7:1] = 7'd0;",
        "assign m_axis_tdata[7:1] = 7'd2;",
    );
    let (_, out) = run_icarus(&bad, tmp.path());
    let at = out.find("MISMATCH line ").expect("a mismatch");
    let lines: Vec<&str> = out[at..].lines().take(3).collect();
    assert!(
        lines[0].contains(": in map=") && lines[0].contains(" gx=") && lines[0].contains(" tuser="),
        "{lines:?}"
    );
    assert!(lines[1].starts_with("  expected zero=") && lines[1].contains(" tlast="));
    assert!(lines[2].starts_with("  got      zero=") && lines[2].contains(" tdata="));
}

#[test]
fn wrapper_mutants_are_judged_by_its_testbench_against_the_wiring() {
    if !require("iverilog") || !require("vvp") || !require("yosys") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &FLAGS, 100);
    let build = tmp.path().join("mutants");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let o = helpers::run(&[
        "mutants",
        &s(&dir),
        "--truth",
        "wrapper",
        "--count",
        "6",
        "--build",
        &s(&build),
    ]);
    let said = text(&o);
    assert_eq!(o.status.code(), Some(0), "{said}");
    assert!(said.contains("ground truth the wiring miter"), "{said}");
    assert!(
        said.contains("wiring passed, wrapper passed: m0 the null mutant"),
        "{said}"
    );
    // Every mutant of the draw: each is a port bit of the top's instance in the wrapper, so
    // the wiring differs, and the testbench fails it.
    for k in 1..=6 {
        let line = said
            .lines()
            .find(|l| l.contains(&format!("[{k}/6]")))
            .unwrap_or_else(|| panic!("m{k}: {said}"));
        assert!(
            line.contains("wiring failed, wrapper failed: m")
                && line.contains("-module rmap_axis -cell u_rmap_top"),
            "{line}"
        );
    }
    assert!(said.contains("SOUND: 6 mutants"), "{said}");
    // The mutant's wrapper passes its file parameters down by name, as the generated one.
    let mutant = std::fs::read_dir(&build)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.is_dir())
        .expect("the work directory")
        .join("m1/design/rmap_axis.v");
    let v = std::fs::read_to_string(&mutant).unwrap();
    assert!(
        v.contains("parameter RECIP_ROM_FILE = \"recip_rom.hex\";")
            && v.contains(".RECIP_ROM_FILE(RECIP_ROM_FILE)"),
        "{v}"
    );

    // Refused in one line: a design without a wrapper, a selection, memories, another check.
    let plain = tmp.path().join("plain");
    hdl::generate(&plain, &["--grad-bits", "8", "--red-bits", "6"], 0);
    let run = |d: &Path, more: &[&str]| {
        let mut a = vec!["mutants", d.to_str().unwrap(), "--truth", "wrapper"];
        a.extend_from_slice(more);
        a.extend(["--build", "nowhere"]);
        helpers::run(&a)
    };
    helpers::assert_error(&run(&plain, &[]), "--truth wrapper: ");
    assert!(
        text(&run(&plain, &[])).contains("has no wrapper around rmap_top (its top is rmap_top)")
    );
    helpers::assert_error(
        &run(&dir, &["--select", "rmap_top"]),
        "--select rmap_top: under --truth wrapper the draw is of the wrapper alone",
    );
    helpers::assert_error(
        &run(&dir, &["--memories", "1"]),
        "--memories 1: under --truth wrapper the memories are the top's",
    );
    helpers::assert_error(
        &run(&dir, &["--method", "prove"]),
        "--method prove: judged against --truth direct or stream, not --truth wrapper",
    );
    helpers::assert_error(
        &helpers::run(&[
            "mutants",
            dir.to_str().unwrap(),
            "--method",
            "wrapper",
            "--build",
            "nowhere",
        ]),
        "--method wrapper: judged against --truth wrapper, not --truth direct",
    );
    assert!(!Path::new("nowhere").exists());
}
