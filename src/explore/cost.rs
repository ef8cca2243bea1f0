//! placeholder
use crate::config::Config;
use crate::scene::Scene;
use anyhow::Result;

pub fn judge(_cfg: &Config, _scene: &Scene, _size: u32, _volume: bool) -> Result<()> {
    Ok(())
}
