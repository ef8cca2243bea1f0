//! `rmapgen explore`: the paper's "test environment ... [with] interactive change of table
//! parameters, to ... view image differences immediately", as a page served on 127.0.0.1.
//!
//! The page ([`PAGE`]) holds the configuration and the scene as fields; every change posts
//! them to `/api/render`, which validates them as their TOML files are validated, renders the
//! object the page shows and answers with the figures and the images' addresses:
//! - the sphere, exactly as `rmapgen render` does ([`crate::render::render_with`]: the same
//!   PNG bytes);
//! - the volume: the synthetic engine block of the paper's Figures 9 and 10, exactly as
//!   `rmapgen volume --synthetic` does ([`crate::volume::report::render`], the ray caster at
//!   its defaults: the same PNG bytes). The block is built once per process ([`ENGINE`]) and
//!   its gradients and bricks once per gradient width.
//!
//! Clicking a pixel asks `/api/trace` for that sample's path through the design
//! ([`crate::stages::path`]: every port of every stage under its Verilog name). A volume pixel
//! blends the samples along its ray: the answer lists them (weight, gradient, the design's and
//! the reference's intensity) and traces the one of largest weight. `/api/config.toml` and
//! `/api/scene.toml` are the files `generate --config` and `--scene` (or `volume --scene`)
//! read.
//!
//! The server is a server (docs/EXPLORE.md, "The API"): [`http`] reads every request under
//! bounds, one thread per connection; [`guard`] admits only the explorer's own page (Host,
//! token, Origin, JSON); [`cost`] refuses a render whose measured cost exceeds the budget,
//! and [`runner`] runs the others one at a time off the serving threads, cancelled past their
//! time or memory ([`LIMITS`]).
//!
//! Bounds: a request body of at most [`MAX_BODY`] bytes, images of at most [`MAX_SIZE`]
//! pixels a side, at most [`MAX_LIGHTS`] lights, and the last [`KEPT`] renders kept.

pub mod cost;
pub mod guard;
pub mod http;
pub mod runner;

use crate::config::{Config, RANGES};
use crate::model::map_fit::MapFit;
use crate::model::{MapSet, Model};
use crate::render::{images, Options, Render};
use crate::scene::Scene;
use crate::toml_input::{one_line, without_place};
use crate::volume::cast::options::CastOptions;
use crate::volume::prepared::Prepared;
use crate::volume::renderer::Renderer;
use crate::volume::report::VolumeRender;
use crate::volume::shear::Classified;
use crate::volume::{synthetic, Volume};
use anyhow::{anyhow, bail, Context, Result};
use http::{Head, Reply};
use runner::{Limits, Runner, Stopped};
use serde::Serialize;
use serde_json::{json, Value};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};
use std::time::{Duration, Instant};

/// The page: fields, images, the trace table (no external resources). Served with the
/// process's token in place of [`TOKEN_SLOT`] and its header's name in place of
/// [`TOKEN_HEADER_SLOT`].
pub const PAGE: &str = include_str!("page.html");
/// Where the page carries the token, and the header it sends it in.
pub const TOKEN_SLOT: &str = "__RMAPGEN_TOKEN__";
pub const TOKEN_HEADER_SLOT: &str = "__RMAPGEN_TOKEN_HEADER__";

/// Largest request body: a configuration and a scene are a few hundred bytes.
pub const MAX_BODY: u64 = 64 << 10;
/// Smallest image side the page may ask for: below it too few pixels fall in a map cell.
pub const MIN_SIZE: u32 = 16;
/// Largest image side the page may ask for: a 512² volume frame with its reference renders
/// in about 0.3 s.
pub const MAX_SIZE: u32 = 512;
/// Most lights a scene may have here.
pub const MAX_LIGHTS: usize = 8;
/// Renders kept for their images and traces (the page shows the last).
pub const KEPT: usize = 4;
/// A render's budget: cancelled past this time, or past this growth of the process's
/// memory. [`cost`] refuses up front what it predicts will not fit.
pub const LIMITS: Limits = Limits {
    seconds: Duration::from_secs(30),
    memory: 2 << 30,
};

/// The volume the page shows: the synthetic engine block at its default size
/// ([`synthetic::DIMS`], unit spacing), as `rmapgen volume --synthetic` builds it; built on
/// the first volume render and kept for the process.
pub static ENGINE: OnceLock<Volume> = OnceLock::new();

