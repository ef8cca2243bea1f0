//! `rmapgen generate` and the Verilog generator (src/emit, src/stages, templates/): the committed rtl_out/
//! is exactly what the default configuration generates; stages a configuration switches off
//! are absent; output is byte-reproducible; errors exit 2 and leave nothing behind; the
//! manifest agrees with the files; and the design lints clean (Verilator -Wall), compiles
//! (Icarus) and synthesises without latches into block RAM (Yosys) in every configuration of
//! the parameter grid (`rmapgen::grid`).
//!
//! The tools are required when CI=true (a missing tool fails the test there); elsewhere a
//! missing tool skips with a message on stderr.

use crate::hdl::{generate, generate_config, require};
use crate::helpers;
use rmapgen::config::Config;
use rmapgen::grid;
use rmapgen::stages::{self, map_bank::banks, rmap_top};
use rmapgen::toolchain::icarus;
use std::path::Path;

/// The names of the design's .v files, sorted.
fn design_files(dir: &Path) -> Vec<String> {
    crate::hdl::design_files(dir)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

/// The manifest of a generated directory.
fn manifest(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("manifest.json")).expect("manifest.json");
    serde_json::from_str(&text).expect("manifest.json is JSON")
}

fn config_of(m: &serde_json::Value) -> Config {
    serde_json::from_value(m["config"].clone()).expect("the manifest's config is a Config")
}

#[test]
fn committed_rtl_out_is_what_the_default_generates() {
    let committed = helpers::root().join("rtl_out");
    assert!(
        committed.join("rmap_top.v").is_file(),
        "rtl_out/ is missing: run `make generate`"
    );
    let t = helpers::tempdir();
    let fresh = t.path().join("rtl_out");
    generate(&fresh, &[], 2000);
    if let Some(d) = helpers::first_difference(&committed, &fresh) {
        panic!("rtl_out/ is not what `rmapgen generate` writes now: {d}; run `make generate`");
    }
}

/// Golden output beyond the default design: each directory under `golden/` is generated from
/// the `tb/config.toml` it holds (`make golden` regenerates them all), so a change to the
/// generator shows up as a diff in the handshake top, a design without the interpolator and
/// one with the colour multiplier, the bus slaves with their register views (C, SystemRDL,
/// Python), not only in `rtl_out/`.
#[test]
fn committed_golden_designs_are_what_their_configs_generate() {
    let golden = helpers::root().join("golden");
    let mut dirs: Vec<_> = std::fs::read_dir(&golden)
        .expect("golden/ exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    let names: Vec<String> = dirs
        .iter()
        .map(|d| d.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "bus_axi4_lite",
            "bus_wishbone",
            "color",
            "handshake",
            "ice40",
            "no_interpolation"
        ]
    );
    let t = helpers::tempdir();
    for dir in &dirs {
        let fresh = t.path().join(dir.file_name().unwrap());
        let config = dir.join("tb/config.toml");
        generate(&fresh, &["--config", config.to_str().unwrap()], 2000);
        if let Some(d) = helpers::first_difference(dir, &fresh) {
            panic!(
                "{} is not what `rmapgen generate` writes now: {d}; run `make golden`",
                dir.display()
            );
        }
    }
}

#[test]
fn switched_off_stages_are_absent() {
    let t = helpers::tempdir();
    let (nocomp, nointerp, color) = (
        t.path().join("nocomp"),
        t.path().join("nointerp"),
        t.path().join("color"),
    );
    generate(&nocomp, &["--no-compensation"], 10);
    generate(&nointerp, &["--no-interpolation"], 10);
    generate(&color, &["--color"], 10);

    let files = design_files(&nocomp);
    assert!(!files.contains(&"atan_rom.v".to_string()), "{files:?}");
    assert!(files.contains(&"linear_index.v".to_string()), "{files:?}");
    assert!(!nocomp.join("atan_rom.hex").exists());
    let top = std::fs::read_to_string(nocomp.join("rmap_top.v")).unwrap();
    assert!(
        !top.to_lowercase().contains("atan"),
        "rmap_top.v mentions atan without compensation"
    );
    assert!(top.contains("linear_index u_linear_index"));

    let files = design_files(&nointerp);
    assert!(!files.contains(&"interpolate.v".to_string()), "{files:?}");
    let top = std::fs::read_to_string(nointerp.join("rmap_top.v")).unwrap();
    assert!(
        !top.contains("interpolate u_"),
        "rmap_top.v instantiates the interpolator"
    );
    assert!(nointerp.join("map_bank.hex").is_file() && !nointerp.join("map_bank_00.hex").exists());

    // The default has colour off; --color adds exactly color_mul.v.
    let default = t.path().join("default");
    generate(&default, &[], 10);
    let (plain, colored) = (design_files(&default), design_files(&color));
    assert!(!plain.contains(&"color_mul.v".to_string()), "{plain:?}");
    assert!(!std::fs::read_to_string(default.join("rmap_top.v"))
        .unwrap()
        .contains("color_mul"));
    let added: Vec<&String> = colored.iter().filter(|f| !plain.contains(f)).collect();
    assert_eq!(added, vec!["color_mul.v"]);
    assert!(
        plain.contains(&"atan_rom.v".to_string()) && plain.contains(&"interpolate.v".to_string())
    );
    assert!(!plain.contains(&"linear_index.v".to_string()));
}

