//! Volume rendering through the reflectance map, as in the paper's Figures 9 and 10 (a CT
//! engine block shaded through the 1.5 KB map and compared with floating point).
//!
//! The pipeline, one module each:
//! - [`load`]: raw files (8- or 16-bit little-endian) and NRRD (`.nrrd`, `.nhdr` + data
//!   file; raw and gzip encodings); [`synthetic`]: the built-in machined part.
//! - [`gradient`]: central differences on the voxel grid, scaled once per volume and
//!   quantised to `grad_bits` two's complement: the shader's input, as hardware receives it.
//! - [`bricks`]: per-brick value ranges and largest gradient magnitudes for empty-space
//!   skipping.
//! - [`crate::scene::transfer`]: the opacity transfer function of the scene file (value
//!   breakpoints, gradient-magnitude ramp, minimum opacity); [`histogram`]: a default one
//!   from the data when none is given.
//! - [`prepared`]: a volume's gradients and bricks, computed once for every view.
//! - [`camera`] and [`cast`]: orthographic ray casting with trilinear sampling, front-to-back
//!   compositing, empty-space skipping and early ray termination; each sample is shaded by a
//!   [`cast::shader::Shader`] (the float reference or the bit-accurate model), or its
//!   gradients are collected for a batch shader (an RTL simulation, through
//!   [`crate::model::IntensitySource`]). The default renderer: its cost grows with the image.
//! - [`shear`]: shear-warp (`--caster shear-warp`), the fast preview: slices composited at
//!   voxel resolution (bilinear value and gradient at the sheared positions, the same
//!   compositing and shaders), skipping runs of transparent cells ([`shear::runs`], once
//!   per volume, transfer function and principal axis) and opaque pixels, then one warp to
//!   the image; its cost grows with the visible voxels.
//! - [`renderer`]: the caster `--caster` picks, behind one interface (fused render, batch
//!   render).
//! - [`report`]: one render with every shader (or the model alone), the images, the error
//!   statistics and `metrics.json`; [`picture`]: the images' pixel formats.
//!
//! Orientation: a volume's [`Volume::axes`] (NRRD `space directions`) place it in the world.
//! The caster works in the voxel-axis frame; the camera turns the world view and up into it,
//! and the shaders see the scene turned the same way ([`Volume::shading_scene`]).

pub mod bricks;
pub mod camera;
pub mod cast;
pub mod gradient;
pub mod histogram;
pub mod load;
pub mod picture;
pub mod prepared;
pub mod renderer;
pub mod report;
pub mod shear;
pub mod synthetic;
pub mod timing;

use anyhow::{bail, Result};
use serde::Serialize;

/// The scene of the synthetic part (`scenes/engine.toml`): a view from the front left and
/// above, one light, the standard material and a transfer function for its values.
pub const ENGINE_SCENE_TOML: &str = include_str!("../../scenes/engine.toml");

/// Memory a volume may take once loaded and prepared for rendering, in bytes (2 GiB): the
/// budget every loader and `--dims` is checked against before anything is allocated.
pub const MEMORY_BUDGET: u64 = 2 << 30;

/// Bytes per voxel of a volume ready to render: its f32 value (4) and its three i16
/// gradient components (6). Loaders decode in chunks, so the file's own voxel type (a
/// double is 8 bytes) adds nothing.
pub const BYTES_PER_VOXEL: u64 = 4 + 6;

/// Largest number of voxels accepted: what fits [`MEMORY_BUDGET`] (214 748 364, e.g.
/// 512 x 512 x 819).
pub const MAX_VOXELS: usize = (MEMORY_BUDGET / BYTES_PER_VOXEL) as usize;

/// A byte count for messages: "2.5 GiB", "300.0 MiB", "12 bytes".
pub fn human_bytes(n: u64) -> String {
    const K: f64 = 1024.0;
    let x = n as f64;
    if x >= K * K * K {
        format!("{:.1} GiB", x / (K * K * K))
    } else if x >= K * K {
        format!("{:.1} MiB", x / (K * K))
    } else if x >= K {
        format!("{:.1} KiB", x / K)
    } else {
        format!("{n} bytes")
    }
}