fn engine() -> Result<&'static Volume> {
    if let Some(v) = ENGINE.get() {
        return Ok(v);
    }
    let v = synthetic::engine_block(synthetic::DIMS, [1.0; 3])?;
    Ok(ENGINE.get_or_init(|| v))
}

/// What the page shows.
#[derive(serde::Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum Object {
    /// The sphere of `rmapgen render`.
    #[default]
    Sphere,
    /// The engine block of `rmapgen volume --synthetic`.
    Volume,
}

/// A finished render of either object.
enum Shown {
    Sphere(Box<Render>),
    Volume(Box<VolumeRender>, Arc<Prepared<'static>>),
}

impl Shown {
    fn cfg(&self) -> &Config {
        match self {
            Shown::Sphere(r) => &r.cfg,
            Shown::Volume(r, _) => &r.cfg,
        }
    }

    fn scene(&self) -> &Scene {
        match self {
            Shown::Sphere(r) => &r.scene,
            Shown::Volume(r, _) => &r.scene,
        }
    }
}

/// One finished render and what its traces need.
struct Kept {
    id: u64,
    shown: Shown,
    model: Model,
    /// The maps the design shades with (a volume's in its voxel-axis frame).
    maps: MapSet,
    /// File name and PNG bytes, as `rmapgen render` (or `volume`) writes them.
    files: Vec<(&'static str, Vec<u8>)>,
}

/// The renders kept, and the next render's id.
#[derive(Default)]
struct Kepts {
    next: u64,
    kept: VecDeque<Arc<Kept>>,
}

/// The explorer: the last renders, the engine block's gradients and bricks for the last
/// gradient width, and the runner of renders. Every request is answered through `&self`,
/// from any number of threads; renders go one at a time through the runner.
pub struct Explorer {
    kept: Mutex<Kepts>,
    prepared: Mutex<Option<(u32, Arc<Prepared<'static>>)>>,
    runner: Runner,
}

fn json_reply(status: u16, v: &Value) -> Reply {
    Reply::new(status, "application/json", v.to_string().into_bytes())
}

/// The page's fields: the configuration as `config.toml` has it, the scene as `scene.toml`
/// has it, the image side and the object shown.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Ask {
    config: serde_json::Map<String, Value>,
    scene: serde_json::Map<String, Value>,
    size: u32,
    #[serde(default)]
    object: Object,
}

/// A TOML file's text from the page's fields (a JSON object of the file's keys).
fn toml_text(fields: &serde_json::Map<String, Value>, what: &str) -> Result<String> {
    let v =
        toml::Value::try_from(Value::Object(fields.clone())).map_err(|e| anyhow!("{what}: {e}"))?;
    toml::to_string(&v).map_err(|e| anyhow!("{what}: {e}"))
}
/// The configuration and the scene of the page's fields, checked as their files are.
fn parse(ask: &Ask) -> Result<(Config, Scene)> {
    let c = toml_text(&ask.config, "config")?;
    let cfg = Config::from_toml_named(&c, "config")
        .map_err(|e| anyhow!(without_place(&format!("{e:#}"), "config")))?;
    let s = toml_text(&ask.scene, "scene")?;
    let scene = Scene::from_toml_named(&s, "scene")
        .map_err(|e| anyhow!(without_place(&format!("{e:#}"), "scene")))?;
    if scene.lights.len() > MAX_LIGHTS {
        bail!(
            "scene: {} lights; the explorer takes at most {MAX_LIGHTS}",
            scene.lights.len()
        );
    }
    if !(MIN_SIZE..=MAX_SIZE).contains(&ask.size) {
        bail!(
            "size {} is out of range; allowed {MIN_SIZE}..={MAX_SIZE}",
            ask.size
        );
    }
    scene.map_fit.check(&cfg)?;
    if ask.object == Object::Volume {
        // The volume's opacity comes from the scene's transfer function.
        crate::volume::report::scene_transfer(&scene)?;
    }
    Ok((cfg, scene))
}

/// What the page builds its fields from: every width with its range and default, the
/// switches, the map fits, the default scene and the bounds.
pub fn schema() -> Value {
    let d = Config::default();
    let widths: Vec<Value> = RANGES
        .iter()
        .map(|&(name, min, max)| json!({"name": name, "min": min, "max": max, "default": d.field(name)}))
        .collect();
    let fits: Vec<&str> = <MapFit as clap::ValueEnum>::value_variants()
        .iter()
        .map(|f| f.name())
        .collect();
    json!({
        "widths": widths,
        "switches": [
            {"name": "compensation", "default": d.compensation},
            {"name": "interpolation", "default": d.interpolation},
        ],
        "comp_table": ["rom", "ram"],
        "map_fits": fits,
        "scene": serde_json::to_value(Scene::standard()).expect("a scene serialises"),
        // The engine block's scene (scenes/engine.toml): its view and transfer function.
        "volume_scene": serde_json::to_value(engine_scene()).expect("a scene serialises"),
        "volume_dims": synthetic::DIMS,
        "max_size": MAX_SIZE,
        "max_lights": MAX_LIGHTS,
    })
}

/// The built-in scene of the engine block, as `rmapgen volume --synthetic` reads it.
fn engine_scene() -> Scene {
    Scene::from_toml_str(crate::volume::ENGINE_SCENE_TOML).expect("the built-in engine scene")
}

/// A pixel's path, as the page's trace table shows it: the sample's gradient, the pixel's
/// value in the design's and the reference's image, and every signal of the sample's path.
#[derive(Serialize)]
struct PathReply {
    x: u32,
    y: u32,
    gradient: [i32; 3],
    model: u32,
    reference: u32,
    signals: Vec<crate::stages::Signal>,
    /// A volume pixel's samples along its ray, front to back (the traced one is the
    /// heaviest); its opacity.
    #[serde(skip_serializing_if = "Option::is_none")]
    samples: Option<Vec<RaySample>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    alpha: Option<f32>,
}

/// One sample of a volume pixel's ray: its compositing weight, its gradient, and its
/// intensity from the design and from the float reference.
#[derive(Serialize)]
struct RaySample {
    weight: f32,
    gradient: [i32; 3],
    model: u32,
    reference: u32,
}

impl Explorer {
    /// An explorer whose renders run within `limits` on `threads` workers (0: one per core).
    pub fn new(threads: usize, limits: Limits) -> std::io::Result<Explorer> {
        Ok(Explorer {
            kept: Mutex::default(),
            prepared: Mutex::new(None),
            runner: Runner::new(threads, limits)?,
        })
    }

