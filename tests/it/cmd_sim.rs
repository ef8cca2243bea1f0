//! `rmapgen sim`, `rmapgen synth` and `rmapgen lint` (src/cmd/sim.rs, synth.rs, lint.rs,
//! src/sim/): they pass a generated design, and each fails, with exit 1 and a message naming
//! what failed, on a design with a fault planted in it (a ROM entry, a latch, an unused
//! signal); bad input is one line and exit 2, with nothing written.
//!
//! The tools are required when CI=true (a missing tool fails the test there); elsewhere a
//! missing tool skips with a message on stderr.

use crate::hdl::{self, require};
use crate::helpers;
use rmapgen::grid;
use std::path::Path;
use std::process::Output;

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Complements the value of entry `entry` (0-based, after the comment lines) of a `$readmemh`
/// file in `dir`.
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
    assert!(k > entry, "{file} has {k} entries");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
}

#[test]
fn sim_passes_every_testbench_under_icarus_and_fails_on_a_planted_rom_fault() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &[], 200);
    let build = tmp.path().join("build");
    let o = helpers::run(&[
        "sim",
        "--icarus",
        "--tb-stream",
        "300",
        "--build",
        s(&build),
        s(&dir),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let tbs = hdl::testbenches(&dir);
    assert!(tbs.len() >= 7, "{tbs:?}");
    for m in &tbs {
        let want = format!(
            "ok:   icarus {m}_tb: {} passed, 0 failed (",
            hdl::vector_count(&dir, m)
        );
        assert!(out.contains(&want), "{want:?} in {out}");
    }
    let cfg = hdl::config_of(&dir);
    let stream = rmapgen::vectors::top_stream_lines(&cfg, 300);
    assert!(
        out.contains(&format!(
            "ok:   icarus rmap_top_tb (stream): {stream} passed, 0 failed ("
        )),
        "{out}"
    );
    assert!(
        out.contains(&format!("---- d: {}\n", cfg.summary())),
        "{out}"
    );
    let canonical = dir.canonicalize().unwrap();
    assert_eq!(
        hdl::last_line(&out),
        format!("sim: all passed in {}", canonical.display())
    );
    // Build products and logs in BUILD/<name>, stamped as rmapgen's; the design untouched.
    let logs = build.join("d/icarus");
    assert!(std::fs::read_to_string(logs.join("rmap_top_tb.log"))
        .unwrap()
        .ends_with(" passed, 0 failed\n"));
    assert!(build.join("d/.rmapgen-files").is_file());
    assert!(!helpers::entries(&dir).iter().any(|e| e.ends_with(".vvp")));

    // One reciprocal-ROM entry wrong (normalise's vectors read every entry): the run fails,
    // names the testbench and the command, shows the mismatches and exits 1.
    let bad = tmp.path().join("bad");
    hdl::copy_design(&dir, &bad);
    corrupt_entry(&bad, "recip_rom.hex", 5);
    let args = [
        "sim",
        "--icarus",
        "--only",
        "normalise",
        "--build",
        s(&build),
    ];
    let o = helpers::run(&[&args[..], &[s(&bad)]].concat());
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(
        out.contains("FAIL: icarus normalise_tb (exit 1, last line: "),
        "{out}"
    );
    assert!(out.contains("  | MISMATCH line "), "{out}");
    let bad_canonical = bad.canonicalize().unwrap();
    assert!(
        // Run from the build directory, the vectors (and the init files) named absolutely.
        out.contains(&format!(
            "  command: (cd {} && vvp -N ",
            build.join("bad/icarus").display()
        )) && out.contains(&format!(
            "+vectors={}/vectors/normalise.hex)",
            bad_canonical.display()
        )),
        "{out}"
    );
    assert!(
        out.ends_with(&format!(
            "sim: 1 FAILED in {}:\n  icarus normalise_tb\n",
            bad_canonical.display()
        )),
        "{out}"
    );
    // The log of the failed run is kept.
    let log = std::fs::read_to_string(build.join("bad/icarus/normalise_tb.log")).unwrap();
    assert!(log.contains("MISMATCH"), "{log}");
    // The same command on the intact design passes: the fault is what failed it.
    let o = helpers::run(&[&args[..], &[s(&dir)]].concat());
    assert_eq!(o.status.code(), Some(0), "{:?}", text(&o));
}

/// The netlist `text` (Yosys `write_verilog` of `synth_ice40`) with one bit of one block
/// RAM's contents complemented: the most significant bit of map bank 00's entry 0 (buffer 0,
/// axis x, every sign and index 0), the entry a gradient along +x reads with all the weight.
/// The bit is found from the cell's own wiring, as Yosys mapped it: the RDATA bit that drives
/// `rd_data_q[M-1]` (M = map_bits), in word 0 of INIT_0 (read and write mode 1 keep the entry
/// of an even address in the even bits of a 16-bit word).
fn flip_bank_entry_msb(text: &str, map_bits: u32) -> String {
    let name = text
        .find(") \\u_map_lookup.u_bank_00.mem.")
        .expect("a block RAM of bank 00 in the netlist");
    let start = text[..name].rfind("SB_RAM40_4K #(").expect("its cell");
    let end = name + text[name..].find(");").expect("the end of its cell");
    let cell = &text[start..end];
    let rdata = cell
        .split(".RDATA({ ")
        .nth(1)
        .expect("RDATA wired bit by bit");
    let rdata = &rdata[..rdata.find(" })").unwrap()];
    let bits: Vec<&str> = rdata.split(", ").collect();
    assert_eq!(bits.len(), 16, "{rdata}");
    let msb = format!("rd_data_q [{}]", map_bits - 1);
    let bit = 15 - bits.iter().position(|b| b.ends_with(&msb)).expect(&msb);
    let init = cell.find(".INIT_0(256'h").expect("INIT_0 in hex") + ".INIT_0(256'h".len();
    // Word 0 is the last four hex digits of the 256-bit parameter.
    let at = start + init + 64 - 1 - bit / 4;
    let digit = u32::from_str_radix(&text[at..=at], 16).expect("a hex digit");
    let flipped = format!("{:x}", digit ^ (1 << (bit % 4)));
    let mut out = text.to_string();
    out.replace_range(at..=at, &flipped);
    out
}

#[test]
fn gate_level_sim_passes_the_netlist_and_fails_on_a_flipped_block_ram_bit_or_a_stale_netlist() {
    if !require("iverilog") || !require("vvp") || !require("yosys") {
        return;
    }
    // A small design (2 index bits: one block RAM per map bank) and few random vectors:
    // about 10 s of synthesis and 3 s of gate-level simulation a run. Built for the iCE40,
    // as make gate-sim's is: with no_rw_check a bank's RDATA drives its read register directly,
    // which is where the fault below is planted.
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &["--index-bits", "2", "--target", "ice40"], 50);
    let build = tmp.path().join("build");
    let o = helpers::run(&[
        "sim",
        "--icarus",
        "--only",
        "rmap_top",
        "--gate",
        "--tb-stream",
        "100",
        "--build",
        s(&build),
        s(&dir),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let cfg = hdl::config_of(&dir);
    let n = hdl::vector_count(&dir, "rmap_top");
    let stream = rmapgen::vectors::top_stream_lines(&cfg, 100);
    for want in [
        format!("ok:   icarus rmap_top_tb: {n} passed, 0 failed ("),
        "ok:   gate yosys synth_ice40: ".to_string(),
        format!("ok:   gate rmap_top_tb: {n} passed, 0 failed ("),
        format!("ok:   gate rmap_top_tb (stream): {stream} passed, 0 failed ("),
    ] {
        assert!(out.contains(&want), "{want:?} in {out}");
    }
    assert!(out.contains(" SB_RAM40_4K) in "), "{out}");
    let gate = build.join("d/gate");
    let netlist = gate.join("rmap_top_netlist.v");
    let text_of = |p: &Path| std::fs::read_to_string(p).unwrap();
    let good = text_of(&netlist);
    // The testbench ran on the netlist, not on the design's files: one flat module of cells.
    assert!(good.contains("module rmap_top(") && !good.contains("module map_bank"));
    assert!(text_of(&gate.join("rmap_top_tb.log")).ends_with(" passed, 0 failed\n"));

    // One bit of one block RAM's contents flipped in the netlist: the RTL cannot see it, the
    // gate-level run fails and names the vector that read it.
    let bad = tmp.path().join("flipped.v");
    std::fs::write(&bad, flip_bank_entry_msb(&good, cfg.map_bits)).unwrap();
    let diff = good
        .bytes()
        .zip(text_of(&bad).bytes())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(diff, 1, "one hex digit changed");
    let args = |netlist: &Path, dir: &Path| {
        let (n, d) = (s(netlist).to_string(), s(dir).to_string());
        let b = s(&build).to_string();
        helpers::run(&["sim", "--gate", "--netlist", &n, "--build", &b, &d])
    };
    let o = args(&bad, &dir);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(
        out.contains("FAIL: gate rmap_top_tb (exit 1, last line: "),
        "{out}"
    );
    assert!(out.contains("  | MISMATCH line "), "{out}");
    assert!(
        out.contains(&format!(
            "  netlist: {}\n",
            bad.canonicalize().unwrap().display()
        )),
        "{out}"
    );
    let canonical = dir.canonicalize().unwrap();
    assert!(
        out.ends_with(&format!(
            "sim: 1 FAILED in {}:\n  gate rmap_top_tb\n",
            canonical.display()
        )),
        "{out}"
    );
    // The intact netlist passes the same command: the flipped bit is what failed it.
    let kept = tmp.path().join("good.v");
    std::fs::write(&kept, &good).unwrap();
    let o = args(&kept, &dir);
    assert_eq!(o.status.code(), Some(0), "{:?}", text(&o));

    // A stale netlist: the same configuration regenerated with another scene's maps (the
    // $readmemh files the RTL reads change; the netlist holds the old contents).
    let other = tmp.path().join("other");
    let scene = helpers::root().join("scenes/diffuse.toml");
    let flags = [
        "--index-bits",
        "2",
        "--target",
        "ice40",
        "--scene",
        s(&scene),
    ];
    hdl::generate(&other, &flags, 50);
    let o = args(&kept, &other);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(out.contains("  | MISMATCH line "), "{out}");
}

#[test]
fn sim_runs_verilator_and_the_cpp_harness_and_the_harness_catches_a_fault() {
    if !require("verilator") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 100);
    let build = tmp.path().join("build");
    let o = helpers::run(&[
        "sim",
        "--verilator",
        "--only",
        "rmap_top",
        "--stream",
        "2000",
        "--tb-stream",
        "500",
        "--build",
        s(&build),
        s(&dir),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let cfg = hdl::config_of(&dir);
    for want in [
        format!(
            "ok:   verilator rmap_top_tb: {} passed, 0 failed (",
            hdl::vector_count(&dir, "rmap_top")
        ),
        format!(
            "ok:   verilator rmap_top_tb (stream): {} passed, 0 failed (",
            rmapgen::vectors::top_stream_lines(&cfg, 500)
        ),
        format!(
            "ok:   verilator top_stream (C++): {} passed, 0 failed (",
            rmapgen::vectors::top_stream_lines(&cfg, 2000)
        ),
    ] {
        assert!(out.contains(&want), "{want:?} in {out}");
    }
    assert!(!out.contains("icarus"), "{out}");

    let bad = tmp.path().join("bad");
    hdl::copy_design(&dir, &bad);
    corrupt_entry(&bad, "recip_rom.hex", 7);
    let o = helpers::run(&["sim", "--stream", "2000", "--build", s(&build), s(&bad)]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(
        out.contains("FAIL: verilator top_stream (C++) (exit 1, last line: "),
        "{out}"
    );
    let bad_canonical = bad.canonicalize().unwrap();
    assert!(
        out.ends_with(&format!(
            "sim: 1 FAILED in {}:\n  verilator top_stream (C++)\n",
            bad_canonical.display()
        )),
        "{out}"
    );
}

#[test]
fn sim_matrix_generates_and_simulates_the_rows_asked_for() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let (designs, build) = (tmp.path().join("m"), tmp.path().join("b"));
    let o = helpers::run(&[
        "sim",
        "--matrix",
        "--row",
        "narrowest",
        "--icarus",
        "--only",
        "rmap_top",
        "--build",
        s(&build),
        s(&designs),
    ]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let row = grid::row("narrowest").unwrap();
    assert!(
        out.starts_with(&format!(
            "==== narrowest: {} ({})\n",
            row.config.summary(),
            row.covers
        )),
        "{out}"
    );
    assert_eq!(helpers::entries(&designs), ["narrowest"]);
    assert_eq!(hdl::config_of(&designs.join("narrowest")), row.config);
    assert!(out.contains("ok:   icarus rmap_top_tb: "), "{out}");
    assert_eq!(
        hdl::last_line(&out),
        "sim: every configuration passed (1 rows)"
    );
}

#[test]
fn synth_checks_a_design_and_fails_on_a_planted_latch() {
    if !require("yosys") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 1);
    let logs = tmp.path().join("logs");
    let o = helpers::run(&["synth", s(&dir), "--logs", s(&logs)]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    let verdict = hdl::last_line(&out);
    assert!(
        verdict.starts_with(&format!("synth: rmap_top in {}: no latches, ", s(&dir)))
            && verdict.contains(&format!(
                " cells, {} memory bits, ",
                manifest["memory_bits"]
            ))
            && verdict.ends_with(" SB_RAM40_4K"),
        "{verdict}"
    );
    assert!(out.contains("Number of cells:"), "{out}");
    assert!(logs.join("yosys.log").is_file() && logs.join("rmap_top.json").is_file());

    // A latch in the top: an incomplete combinational assignment.
    let bad = tmp.path().join("bad");
    hdl::copy_design(&dir, &bad);
    hdl::sabotage(
        &bad,
        "rmap_top.v",
        "\nendmodule",
        "\nreg planted_q;\nalways @* if (valid_i) planted_q = gx_i[0];\nendmodule",
    );
    let o = helpers::run(&["synth", s(&bad), "--logs", s(&logs)]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(err.contains("Assertion failed"), "{err}");
    assert!(
        hdl::last_line(&err).starts_with(&format!("synth: rmap_top in {}: FAILED (log: ", s(&bad))),
        "{err}"
    );
    // The log of the failed run is kept, and says why.
    let log = std::fs::read_to_string(logs.join("yosys.log")).unwrap();
    assert!(log.contains("$dlatch"), "{log}");
}

#[test]
fn lint_passes_a_design_and_fails_on_a_planted_warning() {
    if !require("verilator") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &["--color"], 1);
    let o = helpers::run(&["lint", s(&dir)]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    assert_eq!(
        out,
        format!(
            "lint: {} is clean (verilator -Wall, no warnings)\n",
            s(&dir)
        )
    );
    let bad = tmp.path().join("bad");
    hdl::copy_design(&dir, &bad);
    hdl::sabotage(
        &bad,
        "color_mul.v",
        "\nendmodule",
        "\nwire planted_w = clk_i;\nendmodule",
    );
    let o = helpers::run(&["lint", s(&bad)]);
    let (out, err) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{out}{err}");
    assert!(
        err.contains("%Warning-UNUSED") && err.contains("planted_w"),
        "{err}"
    );
    assert!(
        hdl::last_line(&err).starts_with(&format!(
            "lint: {}: verilator -Wall is not silent (exit ",
            s(&bad)
        )),
        "{err}"
    );
}

#[test]
fn bad_input_is_one_line_and_exit_2_with_nothing_written() {
    let tmp = helpers::tempdir();
    let t = tmp.path();
    let build = t.join("build");
    let b = s(&build);
    let missing = t.join("missing");
    let plain = t.join("plain");
    std::fs::create_dir(&plain).unwrap();
    std::fs::write(plain.join("x.v"), "module x; endmodule\n").unwrap();
    let file = plain.join("x.v");
    let design = t.join("d");
    hdl::generate(&design, &[], 1);
    let d = s(&design);
    let not_generated = format!(
        "{} is not a design rmapgen generated (no manifest.json)",
        s(&plain)
    );
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["sim", "--icarus", "--build", b, s(&missing)],
            format!("design directory {}: No such file", s(&missing)),
        ),
        (
            vec!["sim", "--icarus", "--build", b, s(&file)],
            format!("{} is not a directory", s(&file)),
        ),
        (
            vec!["sim", "--icarus", "--build", b, s(&plain)],
            not_generated.clone(),
        ),
        (
            vec!["sim", "--build", b, d],
            "nothing to run: give --icarus, --verilator, --gate or --stream N".into(),
        ),
        (
            vec!["sim", "--icarus", "--only", "nope", "--build", b, d],
            "--only nope: no testbench".into(),
        ),
        (
            vec!["sim", "--matrix", "--row", "nope", "--icarus", "--build", b],
            "--row nope: no such row in the grid; rows: paper, ".into(),
        ),
        (
            vec!["sim", "--stream", "10000000001", "--build", b, d],
            "--stream must be in 0..=10000000000, not 10000000001".into(),
        ),
        (
            vec!["sim", "--icarus", "--row", "paper", "--build", b, d],
            "--matrix".into(),
        ),
        (
            vec!["sim", "--verilator", "--vcd", "--build", b, d],
            "--icarus".into(),
        ),
        (vec!["sim", "--icarus", "--build", b], "DIR".into()),
        (
            vec!["sim", "--gate", "--only", "normalise", "--build", b, d],
            "--only normalise: --gate simulates the top's netlist; give --only rmap_top".into(),
        ),
        (
            vec!["sim", "--gate", "--netlist", s(&missing), "--build", b, d],
            format!("--netlist {}: no such file", s(&missing)),
        ),
        (
            vec!["sim", "--icarus", "--netlist", s(&file), "--build", b, d],
            "--gate".into(),
        ),
        (
            vec!["synth", s(&missing), "--logs", b],
            "No such file".into(),
        ),
        (vec!["synth", s(&plain), "--logs", b], not_generated.clone()),
        (vec!["lint", s(&missing)], "No such file".into()),
        (vec!["lint", s(&plain)], not_generated),
    ];
    for (args, want) in cases {
        let o = helpers::run(&args);
        helpers::assert_error(&o, &want);
        assert!(!build.exists(), "{args:?} wrote {}", build.display());
    }
    // A build directory holding files rmapgen did not write is refused before any run.
    if !require("iverilog") || !require("vvp") {
        return;
    }
    std::fs::create_dir_all(build.join("d")).unwrap();
    std::fs::write(build.join("d/mine.txt"), "keep").unwrap();
    let o = helpers::run(&["sim", "--icarus", "--build", b, d]);
    helpers::assert_error(&o, "it holds mine.txt, which rmapgen did not write");
    assert_eq!(helpers::entries(&build.join("d")), ["mine.txt"]);
    // Yosys's iCE40 cell models not where YOSYS_DATDIR says: one line naming the place tried.
    if !require("yosys") {
        return;
    }
    let other = t.join("other_build");
    let o = helpers::rmapgen()
        .args(["sim", "--gate", "--build", s(&other), d])
        .env("YOSYS_DATDIR", &missing)
        .output()
        .unwrap();
    helpers::assert_error(
        &o,
        &format!(
            "cannot find Yosys's iCE40 cell models (ice40/cells_sim.v): not at {}/ice40/cells_sim.v; set YOSYS_DATDIR",
            s(&missing)
        ),
    );
    assert!(!other.exists());
}

/// `sim` shows the step under way on a terminal (under util-linux's `script`), and its stderr
/// is empty in a script, its stdout the same lines either way.
#[test]
fn sim_shows_its_steps_on_a_terminal_only() {
    if !require("iverilog") || !rmapgen::toolchain::installed("script") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate_config(&dir, &grid::narrowest(), 5);
    let build = tmp.path().join("b");
    let (ok, tty) = helpers::on_a_terminal(&[
        "sim",
        "--icarus",
        "--only",
        "zero_detect",
        "--build",
        s(&build),
        s(&dir),
    ])
    .expect("script");
    assert!(ok, "{tty}");
    // The spinner's line: the elapsed time, then the step (compile, then the run).
    assert!(tty.contains("icarus zero_detect_tb (compile)"), "{tty}");
    assert!(tty.contains("00:00:0"), "{tty}");
    assert!(tty.contains("ok:   icarus zero_detect_tb: "), "{tty}");
    // In a script: no spinner. (Its plain lines, every RMAPGEN_PROGRESS seconds, are
    // tests/it/progress.rs's; off here, so that a slow machine does not print one.)
    let quiet = |args: &[&str]| {
        helpers::rmapgen()
            .args(args)
            .env("RMAPGEN_PROGRESS", "0")
            .output()
            .expect("rmapgen runs")
    };
    let o = quiet(&[
        "sim",
        "--icarus",
        "--only",
        "zero_detect",
        "--build",
        s(&build),
        "--force",
        s(&dir),
    ]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert_eq!(err, "");
    assert!(!out.contains("(compile)"), "{out}");
    assert!(out.contains("ok:   icarus zero_detect_tb: "), "{out}");
    // synth, one Yosys run: its step on a terminal, nothing on stderr in a script.
    if require("yosys") {
        let logs = tmp.path().join("logs");
        let (ok, tty) =
            helpers::on_a_terminal(&["synth", "--logs", s(&logs), s(&dir)]).expect("script");
        assert!(ok, "{tty}");
        assert!(
            tty.contains("synthesising rmap_top with Yosys synth_ice40"),
            "{tty}"
        );
        let o = quiet(&["synth", "--logs", s(&logs), "--force", s(&dir)]);
        assert!(o.status.success());
        assert_eq!(text(&o).1, "");
    }
}
