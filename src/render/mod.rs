//! The sphere test image: every inside pixel shaded by the bit-accurate model and by the float
//! reference, the images of both, the error image enlarged 50 times (the paper's Figures 6
//! and 7) and the error statistics.
//!
//! A third source of intensities for the same pixels (an RTL simulation of the generated
//! design) plugs in through [`IntensitySource`]: it adds `rtl.png` and the `rtl_equals_model`
//! and `rtl_mismatches` fields of `metrics.json`.

pub mod color;
pub mod images;
pub mod metrics;
pub mod pictures;
pub mod report;
pub mod sphere;

use crate::config::Config;
use crate::model::{IntensitySource, Maps, Model};
use crate::output::StagedDir;
use crate::reference::Reference;
use crate::scene::Scene;
use anyhow::{ensure, Result};
use rayon::prelude::*;
use serde::Serialize;

pub use metrics::{metrics, Metrics};
pub use sphere::{sphere_gradients, Pixel};

pub const DEFAULT_SIZE: u32 = 512;
/// Largest image side: 4096² pixels keep a render within a few hundred MB.
pub const MAX_SIZE: u32 = 4096;

/// What to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Image width and height in pixels.
    pub size: u32,
    /// Gradients are scaled down by 2^shrink (exercises the leading-zero shift).
    pub shrink: u32,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            size: DEFAULT_SIZE,
            shrink: 0,
        }
    }
}

impl Options {
    pub fn validate(&self, cfg: &Config) -> Result<()> {
        ensure!(
            (1..=MAX_SIZE).contains(&self.size),
            "image size {} is out of range; allowed 1..={MAX_SIZE}",
            self.size
        );
        let max = sphere::max_shrink(cfg);
        ensure!(
            self.shrink <= max,
            "shrink {} is out of range; allowed 0..={max} for grad_bits = {} (more would round gradients to zero)",
            self.shrink,
            cfg.grad_bits
        );
        Ok(())
    }
}

/// The model's intensities of many gradients, in order, in parallel.
pub fn model_intensities(model: &Model, maps: &Maps, gradients: &[[i32; 3]]) -> Vec<u32> {
    gradients
        .par_iter()
        .map(|&g| model.intensity(maps, g))
        .collect()
}

/// The pictures' file names, in the order [`Render::pictures`] gives them.
pub const PICTURES: [&str; 4] = [
    "highlight.png",
    "error_signed.png",
    "profile.png",
    "histogram.png",
];

/// The colour images of a `--color` design, in the order [`Render::color_images`] gives them.
pub const COLOR_IMAGES: [&str; 3] = [
    "color_reference.png",
    "color_model.png",
    "color_error50.png",
];

/// A finished render: every inside pixel and its values from each source.
#[derive(Clone, Debug)]
pub struct Render {
    pub cfg: Config,
    pub scene: Scene,
    pub options: Options,
    pub pixels: Vec<Pixel>,
    pub model: Vec<u32>,
    pub reference: Vec<u32>,
    /// Present when an RTL source was given.
    pub rtl: Option<Vec<u32>>,
    /// The model against the reference.
    pub metrics: Metrics,
    /// A `--color` design's colour render ([`color`]).
    pub color: Option<color::ColorRender>,
}

/// The pixel with the largest model error, as written to `metrics.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorstPixel {
    pub x: u32,
    pub y: u32,
    pub gradient: [i32; 3],
    pub model: u32,
    pub reference: u32,
    /// The unquantised reference in output LSBs (light model times 2^M - 1, unclamped).
    pub reference_exact: f64,
}

/// `metrics.json`: the model-against-reference statistics at the top level, then context.
#[derive(Serialize)]
struct Report<'a> {
    generator: String,
    size: u32,
    shrink: u32,
    #[serde(flatten)]
    metrics: &'a Metrics,
    worst: Option<WorstPixel>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rtl_equals_model: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rtl_mismatches: Option<usize>,
    /// A `--color` design's colour figures (8-bit channels).
    #[serde(skip_serializing_if = "Option::is_none")]
    color: Option<&'a color::ColorStats>,
    images: Vec<&'static str>,
    config: &'a Config,
    scene: &'a Scene,
}

/// Shades the sphere with the model, the reference and, when given, an RTL source.
pub fn render(
    cfg: &Config,
    scene: &Scene,
    options: Options,
    rtl: Option<&dyn IntensitySource>,
) -> Result<Render> {
    options.validate(cfg)?;
    render_with(&Model::new(cfg), &scene.maps(cfg), scene, options, rtl)
}

