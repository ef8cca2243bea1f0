//! The generated design as IP a team adopts (src/stages/, src/flow/fpga.rs, package.rs): every
//! pipeline depth passes every testbench; the valid/ready handshake passes under random
//! backpressure and its testbench catches a broken queue; the FuseSoC core and README list
//! what the directory holds; +vcd writes a waveform; the iCE40 flow reports a missed target as
//! a figure and fails, in one line, on a memory in logic, an unknown device or package, and a
//! design that does not fit.
//!
//! The tools are required when CI=true (a missing tool fails the test there); elsewhere a
//! missing tool skips with a message on stderr.

use crate::hdl::{self, config_of, icarus, last_line, require, sabotage, vvp};
use crate::helpers;
use rmapgen::config::Config;
use rmapgen::stages::{self, rmap_top, TOP};
use rmapgen::{emit, flow::fpga};
use std::path::Path;

/// Generates a design into `dir` with `flags` and 300 random vectors per stage.
fn generate(dir: &Path, flags: &[&str]) {
    hdl::generate(dir, flags, 300)
}

#[test]
fn every_depth_passes_every_testbench_under_icarus() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    // The default depth (2) runs in sim.rs and make sim-all; here 0 and 1, with the optional
    // stages switched both ways, and the narrowest widths at depth 1.
    let narrowest_depth1 = [
        vec!["--pipeline-depth".to_string(), "1".into()],
        hdl::narrowest_flags(),
    ]
    .concat();
    let configs: [&[&str]; 3] = [
        &["--pipeline-depth", "0", "--color"],
        &["--pipeline-depth", "1", "--no-compensation", "--color"],
        &hdl::strs(&narrowest_depth1),
    ];
    let mut latencies = Vec::new();
    for flags in configs {
        let tmp = helpers::tempdir();
        let dir = tmp.path().join("d");
        generate(&dir, flags);
        let cfg = config_of(&dir);
        let tb = std::fs::read_to_string(dir.join("tb/rmap_top_tb.v")).unwrap();
        assert!(
            tb.contains(&format!(
                "localparam LATENCY    = {};",
                rmap_top::top_latency(&cfg)
            )),
            "{flags:?}"
        );
        latencies.push(rmap_top::top_latency(&cfg));
        let mut n = 0;
        for e in std::fs::read_dir(dir.join("tb")).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            let Some(m) = name.strip_suffix("_tb.v") else {
                continue;
            };
            let bin = icarus(&dir, m, tmp.path());
            let (code, out) = vvp(&dir, &bin, hdl::NO_ARGS);
            assert!(
                last_line(&out).ends_with(" passed, 0 failed") && code == Some(0),
                "{flags:?} {m}: {out}"
            );
            n += 1;
        }
        assert!(n >= 7, "{flags:?}: {n} testbenches");
    }
    // Depth 0 keeps the compact latency of the colour design (2+3+1+3+2+2+1).
    assert_eq!(latencies[0], 14);
}

#[test]
fn handshake_passes_under_backpressure_and_catches_a_broken_queue() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("hs");
    generate(&dir, &["--handshake", "--color", "--pipeline-depth", "1"]);
    let top = std::fs::read_to_string(dir.join("rmap_top.v")).unwrap();
    assert!(top.contains("output wire        ready_o") || top.contains("ready_o"));
    // A longer stream than the corner file, with the same maps (rmapgen vectors).
    let stream = tmp.path().join("stream.hex");
    let n = hdl::stream(&dir, 20000, &stream);
    let arg = vec![format!("+vectors={}", stream.display())];
    let bin = icarus(&dir, "rmap_top", tmp.path());
    hdl::assert_passed("handshake top", &vvp(&dir, &bin, &arg), n);

    // Three broken queues, each caught: the pipeline ignores backpressure; ready_o claims
    // samples the stalled pipeline drops; the head is overwritten while it waits.
    let broken = [
        ("assign en      = en_q;", "assign en      = 1'b1;"),
        ("assign ready_o = en_q;", "assign ready_o = 1'b1;"),
        (
            "assign take    = !valid_q || pop;",
            "assign take    = 1'b1;",
        ),
    ];
    for (from, to) in broken {
        let bad = tmp.path().join("bad");
        hdl::copy_design(&dir, &bad);
        sabotage(&bad, "rmap_top.v", from, to);
        let bin = icarus(&bad, "rmap_top", tmp.path());
        let (code, out) = vvp(&bad, &bin, &arg);
        assert_eq!(code, Some(1), "{to}: {}", last_line(&out));
        assert!(
            !last_line(&out).ends_with(" passed, 0 failed"),
            "{to}: {}",
            last_line(&out)
        );
    }
}

