//! Issue 14 §2, memory initialisation that does not depend on the working directory: every
//! `$readmemh` file is a string parameter of the top (and of the testbench, which passes it
//! down), so a simulation run from another directory with absolute paths is exact, under
//! Icarus and Verilator. The checks can fail: without the parameters the same run stops on the
//! first missing file, and a bank parameter pointing at another bank's file gives mismatches,
//! which shows the path reaches the memory and not only the testbench's existence check.
//!
//! The tools are required when CI=true; elsewhere a missing tool skips.

use crate::hdl::{self, require, vector_count};
use crate::helpers;
use rmapgen::toolchain::{icarus, verilator};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The file parameters of `rmap_top_tb` with absolute paths into `dir`, and its vector file.
fn absolute_files(dir: &Path) -> (Vec<(String, String)>, PathBuf) {
    let design = rmapgen::design_dir::DesignDir::open(dir).expect("a generated design");
    design
        .testbench_files("rmap_top_tb")
        .expect("the top's testbench")
}

fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = vec![dir.join("tb/rmap_top_tb.v")];
    files.extend(hdl::design_files(dir));
    files
}

/// Compiles the top's testbench under Icarus with `strings`, runs it from `cwd`.
fn icarus_run(
    dir: &Path,
    cwd: &Path,
    strings: &[(String, String)],
    vectors: &Path,
) -> (Option<i32>, String) {
    let vvp = cwd.join("tb.vvp");
    let o = icarus::compile("rmap_top_tb", &vvp, &sources(dir), strings)
        .current_dir(cwd)
        .output()
        .expect("iverilog runs");
    assert!(
        o.status.success(),
        "iverilog: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let args = [format!("+vectors={}", vectors.display())];
    hdl::run_in(cwd, icarus::simulate(cwd, &vvp, &args))
}

#[test]
fn a_simulation_from_another_directory_with_absolute_paths_is_exact() {
    if !require("iverilog") || !require("verilator") {
        return;
    }
    let t = helpers::tempdir();
    let dir = t.path().join("design");
    hdl::generate(&dir, &[], 200);
    let n = vector_count(&dir, "rmap_top");
    let (files, vectors) = absolute_files(&dir);
    assert!(
        files.iter().any(|(p, _)| p == "RECIP_ROM_FILE")
            && files.iter().any(|(p, _)| p == "MAP_BANK_11_FILE")
            && files.iter().any(|(p, _)| p == "MAP2_Z_FILE"),
        "{files:?}"
    );
    let elsewhere = t.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();

    let run = icarus_run(&dir, &elsewhere, &files, &vectors);
    hdl::assert_passed("icarus from elsewhere", &run, n);

    let mdir = elsewhere.join("obj");
    let o = verilator::binary("rmap_top_tb", &mdir, &sources(&dir), &files)
        .unwrap()
        .output()
        .expect("verilator runs");
    assert!(
        o.status.success(),
        "verilator: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut c = Command::new(mdir.join(verilator::BINARY_EXE));
    c.arg(format!("+vectors={}", vectors.display()));
    hdl::assert_passed("verilator from elsewhere", &hdl::run_in(&elsewhere, c), n);

    // Planted fault 1: the same run without the parameters looks for the files in the
    // working directory, and stops naming the first one it misses.
    let (code, out) = icarus_run(&dir, &elsewhere, &[], &vectors);
    assert_ne!(code, Some(0), "{out}");
    assert!(
        out.contains("cannot open recip_rom.hex (RECIP_ROM_FILE)"),
        "{out}"
    );

    // Planted fault 2: bank 00 initialised from bank 11's file: the first map is wrong, so
    // the samples before the swap mismatch.
    let wrong: Vec<(String, String)> = files
        .iter()
        .map(|(p, v)| {
            if p == "MAP_BANK_00_FILE" {
                (p.clone(), dir.join("map_bank_11.hex").display().to_string())
            } else {
                (p.clone(), v.clone())
            }
        })
        .collect();
    let (code, out) = icarus_run(&dir, &elsewhere, &wrong, &vectors);
    assert_ne!(code, Some(0), "{out}");
    assert!(
        !hdl::last_line(&out).ends_with(" 0 failed"),
        "a wrong bank file must give mismatches: {out}"
    );
}

/// The top declares one parameter per init file, passes each down to the instance that reads
/// it, and the generated core declares the same parameters.
#[test]
fn every_init_file_is_a_parameter_of_the_top_and_of_the_core() {
    let t = helpers::tempdir();
    let dir = t.path().join("design");
    hdl::generate(&dir, &[], 0);
    let top = std::fs::read_to_string(dir.join("rmap_top.v")).unwrap();
    let core = std::fs::read_to_string(dir.join("rmap_top.core")).unwrap();
    let lookup = std::fs::read_to_string(dir.join("map_lookup.v")).unwrap();
    for (param, file) in [
        ("RECIP_ROM_FILE", "recip_rom.hex"),
        ("ATAN_ROM_FILE", "atan_rom.hex"),
        ("MAP_BANK_00_FILE", "map_bank_00.hex"),
        ("MAP_BANK_11_FILE", "map_bank_11.hex"),
    ] {
        assert!(
            top.contains(&format!("parameter {param}")) && top.contains(&format!("\"{file}\"")),
            "{param} in rmap_top.v"
        );
        assert!(
            top.contains(&format!(".{param} ({param})")),
            "{param} passed down"
        );
        assert!(
            core.contains(&format!(
                "  {param}:\n    datatype: str\n    paramtype: vlogparam\n    default: {file}\n"
            )),
            "{param} in the core"
        );
    }
    assert!(lookup.contains(".INIT_FILE (MAP_BANK_10_FILE)"), "{lookup}");
    // No quoted file name is left below the top's parameter list: every $readmemh reads a
    // parameter.
    for f in hdl::design_files(&dir) {
        let text = std::fs::read_to_string(&f).unwrap();
        for line in text.lines().filter(|l| l.contains("$readmemh")) {
            assert!(!line.contains('"'), "{}: {line}", f.display());
        }
    }
}
