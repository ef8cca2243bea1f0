//! The parameter grid: every configuration below is generated and checked end to end —
//! Verilator's `--lint-only -Wall` prints nothing, Yosys synthesises it without a latch and
//! with every memory of the manifest inferred as a memory (`scripts/synth.sh --generic`), and
//! the Verilated top testbench agrees with the model exactly on its corner and random vectors
//! plus a stream of [`STREAM`] random ones. Rows marked `icarus` also run every stage's
//! testbench and the top's under Icarus Verilog.
//!
//! The rows are chosen for coverage, and `grid_covers_every_range_end_and_switch` holds them to
//! it: each width at both ends of its range (recip_bits at its smallest legal value,
//! frac_bits + 1), each of the eight combinations of compensation, interpolation and colour,
//! every pipeline depth, and the handshake on and off, mixed so that the ends meet each
//! other and the optional stages. Each row is its own test, so cargo runs them side by side;
//! one Verilator model is built per row and all its vectors go through it.

use crate::hdl::{self, require};
use crate::helpers;
use rmapgen::config::{Config, PIPELINE_DEPTHS, RANGES};
use std::path::Path;

/// Random top-level vectors streamed through each row's Verilated testbench, besides the
/// testbench's own corner and random vectors.
const STREAM: usize = 50_000;
/// Seeded random vectors per stage in each row's generated vector files.
const VECTORS: usize = 500;

struct Row {
    name: &'static str,
    cfg: Config,
    icarus: bool,
}

macro_rules! grid {
    ($( $name:ident: $g:literal $r:literal $w:literal $f:literal $i:literal $p:literal $m:literal
        $comp:literal $interp:literal $color:literal $depth:literal $hs:literal $icarus:literal; )*) => {
        fn rows() -> Vec<Row> {
            vec![$(Row {
                name: stringify!($name),
                cfg: Config {
                    grad_bits: $g, red_bits: $r, recip_bits: $w, frac_bits: $f,
                    index_bits: $i, interp_bits: $p, map_bits: $m,
                    compensation: $comp == 1, interpolation: $interp == 1, color: $color == 1,
                    pipeline_depth: $depth, handshake: $hs == 1,
                    prefix: String::new(),
                },
                icarus: $icarus == 1,
            }),*]
        }
        $(
            #[test]
            fn $name() {
                check(stringify!($name));
            }
        )*
    };
}

// G grad, R reduced, W reciprocal entry, F fraction, I index, P interpolation fraction, M map
// entry bits; comp(ensation), interp(olation), color, pipeline depth, handshake, run in Icarus.
grid! {
//                  G  R  W  F  I  P  M  comp interp color depth hs icarus
    paper:          12 8  10 8  3  3  8  1    1      0     2     0  1;
    paper_depth0:   12 8  10 8  3  3  8  1    1      0     0     0  1;
    paper_depth1:   12 8  10 8  3  3  8  1    1      0     1     0  0;
    paper_hs:       12 8  10 8  3  3  8  1    1      0     2     1  1;
    color:          12 8  10 8  3  3  8  1    1      1     2     0  0;
    no_comp:        12 8  10 8  3  3  8  0    1      0     2     0  0;
    no_interp:      12 8  10 8  3  0  8  1    0      0     1     0  0;
    bare:           12 8  10 8  3  0  8  0    0      0     0     0  1;
    no_comp_color:  12 8  10 8  3  3  8  0    1      1     1     1  0;
    no_interp_color:12 8  10 8  3  0  8  1    0      1     0     1  1;
    bare_color:     12 8  10 8  3  0  8  0    0      1     2     0  0;
    narrowest:       8 6   5 4  2  1  6  1    1      0     0     0  1;
    narrowest_bare:  8 6   5 4  2  0  6  0    0      1     2     1  0;
    widest:         16 12 20 12 6  5  12 1    1      1     2     1  0;
    widest_depth0:  16 12 13 12 6  5  12 0    1      0     0     0  0;
    grad16_red6:    16 6   9 8  3  3  8  1    1      0     1     0  1;
    grad8_red8:      8 8  10 8  3  3  8  1    1      0     2     0  0;
    frac4_recip20:  12 8  20 4  3  2  8  1    1      0     0     1  0;
    frac12_recip13: 12 12 13 12 4  4  10 1    1      0     1     0  0;
    index6_interp1: 12 8  10 8  6  1  8  1    1      0     2     0  0;
    index2_interp5: 12 8  10 8  2  5  8  1    1      1     1     0  1;
    map12:          12 8  10 8  3  3  12 1    1      0     2     0  0;
    map6_nearest:   12 8  10 8  4  0  6  1    0      0     2     0  0;
    index6_nearest: 14 10 12 10 6  0  10 0    0      0     1     1  0;
}

