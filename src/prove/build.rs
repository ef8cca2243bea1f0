//! The two Verilator builds of `rmapgen prove`, each a shared object that [`super::ffi`]
//! loads: the design's front (its zero detect and sort & shift modules, unchanged, inside a
//! wrapper written here) and the design's top, both from the generated files themselves.

use super::front::FRONT;
use crate::config::Config;
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

/// Copies of the front side by side in the wrapper: one evaluation of the model clocks
/// them all, which spreads its fixed cost (about a fifth of the time at one copy).
pub const FRONT_LANES: usize = 4;

/// A chunk of the front's check holds at least one group of the lanes (each call advances).
const _: () = assert!(super::front::CHUNK >= FRONT_LANES);

/// The front wrapper: `copies` copies of each module of [`FRONT`] as the design
/// instantiates it (enable high, the gradient on its gradient ports), copy k's gradient on
/// `g{x,y,z}<k>_i`, with `valid` its valid bit on `<name>_valid_o` (copy 0's: all move together) and its
/// other outputs packed into `<name><k>_o`, the first output field in the low bits (the order
/// [`super::front::pack`] uses). Not part of the design: it only gives the harness ports.
pub fn front_wrapper(cfg: &Config, copies: usize, valid: bool) -> String {
    let g = cfg.grad_bits;
    let mut ports = vec![
        "  input  wire clk_i".to_string(),
        "  input  wire rst_ni".to_string(),
        "  input  wire valid_i".to_string(),
    ];
    let mut body = String::new();
    for k in 0..copies {
        for c in ["gx", "gy", "gz"] {
            ports.push(format!("  input  wire [{}:0] {c}{k}_i", g - 1));
        }
    }
    for unit in FRONT {
        let name = unit.name();
        let outs: Vec<_> = unit
            .fields(cfg)
            .into_iter()
            .filter(|f| f.dir == Dir::Out)
            .collect();
        let width: u32 = outs.iter().map(|f| f.bits).sum();
        if valid {
            ports.push(format!("  output wire {name}_valid_o"));
        }
        for k in 0..copies {
            ports.push(format!("  output wire [{}:0] {name}{k}_o", width - 1));
            let valid = if k == 0 && valid {
                format!("{name}_valid_o")
            } else {
                String::new()
            };
            let _ = writeln!(body, "  {} u_{name}{k} (", unit.module(cfg));
            let mut conns = vec![
                ".clk_i   (clk_i)".to_string(),
                ".rst_ni  (rst_ni)".to_string(),
                ".en_i    (1'b1)".to_string(),
                ".valid_i (valid_i)".to_string(),
                format!(".gx_i    (gx{k}_i)"),
                format!(".gy_i    (gy{k}_i)"),
                format!(".gz_i    (gz{k}_i)"),
                format!(".valid_o ({valid})"),
            ];
            let mut lsb = 0;
            for f in &outs {
                let port = unit.port(f).unwrap_or_else(|| format!("{}_o", f.name));
                conns.push(format!(".{port} ({name}{k}_o[{}:{lsb}])", lsb + f.bits - 1));
                lsb += f.bits;
            }
            let _ = writeln!(body, "    {}\n  );", conns.join(",\n    "));
        }
    }
    format!(
        "// {FRONT_MODULE}.v: written by `rmapgen prove` for the front's engine; not part of the design.\n\
         // The modules of the design that read the gradient, unchanged, {copies} copies side by side.\n\
         `default_nettype none\n\nmodule {FRONT_MODULE} (\n{}\n);\n\n{body}\nendmodule\n\n`default_nettype wire\n",
        ports.join(",\n")
    )
}