    fn kept(&self) -> MutexGuard<'_, Kepts> {
        self.kept.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Answers one admitted request: `method`, the path with its query, and the body. The
    /// page itself (`/`) is the server's ([`serve`]), which carries the token.
    pub fn answer(&self, method: &str, url: &str, body: &[u8]) -> Reply {
        let (path, query) = url.split_once('?').unwrap_or((url, ""));
        let q = |k: &str| {
            query
                .split('&')
                .filter_map(|kv| kv.split_once('='))
                .find(|(a, _)| *a == k)
                .and_then(|(_, v)| v.parse::<u64>().ok())
        };
        match (method, path) {
            ("GET", "/api/schema") => json_reply(200, &schema()),
            // Browsers ask for it; there is none.
            ("GET", "/favicon.ico") => Reply::new(204, "image/x-icon", Vec::new()),
            ("POST", "/api/render") => self.render(body),
            ("POST", "/api/cancel") => {
                json_reply(200, &json!({ "cancelled": self.runner.cancel() }))
            }
            ("GET", "/api/trace") => match (q("id"), q("x"), q("y")) {
                (Some(id), Some(x), Some(y)) => match self.trace(id, x, y) {
                    Ok(r) => r,
                    Err(e) => Reply::error(500, &one_line(&format!("{e:#}"))),
                },
                _ => Reply::error(400, "trace needs id, x and y"),
            },
            ("GET", "/api/config.toml" | "/api/scene.toml") => {
                let Some(k) = q("id").and_then(|id| self.find(id)) else {
                    return Reply::error(404, "no such render");
                };
                let (text, name) = if path.ends_with("config.toml") {
                    (toml::to_string(k.shown.cfg()), "config.toml")
                } else {
                    (toml::to_string(k.shown.scene()), "scene.toml")
                };
                let mut r = Reply::new(
                    200,
                    "application/toml; charset=utf-8",
                    text.expect("config and scene serialise").into_bytes(),
                );
                r.attachment = Some(name);
                r
            }
            ("GET", p) if p.starts_with("/img/") => self.image(p),
            ("GET" | "POST", _) => Reply::error(404, "no such page"),
            _ => Reply::error(405, "only GET and POST"),
        }
    }

