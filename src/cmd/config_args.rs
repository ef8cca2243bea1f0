//! The configuration flags shared by every command that builds a design: a TOML file, then
//! flags that override single fields. The result is validated once, here.

use crate::config::Config;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone, Default)]
pub struct ConfigArgs {
    /// Configuration TOML (fields as in `Config`); flags below override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Gradient component width, two's complement [8..=16, default 12].
    #[arg(long)]
    pub grad_bits: Option<u32>,
    /// Magnitude width after sort & shift [6..=12, <= grad-bits, default 8].
    #[arg(long)]
    pub red_bits: Option<u32>,
    /// Reciprocal ROM entry width [5..=20, >= frac-bits + 1, default 10].
    #[arg(long)]
    pub recip_bits: Option<u32>,
    /// Normalised fraction width; 2^frac-bits compensation ROM entries [4..=12, default 8].
    #[arg(long)]
    pub frac_bits: Option<u32>,
    /// Map index bits per component [2..=6, default 3].
    #[arg(long)]
    pub index_bits: Option<u32>,
    /// Interpolation fraction bits [0..=5, 0 iff interpolation is off, default 3].
    #[arg(long)]
    pub interp_bits: Option<u32>,
    /// Map entry and output intensity width [6..=12, default 8].
    #[arg(long)]
    pub map_bits: Option<u32>,
    /// Leave out distortion compensation (no atan ROM; linear index).
    #[arg(long)]
    pub no_compensation: bool,
    /// Leave out the interpolator (nearest entry; implies --interp-bits 0).
    #[arg(long)]
    pub no_interpolation: bool,
    /// Add the 8-bit RGB colour multiplier.
    #[arg(long)]
    pub color: bool,
    /// Pipeline registers: 0 compact (lowest latency), 1 and 2 add registers for clock rate
    /// [0..=2, default 2].
    #[arg(long, value_name = "N")]
    pub pipeline_depth: Option<u32>,
    /// Valid/ready handshake on the top (backpressure stalls the pipeline) instead of a
    /// plain valid stream.
    #[arg(long)]
    pub handshake: bool,
}

impl ConfigArgs {
    pub fn resolve(&self) -> Result<Config> {
        let mut c = match &self.config {
            Some(p) => Config::from_toml_file(p)?,
            None => Config::default(),
        };
        macro_rules! set {
            ($($f:ident),*) => { $( if let Some(v) = self.$f { c.$f = v; } )* };
        }
        set!(
            grad_bits,
            red_bits,
            recip_bits,
            frac_bits,
            index_bits,
            map_bits,
            pipeline_depth
        );
        if self.no_compensation {
            c.compensation = false;
        }
        if self.no_interpolation {
            c.interpolation = false;
            c.interp_bits = 0;
        }
        if let Some(p) = self.interp_bits {
            c.interp_bits = p;
        }
        if self.color {
            c.color = true;
        }
        if self.handshake {
            c.handshake = true;
        }
        c.validate()?;
        Ok(c)
    }
}
