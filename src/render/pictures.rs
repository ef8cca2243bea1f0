//! The pictures of a render that a user looks at rather than reads (issue 34 §4), beside the
//! paper's grey images:
//!
//! - `highlight.png`: the region around the worst pixel (the highlight), reference, model and
//!   signed error side by side, each pixel a [`ZOOM`] × [`ZOOM`] block (nearest neighbour);
//! - `error_signed.png`: model − reference over the sphere in a diverging colour scale (blue
//!   below, white equal, red above), with the scale bar and its range in LSB;
//! - `profile.png`: reference and model intensity along the image row through the worst pixel;
//! - `histogram.png`: how many pixels have each signed error, on a log scale.
//!
//! Text (the bar's range, the plots' labels) needs a system font ([`crate::plotting::font`]);
//! without one the pictures are drawn without it.

use super::sphere::Pixel;
use crate::plotting::font;
use anyhow::{anyhow, Result};
use image::{Rgb, RgbImage};
use plotters::prelude::*;

/// Side of the crop around the worst pixel, in image pixels (smaller images: the image).
pub const CROP: u32 = 32;
/// Each cropped pixel's side in `highlight.png`.
pub const ZOOM: u32 = 8;
/// The gap between the three crops of `highlight.png`, in its pixels.
pub const GAP: u32 = 8;
/// The background: outside the sphere, and between the crops.
pub const BACKGROUND: Rgb<u8> = Rgb([64, 64, 64]);

/// The diverging colour of a signed error `e` on the scale ±`range` (`range` >= 1): white at
/// 0, fully blue at -range and below, fully red at +range and above.
pub fn signed_colour(e: i64, range: i64) -> Rgb<u8> {
    let t = (e.unsigned_abs() as f64 / range.max(1) as f64).min(1.0);
    let fade = (255.0 * (1.0 - t)).round() as u8;
    if e >= 0 {
        Rgb([255, fade, fade])
    } else {
        Rgb([fade, fade, 255])
    }
}

/// The crop's first column and row: [`CROP`] pixels (at most `size`) around `(x, y)`, kept
/// inside the image.
pub fn crop_origin(size: u32, x: u32, y: u32) -> (u32, u32, u32) {
    let side = CROP.min(size);
    let start = |c: u32| c.saturating_sub(side / 2).min(size - side);
    (start(x), start(y), side)
}

/// What the pictures are drawn from: the render's inside pixels and their values.
pub struct Source<'a> {
    pub size: u32,
    pub pixels: &'a [Pixel],
    pub reference: &'a [u32],
    pub model: &'a [u32],
    /// Values shown as grey: v -> 0..=255.
    pub grey: &'a dyn Fn(u32) -> u8,
    /// The worst pixel's index in `pixels`.
    pub worst: Option<usize>,
    /// The largest |model - reference|, the colour scale's range (at least 1).
    pub range: u32,
}