#[test]
fn generating_twice_gives_the_same_bytes() {
    let t = helpers::tempdir();
    let flags = [
        "--color",
        "--no-compensation",
        "--index-bits",
        "4",
        "--interp-bits",
        "2",
    ];
    generate(&t.path().join("a"), &flags, 50);
    generate(&t.path().join("b"), &flags, 50);
    assert_eq!(
        helpers::first_difference(&t.path().join("a"), &t.path().join("b")),
        None
    );
    // And regenerating over an existing directory replaces it whole.
    generate(&t.path().join("a"), &[], 50);
    assert!(!t.path().join("a").join("color_mul.v").exists());
}

#[test]
fn invalid_config_exits_2_and_writes_nothing() {
    let t = helpers::tempdir();
    let out = t.path().join("x");
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--grad-bits",
        "30",
    ]);
    helpers::assert_error(&o, "--grad-bits must be in 8..=16, not 30");
    assert!(!out.exists(), "an invalid config left {}", out.display());
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--red-bits",
        "12",
        "--grad-bits",
        "10",
    ]);
    helpers::assert_error(&o, "exceeds grad_bits");
    // Nothing else (no staging directory) was left beside it.
    assert!(
        !helpers::nonempty(t.path()),
        "{:?}",
        helpers::tree(t.path()).keys().collect::<Vec<_>>()
    );
}

#[test]
fn unwritable_out_exits_2() {
    let o = helpers::run(&["generate", "--out", "/proc/nonexistent/x", "--vectors", "1"]);
    helpers::assert_error(&o, "/proc/nonexistent/x");
}

#[test]
fn failed_generate_keeps_the_existing_output() {
    let t = helpers::tempdir();
    let out = t.path().join("rtl");
    generate(&out, &[], 5);
    let before = helpers::tree(&out);
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--scene",
        "/nonexistent/scene.toml",
    ]);
    helpers::assert_error(&o, "scene");
    assert!(
        before == helpers::tree(&out),
        "a failed run changed {}",
        out.display()
    );
}

/// (direction, range, name) of each port declaration in a generated module file.
fn declared_ports(text: &str) -> Vec<(String, String, String)> {
    let start = text.find("\nmodule ").expect("a module");
    let head = &text[start..start + text[start..].find("\n);").expect("end of ports")];
    head.lines()
        .map(str::trim)
        .filter(|l| l.starts_with("input ") || l.starts_with("output "))
        .map(|l| {
            let code = l.split("//").next().unwrap().trim().trim_end_matches(',');
            let words: Vec<&str> = code.split_whitespace().collect();
            let name = words.last().unwrap().to_string();
            let width = words
                .iter()
                .find(|w| w.starts_with('['))
                .map(|w| w.to_string())
                .unwrap_or_default();
            (words[0].to_string(), width, name)
        })
        .collect()
}

