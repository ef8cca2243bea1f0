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

mod best;
pub mod cells;
mod context;
pub mod measure;
pub mod outcome;
pub mod space;
pub mod target;

use crate::config::Config;
use crate::model::map_fit::MapFit;
use crate::scene::Scene;
use anyhow::Result;
pub use context::Progress;
use context::{Ctx, Killers, MapCache, BATCH};
use measure::{Errors, TestImage};
use outcome::{Candidate, Decision, Outcome};
use rayon::prelude::*;
pub use space::CostKind;
use std::sync::Mutex;
use std::time::Instant;
use target::Target;

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
    /// The family whose Yosys synthesis counts the cells (cost in cells).
    pub family: crate::rtl::fpga::Family,
    /// Passing candidates reported after the choice.
    pub runners_up: usize,
    /// With cost in cells: candidates synthesised.
    pub synth_limit: usize,
    /// How the maps are filled (the scene's own `map_fit` unless overridden).
    pub map_fit: MapFit,
}
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
        return Ok(Outcome::Unreachable(Box::new(best::unreachable(
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
                    c.cells = Some(cells::cells(&cands[i], scene, opts.family)?);
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
        paper.cells = Some(cells::cells(&paper.config, scene, opts.family)?);
    }
    Ok(Outcome::Found(Box::new(Decision {
        target,
        cost: opts.cost,
        family: opts.family,
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