impl Source<'_> {
    /// Every picture by file name, in the order of [`super::PICTURES`]; `max` is the largest
    /// intensity (the profile's scale).
    pub fn all(&self, max: u32) -> Result<Vec<(&'static str, RgbImage)>> {
        let p = super::PICTURES;
        Ok(vec![
            (p[0], self.highlight()),
            (p[1], self.error_signed()?),
            (p[2], self.profile(max)?),
            (p[3], self.histogram()?),
        ])
    }

    fn at(&self) -> Vec<Option<usize>> {
        let mut at = vec![None; (self.size * self.size) as usize];
        for (i, &(x, y, _)) in self.pixels.iter().enumerate() {
            at[(y * self.size + x) as usize] = Some(i);
        }
        at
    }

    fn error(&self, i: usize) -> i64 {
        self.model[i] as i64 - self.reference[i] as i64
    }

    /// `highlight.png`: reference | model | signed error around the worst pixel, zoomed.
    pub fn highlight(&self) -> RgbImage {
        let (wx, wy) = self.worst.map_or((self.size / 2, self.size / 2), |i| {
            (self.pixels[i].0, self.pixels[i].1)
        });
        let (x0, y0, side) = crop_origin(self.size, wx, wy);
        let panel = side * ZOOM;
        let mut img = RgbImage::from_pixel(3 * panel + 2 * GAP, panel, BACKGROUND);
        let at = self.at();
        for dy in 0..side {
            for dx in 0..side {
                let Some(i) = at[((y0 + dy) * self.size + x0 + dx) as usize] else {
                    continue;
                };
                let g = |v: u32| {
                    let l = (self.grey)(v);
                    Rgb([l, l, l])
                };
                let colours = [
                    g(self.reference[i]),
                    g(self.model[i]),
                    signed_colour(self.error(i), self.range as i64),
                ];
                for (k, c) in colours.into_iter().enumerate() {
                    let left = k as u32 * (panel + GAP) + dx * ZOOM;
                    for py in 0..ZOOM {
                        for px in 0..ZOOM {
                            img.put_pixel(left + px, dy * ZOOM + py, c);
                        }
                    }
                }
            }
        }
        img
    }

    /// `error_signed.png`: the signed error over the sphere, and the scale bar beside it.
    pub fn error_signed(&self) -> Result<RgbImage> {
        let bar = 120u32;
        let (w, h) = (self.size + bar, self.size.max(160));
        let mut buf = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            let e = |e: DrawingAreaErrorKind<_>| anyhow!("drawing error_signed.png: {e}");
            root.fill(&RGBColor(BACKGROUND.0[0], BACKGROUND.0[1], BACKGROUND.0[2]))
                .map_err(e)?;
            for (i, &(x, y, _)) in self.pixels.iter().enumerate() {
                let Rgb([r, g, b]) = signed_colour(self.error(i), self.range as i64);
                root.draw_pixel((x as i32, y as i32), &RGBColor(r, g, b))
                    .map_err(e)?;
            }
            // The bar: +range at the top, -range at the bottom.
            let (top, bottom) = (20i32, h as i32 - 20);
            let x = self.size as i32 + 16;
            let r = self.range as i64;
            for py in top..bottom {
                let t = (bottom - 1 - py) as f64 / (bottom - 1 - top) as f64;
                let v = (-r as f64 + 2.0 * r as f64 * t).round() as i64;
                let Rgb([cr, cg, cb]) = signed_colour(v, r);
                root.draw(&Rectangle::new(
                    [(x, py), (x + 20, py + 1)],
                    RGBColor(cr, cg, cb).filled(),
                ))
                .map_err(e)?;
            }
            if font() {
                let style = ("sans-serif", 14).into_font().color(&WHITE);
                for (label, py) in [
                    (format!("+{r} LSB"), top),
                    ("0".to_string(), (top + bottom) / 2),
                    (format!("-{r} LSB"), bottom - 14),
                ] {
                    root.draw_text(&label, &style, (x + 26, py)).map_err(e)?;
                }
                root.draw_text("model - reference", &style, (x - 8, 2))
                    .map_err(e)?;
            }
            root.present().map_err(e)?;
        }
        RgbImage::from_raw(w, h, buf).ok_or_else(|| anyhow!("error_signed.png: buffer size"))
    }

    /// `profile.png`: reference and model along the row through the worst pixel.
    pub fn profile(&self, full_scale: u32) -> Result<RgbImage> {
        let row = self.worst.map_or(self.size / 2, |i| self.pixels[i].1);
        let mut points: Vec<(u32, u32, u32)> = self
            .pixels
            .iter()
            .enumerate()
            .filter(|(_, p)| p.1 == row)
            .map(|(i, p)| (p.0, self.reference[i], self.model[i]))
            .collect();
        points.sort();
        let size = (800u32, 400u32);
        let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
            let e = |e: DrawingAreaErrorKind<_>| anyhow!("drawing profile.png: {e}");
            root.fill(&WHITE).map_err(e)?;
            let text = font();
            let mut b = ChartBuilder::on(&root);
            b.margin(12);
            if text {
                b.caption(
                    format!("intensity along row {row} (through the worst pixel)"),
                    ("sans-serif", 18),
                )
                .x_label_area_size(32)
                .y_label_area_size(48);
            }
            let mut chart = b
                .build_cartesian_2d(0u32..self.size, 0u32..full_scale + 1)
                .map_err(e)?;
            if text {
                chart
                    .configure_mesh()
                    .x_desc("column")
                    .y_desc("intensity (LSB)")
                    .draw()
                    .map_err(e)?;
            }
            for (k, colour) in [(0usize, BLUE), (1, RED)] {
                let series = LineSeries::new(
                    points
                        .iter()
                        .map(|&(x, r, m)| (x, if k == 0 { r } else { m })),
                    colour.stroke_width(2),
                );
                let drawn = chart.draw_series(series).map_err(e)?;
                if text {
                    drawn
                        .label(if k == 0 { "reference" } else { "model" })
                        .legend(move |(x, y)| {
                            PathElement::new([(x, y), (x + 16, y)], colour.stroke_width(2))
                        });
                }
            }
            if text {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .border_style(BLACK)
                    .background_style(WHITE)
                    .draw()
                    .map_err(e)?;
            }
            root.present().map_err(e)?;
        }
        RgbImage::from_raw(size.0, size.1, buf).ok_or_else(|| anyhow!("profile.png: buffer size"))
    }

    /// The pixels with each signed error, from -range to +range.
    pub fn histogram_counts(&self) -> Vec<(i64, u64)> {
        let r = self.range as i64;
        let mut counts = vec![0u64; (2 * r + 1) as usize];
        for i in 0..self.pixels.len() {
            counts[(self.error(i).clamp(-r, r) + r) as usize] += 1;
        }
        (-r..=r).zip(counts).collect()
    }

    /// `histogram.png`: the counts of [`Source::histogram_counts`] as bars, log scale.
    pub fn histogram(&self) -> Result<RgbImage> {
        let counts = self.histogram_counts();
        let r = self.range as i64;
        let top = counts.iter().map(|c| c.1).max().unwrap_or(1).max(1) as f64 * 2.0;
        let size = (800u32, 400u32);
        let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
            let e = |e: DrawingAreaErrorKind<_>| anyhow!("drawing histogram.png: {e}");
            root.fill(&WHITE).map_err(e)?;
            let text = font();
            let mut b = ChartBuilder::on(&root);
            b.margin(12);
            if text {
                b.caption(
                    "pixels by signed error (model - reference)",
                    ("sans-serif", 18),
                )
                .x_label_area_size(32)
                .y_label_area_size(56);
            }
            let mut chart = b
                .build_cartesian_2d(-r as f64 - 0.5..r as f64 + 0.5, (0.5f64..top).log_scale())
                .map_err(e)?;
            if text {
                chart
                    .configure_mesh()
                    .x_desc("error (LSB)")
                    .y_desc("pixels")
                    .x_label_formatter(&|v| format!("{v:.0}"))
                    .y_label_formatter(&|v| format!("{v:.0}"))
                    .draw()
                    .map_err(e)?;
            }
            chart
                .draw_series(counts.iter().filter(|c| c.1 > 0).map(|&(v, n)| {
                    let Rgb([cr, cg, cb]) = signed_colour(v, r);
                    let fill = if v == 0 {
                        RGBColor(160, 160, 160)
                    } else {
                        RGBColor(cr, cg, cb)
                    };
                    Rectangle::new(
                        [(v as f64 - 0.4, 0.5), (v as f64 + 0.4, n as f64)],
                        fill.filled(),
                    )
                }))
                .map_err(e)?;
            root.present().map_err(e)?;
        }
        RgbImage::from_raw(size.0, size.1, buf).ok_or_else(|| anyhow!("histogram.png: buffer size"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_is_white_at_zero_and_saturates_at_the_range() {
        assert_eq!(signed_colour(0, 5), Rgb([255, 255, 255]));
        assert_eq!(signed_colour(5, 5), Rgb([255, 0, 0]));
        assert_eq!(signed_colour(9, 5), Rgb([255, 0, 0]));
        assert_eq!(signed_colour(-5, 5), Rgb([0, 0, 255]));
        let half = signed_colour(-2, 4);
        assert_eq!(half, Rgb([128, 128, 255]));
        // A crop stays inside the image, centred where it can be.
        assert_eq!(crop_origin(512, 300, 10), (284, 0, 32));
        assert_eq!(crop_origin(512, 511, 500), (480, 480, 32));
        assert_eq!(crop_origin(20, 3, 3), (0, 0, 20));
    }
}
