//! Issue 14 §1, two configurations in one design: with `--prefix`, every module, file, hex
//! file, testbench, vector file and the FuseSoC core carry the prefix, so two generated
//! designs copied into one directory share no name. Their union, with a wrapper that
//! instantiates both tops side by side, lints clean under Verilator -Wall, and each top's own
//! testbench, compiled from the union, is exact against its model under Icarus and Verilator.
//! Without a prefix the names are as before (the golden output, rtl_generate.rs), and the
//! cores of two configurations still have different names.
//!
//! The tools are required when CI=true (a missing tool fails the test there); elsewhere a
//! missing tool skips with a message on stderr.

use crate::hdl::{self, config_of, require, vector_count};
use crate::helpers;
use rmapgen::config::Config;
use rmapgen::emit::manifest::{config_hash, Core};
use rmapgen::hdl::ports::{Dir, Width};
use rmapgen::stages::{self, TOP};
use std::collections::BTreeSet;
use std::path::Path;

/// The two designs: the default and a different one, each with its own prefix.
const DESIGNS: [(&str, &[&str]); 2] = [
    ("a_", &["--prefix", "a_"]),
    (
        "b_",
        &["--index-bits", "4", "--no-compensation", "--prefix", "b_"],
    ),
];

/// What every generated directory holds under the same name, whatever the prefix: files that
/// describe their own directory (and rmapgen's list of the files it wrote).
const DIRECTORY_FILES: &[&str] = &[
    ".rmapgen-files",
    "README.md",
    "manifest.json",
    "tb/config.toml",
    "tb/rmap_top_config.h",
];

/// `pair_top`: both tops side by side, sharing the clock and reset; every other port of a
/// top is a port of the wrapper named with that design's prefix.
fn wrapper(designs: &[Config]) -> String {
    let mut ports = vec![
        "  input  wire clk_i".to_string(),
        "  input  wire rst_ni".to_string(),
    ];
    let mut body = String::new();
    for cfg in designs {
        let p = &cfg.prefix;
        let mut pins = Vec::new();
        for port in TOP.ports(cfg) {
            let n = port.name;
            if n == "clk_i" || n == "rst_ni" {
                pins.push(format!("    .{n} ({n})"));
                continue;
            }
            let dir = match port.dir {
                Dir::Input => "input ",
                Dir::Output => "output",
            };
            let range = match port.width {
                Width::Bits(1) => String::new(),
                Width::Bits(b) => format!("[{}:0] ", b - 1),
                Width::Param(w) => panic!("top port {n} has a parameter width {w}"),
            };
            ports.push(format!("  {dir} wire {range}{p}{n}"));
            pins.push(format!("    .{n} ({p}{n})"));
        }
        body.push_str(&format!(
            "  {} u_{p}top (\n{}\n  );\n\n",
            TOP.module(cfg),
            pins.join(",\n")
        ));
    }
    format!(
        "`default_nettype none\n\n// Two generated designs side by side (tests/it/prefix.rs).\n\
         module pair_top (\n{}\n);\n\n{body}endmodule\n\n`default_nettype wire\n",
        ports.join(",\n")
    )
}

/// The modules a Verilog file declares.
fn declared(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("module "))
        .map(|l| {
            l.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .next()
                .unwrap()
                .to_string()
        })
        .collect()
}

/// The `.hex` file names quoted in a Verilog file (`$readmemh`, `$fopen`, INIT_FILE).
fn quoted_hex(text: &str) -> Vec<String> {
    text.split('"')
        .skip(1)
        .step_by(2)
        .filter(|s| s.ends_with(".hex"))
        .map(String::from)
        .collect()
}

