//! The renderer `--caster` picks ([`Renderer`]): the ray caster ([`super::cast`]) or
//! shear-warp ([`super::shear`]), behind one interface for the report and the command line:
//! a fused render with any [`Shader`], and a batch render through an
//! [`IntensitySource`] (the Verilated RTL) that gathers the contributing samples, shades
//! them in one batch and composites them in the fused path's order.

use super::cast::frame::Frame;
use super::cast::options::{CastOptions, CasterKind};
use super::cast::shader::Shader;
use super::cast::Caster;
use super::shear::{Classified, ShearWarp};
use crate::config::Config;
use crate::model::IntensitySource;
use anyhow::{bail, Result};

pub enum Renderer<'a> {
    Ray(Caster<'a>),
    ShearWarp(ShearWarp<'a>),
}

impl<'a> Renderer<'a> {
    /// The renderer of `opts.caster` for a classified volume (its prepared volume and
    /// transfer function) and a view direction (from the volume towards the viewer).
    pub fn new(cl: &'a Classified<'a>, view: [f64; 3], opts: CastOptions) -> Result<Self> {
        Ok(match opts.caster {
            CasterKind::Ray => Renderer::Ray(Caster::new(cl.prepared, &cl.transfer, view, opts)?),
            CasterKind::ShearWarp => Renderer::ShearWarp(ShearWarp::new(cl, view, opts)?),
        })
    }

    pub fn render<S: Shader>(&self, shader: &S) -> Frame {
        match self {
            Renderer::Ray(c) => c.render(shader),
            Renderer::ShearWarp(s) => s.render(shader),
        }
    }

    /// [`Self::render`] into `out`; shear-warp reuses its buffers (the ray caster replaces
    /// it).
    pub fn render_into<S: Shader>(&self, shader: &S, out: &mut Frame) {
        match self {
            Renderer::Ray(c) => *out = c.render(shader),
            Renderer::ShearWarp(s) => s.render_into(shader, out),
        }
    }

    pub fn camera(&self) -> &super::camera::Camera {
        match self {
            Renderer::Ray(c) => c.camera(),
            Renderer::ShearWarp(s) => s.camera(),
        }
    }

    /// One pixel's contributing samples and opacity ([`Caster::pixel`]): the ray caster's
    /// only; a shear-warp pixel is warped from several intermediate pixels.
    pub fn pixel(&self, x: u32, y: u32) -> Option<(f32, Vec<(f32, [i32; 3])>)> {
        match self {
            Renderer::Ray(c) => c.pixel(x, y),
            Renderer::ShearWarp(_) => None,
        }
    }

    /// Fraction of the skipping units (bricks, or slice cells) empty for the transfer
    /// function.
    pub fn empty_fraction(&self) -> f64 {
        match self {
            Renderer::Ray(c) => c.empty_brick_fraction(),
            Renderer::ShearWarp(s) => s.empty_cell_fraction(),
        }
    }

    /// The image of a batch shader: the contributing samples' gradients shaded in one batch
    /// (checked: one intensity per sample, each within `map_bits`), then composited.
    pub fn batch(&self, src: &dyn IntensitySource, cfg: &Config) -> Result<Frame> {
        let check = |v: &[u32], n: usize| -> Result<()> {
            if v.len() != n {
                bail!(
                    "the batch shader gave {} intensities for {n} samples",
                    v.len()
                );
            }
            if let Some(bad) = v.iter().find(|&&i| i > cfg.map_max()) {
                bail!(
                    "the batch shader gave intensity {bad}, wider than map_bits = {}",
                    cfg.map_bits
                );
            }
            Ok(())
        };
        match self {
            Renderer::Ray(c) => {
                let s = c.collect()?;
                let v = src.intensities(&s.gradients)?;
                check(&v, s.gradients.len())?;
                s.composite(&v)
            }
            Renderer::ShearWarp(sw) => {
                let s = sw.collect()?;
                let v = src.intensities(&s.gradients)?;
                check(&v, s.gradients.len())?;
                sw.composite(&s, &v)
            }
        }
    }
}
