//! `rmapgen volume`: a volume (raw, NRRD or the built-in synthetic part) ray cast and shaded
//! by the float reference and by the bit-accurate model; the images, the 50x error image
//! and the error statistics, and with `--timing` the render times with and without
//! skipping.

use super::config_args::ConfigArgs;
use super::map_args::MapArgs;
use crate::output::StagedDir;
use crate::scene::transfer::Transfer;
use crate::scene::Scene;
use crate::volume::cast::options::{self, CastOptions, CasterKind};
use crate::volume::load::{self, RawFormat};
use crate::volume::picture::PixelFormat;
use crate::volume::prepared::Prepared;
use crate::volume::report::{self, VolumeRender};
use crate::volume::{histogram, synthetic, Volume, ENGINE_SCENE_TOML};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct VolumeArgs {
    #[command(flatten)]
    pub cfg: ConfigArgs,
    /// Volume file: NRRD (.nrrd, or .nhdr with a detached data file) or raw voxels (give
    /// --dims).
    #[arg(
        value_name = "FILE",
        conflicts_with = "synthetic",
        required_unless_present = "synthetic"
    )]
    pub input: Option<PathBuf>,
    /// Render the built-in synthetic engine block (256x256x128 unless --dims).
    #[arg(long)]
    pub synthetic: bool,
    /// Raw file (or synthetic) dimensions in voxels, x fastest.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub dims: Option<String>,
    /// Voxel spacing (world units per voxel along x, y, z) [default: 1,1,1 or the NRRD's].
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub spacing: Option<String>,
    /// Raw voxel width: 8 or 16 bits (16-bit little-endian) [default: 8].
    #[arg(long, value_name = "BITS")]
    pub bits: Option<u32>,
    /// Raw voxels are signed (two's complement).
    #[arg(long)]
    pub signed: bool,
    /// The scene (view, lights, material and [transfer] opacity function) and how its maps
    /// are filled.
    #[command(flatten)]
    pub map: MapArgs,
    /// Transfer function breakpoints value:opacity,... (replaces the scene's).
    #[arg(long, value_name = "V:A,...", allow_hyphen_values = true)]
    pub transfer: Option<String>,
    /// Opacity ramp on the gradient magnitude (value units per world unit),
    /// magnitude:factor,... with magnitudes increasing; multiplies the value's opacity
    /// (replaces the scene's [transfer] gradient).
    #[arg(long, value_name = "M:A,...", allow_hyphen_values = true)]
    pub gradient_ramp: Option<String>,
    /// Opacity (per voxel length) below which a sample is transparent and skipped [0..=1].
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    pub min_opacity: Option<f64>,
    /// View direction, from the volume towards the viewer (replaces the scene's).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub view: Option<String>,
    /// World direction shown as up in the image [default: +z, or +y for a view along z].
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub up: Option<String>,
    /// Magnification about the volume's centre: 2 shows the middle half of the default
    /// frame (0, 1000].
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    pub zoom: f64,
    /// Render only the voxels X0..=X1, Y0..=Y1, Z0..=Z1 (framed as the whole volume is).
    #[arg(long, value_name = "X0:X1,Y0:Y1,Z0:Z1", allow_hyphen_values = true, value_parser = super::parse::named(crop_box))]
    pub crop: Option<([usize; 3], [usize; 3])>,
    /// Render with the model only: no float reference, no error image or statistics.
    #[arg(long, conflicts_with = "rtl")]
    pub model_only: bool,
    /// Pixel format of the shaded images (the error image stays 8-bit grey).
    #[arg(long, value_enum, default_value_t = PixelFormat::Gray8)]
    pub png: PixelFormat,
    /// Image width and height in pixels [1..=4096].
    #[arg(long, value_name = "N", default_value_t = 512, value_parser = super::parse::count::<u32>())]
    pub size: u32,
    /// Renderer: ray (a ray per pixel, samples --step apart; cost grows with the image) or
    /// shear-warp (the fast preview: slices composited at voxel resolution, then warped;
    /// cost grows with the volume's visible voxels, images coarser).
    #[arg(long, value_enum, default_value_t = CasterKind::default())]
    pub caster: CasterKind,
    /// Sample step along a ray, in smallest voxel spacings [0.05..=4] (ray caster; shear-warp
    /// samples once per slice).
    #[arg(long, value_name = "S", default_value_t = options::DEFAULT_STEP, value_parser = super::parse::positive())]
    pub step: f64,
    /// Shear-warp samples per slice spacing along a ray [1..=8]: more are interpolated
    /// between the slices (trilinear), closer to the ray caster's image at more work.
    #[arg(long, value_name = "N", default_value_t = options::DEFAULT_SLICE_SAMPLES, value_parser = super::parse::count::<u32>())]
    pub slice_samples: u32,
    /// Shear-warp intermediate pixels per voxel along each slice axis [1..=4]: a finer
    /// intermediate image for the warp, at the square of the work.
    #[arg(long, value_name = "R", default_value_t = options::DEFAULT_SUPERSAMPLE, value_parser = super::parse::count::<u32>())]
    pub supersample: u32,
    /// Early ray termination: accumulated opacity at which a pixel counts as opaque (0, 1].
    #[arg(long, value_name = "A", default_value_t = options::DEFAULT_ERT, value_parser = super::parse::positive())]
    pub ert: f64,
    /// Brick side in cells for the ray caster's empty-space skipping [a power of two, 2..=64].
    #[arg(long, value_name = "N", default_value_t = options::DEFAULT_BRICK, value_parser = super::parse::count::<usize>())]
    pub brick: usize,
    /// Turn skipping off (empty space, early termination, unshaded samples): same image,
    /// more work.
    #[arg(long)]
    pub no_skip: bool,
    /// Also time the model render with skipping on and off and the float render, write
    /// timing.json and print a report.
    #[arg(long)]
    pub timing: bool,
    /// Also shade every sample with the generated RTL (Verilated top) and write rtl.png; fails
    /// unless the RTL image equals the model image pixel for pixel.
    #[arg(long)]
    pub rtl: bool,
    /// Timed runs per measurement with --timing (the median is reported) [1..=100].
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = super::parse::count::<u32>())]
    pub repeat: u32,
    /// Output directory for reference.png, model.png, error50.png and metrics.json (replaced
    /// whole on success).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

