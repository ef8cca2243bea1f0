//! `rmapgen fit`: the cheapest configuration whose error on the scene's test image meets a
//! target.
//!
//! Every candidate of [`space::candidates`] is a point of the search; they are measured in
//! order of cost ([`space::order_key`]), in parallel batches, until the first that meets the
//! target: so every cheaper candidate has been measured on the image and rejected, none is
//! ruled out by a rule of thumb. The search goes on for a few more passing candidates (the
//! runners-up). Measuring ([`measure::measure`]) uses the bit-exact fast path and stops a
//! candidate as soon as one pixel proves it misses the target.
//!
//! With cost in Yosys cells (iCE40 synthesis, [`cells`]), the order of the search is still by
//! bits (cells are only known after synthesis): for each combination of the optional datapath
//! stages (compensation, interpolation) the search collects the first passing candidates in
//! bits order that are not larger in every width than one found before (a larger one has at
//! least its logic), `synth_limit` in all, synthesises them and picks the fewest cells.
//!
//! When no candidate meets the target, [`best`] finds the lowest error reachable over the
//! whole space (branch and bound: a candidate stops once it is proved worse than the best so
//! far) and the search reports it.

pub mod measure;
pub mod space;

use crate::config::Config;
use crate::model::map_fit::{self, MapFit};
use crate::model::Maps;
use crate::scene::Scene;
use anyhow::{Context, Result};
use measure::{Errors, Limits, TestImage};
use rayon::prelude::*;
use serde::Serialize;
pub use space::CostKind;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The error a design must meet; at least one field is set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Target {
    /// Largest absolute error of any output, in its LSBs.
    pub max_error: Option<u32>,
    /// RMS intensity error in output LSBs.
    pub rmse: Option<f64>,
}

impl Target {
    pub fn met_by(&self, e: &Errors) -> bool {
        e.complete
            && self.max_error.map_or(true, |m| e.max_any() <= m)
            && self.rmse.map_or(true, |r| e.rmse <= r)
    }

    fn limits(&self, pixels: usize) -> Limits {
        Limits {
            max: self.max_error,
            // The RMSE bound as a sum of squares, with a hair of slack for rounding.
            sse: self
                .rmse
                .map(|r| r * r * pixels as f64 * (1.0 + 1e-12) + 1e-9),
        }
    }

    /// "max error <= 3 LSB and RMSE <= 0.9 LSB".
    pub fn describe(&self) -> String {
        let mut v = Vec::new();
        if let Some(m) = self.max_error {
            v.push(format!("max abs error <= {m} LSB"));
        }
        if let Some(r) = self.rmse {
            v.push(format!("RMSE <= {r} LSB"));
        }
        v.join(" and ")
    }
}

/// What to search.
#[derive(Clone, Debug)]
pub struct Options {
    /// The interface fields (grad_bits, map_bits, color, pipeline_depth, handshake); the
    /// others are searched.
    pub base: Config,
    /// Side of the sphere test image.
    pub size: u32,
    pub target: Target,
    pub cost: CostKind,
    /// Passing candidates reported after the choice.
    pub runners_up: usize,
    /// With cost in cells: candidates synthesised.
    pub synth_limit: usize,
    /// How the maps are filled (the scene's own `map_fit` unless overridden).
    pub map_fit: MapFit,
}

/// One measured candidate.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub config: Config,
    pub summary: String,
    pub bits: u64,
    pub cells: Option<u64>,
    pub errors: Errors,
    pub meets_target: bool,
}

/// The result of a successful search.
#[derive(Clone, Debug, Serialize)]
pub struct Decision {
    pub target: Target,
    pub cost: CostKind,
    pub image_size: u32,
    pub pixels: usize,
    pub map_fit: MapFit,
    /// What building the maps evaluates ([`Scene::terms`]).
    pub scene_terms: String,
    pub chosen: Candidate,
    /// The next passing candidates (by cost).
    pub runners_up: Vec<Candidate>,
    /// The most expensive candidates cheaper than the choice, all rejected, measured in full.
    pub rejected_below: Vec<Candidate>,
    /// The paper's design with the same interface.
    pub paper: Candidate,
    /// Candidates in the space, measured, and cheaper (in bits) than the choice.
    pub space: usize,
    pub measured: usize,
    pub cheaper_rejected: usize,
    /// Candidates synthesised (cost in cells; 0 otherwise), besides the paper's.
    pub synthesised: usize,
    pub seconds: f64,
}

