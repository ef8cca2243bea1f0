//! A candidate's error on the scene's test image: the sphere of `rmapgen render` (every
//! inside pixel of an N x N image at full gradient scale), shaded by the bit-exact fast path
//! ([`FastShader`]) against the float reference ([`Reference`]), in LSBs of the output.
//!
//! With a scene colour, every pixel also carries the scene's 8-bit colour, and the three
//! channels of the colour multiplier are compared with the colour times the exact light model
//! (round half up), in LSBs of the 8-bit channels.
//!
//! A measurement may stop early once it has proved a candidate misses a limit (a pixel above
//! the largest error allowed, or a sum of squared errors above what the RMSE allows): the
//! candidate is then rejected on evidence, and its errors are lower bounds. Pixels are
//! visited in a fixed shuffled order (so the first few thousand sample the whole sphere), and
//! the pixels that rejected earlier candidates are tried first.

use crate::config::Config;
use crate::model::fast::FastShader;
use crate::model::{color_mul, Maps, Model};
use crate::reference::Reference;
use crate::render::sphere_gradients;
use crate::rng::SplitMix64;
use crate::scene::Scene;
use serde::Serialize;

/// The scene's test image, in the shuffled order measurements visit it.
#[derive(Clone, Debug)]
pub struct TestImage {
    pub size: u32,
    /// Inside pixels' gradients, shuffled.
    pub gradients: Vec<[i32; 3]>,
    /// The reference intensity of each, quantised to map_bits.
    pub reference: Vec<u32>,
    /// The scene's colour (8-bit RGB), and each pixel's reference channels.
    pub color: Option<([u32; 3], Vec<[u32; 3]>)>,
}

impl TestImage {
    /// The sphere image of side `size` for the interface of `base` (its gradient and map
    /// widths; every candidate shares them, so one reference serves them all).
    pub fn new(base: &Config, scene: &Scene, size: u32) -> TestImage {
        let mut gradients: Vec<[i32; 3]> = sphere_gradients(base, size, 0)
            .into_iter()
            .map(|p| p.2)
            .collect();
        let mut rng = SplitMix64::new(0x5eed);
        for i in (1..gradients.len()).rev() {
            let j = rng.below(i as u64 + 1) as usize;
            gradients.swap(i, j);
        }
        let r = Reference::new(base, scene);
        let reference = r.intensities(&gradients);
        let color = scene.color8().map(|c| {
            let refs = gradients
                .iter()
                .map(|&g| {
                    let s = r.exact(g).unwrap_or(0.0);
                    let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) };
                    c.map(|ch| (ch as f64 * s + 0.5).floor() as u32)
                })
                .collect();
            (c, refs)
        });
        TestImage {
            size,
            gradients,
            reference,
            color,
        }
    }

    pub fn pixels(&self) -> usize {
        self.gradients.len()
    }

    /// The same pixels visited in another order: `order[k]` is the pixel visited k-th.
    pub fn reordered(&self, order: &[usize]) -> TestImage {
        assert_eq!(order.len(), self.pixels());
        TestImage {
            size: self.size,
            gradients: order.iter().map(|&k| self.gradients[k]).collect(),
            reference: order.iter().map(|&k| self.reference[k]).collect(),
            color: self
                .color
                .as_ref()
                .map(|(c, r)| (*c, order.iter().map(|&k| r[k]).collect())),
        }
    }
}

/// When a measurement may stop: once the error is proved above `max` (intensity or a
/// channel) or the sum of squared intensity errors above `sse`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Limits {
    pub max: Option<u32>,
    pub sse: Option<f64>,
}

/// A candidate's errors on the test image.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Errors {
    /// Largest |model - reference| of the intensity, in output LSBs.
    pub max_abs_error: u32,
    /// RMS intensity error in output LSBs.
    pub rmse: f64,
    /// Largest channel error of the colour multiplier's outputs, in 8-bit LSBs.
    pub color_max_abs_error: Option<u32>,
    /// False when the measurement stopped early: the figures are lower bounds, from
    /// `pixels_seen` pixels.
    pub complete: bool,
    pub pixels_seen: usize,
}

impl Errors {
    /// The largest error of any output (intensity or channel).
    pub fn max_any(&self) -> u32 {
        self.max_abs_error
            .max(self.color_max_abs_error.unwrap_or(0))
    }
}

