//! One volume render with every shader: the float reference and the bit-accurate model
//! (fused path), and optionally a batch shader such as the Verilated RTL (two-pass path,
//! through [`crate::model::IntensitySource`], the same hook as the sphere render). The
//! images, the error statistics and `metrics.json` reuse the sphere render's
//! [`crate::render::metrics`] and [`crate::render::images`]; the statistics are taken over
//! the pixels the volume covers (accumulated opacity > 0), as the sphere's over its disc.

use super::cast::frame::Stats;
use super::cast::options::CastOptions;
use super::cast::shader::ModelShader;
use super::picture::{self, PixelFormat};
use super::prepared::Prepared;
use super::renderer::Renderer;
use super::shear::Classified;
use super::VolumeInfo;
use crate::config::Config;
use crate::model::IntensitySource;
use crate::output::StagedDir;
use crate::reference::Reference;
use crate::render::images::error50;
use crate::render::{metrics, Metrics};
use crate::scene::transfer::Transfer;
use crate::scene::Scene;
use anyhow::{bail, Result};
use image::{DynamicImage, GrayImage};
use serde::Serialize;
use std::time::Instant;

/// A finished volume render.
#[derive(Clone, Debug)]
pub struct VolumeRender {
    pub cfg: Config,
    pub scene: Scene,
    pub opts: CastOptions,
    /// Pixels whose ray accumulated some opacity, raster order.
    pub covered: Vec<bool>,
    /// Accumulated opacity per pixel (the same for every shader).
    pub alpha: Vec<f32>,
    /// The float reference's image; `None` with `--model-only`.
    pub reference: Option<Vec<u32>>,
    pub model: Vec<u32>,
    pub rtl: Option<Vec<u32>>,
    /// The model against the reference over the covered pixels; `None` without a reference.
    pub metrics: Option<Metrics>,
    /// Work of the model render.
    pub stats: Stats,
    pub context: Context,
    /// Wall-clock times of the model and the reference render, in ms.
    pub model_ms: f64,
    pub reference_ms: Option<f64>,
    /// The pixel format of the shaded images.
    pub format: PixelFormat,
}

/// What was rendered, for `metrics.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Context {
    #[serde(flatten)]
    pub info: VolumeInfo,
    pub dims: [usize; 3],
    pub spacing: [f64; 3],
    pub value_range: [f32; 2],
    /// Quantisation scale of the gradients, LSB per (value unit per world unit).
    pub gradient_scale: f64,
    pub gradient_max_component: f64,
    /// Unit vectors of the image's right and up directions, and a pixel's world width.
    pub image_right: [f64; 3],
    pub image_up: [f64; 3],
    pub pixel: f64,
    /// Fraction of the skipping units empty for the transfer function: bricks (ray
    /// caster) or slice cells (shear-warp).
    pub empty_fraction: f64,
}

/// The pixel with the largest model error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorstPixel {
    pub x: u32,
    pub y: u32,
    pub model: u32,
    pub reference: u32,
}

#[derive(Serialize)]
struct Skipping {
    #[serde(flatten)]
    stats: Stats,
    skipped_fraction: f64,
    unshaded_fraction: f64,
}

/// `metrics.json`: the sphere render's fields (without its `shrink`), then the volume's.
#[derive(Serialize)]
struct Report<'a> {
    generator: String,
    size: u32,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    metrics: Option<&'a Metrics>,
    model_only: bool,
    png: PixelFormat,
    worst: Option<WorstPixel>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rtl_equals_model: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rtl_mismatches: Option<usize>,
    images: Vec<&'static str>,
    config: &'a Config,
    scene: &'a Scene,
    volume: &'a Context,
    cast: &'a CastOptions,
    skipping: Skipping,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The scene's transfer function, or an error saying where one is needed.
pub fn scene_transfer(scene: &Scene) -> Result<&Transfer> {
    match &scene.transfer {
        Some(t) => Ok(t),
        None => bail!("the scene has no [transfer] section; volume rendering needs an opacity transfer function (or give --transfer)"),
    }
}

