//! Every command that takes a generated design, on small designs built with each option that
//! changes what a design is (issue 32 §2): a prefix, lanes, the AXI4-Stream top (with a
//! prefix), colour, ECP5 memories, inferred multipliers and a non-default width. Each command (lint, synth, roms
//! --update, vectors --maps, sim, fpga --dir, prove) reads the design (its manifest) and either
//! does its job right or refuses in one line (exit 2); none reports success on a wrong result
//! or fails a correct design.

use crate::hdl::require;
use crate::helpers::{self, run_in, tempdir, text, tree};
use std::process::Output;

fn ok(what: &str, o: &Output) -> String {
    let t = text(o);
    assert_eq!(o.status.code(), Some(0), "{what}: {t}");
    t
}

/// What a variant's design is checked with beyond the common commands.
#[derive(Clone, Copy, PartialEq)]
enum Prove {
    /// The structure part only (Yosys; no Verilator build).
    Structure,
    /// The whole factored proof.
    Whole,
    /// Refused: the design has lanes.
    Refused,
}

fn check(flags: &[&str], prove: Prove) {
    if !require("iverilog") || !require("verilator") || !require("yosys") {
        return;
    }
    let t = tempdir();
    let p = t.path();
    let mut args = vec!["generate", "--vectors", "50", "--out", "d"];
    args.extend(flags);
    ok("generate", &run_in(p, &args));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p.join("d/manifest.json")).unwrap()).unwrap();
    let top = manifest["top"].as_str().unwrap().to_string();
    let prefix = manifest["config"]["prefix"]
        .as_str()
        .unwrap_or("")
        .to_string();
    let rmap_top = format!("{prefix}rmap_top");

    assert!(ok("lint", &run_in(p, &["lint", "d"])).contains("is clean"));
    let said = ok("synth", &run_in(p, &["synth", "d", "--logs", "s"]));
    assert!(
        said.contains(&format!("synth: {top} in d: no latches")),
        "{said}"
    );

    // roms --update with the design's own scene: the design is written again byte for byte.
    let before = tree(&p.join("d"));
    let said = ok("roms --update", &run_in(p, &["roms", "--update", "d"]));
    assert!(said.contains(": 0 files changed"), "{said}");
    assert_eq!(
        tree(&p.join("d")),
        before,
        "roms --update of the same scene"
    );

    // vectors --maps: the design's own top vectors, from its configuration and maps.
    ok(
        "vectors --maps",
        &run_in(
            p,
            &[
                "vectors", "--maps", "d", "--count", "50", "--seed", "1", "--out", "v.hex",
            ],
        ),
    );
    assert_eq!(
        std::fs::read(p.join("v.hex")).unwrap(),
        before[&format!("vectors/{rmap_top}.hex")],
        "vectors --maps equals the design's vectors"
    );

    // The design top's testbench (rmap_lanes's, rmap_axis's: every top has one) in Icarus.
    let tb_top = top.clone();
    let said = ok(
        "sim",
        &run_in(
            p,
            &["sim", "d", "--icarus", "--only", &tb_top, "--build", "b"],
        ),
    );
    assert!(
        said.contains(&format!("ok:   icarus {tb_top}_tb: ")),
        "{said}"
    );

    // fpga --dir, from the design's parent directory: placed on the iCE40 when the design has
    // block-RAM memories (an ECP5 design's DP16KD attributes are block RAM on the iCE40 too),
    // else refused in one line naming the target to generate. The ECP5 design also on the
    // ECP5, whose tools are the venv's, found from this directory too.
    let target = manifest["config"]["target"].as_str().unwrap_or("generic");
    let placed = run_in(p, &["fpga", "--dir", "d", "--logs", "f"]);
    if target == "generic" {
        helpers::assert_error(
            &placed,
            "the design was generated for --target generic: generate it with --target ice40",
        );
    } else {
        let said = ok("fpga --dir", &placed);
        assert!(said.contains("fpga: timing "), "{said}");
        if crate::ecp5::ecp5_tools() {
            let said = ok(
                "fpga --family ecp5 --dir",
                &run_in(
                    p,
                    &["fpga", "--family", "ecp5", "--dir", "d", "--logs", "f5"],
                ),
            );
            assert!(said.contains("fpga: timing "), "{said}");
            assert!(said.contains("ECP5 85k CABGA381"), "{said}");
        }
    }

    match prove {
        Prove::Refused => {
            helpers::assert_error(
                &run_in(p, &["prove", "d", "--build", "pb"]),
                "rmapgen prove proves one rmap_top; this design has lanes = 2",
            );
            assert!(!p.join("pb").exists(), "a refused proof leaves nothing");
            helpers::assert_error(
                &run_in(p, &["sim", "d", "--stream", "100", "--build", "sb"]),
                "--stream drives one rmap_top through the C++ harness",
            );
        }
        Prove::Structure | Prove::Whole => {
            let mut args = vec!["prove", "d", "--build", "pb"];
            if prove == Prove::Structure {
                args.extend(["--part", "structure"]);
            }
            let said = ok("prove", &run_in(p, &args));
            assert!(said.contains("PASSED"), "{said}");
            assert_eq!(
                said.contains(&format!("  scope             {rmap_top} inside {top}")),
                top != rmap_top,
                "{said}"
            );
            // The wrapper is claimed only as checked by what checks it: its testbench, which
            // the sim above ran.
            assert_eq!(
                said.contains(&format!(
                    "its testbench tb/{top}_tb.v, run by `rmapgen sim`"
                )),
                top != rmap_top,
                "{said}"
            );
        }
    }
}

const SMALL: [&str; 4] = ["--grad-bits", "8", "--red-bits", "6"];

fn small(extra: &[&'static str]) -> Vec<&'static str> {
    let mut v = SMALL.to_vec();
    v.extend(extra);
    v
}

#[test]
fn a_prefixed_design() {
    check(&small(&["--prefix", "vr_"]), Prove::Whole);
}

#[test]
fn a_lanes_design() {
    check(&small(&["--lanes", "2"]), Prove::Refused);
}

/// Without tuser (`--axis-user 0`, the default) and with a prefix: the wrapper's testbench
/// names every module and file with it.
#[test]
fn an_axis_design() {
    check(
        &small(&["--axis", "--handshake", "--prefix", "ax_"]),
        Prove::Structure,
    );
}

#[test]
fn a_colour_design() {
    check(&small(&["--color"]), Prove::Structure);
}

#[test]
fn an_ecp5_design() {
    check(&small(&["--target", "ecp5"]), Prove::Structure);
}

#[test]
fn an_inferred_multiplier_design() {
    check(&small(&["--mult", "infer"]), Prove::Structure);
}

#[test]
fn a_design_of_another_width() {
    check(
        &["--grad-bits", "9", "--red-bits", "6", "--index-bits", "4"],
        Prove::Whole,
    );
}
