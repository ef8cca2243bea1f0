//! `rmapgen prove` (src/prove/): the generated RTL of a design equals its model on every
//! gradient. A small design (G = 8: 2^24 gradients) is proven in two shards that merge into
//! one verdict; each part of the proof catches a fault planted in a copy of the design and
//! says where (the gradient, the module and field, or the netlist cell); every G = 8 row of
//! the grid is proven with every gradient through its top (`--direct`); bad input is one
//! line, exit 2.
//!
//! The tools (Verilator, Yosys) are required when CI=true; elsewhere a missing tool skips.

use crate::hdl::{self, require};
use crate::helpers;
use rmapgen::config::Config;
use rmapgen::grid;
use std::path::Path;
use std::process::Output;

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn tools() -> bool {
    require("verilator") && require("yosys")
}

/// Runs `rmapgen prove DIR ARGS` building under `build`.
fn prove(dir: &Path, build: &Path, args: &[&str]) -> Output {
    let mut a = vec!["prove", s(dir), "--build", s(build)];
    a.extend_from_slice(args);
    helpers::run(&a)
}

/// A copy of the design in `dir` with `old` replaced by `new` once in `file`.
fn plant(dir: &Path, to: &Path, file: &str, old: &str, new: &str) {
    copy_dir(dir, to);
    let p = to.join(file);
    let text = std::fs::read_to_string(&p).unwrap();
    assert_eq!(text.matches(old).count(), 1, "{old:?} once in {file}");
    std::fs::write(&p, text.replacen(old, new, 1)).unwrap();
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let t = to.join(e.file_name());
        if e.path().is_dir() {
            copy_dir(&e.path(), &t);
        } else {
            std::fs::copy(e.path(), &t).unwrap();
        }
    }
}

/// Flips every bit of entry `entry` of a `$readmemh` file.
fn corrupt_entry(dir: &Path, file: &str, entry: usize) {
    let p = dir.join(file);
    let text = std::fs::read_to_string(&p).unwrap();
    let mut k = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if l.starts_with("//") {
                return l.to_string();
            }
            k += 1;
            if k - 1 != entry {
                return l.to_string();
            }
            let bits = 4 * l.len() as u32;
            let v = u64::from_str_radix(l, 16).unwrap() ^ ((1u64 << bits) - 1);
            format!("{v:0w$x}", w = l.len())
        })
        .collect();
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
}

/// The front's engines (`--front-engine`); each must catch the front's planted faults.
const ENGINES: [&str; 2] = ["gates", "verilator"];

fn assert_fails(o: &Output, part: &str, want: &[&str]) {
    let t = text(o);
    assert_eq!(o.status.code(), Some(1), "a planted fault fails: {t}");
    assert!(
        t.contains(&format!("  {part} ")) && t.contains("FAILED"),
        "{part} fails: {t}"
    );
    for w in want {
        assert!(t.contains(w), "the failure says {w:?}: {t}");
    }
}