/// Largest `--repeat`: each timed run renders a frame (up to seconds with skipping off).
pub const MAX_REPEAT: u32 = 100;

/// Parses `X,Y,Z` into three numbers.
fn triple<T: std::str::FromStr>(flag: &str, s: &str) -> Result<[T; 3]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        bail!("{flag} {s}: give three comma-separated values X,Y,Z");
    }
    let mut out = Vec::with_capacity(3);
    for p in parts {
        match p.parse::<T>() {
            Ok(v) => out.push(v),
            Err(_) => bail!("{flag} {s}: '{p}' is not a number"),
        }
    }
    let [a, b, c]: [T; 3] = out.try_into().ok().expect("three values");
    Ok([a, b, c])
}

/// The scene with --view, --up and --transfer applied, validated; without a transfer
/// function when neither the arguments nor the scene give one (see [`transfer`]).
fn scene(a: &VolumeArgs) -> Result<Scene> {
    let mut scene = a.map.scene_or(|| {
        Ok(Scene::from_toml_str(ENGINE_SCENE_TOML)
            .context("the built-in engine scene")?
            .named("scenes/engine.toml"))
    })?;
    if let Some(v) = &a.view {
        let d = triple::<f64>("--view", v)?;
        crate::scene::check_direction("--view", d)?;
        scene.view.direction = d;
    }
    if let Some(t) = &a.transfer {
        scene.transfer = Some(Transfer::parse(t)?);
    } else if a.map.input().is_none() && !a.synthetic {
        // The built-in scene's function is the synthetic part's (1100..1900): on another
        // volume it is a guess, so the data's own default is used instead.
        scene.transfer = None;
    }
    let ramp = a
        .gradient_ramp
        .as_deref()
        .map(crate::scene::transfer::parse_ramp)
        .transpose()?;
    if let Some(m) = a.min_opacity {
        if !(0.0..=1.0).contains(&m) {
            bail!("--min-opacity {m} is out of range; allowed 0..=1");
        }
    }
    if let Some(t) = &mut scene.transfer {
        apply_classification(a, t, ramp.clone());
    }
    if let Some(u) = &a.up {
        let u = triple::<f64>("--up", u)?;
        let view = crate::scene::check_direction("view.direction", scene.view.direction)?;
        crate::volume::camera::check_up(u, view)?;
    }
    scene.validate()?;
    Ok(scene)
}

