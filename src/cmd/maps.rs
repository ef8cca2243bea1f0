//! `rmapgen maps`: one frame's maps as the host write port's stream (axis, address, data, in
//! write order), as hex, raw binary or a C array ([`crate::map_stream`]), for a host driver
//! to send each frame. The maps are the design's: the same value `generate` writes.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::design::Design;
use crate::map_stream::{self, Format};
use crate::output::StagedFile;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct MapsArgs {
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
    let cfg = a.cfg.resolve()?;
    let scene = a.map.scene_for(&cfg)?;
    let policy = a.force.policy(&[a.cfg.config.as_deref(), a.map.input()]);
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