    fn find(&self, id: u64) -> Option<Arc<Kept>> {
        self.kept().kept.iter().find(|k| k.id == id).cloned()
    }

    /// The engine block's gradients and bricks for `grad_bits` (kept for the last width; a
    /// volume render keeps its own for its traces).
    fn prepared(&self, grad_bits: u32) -> Result<Arc<Prepared<'static>>> {
        let mut slot = self.prepared.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((g, p)) = slot.as_ref() {
            if *g == grad_bits {
                return Ok(p.clone());
            }
        }
        *slot = None;
        let p = Arc::new(Prepared::try_new(
            engine()?,
            grad_bits,
            CastOptions::default().brick,
        )?);
        *slot = Some((grad_bits, p.clone()));
        Ok(p)
    }

    /// `POST /api/render`: the fields checked, the cost judged, the render run by the runner.
    fn render(&self, body: &[u8]) -> Reply {
        let checked = serde_json::from_slice::<Ask>(body)
            .context("the request")
            .and_then(|ask| {
                let (cfg, scene) = parse(&ask)?;
                cost::judge(&cfg, &scene, ask.size, ask.object == Object::Volume)?;
                Ok((ask, cfg, scene))
            });
        let (ask, cfg, scene) = match checked {
            Ok(v) => v,
            Err(e) => return Reply::error(400, &one_line(&format!("{e:#}"))),
        };
        let id = {
            let mut k = self.kept();
            k.next += 1;
            k.next
        };
        match self.runner.run(id, || self.draw(id, &ask, cfg, scene)) {
            Ok(Ok((kept, reply))) => {
                let mut k = self.kept();
                k.kept.push_back(Arc::new(kept));
                while k.kept.len() > KEPT {
                    k.kept.pop_front();
                }
                json_reply(200, &reply)
            }
            Ok(Err(e)) => Reply::error(400, &one_line(&format!("{e:#}"))),
            Err(stopped) => {
                let r = Reply::error(503, &stopped.message(self.runner.limits()));
                match stopped {
                    Stopped::Busy { .. } => r.with_header("Retry-After", "1".into()),
                    _ => r,
                }
            }
        }
    }

    /// Render `id` of the page's fields: what is kept of it, and the answer.
    fn draw(&self, id: u64, ask: &Ask, cfg: Config, scene: Scene) -> Result<(Kept, Value)> {
        let t = Instant::now();
        let model = Model::new(&cfg);
        let mut files = Vec::new();
        let (shown, maps, summary, metrics, worst) = match ask.object {
            Object::Sphere => {
                let maps = scene.maps(&cfg);
                let options = Options {
                    size: ask.size,
                    shrink: 0,
                };
                let render = crate::render::render_with(&model, &maps, &scene, options, None)?;
                for (name, img) in render.images() {
                    files.push((name, images::png(&img)?));
                }
                for (name, img) in render.pictures()?.into_iter().chain(render.color_images()) {
                    files.push((name, images::png_rgb(&img)?));
                }
                let (summary, metrics) = (render.summary(), serde_json::to_value(&render.metrics)?);
                let worst = serde_json::to_value(render.worst())?;
                (
                    Shown::Sphere(Box::new(render)),
                    maps,
                    summary,
                    metrics,
                    worst,
                )
            }
            Object::Volume => {
                let opts = CastOptions {
                    size: ask.size,
                    ..CastOptions::default()
                };
                let p = self.prepared(cfg.grad_bits)?;
                let render = crate::volume::report::render(&p, &cfg, &scene, opts, None, false)?;
                crate::volume::report::check_covered(&render, p.vol)?;
                for (name, img) in render.images() {
                    files.push((name, crate::volume::picture::png(&img)?));
                }
                for (name, img) in render.pictures()? {
                    let img = image::DynamicImage::ImageRgb8(img);
                    files.push((name, crate::volume::picture::png(&img)?));
                }
                let maps = p.vol.shading_scene(&scene).maps(&cfg);
                let (summary, metrics) = (render.summary(), serde_json::to_value(&render.metrics)?);
                let worst = serde_json::to_value(render.worst())?;
                (
                    Shown::Volume(Box::new(render), p),
                    maps,
                    summary,
                    metrics,
                    worst,
                )
            }
        };
        let addr = |name: &str| format!("/img/{id}/{name}");
        let images: serde_json::Map<String, Value> = files
            .iter()
            .map(|(n, _)| (n.to_string(), Value::String(addr(n))))
            .collect();
        let reply = json!({
            "id": id,
            "ms": t.elapsed().as_millis() as u64,
            "summary": summary,
            "metrics": metrics,
            "worst": worst,
            "config": toml::to_string(&cfg)?,
            "images": images,
            "rom_bits": cfg.rom_total_bits(),
            "map_bits": cfg.map_total_bits(),
        });
        let kept = Kept {
            id,
            shown,
            model,
            maps: MapSet {
                second: maps.clone(),
                scene: maps,
            },
            files,
        };
        Ok((kept, reply))
    }

