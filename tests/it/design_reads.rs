//! A command given a design reads the design (issue 32, part 1): its configuration, prefix and
//! files come from its manifest.json; a flag that contradicts it is refused in one line, and
//! nothing changes. `roms --update` writes the design again for new maps so that it passes its
//! own testbenches; a testbench's every mismatch line shows the expected and the actual value.

use crate::hdl::{self, last_line, require, vector_count, vvp};
use crate::helpers::{assert_error, run_in, tempdir, text, tree};
use std::path::Path;
use std::process::Output;

fn ok(o: &Output) -> String {
    let t = text(o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    t
}

/// The design of the issue: 10-bit gradient, 4 index bits, colour, the handshake, a prefix.
const IP10: &[&str] = &[
    "--grad-bits",
    "10",
    "--index-bits",
    "4",
    "--color",
    "--handshake",
    "--prefix",
    "vr_",
];

const MY_SCENE: &str = "map_fit = \"lsq\"\n\n[material]\nambient = 0.05\ndiffuse = 0.5\n\
specular = 0.45\nshininess = 60.0\n\n[[light]]\ndirection = [-1.0, 0.5, 1.5]\nintensity = 1.0\n";

fn generate_ip10(dir: &Path) {
    let mut args = vec!["generate", "--vectors", "300", "--out", "ip10"];
    args.extend(IP10);
    ok(&run_in(dir, &args));
    std::fs::write(dir.join("my.toml"), MY_SCENE).unwrap();
}

#[test]
fn roms_update_reads_the_design_and_leaves_it_consistent() {
    let t = tempdir();
    generate_ip10(t.path());
    let d = t.path().join("ip10");
    let before = tree(&d);

    // Flags that contradict the design are refused, naming both sides; nothing changes.
    for (flags, says) in [
        (
            vec!["--grad-bits", "12"],
            "--grad-bits 12 sets grad_bits 12, the design has 10",
        ),
        (
            vec!["--prefix", "xx_"],
            "--prefix xx_ sets prefix \"xx_\", the design has \"vr_\"",
        ),
        (
            vec!["--lanes", "2"],
            "--lanes 2 sets lanes 2, the design has its default",
        ),
    ] {
        let mut args = vec!["roms", "--update", "ip10", "--scene", "my.toml"];
        args.extend(flags);
        assert_error(&run_in(t.path(), &args), says);
        assert_eq!(tree(&d), before, "{says}: the design is unchanged");
    }
    // A configuration file other than the design's: refused too.
    std::fs::write(t.path().join("c.toml"), "grad_bits = 10\n").unwrap();
    assert_error(
        &run_in(
            t.path(),
            &["roms", "--update", "ip10", "--config", "c.toml"],
        ),
        "config c.toml sets color false, the design has true",
    );
    assert_eq!(tree(&d), before);

    // The update, with a flag that agrees with the design and its own config file.
    let o = run_in(
        t.path(),
        &[
            "roms",
            "--update",
            "ip10",
            "--scene",
            "my.toml",
            "--grad-bits",
            "10",
            "--config",
            "ip10/tb/config.toml",
        ],
    );
    let said = ok(&o);
    assert!(
        said.contains("to the maps of scene my.toml (map_fit lsq)"),
        "{said}"
    );
    assert!(said.contains("prefix=vr_"), "{said}");
    let after = tree(&d);
    // The same files, none added (no unprefixed G12 files beside the design).
    assert_eq!(
        after.keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>()
    );
    let changed: Vec<&String> = after.keys().filter(|f| after[*f] != before[*f]).collect();
    for f in [
        "vr_map_x.hex",
        "vr_map_bank_00.hex",
        "vectors/vr_rmap_top.hex",
        "README.md",
        "manifest.json",
    ] {
        assert!(
            changed.iter().any(|c| c.as_str() == f),
            "{f} changed: {changed:?}"
        );
    }
    for f in &changed {
        assert!(!f.ends_with(".v"), "the Verilog is unchanged: {f}");
    }
    let readme = std::fs::read_to_string(d.join("README.md")).unwrap();
    assert!(
        readme.contains("scene `my.toml`, filled with `map_fit = \"lsq\"`"),
        "README"
    );
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["scene_name"], "my.toml");
    assert_eq!(manifest["scene"]["material"]["shininess"], 60.0);
    assert_eq!(manifest["vectors"]["random"], 300);

    // Without --scene the design keeps its own scene; --map-fit changes only the fit.
    let said = ok(&run_in(
        t.path(),
        &["roms", "--update", "ip10", "--map-fit", "sample"],
    ));
    assert!(said.contains("scene my.toml (map_fit sample)"), "{said}");
    let readme = std::fs::read_to_string(d.join("README.md")).unwrap();
    assert!(readme.contains("scene `my.toml`, filled with `map_fit = \"sample\"`"));

    // The updated design passes its own top testbench; the vectors of the old maps fail it,
    // and every mismatch line, also past the first few shown in full, says what was
    // expected and what came out.
    if !require("iverilog") || !require("vvp") {
        return;
    }
    let old_vectors = t.path().join("old_top.hex");
    std::fs::write(&old_vectors, &before["vectors/vr_rmap_top.hex"]).unwrap();
    let bin = hdl::icarus(&d, "vr_rmap_top", t.path());
    let n = vector_count(&d, "vr_rmap_top");
    hdl::assert_passed("updated design", &vvp(&d, &bin, hdl::NO_ARGS), n);
    let (code, out) = vvp(&d, &bin, &[format!("+vectors={}", old_vectors.display())]);
    assert_eq!(code, Some(1), "{out}");
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("MISMATCH")).collect();
    assert!(lines.len() > 20, "many samples see other maps: {out}");
    let last = lines.last().unwrap();
    assert!(
        last.contains(": expected ") && last.contains(", got "),
        "a mismatch line past the detailed ones: {last}"
    );
    assert!(last_line(&out).ends_with(" failed"), "{out}");
}

