//! The lowest error reachable over the whole space, when no candidate meets the target:
//! a branch and bound over the candidates in order of cost. Separate from the search, which
//! only calls it once the search has found nothing.

use super::context::{Bounds, Ctx, Killers, MapCache, Progress, BATCH};
use super::measure::{self, Errors, Limits};
use super::outcome::{Candidate, Unreachable};
use super::target::Target;
use crate::config::Config;
use rayon::prelude::*;
use std::sync::Mutex;

/// The lowest error over the whole space, for each kind of target given.
pub(super) fn unreachable(
    ctx: &Ctx,
    cands: &[Config],
    target: &Target,
    progress: Progress,
) -> Unreachable {
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
            bounds: Bounds::default(),
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
                    if bd.is_none_or(|o| better(&e, &o)) {
                        *bd = Some(e);
                    }
                }
                (b * BATCH + k, e)
            })
            .collect();
        if std::env::var_os("FIT_DEBUG").is_some() {
            for (i, e) in &got {
                crate::errln!(
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
