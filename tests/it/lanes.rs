//! Issue 15 §1, lanes (`--lanes L`, src/stages/rmap_lanes): the lanes top's testbench passes
//! exactly under Icarus and Verilator, with and without the handshake, and it CAN fail: each
//! planted fault below (two lanes' outputs swapped in the packing, one lane's valid bit
//! dropped, one lane's copy of the maps never written, one lane that does not swap, lane 1
//! reading lane 0's address on the reciprocal ROM the two share) makes it fail with a line
//! that names the lane. The shared ROM (every target but ice40) is checked on generic and
//! ecp5 designs, the replicated one on an ice40 design. With one lane nothing changes: no rmap_lanes, the
//! TOML as before. The grid rows `lanes2*` and `lanes4*` (tests/it/grid.rs) add lint,
//! synthesis and a long stream in Verilator.
//!
//! The tools are required when CI=true; elsewhere a missing tool skips.

use crate::hdl::{self, last_line, require, vector_count};
use crate::helpers;
use std::path::Path;

/// Random vectors per stage: enough for every valid pattern of two lanes around the swap.
const VECTORS: usize = 300;

fn lanes_tb(dir: &Path, build: &Path) -> std::path::PathBuf {
    hdl::icarus(dir, "rmap_lanes", build)
}

/// Runs the lanes testbench under Icarus; (passed, the output).
fn run_icarus(dir: &Path, build: &Path) -> (bool, String) {
    let bin = lanes_tb(dir, build);
    let (code, out) = hdl::vvp(dir, &bin, hdl::NO_ARGS);
    let want = format!("{} passed, 0 failed", vector_count(dir, "rmap_top"));
    (code == Some(0) && last_line(&out) == want, out)
}

/// A copy of a generated directory (its files, tb/ and vectors/).
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// `text` with `from` replaced by `to` inside lane `k`'s instance only (exactly once).
fn in_lane(text: &str, k: u32, from: &str, to: &str) -> String {
    in_instance(text, &format!("u_lane{k}"), from, to)
}

/// `text` with `from` replaced by `to` inside instance `inst` only (exactly once).
fn in_instance(text: &str, inst_name: &str, from: &str, to: &str) -> String {
    let start = text
        .find(&format!(" {inst_name} ("))
        .unwrap_or_else(|| panic!("no {inst_name}"));
    let end = start + text[start..].find(");").expect("the instance ends");
    let inst = &text[start..end];
    assert_eq!(
        inst.matches(from).count(),
        1,
        "{from} in {inst_name}: {inst}"
    );
    format!(
        "{}{}{}",
        &text[..start],
        inst.replace(from, to),
        &text[end..]
    )
}

#[test]
fn one_lane_changes_nothing() {
    let cfg = rmapgen::config::Config {
        lanes: 1,
        ..Default::default()
    };
    assert_eq!(cfg, rmapgen::config::Config::default());
    let t = toml::to_string(&cfg).unwrap();
    assert!(!t.contains("lanes"), "{t}");
    assert_eq!(rmapgen::stages::top(&cfg).name(), "rmap_top");
    assert!(rmapgen::cmd::config_args::ConfigArgs::flags(&cfg).is_empty());
    // And --lanes 1 writes the default design byte for byte.
    let tmp = helpers::tempdir();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    hdl::generate(&a, &[], 20);
    hdl::generate(&b, &["--lanes", "1"], 20);
    assert_eq!(helpers::first_difference(&a, &b), None);
}

#[test]
fn the_lanes_testbench_passes_in_both_simulators_and_catches_planted_faults() {
    if !require("iverilog") || !require("verilator") {
        return;
    }
    // Lane 1's own valid bit: its valid_i without the handshake, its side_i with it.
    let valid_pin = "(valid_i[1])";
    for flags in [
        &["--lanes", "2"][..],
        &["--lanes", "2", "--handshake"][..],
        &["--lanes", "2", "--target", "ecp5"][..],
        &["--lanes", "2", "--handshake", "--target", "ice40"][..],
    ] {
        let shared = !flags.contains(&"ice40");
        let tmp = helpers::tempdir();
        let dir = tmp.path().join("d");
        hdl::generate(&dir, flags, VECTORS);
        assert!(dir.join("rmap_lanes.v").is_file());
        assert!(
            !dir.join("vectors/rmap_lanes.hex").exists(),
            "the top's vectors serve"
        );
        hdl::assert_lint_clean_top(&format!("{flags:?}"), &dir, "rmap_lanes");

        let (ok, out) = run_icarus(&dir, tmp.path());
        assert!(ok, "{flags:?} icarus: {out}");
        assert!(out.contains("swap with line"), "{out}");
        assert!(out.contains("reset mid-stream"), "{out}");
        let sim = hdl::verilator(&dir, "rmap_lanes", tmp.path());
        hdl::assert_passed(
            &format!("{flags:?} verilator"),
            &hdl::sim(&dir, &sim, hdl::NO_ARGS),
            vector_count(&dir, "rmap_top"),
        );

        let top = std::fs::read_to_string(dir.join("rmap_lanes.v")).unwrap();
        // Two lanes read one reciprocal ROM where the block RAM is true dual-port.
        assert_eq!(top.contains(" u_recip_rom0 ("), shared, "{flags:?}");
        assert_eq!(
            std::fs::read_to_string(dir.join("normalise.v"))
                .unwrap()
                .contains(" u_recip_rom ("),
            !shared,
            "{flags:?}"
        );
        let swapped = in_lane(&top, 0, "(i_o[7:0])", "(i_o[15:8])");
        let swapped = in_lane(&swapped, 1, "(i_o[15:8])", "(i_o[7:0])");
        let mut faults = vec![
            ("lanes 0 and 1 swapped in i_o", swapped, "MISMATCH lane"),
            (
                "lane 1's valid bit dropped",
                in_lane(&top, 1, valid_pin, "(1'b0)"),
                "valid_o is not the beat's valid_i",
            ),
            (
                "lane 1's maps never written",
                in_lane(&top, 1, "(wr_en_i)", "(1'b0)"),
                "MISMATCH lane 1",
            ),
            (
                "lane 1 never swaps",
                in_lane(&top, 1, "(swap_i)", "(1'b0)"),
                "MISMATCH lane 1",
            ),
        ];
        if shared {
            // Port b of the shared ROM (lane 1's) reads lane 0's address: lane 1 gets lane 0's
            // reciprocal.
            faults.push((
                "lane 1 reads lane 0's address on the shared reciprocal ROM",
                in_instance(
                    &top,
                    "u_recip_rom0",
                    "(recip_addr[13:7])",
                    "(recip_addr[6:0])",
                ),
                "MISMATCH lane 1",
            ));
        }
        for (what, text, says) in faults {
            let bad = tmp.path().join("bad");
            let _ = std::fs::remove_dir_all(&bad);
            copy_dir(&dir, &bad);
            std::fs::write(bad.join("rmap_lanes.v"), text).unwrap();
            let build = tmp.path().join("bad_build");
            std::fs::create_dir_all(&build).unwrap();
            let (ok, out) = run_icarus(&bad, &build);
            assert!(!ok, "{flags:?}: {what} was not caught: {out}");
            assert!(
                out.contains(says),
                "{flags:?}: {what}: no {says:?} in {out}"
            );
        }
    }
}