#[test]
fn manifest_agrees_with_the_files_and_the_latency_function() {
    let t = helpers::tempdir();
    // Every configuration of the parameter grid (src/grid.rs).
    for row in grid::rows() {
        let name = row.name;
        let dir = t.path().join(name);
        generate_config(&dir, &row.config, 5);
        let m = manifest(&dir);
        let cfg = config_of(&m);
        assert_eq!(m["rmapgen_version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(m["latency"], rmap_top::top_latency(&cfg), "{name}");
        let listed: Vec<&str> = m["modules"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x["name"].as_str().unwrap())
            .collect();
        let expected: Vec<&str> = stages::modules(&cfg).iter().map(|m| m.name()).collect();
        assert_eq!(listed, expected, "{name}");
        // The design's top: the AXI4-Stream wrapper with `axis`, which instantiates rmap_top.
        assert_eq!(listed[0], stages::top(&cfg).name(), "{name}");
        assert_eq!(m["top"], listed[0], "{name}");
        if cfg.axis {
            assert_eq!(listed[..2], ["rmap_axis", "rmap_top"], "{name}");
            assert!(
                m["axis"]["s_tdata"]["bits"]
                    .as_u64()
                    .unwrap()
                    .is_multiple_of(8),
                "{name}"
            );
        } else if cfg.lanes > 1 {
            // The lanes top: one rmap_top per lane, each with its own memories.
            assert_eq!(listed[..2], ["rmap_lanes", "rmap_top"], "{name}");
            assert_eq!(m["lanes"]["lanes"], cfg.lanes, "{name}");
            assert_eq!(
                m["memory_bits"].as_u64().unwrap(),
                cfg.lanes as u64 * m["lanes"]["memory_bits_per_lane"].as_u64().unwrap(),
                "{name}"
            );
            assert!(m.get("axis").is_none(), "{name}");
        } else {
            assert_eq!(listed[0], "rmap_top");
            assert!(
                m.get("axis").is_none() && m.get("lanes").is_none(),
                "{name}"
            );
        }
        // Exactly the listed modules have files.
        let mut files: Vec<String> = listed.iter().map(|n| format!("{n}.v")).collect();
        files.sort();
        assert_eq!(design_files(&dir), files, "{name}");
        for module in m["modules"].as_array().unwrap() {
            let mname = module["name"].as_str().unwrap();
            let lat = stages::modules(&cfg)
                .into_iter()
                .find(|m| m.name() == mname)
                .unwrap()
                .latency(&cfg);
            assert_eq!(module["latency"], serde_json::json!(lat), "{name} {mname}");
            let text = std::fs::read_to_string(dir.join(format!("{mname}.v"))).unwrap();
            assert!(text.starts_with(&format!(
                "// {mname}.v: generated by rmapgen {}",
                env!("CARGO_PKG_VERSION")
            )));
            assert!(
                text.contains(&format!("grad_bits={}", cfg.grad_bits)) && text.contains("color=")
            );
            assert!(
                text.ends_with("`default_nettype wire\n"),
                "{mname}.v ends with one newline"
            );
            assert!(
                !text.contains('\t') && !text.lines().any(|l| l.ends_with(' ')),
                "{mname}.v whitespace"
            );
            let declared = declared_ports(&text);
            let ports = module["ports"].as_array().unwrap();
            assert_eq!(declared.len(), ports.len(), "{name} {mname}: {declared:?}");
            for ((dir_, width, pname), p) in declared.iter().zip(ports) {
                assert_eq!(pname, p["name"].as_str().unwrap(), "{name} {mname}");
                assert_eq!(dir_, p["dir"].as_str().unwrap(), "{name} {mname} {pname}");
                let w = match &p["width"] {
                    serde_json::Value::Number(n) if n.as_u64() == Some(1) => String::new(),
                    serde_json::Value::Number(n) => format!("[{}:0]", n.as_u64().unwrap() - 1),
                    serde_json::Value::String(s) => format!("[{s}-1:0]"),
                    other => panic!("width {other}"),
                };
                assert_eq!(width, &w, "{name} {mname} {pname}");
            }
        }
        // Every memory's init file exists with one line per entry after its comments.
        let mut bits = 0;
        for mem in m["memories"].as_array().unwrap() {
            let file = mem["init_file"].as_str().unwrap();
            let text = std::fs::read_to_string(dir.join(file))
                .unwrap_or_else(|_| panic!("{name}: {file}"));
            let entries = text.lines().filter(|l| !l.starts_with("//")).count() as u64;
            assert_eq!(entries, mem["entries"].as_u64().unwrap(), "{name} {file}");
            bits += mem["bits"].as_u64().unwrap();
        }
        assert_eq!(m["memory_bits"].as_u64().unwrap(), bits);
        assert_eq!(
            m["files"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|f| f.as_str().unwrap().ends_with(".v"))
                .count(),
            files.len()
        );
    }
}

#[test]
fn bank_files_hold_the_scene_map_in_both_buffers() {
    let t = helpers::tempdir();
    let dir = t.path().join("d");
    generate(&dir, &[], 1);
    let cfg = Config::default();
    let entries = |f: &str| -> Vec<u32> {
        std::fs::read_to_string(dir.join(f))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with("//"))
            .map(|l| u32::from_str_radix(l, 16).unwrap())
            .collect()
    };
    let banks: Vec<Vec<u32>> = (0..4)
        .map(|k| entries(&banks::bank_file(&cfg, k)))
        .collect();
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        let map = entries(&format!("map_{name}.hex"));
        for buf in 0..2 {
            for (addr, &e) in map.iter().enumerate() {
                let s = banks::bank_slot(&cfg, buf, axis as u32, addr as u32);
                assert_eq!(
                    banks[s.bank][s.addr as usize], e,
                    "axis {name} buf {buf} addr {addr}"
                );
            }
        }
    }
    // The second map is the alternate scene's, and differs from the first.
    assert_ne!(entries("map_x.hex"), entries("map2_x.hex"));
}