/// Sets --gradient-ramp and --min-opacity on a transfer function.
fn apply_classification(a: &VolumeArgs, t: &mut Transfer, ramp: Option<Vec<[f64; 2]>>) {
    if ramp.is_some() {
        t.gradient = ramp;
    }
    if a.min_opacity.is_some() {
        t.min_opacity = a.min_opacity;
    }
}

/// Gives the scene a transfer function from the data's histogram when it has none; returns
/// the line saying what was chosen.
fn transfer(a: &VolumeArgs, scene: &mut Scene, vol: &Volume) -> Result<Option<String>> {
    if scene.transfer.is_some() {
        return Ok(None);
    }
    let (mut t, text) = histogram::default_transfer(vol);
    let ramp = a
        .gradient_ramp
        .as_deref()
        .map(crate::scene::transfer::parse_ramp)
        .transpose()?;
    apply_classification(a, &mut t, ramp);
    scene.transfer = Some(t);
    scene.validate()?;
    Ok(Some(text))
}

/// Parses `--crop X0:X1,Y0:Y1,Z0:Z1` (the flag's parser names it in the error).
fn crop_box(s: &str) -> std::result::Result<([usize; 3], [usize; 3]), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err("give three ranges X0:X1,Y0:Y1,Z0:Z1 (voxel indices)".into());
    }
    let (mut lo, mut hi) = ([0; 3], [0; 3]);
    for (a, p) in parts.iter().enumerate() {
        let r = p.split_once(':').and_then(|(x, y)| {
            Some((
                x.trim().parse::<usize>().ok()?,
                y.trim().parse::<usize>().ok()?,
            ))
        });
        let Some((l, h)) = r else {
            return Err(format!("'{p}' is not first:last (voxel indices >= 0)"));
        };
        (lo[a], hi[a]) = (l, h);
    }
    Ok((lo, hi))
}

/// Loads the volume the arguments name.
fn volume(a: &VolumeArgs) -> Result<Volume> {
    let spacing = a
        .spacing
        .as_deref()
        .map(|s| triple::<f64>("--spacing", s))
        .transpose()?;
    let dims = a
        .dims
        .as_deref()
        .map(|s| triple::<i64>("--dims", s))
        .transpose()?;
    if a.synthetic {
        if a.bits.is_some() || a.signed {
            bail!("--bits and --signed are for raw files, not --synthetic");
        }
        let d =
            crate::volume::check_dims(dims.unwrap_or(synthetic::DIMS.map(|n| n as i64)), "--dims")?;
        let s = crate::volume::check_spacing(spacing.unwrap_or([1.0; 3]), "--spacing")?;
        return crop(a, synthetic::engine_block(d, s)?);
    }
    let path = a
        .input
        .as_ref()
        .expect("clap requires FILE without --synthetic");
    if path.is_dir() {
        bail!("{} is a directory, not a volume file", path.display());
    }
    if load::is_nrrd(path) {
        if a.dims.is_some() || a.bits.is_some() || a.signed {
            bail!("--dims, --bits and --signed are for raw files; the NRRD header {} gives the layout", path.display());
        }
        let mut v = load::load_nrrd(path)?;
        if let Some(s) = spacing {
            v.spacing = crate::volume::check_spacing(s, "--spacing")?;
        }
        crop(a, v)
    } else {
        let Some(dims) = dims else {
            bail!(
                "raw file {} needs --dims X,Y,Z (or give an .nrrd or .nhdr file)",
                path.display()
            );
        };
        let format = RawFormat {
            bits: a.bits.unwrap_or(8),
            signed: a.signed,
        };
        crop(
            a,
            load::load_raw(path, dims, spacing.unwrap_or([1.0; 3]), format)?,
        )
    }
}

