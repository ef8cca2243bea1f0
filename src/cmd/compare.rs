//! `rmapgen compare A.png B.png`: the error statistics of one image against another, sample by
//! sample, in the images' own LSBs: what `render` and `volume` write to `metrics.json` for
//! their model against their reference, for any two images (a caster against a finely
//! sampled one, a shear-warp preview against the ray caster, two configurations).

use crate::render::metrics::{metrics, Metrics};
use anyhow::{bail, Context, Result};
use clap::Args;
use image::DynamicImage;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The largest width or height read: a 16384² RGBA16 image is 2 GiB, so the allocation
/// limit ([`MAX_ALLOC`]) decides first for the wide kinds.
pub const MAX_SIDE: u32 = 16384;
/// The most memory one decoded image may take.
pub const MAX_ALLOC: u64 = 1 << 30;

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image under test (PNG: 8- or 16-bit grey, grey-alpha, RGB or RGBA)
    pub image: PathBuf,
    /// The reference, of the same size and kind
    pub reference: PathBuf,
    /// Print the statistics as one JSON object (with the size and kind) instead of a line
    #[arg(long)]
    pub json: bool,
}

/// What is printed with `--json`.
#[derive(Serialize)]
struct Report {
    width: u32,
    height: u32,
    kind: &'static str,
    channels: usize,
    /// The worst sample's pixel and channel (absent when the images are equal).
    worst_pixel: Option<(u32, u32, usize)>,
    #[serde(flatten)]
    metrics: Metrics,
}

/// A decoded image's samples (row by row, channels interleaved), the largest value, its kind
/// and its channel count.
fn samples(path: &Path, img: &DynamicImage) -> Result<(Vec<u32>, u32, &'static str, usize)> {
    use DynamicImage::*;
    fn wide<T: Copy + Into<u32>>(v: &[T]) -> Vec<u32> {
        v.iter().map(|&x| x.into()).collect()
    }
    Ok(match img {
        ImageLuma8(b) => (wide(b.as_raw()), 255, "gray8", 1),
        ImageLumaA8(b) => (wide(b.as_raw()), 255, "gray-alpha8", 2),
        ImageRgb8(b) => (wide(b.as_raw()), 255, "rgb8", 3),
        ImageRgba8(b) => (wide(b.as_raw()), 255, "rgba8", 4),
        ImageLuma16(b) => (wide(b.as_raw()), 65535, "gray16", 1),
        ImageLumaA16(b) => (wide(b.as_raw()), 65535, "gray-alpha16", 2),
        ImageRgb16(b) => (wide(b.as_raw()), 65535, "rgb16", 3),
        ImageRgba16(b) => (wide(b.as_raw()), 65535, "rgba16", 4),
        other => bail!(
            "{}: a {:?} image; compare reads 8- and 16-bit grey, grey-alpha, RGB and RGBA PNGs",
            path.display(),
            other.color()
        ),
    })
}

/// Reads a PNG within the size and memory limits.
fn read(path: &Path) -> Result<DynamicImage> {
    let mut reader =
        image::ImageReader::open(path).with_context(|| format!("reading {}", path.display()))?;
    reader.set_format(image::ImageFormat::Png);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(MAX_ALLOC);
    reader.limits(limits);
    reader.decode().with_context(|| {
        format!(
            "decoding {} as a PNG (at most {MAX_SIDE} pixels a side)",
            path.display()
        )
    })
}

pub fn run(a: &CompareArgs) -> Result<()> {
    let (img, reference) = (read(&a.image)?, read(&a.reference)?);
    let (x, peak, kind, channels) = samples(&a.image, &img)?;
    let (y, _, ref_kind, _) = samples(&a.reference, &reference)?;
    let (w, h) = (img.width(), img.height());
    if (w, h) != (reference.width(), reference.height()) || kind != ref_kind {
        bail!(
            "{} is {w}x{h} {kind} and {} is {}x{} {ref_kind}: compare needs images of the same size and kind",
            a.image.display(),
            a.reference.display(),
            reference.width(),
            reference.height()
        );
    }
    let m = metrics(&x, &y, peak);
    let worst_pixel = (m.max_abs_error > 0).then(|| {
        let i = m.worst_index.expect("a largest error has an index");
        let p = (i / channels) as u32;
        (p % w, p / w, i % channels)
    });
    if a.json {
        let r = Report {
            width: w,
            height: h,
            kind,
            channels,
            worst_pixel,
            metrics: m,
        };
        println!("{}", serde_json::to_string_pretty(&r)?);
        return Ok(());
    }
    let what = format!(
        "{} against {}: {w}x{h} {kind} ({} samples)",
        a.image.display(),
        a.reference.display(),
        m.pixels
    );
    match (worst_pixel, m.psnr_db) {
        (Some((px, py, c)), Some(psnr)) => println!(
            "compare: {what}: max abs error {} LSB at pixel ({px}, {py}) channel {c}, mean abs error {:.4}, mean error {:+.4}, RMSE {:.4} LSB, PSNR {psnr:.2} dB (peak {peak})",
            m.max_abs_error, m.mean_abs_error, m.mean_error, m.rmse
        ),
        _ => println!("compare: {what}: identical"),
    }
    Ok(())
}