    fn image(&self, path: &str) -> Reply {
        let mut parts = path.trim_start_matches("/img/").splitn(2, '/');
        let id = parts.next().and_then(|s| s.parse::<u64>().ok());
        let name = parts.next().unwrap_or("");
        let Some(k) = id.and_then(|id| self.find(id)) else {
            return Reply::error(404, "no such image");
        };
        match k.files.iter().find(|(n, _)| *n == name) {
            Some((_, png)) => Reply::new(200, "image/png", png.clone()),
            None => Reply::error(404, "no such image"),
        }
    }

    fn trace(&self, id: u64, x: u64, y: u64) -> Result<Reply> {
        let Some(k) = self.find(id) else {
            return Ok(Reply::error(404, "no such render"));
        };
        let r = match &k.shown {
            Shown::Sphere(r) => r,
            Shown::Volume(v, p) => return trace_volume(&k, v, p, x, y),
        };
        let Some(i) = r
            .pixels
            .iter()
            .position(|p| p.0 as u64 == x && p.1 as u64 == y)
        else {
            return Ok(Reply::error(
                404,
                &format!("pixel ({x}, {y}) is outside the sphere"),
            ));
        };
        let (px, py, g) = r.pixels[i];
        let rgb = if r.cfg.color {
            crate::render::color::sample_color(&r.scene, r.options.size, px, py)
        } else {
            [0; 3]
        };
        let p = PathReply {
            x: px,
            y: py,
            gradient: g,
            model: r.model[i],
            reference: r.reference[i],
            signals: crate::stages::path(&k.model, &k.maps, 0, g, rgb),
            samples: None,
            alpha: None,
        };
        Ok(json_reply(200, &serde_json::to_value(p)?))
    }
}

/// A volume pixel: the samples its ray composites (marched again by the same caster, view
/// and options, through the render's own prepared volume), and the path of the one of
/// largest weight.
fn trace_volume(
    k: &Kept,
    v: &VolumeRender,
    p: &Prepared<'static>,
    x: u64,
    y: u64,
) -> Result<Reply> {
    let (cfg, scene, opts) = (&v.cfg, &v.scene, v.opts);
    let n = opts.size as u64;
    if x >= n || y >= n {
        return Ok(Reply::error(
            404,
            &format!("pixel ({x}, {y}) is outside the {n}x{n} image"),
        ));
    }
    let (shading, (alpha, samples)) = {
        let classified = Classified::new(p, crate::volume::report::scene_transfer(scene)?)?;
        let caster = Renderer::new(&classified, scene.view.direction, opts)?;
        let ray = caster.pixel(x as u32, y as u32);
        (p.vol.shading_scene(scene), ray.unwrap_or((0.0, Vec::new())))
    };
    let reference = crate::reference::Reference::new(cfg, &shading);
    let i = (y * n + x) as usize;
    let Some(&(_, g)) = samples.iter().max_by(|a, b| a.0.total_cmp(&b.0)) else {
        return Ok(Reply::error(
            404,
            &format!("pixel ({x}, {y}) shows no part of the volume"),
        ));
    };
    let maps = &k.maps.scene;
    let list = samples
        .iter()
        .map(|&(weight, gradient)| RaySample {
            weight,
            gradient,
            model: k.model.intensity(maps, gradient),
            reference: reference.intensity(gradient),
        })
        .collect();
    let reply = PathReply {
        x: x as u32,
        y: y as u32,
        gradient: g,
        model: v.model[i],
        reference: v.reference.as_ref().map_or(0, |r| r[i]),
        signals: crate::stages::path(&k.model, &k.maps, 0, g, [0; 3]),
        samples: Some(list),
        alpha: Some(alpha),
    };
    Ok(json_reply(200, &serde_json::to_value(reply)?))
}

/// The server: its guard, and the explorer behind it.
struct Server {
    guard: guard::Guard,
    explorer: Explorer,
}

impl http::Handler for Server {
    fn admit(&self, head: &Head) -> std::result::Result<(), Reply> {
        self.guard.admit(head)
    }