#[test]
fn a_small_design_is_proven_in_two_shards_and_every_part_catches_a_planted_fault() {
    if !tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &hdl::strs(&hdl::narrowest_flags()), 0);
    let build = tmp.path().join("build");
    let (r1, r2) = (tmp.path().join("1.json"), tmp.path().join("2.json"));
    for (k, r) in [("1/2", &r1), ("2/2", &r2)] {
        let o = prove(&dir, &build, &["--shard", k, "--report", s(r)]);
        assert_eq!(o.status.code(), Some(0), "shard {k} passes: {}", text(&o));
    }
    let o = helpers::run(&["prove", "--merge", s(&r1), s(&r2)]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("PROVEN: 16777216 gradients"), "{t}");
    for part in ["structure", "states", "zero", "front"] {
        assert!(t.contains(&format!("  {part} ")), "{part} in {t}");
    }
    // The default front engine is the gates; the Verilated front proves the same range.
    assert!(t.contains("front (gates)"), "{t}");
    let o = prove(
        &dir,
        &build,
        &["--part", "front", "--front-engine", "verilator"],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(
        t.contains("front (verilator)") && t.contains("16777216 of"),
        "{t}"
    );
    // A shard missing or given twice is refused.
    helpers::assert_error(
        &helpers::run(&["prove", "--merge", s(&r1)]),
        "shard 2/2 is missing",
    );
    helpers::assert_error(
        &helpers::run(&["prove", "--merge", s(&r1), s(&r1)]),
        "given twice",
    );

    // One reciprocal ROM entry wrong: the states through the top.
    let d = tmp.path().join("rom");
    copy_dir(&dir, &d);
    corrupt_entry(&d, "recip_rom.hex", 3);
    let o = prove(&d, &build, &["--part", "states"]);
    assert_fails(
        &o,
        "states",
        &["states: sample", "gradient [", "expected zero=0 i="],
    );
    // ... and the same through --direct.
    let o = prove(&d, &build, &["--direct", "--part", "direct"]);
    assert_fails(&o, "direct", &["direct: sample", "gradient ["]);

    // Sort & shift's leading-zero count off by one for x magnitudes 8..15.
    let d = tmp.path().join("shift");
    plant(
        &dir,
        &d,
        "sort_shift.v",
        "(mag_x[3]) lz_x_d = 3'd4;",
        "(mag_x[3]) lz_x_d = 3'd3;",
    );
    for engine in ENGINES {
        let o = prove(&d, &build, &["--part", "front", "--front-engine", engine]);
        assert_fails(
            &o,
            "front",
            &["front: sort_shift on gradient [", "m expected"],
        );
    }

    // Zero detect blind to gz's sign bit: (0, 0, -128) is taken for zero.
    let d = tmp.path().join("zero");
    plant(
        &dir,
        &d,
        "zero_detect.v",
        "(gz_i == {G{1'b0}})",
        "(gz_i[G-2:0] == {(G-1){1'b0}})",
    );
    for engine in ENGINES {
        let o = prove(&d, &build, &["--part", "front", "--front-engine", engine]);
        assert_fails(
            &o,
            "front",
            &["front: zero_detect on gradient [0, 0, -128]: zero expected 0x0, got 0x1"],
        );
    }

    // A register skipped on one output: s_u leaves sort & shift a clock early, so each
    // sample carries the next one's sign of u. The gates make every register a wire and
    // cannot see it (they rely on the structure for the timing, docs/VERIFICATION.md); the
    // structure sees a path one register short, and the clocked Verilated front sees the
    // wrong sample's sign.
    let d = tmp.path().join("early");
    plant(
        &dir,
        &d,
        "sort_shift.v",
        "s_u_q2   <= s_u_q1;",
        "s_u_q2   <= s_u_d;",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(&o, "structure", &["out_i is [", "registers"]);
    let o = prove(
        &d,
        &build,
        &["--part", "front", "--front-engine", "verilator"],
    );
    assert_fails(
        &o,
        "front",
        &["front: sort_shift on gradient [", "s_u expected"],
    );
    let o = prove(&d, &build, &["--part", "front", "--front-engine", "gates"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));

    // An undefined literal in the front: the gates would take it as "any value", so the
    // gate engine refuses the design (bad input), naming the line.
    let d = tmp.path().join("undef");
    plant(
        &dir,
        &d,
        "sort_shift.v",
        "lz_x_d = 3'd4;",
        "lz_x_d = 3'bxx0;",
    );
    let o = prove(&d, &build, &["--part", "front"]);
    helpers::assert_error(&o, "sort_shift.v:");

    // A register that holds while the others move: invisible to a full-rate stream, which
    // is why the structure is checked.
    let d = tmp.path().join("enable");
    plant(
        &dir,
        &d,
        "zero_detect.v",
        "  always @(posedge clk_i) begin\n    if (en_i) begin",
        "  always @(posedge clk_i) begin\n    if (en_i && valid_i) begin",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(&o, "structure", &["different enables"]);

    // The gradient reaching the output past the front.
    let d = tmp.path().join("leak");
    plant(
        &dir,
        &d,
        "rmap_top.v",
        "assign out_i     = lk_i;",
        "assign out_i     = lk_i ^ gx_i[M-1:0];",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(
        &o,
        "structure",
        &[
            "reads the gradient; only zero_detect and sort_shift may",
            "out_i is [0, ",
        ],
    );
}

/// Every grid row with an 8-bit gradient, every one of its 2^24 gradients through its top.
#[test]
fn every_g8_grid_row_is_proven_with_every_gradient_through_its_top() {
    if !tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let rows: Vec<_> = grid::rows()
        .into_iter()
        .filter(|r| r.config.grad_bits == 8)
        .collect();
    assert!(rows.len() >= 4, "the grid has G = 8 rows");
    std::thread::scope(|sc| {
        for chunk in rows.chunks(rows.len().div_ceil(2)) {
            let tmp = tmp.path();
            sc.spawn(move || {
                for r in chunk {
                    let dir = tmp.join(r.name);
                    let flags = rmapgen::cmd::config_args::ConfigArgs::flags(&r.config);
                    hdl::generate(&dir, &hdl::strs(&flags), 0);
                    let o = prove(&dir, &tmp.join("build"), &["--direct"]);
                    let t = text(&o);
                    assert_eq!(o.status.code(), Some(0), "{}: {t}", r.name);
                    assert!(
                        t.lines().any(|l| l.trim_start().starts_with("direct ")
                            && l.contains(" 16777216 of       16777216 ")),
                        "{}: {t}",
                        r.name
                    );
                }
            });
        }
    });
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    for (args, want) in [
        (vec!["--shard", "0/2"], "K must be in 1..=2"),
        (vec!["--shard", "3/2"], "K must be in 1..=2"),
        (vec!["--shard", "1"], "a shard is K/N"),
        (vec!["--shard", "1/0"], "N must be in"),
    ] {
        let mut a = vec!["prove", "nowhere"];
        a.extend(args);
        helpers::assert_error(&helpers::run(&a), want);
    }
    // The widest gradient: too many for --direct, and 2^48 for the factored proof.
    let wide = Config {
        grad_bits: 16,
        red_bits: 8,
        ..Config::default()
    };
    hdl::generate(
        &dir,
        &hdl::strs(&rmapgen::cmd::config_args::ConfigArgs::flags(&wide)),
        0,
    );
    let build = tmp.path().join("build");
    helpers::assert_error(&prove(&dir, &build, &[]), "grad_bits = 16 is above 12");
    helpers::assert_error(
        &prove(&dir, &build, &["--direct"]),
        "grad_bits = 16 is above 9",
    );
    assert!(!build.exists(), "nothing written");
    // A file that is not a report.
    let junk = tmp.path().join("junk.json");
    std::fs::write(&junk, "{}").unwrap();
    helpers::assert_error(
        &helpers::run(&["prove", "--merge", s(&junk)]),
        "not a report of rmapgen prove",
    );
}