/// The lowest error reachable, when nothing meets the target.
#[derive(Clone, Debug, Serialize)]
pub struct Unreachable {
    pub target: Target,
    pub space: usize,
    /// The candidate with the lowest max error (when the target has one).
    pub best_max: Option<Candidate>,
    /// The candidate with the lowest RMSE (when the target has one).
    pub best_rmse: Option<Candidate>,
}

impl Unreachable {
    /// One line: what was asked, and the best reachable with its configuration.
    pub fn message(&self, scene: &str) -> String {
        let mut parts = Vec::new();
        if let Some(c) = &self.best_max {
            parts.push(format!(
                "the lowest max error reachable is {} LSB (RMSE {:.3}) with {}",
                c.errors.max_any(),
                c.errors.rmse,
                c.summary
            ));
        }
        if let Some(c) = &self.best_rmse {
            parts.push(format!(
                "the lowest RMSE reachable is {:.3} LSB (max error {}) with {}",
                c.errors.rmse,
                c.errors.max_any(),
                c.summary
            ));
        }
        format!(
            "no configuration meets {} on {scene} ({} configurations searched); {}",
            self.target.describe(),
            self.space,
            parts.join("; ")
        )
    }
}

pub enum Outcome {
    Found(Box<Decision>),
    Unreachable(Box<Unreachable>),
}

/// The maps of each candidate. The sampled map depends only on the index bits, the
/// compensation and the map width (entry directions and quantisation), so it is built once
/// per such key; fitted maps depend on the whole pipeline and are built per candidate.
struct MapCache {
    fit: MapFit,
    shade: crate::scene::PreparedScene,
    sampled: Mutex<HashMap<(u32, bool, u32), Arc<Maps>>>,
}

impl MapCache {
    fn new(scene: &Scene, fit: MapFit) -> MapCache {
        MapCache {
            fit,
            shade: scene.prepared(),
            sampled: Mutex::new(HashMap::new()),
        }
    }

    fn get(&self, cfg: &Config) -> Arc<Maps> {
        let build = |c: &Config| Arc::new(map_fit::contents(c, self.fit, |n| self.shade.shade(n)));
        if self.fit != MapFit::Sample {
            return build(cfg);
        }
        let key = (cfg.index_bits, cfg.compensation, cfg.map_bits);
        if let Some(m) = self.sampled.lock().expect("map cache").get(&key) {
            return m.clone();
        }
        let m = build(cfg);
        self.sampled
            .lock()
            .expect("map cache")
            .entry(key)
            .or_insert(m)
            .clone()
    }
}

/// Pixels that rejected candidates, most recent first: tried first by the next ones.
struct Killers(Mutex<Vec<usize>>);

impl Killers {
    const KEEP: usize = 24;
    fn snapshot(&self) -> Vec<usize> {
        self.0.lock().expect("killers").clone()
    }
    fn add(&self, k: usize) {
        let mut v = self.0.lock().expect("killers");
        if let Some(p) = v.iter().position(|&x| x == k) {
            v.remove(p);
        }
        v.insert(0, k);
        v.truncate(Self::KEEP);
    }
}

/// Progress of a search: candidates measured, of how many, and a note.
pub type Progress<'a> = &'a (dyn Fn(usize, usize, &str) + Sync);

struct Ctx<'a> {
    img: &'a TestImage,
    maps: MapCache,
    killers: Killers,
}

impl Ctx<'_> {
    fn measure(&self, cfg: &Config, limits: Limits) -> Errors {
        let maps = self.maps.get(cfg);
        let (e, worst) = measure::measure(cfg, &maps, self.img, limits, &self.killers.snapshot());
        if !e.complete {
            if let Some(k) = worst {
                self.killers.add(k);
            }
        }
        e
    }

    fn candidate(&self, cfg: &Config, errors: Errors, target: &Target) -> Candidate {
        Candidate {
            config: cfg.clone(),
            summary: cfg.summary(),
            bits: space::bits(cfg),
            cells: None,
            meets_target: target.met_by(&errors),
            errors,
        }
    }

    /// A full measurement.
    fn full(&self, cfg: &Config, target: &Target) -> Candidate {
        let e = self.measure(cfg, Limits::default());
        self.candidate(cfg, e, target)
    }
}

/// Candidates measured per parallel batch.
const BATCH: usize = 64;
/// Rejected candidates below the choice shown in full.
const SHOWN_BELOW: usize = 3;

