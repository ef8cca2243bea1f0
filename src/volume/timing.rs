//! `rmapgen volume --timing`: the renders timed frame by frame (median and fastest of
//! `--repeat` runs), with and without empty-space skipping, the model against the float
//! reference, and a check that skipping and repeated frames leave the image unchanged.

use super::cast::frame::Stats;
use super::cast::options::{CastOptions, CasterKind};
use super::cast::shader::ModelShader;
use super::prepared::Prepared;
use super::renderer::Renderer;
use super::report;
use super::shear::Classified;
use crate::config::Config;
use crate::reference::Reference;
use crate::scene::Scene;
use anyhow::{bail, Result};
use serde::Serialize;
use std::time::Instant;

/// One timed measurement: the median and the fastest of `n` runs, in ms.
#[derive(Clone, Debug, Serialize)]
pub struct Timed {
    pub median_ms: f64,
    pub min_ms: f64,
    pub runs: u32,
}

pub fn time(n: u32, mut f: impl FnMut()) -> Timed {
    let mut v: Vec<f64> = (0..n.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    v.sort_by(f64::total_cmp);
    Timed {
        median_ms: v[v.len() / 2],
        min_ms: v[0],
        runs: v.len() as u32,
    }
}

#[derive(Serialize)]
pub struct Timing {
    pub threads: usize,
    pub caster: CasterKind,
    pub load_ms: f64,
    /// Gradients and brick ranges: once per volume and gradient width.
    pub prepare_ms: f64,
    /// Shear-warp's runs of visible cells for the view's principal axis: once per volume,
    /// transfer function and axis (0 for the ray caster).
    pub classify_ms: f64,
    /// One frame: the shader's scene part (maps and the model's intensity table; its
    /// position table depends on the configuration only and is built once), the renderer
    /// (for the ray caster the empty bricks of the transfer function) and the image.
    pub model_skipping_on: Timed,
    /// Parts of a model frame: the shader alone (maps and intensity table), and the
    /// renderer and image alone with the shader built.
    pub model_shader: Timed,
    pub model_image: Timed,
    pub float_skipping_on: Timed,
    pub model_skipping_off: Timed,
    pub speedup: f64,
    pub skipping_on: Stats,
    pub skipping_off: Stats,
    pub skipped_fraction: f64,
    pub unshaded_fraction: f64,
}

/// Times the renders and checks that skipping leaves the image unchanged.
pub fn timing(
    p: &Prepared,
    cfg: &Config,
    scene: &Scene,
    opts: CastOptions,
    repeat: u32,
) -> Result<(Timing, String)> {
    let tf = report::scene_transfer(scene)?;
    let view = scene.view.direction;
    // The shaders see the scene in the volume's axis frame, as in `report::render`.
    let shading = p.vol.shading_scene(scene);
    let scene = &shading;
    let model = ModelShader::new(cfg, scene);
    let on = CastOptions { skip: true, ..opts };
    let off = CastOptions {
        skip: false,
        ..opts
    };
    // Classified once, untimed like the gradients (VolPack's vpClassifyVolume likewise):
    // it depends on the volume and the transfer function, not on the frame.
    let t = Instant::now();
    let classified = Classified::new(p, tf)?;
    let first = Renderer::new(&classified, view, on)?;
    let classify_ms = if opts.caster == CasterKind::ShearWarp {
        t.elapsed().as_secs_f64() * 1e3
    } else {
        0.0
    };
    let frame_on = first.render(&model);
    let frame_off = Renderer::new(&classified, view, off)?.render(&model);
    if frame_on.value != frame_off.value || frame_on.alpha != frame_off.alpha {
        bail!("internal error: the image with skipping differs from the image without");
    }
    // Each timed run builds the frame's shader (the maps and the model's tables, or the
    // reference) and the renderer (for the ray caster the empty bricks of the transfer
    // function), then renders.
    // The model's configuration tables (its position table) are built once, as the
    // gradients are; a frame rebuilds what depends on the scene (the maps, and the fused
    // intensity table when it is no larger than the previous frame's shaded samples, as an
    // interactive preview would know them).
    // Frames render into one image buffer, as VolPack's into the image its caller set
    // once (the ray caster replaces it).
    let mut m = ModelShader::new(cfg, scene);
    let shaded = frame_on.stats.shaded as usize;
    let mut image = frame_on.clone();
    let model_on = time(repeat, || {
        m.set_scene_for(scene, shaded);
        Renderer::new(&classified, view, on)
            .expect("checked")
            .render_into(&m, &mut image);
    });
    if image != frame_on {
        bail!("internal error: a repeated frame differs from the first");
    }
    let model_shader = time(repeat, || {
        m.set_scene_for(scene, shaded);
    });
    let model_image = time(repeat, || {
        Renderer::new(&classified, view, on)
            .expect("checked")
            .render_into(&model, &mut image);
    });
    let float_on = time(repeat, || {
        let r = Reference::new(cfg, scene);
        Renderer::new(&classified, view, on)
            .expect("checked")
            .render_into(&r, &mut image);
    });
    let model_off = time(repeat.min(2), || {
        m.set_scene_for(scene, shaded);
        Renderer::new(&classified, view, off)
            .expect("checked")
            .render(&m);
    });
    let st = frame_on.stats;
    let t = Timing {
        threads: rayon::current_num_threads(),
        caster: opts.caster,
        load_ms: 0.0,
        prepare_ms: 0.0,
        classify_ms,
        speedup: model_off.median_ms / model_on.median_ms,
        model_skipping_on: model_on,
        model_shader,
        model_image,
        float_skipping_on: float_on,
        model_skipping_off: model_off,
        skipping_on: st,
        skipping_off: frame_off.stats,
        skipped_fraction: st.skipped_fraction(),
        unshaded_fraction: st.unshaded_fraction(),
    };
    let pct = |n: u64| 100.0 * n as f64 / st.samples.max(1) as f64;
    let text = format!(
        "  model, skipping on   {:8.1} ms (median of {}, fastest {:.1}): shader {:.1} ms, image {:.1} ms\n  float, skipping on   {:8.1} ms (median of {}, fastest {:.1})\n  model, skipping off  {:8.1} ms (median of {}), speed-up {:.1}x, identical image\n  samples on rays {}: {:.1}% skipped ({:.1}% empty space, {:.1}% after termination), {:.2}% shaded, {:.1}% of {} empty",
        t.model_skipping_on.median_ms,
        t.model_skipping_on.runs,
        t.model_skipping_on.min_ms,
        t.model_shader.median_ms,
        t.model_image.median_ms,
        t.float_skipping_on.median_ms,
        t.float_skipping_on.runs,
        t.float_skipping_on.min_ms,
        t.model_skipping_off.median_ms,
        t.model_skipping_off.runs,
        t.speedup,
        st.samples,
        pct(st.empty_skipped + st.terminated),
        pct(st.empty_skipped),
        pct(st.terminated),
        pct(st.shaded),
        100.0 * first.empty_fraction(),
        match opts.caster {
            CasterKind::Ray => "bricks",
            CasterKind::ShearWarp => "slice cells",
        }
    );
    Ok((t, text))
}