#[test]
fn verilator_lint_is_silent_and_icarus_compiles() {
    if !require("verilator") || !require("iverilog") {
        return;
    }
    let t = helpers::tempdir();
    for row in grid::rows() {
        let name = row.name;
        let dir = t.path().join(name);
        generate_config(&dir, &row.config, 1);
        crate::hdl::assert_lint_clean(name, &dir);
        let o = icarus::compile(
            "rmap_top",
            Path::new("/dev/null"),
            &crate::hdl::design_files(&dir),
            &[],
        )
        .current_dir(&dir)
        .output()
        .expect("iverilog runs");
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            o.status.success() && said.trim().is_empty(),
            "iverilog -Wall on {name}:\n{said}"
        );
    }
}

#[test]
fn default_for_the_ice40_synthesises_without_latches_into_block_ram() {
    if !require("yosys") {
        return;
    }
    let t = helpers::tempdir();
    let dir = t.path().join("rtl");
    generate(&dir, &["--target", "ice40"], 1);
    let o = helpers::run(&[
        "synth",
        dir.to_str().unwrap(),
        "--logs",
        t.path().join("synth").to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "synth failed:\n{said}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let m = manifest(&dir);
    // recip ROM 128 x 10: 1 EBR; two atan ROMs 256 x 6: 1 each; four banks 1024 x 8: 2 each.
    let verdict = said.lines().last().unwrap_or("");
    assert!(verdict.contains("no latches"), "{verdict}");
    let tail = format!("{} memory bits, 11 SB_RAM40_4K", m["memory_bits"]);
    assert!(
        verdict.ends_with(&tail),
        "{verdict} should end with {tail:?}"
    );
}

/// `--target`: the portable default carries no vendor attribute and reads one compensation ROM
/// through two ports; `ice40` puts Yosys's block-RAM attributes on every memory and gives
/// each read port its own ROM copy. The behaviour is the same (the grid simulates both), and
/// the memories the manifest lists are the arrays the Verilog declares.
#[test]
fn the_target_changes_only_the_memories() {
    let t = helpers::tempdir();
    let generic = t.path().join("generic");
    let ice40 = t.path().join("ice40");
    generate(&generic, &[], 0);
    generate(&ice40, &["--target", "ice40"], 0);
    let read = |d: &std::path::Path, f: &str| std::fs::read_to_string(d.join(f)).unwrap();
    for f in ["recip_rom.v", "atan_rom.v", "map_bank.v"] {
        let g = read(&generic, f);
        assert!(!g.contains("(*"), "{f}: an attribute in the generic design");
        let i = read(&ice40, f);
        assert!(
            i.contains("ram_style = \"block\" *)"),
            "{f}: no ram_style for ice40"
        );
    }
    assert!(read(&ice40, "map_bank.v").contains("(* no_rw_check, ram_style = \"block\" *)"));
    let arrays = |d: &std::path::Path| -> Vec<String> {
        manifest(d)["memories"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["module"] == "atan_rom")
            .map(|m| m["instance"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(arrays(&generic), ["u_atan_rom.rom"]);
    assert_eq!(arrays(&ice40), ["u_atan_rom.rom_u", "u_atan_rom.rom_v"]);
    let g = read(&generic, "atan_rom.v");
    assert!(
        g.contains("pu_q <= rom[u_i];") && g.contains("pv_q <= rom[v_i];"),
        "{g}"
    );
    // Everything but the memories' modules is the same text, headers included (the target is
    // a field of the configuration only when it is not the default).
    for f in [
        "sort_shift.v",
        "normalise.v",
        "map_lookup.v",
        "interpolate.v",
    ] {
        let (g, i) = (read(&generic, f), read(&ice40, f));
        let body = |s: &str| {
            s.lines()
                .skip_while(|l| l.starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        assert_eq!(body(&g), body(&i), "{f}");
    }
    assert!(read(&ice40, "README.md").contains("**Target: `ice40`.**"));
    assert!(read(&generic, "README.md").contains("**Target: `generic`.**"));
}

/// A bad `--target` is one line naming the allowed values, exit 2, nothing written.
#[test]
fn an_unknown_target_is_refused() {
    let t = helpers::tempdir();
    let out = t.path().join("o");
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--target",
        "xilinx",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("xilinx") && err.contains("generic") && err.contains("ice40"),
        "{err}"
    );
    assert!(!out.exists());
    let cfg = t.path().join("c.toml");
    std::fs::write(&cfg, "target = \"xilinx\"\n").unwrap();
    let o = helpers::run(&[
        "generate",
        "--out",
        out.to_str().unwrap(),
        "--config",
        cfg.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("target"), "{err}");
    assert!(!out.exists());
}