#[test]
fn core_and_readme_describe_the_directory() {
    let tmp = helpers::tempdir();
    let mut names = Vec::new();
    for (name, flags) in [
        ("plain", &[][..]),
        ("hs", &["--handshake", "--color"][..]),
        ("axis", &["--handshake", "--axis", "--axis-user", "2"][..]),
        ("lanes", &["--lanes", "2"][..]),
    ] {
        let dir = tmp.path().join(name);
        generate(&dir, flags);
        let cfg = config_of(&dir);
        // One rule names the core: after the module users instantiate, the design's top (the
        // manifest's `top`), which is its toplevel; its sim target runs that module's testbench.
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                .unwrap();
        let top = m["top"].as_str().unwrap().to_string();
        assert_eq!(top, stages::top(&cfg).module(&cfg));
        let file = format!("{top}.core");
        assert_eq!(m["core"]["file"], file.as_str());
        assert_eq!(m["core"]["toplevel"], top.as_str());
        assert_eq!(m["core"]["sim_toplevel"], format!("{top}_tb").as_str());
        let core = std::fs::read_to_string(dir.join(&file)).unwrap();
        assert!(
            core.starts_with(&format!("CAPI=2:\n# {file}: generated")),
            "{core}"
        );
        // Named after that top and the configuration, so the cores differ.
        let vlnv = format!(
            "rmapgen:ip:{top}_{}:{}",
            emit::manifest::config_hash(&cfg),
            env!("CARGO_PKG_VERSION")
        );
        assert_eq!(m["core"]["name"], vlnv.as_str());
        assert!(core.contains(&format!("\nname: {vlnv}\n")), "{core}");
        names.push(vlnv.clone());
        assert!(
            core.contains(&format!("    toplevel: {top}\n"))
                && core.contains(&format!("    toplevel: {top}_tb\n"))
                && core.contains(&format!("      - tb/{top}_tb.v\n")),
            "{core}"
        );
        assert!(dir.join(format!("tb/{top}_tb.v")).is_file());
        // The README says the name, and the rule, once.
        let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
        assert_eq!(readme.matches(&vlnv).count(), 2, "{readme}");
        assert_eq!(readme.matches("rmapgen:ip:<module>_<hash>").count(), 1);
        assert!(!readme.contains("rmapgen:ip:rmap_top_") || top == "rmap_top");
        // No other core file: the one rule names the only one.
        let cores: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".core"))
            .collect();
        assert_eq!(cores.len(), 1, "{name}");
        // Every module file and every memory's init file, each of which exists.
        for m in stages::modules(&cfg) {
            assert!(
                core.contains(&format!("      - {}\n", m.file(&cfg))),
                "{}",
                m.file(&cfg)
            );
        }
        for mem in emit::manifest::memories(&cfg) {
            let f = &mem.init_file;
            assert!(
                core.contains(&format!("      - {f}: {{file_type: user, copyto: {f}}}")),
                "{f}"
            );
            assert!(dir.join(f).is_file(), "{f}");
        }
        for line in core.lines().filter(|l| l.starts_with("      - ")) {
            let f = line[8..].split(':').next().unwrap();
            assert!(
                dir.join(f).is_file(),
                "the core lists {f}, which is missing"
            );
        }
        let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
        for p in TOP.ports(&cfg) {
            assert!(readme.contains(&format!("| `{}` |", p.name)), "{}", p.name);
        }
        assert!(readme.contains(&format!(
            "**Latency**: {} clocks",
            rmap_top::top_latency(&cfg)
        )));
        assert!(readme.contains("## Reset") && readme.contains("swap_i"));
        assert_eq!(readme.contains("`ready_i`"), cfg.handshake, "{flags:?}");
        // Both are in the manifest's file list.
        let files = m["files"].as_array().unwrap();
        assert!(files.contains(&file.as_str().into()) && files.contains(&"README.md".into()));
    }
    names.sort();
    names.dedup();
    assert_eq!(names.len(), 4);
}

