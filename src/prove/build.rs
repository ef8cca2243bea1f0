//! The two Verilator builds of `rmapgen prove`, each a shared object that [`super::ffi`]
//! loads: the design's front (its zero detect and sort & shift modules, unchanged, inside a
//! wrapper written here) and the design's top, both from the generated files themselves.

use super::front::FRONT;
use crate::design_dir::DesignDir;
use crate::stages::TOP;
use crate::toolchain::{run_logged, verilator};
use crate::vectors::field::Dir;
use anyhow::{bail, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const FRONT_HARNESS: &str = include_str!("../../tb/prove_front.cpp");
const TOP_HARNESS: &str = include_str!("../../tb/prove_top.cpp");

/// The wrapper's module name (also its Verilator class, `Vprove_front`).
pub const FRONT_MODULE: &str = "prove_front";

/// The front wrapper: each module of [`FRONT`] as the design instantiates it (enable high,
/// the gradient on its gradient ports), its valid bit on `<name>_valid_o` and its other
/// outputs packed into `<name>_o`, the first output field in the low bits (the order
/// [`super::front::pack`] uses). Not part of the design: it only gives the harness one port
/// per module.
pub fn front_wrapper(d: &DesignDir) -> String {
    let cfg = &d.config;
    let g = cfg.grad_bits;
    let mut ports = vec![
        "  input  wire clk_i".to_string(),
        "  input  wire rst_ni".to_string(),
        "  input  wire valid_i".to_string(),
    ];
    for c in ["gx", "gy", "gz"] {
        ports.push(format!("  input  wire [{}:0] {c}_i", g - 1));
    }
    let mut body = String::new();
    for unit in FRONT {
        let name = unit.name();
        let outs: Vec<_> = unit
            .fields(cfg)
            .into_iter()
            .filter(|f| f.dir == Dir::Out)
            .collect();
        let width: u32 = outs.iter().map(|f| f.bits).sum();
        ports.push(format!("  output wire {name}_valid_o"));
        ports.push(format!("  output wire [{}:0] {name}_o", width - 1));
        let _ = writeln!(body, "  {} u_{name} (", unit.module(cfg));
        let mut conns = vec![
            ".clk_i   (clk_i)".to_string(),
            ".rst_ni  (rst_ni)".to_string(),
            ".en_i    (1'b1)".to_string(),
            ".valid_i (valid_i)".to_string(),
            ".gx_i    (gx_i)".to_string(),
            ".gy_i    (gy_i)".to_string(),
            ".gz_i    (gz_i)".to_string(),
            format!(".valid_o ({name}_valid_o)"),
        ];
        let mut lsb = 0;
        for f in &outs {
            let port = unit.port(f).unwrap_or_else(|| format!("{}_o", f.name));
            conns.push(format!(".{port} ({name}_o[{}:{lsb}])", lsb + f.bits - 1));
            lsb += f.bits;
        }
        let _ = writeln!(body, "    {}\n  );", conns.join(",\n    "));
    }
    format!(
        "// {FRONT_MODULE}.v: written by `rmapgen prove` for Verilator; not part of the design.\n\
         // The modules of the design that read the gradient, unchanged, one port per module.\n\
         `default_nettype none\n\nmodule {FRONT_MODULE} (\n{}\n);\n\n{body}\nendmodule\n\n`default_nettype wire\n",
        ports.join(",\n")
    )
}

/// Builds `lib` (a shared object) in `mdir` from `files` with `harness`; the log goes to
/// `mdir/verilator.log`.
fn shared(
    top: &str,
    prefix: &str,
    mdir: &Path,
    files: &[PathBuf],
    harness: &Path,
    include: &Path,
    strings: &[(String, String)],
) -> Result<PathBuf> {
    std::fs::create_dir_all(mdir)?;
    let lib = format!("lib{prefix}.so");
    let mut cmd = verilator::shared(top, prefix, mdir, &lib, files, harness, include, strings);
    let ran = run_logged(&mut cmd, &mdir.join("verilator.log"))?;
    if !ran.success() {
        let first_error = ran
            .output
            .lines()
            .find(|l| l.contains("error:") || l.starts_with("%Error"))
            .unwrap_or("")
            .to_string();
        bail!(
            "Verilator could not build {top} ({}; {}): {first_error}",
            ran.exit(),
            mdir.join("verilator.log").display()
        );
    }
    Ok(mdir.join(lib))
}

/// The front's shared object, built in `build/front`.
pub fn front(d: &DesignDir, build: &Path) -> Result<PathBuf> {
    let dir = build.join("front");
    std::fs::create_dir_all(&dir)?;
    let wrapper = dir.join(format!("{FRONT_MODULE}.v"));
    std::fs::write(&wrapper, front_wrapper(d))?;
    let harness = dir.join("prove_front.cpp");
    std::fs::write(&harness, FRONT_HARNESS)?;
    let mut files: Vec<PathBuf> = FRONT
        .iter()
        .map(|u| d.path().join(u.file(&d.config)))
        .collect();
    files.push(wrapper);
    shared(
        FRONT_MODULE,
        "Vprove_front",
        &dir.join("obj"),
        &files,
        &harness,
        &dir,
        &[],
    )
}

/// The top's shared object (the design's rmap_top, also inside an AXI4-Stream design),
/// built in `build/top`, its memories read from the design directory by absolute path.
pub fn top(d: &DesignDir, build: &Path) -> Result<PathBuf> {
    let dir = build.join("top");
    std::fs::create_dir_all(&dir)?;
    let harness = dir.join("prove_top.cpp");
    std::fs::write(&harness, TOP_HARNESS)?;
    shared(
        &TOP.module(&d.config),
        "Vrmap_top",
        &dir.join("obj"),
        &d.files(),
        &harness,
        &d.path().join("tb"),
        &d.top_files()?,
    )
}