    fn answer(&self, head: &Head, body: Vec<u8>) -> Reply {
        if (head.method.as_str(), head.path()) == ("GET", "/") {
            return page(self.guard.token());
        }
        self.explorer.answer(&head.method, &head.target, &body)
    }
}

/// The page with its token, and the headers that keep other sites from framing it.
fn page(token: &str) -> Reply {
    Reply::new(
        200,
        "text/html; charset=utf-8",
        PAGE.replace(TOKEN_HEADER_SLOT, guard::TOKEN_HEADER)
            .replace(TOKEN_SLOT, token)
            .into_bytes(),
    )
    .with_header(
        "Content-Security-Policy",
        "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src blob:; connect-src 'self' blob:; frame-ancestors 'none'; base-uri 'none'; form-action 'none'".into(),
    )
    .with_header("X-Frame-Options", "DENY".into())
}

/// Serves the page on 127.0.0.1:`port` (0: a free port) until the process is stopped; calls
/// `ready` with the address once it listens. Renders run within [`LIMITS`].
pub fn serve(port: u16, ready: impl FnOnce(&str) -> Result<()>) -> Result<()> {
    serve_within(port, LIMITS, ready)
}

/// [`serve`] with other limits (the tests: a render's budget in milliseconds).
pub fn serve_within(
    port: u16,
    limits: Limits,
    ready: impl FnOnce(&str) -> Result<()>,
) -> Result<()> {
    let listener = std::net::TcpListener::bind(("127.0.0.1", port))
        .map_err(|e| anyhow!("cannot listen on 127.0.0.1:{port}: {e}"))?;
    let addr = listener.local_addr()?;
    let server = Server {
        guard: guard::Guard::new(addr.port()).context("the token (/dev/urandom)")?,
        explorer: Explorer::new(0, limits)?,
    };
    ready(&format!("http://{addr}/"))?;
    http::serve(listener, http::Bounds::new(MAX_BODY), Arc::new(server))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ask(config: Value, size: u32) -> Vec<u8> {
        let scene = serde_json::to_value(Scene::standard()).unwrap();
        json!({"config": config, "scene": scene, "size": size})
            .to_string()
            .into_bytes()
    }

    fn explorer() -> Explorer {
        Explorer::new(0, LIMITS).unwrap()
    }

    fn body(r: &Reply) -> Value {
        serde_json::from_slice(&r.body).unwrap()
    }

    #[test]
    fn a_render_gives_renders_images_and_each_pixels_path() {
        let ex = explorer();
        let r = ex.answer("POST", "/api/render", &ask(json!({"index_bits": 4}), 64));
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
        let v = body(&r);
        let id = v["id"].as_u64().unwrap();
        // The same bytes as `rmapgen render` writes for this configuration and scene.
        let cfg = Config {
            index_bits: 4,
            ..Config::default()
        };
        let want = crate::render::render(
            &cfg,
            &Scene::standard(),
            Options {
                size: 64,
                shrink: 0,
            },
            None,
        )
        .unwrap();
        let model_png = images::png(&want.images()[1].1).unwrap();
        let url = v["images"]["model.png"].as_str().unwrap();
        let img = ex.answer("GET", url, b"");
        assert_eq!((img.status, img.kind), (200, "image/png"));
        assert_eq!(img.body, model_png);
        assert_eq!(
            v["metrics"]["max_abs_error"],
            json!(want.metrics.max_abs_error)
        );
        // A pixel's path ends in the model image's value there.
        let (x, y, g) = want.pixels[want.pixels.len() / 3];
        let t = ex.answer("GET", &format!("/api/trace?id={id}&x={x}&y={y}"), b"");
        assert_eq!(t.status, 200);
        let t = body(&t);
        assert_eq!(t["gradient"], json!(g));
        let sig = t["signals"].as_array().unwrap();
        let i_o = sig.iter().find(|s| s["name"] == "i_o").unwrap();
        assert_eq!(i_o["value"], json!(want.model[want.pixels.len() / 3]));
        assert!(sig.iter().any(|s| s["name"] == "u_atan_rom.pu_o"));
        // Outside the sphere, and a render long gone.
        assert_eq!(
            ex.answer("GET", &format!("/api/trace?id={id}&x=0&y=0"), b"")
                .status,
            404
        );
        let toml = ex.answer("GET", &format!("/api/config.toml?id={id}"), b"");
        assert_eq!(toml.attachment, Some("config.toml"));
        assert_eq!(
            Config::from_toml_named(std::str::from_utf8(&toml.body).unwrap(), "t").unwrap(),
            cfg
        );
        for _ in 0..KEPT {
            ex.answer("POST", "/api/render", &ask(json!({}), 16));
        }
        assert_eq!(
            ex.answer("GET", url, b"").status,
            404,
            "only the last {KEPT} are kept"
        );
    }

    #[test]
    fn a_volume_render_is_the_volume_commands_and_a_pixel_lists_its_rays_samples() {
        let ex = explorer();
        let scene = engine_scene();
        let b = json!({"config": {"index_bits": 4}, "scene": serde_json::to_value(&scene).unwrap(),
                       "size": 64, "object": "volume"});
        let r = ex.answer("POST", "/api/render", b.to_string().as_bytes());
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
        let v = body(&r);
        let id = v["id"].as_u64().unwrap();
        // The same bytes as `rmapgen volume --synthetic --size 64` writes.
        let cfg = Config {
            index_bits: 4,
            ..Config::default()
        };
        let vol = synthetic::engine_block(synthetic::DIMS, [1.0; 3]).unwrap();
        let p = Prepared::new(&vol, cfg.grad_bits, CastOptions::default().brick);
        let opts = CastOptions {
            size: 64,
            ..CastOptions::default()
        };
        let want = crate::volume::report::render(&p, &cfg, &scene, opts, None, false).unwrap();
        for (name, img) in want.images() {
            let got = ex.answer("GET", v["images"][name].as_str().unwrap(), b"");
            assert_eq!(
                got.body,
                crate::volume::picture::png(&img).unwrap(),
                "{name}"
            );
        }
        assert_eq!(
            v["metrics"]["max_abs_error"],
            json!(want.metrics.as_ref().unwrap().max_abs_error)
        );
        // Every covered pixel's samples blend to its value in the design's image, the traced
        // sample is the heaviest, and its path ends in that sample's intensity.
        let covered: Vec<usize> = (0..want.covered.len())
            .filter(|&i| want.covered[i])
            .collect();
        assert!(covered.len() > 100);
        for &i in covered.iter().step_by(covered.len() / 25) {
            let (x, y) = (i % 64, i / 64);
            let t = ex.answer("GET", &format!("/api/trace?id={id}&x={x}&y={y}"), b"");
            assert_eq!(t.status, 200, "{}", String::from_utf8_lossy(&t.body));
            let t = body(&t);
            let samples = t["samples"].as_array().unwrap();
            let blend: f32 = samples
                .iter()
                .map(|s| s["weight"].as_f64().unwrap() as f32 * s["model"].as_u64().unwrap() as f32)
                .sum();
            let pixel = (blend.round().max(0.0) as u32).min(cfg.map_max());
            assert_eq!(json!(pixel), t["model"], "pixel ({x}, {y})");
            assert_eq!(t["model"], json!(want.model[i]));
            assert_eq!(t["reference"], json!(want.reference.as_ref().unwrap()[i]));
            let heaviest = samples
                .iter()
                .max_by(|a, b| {
                    a["weight"]
                        .as_f64()
                        .unwrap()
                        .total_cmp(&b["weight"].as_f64().unwrap())
                })
                .unwrap();
            assert_eq!(heaviest["gradient"], t["gradient"]);
            let sig = t["signals"].as_array().unwrap();
            let i_o = sig.iter().find(|s| s["name"] == "i_o").unwrap();
            assert_eq!(i_o["value"], heaviest["model"]);
        }
        // A pixel showing nothing, one outside the image.
        let empty = (0..want.covered.len()).find(|&i| !want.covered[i]).unwrap();
        let t = ex.answer(
            "GET",
            &format!("/api/trace?id={id}&x={}&y={}", empty % 64, empty / 64),
            b"",
        );
        assert_eq!(t.status, 404);
        assert!(body(&t)["error"]
            .as_str()
            .unwrap()
            .contains("no part of the volume"));
        assert_eq!(
            ex.answer("GET", &format!("/api/trace?id={id}&x=64&y=0"), b"")
                .status,
            404
        );
        // The scene saved is the one rendered: the engine's view and transfer function.
        let s = ex.answer("GET", &format!("/api/scene.toml?id={id}"), b"");
        let saved = Scene::from_toml_named(std::str::from_utf8(&s.body).unwrap(), "t").unwrap();
        assert_eq!(saved.view.direction, scene.view.direction);
        assert!(saved.transfer.is_some());
        // The sphere's scene has no transfer function: the volume needs one.
        let r = ex.answer("POST", "/api/render", &{
            let mut b: Value = serde_json::from_slice(&ask(json!({}), 64)).unwrap();
            b["object"] = json!("volume");
            b.to_string().into_bytes()
        });
        assert_eq!(r.status, 400);
        assert!(
            body(&r)["error"].as_str().unwrap().contains("transfer"),
            "{}",
            body(&r)
        );
    }

    #[test]
    fn bad_fields_are_one_line_naming_the_field() {
        let ex = explorer();
        let say = |ex: &Explorer, b: Vec<u8>| {
            let r = ex.answer("POST", "/api/render", &b);
            assert_eq!(r.status, 400);
            body(&r)["error"].as_str().unwrap().to_string()
        };
        assert_eq!(
            say(&ex, ask(json!({"grad_bits": 40}), 64)),
            "config: grad_bits = 40 is out of range; allowed 8..=16"
        );
        assert!(say(&ex, ask(json!({"grad_bitz": 8}), 64)).contains("unknown field `grad_bitz`"));
        assert!(say(&ex, ask(json!({}), 5000)).starts_with("size 5000 is out of range"));
        assert!(say(&ex, b"{".to_vec()).starts_with("the request"));
        let mut scene = serde_json::to_value(Scene::standard()).unwrap();
        scene["map_fit"] = json!("table");
        let b = json!({"config": {}, "scene": scene, "size": 64})
            .to_string()
            .into_bytes();
        assert!(say(&ex, b).contains("comp-table ram"));
        let mut scene = serde_json::to_value(Scene::standard()).unwrap();
        let light = scene["light"][0].clone();
        scene["light"] = Value::Array(vec![light; MAX_LIGHTS + 1]);
        let b = json!({"config": {}, "scene": scene, "size": 64});
        assert_eq!(
            say(&ex, b.to_string().into_bytes()),
            format!(
                "scene: {} lights; the explorer takes at most {MAX_LIGHTS}",
                MAX_LIGHTS + 1
            )
        );
        assert_eq!(ex.answer("DELETE", "/", b"").status, 405);
        assert_eq!(ex.answer("GET", "/nothing", b"").status, 404);
    }

    /// The page carries the token and the header to send it in, every slot filled, and may
    /// not be framed.
    #[test]
    fn the_page_carries_its_token() {
        let r = page("0123abcd");
        let text = String::from_utf8(r.body).unwrap();
        assert!(text.contains(r#"content="0123abcd" data-header="X-Rmapgen-Token""#));
        assert!(!text.contains("__RMAPGEN"), "a slot left unfilled");
        let csp = r
            .headers
            .iter()
            .find(|h| h.0 == "Content-Security-Policy")
            .unwrap();
        assert!(csp.1.contains("frame-ancestors 'none'"));
    }

    #[test]
    fn the_schema_is_the_configurations_ranges() {
        let s = schema();
        let w = s["widths"].as_array().unwrap();
        assert_eq!(w.len(), RANGES.len());
        for (v, &(name, min, max)) in w.iter().zip(RANGES) {
            assert_eq!(
                (
                    v["name"].as_str().unwrap(),
                    v["min"].as_u64().unwrap(),
                    v["max"].as_u64().unwrap()
                ),
                (name, min as u64, max as u64)
            );
        }
        assert!(s["map_fits"]
            .as_array()
            .unwrap()
            .contains(&json!("minimax")));
    }
}