#[test]
fn two_prefixed_designs_share_one_directory_and_both_are_exact() {
    let tmp = helpers::tempdir();
    let both = tmp.path().join("both");
    std::fs::create_dir_all(both.join("tb")).unwrap();
    std::fs::create_dir_all(both.join("vectors")).unwrap();
    let mut cfgs = Vec::new();
    let mut trees = Vec::new();
    for (prefix, flags) in DESIGNS {
        let dir = tmp.path().join(prefix);
        hdl::generate(&dir, flags, 300);
        let cfg = config_of(&dir);
        assert_eq!(cfg.prefix, prefix);
        let tree = helpers::tree(&dir);
        for (name, bytes) in &tree {
            if DIRECTORY_FILES.contains(&name.as_str()) {
                continue;
            }
            let file = name.rsplit('/').next().unwrap();
            assert!(file.starts_with(prefix), "{prefix}: {name} has no prefix");
            let text = String::from_utf8_lossy(bytes);
            if name.ends_with(".v") {
                // Every module it declares and every hex file it reads carry the prefix.
                for m in declared(&text) {
                    assert!(m.starts_with(prefix), "{name} declares {m}");
                }
                for h in quoted_hex(&text) {
                    let h = h.trim_start_matches("vectors/");
                    assert!(h.starts_with(prefix), "{name} reads {h}");
                    assert!(tree.contains_key(h) || tree.contains_key(&format!("vectors/{h}")));
                }
            }
            let to = both.join(name);
            assert!(!to.exists(), "{name} is in both designs");
            std::fs::write(&to, bytes).unwrap();
        }
        // The manifest lists the prefixed names; the core is named after the prefixed top.
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap())
                .unwrap();
        assert_eq!(m["top"], format!("{prefix}rmap_top"));
        for (info, unit) in m["modules"]
            .as_array()
            .unwrap()
            .iter()
            .zip(stages::modules(&cfg))
        {
            assert_eq!(info["name"], format!("{prefix}{}", unit.name()));
            assert_eq!(info["file"], format!("{prefix}{}.v", unit.name()));
        }
        let core = std::fs::read_to_string(dir.join(format!("{prefix}rmap_top.core"))).unwrap();
        assert!(
            core.contains(&format!("\nname: {}\n", Core::new(&cfg).name))
                && Core::new(&cfg)
                    .name
                    .starts_with(&format!("rmapgen:ip:{prefix}rmap_top_"))
                && core.contains(&format!("toplevel: {prefix}rmap_top_tb\n")),
            "{core}"
        );
        // `rmapgen vectors` reads the prefixed maps of the directory: the same stream as the
        // top's vector file for the same count and seed.
        let stream = tmp.path().join(format!("{prefix}stream.hex"));
        hdl::stream(&dir, 300, &stream);
        assert_eq!(
            std::fs::read(&stream).unwrap(),
            tree[&format!("vectors/{prefix}rmap_top.hex")]
        );
        trees.push(tree);
        cfgs.push(cfg);
    }
    // The two directories share only the files that describe them.
    let names = |t: &std::collections::BTreeMap<String, Vec<u8>>| -> BTreeSet<String> {
        t.keys().cloned().collect()
    };
    let shared: Vec<String> = names(&trees[0])
        .intersection(&names(&trees[1]))
        .cloned()
        .collect();
    assert_eq!(shared, DIRECTORY_FILES);
    // The cores of the two configurations differ in name; so would they without prefixes.
    assert_ne!(Core::new(&cfgs[0]).name, Core::new(&cfgs[1]).name);
    let bare = |c: &Config| Config {
        prefix: String::new(),
        ..c.clone()
    };
    assert_ne!(
        Core::new(&bare(&cfgs[0])).name,
        Core::new(&bare(&cfgs[1])).name
    );
    std::fs::write(both.join("pair_top.v"), wrapper(&cfgs)).unwrap();

    if require("verilator") {
        hdl::assert_lint_clean_top("both designs and pair_top", &both, "pair_top");
    }
    let icarus = require("iverilog") && require("vvp");
    let verilator = require("verilator");
    for cfg in &cfgs {
        let top = TOP.module(cfg);
        let n = vector_count(&both, &top);
        if icarus {
            let bin = hdl::icarus(&both, &top, tmp.path());
            hdl::assert_passed(
                &format!("{top} under Icarus"),
                &hdl::vvp(&both, &bin, hdl::NO_ARGS),
                n,
            );
        }
        if verilator {
            let bin = hdl::verilator(&both, &top, tmp.path());
            hdl::assert_passed(
                &format!("{top} under Verilator"),
                &hdl::sim(&both, &bin, hdl::NO_ARGS),
                n,
            );
        }
    }
}

#[test]
fn without_a_prefix_the_names_are_the_stage_names() {
    let cfg = Config::default();
    for m in stages::modules(&cfg) {
        assert_eq!(m.module(&cfg), m.name());
        assert_eq!(m.file(&cfg), format!("{}.v", m.name()));
    }
    assert_eq!(Core::new(&cfg).file, "rmap_top.core");
    // The hash is of the configuration: stable, eight hex digits, different for another.
    let h = config_hash(&cfg);
    assert_eq!(h, config_hash(&Config::default()));
    assert!(
        h.len() == 8 && h.bytes().all(|b| b.is_ascii_hexdigit()),
        "{h}"
    );
    assert_eq!(
        Core::new(&cfg).name,
        format!("rmapgen:ip:rmap_top_{h}:{}", env!("CARGO_PKG_VERSION"))
    );
    let other = Config {
        color: true,
        ..Config::default()
    };
    assert_ne!(config_hash(&other), h);
}

/// A prefixed design's stage testbenches need nothing of the unprefixed names: one stage
/// with a memory, run from its own directory.
#[test]
fn a_prefixed_stage_testbench_passes() {
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("d");
    hdl::generate(&dir, &["--prefix", "Shader2_", "--no-interpolation"], 100);
    for m in ["Shader2_normalise", "Shader2_map_lookup"] {
        let bin = hdl::icarus(&dir, m, tmp.path());
        hdl::assert_passed(
            m,
            &hdl::vvp(&dir, &bin, hdl::NO_ARGS),
            vector_count(&dir, m),
        );
    }
    assert!(Path::new(&dir.join("Shader2_map_bank.hex")).is_file());
}
