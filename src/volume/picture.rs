//! The pixel formats a volume render's images are written in (`--png`): 8-bit grey (the
//! default, as the sphere render), 16-bit grey (the full `map_bits` range without rounding
//! to 8 bits) and RGBA (grey with the accumulated opacity as straight alpha, to lay the
//! volume over any background). The error image is always 8-bit grey (50 levels per LSB).

use crate::render::images::display8;
use anyhow::{Context, Result};
use image::{DynamicImage, GrayImage, ImageBuffer, ImageFormat, Luma, Rgba};
use serde::Serialize;
use std::io::Cursor;

#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PixelFormat {
    /// 8-bit grey.
    #[default]
    Gray8,
    /// 16-bit grey: v * 65535 / (2^M - 1), rounded half up.
    Gray16,
    /// 8-bit RGBA: grey un-premultiplied by the opacity, alpha = opacity * 255.
    Rgba,
}

/// An M-bit intensity on 0..=65535 (0 stays black, full scale white), rounded half up.
pub fn display16(v: u32, map_bits: u32) -> u16 {
    let max = (1u64 << map_bits) - 1;
    let v = (v as u64).min(max);
    ((v * 65535 + max / 2) / max) as u16
}

/// An `n` x `n` image of intensities `v` (with the pixels' accumulated opacities `alpha`
/// for RGBA) in format `f`.
pub fn shown(v: &[u32], alpha: &[f32], n: u32, map_bits: u32, f: PixelFormat) -> DynamicImage {
    match f {
        PixelFormat::Gray8 => DynamicImage::ImageLuma8(
            GrayImage::from_raw(n, n, v.iter().map(|&i| display8(i, map_bits)).collect())
                .expect("n x n pixels"),
        ),
        PixelFormat::Gray16 => {
            let px: Vec<u16> = v.iter().map(|&i| display16(i, map_bits)).collect();
            DynamicImage::ImageLuma16(
                ImageBuffer::<Luma<u16>, _>::from_raw(n, n, px).expect("n x n pixels"),
            )
        }
        PixelFormat::Rgba => {
            let mut img = ImageBuffer::<Rgba<u8>, Vec<u8>>::new(n, n);
            for (p, (&i, &a)) in img.pixels_mut().zip(v.iter().zip(alpha)) {
                // The composited value is premultiplied (black background): divide by the
                // opacity for the straight alpha PNG expects.
                let a = a.clamp(0.0, 1.0);
                let g = if a > 0.0 {
                    (display8(i, map_bits) as f32 / a).round().min(255.0) as u8
                } else {
                    0
                };
                *p = Rgba([g, g, g, (a * 255.0).round() as u8]);
            }
            DynamicImage::ImageRgba8(img)
        }
    }
}

/// The PNG bytes of an image.
pub fn png(img: &DynamicImage) -> Result<Vec<u8>> {
    let mut buf = Cursor::new(Vec::new());
    img.write_to(&mut buf, ImageFormat::Png)
        .context("cannot encode PNG")?;
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats() {
        assert_eq!((display16(0, 8), display16(255, 8)), (0, 65535));
        assert_eq!(display16(1, 8), 257);
        assert_eq!(display16(2047, 11), 65535);
        let v = [0, 128, 255, 255];
        let a = [0.0, 0.5, 1.0, 0.25];
        let g = shown(&v, &a, 2, 8, PixelFormat::Gray8).to_luma8();
        assert_eq!(g.into_raw(), vec![0, 128, 255, 255]);
        let g = shown(&v, &a, 2, 8, PixelFormat::Gray16).to_luma16();
        assert_eq!(g.into_raw(), vec![0, 32896, 65535, 65535]);
        let c = shown(&v, &a, 2, 8, PixelFormat::Rgba).to_rgba8();
        assert_eq!(
            c.pixels().map(|p| p.0).collect::<Vec<_>>(),
            vec![
                [0, 0, 0, 0],
                [255, 255, 255, 128],
                [255; 4],
                [255, 255, 255, 64]
            ]
        );
        let bytes = png(&shown(&v, &a, 2, 8, PixelFormat::Gray16)).unwrap();
        let back = image::load_from_memory(&bytes).unwrap();
        assert_eq!(back.color(), image::ColorType::L16);
    }
}