/// [`render`] with the model and the scene's maps already built (`rmapgen explore` keeps
/// them to trace the pixels it is asked about).
pub fn render_with(
    model: &Model,
    maps: &Maps,
    scene: &Scene,
    options: Options,
    rtl: Option<&dyn IntensitySource>,
) -> Result<Render> {
    let cfg = &model.cfg;
    options.validate(cfg)?;
    let pixels = sphere_gradients(cfg, options.size, options.shrink);
    let gradients: Vec<[i32; 3]> = pixels.iter().map(|p| p.2).collect();
    let model = model_intensities(model, maps, &gradients);
    let reference = Reference::new(cfg, scene).intensities(&gradients);
    let rtl = match rtl {
        None => None,
        Some(src) => {
            let v = src.intensities(&gradients)?;
            ensure!(
                v.len() == gradients.len(),
                "RTL gave {} intensities for {} pixels",
                v.len(),
                gradients.len()
            );
            if let Some(bad) = v.iter().find(|&&i| i > cfg.map_max()) {
                anyhow::bail!(
                    "RTL gave intensity {bad}, wider than map_bits = {}",
                    cfg.map_bits
                );
            }
            Some(v)
        }
    };
    let metrics = metrics(&model, &reference, cfg.map_max());
    let color = color::render(cfg, scene, options.size, &pixels, &model);
    Ok(Render {
        cfg: cfg.clone(),
        scene: scene.clone(),
        options,
        pixels,
        model,
        reference,
        rtl,
        metrics,
        color,
    })
}

impl Render {
    /// The worst pixel of the model against the reference.
    pub fn worst(&self) -> Option<WorstPixel> {
        let i = self.metrics.worst_index?;
        let (x, y, gradient) = self.pixels[i];
        let exact = Reference::new(&self.cfg, &self.scene)
            .exact(gradient)
            .unwrap_or(0.0);
        Some(WorstPixel {
            x,
            y,
            gradient,
            model: self.model[i],
            reference: self.reference[i],
            reference_exact: exact * self.cfg.map_max() as f64,
        })
    }

    /// Pixels where the RTL differs from the model; `None` without an RTL source.
    pub fn rtl_mismatches(&self) -> Option<usize> {
        let rtl = self.rtl.as_ref()?;
        Some(rtl.iter().zip(&self.model).filter(|(a, b)| a != b).count())
    }