fn row(name: &str) -> Row {
    rows()
        .into_iter()
        .find(|r| r.name == name)
        .expect("a row of the grid")
}

/// `generate` flags for a configuration.
fn flags(c: &Config) -> Vec<String> {
    let mut f: Vec<String> = [
        ("--grad-bits", c.grad_bits),
        ("--red-bits", c.red_bits),
        ("--recip-bits", c.recip_bits),
        ("--frac-bits", c.frac_bits),
        ("--index-bits", c.index_bits),
        ("--interp-bits", c.interp_bits),
        ("--map-bits", c.map_bits),
        ("--pipeline-depth", c.pipeline_depth),
    ]
    .iter()
    .flat_map(|(k, v)| [k.to_string(), v.to_string()])
    .collect();
    for (on, flag) in [
        (!c.compensation, "--no-compensation"),
        (!c.interpolation, "--no-interpolation"),
        (c.color, "--color"),
        (c.handshake, "--handshake"),
    ] {
        if on {
            f.push(flag.into());
        }
    }
    f
}

fn check(name: &str) {
    let r = row(name);
    r.cfg.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    if !require("verilator") || !require("yosys") || (r.icarus && !require("iverilog")) {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join(name);
    let f = flags(&r.cfg);
    let f: Vec<&str> = f.iter().map(String::as_str).collect();
    hdl::generate(&dir, &f, VECTORS);
    assert_eq!(
        hdl::config_of(&dir),
        r.cfg,
        "{name}: the flags give the row"
    );

    hdl::assert_lint_clean(name, &dir);
    synthesise(name, &dir, &tmp.path().join("synth"));

    // Exact agreement in Verilator: the testbench's own vectors, then a long random stream.
    let sim = hdl::verilator(&dir, "rmap_top", tmp.path());
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
            hdl::assert_passed(
                &what,
                &hdl::vvp(&dir, &bin, hdl::NO_ARGS),
                hdl::vector_count(&dir, m),
            );
        }
    }
}

/// Generic Yosys synthesis: no latch, and exactly the manifest's memories inferred.
fn synthesise(name: &str, dir: &Path, logs: &Path) {
    let o = std::process::Command::new(helpers::root().join("scripts/synth.sh"))
        .arg("--generic")
        .arg(dir)
        .arg(logs)
        .output()
        .expect("scripts/synth.sh runs");
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{name}: synth failed:\n{said}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let memories = rmapgen::rtl::manifest::memories(&hdl::config_of(dir)).len();
    let verdict = said.lines().last().unwrap_or("");
    assert!(
        verdict.contains("no latches") && verdict.ends_with(&format!(" in {memories} memories")),
        "{name}: {verdict} (the manifest has {memories} memories)"
    );
}

#[test]
fn grid_covers_every_range_end_and_switch() {
    let rows = rows();
    assert!(rows.len() >= 20, "{} rows", rows.len());
    for r in &rows {
        r.cfg
            .validate()
            .unwrap_or_else(|e| panic!("{}: {e}", r.name));
    }
    for (i, a) in rows.iter().enumerate() {
        for b in &rows[i + 1..] {
            assert_ne!(a.cfg, b.cfg, "{} and {} are the same", a.name, b.name);
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
                rows.iter().any(|r| r.cfg.field(field) == end),
                "no row has {field} = {end}"
            );
        }
    }
    for comp in [false, true] {
        for interp in [false, true] {
            for color in [false, true] {
                assert!(
                    rows.iter().any(|r| r.cfg.compensation == comp
                        && r.cfg.interpolation == interp
                        && r.cfg.color == color),
                    "no row with compensation {comp}, interpolation {interp}, colour {color}"
                );
            }
        }
    }
    for depth in PIPELINE_DEPTHS.0..=PIPELINE_DEPTHS.1 {
        for hs in [false, true] {
            assert!(
                rows.iter()
                    .any(|r| r.cfg.pipeline_depth == depth && r.cfg.handshake == hs),
                "no row with pipeline depth {depth} and handshake {hs}"
            );
        }
    }
    // Icarus runs a subset that still has every optional stage and both interfaces.
    let ic: Vec<&Row> = rows.iter().filter(|r| r.icarus).collect();
    assert!(ic.len() >= 5);
    assert!(ic.iter().any(|r| r.cfg.color) && ic.iter().any(|r| !r.cfg.compensation));
    assert!(ic.iter().any(|r| r.cfg.handshake) && ic.iter().any(|r| !r.cfg.interpolation));
}