#[test]
fn vcd_plusarg_writes_a_waveform() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &[], 20);
    let bin = icarus(&dir, "rmap_top", tmp.path());
    let vcd = tmp.path().join("top.vcd");
    let (code, out) = vvp(&dir, &bin, &[format!("+vcd={}", vcd.display())]);
    assert_eq!(code, Some(0), "{out}");
    let text = std::fs::read_to_string(&vcd).expect("a VCD");
    assert!(text.contains("$var") && text.contains(" valid_o ") && text.contains("#"));
    // Without the plusarg nothing is written.
    let (code, _) = vvp(&dir, &bin, hdl::NO_ARGS);
    assert_eq!(code, Some(0));
    assert!(!dir.join("top.vcd").exists());
}

fn fpga_tools() -> bool {
    require("yosys") && require("nextpnr-ice40")
}

/// A small configuration, so that the flow takes seconds.
fn narrow() -> Config {
    rmapgen::grid::narrowest()
}

#[test]
fn fpga_rejects_unknown_devices_and_packages_in_one_line() {
    if !fpga_tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let logs = tmp.path().join("logs");
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &[], 1);
    let d = dir.to_str().unwrap();
    let l = logs.to_str().unwrap();
    let o = helpers::run(&["fpga", "--dir", d, "--logs", l, "--device", "hx9k"]);
    helpers::assert_error(&o, "unrecognised option '--hx9k'");
    let o = helpers::run(&["fpga", "--dir", d, "--logs", l, "--package", "ct257"]);
    helpers::assert_error(&o, "Unsupported package 'ct257'");
    let o = helpers::run(&["fpga", "--dir", tmp.path().to_str().unwrap(), "--logs", l]);
    helpers::assert_error(&o, "no manifest.json");
}

#[test]
fn fpga_fails_on_a_memory_in_logic_and_on_a_design_too_big() {
    if !fpga_tools() {
        return;
    }
    let tmp = helpers::tempdir();
    let logs = tmp.path().join("logs");
    let l = logs.to_str().unwrap();
    // The narrow configuration's ROMs are small enough that Yosys would build them from LUTs
    // without the ram_style attribute.
    let dir = tmp.path().join("d");
    let mut flags = hdl::narrowest_flags();
    flags.extend(["--target".to_string(), "ice40".to_string()]);
    hdl::generate(&dir, &hdl::strs(&flags), 1);
    sabotage(
        &dir,
        "recip_rom.v",
        "(* ram_style = \"block\" *)",
        "(* ram_style = \"logic\" *)",
    );
    let o = helpers::run(&["fpga", "--dir", dir.to_str().unwrap(), "--logs", l]);
    helpers::assert_error(&o, "fell back to logic");
    helpers::assert_error(&o, "u_normalise.u_recip_rom.rom");
    assert!(!String::from_utf8_lossy(&o.stderr).contains("u_atan_rom"));
    assert!(!String::from_utf8_lossy(&o.stderr).contains("--target"));
    // The same configuration generated for the portable default: its small ROMs are Yosys's
    // to place, and when they land in logic the error says how to get block RAM.
    let generic = tmp.path().join("g");
    hdl::generate(&generic, &hdl::strs(&hdl::narrowest_flags()), 1);
    let o = helpers::run(&["fpga", "--dir", generic.to_str().unwrap(), "--logs", l]);
    helpers::assert_error(&o, "fell back to logic");
    helpers::assert_error(&o, "generate it with --target ice40");
    // The default design needs about 1,700 logic cells; the HX1K has 1,280.
    let o = helpers::run(&[
        "fpga",
        "--logs",
        l,
        "--device",
        "hx1k",
        "--package",
        "tq144",
    ]);
    // One line: what ran out (the need and the part's count, from nextpnr's utilisation
    // table), what to change, then nextpnr's own words.
    helpers::assert_error(
        &o,
        "nextpnr-ice40 --hx1k --package tq144: the design needs ",
    );
    helpers::assert_error(
        &o,
        " (logic cells), the part has 1280: use a larger part (--device)",
    );
    helpers::assert_error(&o, "; nextpnr: ERROR:");
    helpers::assert_error(&o, "no BELs remaining");
}