#[derive(Default)]
struct Acc {
    max: u32,
    color_max: u32,
    sse: f64,
    n: usize,
    worst: Option<usize>,
    worst_err: u32,
}

impl Acc {
    #[inline]
    fn add(&mut self, img: &TestImage, cfg: &Config, k: usize, i: u32) {
        let e = i.abs_diff(img.reference[k]);
        self.sse += (e as f64) * (e as f64);
        self.max = self.max.max(e);
        let mut worst = e;
        if let Some((rgb, refs)) = &img.color {
            let ch = color_mul::eval(cfg, *rgb, i);
            for c in 0..3 {
                let ce = ch[c].abs_diff(refs[k][c]);
                self.color_max = self.color_max.max(ce);
                worst = worst.max(ce);
            }
        }
        if self.worst.is_none() || worst > self.worst_err {
            self.worst = Some(k);
            self.worst_err = worst;
        }
        self.n += 1;
    }

    fn exceeds(&self, l: &Limits) -> bool {
        l.max.is_some_and(|m| self.max > m || self.color_max > m)
            || l.sse.is_some_and(|s| self.sse > s)
    }

    fn errors(&self, img: &TestImage, complete: bool) -> Errors {
        Errors {
            max_abs_error: self.max,
            // Incomplete: a lower bound, the squared errors seen over every pixel.
            rmse: (self.sse / img.pixels().max(1) as f64).sqrt(),
            color_max_abs_error: img.color.as_ref().map(|_| self.color_max),
            complete,
            pixels_seen: self.n,
        }
    }
}

/// Pixels shaded before the first check of the limits; the checks then come after twice as
/// many pixels each time, up to one per CHUNK.
const FIRST_CHUNK: usize = 1 << 8;
const CHUNK: usize = 1 << 14;

/// The absolute intensity error of every pixel, in the image's order.
pub fn pixel_errors(cfg: &Config, maps: &Maps, img: &TestImage) -> Vec<u32> {
    let fast = FastShader::for_samples(&Model::new(cfg), maps, img.pixels() / 2);
    let mut out = vec![0u16; img.pixels()];
    fast.shade_batch(&img.gradients, &mut out);
    out.iter()
        .zip(&img.reference)
        .map(|(&i, &r)| (i as u32).abs_diff(r))
        .collect()
}

/// Measures `cfg` with `maps` on the image, stopping once `limits` are proved exceeded.
/// `killers` are pixels tried first. Returns the errors and the pixel of the largest error.
pub fn measure(
    cfg: &Config,
    maps: &Maps,
    img: &TestImage,
    limits: Limits,
    killers: &[usize],
) -> (Errors, Option<usize>) {
    let model = Model::new(cfg);
    if limits != Limits::default() {
        // The pixels that rejected other candidates, through the per-stage model (no tables
        // to build), one at a time.
        let mut acc = Acc::default();
        for &k in killers {
            acc.add(img, cfg, k, model.intensity(maps, img.gradients[k]));
            if acc.exceeds(&limits) {
                return (acc.errors(img, false), acc.worst);
            }
        }
    }
    // Tables of at most half the image: building them never costs more than shading it.
    let fast = FastShader::for_samples(&model, maps, img.pixels() / 2);
    let mut acc = Acc::default();
    let mut out = vec![0u16; CHUNK];
    let mut start = 0;
    while start < img.pixels() {
        // Checks after 256, 512, 1024, ... pixels, then every CHUNK.
        let len = start.clamp(FIRST_CHUNK, CHUNK).min(img.pixels() - start);
        fast.shade_batch(&img.gradients[start..start + len], &mut out[..len]);
        for (j, &i) in out[..len].iter().enumerate() {
            acc.add(img, cfg, start + j, i as u32);
        }
        start += len;
        if start < img.pixels() && acc.exceeds(&limits) {
            return (acc.errors(img, false), acc.worst);
        }
    }
    (acc.errors(img, true), acc.worst)
}

