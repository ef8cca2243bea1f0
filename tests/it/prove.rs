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
use std::path::{Path, PathBuf};
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

/// The design of issue 31's reproduction (G = 8, R = 6), generated into `d` of a fresh
/// temporary directory.
fn issue_design() -> (tempfile::TempDir, PathBuf) {
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &["--grad-bits", "8", "--red-bits", "6"], 0);
    (tmp, dir)
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
    assert!(
        t.contains("(16777216 gradients)") && t.starts_with("prove "),
        "{t}"
    );
    assert!(t.contains("PROVEN: G8 "), "{t}");
    assert!(t.contains("all as generated"), "{t}");
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
        &[
            "states (buffer 0 as loaded): sample",
            "gradient [",
            "expected zero=0 i=",
        ],
    );
    // ... and the same through --direct.
    let o = prove(&d, &build, &["--direct", "--part", "direct"]);
    assert_fails(
        &o,
        "direct",
        &["direct (buffer 0 as loaded): sample", "gradient ["],
    );
    // ... and in a --direct shard, which drives its own share only: the last quarter of the
    // samples, the pass on buffer 1 as written, where the fault is found on a gradient driven
    // (not only reported as never driven: "samples .. were never driven").
    let o = prove(
        &d,
        &build,
        &["--direct", "--part", "direct", "--shard", "4/4"],
    );
    assert_fails(
        &o,
        "direct",
        &[
            "direct (buffer 1 written): sample ",
            "gradient [",
            " 16777216 of ",
            " 67108864 inputs [50331648..67108864) ",
        ],
    );
    assert!(!text(&o).contains("as loaded"), "{}", text(&o));

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

    // The reciprocal ROM's read register clocked on the falling edge: that path is half a
    // clock short, so each sample reads its neighbour's reciprocal, which consecutive states
    // (most share their max) hide from the states part. Found by `rmapgen mutants` (Yosys
    // inverted the register's clock); the structure now requires one clock edge.
    let d = tmp.path().join("negedge");
    plant(
        &dir,
        &d,
        "recip_rom.v",
        "always @(posedge clk_i)",
        "always @(negedge clk_i)",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(&o, "structure", &["different clock edges", "polarity 0"]);

    // A register never loaded (it holds its own value): Verilator's two-state simulation
    // gives it 0, which here changes no output (a_max only hastens a saturation that comes
    // anyway), so every gradient passes, even under --direct; synthesis takes it as any
    // value and the netlist is wrong. Found by `rmapgen mutants` (m13: Yosys inverted this
    // register's enable); the structure now refuses any undefined value read.
    let d = tmp.path().join("stuck");
    plant(
        &dir,
        &d,
        "normalise.v",
        "a_max_q2 <= a_max_q1;",
        "a_max_q2 <= a_max_q2;",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(
        &o,
        "structure",
        &[
            "reads an undefined value on D",
            "register u_normalise.a_max_q2 (normalise.v:",
            "is never loaded",
        ],
    );

    // A register never loaded whose value reaches only a multiplexer's data input: `opt_dff`
    // makes it an `x`, which a data input may carry (`proc` writes `x` into inputs no path
    // selects), so the undefined-value check above passed it, and so did every simulation
    // (two-state: it reads 0, and valid_q ? valid_q : 0 is valid_q); synthesis may make it 1
    // and raise valid_o for ever. The structure now finds registers whose D is their own Q
    // before `opt_dff` removes them, whatever reads them.
    let d = tmp.path().join("held");
    plant(
        &dir,
        &d,
        "interpolate.v",
        "  assign valid_o = valid_q[LATENCY-1];",
        "  reg hold_q;\n  always @(posedge clk_i) hold_q <= hold_q;\n  assign valid_o = valid_q[LATENCY-1] ? valid_q[LATENCY-1] : hold_q;",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(
        &o,
        "structure",
        &[
            "register u_interpolate.hold_q (interpolate.v:",
            "is never loaded: bits [0]",
        ],
    );

    // The last stage never raises valid_o: no result leaves the top. A wrong design, so a
    // failed proof (exit 1) naming the part and its samples, not an error of the tool.
    let d = tmp.path().join("silent");
    plant(
        &dir,
        &d,
        "interpolate.v",
        "assign valid_o = valid_q[LATENCY-1];",
        "assign valid_o = 1'b0;",
    );
    let o = prove(&d, &build, &["--part", "states"]);
    assert_fails(
        &o,
        "states",
        &[
            "states (buffer 0 as loaded): samples 0..=",
            "the top lost or added a result",
        ],
    );

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

    // One bit of a partial product a clock late, where it enters an adder whose low sum bits
    // are rounded away: the late bit reaches the kept bits only through the carries. A
    // depth count that passed an adder's input bit k to its output bit k alone (cargo-mutants:
    // `&&` -> `||` in `depths`' bitwise test) saw it only in the dropped bits and passed
    // the design, which `--direct` fails on 82,068 gradients.
    let d = tmp.path().join("late");
    plant(
        &dir,
        &d,
        "normalise.v",
        "  assign pa_l2_d = {({{5{1'b0}}, pa_l1_0_q[6:2]}",
        "  reg late_q;\n  always @(posedge clk_i) late_q <= pa_l1_0_q[2];\n  assign pa_l2_d = {({{5{1'b0}}, pa_l1_0_q[6:3], late_q}",
    );
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(
        &o,
        "structure",
        &["out_i is [20, 21] registers from the sample inputs, not exactly 20"],
    );

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

/// Under the handshake a register loaded when the pipeline's enable is low moves exactly when
/// the others hold. Its enable is the same net as theirs, at the other polarity, so the
/// structure must tell enables apart by polarity too (cargo-mutants: `==` -> `!=` where the
/// polarity is added to a non-constant enable's name passed it).
#[test]
fn an_enable_of_the_other_polarity_fails_the_structure() {
    if !tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    let mut flags = hdl::narrowest_flags();
    flags.push("--handshake".into());
    hdl::generate(&dir, &hdl::strs(&flags), 0);
    let d = tmp.path().join("inverted");
    plant(
        &dir,
        &d,
        "zero_detect.v",
        "  always @(posedge clk_i) begin\n    if (en_i) begin",
        "  always @(posedge clk_i) begin\n    if (!en_i) begin",
    );
    let build = tmp.path().join("build");
    let o = prove(&dir, &build, &["--part", "structure"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = prove(&d, &build, &["--part", "structure"]);
    assert_fails(
        &o,
        "structure",
        &["2 different enables", "polarity 0 (1 of them)"],
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
                            && l.contains(" 67108864 of       67108864 ")),
                        "{}: {t}",
                        r.name
                    );
                }
            });
        }
    });
}