#[test]
fn ice40_report_gives_a_missed_target_as_a_figure() {
    if !fpga_tools() {
        return;
    }
    let cfg = narrow();
    let opts = fpga::Options {
        freq_mhz: 500.0,
        ..fpga::Options::default()
    };
    let r = fpga::report(&cfg, &opts).expect("the flow runs");
    assert!(
        !r.timing_met && r.fmax_mhz > 50.0 && r.fmax_mhz < 500.0,
        "{r:?}"
    );
    // The report is of the design built for the iCE40, whatever the configuration's target.
    let ice40 = cfg.for_target(rmapgen::config::Target::Family(
        rmapgen::family::Family::Ice40,
    ));
    assert_eq!(r.memories.len(), emit::manifest::memories(&ice40).len());
    assert!(r.in_logic().is_empty());
    assert_eq!(
        r.block_rams,
        r.memories.iter().map(|m| m.block_rams).sum::<u32>(),
        "{r:?}"
    );
    assert!(r.logic_cells > 100 && r.logic_cells < r.logic_cells_available);
    assert!(r.luts > 0 && r.carries > 0 && r.flip_flops > 0);
    let c = r.critical_path.as_ref().expect("a critical path");
    assert!(c.logic_ns + c.routing_ns > 1000.0 / 500.0, "{c:?}");
    assert!(r.summary().contains("FAIL at 500 MHz"), "{}", r.summary());
}

/// `fpga` says what it is doing on a terminal (its steps under a pseudo-terminal made by
/// util-linux's `script`) and nothing on stderr in a script.
#[test]
fn fpga_shows_its_steps_on_a_terminal_only() {
    if !fpga_tools() || !rmapgen::toolchain::installed("script") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    let mut flags = hdl::narrowest_flags();
    flags.extend(["--target".to_string(), "ice40".to_string()]);
    hdl::generate(&dir, &hdl::strs(&flags), 1);
    let logs = tmp.path().join("logs");
    let (ok, tty) = crate::helpers::on_a_terminal(&[
        "fpga",
        "--dir",
        dir.to_str().unwrap(),
        "--logs",
        logs.to_str().unwrap(),
    ])
    .expect("script");
    assert!(ok, "{tty}");
    for step in [
        "synthesising with Yosys synth_ice40",
        "placing and routing: nextpnr-ice40 --hx8k",
    ] {
        assert!(tty.contains(step), "{step}: {tty}");
    }
    let o = helpers::run(&[
        "fpga",
        "--dir",
        dir.to_str().unwrap(),
        "--logs",
        logs.to_str().unwrap(),
        "--force",
    ]);
    assert!(o.status.success());
    assert_eq!(String::from_utf8_lossy(&o.stderr), "");
    assert!(!String::from_utf8_lossy(&o.stdout).contains("placing and routing"));
}
