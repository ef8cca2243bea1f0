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
use context::{Ctx, Killers, MapCache};
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
    /// The part: its family's Yosys synthesis counts the cells (cost in cells); with
    /// `check_part`, the choice and the runners-up must fit it.
    pub part: crate::flow::fpga::Options,
    /// Whether a passing candidate must fit `part` ([`cells::on_part`] packs it) to be chosen.
    pub check_part: bool,
    /// Passing candidates reported after the choice.
    pub runners_up: usize,
    /// With cost in cells, or the part checked: passing candidates synthesised (at most).
    pub synth_limit: usize,
    /// How the maps are filled (the scene's own `map_fit` unless overridden).
    pub map_fit: MapFit,
    /// Searched fields the caller fixed: only candidates with those values are searched.
    pub fixed: space::Fixed,
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
        bounds: Default::default(),
    };
    let cands = space::by_bits(&base, &opts.fixed);
    anyhow::ensure!(
        !cands.is_empty(),
        "no valid configuration has {} (with --grad-bits {} and --map-bits {}): fix fewer fields",
        opts.fixed.describe(),
        base.grad_bits,
        base.map_bits
    );
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
    // With the part checked and cost in bits: passing candidates in bits order are
    // synthesised and packed (a few at a time) until enough fit or `synth_limit` were tried.
    let check_bits = opts.check_part && opts.cost == CostKind::Bits;
    let mut on_part: Vec<Option<cells::OnPart>> = vec![None; cands.len()];
    let mut fitting: Vec<usize> = Vec::new();
    let mut tried = 0;
    let wanted = |passing: &[usize],
                  fitting: &[usize],
                  tried: usize,
                  minimal: &[Vec<usize>],
                  left: &[usize]| match opts.cost {
        CostKind::Bits if check_bits => {
            fitting.len() > opts.runners_up || tried >= opts.synth_limit
        }
        CostKind::Bits => passing.len() > opts.runners_up,
        CostKind::Cells => (0..4).all(|k| minimal[k].len() >= per_class || left[k] == 0),
    };
    let mut pos = 0;
    while pos < cands.len() && !wanted(&passing, &fitting, tried, &minimal, &class_left) {
        let end = (pos + context::search_batch()).min(cands.len());
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
        if check_bits {
            let fresh: Vec<usize> = passing
                .iter()
                .copied()
                .filter(|&i| on_part[i].is_none())
                .collect();
            for chunk in fresh.chunks(rayon::current_num_threads().max(1)) {
                if fitting.len() > opts.runners_up || tried >= opts.synth_limit {
                    break;
                }
                let chunk = &chunk[..chunk.len().min(opts.synth_limit - tried)];
                let done: Vec<cells::OnPart> = chunk
                    .par_iter()
                    .map(|&i| cells::on_part(&cands[i], scene, &opts.part, true))
                    .collect::<Result<_>>()?;
                for (&i, o) in chunk.iter().zip(done) {
                    tried += 1;
                    if o.shortage.is_none() {
                        fitting.push(i);
                    }
                    progress(
                        tried,
                        opts.synth_limit,
                        &format!(
                            "packed {}: {}",
                            cands[i].summary(),
                            o.shortage.as_deref().unwrap_or("fits")
                        ),
                    );
                    on_part[i] = Some(o);
                }
            }
        }
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
    let with_part = |mut c: Candidate, o: &cells::OnPart| {
        if opts.cost == CostKind::Cells {
            c.cells = Some(o.cells);
        }
        if opts.check_part {
            c.fits = Some(o.shortage.is_none());
            c.shortage = o.shortage.clone();
        }
        c
    };
    // Every passing candidate synthesised (and with the part checked, packed), in the order
    // of the choice.
    let mut shown: Vec<Candidate> = match opts.cost {
        CostKind::Bits if check_bits => passing
            .iter()
            .filter_map(|&i| Some((i, on_part[i].as_ref()?)))
            .map(|(i, o)| {
                with_part(
                    ctx.candidate(&cands[i], results[i].expect("measured"), &target),
                    o,
                )
            })
            .collect(),
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
                    let c = ctx.candidate(&cands[i], results[i].expect("measured"), &target);
                    let o = cells::on_part(&cands[i], scene, &opts.part, opts.check_part)?;
                    let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(n, pick.len(), &format!("synthesised {}", c.summary));
                    Ok(with_part(c, &o))
                })
                .collect::<Result<_>>()?;
            v.sort_by_key(|c| (c.cells, space::order_key(&c.config, c.bits)));
            v
        }
    };
    let synthesised = if opts.cost == CostKind::Cells || check_bits {
        shown.len()
    } else {
        0
    };
    // Those that do not fit the part are not chosen; the first of them is reported.
    let too_big: Vec<Candidate> = shown
        .iter()
        .filter(|c| c.fits == Some(false))
        .cloned()
        .collect();
    shown.retain(|c| c.fits != Some(false));
    if shown.is_empty() {
        let c = too_big
            .first()
            .expect("a passing candidate was synthesised");
        anyhow::bail!(
            "none of the {} configurations that meet {} and were synthesised fits the {} {} (--synth-limit {}): the first, {}: {}",
            too_big.len(),
            target.describe(),
            opts.part.family.title(),
            opts.part.device,
            opts.synth_limit,
            c.summary,
            c.shortage.as_deref().unwrap_or_default()
        );
    }
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
    if opts.cost == CostKind::Cells || opts.check_part {
        let o = cells::on_part(&paper.config, scene, &opts.part, opts.check_part)?;
        paper = with_part(paper, &o);
    }
    let part = opts.check_part.then(|| outcome::Part {
        family: opts.part.family,
        device: opts.part.device.clone(),
        package: opts.part.package.clone(),
        too_big: too_big.len(),
        first_too_big: too_big.into_iter().next(),
    });
    Ok(Outcome::Found(Box::new(Decision {
        target,
        cost: opts.cost,
        family: opts.part.family,
        part,
        image_size: opts.size,
        pixels: img.pixels(),
        map_fit: opts.map_fit,
        scene_terms: scene.terms(),
        chosen,
        runners_up: shown,
        rejected_below,
        paper,
        space: cands.len(),
        fixed: opts.fixed,
        measured,
        cheaper_rejected: first,
        synthesised,
        seconds: start.elapsed().as_secs_f64(),
    })))
}