/// Refuses a render in which the transfer function made every sample transparent (no pixel
/// covered): the image would be blank. The message gives the data's value distribution and
/// the breakpoints, to choose breakpoints from.
pub fn check_covered(r: &VolumeRender, vol: &super::Volume) -> Result<()> {
    if r.covered.iter().any(|&c| c) {
        return Ok(());
    }
    let t = scene_transfer(&r.scene)?;
    let [min, p1, p50, p99, max] = percentiles(vol);
    let mut extra = String::new();
    if t.gradient.is_some() || t.min_opacity.is_some() {
        extra = " (with its gradient-magnitude ramp and minimum opacity)".to_string();
    }
    bail!(
        "nothing covered: the transfer function{extra} makes every sample of the volume transparent (0 of {n}x{n} pixels); the data's values are min {min}, p1 {p1}, p50 {p50}, p99 {p99}, max {max}, and the transfer function's breakpoints (value:opacity) are {}; give breakpoints with opacity > 0 inside the data's range (--transfer or the scene's [transfer])",
        t.points_text(),
        n = r.opts.size
    )
}

/// Minimum, 1st, 50th and 99th percentile and maximum of the voxel values (nearest rank;
/// the percentiles of an evenly strided sample of at most 2^22 values for larger volumes).
pub fn percentiles(vol: &super::Volume) -> [f32; 5] {
    let (min, max) = vol.range();
    let stride = vol.data.len().div_ceil(1 << 22).max(1);
    let mut v: Vec<f32> = vol.data.iter().step_by(stride).copied().collect();
    if v.is_empty() {
        return [min, min, min, max, max];
    }
    let mut at = |q: f64| {
        let k = ((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
        *v.select_nth_unstable_by(k, f32::total_cmp).1
    };
    let (p1, p50, p99) = (at(0.01), at(0.5), at(0.99));
    [min, p1, p50, p99, max]
}

/// Renders a prepared volume with the scene's view direction and transfer function; the
/// float reference too unless `model_only`. The shaders see the scene in the volume's
/// voxel-axis frame ([`super::Volume::shading_scene`]).
pub fn render(
    p: &Prepared,
    cfg: &Config,
    scene: &Scene,
    opts: CastOptions,
    rtl: Option<&dyn IntensitySource>,
    model_only: bool,
) -> Result<VolumeRender> {
    scene.validate()?;
    let transfer = scene_transfer(scene)?;
    let shading = p.vol.shading_scene(scene);
    let t = Instant::now();
    // The classification (shear-warp's runs of visible cells) is built by the first frame
    // and reused by the reference's.
    let classified = Classified::new(p, transfer)?;
    let model_shader = ModelShader::new(cfg, &shading);
    let caster = Renderer::new(&classified, scene.view.direction, opts)?;
    let model_frame = caster.render(&model_shader);
    let model_ms = ms(t);
    let (reference_frame, reference_ms) = if model_only {
        (None, None)
    } else {
        let t = Instant::now();
        let f = Renderer::new(&classified, scene.view.direction, opts)?
            .render(&Reference::new(cfg, &shading));
        (Some(f), Some(ms(t)))
    };
    let rtl = match rtl {
        None => None,
        Some(src) => Some(caster.batch(src, cfg)?.pixels(cfg.map_max())),
    };

    let covered: Vec<bool> = model_frame.alpha.iter().map(|&a| a > 0.0).collect();
    let max = cfg.map_max();
    let model = model_frame.pixels(max);
    let reference = reference_frame.map(|f| f.pixels(max));
    let pick = |v: &[u32]| {
        v.iter()
            .zip(&covered)
            .filter(|c| *c.1)
            .map(|c| *c.0)
            .collect::<Vec<u32>>()
    };
    let metrics = reference
        .as_ref()
        .map(|r| metrics(&pick(&model), &pick(r), max));
    let (lo, hi) = p.vol.range();
    let cam = caster.camera();
    let context = Context {
        info: p.vol.info.clone(),
        dims: p.vol.dims,
        spacing: p.vol.spacing,
        value_range: [lo, hi],
        gradient_scale: p.grads.scale,
        gradient_max_component: p.grads.max_component,
        image_right: cam.right.to_array(),
        image_up: cam.up.to_array(),
        pixel: cam.pixel,
        empty_fraction: caster.empty_fraction(),
    };
    Ok(VolumeRender {
        cfg: cfg.clone(),
        scene: scene.clone(),
        opts,
        covered,
        alpha: model_frame.alpha,
        reference,
        model,
        rtl,
        metrics,
        stats: model_frame.stats,
        context,
        model_ms,
        reference_ms,
        format: PixelFormat::default(),
    })
}

impl VolumeRender {
    /// The worst pixel of the model against the reference.
    pub fn worst(&self) -> Option<WorstPixel> {
        let k = self.metrics.as_ref()?.worst_index?;
        let i = self.covered.iter().enumerate().filter(|c| *c.1).nth(k)?.0;
        let n = self.opts.size as usize;
        Some(WorstPixel {
            x: (i % n) as u32,
            y: (i / n) as u32,
            model: self.model[i],
            reference: self.reference.as_ref()?[i],
        })
    }

    /// Pixels where the RTL differs from the model; `None` without an RTL source.
    pub fn rtl_mismatches(&self) -> Option<usize> {
        let rtl = self.rtl.as_ref()?;
        Some(rtl.iter().zip(&self.model).filter(|(a, b)| a != b).count())
    }

    pub fn image_names(&self) -> Vec<&'static str> {
        let mut v = vec![];
        if self.reference.is_some() {
            v.push("reference.png");
        }
        v.push("model.png");
        if self.reference.is_some() {
            v.push("error50.png");
        }
        if self.rtl.is_some() {
            v.push("rtl.png");
        }
        if self.reference.is_some() {
            v.extend(crate::render::PICTURES);
        }
        v
    }

    /// The sphere render's pictures ([`crate::render::pictures`]) of the covered pixels: the
    /// highlight around the worst pixel, the signed error with its scale, the profile through
    /// the worst pixel's row and the error histogram; none without the reference.
    pub fn pictures(&self) -> Result<Vec<(&'static str, image::RgbImage)>> {
        let (Some(reference), Some(m)) = (&self.reference, &self.metrics) else {
            return Ok(Vec::new());
        };
        let n = self.opts.size;
        let inside: Vec<usize> = (0..self.covered.len())
            .filter(|&i| self.covered[i])
            .collect();
        let pixels: Vec<crate::render::Pixel> = inside
            .iter()
            .map(|&i| ((i as u32 % n), (i as u32 / n), [0; 3]))
            .collect();
        let model: Vec<u32> = inside.iter().map(|&i| self.model[i]).collect();
        let reference: Vec<u32> = inside.iter().map(|&i| reference[i]).collect();
        let bits = self.cfg.map_bits;
        let grey = move |v: u32| crate::render::images::display8(v, bits);
        crate::render::pictures::Source {
            size: n,
            pixels: &pixels,
            reference: &reference,
            model: &model,
            grey: &grey,
            worst: m.worst_index,
            range: m.max_abs_error.max(1),
        }
        .all(self.cfg.map_max())
    }

    /// The images by file name: intensities in [`VolumeRender::format`] (background black
    /// or transparent), and the error |model - reference| in LSBs times 50 (8-bit grey).
    pub fn images(&self) -> Vec<(&'static str, DynamicImage)> {
        let n = self.opts.size;
        let m = self.cfg.map_bits;
        let shown = |v: &[u32]| picture::shown(v, &self.alpha, n, m, self.format);
        let mut v = vec![("model.png", shown(&self.model))];
        if let Some(r) = &self.reference {
            v.insert(0, ("reference.png", shown(r)));
            let e = self
                .model
                .iter()
                .zip(r)
                .map(|(&a, &b)| error50(a, b))
                .collect();
            let e = GrayImage::from_raw(n, n, e).expect("n x n pixels");
            v.push(("error50.png", DynamicImage::ImageLuma8(e)));
        }
        if let Some(rtl) = &self.rtl {
            v.push(("rtl.png", shown(rtl)));
        }
        v
    }

    pub fn metrics_json(&self) -> Result<String> {
        let mismatches = self.rtl_mismatches();
        let report = Report {
            generator: format!("rmapgen {}", env!("CARGO_PKG_VERSION")),
            size: self.opts.size,
            metrics: self.metrics.as_ref(),
            model_only: self.reference.is_none(),
            png: self.format,
            worst: self.worst(),
            rtl_equals_model: mismatches.map(|n| n == 0),
            rtl_mismatches: mismatches,
            images: self.image_names(),
            config: &self.cfg,
            scene: &self.scene,
            volume: &self.context,
            cast: &self.opts,
            skipping: Skipping {
                stats: self.stats,
                skipped_fraction: self.stats.skipped_fraction(),
                unshaded_fraction: self.stats.unshaded_fraction(),
            },
        };
        Ok(serde_json::to_string_pretty(&report)?)
    }

    /// Writes the images and `metrics.json`.
    pub fn write(&self, out: &StagedDir) -> Result<()> {
        for (name, img) in self.images() {
            out.write_bytes(name, &picture::png(&img)?)?;
        }
        for (name, img) in self.pictures()? {
            out.write_bytes(name, &picture::png(&DynamicImage::ImageRgb8(img))?)?;
        }
        out.write_text("metrics.json", &self.metrics_json()?)
    }

    /// One line: what was rendered and the model's error against the reference.
    pub fn summary(&self) -> String {
        let d = self.context.dims;
        let px = self.covered.iter().filter(|&&c| c).count();
        let error = match &self.metrics {
            Some(m) => format!(
                "max abs error {} LSB, RMSE {:.3} LSB, PSNR {} dB",
                m.max_abs_error,
                m.rmse,
                m.psnr_db.map_or("inf".to_string(), |p| format!("{p:.2}"))
            ),
            None => "model only (no float reference, no error statistics)".to_string(),
        };
        let mut s = format!(
            "{}x{}x{} volume, {n}x{n} image, {px} covered pixels: {error}; {sk:.1}% of samples skipped",
            d[0],
            d[1],
            d[2],
            n = self.opts.size,
            sk = 100.0 * self.stats.skipped_fraction()
        );
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
    use crate::volume::synthetic;

    struct Fixed(u32);
    impl IntensitySource for Fixed {
        fn intensities(&self, g: &[[i32; 3]]) -> Result<Vec<u32>> {
            Ok(vec![self.0; g.len()])
        }
    }

    struct AsModel(ModelShader);
    impl IntensitySource for AsModel {
        fn intensities(&self, g: &[[i32; 3]]) -> Result<Vec<u32>> {
            use crate::volume::cast::shader::Shader;
            Ok(g.iter().map(|&g| self.0.intensity(g)).collect())
        }
    }

    fn scene() -> Scene {
        Scene::from_toml_str(super::super::ENGINE_SCENE_TOML).unwrap()
    }

    #[test]
    fn render_metrics_and_rtl_hook() {
        let vol = synthetic::engine_block([64, 64, 32], [1.0; 3]).unwrap();
        let cfg = Config::default();
        let p = Prepared::new(&vol, cfg.grad_bits, 8);
        let o = CastOptions {
            size: 64,
            ..CastOptions::default()
        };
        let s = scene();
        let r = render(
            &p,
            &cfg,
            &s,
            o,
            Some(&AsModel(ModelShader::new(&cfg, &s))),
            false,
        )
        .unwrap();
        assert_eq!(r.rtl_mismatches(), Some(0));
        assert!(
            r.metrics.as_ref().unwrap().pixels > 64 * 64 / 4
                && r.metrics.as_ref().unwrap().pixels < 64 * 64,
            "{}",
            r.metrics.as_ref().unwrap().pixels
        );
        // The model is close to the reference but not identical.
        assert!(
            r.metrics.as_ref().unwrap().max_abs_error >= 1
                && r.metrics.as_ref().unwrap().max_abs_error <= 12,
            "{:?}",
            r.metrics.as_ref().unwrap()
        );
        let w = r.worst().unwrap();
        assert_eq!(
            w.model.abs_diff(w.reference),
            r.metrics.as_ref().unwrap().max_abs_error
        );
        let j: serde_json::Value = serde_json::from_str(&r.metrics_json().unwrap()).unwrap();
        for k in [
            "max_abs_error",
            "rmse",
            "psnr_db",
            "pixels",
            "worst",
            "config",
            "scene",
            "volume",
            "skipping",
        ] {
            assert!(!j[k].is_null(), "{k}");
        }
        assert_eq!(j["rtl_equals_model"], true);
        assert_eq!(j["scene"]["transfer"]["points"][1][0], 1900.0);
        let imgs = r.images();
        let pictures = r.pictures().unwrap();
        assert_eq!(
            imgs.iter()
                .map(|i| i.0)
                .chain(pictures.iter().map(|p| p.0))
                .collect::<Vec<_>>(),
            r.image_names()
        );
        // Background stays black; the error image is 50 per LSB.
        assert_eq!(imgs[1].1.to_luma8().get_pixel(0, 0).0[0], 0);
        let e = imgs[2].1.to_luma8();
        let (x, y) = (w.x, w.y);
        assert_eq!(
            e.get_pixel(x, y).0[0] as u32,
            (50 * r.metrics.as_ref().unwrap().max_abs_error).min(255)
        );

        // A batch shader that disagrees is reported; one that is out of range is refused.
        let other = render(&p, &cfg, &s, o, Some(&Fixed(3)), false).unwrap();
        assert!(
            other.rtl_mismatches().unwrap() > 0
                && other.summary().contains("differs from the model")
        );
        assert!(render(&p, &cfg, &s, o, Some(&Fixed(256)), false)
            .unwrap_err()
            .to_string()
            .contains("wider than"));
    }

    #[test]
    fn shear_warp_batch_hook() {
        // `--rtl` with shear-warp: the batch shader shades the collected samples; one that
        // agrees with the model gives its image, one that does not is reported.
        let vol = synthetic::engine_block([48, 48, 24], [1.0; 3]).unwrap();
        let cfg = Config::default();
        let p = Prepared::new(&vol, cfg.grad_bits, 8);
        let o = CastOptions {
            size: 48,
            caster: crate::volume::cast::options::CasterKind::ShearWarp,
            ..CastOptions::default()
        };
        let s = scene();
        let same = AsModel(ModelShader::new(&cfg, &s));
        // One sample per slice and voxel, and samples between slices on a finer
        // intermediate image.
        for (slice_samples, supersample) in [(1, 1), (2, 2)] {
            let o = CastOptions {
                slice_samples,
                supersample,
                ..o
            };
            let r = render(&p, &cfg, &s, o, Some(&same), false).unwrap();
            assert_eq!(r.rtl_mismatches(), Some(0));
            assert!(r.metrics.as_ref().unwrap().pixels > 48 * 48 / 4);
            let other = render(&p, &cfg, &s, o, Some(&Fixed(3)), false).unwrap();
            assert!(other.rtl_mismatches().unwrap() > 0);
        }
    }

    #[test]
    fn a_scene_without_transfer_is_refused() {
        let vol = synthetic::engine_block([16, 16, 8], [1.0; 3]).unwrap();
        let p = Prepared::new(&vol, 12, 8);
        let e = render(
            &p,
            &Config::default(),
            &Scene::standard(),
            CastOptions::default(),
            None,
            false,
        )
        .unwrap_err();
        assert!(e.to_string().contains("no [transfer] section"));
    }
}
