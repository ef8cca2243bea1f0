//! How to cast ([`CastOptions`]): image size, sample step, early-ray-termination threshold,
//! brick size and skipping, with their defaults and allowed ranges. Separate from the caster
//! because the command line and the report take them without casting.

use anyhow::{ensure, Result};
use serde::Serialize;

/// Default early-ray-termination threshold.
pub const DEFAULT_ERT: f64 = 0.99;
/// Default sample step, in units of the smallest voxel spacing.
pub const DEFAULT_STEP: f64 = 0.5;
/// Default brick size (cells per side) for empty-space skipping.
pub const DEFAULT_BRICK: usize = 8;
/// Smallest sample step in voxels (`--step`): the samples on a ray, hence the work of a
/// frame, grow as 1 / step.
pub const MIN_STEP: f64 = 0.05;
/// Largest sample step in voxels: beyond it samples skip whole cells.
pub const MAX_STEP: f64 = 4.0;
/// Largest `--zoom`: beyond it a pixel is far below a voxel.
pub const MAX_ZOOM: f64 = 1000.0;
/// Largest brick side in cells (`--brick`): larger bricks are rarely empty.
pub const MAX_BRICK: usize = 64;
/// Default shear-warp samples per slice spacing (`--slice-samples`).
pub const DEFAULT_SLICE_SAMPLES: u32 = 1;
/// Default shear-warp intermediate pixels per voxel along each slice axis (`--supersample`).
pub const DEFAULT_SUPERSAMPLE: u32 = 1;
/// Largest `--supersample`: the work of a frame grows with its square.
pub const MAX_SUPERSAMPLE: u32 = 4;
/// Largest `--slice-samples`: the work of a frame grows with it, and beyond it the samples
/// are closer than the ray caster's finest `--step` on any view.
pub const MAX_SLICE_SAMPLES: u32 = 8;

/// Which renderer makes the image.
///
/// The default is the ray caster, by measurement (docs/PERFORMANCE.md): shear-warp is
/// 20-60x faster, but its images are not as good (one sample per slice, one intermediate
/// pixel per voxel, a warp: on the MRI head its model image is 29.0 dB PSNR from a fine ray
/// float image, the ray caster's 40.5 dB), so it is the fast preview. Sampled finely enough
/// to match (`slice_samples` 4, `supersample` 3: 41.3 dB) it does 36x the work and costs
/// about as much as the ray caster.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CasterKind {
    /// Ray casting ([`crate::volume::cast`]): one ray per pixel, trilinear samples `step`
    /// apart; its cost grows with the image.
    #[default]
    Ray,
    /// Shear-warp (`volume::shear`): slices composited at voxel resolution, then
    /// one 2D warp; its cost grows with the volume's visible voxels.
    ShearWarp,
}

/// How to cast.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CastOptions {
    /// Image width and height in pixels.
    pub size: u32,
    /// Sample step along a ray, in units of the smallest voxel spacing.
    pub step: f64,
    /// Early-ray-termination threshold on the accumulated opacity, in (0, 1].
    pub ert: f64,
    /// Cells per brick side for empty-space skipping.
    pub brick: usize,
    /// Skip empty space, terminate early and shade only contributing samples.
    pub skip: bool,
    /// Magnification about the volume's centre (> 0).
    pub zoom: f64,
    /// World direction shown as image up; `None` for world +z (see [`crate::volume::camera`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub up: Option<[f64; 3]>,
    /// The renderer (`step` and `brick` apply to the ray caster only).
    pub caster: CasterKind,
    /// Shear-warp samples per slice spacing along a ray (1: one per slice; more are
    /// interpolated between the slices).
    pub slice_samples: u32,
    /// Shear-warp intermediate pixels per voxel along each slice axis (1: one per voxel).
    pub supersample: u32,
}

impl Default for CastOptions {
    fn default() -> Self {
        CastOptions {
            size: 512,
            step: DEFAULT_STEP,
            ert: DEFAULT_ERT,
            brick: DEFAULT_BRICK,
            skip: true,
            zoom: 1.0,
            up: None,
            caster: CasterKind::default(),
            slice_samples: DEFAULT_SLICE_SAMPLES,
            supersample: DEFAULT_SUPERSAMPLE,
        }
    }
}

impl CastOptions {
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (1..=crate::render::MAX_SIZE).contains(&self.size),
            "image size {} is out of range; allowed 1..={}",
            self.size,
            crate::render::MAX_SIZE
        );
        ensure!(
            self.step.is_finite() && self.step >= MIN_STEP && self.step <= MAX_STEP,
            "step {} is out of range; allowed {MIN_STEP}..={MAX_STEP} (voxels)",
            self.step
        );
        ensure!(
            self.ert > 0.0 && self.ert <= 1.0,
            "ert {} is out of range; allowed (0, 1]",
            self.ert
        );
        ensure!(
            (2..=MAX_BRICK).contains(&self.brick) && self.brick.is_power_of_two(),
            "brick {} is not allowed; give a power of two in 2..={MAX_BRICK}",
            self.brick
        );
        ensure!(
            self.zoom.is_finite() && self.zoom > 0.0 && self.zoom <= MAX_ZOOM,
            "zoom {} is out of range; allowed (0, {MAX_ZOOM}]",
            self.zoom
        );
        ensure!(
            (1..=MAX_SLICE_SAMPLES).contains(&self.slice_samples),
            "slice samples {} is out of range; allowed 1..={MAX_SLICE_SAMPLES}",
            self.slice_samples
        );
        ensure!(
            (1..=MAX_SUPERSAMPLE).contains(&self.supersample),
            "supersample {} is out of range; allowed 1..={MAX_SUPERSAMPLE}",
            self.supersample
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_are_checked() {
        let bad = |o: CastOptions| o.validate().unwrap_err().to_string();
        assert!(bad(CastOptions {
            size: 0,
            ..CastOptions::default()
        })
        .contains("size 0"));
        assert!(bad(CastOptions {
            step: 0.0,
            ..CastOptions::default()
        })
        .contains("step"));
        assert!(bad(CastOptions {
            ert: 1.5,
            ..CastOptions::default()
        })
        .contains("ert"));
        assert!(bad(CastOptions {
            brick: 1,
            ..CastOptions::default()
        })
        .contains("brick"));
        assert!(bad(CastOptions {
            brick: 12,
            ..CastOptions::default()
        })
        .contains("power of two"));
        for zoom in [0.0, -2.0, f64::NAN, 1e4] {
            assert!(bad(CastOptions {
                zoom,
                ..CastOptions::default()
            })
            .contains("zoom"));
        }
        for slice_samples in [0, MAX_SLICE_SAMPLES + 1] {
            assert!(bad(CastOptions {
                slice_samples,
                ..CastOptions::default()
            })
            .contains("slice samples"));
        }
        for supersample in [0, MAX_SUPERSAMPLE + 1] {
            assert!(bad(CastOptions {
                supersample,
                ..CastOptions::default()
            })
            .contains("supersample"));
        }
        CastOptions {
            brick: 16,
            slice_samples: MAX_SLICE_SAMPLES,
            supersample: MAX_SUPERSAMPLE,
            ..CastOptions::default()
        }
        .validate()
        .unwrap();
    }
}
