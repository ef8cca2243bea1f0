//! The parameter grid (`rmapgen::grid`, src/grid.rs): every configuration there is generated
//! and checked end to end — Verilator's `--lint-only -Wall` prints nothing, Yosys synthesises it
//! without a latch and with every memory of the manifest inferred as a memory (`rmapgen synth
//! --generic`), and the Verilated top testbench agrees with the model exactly on its corner and
//! random vectors plus a stream of [`STREAM`] random ones. Rows marked `icarus` also run every
//! stage's testbench and the top's under Icarus Verilog.
//!
//! `grid_covers_every_range_end_and_switch` holds the rows to the coverage they claim. Each row
//! is its own test, so cargo runs them side by side (`every_row_has_a_test` keeps the list of
//! tests below equal to the grid's rows); one Verilator model is built per row and all its
//! vectors go through it.

use crate::hdl::{self, require};
use crate::helpers;
use rmapgen::config::{CompTable, Mult, Target, PIPELINE_DEPTHS, RANGES};
use rmapgen::family::Family;
use rmapgen::grid::{self, GridRow};
use std::path::Path;

/// Random top-level vectors streamed through each row's Verilated testbench, besides the
/// testbench's own corner and random vectors.
const STREAM: usize = 50_000;
/// Seeded random vectors per stage in each row's generated vector files.
const VECTORS: usize = 500;

macro_rules! tests {
    ($($name:ident),* $(,)?) => {
        /// The rows with a test below.
        const TESTED: &[&str] = &[$(stringify!($name)),*];
        $(
            #[test]
            fn $name() {
                check(stringify!($name));
            }
        )*
    };
}

tests! {
    paper, paper_depth0, paper_depth1, paper_hs, color, no_comp, no_interp, bare, no_comp_color,
    no_interp_color, bare_color, narrowest, narrowest_bare, widest, widest_depth0, grad16_red6,
    grad8_red8, no_truncation, frac4_recip20, frac12_recip13, index6_interp1, index2_interp5,
    map12, map6_nearest, index6_nearest, axis_color, axis_table_narrow, lanes2, lanes2_hs, lanes4, lanes4_hs,
    lanes2_hs_ecp5, lanes4_gowin,
    paper_infer, color_infer, hs_infer, widest_infer, table_ram, table_ram_narrow,
    table_ram_lanes2_hs,
}

#[test]
fn every_row_has_a_test() {
    let rows: Vec<&str> = grid::rows().iter().map(|r| r.name).collect();
    assert_eq!(TESTED, rows, "tests! above must list the grid's rows");
}

fn row(name: &str) -> GridRow {
    grid::row(name).expect("a row of the grid")
}

