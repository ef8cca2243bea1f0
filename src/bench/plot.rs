//! Scatter plots of error against a cost (bits, or run time), one colour per scene, one marker
//! per map kind, each scene's Pareto front as a line; drawn once into an SVG string and once
//! into an RGB buffer saved as PNG with `image`.
//!
//! Text needs a font ([`crate::plotting::font`]); without one the plots are drawn without
//! captions and labels.

use crate::plotting::font;
use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One point: x, y, scene index, marker (0 sampled cube map, 1 fitted, 2 octahedral, 3 fitted
/// with a loaded compensation table, drawn last as an outlined bar).
#[derive(Clone, Copy, Debug)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub scene: usize,
    pub marker: u8,
}

pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub scenes: &'a [String],
    pub points: &'a [Point],
    /// Per scene, the Pareto front in x order.
    pub fronts: &'a [Vec<(f64, f64)>],
}

const SIZE: (u32, u32) = (900, 600);
fn colour(scene: usize) -> RGBColor {
    [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
    ][scene % 4]
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, c: &Chart) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("plot {}: {x:?}", c.title);
    root.fill(&WHITE).map_err(e)?;
    let text = font();
    let (x0, x1) = c
        .points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.x), b.max(p.x))
        });
    let y1 = c.points.iter().fold(0.0f64, |a, p| a.max(p.y)) * 1.08 + 1e-9;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(20);
    if text {
        builder
            .caption(c.title, ("sans-serif", 22))
            .x_label_area_size(45)
            .y_label_area_size(60);
    } else {
        builder.x_label_area_size(10).y_label_area_size(10);
    }
    macro_rules! body {
        ($chart:expr) => {{
            let mut chart = $chart;
            let mut mesh = chart.configure_mesh();
            if text {
                mesh.x_desc(c.x_label)
                    .y_desc(c.y_label)
                    .label_style(("sans-serif", 14));
            } else {
                mesh.disable_x_mesh()
                    .disable_y_mesh()
                    .x_labels(0)
                    .y_labels(0);
            }
            mesh.draw().map_err(e)?;
            for (s, front) in c.fronts.iter().enumerate() {
                let col = colour(s);
                let series = chart
                    .draw_series(LineSeries::new(front.iter().copied(), col.stroke_width(2)))
                    .map_err(e)?;
                if text {
                    series.label(&c.scenes[s]).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                    });
                }
            }
            // The loaded-table points last, on top of the others at about the same memory.
            let order = c
                .points
                .iter()
                .filter(|p| p.marker != 3)
                .chain(c.points.iter().filter(|p| p.marker == 3));
            for p in order {
                let col = colour(p.scene);
                let xy = (p.x, p.y);
                match p.marker {
                    0 => chart
                        .draw_series(std::iter::once(Circle::new(xy, 5, col.filled())))
                        .map_err(e)?,
                    1 => chart
                        .draw_series(std::iter::once(TriangleMarker::new(xy, 7, col.filled())))
                        .map_err(e)?,
                    // A bar outlined in black, about one LSB high on the error charts: it sits
                    // among the other designs of about the same memory.
                    3 => {
                        let corners = [
                            (p.x * 0.965, p.y - y1 * 0.009),
                            (p.x * 1.035, p.y + y1 * 0.009),
                        ];
                        chart
                            .draw_series(std::iter::once(Rectangle::new(corners, col.filled())))
                            .map_err(e)?;
                        chart
                            .draw_series(std::iter::once(Rectangle::new(
                                corners,
                                BLACK.stroke_width(2),
                            )))
                            .map_err(e)?
                    }
                    _ => chart
                        .draw_series(std::iter::once(Cross::new(xy, 6, col.stroke_width(2))))
                        .map_err(e)?,
                };
            }
            if text {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 14))
                    .draw()
                    .map_err(e)?;
            }
        }};
    }
    if c.log_x {
        body!(builder
            .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), 0.0..y1)
            .map_err(e)?);
    } else {
        let pad = (x1 - x0).max(1e-9) * 0.08;
        body!(builder
            .build_cartesian_2d(x0 - pad..x1 + pad, 0.0..y1)
            .map_err(e)?);
    }
    root.present().map_err(e)?;
    Ok(())
}

/// The chart as an SVG document.
pub fn svg(c: &Chart) -> Result<String> {
    let mut s = String::new();
    draw(SVGBackend::with_string(&mut s, SIZE).into_drawing_area(), c)?;
    Ok(s)
}

/// The chart as a PNG file's bytes.
pub fn png(c: &Chart) -> Result<Vec<u8>> {
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(
        BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area(),
        c,
    )?;
    let img = image::RgbImage::from_raw(SIZE.0, SIZE.1, buf)
        .ok_or_else(|| anyhow!("plot buffer size"))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)?;
    Ok(out.into_inner())
}