/// A design Verilator cannot build fails the proof with Verilator's first error and the log
/// named, not an empty message.
#[test]
fn a_design_verilator_cannot_build_fails_naming_its_first_error() {
    if !tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &hdl::strs(&hdl::narrowest_flags()), 0);
    let bad = tmp.path().join("bad");
    plant(
        &dir,
        &bad,
        "zero_detect.v",
        "endmodule",
        "wire ;\nendmodule",
    );
    let build = tmp.path().join("build");
    let o = prove(&bad, &build, &["--part", "states"]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("Verilator could not build rmap_top ("), "{t}");
    assert!(
        t.contains("verilator.log): %Error"),
        "the first error is shown: {t}"
    );
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
        (vec!["--shards", "4"], "--slurm"),
        (vec!["--slurm", "--shard", "1/2"], "cannot be used with"),
        (vec!["--build-only", "--reuse", "x"], "cannot be used with"),
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
        "grad_bits = 16 is above 12",
    );
    assert!(!build.exists(), "nothing written");
    // rmapgen mutants judges every mutant by prove, so it takes the designs prove takes,
    // whatever its ground truth.
    for truth in ["direct", "stream"] {
        helpers::assert_error(
            &helpers::run(&["mutants", s(&dir), "--build", s(&build), "--truth", truth]),
            "rmapgen mutants judges by rmapgen prove: rmapgen prove covers",
        );
    }
    assert!(!build.exists(), "nothing written");
    // A design prove takes but --direct does not (G = 12): the sampled truth is named.
    let g12 = tmp.path().join("g12");
    hdl::generate(&g12, &[], 0);
    helpers::assert_error(
        &helpers::run(&["mutants", s(&g12), "--build", s(&build)]),
        "the ground truth of rmapgen mutants is prove --direct: --direct drives all 2^(3 grad_bits) gradients",
    );
    helpers::assert_error(
        &helpers::run(&[
            "mutants",
            s(&g12),
            "--build",
            s(&build),
            "--truth",
            "stream",
            "--truth-stream",
            "0",
        ]),
        "--truth-stream 0",
    );
    assert!(!build.exists(), "nothing written");
    // The flow ground truth judges the formal harness, on the designs it takes; each check
    // is judged against its own truth; a memory changes no flow signal.
    let flow = |d: &Path, more: &[&str]| {
        let mut a = vec!["mutants", s(d), "--build", s(&build), "--truth", "flow"];
        a.extend_from_slice(more);
        helpers::run(&a)
    };
    helpers::assert_error(
        &flow(&g12, &[]),
        "--truth flow: the formal harness takes a --handshake --axis design",
    );
    let hs = tmp.path().join("hs");
    hdl::generate(
        &hs,
        &[
            "--handshake",
            "--axis",
            "--grad-bits",
            "8",
            "--red-bits",
            "6",
        ],
        0,
    );
    helpers::assert_error(
        &flow(&hs, &["--method", "prove"]),
        "--method prove: judged against --truth direct or stream, not --truth flow",
    );
    helpers::assert_error(
        &helpers::run(&[
            "mutants",
            s(&g12),
            "--build",
            s(&build),
            "--method",
            "formal",
        ]),
        "--method formal: judged against --truth flow, not --truth direct",
    );
    helpers::assert_error(
        &flow(&hs, &["--method", "formal,flow"]),
        "--method flow: a ground truth runs on every mutant already",
    );
    helpers::assert_error(
        &flow(&hs, &["--memories", "2"]),
        "--memories 2: under --truth flow a memory's contents change no flow signal",
    );
    helpers::assert_error(
        &flow(&hs, &["--python", "no/python"]),
        "--python no/python: not found",
    );
    helpers::assert_error(
        &flow(&hs, &["--select", "rmap_top; shell"]),
        "--select \"rmap_top; shell\": one Yosys selection",
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

/// The reproduction of issue 31: bit 8 of every reciprocal ROM entry flipped (the file's
/// format kept). The states part failed to drive the top at all in the release build (a
/// miscompiled count, docs/VERIFICATION.md "The false proof") and passed; now every part
/// counts the samples it checked, and this fails in `states`, naming the pass, the sample
/// and the gradient, and the report names the edited file.
#[test]
fn a_flipped_rom_bit_fails_the_factored_proof_and_the_edited_file_is_named() {
    if !tools() {
        return;
    }
    let (tmp, dir) = issue_design();
    let p = dir.join("recip_rom.hex");
    let text = std::fs::read_to_string(&p).unwrap();
    let flipped: Vec<String> = text
        .lines()
        .map(|l| {
            if l.starts_with("//") {
                return l.to_string();
            }
            let v = u64::from_str_radix(l, 16).unwrap() ^ (1 << 8);
            format!("{v:0w$x}", w = l.len())
        })
        .collect();
    std::fs::write(&p, flipped.join("\n") + "\n").unwrap();
    let build = tmp.path().join("build");
    let report = tmp.path().join("r.json");
    let o = prove(&dir, &build, &["--report", s(&report)]);
    assert_fails(
        &o,
        "states",
        &[
            "states (buffer 0 as loaded): sample ",
            " gradient [",
            "edited since generated (not as in .rmapgen-files): recip_rom.hex",
        ],
    );
    // Every part says what it checked: the states part drove all its samples.
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for part in r["parts"].as_array().unwrap() {
        let range = part["end"].as_u64().unwrap() - part["first"].as_u64().unwrap();
        assert_eq!(part["ran"].as_u64(), Some(range), "{part}");
        assert!(range > 0, "{part}");
    }
    let files = r["files"].as_array().unwrap();
    let rom = files.iter().find(|f| f["name"] == "recip_rom.hex").unwrap();
    assert_eq!(rom["as_generated"], false);
    assert_eq!(rom["sha256"].as_str().unwrap().len(), 64);
    assert!(files.iter().any(|f| f["name"] == "rmap_top.v"));
}

/// `--build-only` builds once what the shards simulate, and shards given `--reuse` load it
/// instead of compiling their own: the shards merge into the verdict of a run that built
/// itself. A build is reused only for the files it was built from: a design edited since is
/// refused (exit 2, naming the file), and a build of the edited design fails its proof.
#[test]
fn shards_reuse_one_build_of_the_same_files_and_nothing_else() {
    if !tools() {
        return;
    }
    let (tmp, dir) = issue_design();
    let build = tmp.path().join("build");
    let o = prove(&dir, &build, &["--build-only"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(
        t.starts_with("built the Verilated top and the front (gates) for "),
        "{t}"
    );
    let built = build.join("d-build");
    assert!(built.join("built.json").is_file(), "{t}");
    let shards = tmp.path().join("shards");
    let mut reports = Vec::new();
    for k in 1..=2 {
        let r = tmp.path().join(format!("r{k}.json"));
        let o = prove(
            &dir,
            &shards,
            &[
                "--shard",
                &format!("{k}/2"),
                "--reuse",
                s(&built),
                "--report",
                s(&r),
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        // Nothing Verilated in the shard's own build directory: it loaded the shared one.
        assert!(!shards.join(format!("d-{k}of2")).join("top").exists());
        reports.push(r);
    }
    let mut a = vec!["prove", "--merge"];
    a.extend(reports.iter().map(|r| s(r)));
    let o = helpers::run(&a);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(text(&o).contains("PROVEN: G8 R6"), "{}", text(&o));
    // Another front engine than the build's, and a directory that is no build.
    helpers::assert_error(
        &prove(
            &dir,
            &shards,
            &["--reuse", s(&built), "--front-engine", "verilator"],
        ),
        "built for front engine gates, not verilator",
    );
    helpers::assert_error(
        &prove(&dir, &shards, &["--reuse", s(&shards)]),
        "no finished `rmapgen prove --build-only` build there",
    );
    // Edited after the build: refused; its own build proves it wrong.
    corrupt_entry(&dir, "recip_rom.hex", 4);
    helpers::assert_error(
        &prove(&dir, &shards, &["--reuse", s(&built)]),
        "(recip_rom.hex differs): build again with --build-only",
    );
    let o = prove(&dir, &build, &["--build-only"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_fails(
        &prove(&dir, &shards, &["--reuse", s(&built)]),
        "states",
        &["states (buffer 0 as loaded): sample "],
    );
}

/// A build holds the models its run needs, and says which: `--direct` builds the top alone,
/// `--part front` the front alone. A shard reusing it runs with the models it has and is
/// refused, in one line, a model it lacks.
#[test]
fn a_build_serves_the_runs_it_has_the_models_for_and_no_other() {
    if !tools() {
        return;
    }
    let (tmp, dir) = issue_design();
    let build = tmp.path().join("build");
    let built = build.join("d-build");
    let shards = tmp.path().join("shards");
    // Exit 0, with a line that starts with `says` (a build's line, or a part's that passed).
    let ok = |o: Output, says: &str| {
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{t}");
        assert!(
            t.lines()
                .any(|l| l.trim_start().starts_with(says) && !l.contains("FAILED")),
            "{t}"
        );
    };

    ok(
        prove(&dir, &build, &["--direct", "--build-only"]),
        &format!("built the Verilated top for {}", s(&dir)),
    );
    let shard = ["--shard", "64/64", "--reuse", s(&built)];
    ok(
        prove(&dir, &shards, &[&["--direct"][..], &shard].concat()),
        "direct ",
    );
    helpers::assert_error(
        &prove(&dir, &shards, &[&["--part", "front"][..], &shard].concat()),
        "built for front engine none, not gates",
    );

    let front = ["--part", "front", "--front-engine", "verilator"];
    ok(
        prove(&dir, &build, &[&front[..], &["--build-only"]].concat()),
        &format!("built the front (verilator) for {}", s(&dir)),
    );
    ok(
        prove(&dir, &shards, &[&front[..], &shard].concat()),
        "front (verilator) ",
    );
    helpers::assert_error(
        &prove(&dir, &shards, &[&["--part", "states"][..], &shard].concat()),
        "the build has no Verilated top",
    );
}

/// One entry changed in each class of memory file the top reads (the reciprocal ROM, the
/// compensation ROM, each map bank in its buffer-0 and buffer-1 halves) or the model reads
/// (the scene's logical map): the factored proof fails on each, in the pass that reads it.
#[test]
fn a_single_changed_entry_of_every_memory_class_fails_the_states() {
    if !tools() {
        return;
    }
    let (tmp, dir) = issue_design();
    let build = tmp.path().join("build");
    // (file, entry, the pass that must see it). A bank holds 1,024 entries: address
    // {buf, axis, s_max, s_u, i_u >> 1, s_v, i_v >> 1}, 512 a buffer; entry 100 is axis 0.
    let cases = [
        ("recip_rom.hex", 7, "buffer 0 as loaded"),
        ("atan_rom.hex", 40, "buffer 0 as loaded"),
        ("map_bank_00.hex", 100, "buffer 0 as loaded"),
        ("map_bank_01.hex", 100, "buffer 0 as loaded"),
        ("map_bank_10.hex", 100, "buffer 0 as loaded"),
        ("map_bank_11.hex", 612, "buffer 1 as loaded"),
        ("map_x.hex", 300, "buffer 0 as loaded"),
    ];
    for (file, entry, pass) in cases {
        let d = tmp.path().join(file.replace('.', "_"));
        copy_dir(&dir, &d);
        corrupt_entry(&d, file, entry);
        let o = prove(&d, &build, &["--part", "states"]);
        assert_fails(&o, "states", &[&format!("states ({pass}): sample "), file]);
    }
}

/// `--merge` certifies only a whole run: every part of every shard once, for one
/// configuration and the same files, totals the configuration gives, every input of a
/// part's range checked. Each forgery here is one line and exit 2.
#[test]
fn merge_refuses_reports_that_do_not_cover_the_run() {
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
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let forge = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = read(&r1);
        edit(&mut v);
        let p = tmp.path().join(name);
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    let whole =
        |v: &mut serde_json::Value| v["shard"] = serde_json::json!({"index": 1, "count": 1});
    let only_structure = forge("structure.json", &|v| {
        whole(v);
        v["parts"]
            .as_array_mut()
            .unwrap()
            .retain(|p| p["name"] == "structure");
    });
    let no_parts = forge("none.json", &|v| {
        whole(v);
        v["parts"] = serde_json::json!([]);
    });
    let front10 = forge("front10.json", &|v| {
        for p in v["parts"].as_array_mut().unwrap() {
            if p["name"] == "front" {
                // Consistent in itself: its range within the total it claims.
                p["total"] = 10.into();
                p["end"] = 10.into();
                p["ran"] = 10.into();
            }
        }
    });
    let huge = forge("huge.json", &|v| {
        v["shard"] = serde_json::json!({"index": 1, "count": 1u64 << 62});
    });
    let short = forge("short.json", &|v| {
        for p in v["parts"].as_array_mut().unwrap() {
            if p["name"] == "states" {
                p["ran"] = (p["ran"].as_u64().unwrap() - 1).into();
            }
        }
    });
    let other_file = forge("file.json", &|v| {
        v["files"][0]["sha256"] = "0".repeat(64).into();
    });
    let other_config = forge("config.json", &|v| {
        v["config"]["map_bits"] = 7.into();
        let summary = v["config_summary"]
            .as_str()
            .unwrap()
            .replace(" M6 ", " M7 ");
        v["config_summary"] = summary.into();
    });
    let old = forge("old.json", &|v| v["format"] = "rmapgen-prove-1".into());
    // Issue 60's edits: a shard's own verdict, a failure added, a negative time.
    let failed = forge("failed.json", &|v| v["passed"] = false.into());
    let example = forge("example.json", &|v| {
        v["parts"][1]["examples"] = serde_json::json!(["states (buffer 0 as loaded): sample 7"]);
    });
    let negative = forge("negative.json", &|v| v["seconds"] = (-100.0).into());
    for (files, want) in [
        (
            vec![&failed, &r2],
            "failed.json: passed is false, but no part failed; rmapgen prove writes no such report (was it edited?)",
        ),
        (
            vec![&r2, &example],
            "example.json: parts[1] (states): examples lists 1 failures, but failures is 0",
        ),
        (vec![&negative, &r2], "negative.json: seconds is -100, not a time"),
        (vec![&only_structure], "front, states, zero missing"),
        (vec![&no_parts], "has the parts []"),
        (
            vec![&front10, &r2],
            "claims 10 inputs; the configuration gives",
        ),
        (vec![&huge], "is not a shard"),
        (vec![&short, &r2], "checked"),
        (vec![&other_file, &r2], "proved other files"),
        (vec![&other_config, &r2], "another configuration"),
        (vec![&old, &r2], "its format is \"rmapgen-prove-1\""),
        (vec![&r1, &r1], "given twice"),
        (vec![&r2], "shard 1/2 is missing"),
    ] {
        let mut a = vec!["prove", "--merge"];
        a.extend(files.iter().map(|p| s(p)));
        helpers::assert_error(&helpers::run(&a), want);
    }
    // A shard that failed and says so throughout is a verdict: FAILED, exit 1, its failure
    // shown.
    let failing = forge("failing.json", &|v| {
        v["passed"] = false.into();
        v["parts"][1]["failures"] = 1.into();
        v["parts"][1]["examples"] = serde_json::json!(["states (buffer 0 as loaded): sample 7"]);
    });
    let o = helpers::run(&["prove", "--merge", s(&failing), s(&r2)]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(1), "{t}");
    assert!(t.contains("\nFAILED: G8 ") && !t.contains("PROVEN"), "{t}");
    assert!(
        t.contains("    states (buffer 0 as loaded): sample 7"),
        "{t}"
    );
}

/// `--merge` reads at most its bound of each report, whatever the file's metadata says: a
/// device (whose length is 0) and a FIFO fed without end are refused after one byte past it.
#[test]
fn merge_reads_a_device_or_a_fifo_only_up_to_its_bound() {
    helpers::assert_error(
        &helpers::run(&["prove", "--merge", "/dev/zero"]),
        "/dev/zero is larger than 4194304 bytes, not a report of rmapgen prove",
    );
    let tmp = helpers::tempdir();
    let fifo = tmp.path().join("fifo.json");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    // A writer that never stops (until its reader goes: a broken pipe).
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
            let block = vec![b' '; 1 << 16];
            let mut sent = 0u64;
            while f.write_all(&block).is_ok() {
                sent += block.len() as u64;
            }
            sent
        })
    };
    let o = helpers::run(&["prove", "--merge", s(&fifo)]);
    helpers::assert_error(&o, "fifo.json is larger than 4194304 bytes");
    let sent = writer.join().unwrap();
    // What the pipe holds beyond what was read: at most a few of its buffers.
    assert!(sent < (4 << 20) + (4 << 20), "{sent} bytes sent");
}