/// Searches the space for `scene` (see the module documentation).
pub fn search(scene: &Scene, opts: &Options, progress: Progress) -> Result<Outcome> {
    anyhow::ensure!(
        opts.target.max_error.is_some() || opts.target.rmse.is_some(),
        "give a target: --max-error E and/or --rmse R"
    );
    if let Some(r) = opts.target.rmse {
        anyhow::ensure!(
            r.is_finite() && r >= 0.0,
            "RMSE target {r} must be a finite number >= 0"
        );
    }
    let start = Instant::now();
    let base = Config {
        color: scene.color.is_some(),
        ..opts.base.clone()
    };
    base.validate()?;
    let img = TestImage::new(&base, scene, opts.size);
    let ctx = Ctx {
        img: &img,
        maps: MapCache::new(scene, opts.map_fit),
        killers: Killers(Mutex::new(Vec::new())),
    };
    let cands = space::by_bits(&base);
    let target = opts.target;
    let limits = target.limits(img.pixels());
    let mut results: Vec<Option<Errors>> = vec![None; cands.len()];
    let mut first: Option<usize> = None;
    let mut passing: Vec<usize> = Vec::new();
    // With cost in cells: per combination of the optional datapath stages (compensation,
    // interpolation), the first passing candidates in bits order that are not larger than
    // one found before in every width; each class gets its share of `synth_limit`.
    let classes = |c: &Config| (c.compensation as usize) * 2 + c.interpolation as usize;
    let per_class = opts.synth_limit.max(1).div_ceil(4);
    let mut minimal: Vec<Vec<usize>> = vec![Vec::new(); 4];
    let mut class_left: Vec<usize> = (0..4)
        .map(|k| cands.iter().filter(|c| classes(c) == k).count())
        .collect();
    let wanted = |passing: &[usize], minimal: &[Vec<usize>], left: &[usize]| match opts.cost {
        CostKind::Bits => passing.len() > opts.runners_up,
        CostKind::Cells => (0..4).all(|k| minimal[k].len() >= per_class || left[k] == 0),
    };
    let mut pos = 0;
    while pos < cands.len() && !wanted(&passing, &minimal, &class_left) {
        let end = (pos + BATCH).min(cands.len());
        let batch: Vec<Errors> = cands[pos..end]
            .par_iter()
            .map(|c| ctx.measure(c, limits))
            .collect();
        for (k, e) in batch.into_iter().enumerate() {
            let i = pos + k;
            let class = classes(&cands[i]);
            class_left[class] -= 1;
            if target.met_by(&e) {
                first.get_or_insert(i);
                passing.push(i);
                let m = &mut minimal[class];
                if m.len() < per_class && !m.iter().any(|&j| space::no_larger(&cands[j], &cands[i]))
                {
                    m.push(i);
                }
            }
            results[i] = Some(e);
        }
        pos = end;
        let note = match first {
            Some(f) => format!("cheapest passing so far: {} bits", space::bits(&cands[f])),
            None => format!(
                "{} bits reached, none passes yet",
                space::bits(&cands[end - 1])
            ),
        };
        progress(pos, cands.len(), &note);
    }
    let measured = pos;
    let Some(first) = first else {
        return Ok(Outcome::Unreachable(Box::new(unreachable(
            &ctx, &cands, &target, progress,
        ))));
    };
    let mut shown: Vec<Candidate> = match opts.cost {
        CostKind::Bits => passing
            .iter()
            .take(opts.runners_up + 1)
            .map(|&i| ctx.candidate(&cands[i], results[i].expect("measured"), &target))
            .collect(),
        CostKind::Cells => {
            let mut pick: Vec<usize> = minimal.concat();
            pick.sort_unstable();
            let done = std::sync::atomic::AtomicUsize::new(0);
            let mut v: Vec<Candidate> = pick
                .par_iter()
                .map(|&i| {
                    let mut c = ctx.candidate(&cands[i], results[i].expect("measured"), &target);
                    c.cells = Some(cells(&cands[i], scene)?);
                    let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(n, pick.len(), &format!("synthesised {}", c.summary));
                    Ok(c)
                })
                .collect::<Result<_>>()?;
            v.sort_by_key(|c| (c.cells, space::order_key(&c.config, c.bits)));
            v
        }
    };
    let synthesised = if opts.cost == CostKind::Cells {
        shown.len()
    } else {
        0
    };
    let chosen = shown.remove(0);
    shown.truncate(opts.runners_up);
    // The nearest rejected candidates below the (bits-)cheapest passing one, measured in full.
    let rejected_below: Vec<Candidate> = (0..first)
        .rev()
        .take(SHOWN_BELOW)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|i| ctx.full(&cands[i], &target))
        .collect();
    let mut paper = ctx.full(&space::paper(&base), &target);
    if opts.cost == CostKind::Cells {
        paper.cells = Some(cells(&paper.config, scene)?);
    }
    Ok(Outcome::Found(Box::new(Decision {
        target,
        cost: opts.cost,
        image_size: opts.size,
        pixels: img.pixels(),
        map_fit: opts.map_fit,
        scene_terms: scene.terms(),
        chosen,
        runners_up: shown,
        rejected_below,
        paper,
        space: cands.len(),
        measured,
        cheaper_rejected: first,
        synthesised,
        seconds: start.elapsed().as_secs_f64(),
    })))
}