/// The volume cropped to --crop, if given.
fn crop(a: &VolumeArgs, v: Volume) -> Result<Volume> {
    match a.crop {
        None => Ok(v),
        Some((lo, hi)) => v.crop(lo, hi),
    }
}

pub fn run(a: &VolumeArgs) -> Result<()> {
    let cfg = a.cfg.resolve()?;
    let mut scene = scene(a)?;
    scene.map_fit.check(&cfg)?;
    let opts = CastOptions {
        size: a.size,
        step: a.step,
        ert: a.ert,
        brick: a.brick,
        skip: !a.no_skip,
        zoom: a.zoom,
        up: a
            .up
            .as_deref()
            .map(|u| triple::<f64>("--up", u))
            .transpose()?,
        caster: a.caster,
        slice_samples: a.slice_samples,
        supersample: a.supersample,
    };
    opts.validate()?;
    if a.timing && a.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    if a.repeat > MAX_REPEAT {
        bail!(
            "--repeat {} is more than the limit of {MAX_REPEAT}",
            a.repeat
        );
    }
    let t = Instant::now();
    let vol = volume(a)?;
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    let chosen = transfer(a, &mut scene, &vol)?;

    let policy = a
        .force
        .policy(&[a.cfg.config.as_deref(), a.map.input(), a.input.as_deref()]);
    let out = StagedDir::new(&a.out, &policy)?;
    let t = Instant::now();
    let p = Prepared::try_new(&vol, cfg.grad_bits, opts.brick)?;
    let prepare_ms = t.elapsed().as_secs_f64() * 1e3;
    let rtl = if a.rtl {
        Some(crate::sim::verilated::VerilatedTop::build(
            &cfg,
            &vol.shading_scene(&scene),
        )?)
    } else {
        None
    };
    let r: VolumeRender = report::render(
        &p,
        &cfg,
        &scene,
        opts,
        rtl.as_ref()
            .map(|t| t as &dyn crate::model::IntensitySource),
        a.model_only,
    )?;
    let mut r = r;
    r.format = a.png;
    if let Some(text) = &chosen {
        crate::outln!("{text}")?;
    }
    report::check_covered(&r, &vol)?;
    if let Some(n) = r.rtl_mismatches() {
        if n > 0 {
            bail!("the RTL image differs from the model image in {n} pixels");
        }
    }
    r.write(&out)?;
    let timing = if a.timing {
        let (mut t, text) = crate::volume::timing::timing(&p, &cfg, &scene, opts, a.repeat)?;
        t.load_ms = load_ms;
        t.prepare_ms = prepare_ms;
        out.write_text("timing.json", &serde_json::to_string_pretty(&t)?)?;
        Some(text)
    } else {
        None
    };
    let dir = out.commit()?;
    crate::outln!("{} -> {}", r.summary(), dir.display())?;
    let float = r
        .reference_ms
        .map_or(String::new(), |t| format!(", float render {t:.1} ms"));
    crate::outln!(
        "  {}: load {load_ms:.1} ms, gradients and bricks {prepare_ms:.1} ms, model render {:.1} ms{float} (skipping {})",
        vol.info.source,
        r.model_ms,
        if opts.skip { "on" } else { "off" }
    )?;
    if let Some(text) = timing {
        crate::outln!(
            "  timing, {} threads:\n{text}",
            rayon::current_num_threads()
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triples() {
        assert_eq!(triple::<i64>("--dims", "4, 5,6").unwrap(), [4, 5, 6]);
        assert_eq!(triple::<i64>("--dims", "4,-5,6").unwrap(), [4, -5, 6]);
        assert!(triple::<i64>("--dims", "4,5")
            .unwrap_err()
            .to_string()
            .contains("three"));
        assert!(triple::<f64>("--view", "1,x,0")
            .unwrap_err()
            .to_string()
            .contains("'x' is not a number"));
    }
}
