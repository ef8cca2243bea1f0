//! 8-bit grey PNG images of a render: the inside pixels carry values, the background is 0.

use super::sphere::Pixel;
use anyhow::{Context, Result};
use image::{GrayImage, ImageFormat, Luma};
use std::io::Cursor;

/// Gain of the error image, as in the paper's Figure 7.
pub const ERROR_GAIN: u32 = 50;

/// An `map_bits`-wide intensity for display: the range 0..=2^M - 1 is rescaled linearly onto
/// 0..=255 and rounded to nearest (v * 255 / (2^M - 1), half up), so 0 stays black, full scale
/// stays white and M = 8 is the identity.
pub fn display8(v: u32, map_bits: u32) -> u8 {
    let max = (1u64 << map_bits) - 1;
    let v = (v as u64).min(max);
    ((v * 255 + max / 2) / max) as u8
}

/// One pixel of the error image: |a - b| in output LSBs (not rescaled for display, so one
/// LSB is always 50 grey levels) times [`ERROR_GAIN`], clamped to 255.
pub fn error50(a: u32, b: u32) -> u8 {
    (a.abs_diff(b).saturating_mul(ERROR_GAIN)).min(255) as u8
}

/// An `size` x `size` image, 0 outside the sphere and `values[i]` at `pixels[i]`.
pub fn grey(size: u32, pixels: &[Pixel], values: impl IntoIterator<Item = u8>) -> GrayImage {
    let mut img = GrayImage::new(size, size);
    let mut n = 0;
    for (&(x, y, _), v) in pixels.iter().zip(values) {
        img.put_pixel(x, y, Luma([v]));
        n += 1;
    }
    assert_eq!(n, pixels.len(), "one value per pixel");
    img
}

/// An RGB image encoded as PNG.
pub fn png_rgb(img: &image::RgbImage) -> Result<Vec<u8>> {
    let mut buf = Cursor::new(Vec::new());
    img.write_to(&mut buf, ImageFormat::Png)
        .context("cannot encode PNG")?;
    Ok(buf.into_inner())
}

/// The image encoded as PNG.
pub fn png(img: &GrayImage) -> Result<Vec<u8>> {
    let mut buf = Cursor::new(Vec::new());
    img.write_to(&mut buf, ImageFormat::Png)
        .context("cannot encode PNG")?;
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_scaling() {
        for v in 0..=255 {
            assert_eq!(display8(v, 8), v as u8);
        }
        assert_eq!(
            (display8(0, 10), display8(1023, 10), display8(512, 10)),
            (0, 255, 128)
        );
        assert_eq!((display8(63, 6), display8(1, 6)), (255, 4));
    }

    #[test]
    fn error_gain_and_clamp() {
        assert_eq!(
            (error50(7, 7), error50(7, 8), error50(9, 4), error50(6, 0)),
            (0, 50, 250, 255)
        );
    }

    #[test]
    fn png_round_trip() {
        let px = [(1, 0, [0; 3]), (0, 1, [0; 3])];
        let img = grey(2, &px, [200, 100]);
        let back = image::load_from_memory(&png(&img).unwrap())
            .unwrap()
            .to_luma8();
        assert_eq!(back.into_raw(), vec![0, 200, 100, 0]);
    }
}