    /// File names of the images, in the order [`Render::images`] gives them, then the
    /// pictures of [`Render::pictures`].
    pub fn image_names(&self) -> Vec<&'static str> {
        let mut v = vec!["reference.png", "model.png", "error50.png"];
        if self.rtl.is_some() {
            v.push("rtl.png");
        }
        v.extend(PICTURES);
        if self.color.is_some() {
            v.extend(COLOR_IMAGES);
        }
        v
    }

    /// What the pictures are drawn from.
    pub fn picture_source<'a>(&'a self, grey: &'a dyn Fn(u32) -> u8) -> pictures::Source<'a> {
        pictures::Source {
            size: self.options.size,
            pixels: &self.pixels,
            reference: &self.reference,
            model: &self.model,
            grey,
            worst: self.metrics.worst_index,
            range: self.metrics.max_abs_error.max(1),
        }
    }

    /// The pictures ([`pictures`]): the highlight zoomed, the signed error with its scale,
    /// the profile through the worst pixel and the error histogram, by file name.
    pub fn pictures(&self) -> Result<Vec<(&'static str, image::RgbImage)>> {
        let m = self.cfg.map_bits;
        let grey = move |v: u32| images::display8(v, m);
        self.picture_source(&grey).all(self.cfg.map_max())
    }

    /// The images by file name.
    pub fn images(&self) -> Vec<(&'static str, image::GrayImage)> {
        let n = self.options.size;
        let m = self.cfg.map_bits;
        let shown =
            |v: &[u32]| images::grey(n, &self.pixels, v.iter().map(|&i| images::display8(i, m)));
        let mut v = vec![
            ("reference.png", shown(&self.reference)),
            ("model.png", shown(&self.model)),
            (
                "error50.png",
                images::grey(
                    n,
                    &self.pixels,
                    self.model
                        .iter()
                        .zip(&self.reference)
                        .map(|(&a, &b)| images::error50(a, b)),
                ),
            ),
        ];
        if let Some(rtl) = &self.rtl {
            v.push(("rtl.png", shown(rtl)));
        }
        v
    }

    /// A `--color` design's colour images: the reference, the design and their largest
    /// channel difference times 50 (grey), by file name; empty for another design.
    pub fn color_images(&self) -> Vec<(&'static str, image::RgbImage)> {
        let Some(c) = &self.color else {
            return Vec::new();
        };
        let n = self.options.size;
        let err: Vec<[u32; 3]> = c
            .model
            .iter()
            .zip(&c.reference)
            .map(|(a, b)| {
                let e = (0..3)
                    .map(|k| images::error50(a[k], b[k]))
                    .max()
                    .unwrap_or(0);
                [e as u32; 3]
            })
            .collect();
        vec![
            (COLOR_IMAGES[0], color::image(n, &self.pixels, &c.reference)),
            (COLOR_IMAGES[1], color::image(n, &self.pixels, &c.model)),
            (COLOR_IMAGES[2], color::image(n, &self.pixels, &err)),
        ]
    }

    /// `metrics.json`.
    pub fn metrics_json(&self) -> Result<String> {
        let mismatches = self.rtl_mismatches();
        let report = Report {
            generator: format!("rmapgen {}", env!("CARGO_PKG_VERSION")),
            size: self.options.size,
            shrink: self.options.shrink,
            metrics: &self.metrics,
            worst: self.worst(),
            rtl_equals_model: mismatches.map(|n| n == 0),
            rtl_mismatches: mismatches,
            color: self.color.as_ref().map(|c| &c.stats),
            images: self.image_names(),
            config: &self.cfg,
            scene: &self.scene,
        };
        Ok(serde_json::to_string_pretty(&report)?)
    }

    /// Writes the images and `metrics.json`.
    pub fn write(&self, out: &StagedDir) -> Result<()> {
        let mut files = Vec::new();
        for (name, img) in self.images() {
            files.push((name, images::png(&img)?));
        }
        for (name, img) in self.pictures()?.into_iter().chain(self.color_images()) {
            files.push((name, images::png_rgb(&img)?));
        }
        for (name, png) in &files {
            out.write_bytes(name, png)?;
        }
        out.write_text("report.html", &report::html(self, &files)?)?;
        out.write_text("metrics.json", &self.metrics_json()?)
    }

    /// One line: the model's error against the reference (and the RTL verdict when present).
    pub fn summary(&self) -> String {
        let m = &self.metrics;
        let psnr = m.psnr_db.map_or("inf".to_string(), |p| format!("{p:.2}"));
        let mut s = format!(
            "{n}x{n} sphere, shrink {k}, {px} pixels: max abs error {e} LSB, RMSE {r:.3} LSB, PSNR {psnr} dB",
            n = self.options.size,
            k = self.options.shrink,
            px = m.pixels,
            e = m.max_abs_error,
            r = m.rmse
        );
        if let Some(c) = &self.color {
            s.push_str(&format!(
                "; colour ({}): max abs error {} LSB, RMSE {:.3} LSB of 8-bit channels",
                c.stats.source, c.stats.max_abs_error, c.stats.rmse
            ));
        }
        if let Some(n) = self.rtl_mismatches() {
            s.push_str(&format!(
                "; RTL {}",
                if n == 0 {
                    "equals the model".to_string()
                } else {
                    format!("differs from the model at {n} pixels")
                }
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Fixed(Vec<u32>);
    impl IntensitySource for Fixed {
        fn intensities(&self, _: &[[i32; 3]]) -> Result<Vec<u32>> {
            Ok(self.0.clone())
        }
    }

    #[test]
    fn options_are_checked() {
        let c = Config::default();
        assert!(Options { size: 0, shrink: 0 }
            .validate(&c)
            .unwrap_err()
            .to_string()
            .contains("size 0"));
        assert!(Options {
            size: 8,
            shrink: 12
        }
        .validate(&c)
        .unwrap_err()
        .to_string()
        .contains("0..=11"));
        Options {
            size: 8,
            shrink: 11,
        }
        .validate(&c)
        .unwrap();
    }

    /// The pictures show the render's own values where they say: the worst pixel at the
    /// centre of the highlight's crops (its model grey, its error saturated), in the signed
    /// error image, and counted in the histogram, whose counts are every pixel once.
    #[test]
    fn the_pictures_show_the_worst_pixel_where_they_say() {
        let c = Config::default();
        let r = render(
            &c,
            &Scene::standard(),
            Options {
                size: 96,
                shrink: 0,
            },
            None,
        )
        .unwrap();
        let w = r.metrics.worst_index.unwrap();
        let (x, y, _) = r.pixels[w];
        let pics = r.pictures().unwrap();
        assert_eq!(
            pics.iter().map(|p| p.0).collect::<Vec<_>>(),
            PICTURES.to_vec()
        );
        let names = r.image_names();
        assert!(PICTURES.iter().all(|p| names.contains(p)));
        let m = c.map_bits;
        let grey = move |v: u32| images::display8(v, m);
        let s = r.picture_source(&grey);
        let e = r.model[w] as i64 - r.reference[w] as i64;
        let saturated = pictures::signed_colour(e, r.metrics.max_abs_error as i64);
        assert!(saturated == image::Rgb([255, 0, 0]) || saturated == image::Rgb([0, 0, 255]));
        // The highlight: three panels of the crop, the worst pixel's block in each.
        let h = &pics[0].1;
        let (x0, y0, side) = pictures::crop_origin(96, x, y);
        let panel = side * pictures::ZOOM;
        assert_eq!(h.dimensions(), (3 * panel + 2 * pictures::GAP, panel));
        let block = |k: u32| {
            let px = k * (panel + pictures::GAP) + (x - x0) * pictures::ZOOM + pictures::ZOOM / 2;
            *h.get_pixel(px, (y - y0) * pictures::ZOOM + pictures::ZOOM / 2)
        };
        let g = |v: u32| image::Rgb([grey(v); 3]);
        assert_eq!(block(0), g(r.reference[w]));
        assert_eq!(block(1), g(r.model[w]));
        assert_eq!(block(2), saturated);
        // The signed error image: the same colour at the same place.
        assert_eq!(*pics[1].1.get_pixel(x, y), saturated);
        // The histogram: every pixel once, the worst error among them.
        let counts = s.histogram_counts();
        assert_eq!(
            counts.iter().map(|c| c.1).sum::<u64>(),
            r.pixels.len() as u64
        );
        assert!(counts.iter().any(|&(v, n)| v == e && n > 0));
        assert_eq!(counts.len() as u32, 2 * r.metrics.max_abs_error + 1);
    }

    #[test]
    fn rtl_hook_compares_with_the_model() {
        let c = Config::default();
        let s = Scene::standard();
        let o = Options {
            size: 32,
            shrink: 0,
        };
        let plain = render(&c, &s, o, None).unwrap();
        assert_eq!(plain.images().len(), 3);
        assert!(!plain.metrics_json().unwrap().contains("rtl"));

        let same = render(&c, &s, o, Some(&Fixed(plain.model.clone()))).unwrap();
        assert_eq!(same.rtl_mismatches(), Some(0));
        assert_eq!(same.images().last().unwrap().0, "rtl.png");
        let j: serde_json::Value = serde_json::from_str(&same.metrics_json().unwrap()).unwrap();
        assert_eq!(j["rtl_equals_model"], true);

        let mut off = plain.model.clone();
        off[3] ^= 1;
        let diff = render(&c, &s, o, Some(&Fixed(off))).unwrap();
        assert_eq!(diff.rtl_mismatches(), Some(1));
        assert!(diff
            .summary()
            .contains("differs from the model at 1 pixels"));

        assert!(render(&c, &s, o, Some(&Fixed(vec![0; 3]))).is_err());
        assert!(render(&c, &s, o, Some(&Fixed(vec![256; plain.pixels.len()]))).is_err());
    }

    #[test]
    fn json_has_the_named_fields() {
        let r = render(
            &Config::default(),
            &Scene::standard(),
            Options {
                size: 64,
                shrink: 2,
            },
            None,
        )
        .unwrap();
        let j: serde_json::Value = serde_json::from_str(&r.metrics_json().unwrap()).unwrap();
        for k in [
            "max_abs_error",
            "rmse",
            "psnr_db",
            "pixels",
            "mean_abs_error",
            "worst",
            "config",
            "scene",
        ] {
            assert!(!j[k].is_null(), "{k} in {j}");
        }
        assert_eq!(j["pixels"], r.pixels.len());
        assert_eq!(j["shrink"], 2);
        let w = r.worst().unwrap();
        assert_eq!(j["worst"]["x"], w.x);
        assert_eq!(w.model.abs_diff(w.reference), r.metrics.max_abs_error);
    }
}
