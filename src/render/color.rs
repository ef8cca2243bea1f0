//! Colour renders of a `--color` design: every pixel carries a sample colour, which the
//! design's colour multiplier scales by its intensity ([`crate::model::color_mul`], on the
//! model's intensity) and the reference scales by the float light model, both as 8-bit
//! channels. The sample colour is the scene's `color` when it has one; otherwise a ramp across
//! the image (red from left to right, green from top to bottom, blue falling along the
//! diagonal), so that one render shows the multiplier over many colours.

use super::sphere::Pixel;
use crate::config::{Config, COLOR_BITS};
use crate::model::color_mul;
use crate::reference::Reference;
use crate::scene::Scene;
use serde::Serialize;

/// The largest channel value.
const CMAX: u32 = (1 << COLOR_BITS) - 1;

/// A colour render: per pixel the sample colour, the design's and the reference's result.
#[derive(Clone, Debug)]
pub struct ColorRender {
    pub rgb: Vec<[u32; 3]>,
    pub model: Vec<[u32; 3]>,
    pub reference: Vec<[u32; 3]>,
    pub stats: ColorStats,
}

/// The colour figures of `metrics.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColorStats {
    /// `"scene"` (the scene's `color`) or `"ramp"` (the colour ramp across the image).
    pub source: &'static str,
    /// The largest difference of a channel, model against reference, in 8-bit colour LSBs.
    pub max_abs_error: u32,
    /// The root mean square over every channel of every pixel, in 8-bit colour LSBs.
    pub rmse: f64,
}

/// The sample colour of pixel (x, y) of a `size`-pixel image.
pub fn sample_color(scene: &Scene, size: u32, x: u32, y: u32) -> [u32; 3] {
    if let Some(c) = scene.color8() {
        return c;
    }
    let d = size.saturating_sub(1).max(1);
    let ramp = |v: u32, over: u32| (v * CMAX + over / 2) / over;
    [ramp(x, d), ramp(y, d), CMAX - ramp(x + y, 2 * d)]
}

/// The reference's channel: the colour times the light model clamped to 0..=1, rounded half
/// up (the multiplier rounds its quotient half up too).
fn reference_channel(c: u32, exact: f64) -> u32 {
    (c as f64 * exact.clamp(0.0, 1.0) + 0.5).floor() as u32
}

/// The colour render of the pixels, from the model's intensities; `None` unless the design
/// has the colour multiplier.
pub fn render(
    cfg: &Config,
    scene: &Scene,
    size: u32,
    pixels: &[Pixel],
    model: &[u32],
) -> Option<ColorRender> {
    if !cfg.color {
        return None;
    }
    let reference = Reference::new(cfg, scene);
    let rgb: Vec<[u32; 3]> = pixels
        .iter()
        .map(|&(x, y, _)| sample_color(scene, size, x, y))
        .collect();
    let out: Vec<[u32; 3]> = rgb
        .iter()
        .zip(model)
        .map(|(&c, &i)| color_mul::eval(cfg, c, i))
        .collect();
    let want: Vec<[u32; 3]> = rgb
        .iter()
        .zip(pixels)
        .map(|(&c, &(_, _, g))| {
            let e = reference.exact(g).unwrap_or(0.0);
            c.map(|v| reference_channel(v, e))
        })
        .collect();
    let (mut max, mut sq) = (0u32, 0f64);
    for (a, b) in out.iter().zip(&want) {
        for k in 0..3 {
            let d = a[k].abs_diff(b[k]);
            max = max.max(d);
            sq += (d as f64) * (d as f64);
        }
    }
    let n = (3 * pixels.len()).max(1) as f64;
    Some(ColorRender {
        stats: ColorStats {
            source: if scene.color.is_some() {
                "scene"
            } else {
                "ramp"
            },
            max_abs_error: max,
            rmse: (sq / n).sqrt(),
        },
        rgb,
        model: out,
        reference: want,
    })
}

/// An RGB image of `size` pixels, black outside the sphere.
pub fn image(size: u32, pixels: &[Pixel], values: &[[u32; 3]]) -> image::RgbImage {
    assert_eq!(pixels.len(), values.len(), "one colour per pixel");
    let mut img = image::RgbImage::new(size, size);
    for (&(x, y, _), v) in pixels.iter().zip(values) {
        img.put_pixel(x, y, image::Rgb(v.map(|c| c.min(CMAX) as u8)));
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_spans_every_channel_and_a_scene_colour_is_uniform() {
        let s = Scene::standard();
        assert_eq!(s.color, None);
        assert_eq!(sample_color(&s, 256, 0, 0), [0, 0, 255]);
        assert_eq!(sample_color(&s, 256, 255, 0), [255, 0, 127]);
        assert_eq!(sample_color(&s, 256, 0, 255), [0, 255, 127]);
        assert_eq!(sample_color(&s, 256, 255, 255), [255, 255, 0]);
        assert_eq!(sample_color(&s, 1, 0, 0), [0, 0, 255]);
        let s = Scene {
            color: Some([1.0, 0.5, 0.0]),
            ..Scene::standard()
        };
        for (x, y) in [(0, 0), (17, 200), (255, 255)] {
            assert_eq!(sample_color(&s, 256, x, y), [255, 128, 0]);
        }
    }

    #[test]
    fn the_reference_rounds_the_colour_times_the_clamped_light() {
        assert_eq!(reference_channel(255, 1.0), 255);
        assert_eq!(reference_channel(255, 1.7), 255);
        assert_eq!(reference_channel(255, -0.2), 0);
        assert_eq!(reference_channel(200, 0.5), 100);
        assert_eq!(reference_channel(3, 0.5), 2);
        assert_eq!(reference_channel(3, 0.49), 1);
    }

    #[test]
    fn a_colour_design_is_rendered_in_colour_within_a_few_lsb() {
        let cfg = Config {
            color: true,
            ..Config::default()
        };
        let scene = Scene::standard();
        let size = 64;
        let pixels = super::super::sphere_gradients(&cfg, size, 0);
        let grads: Vec<_> = pixels.iter().map(|p| p.2).collect();
        let model = super::super::model_intensities(
            &crate::model::Model::new(&cfg),
            &scene.maps(&cfg),
            &grads,
        );
        let c = render(&cfg, &scene, size, &pixels, &model).unwrap();
        // Each channel is the multiplier's result on the model's intensity.
        for ((out, &rgb), &i) in c.model.iter().zip(&c.rgb).zip(&model) {
            assert_eq!(*out, color_mul::eval(&cfg, rgb, i));
        }
        assert_eq!(c.stats.source, "ramp");
        // The intensity's error, scaled by a colour of at most 255 over 2^M - 1, plus rounding.
        let m = super::super::metrics(
            &model,
            &Reference::new(&cfg, &scene).intensities(&grads),
            cfg.map_max(),
        );
        assert!(
            c.stats.max_abs_error <= m.max_abs_error + 1,
            "{:?}",
            c.stats
        );
        assert!(c.stats.max_abs_error > 0);
        // The image is in colour: some pixel's channels differ.
        let img = image(size, &pixels, &c.model);
        assert!(img.pixels().any(|p| p[0] != p[1] || p[1] != p[2]));
        // Without the multiplier there is no colour render.
        assert!(render(&Config::default(), &scene, size, &pixels, &model).is_none());
    }
}