/// The information bound: a lower bound on the errors of `cfg` on the image whatever its
/// maps and compensation table hold. The output of a sample is a function of its state
/// ([`Model::state`]: face, quadrant and the two fraction codes), so the pixels of one state
/// share one output y, and the best y for them errs by at least half the spread of their
/// references (rounded up: outputs and references are integers), and in squares by at least
/// their squared distances to the integer nearest their mean. It depends only on the front
/// end (red, frac and recip widths), so `fit` computes it once per front end and skips the
/// map fit of every candidate it already rules out (the table fit is seconds a candidate).
pub fn information_bound(cfg: &Config, img: &TestImage) -> Errors {
    #[derive(Clone, Copy)]
    struct Group {
        lo: u32,
        hi: u32,
        sum: f64,
        sq: f64,
        n: f64,
        ch: [(u32, u32); 3],
    }
    let model = Model::new(cfg);
    let mut groups: std::collections::HashMap<u64, Group> = std::collections::HashMap::new();
    for (k, &g) in img.gradients.iter().enumerate() {
        let r = img.reference[k];
        let ch = img
            .color
            .as_ref()
            .map_or([(0, 0); 3], |(_, refs)| refs[k].map(|c| (c, c)));
        let e = groups.entry(model.state(g)).or_insert(Group {
            lo: r,
            hi: r,
            sum: 0.0,
            sq: 0.0,
            n: 0.0,
            ch,
        });
        e.lo = e.lo.min(r);
        e.hi = e.hi.max(r);
        e.sum += r as f64;
        e.sq += (r as f64) * (r as f64);
        e.n += 1.0;
        for c in 0..3 {
            e.ch[c] = (e.ch[c].0.min(ch[c].0), e.ch[c].1.max(ch[c].1));
        }
    }
    let (mut max, mut color_max, mut sse) = (0u32, 0u32, 0.0f64);
    for g in groups.values() {
        max = max.max((g.hi - g.lo).div_ceil(2));
        for &(lo, hi) in &g.ch {
            color_max = color_max.max((hi - lo).div_ceil(2));
        }
        // sum (y - r)^2 = sq - 2 y sum + n y^2, smallest at the integer nearest the mean.
        let y = (g.sum / g.n).round();
        sse += (g.sq - 2.0 * y * g.sum + g.n * y * y).max(0.0);
    }
    Errors {
        max_abs_error: max,
        rmse: (sse / img.pixels().max(1) as f64).sqrt(),
        color_max_abs_error: img.color.as_ref().map(|_| color_max),
        complete: false,
        pixels_seen: 0,
    }
}

