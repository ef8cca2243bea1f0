//! `rmapgen maps`: one frame's maps as the host write port's stream (axis, address, data, in
//! write order), as hex, raw binary or a C array ([`crate::map_stream`]), for a host driver
//! to send each frame. The maps are the design's: the same value `generate` writes.
//!
//! The configuration is a generated design's (`rmapgen maps DIR`: its manifest's, which
//! configuration flags may only agree with, as for every command given a design), or the one
//! `--config` and the configuration flags describe; given neither, `maps` refuses rather than
//! assume the default design (its header and C names would be wrong for any other).

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design::Design;
use crate::design_dir::DesignDir;
use crate::map_stream::{self, Format};
use crate::output::StagedFile;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MapsArgs {
    /// The generated design whose maps to write (`rmapgen generate --out DIR`): its
    /// configuration, prefix and scene (manifest.json); --scene and --map-fit give a new
    /// frame's maps for it, configuration flags may only agree with it.
    #[arg(value_name = "DIR")]
    pub dir: Option<PathBuf>,
    #[command(flatten)]
    pub cfg: ConfigArgs,
    #[command(flatten)]
    pub map: MapArgs,
    /// hex: one write per line, `axis address data`; bin: 6-byte records of three
    /// little-endian u16 (axis, address, data); c: a C array of {axis, address, data}.
    #[arg(long, value_enum, default_value_t = Format::Hex)]
    pub format: Format,
    /// File to write (replaced only when complete; an existing file only if rmapgen wrote it
    /// in this format, or with --force).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

pub fn run(a: &MapsArgs) -> Result<()> {
    let (cfg, scene) = match &a.dir {
        Some(dir) => {
            let design = DesignDir::open(dir)?;
            let cfg = a.cfg.for_design(&design.config, dir)?;
            // The design's own scene unless --scene names the new frame's.
            let scene = a.map.scene_or(|| {
                design.scene.clone().with_context(|| {
                    format!(
                        "{}: its {} records no scene (written by an older rmapgen): give --scene",
                        dir.display(),
                        crate::emit::manifest::FILE
                    )
                })
            })?;
            scene.map_fit.check(&cfg)?;
            (cfg, scene)
        }
        None if !a.cfg.any() => bail!(
            "maps: give the design (rmapgen maps DIR) or its configuration (--config FILE or the flags it was generated with); the maps, the header and the C names depend on it, and maps does not assume the default design"
        ),
        None => {
            let cfg = a.cfg.resolve()?;
            (cfg.clone(), a.map.scene_for(&cfg)?)
        }
    };
    let policy = a
        .force
        .policy(&[a.cfg.config.as_deref(), a.map.input(), a.dir.as_deref()]);
    let out = StagedFile::new(&a.out, &policy)?;
    // The design's own maps (buffer 0, what map_<axis>.hex and the bank init files hold).
    let design = Design::for_scene(&cfg, &scene)?;
    let bytes = map_stream::encode(&cfg, &scene, &design.maps.scene, a.format);
    out.write(&bytes)?;
    let p = out.commit()?;
    crate::errln!(
        "rmapgen: wrote {} host writes ({}, scene {}, map_fit {}) to {}",
        map_stream::write_count(&cfg),
        cfg.summary(),
        scene.name,
        scene.map_fit.name(),
        p.display()
    );
    Ok(())
}