fn check(name: &str) {
    let r = row(name);
    r.config
        .validate()
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    if !require("verilator") || !require("yosys") || (r.icarus && !require("iverilog")) {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join(name);
    hdl::generate_config(&dir, &r.config, VECTORS);

    // The design's top, whose testbench reads the top's vectors: rmap_lanes with lanes (every
    // lane an rmap_top), rmap_axis with axis (each sample a beat, packed into tdata), else
    // rmap_top.
    let top = rmapgen::stages::top(&r.config);
    let checked = top.module(&r.config);
    hdl::assert_lint_clean_top(name, &dir, &top.module(&r.config));
    synthesise(name, &dir, &tmp.path().join("synth"));

    // Exact agreement in Verilator: the testbench's own vectors, then a long random stream.
    let sim = hdl::verilator(&dir, &checked, tmp.path());
    let n = hdl::vector_count(&dir, "rmap_top");
    hdl::assert_passed(name, &hdl::sim(&dir, &sim, hdl::NO_ARGS), n);
    let stream = tmp.path().join("stream.hex");
    let n = hdl::stream(&dir, STREAM, &stream);
    let arg = [format!("+vectors={}", stream.display())];
    hdl::assert_passed(name, &hdl::sim(&dir, &sim, &arg), n);

    if r.icarus {
        let tbs = hdl::testbenches(&dir);
        assert!(tbs.len() >= 6, "{name}: {tbs:?}");
        for m in &tbs {
            let bin = hdl::icarus(&dir, m, tmp.path());
            let what = format!("{name}: icarus {m}");
            // rmap_lanes' and rmap_axis' testbenches read the top's vectors.
            let vectors = if *m == checked {
                "rmap_top"
            } else {
                m.as_str()
            };
            hdl::assert_passed(
                &what,
                &hdl::vvp(&dir, &bin, hdl::NO_ARGS),
                hdl::vector_count(&dir, vectors),
            );
        }
    }
}

/// Generic Yosys synthesis: no latch, and exactly the manifest's memories inferred.
fn synthesise(name: &str, dir: &Path, logs: &Path) {
    let o = helpers::run(&[
        "synth",
        "--generic",
        dir.to_str().unwrap(),
        "--logs",
        logs.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{name}: synth failed:\n{said}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let memories = rmapgen::emit::manifest::memories(&hdl::config_of(dir)).len();
    let verdict = said.lines().last().unwrap_or("");
    assert!(
        verdict.contains("no latches") && verdict.ends_with(&format!(" in {memories} memories")),
        "{name}: {verdict} (the manifest has {memories} memories)"
    );
}

#[test]
fn grid_covers_every_range_end_and_switch() {
    let rows = grid::rows();
    assert!(rows.len() >= 20, "{} rows", rows.len());
    for r in &rows {
        r.config
            .validate()
            .unwrap_or_else(|e| panic!("{}: {e}", r.name));
    }
    for (i, a) in rows.iter().enumerate() {
        for b in &rows[i + 1..] {
            assert_ne!(a.config, b.config, "{} and {} are the same", a.name, b.name);
        }
    }
    for &(field, min, max) in RANGES {
        // The smallest reciprocal width the constraint allows: frac_bits + 1.
        let min = if field == "recip_bits" {
            min.max(RANGES.iter().find(|r| r.0 == "frac_bits").unwrap().1 + 1)
        } else {
            min
        };
        for end in [min, max] {
            assert!(
                rows.iter().any(|r| r.config.field(field) == end),
                "no row has {field} = {end}"
            );
        }
    }
    for comp in [false, true] {
        for interp in [false, true] {
            for color in [false, true] {
                assert!(
                    rows.iter().any(|r| r.config.compensation == comp
                        && r.config.interpolation == interp
                        && r.config.color == color),
                    "no row with compensation {comp}, interpolation {interp}, colour {color}"
                );
            }
        }
    }
    for depth in PIPELINE_DEPTHS.0..=PIPELINE_DEPTHS.1 {
        for hs in [false, true] {
            assert!(
                rows.iter()
                    .any(|r| r.config.pipeline_depth == depth && r.config.handshake == hs),
                "no row with pipeline depth {depth} and handshake {hs}"
            );
        }
    }
    // Both memory targets, each with and without the compensation ROM (whose read ports are
    // what differs most between them).
    for target in [Target::Generic, Target::Family(Family::Ice40)] {
        for comp in [false, true] {
            assert!(
                rows.iter()
                    .any(|r| r.config.target == target && r.config.compensation == comp),
                "no row with target {target:?} and compensation {comp}"
            );
        }
    }
    // Lanes sharing a reciprocal ROM (every target but ice40) and lanes with their own (ice40),
    // 2 and 4 lanes, with and without the handshake; the ecp5 target among them.
    for l in [2, 4] {
        for hs in [false, true] {
            assert!(
                rows.iter().any(|r| r.config.lanes == l
                    && r.config.handshake == hs
                    && rmapgen::stages::recip_rom::dual(&r.config)),
                "no row with {l} lanes sharing a ROM and handshake {hs}"
            );
        }
    }
    assert!(rows
        .iter()
        .any(|r| r.config.lanes > 1 && r.config.target == Target::Family(Family::Ice40)));
    assert!(rows.iter().any(|r| r.config.lanes > 1
        && r.config.target == Target::Family(Family::Ecp5)
        && r.icarus));
    // Icarus runs a subset that still has every optional stage and both interfaces.
    let ic: Vec<&GridRow> = rows.iter().filter(|r| r.icarus).collect();
    assert!(ic.len() >= 5);
    assert!(ic.iter().any(|r| r.config.color) && ic.iter().any(|r| !r.config.compensation));
    assert!(ic.iter().any(|r| r.config.handshake) && ic.iter().any(|r| !r.config.interpolation));
    assert!(ic
        .iter()
        .any(|r| r.config.target == Target::Family(Family::Ice40)));
    assert!(ic.iter().any(|r| r.config.axis && r.config.axis_user > 0));
    // The AXI4-Stream top without tuser, and with the loaded compensation table.
    assert!(rows.iter().any(|r| r.config.axis
        && r.config.axis_user == 0
        && r.config.comp_table == CompTable::Ram));
    // Inferred multipliers (--mult infer): the paper's design, colour, the widest widths, the
    // handshake, every depth (each places the products' registers differently), in Icarus too.
    let inf: Vec<&GridRow> = rows
        .iter()
        .filter(|r| r.config.mult == Mult::Infer)
        .collect();
    assert!(inf.iter().any(|r| r.config
        == rmapgen::config::Config {
            mult: Mult::Infer,
            ..Default::default()
        }));
    assert!(inf.iter().any(|r| r.config.color) && inf.iter().any(|r| r.config.handshake));
    assert!(inf.iter().any(|r| !r.config.compensation) && inf.iter().any(|r| r.icarus));
    assert!(inf
        .iter()
        .any(|r| r.config.grad_bits == 16 && r.config.recip_bits == 20));
    for depth in PIPELINE_DEPTHS.0..=PIPELINE_DEPTHS.1 {
        assert!(
            inf.iter().any(|r| r.config.pipeline_depth == depth),
            "no row with --mult infer at depth {depth}"
        );
    }
    // The loaded compensation table (--comp-table ram): with and without the handshake, with
    // lanes, for every memory target, in Icarus too.
    let ram: Vec<&GridRow> = rows
        .iter()
        .filter(|r| r.config.comp_table == CompTable::Ram)
        .collect();
    assert!(ram.iter().any(|r| r.config.handshake) && ram.iter().any(|r| !r.config.handshake));
    assert!(ram.iter().any(|r| r.config.lanes > 1) && ram.iter().any(|r| r.icarus));
    for target in [
        Target::Generic,
        Target::Family(Family::Ice40),
        Target::Family(Family::Ecp5),
    ] {
        assert!(
            ram.iter().any(|r| r.config.target == target),
            "no row with the loaded table and target {target:?}"
        );
    }
    // Lanes: 2 and 4, each with and without the handshake.
    for lanes in [2, 4] {
        for hs in [false, true] {
            assert!(
                rows.iter()
                    .any(|r| r.config.lanes == lanes && r.config.handshake == hs),
                "no row with {lanes} lanes and handshake {hs}"
            );
        }
    }
}