/// `prove_front_lanes.h`, which tb/prove_front.cpp includes: the number of copies and how
/// to apply a group of gradients and collect a group of results, port by port.
pub fn front_lanes_header() -> String {
    let [zero, sort] = FRONT.map(|u| u.name());
    let mut apply = String::new();
    let mut zeros = String::new();
    let mut sorts = String::new();
    for k in 0..FRONT_LANES {
        let _ = write!(
            apply,
            " t.gx{k}_i = g[{}]; t.gy{k}_i = g[{}]; t.gz{k}_i = g[{}];",
            3 * k,
            3 * k + 1,
            3 * k + 2
        );
        let _ = write!(zeros, " z[{k}] = t.{zero}{k}_o;");
        let _ = write!(sorts, " s[{k}] = t.{sort}{k}_o;");
    }
    format!(
        "// prove_front_lanes.h: written by `rmapgen prove` for tb/prove_front.cpp.\n\
         #pragma once\n\
         #define RP_LANES {FRONT_LANES}\n\
         #define RP_APPLY(t, g) do {{{apply} }} while (0)\n\
         #define RP_ZERO_VALID(t) (t.{zero}_valid_o)\n\
         #define RP_SORT_VALID(t) (t.{sort}_valid_o)\n\
         #define RP_ZEROS(t, z) do {{{zeros} }} while (0)\n\
         #define RP_SORTS(t, s) do {{{sorts} }} while (0)\n"
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
    crate::disk::create_dir_all(mdir)?;
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

/// Where [`top`] puts the top's shared object in `build`.
pub fn top_lib(build: &Path) -> PathBuf {
    build
        .join("top")
        .join("obj")
        .join(format!("lib{TOP_PREFIX}.so"))
}

/// Where [`front`] puts the front's shared object in `build`.
pub fn front_lib(build: &Path) -> PathBuf {
    build
        .join("front")
        .join("obj")
        .join(format!("lib{FRONT_PREFIX}.so"))
}

/// The Verilated classes' prefixes (the libraries' names).
const TOP_PREFIX: &str = "Vrmap_top";
const FRONT_PREFIX: &str = "Vprove_front";

/// The front's shared object, built in `build/front` (at [`front_lib`]).
pub fn front(d: &DesignDir, build: &Path) -> Result<PathBuf> {
    let dir = build.join("front");
    crate::disk::create_dir_all(&dir)?;
    let wrapper = dir.join(format!("{FRONT_MODULE}.v"));
    crate::disk::write(&wrapper, front_wrapper(&d.config, FRONT_LANES, true))?;
    let harness = dir.join("prove_front.cpp");
    crate::disk::write(&harness, FRONT_HARNESS)?;
    crate::disk::write(&dir.join("prove_front_lanes.h"), front_lanes_header())?;
    let mut files: Vec<PathBuf> = FRONT
        .iter()
        .map(|u| d.path().join(u.file(&d.config)))
        .collect();
    files.push(wrapper);
    shared(
        FRONT_MODULE,
        FRONT_PREFIX,
        &dir.join("obj"),
        &files,
        &harness,
        &dir,
        &[],
    )
}

/// The top's shared object (the design's rmap_top, also inside an AXI4-Stream design),
/// built in `build/top` (at [`top_lib`]), its memories read from the design directory by
/// absolute path.
pub fn top(d: &DesignDir, build: &Path) -> Result<PathBuf> {
    let dir = build.join("top");
    crate::disk::create_dir_all(&dir)?;
    let harness = dir.join("prove_top.cpp");
    crate::disk::write(&harness, TOP_HARNESS)?;
    shared(
        &TOP.module(&d.config),
        TOP_PREFIX,
        &dir.join("obj"),
        &d.files(),
        &harness,
        &d.path().join("tb"),
        &d.top_files()?,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prove::front::{pack, widths};

    /// The wrapper's lines for copy `k` of module `name`: its instance and connections.
    fn instance<'a>(v: &'a str, name: &str, k: usize) -> &'a str {
        let head = format!("u_{name}{k} (");
        let at = v.find(&head).unwrap_or_else(|| panic!("no {head} in\n{v}"));
        let end = at + v[at..].find(");").unwrap();
        &v[at..end]
    }

    #[test]
    fn the_wrapper_packs_each_copy_as_the_model_packs_it() {
        let cfg = Config {
            grad_bits: 8,
            red_bits: 6,
            ..Config::default()
        };
        let v = front_wrapper(&cfg, 2, true);
        for k in 0..2 {
            for c in ["gx", "gy", "gz"] {
                assert!(
                    v.contains(&format!("input  wire [7:0] {c}{k}_i")),
                    "{c}{k}\n{v}"
                );
            }
        }
        for unit in FRONT {
            let name = unit.name();
            let w = widths(unit, &cfg);
            let total: u32 = w.iter().map(|(_, b)| b).sum();
            assert!(v.contains(&format!("output wire {name}_valid_o")), "{v}");
            for k in 0..2 {
                assert!(v.contains(&format!("output wire [{}:0] {name}{k}_o", total - 1)));
                let inst = instance(&v, name, k);
                assert!(inst.contains(&format!(".gx_i    (gx{k}_i)")), "{inst}");
                assert!(inst.contains(&format!(".gz_i    (gz{k}_i)")), "{inst}");
                let valid = if k == 0 {
                    format!("{name}_valid_o")
                } else {
                    String::new()
                };
                assert!(inst.contains(&format!(".valid_o ({valid})")), "{inst}");
                // Each output field's slice holds what pack puts there: a field of all ones
                // alone packs to exactly the slice's bits.
                let fields: Vec<_> = unit
                    .fields(&cfg)
                    .into_iter()
                    .filter(|f| f.dir == Dir::Out)
                    .collect();
                for (i, f) in fields.iter().enumerate() {
                    let mut values = vec![0u64; w.len()];
                    values[i] = (1 << f.bits) - 1;
                    let word = pack(&values, &w);
                    let (lsb, msb) = (word.trailing_zeros(), 63 - word.leading_zeros());
                    let port = unit.port(f).unwrap_or_else(|| format!("{}_o", f.name));
                    let conn = format!(".{port} ({name}{k}_o[{msb}:{lsb}])");
                    assert!(inst.contains(&conn), "{conn} not in {inst}");
                }
            }
        }
        // Without the valid outputs, no copy drives one.
        let v = front_wrapper(&cfg, 1, false);
        assert!(!v.contains("_valid_o"), "{v}");
        assert!(instance(&v, FRONT[0].name(), 0).contains(".valid_o ()"));
    }

    #[test]
    fn the_lanes_header_applies_and_collects_every_lane() {
        let h = front_lanes_header();
        let [zero, sort] = FRONT.map(|u| u.name());
        assert!(
            h.contains(&format!("#define RP_LANES {FRONT_LANES}\n")),
            "{h}"
        );
        for k in 0..FRONT_LANES {
            let apply = format!(
                " t.gx{k}_i = g[{}]; t.gy{k}_i = g[{}]; t.gz{k}_i = g[{}];",
                3 * k,
                3 * k + 1,
                3 * k + 2
            );
            assert!(h.contains(&apply), "{apply}\n{h}");
            assert!(h.contains(&format!(" z[{k}] = t.{zero}{k}_o;")), "{h}");
            assert!(h.contains(&format!(" s[{k}] = t.{sort}{k}_o;")), "{h}");
        }
        assert!(h.contains(&format!("#define RP_ZERO_VALID(t) (t.{zero}_valid_o)")));
        assert!(h.contains(&format!("#define RP_SORT_VALID(t) (t.{sort}_valid_o)")));
    }
}