/// A scalar volume on a regular grid. Voxel (x, y, z) sits at world position
/// (x * spacing[0], y * spacing[1], z * spacing[2]); x varies fastest in `data`.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    pub dims: [usize; 3],
    pub spacing: [f64; 3],
    /// Voxel values in the file's own units (integers up to 2^24 are exact in f32).
    pub data: Vec<f32>,
    /// World direction of each voxel axis, orthonormal rows (NRRD `space directions`;
    /// [`camera::IDENTITY`] otherwise): voxel (x, y, z) sits at `x sx axes[0] + y sy axes[1]
    /// + z sz axes[2]`.
    pub axes: [[f64; 3]; 3],
    /// Where the volume came from and its voxel type, for reports.
    pub info: VolumeInfo,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VolumeInfo {
    pub source: String,
    pub voxel_type: String,
}

/// Checks volume dimensions: each at least 2 (a cell needs two voxels along every axis)
/// and not too many voxels in all.
pub fn check_dims(dims: [i64; 3], what: &str) -> Result<[usize; 3]> {
    for (axis, &n) in dims.iter().enumerate() {
        let name = ["x", "y", "z"][axis];
        if n <= 0 {
            bail!("{what}: size {n} along {name} is not positive; every size must be at least 2");
        }
        if n < 2 {
            bail!("{what}: size {n} along {name} is too small; every size must be at least 2");
        }
    }
    let total = dims
        .iter()
        .fold(1u128, |acc, &n| acc.saturating_mul(n as u128));
    if total > MAX_VOXELS as u128 {
        let need = total.saturating_mul(BYTES_PER_VOXEL as u128);
        bail!(
            "{what}: {} x {} x {} voxels need {} ({BYTES_PER_VOXEL} bytes a voxel for values and gradients), more than the limit of {} ({MAX_VOXELS} voxels)",
            dims[0],
            dims[1],
            dims[2],
            human_bytes(u64::try_from(need).unwrap_or(u64::MAX)),
            human_bytes(MEMORY_BUDGET)
        );
    }
    Ok(dims.map(|n| n as usize))
}

/// Checks a voxel spacing: three finite positive numbers.
pub fn check_spacing(spacing: [f64; 3], what: &str) -> Result<[f64; 3]> {
    for (axis, &s) in spacing.iter().enumerate() {
        if !s.is_finite() || s <= 0.0 {
            bail!(
                "{what}: spacing {s} along {} must be a finite number > 0",
                ["x", "y", "z"][axis]
            );
        }
    }
    Ok(spacing)
}

impl Volume {
    /// A volume from its parts; checks the dimensions, the spacing, the length of `data` and
    /// that every value is finite.
    pub fn new(
        dims: [usize; 3],
        spacing: [f64; 3],
        data: Vec<f32>,
        info: VolumeInfo,
    ) -> Result<Volume> {
        check_dims(dims.map(|n| n as i64), &info.source)?;
        check_spacing(spacing, &info.source)?;
        let want = dims[0] * dims[1] * dims[2];
        if data.len() != want {
            bail!(
                "{}: {} voxel values for {} x {} x {} voxels",
                info.source,
                data.len(),
                dims[0],
                dims[1],
                dims[2]
            );
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            bail!(
                "{}: voxel {} has the non-finite value {}",
                info.source,
                i,
                data[i]
            );
        }
        Ok(Volume {
            dims,
            spacing,
            data,
            axes: camera::IDENTITY,
            info,
        })
    }

    /// Index of voxel (x, y, z) in `data`.
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    #[inline]
    pub fn at(&self, x: usize, y: usize, z: usize) -> f32 {
        self.data[self.index(x, y, z)]
    }

