//! `rmapgen compare A.png B.png`: the error statistics of one image against another, sample by
//! sample, in the images' own LSBs: what `render` and `volume` write to `metrics.json` for
//! their model against their reference, for any two images (a caster against a finely
//! sampled one, a shear-warp preview against the ray caster, two configurations).

use crate::render::metrics::{Accumulator, Metrics};
use crate::volume::human_bytes;
use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// The largest width or height read: a 16384² RGBA16 image is 2 GiB, so the allocation
/// limit ([`MAX_ALLOC`]) decides first for the wide kinds.
pub const MAX_SIDE: u32 = 16384;
/// The largest decoded size (width × height × bytes a pixel) of an image read: the memory
/// an interlaced image takes, held whole (others are streamed by rows).
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
struct Report<'a> {
    width: u32,
    height: u32,
    kind: &'static str,
    channels: usize,
    /// The worst sample's pixel and channel (absent when the images are equal).
    worst_pixel: Option<(u32, u32, usize)>,
    #[serde(flatten)]
    metrics: &'a Metrics,
}

/// The statistics of one image against another.
#[derive(Debug)]
pub struct Comparison {
    pub width: u32,
    pub height: u32,
    pub kind: &'static str,
    pub channels: usize,
    pub metrics: Metrics,
}

impl Comparison {
    /// The worst sample's pixel and channel, when the images differ.
    pub fn worst_pixel(&self) -> Option<(u32, u32, usize)> {
        let i = self
            .metrics
            .worst_index
            .filter(|_| self.metrics.max_abs_error > 0)?;
        let p = (i / self.channels) as u64;
        let w = self.width as u64;
        Some(((p % w) as u32, (p / w) as u32, i % self.channels))
    }
}

/// A PNG read row by row. A non-interlaced image is streamed from the decoder, so only a
/// row or so is held; an interlaced (Adam7) one arrives in seven passes, so it is decoded
/// whole first (its decoded size, at most [`MAX_ALLOC`]).
struct Png {
    path: PathBuf,
    width: u32,
    height: u32,
    kind: &'static str,
    channels: usize,
    /// 16 bits a sample (big-endian, as PNG stores them), else 8.
    wide: bool,
    rows: Rows,
}

enum Rows {
    Stream(Box<png::Reader<BufReader<File>>>),
    Whole {
        buf: Vec<u8>,
        line: usize,
        next: usize,
    },
}

impl Png {
    /// Opens a PNG within the size and memory limits: 8- or 16-bit grey, grey-alpha, RGB or
    /// RGBA after expansion (a palette becomes RGB or RGBA, fewer bits become 8), as the
    /// `image` crate reads it.
    fn open(path: &Path) -> Result<Png> {
        let shown = path.display();
        let file = File::open(path).with_context(|| format!("reading {shown}"))?;
        let decoding = || format!("decoding {shown} as a PNG");
        let mut d = png::Decoder::new_with_limits(
            BufReader::new(file),
            png::Limits {
                bytes: MAX_ALLOC as usize,
            },
        );
        d.set_transformations(png::Transformations::EXPAND);
        let info = d.read_header_info().with_context(decoding)?;
        let (width, height) = (info.width, info.height);
        if width > MAX_SIDE || height > MAX_SIDE {
            bail!("{shown} is {width}x{height}: compare reads at most {MAX_SIDE} pixels a side");
        }
        let reader = d.read_info().with_context(decoding)?;
        use png::{BitDepth::*, ColorType::*};
        let (kind, channels, wide) = match reader.output_color_type() {
            (Grayscale, Eight) => ("gray8", 1, false),
            (GrayscaleAlpha, Eight) => ("gray-alpha8", 2, false),
            (Rgb, Eight) => ("rgb8", 3, false),
            (Rgba, Eight) => ("rgba8", 4, false),
            (Grayscale, Sixteen) => ("gray16", 1, true),
            (GrayscaleAlpha, Sixteen) => ("gray-alpha16", 2, true),
            (Rgb, Sixteen) => ("rgb16", 3, true),
            (Rgba, Sixteen) => ("rgba16", 4, true),
            (c, b) => bail!(
                "{shown}: a {c:?} {b:?} image; compare reads 8- and 16-bit grey, grey-alpha, RGB and RGBA PNGs"
            ),
        };
        let line = width as usize * channels * if wide { 2 } else { 1 };
        let decoded = line as u64 * height as u64;
        if decoded > MAX_ALLOC {
            bail!(
                "{shown} is {width}x{height} {kind}: {} decoded, more than compare's limit of {}",
                human_bytes(decoded),
                human_bytes(MAX_ALLOC)
            );
        }
        let rows = if reader.info().interlaced {
            let mut reader = reader;
            let mut buf = Vec::new();
            buf.try_reserve_exact(decoded as usize)
                .with_context(|| format!("{shown}: no memory for {}", human_bytes(decoded)))?;
            buf.resize(decoded as usize, 0);
            reader.next_frame(&mut buf).with_context(decoding)?;
            Rows::Whole { buf, line, next: 0 }
        } else {
            Rows::Stream(Box::new(reader))
        };
        Ok(Png {
            path: path.to_path_buf(),
            width,
            height,
            kind,
            channels,
            wide,
            rows,
        })
    }