#[test]
fn other_commands_given_a_design_take_its_configuration() {
    let t = tempdir();
    generate_ip10(t.path());
    // vectors --maps reads the prefixed design's configuration and maps.
    let said = ok(&run_in(
        t.path(),
        &[
            "vectors", "--maps", "ip10", "--count", "50", "--out", "v.hex",
        ],
    ));
    assert!(said.contains("G10 R8"), "{said}");
    assert_error(
        &run_in(
            t.path(),
            &[
                "vectors",
                "--maps",
                "ip10",
                "--index-bits",
                "3",
                "--count",
                "5",
                "--out",
                "w.hex",
            ],
        ),
        "--index-bits 3 sets index_bits 3, the design has 4",
    );
    assert!(!t.path().join("w.hex").exists());
    // fpga --dir: a contradicting flag is refused before anything is made (no tool runs).
    assert_error(
        &run_in(
            t.path(),
            &[
                "fpga",
                "--dir",
                "ip10",
                "--no-compensation",
                "--logs",
                "logs",
            ],
        ),
        "--no-compensation sets compensation false, the design has true",
    );
    assert!(!t.path().join("logs").exists());

    // generate over a design of another configuration says what it replaces.
    let said = ok(&run_in(
        t.path(),
        &["generate", "--vectors", "10", "--out", "ip10"],
    ));
    assert!(
        said.contains("wrote ip10: ")
            && said.contains("(replacing a design of grad_bits=10 red_bits=8 recip_bits=10 frac_bits=8 index_bits=4 interp_bits=3 map_bits=8 compensation=true interpolation=true color=true pipeline_depth=2 handshake=true prefix=vr_)")
            && said.contains("\n  grad_bits=12 "),
        "{said}"
    );
    // ... and nothing when the configuration is the same.
    let said = ok(&run_in(
        t.path(),
        &["generate", "--vectors", "10", "--out", "ip10"],
    ));
    assert!(!said.contains("replacing"), "{said}");
}

#[test]
fn the_stream_harness_runs_a_prefixed_design() {
    if !require("verilator") {
        return;
    }
    let t = tempdir();
    generate_ip10(t.path());
    let o = run_in(
        t.path(),
        &["sim", "ip10", "--stream", "500", "--build", "b"],
    );
    let said = ok(&o);
    assert!(
        said.contains("ok:   verilator top_stream (C++): "),
        "{said}"
    );
    assert!(said.contains("sim: all passed"), "{said}");
}