    /// Smallest and largest voxel value.
    pub fn range(&self) -> (f32, f32) {
        use rayon::prelude::*;
        self.data
            .par_chunks(1 << 16)
            .map(|c| {
                c.iter()
                    .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                        (lo.min(v), hi.max(v))
                    })
            })
            .reduce(
                || (f32::INFINITY, f32::NEG_INFINITY),
                |a, b| (a.0.min(b.0), a.1.max(b.1)),
            )
    }

    /// The voxels `lo[a]..=hi[a]` along each axis, as a volume of their own (same spacing
    /// and axes); refuses a box outside the volume or under 2 voxels along an axis.
    pub fn crop(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume> {
        for a in 0..3 {
            let name = ["x", "y", "z"][a];
            if hi[a] >= self.dims[a] {
                bail!(
                    "--crop: {name} range {}:{} ends outside the volume (voxels 0:{} along {name})",
                    lo[a],
                    hi[a],
                    self.dims[a] - 1
                );
            }
            if lo[a] >= hi[a] {
                bail!(
                    "--crop: {name} range {}:{} holds fewer than 2 voxels; give first:last with first < last",
                    lo[a],
                    hi[a]
                );
            }
        }
        let dims = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
        let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let i = self.index(0, y, z);
                data.extend_from_slice(&self.data[i + lo[0]..=i + hi[0]]);
            }
        }
        let mut info = self.info.clone();
        info.source = format!(
            "{} [{}:{},{}:{},{}:{}]",
            info.source, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]
        );
        let mut v = Volume::new(dims, self.spacing, data, info)?;
        v.axes = self.axes;
        Ok(v)
    }

    /// The scene the shaders see: its view and light directions in the voxel-axis frame,
    /// where the gradients are (equal to `scene` for [`camera::IDENTITY`]). Dot products
    /// are unchanged by the orthonormal axes, so the shading is the world scene's.
    pub fn shading_scene(&self, scene: &crate::scene::Scene) -> crate::scene::Scene {
        let mut s = scene.clone();
        s.view.direction = camera::to_axes(&self.axes, s.view.direction);
        for l in &mut s.lights {
            l.direction = camera::to_axes(&self.axes, l.direction);
        }
        s
    }

    /// The smallest spacing: the unit of sample steps and of transfer-function opacities.
    pub fn unit(&self) -> f64 {
        self.spacing.iter().cloned().fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dims_are_checked() {
        assert_eq!(check_dims([4, 5, 6], "t").unwrap(), [4, 5, 6]);
        assert!(check_dims([4, 0, 6], "t")
            .unwrap_err()
            .to_string()
            .contains("size 0 along y is not positive"));
        assert!(check_dims([-3, 5, 6], "t")
            .unwrap_err()
            .to_string()
            .contains("not positive"));
        assert!(check_dims([1, 5, 6], "t")
            .unwrap_err()
            .to_string()
            .contains("at least 2"));
        assert!(check_dims([1 << 20, 1 << 20, 1 << 20], "t")
            .unwrap_err()
            .to_string()
            .contains("limit"));
        assert!(check_spacing([1.0, 0.0, 1.0], "t")
            .unwrap_err()
            .to_string()
            .contains("along y"));
        assert!(check_spacing([1.0, 1.0, f64::NAN], "t").is_err());
    }

    #[test]
    fn new_checks_length_and_values() {
        let info = VolumeInfo {
            source: "t".into(),
            voxel_type: "float".into(),
        };
        assert!(Volume::new([2, 2, 2], [1.0; 3], vec![0.0; 7], info.clone()).is_err());
        let mut d = vec![0.0; 8];
        d[5] = f32::NAN;
        assert!(Volume::new([2, 2, 2], [1.0; 3], d, info.clone())
            .unwrap_err()
            .to_string()
            .contains("voxel 5"));
        let v = Volume::new(
            [2, 3, 4],
            [1.0, 0.5, 2.0],
            (0..24).map(|i| i as f32).collect(),
            info,
        )
        .unwrap();
        assert_eq!(v.at(1, 2, 3), 23.0);
        assert_eq!(v.range(), (0.0, 23.0));
        assert_eq!(v.unit(), 0.5);
        let c = v.crop([1, 1, 2], [1, 2, 3]);
        assert!(c.unwrap_err().to_string().contains("fewer than 2"));
        let c = v.crop([0, 1, 2], [1, 2, 3]).unwrap();
        assert_eq!(
            (c.dims, c.at(0, 0, 0), c.at(1, 1, 1)),
            ([2, 2, 2], 14.0, 23.0)
        );
        assert!(v
            .crop([0, 0, 0], [1, 3, 3])
            .unwrap_err()
            .to_string()
            .contains("outside"));
    }
}