    /// The next row's bytes (`width * channels` samples).
    fn next_row(&mut self) -> Result<&[u8]> {
        let path = &self.path;
        match &mut self.rows {
            Rows::Stream(r) => r
                .next_row()
                .with_context(|| format!("decoding {} as a PNG", path.display()))?
                .map(|row| row.data())
                .with_context(|| {
                    format!("decoding {}: fewer rows than its height", path.display())
                }),
            Rows::Whole { buf, line, next } => {
                let row = &buf[*next * *line..][..*line];
                *next += 1;
                Ok(row)
            }
        }
    }
}

/// Compares `image` with `reference` sample by sample, row by row: two rows are held at a
/// time, and an interlaced PNG whole (see [`Png`]); never a converted copy of either.
pub fn compare(image: &Path, reference: &Path) -> Result<Comparison> {
    let mut a = Png::open(image)?;
    let mut b = Png::open(reference)?;
    let (w, h, kind) = (a.width, a.height, a.kind);
    if (w, h, kind) != (b.width, b.height, b.kind) {
        bail!(
            "{} is {w}x{h} {kind} and {} is {}x{} {}: compare needs images of the same size and kind",
            image.display(),
            reference.display(),
            b.width,
            b.height,
            b.kind
        );
    }
    let (channels, wide) = (a.channels, a.wide);
    let mut acc = Accumulator::new(if wide { 65535 } else { 255 });
    for _ in 0..h {
        let (x, y) = (a.next_row()?, b.next_row()?);
        if wide {
            let be = |c: &[u8]| u16::from_be_bytes([c[0], c[1]]) as u32;
            for (p, q) in x.chunks_exact(2).zip(y.chunks_exact(2)) {
                acc.add(be(p), be(q));
            }
        } else {
            for (&p, &q) in x.iter().zip(y) {
                acc.add(p as u32, q as u32);
            }
        }
    }
    Ok(Comparison {
        width: w,
        height: h,
        kind,
        channels,
        metrics: acc.finish(),
    })
}

pub fn run(a: &CompareArgs) -> Result<()> {
    let c = compare(&a.image, &a.reference)?;
    let (w, h, kind, m) = (c.width, c.height, c.kind, &c.metrics);
    let worst_pixel = c.worst_pixel();
    if a.json {
        let r = Report {
            width: w,
            height: h,
            kind,
            channels: c.channels,
            worst_pixel,
            metrics: m,
        };
        crate::outln!("{}", serde_json::to_string_pretty(&r)?)?;
        return Ok(());
    }
    let what = format!(
        "{} against {}: {w}x{h} {kind} ({} samples)",
        a.image.display(),
        a.reference.display(),
        m.pixels
    );
    match (worst_pixel, m.psnr_db) {
        (Some((px, py, ch)), Some(psnr)) => crate::outln!(
            "compare: {what}: max abs error {} LSB at pixel ({px}, {py}) channel {ch}, mean abs error {:.4}, mean error {:+.4}, RMSE {:.4} LSB, PSNR {psnr:.2} dB (peak {})",
            m.max_abs_error, m.mean_abs_error, m.mean_error, m.rmse, m.peak
        )?,
        _ => crate::outln!("compare: {what}: identical")?,
    }
    Ok(())
}