/// The lowest error over the whole space, for each kind of target given.
fn unreachable(ctx: &Ctx, cands: &[Config], target: &Target, progress: Progress) -> Unreachable {
    let max = target
        .max_error
        .map(|_| best(ctx, cands, Objective::Max, target, progress));
    let rmse = target.rmse.map(|_| {
        // A candidate proves itself worse in RMSE only once its squared errors add up past
        // the best's, so visit first the pixels where the most expensive candidate (likely
        // near the best) errs most: errors concentrate there (highlights, face edges), and
        // the sums grow fastest. The order only changes the speed, never the result.
        let last = cands.last().expect("a non-empty space");
        let err = measure::pixel_errors(last, &ctx.maps.get(last), ctx.img);
        let mut order: Vec<usize> = (0..err.len()).collect();
        order.sort_by_key(|&k| std::cmp::Reverse(err[k]));
        let img = ctx.img.reordered(&order);
        let sorted = Ctx {
            img: &img,
            maps: MapCache {
                fit: ctx.maps.fit,
                shade: ctx.maps.shade.clone(),
                sampled: Mutex::new(ctx.maps.sampled.lock().expect("map cache").clone()),
            },
            killers: Killers(Mutex::new(Vec::new())),
        };
        best(&sorted, cands, Objective::Rmse, target, progress)
    });
    Unreachable {
        target: *target,
        space: cands.len(),
        best_max: max,
        best_rmse: rmse,
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Objective {
    Max,
    Rmse,
}

/// The cheapest candidate with the lowest max error (of any output) or the lowest RMSE.
/// Candidates are measured in order of cost (`cands` is sorted), each stopping as soon as it
/// is proved no better than the best complete measurement so far: the first candidate to
/// reach the final best completes (nothing before it was as good), so the result is exact
/// and the cheapest of its error.
fn best(
    ctx: &Ctx,
    cands: &[Config],
    objective: Objective,
    target: &Target,
    progress: Progress,
) -> Candidate {
    let pixels = ctx.img.pixels() as f64;
    let bound = Mutex::new(None::<Errors>);
    let better = |e: &Errors, o: &Errors| match objective {
        Objective::Max => e.max_any() < o.max_any(),
        Objective::Rmse => e.rmse < o.rmse,
    };
    let mut found: Vec<(usize, Errors)> = Vec::new();
    for (b, chunk) in cands.chunks(BATCH).enumerate() {
        let got: Vec<(usize, Errors)> = chunk
            .par_iter()
            .enumerate()
            .map(|(k, c)| {
                let lim = match *bound.lock().expect("bound") {
                    None => Limits::default(),
                    // Stop once no better: an error of max_any - 1 at most, or a sum of
                    // squares below the best's.
                    Some(o) => match objective {
                        Objective::Max if o.max_any() == 0 => Limits {
                            max: Some(0),
                            sse: Some(-1.0),
                        },
                        Objective::Max => Limits {
                            max: Some(o.max_any() - 1),
                            sse: None,
                        },
                        Objective::Rmse => Limits {
                            max: None,
                            sse: Some(o.rmse * o.rmse * pixels * (1.0 - 1e-12)),
                        },
                    },
                };
                let e = ctx.measure(c, lim);
                if e.complete {
                    let mut bd = bound.lock().expect("bound");
                    if bd.map_or(true, |o| better(&e, &o)) {
                        *bd = Some(e);
                    }
                }
                (b * BATCH + k, e)
            })
            .collect();
        if std::env::var_os("FIT_DEBUG").is_some() {
            for (i, e) in &got {
                eprintln!(
                    "DBG {} {} {} {:.4} {}",
                    i,
                    e.pixels_seen,
                    e.complete,
                    e.rmse,
                    cands[*i].summary()
                );
            }
        }
        found.extend(got.into_iter().filter(|(_, e)| e.complete));
        progress(
            ((b + 1) * BATCH).min(cands.len()),
            cands.len(),
            "no configuration meets the target: searching for the lowest error reachable",
        );
    }
    // The best error, and the cheapest (first in order) candidate that measured it.
    let (i, e) = found
        .into_iter()
        .reduce(|a, b| {
            if better(&b.1, &a.1) || (!better(&a.1, &b.1) && b.0 < a.0) {
                b
            } else {
                a
            }
        })
        .expect("the first candidate is measured in full");
    ctx.candidate(&cands[i], e, target)
}

/// Cells of Yosys synthesis for the iCE40 (`synth_ice40` through
/// [`crate::toolchain::yosys::synth_ice40`], as `rmapgen fpga` runs it: memories in block RAM,
/// each SB_RAM40_4K one cell) of a configuration's design with the scene's maps. `YOSYS` names
/// the tool.
pub fn cells(cfg: &Config, scene: &Scene) -> Result<u64> {
    let tmp = crate::output::Scratch::new()?;
    let out = crate::output::StagedDir::new(&tmp.path().join("design"), &Default::default())?;
    let manifest = crate::rtl::write_design(
        cfg,
        &crate::vectors::MapSet::from_scenes(cfg, scene, &Scene::alternate()),
        &out,
    )?;
    let dir = out.commit()?;
    let files: Vec<String> = manifest.modules.iter().map(|m| m.file.clone()).collect();
    let stat = crate::toolchain::yosys::synth_ice40(&dir, "rmap_top", &files, tmp.path())
        .with_context(|| format!("--cost cells: synthesis of {}", cfg.summary()))?;
    Ok(stat.cells as u64)
}

impl Decision {
    /// The decision as a text table: the choice, the runners-up, the nearest rejected
    /// candidates below it and the paper's design.
    pub fn table(&self) -> String {
        let cells = self.cost == CostKind::Cells;
        let mut s = String::new();
        s.push_str(&format!(
            "{:<14} {:<62} {:>7} {:>7} {:>7} {:>9}{}\n",
            "",
            "configuration",
            "max err",
            "RMSE",
            "colour",
            "bits",
            if cells { "     cells" } else { "" }
        ));
        let mut row = |label: &str, c: &Candidate| {
            let e = &c.errors;
            let lb = if e.complete { "" } else { ">=" };
            s.push_str(&format!(
                "{:<14} {:<62} {:>7} {:>7.3} {:>7} {:>9}{}{}\n",
                label,
                c.summary,
                format!("{lb}{}", e.max_abs_error),
                e.rmse,
                e.color_max_abs_error
                    .map_or("-".to_string(), |x| x.to_string()),
                c.bits,
                if cells {
                    format!(" {:>9}", c.cells.map_or("-".into(), |x| x.to_string()))
                } else {
                    String::new()
                },
                if c.meets_target { "" } else { "  (misses)" }
            ));
        };
        row("chosen", &self.chosen);
        for (k, c) in self.runners_up.iter().enumerate() {
            row(&format!("runner-up {}", k + 1), c);
        }
        for c in &self.rejected_below {
            row("cheaper", c);
        }
        row("paper", &self.paper);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampled_maps_depend_only_on_the_cache_key() {
        let scene = Scene::alternate();
        let cache = MapCache::new(&scene, MapFit::Sample);
        for c in space::candidates(&Config::default()).iter().step_by(977) {
            assert_eq!(*cache.get(c), scene.maps(c), "{}", c.summary());
        }
    }

    #[test]
    fn target_checks_every_output_and_needs_a_complete_measurement() {
        let e = Errors {
            max_abs_error: 3,
            rmse: 1.0,
            color_max_abs_error: Some(4),
            complete: true,
            pixels_seen: 10,
        };
        let t = |m, r| Target {
            max_error: m,
            rmse: r,
        };
        assert!(t(Some(4), None).met_by(&e));
        assert!(!t(Some(3), None).met_by(&e));
        assert!(t(None, Some(1.0)).met_by(&e));
        assert!(!t(Some(4), Some(0.99)).met_by(&e));
        assert!(!t(Some(4), None).met_by(&Errors {
            complete: false,
            ..e
        }));
    }
}