/// Whether errors at least `bound` are proved to exceed `limits` (see [`Acc::exceeds`]). The
/// squared errors are rebuilt from the RMSE, so they must exceed the limit by more than
/// rounding could add.
pub fn bound_exceeds(bound: &Errors, limits: &Limits, pixels: usize) -> bool {
    limits.max.is_some_and(|m| {
        bound.max_abs_error > m || bound.color_max_abs_error.is_some_and(|c| c > m)
    }) || limits
        .sse
        .is_some_and(|s| bound.rmse * bound.rmse * pixels as f64 > s * (1.0 + 1e-9) + 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{self, Options};

    #[test]
    fn complete_measurement_equals_the_render_metrics() {
        for (cfg, scene) in [
            (Config::default(), Scene::standard()),
            (
                Config {
                    compensation: false,
                    interpolation: false,
                    interp_bits: 0,
                    index_bits: 4,
                    ..Config::default()
                },
                Scene::alternate(),
            ),
        ] {
            let img = TestImage::new(&cfg, &scene, 96);
            let maps = scene.maps(&cfg);
            let (e, _) = measure(&cfg, &maps, &img, Limits::default(), &[]);
            let r = render::render(
                &cfg,
                &scene,
                Options {
                    size: 96,
                    shrink: 0,
                },
                None,
            )
            .unwrap();
            assert!(e.complete);
            assert_eq!(e.pixels_seen, r.pixels.len());
            assert_eq!(e.max_abs_error, r.metrics.max_abs_error);
            assert!(
                (e.rmse - r.metrics.rmse).abs() < 1e-9,
                "{} {}",
                e.rmse,
                r.metrics.rmse
            );
            assert_eq!(e.color_max_abs_error, None);
        }
    }

    #[test]
    fn stops_early_only_with_evidence() {
        let cfg = Config {
            index_bits: 2,
            ..Config::default()
        };
        let scene = Scene::standard();
        let img = TestImage::new(&cfg, &scene, 128);
        let maps = scene.maps(&cfg);
        let (full, worst) = measure(&cfg, &maps, &img, Limits::default(), &[]);
        let lim = Limits {
            max: Some(full.max_abs_error - 1),
            sse: None,
        };
        let (early, _) = measure(&cfg, &maps, &img, lim, &[]);
        assert!(!early.complete && early.max_abs_error > full.max_abs_error - 1);
        // The worst pixel first rejects at once.
        let (k, _) = measure(&cfg, &maps, &img, lim, &[worst.unwrap()]);
        assert_eq!((k.pixels_seen, k.max_abs_error), (1, full.max_abs_error));
        // A limit it meets never stops it.
        let ok = Limits {
            max: Some(full.max_abs_error),
            sse: Some(full.rmse * full.rmse * img.pixels() as f64 + 1e-6),
        };
        assert_eq!(measure(&cfg, &maps, &img, ok, &[worst.unwrap()]).0, full);
    }

    #[test]
    fn colour_channels_are_measured() {
        let mut scene = Scene::standard();
        scene.color = Some([1.0, 0.5, 0.25]);
        let cfg = Config {
            color: true,
            ..Config::default()
        };
        let img = TestImage::new(&cfg, &scene, 64);
        let maps = scene.maps(&cfg);
        let (e, _) = measure(&cfg, &maps, &img, Limits::default(), &[]);
        let ch = e.color_max_abs_error.unwrap();
        // The channel scales the intensity by at most 255/255, plus rounding.
        assert!(ch <= e.max_abs_error + 1, "{e:?}");
        assert!(ch > 0);
    }

    /// The bound is a lower bound for any contents: for the model's own maps, fitted maps
    /// and random maps and tables alike, and it rules out a coarse front end.
    #[test]
    fn the_information_bound_is_below_every_contents_errors() {
        let scene = Scene::standard();
        for cfg in [
            Config::default(),
            Config {
                red_bits: 6,
                frac_bits: 5,
                recip_bits: 7,
                index_bits: 3,
                ..Config::default()
            },
            Config {
                comp_table: crate::config::CompTable::Ram,
                frac_bits: 6,
                ..Config::default()
            },
        ] {
            let img = TestImage::new(&cfg, &scene, 96);
            let b = information_bound(&cfg, &img);
            let mut rng = crate::rng::SplitMix64::new(7);
            let n = 3 * cfg.map_entries() as usize;
            let random = Maps::from_data(&cfg, (0..n).map(|_| rng.below(256) as u32).collect());
            let mut all = vec![scene.maps(&cfg), random];
            if !cfg.comp_table.is_rom() {
                let m = crate::model::map_fit::contents(
                    &cfg,
                    crate::model::map_fit::MapFit::Table,
                    |d| scene.prepared().shade(d),
                );
                all.push(m);
            }
            for maps in &all {
                let (e, _) = measure(&cfg, maps, &img, Limits::default(), &[]);
                assert!(b.max_abs_error <= e.max_abs_error, "{b:?} {e:?}");
                assert!(b.rmse <= e.rmse + 1e-12, "{b:?} {e:?}");
            }
        }
        // Four fraction bits and a 6-bit reduced gradient cannot draw the highlight.
        let coarse = Config {
            red_bits: 6,
            frac_bits: 4,
            recip_bits: 5,
            ..Config::default()
        };
        let img = TestImage::new(&coarse, &scene, 128);
        let b = information_bound(&coarse, &img);
        assert!(b.max_abs_error > 4, "{b:?}");
        let lim = Limits {
            max: Some(4),
            sse: None,
        };
        assert!(bound_exceeds(&b, &lim, img.pixels()));
        assert!(!bound_exceeds(&b, &Limits::default(), img.pixels()));
        // In squares: a limit below the bound's is exceeded, one at it is not.
        let sse = b.rmse * b.rmse * img.pixels() as f64;
        let at = |s: f64| Limits {
            max: None,
            sse: Some(s),
        };
        assert!(sse > 0.0 && bound_exceeds(&b, &at(0.99 * sse), img.pixels()));
        assert!(!bound_exceeds(&b, &at(sse), img.pixels()));
    }
}
