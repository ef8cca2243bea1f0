//! Writing a design: every module of the configuration (each rendered by its own unit in
//! `crate::stages`), the ROM and map init files, the FuseSoC core and README of [`package`],
//! and `manifest.json`. docs/ARCHITECTURE.md is the specification; the units are its tables
//! in code, and everything here walks them.

pub mod dir;
pub mod manifest;
pub mod package;
pub mod tb;

use crate::design::Design;
pub use crate::hdl::{Dir, Port, Width};
use crate::hexfile;
use crate::model::map_set::{map_file, AXES, TABLE};
use crate::output::StagedDir;
use crate::stages::map_bank::banks;
use crate::stages::{self, Head};
use anyhow::{Context, Result};
pub use manifest::Manifest;

/// Every `$readmemh` file of a design: recip_rom.hex, atan_rom.hex (with compensation), the
/// scene's logical maps map_<axis>.hex, the second map map2_<axis>.hex (the alternate scene's,
/// which testbenches load through the host port) and the map banks' init files, each name
/// with the configuration's prefix. `generate` and `roms` both write exactly these.
pub fn hex_files(design: &Design) -> Vec<(String, String)> {
    let cfg = design.cfg();
    let maps = &design.maps;
    let mut v = hexfile::all(&design.model, &maps.scene);
    let alt = &maps.second;
    for (axis, name) in AXES.iter().enumerate() {
        let what = format!(
            "second reflectance map (scene two_lights), max axis {name}, address {{s_max, s_u, i_u, s_v, i_v}}"
        );
        v.push((
            map_file(cfg, 1, name),
            hexfile::format(cfg, &what, cfg.map_bits, alt.axis(axis as u32)),
        ));
    }
    if let Some(table) = &alt.table {
        v.push((
            map_file(cfg, 1, TABLE),
            hexfile::format(
                cfg,
                "second compensation table (the linear index's positions), address u",
                cfg.pos_bits(),
                table,
            ),
        ));
    }
    v.extend(banks::bank_files(cfg, &maps.scene));
    v
}

/// Writes every module's `.v`, the ROM and map init files, the logical maps of the scene
/// (`map_<axis>.hex`) and of the alternate scene (`map2_<axis>.hex`, which testbenches load
/// through the host port), the FuseSoC core and README of [`package`], and `manifest.json`.
/// Returns the manifest. The caller builds `design` once and hands the same value to the
/// vectors and the testbenches.
pub fn write_design(
    design: &Design,
    out: &StagedDir,
    vectors: Option<manifest::VectorsInfo>,
) -> Result<Manifest> {
    let cfg = design.cfg();
    let mut files = Vec::new();
    let mut write = |name: String, text: &str| -> Result<()> {
        out.write_text(&name, text)?;
        files.push(name);
        Ok(())
    };
    for m in stages::modules(cfg) {
        let text = m
            .render(cfg, Head::new(cfg, m))
            .with_context(|| format!("cannot render src/stages/{0}/{0}.v", m.name()))?;
        write(m.file(cfg), &text)?;
    }
    for (name, text) in hex_files(design) {
        write(name, &text)?;
    }
    for m in stages::modules(cfg) {
        for (name, text) in m.files(cfg)? {
            write(name, &text)?;
        }
    }
    write(manifest::Core::new(cfg).file, &package::core(cfg)?)?;
    write(package::README_FILE.into(), &package::readme(design)?)?;
    files.push(manifest::FILE.to_string());
    let manifest = Manifest::new(cfg, &design.scene, vectors, files);
    out.write_text(manifest::FILE, &manifest.to_json())?;
    Ok(manifest)
}
