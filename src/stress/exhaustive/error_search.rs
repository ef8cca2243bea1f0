//! Step 3 of the exhaustive run: the exact worst intensity error of every class, found by
//! bounding the reference on every cell of constant output and evaluating, input by input,
//! only the cells whose bound could beat the worst error found so far. Separate from the
//! enumeration of every input ([`super::run`]), which calls it once positions are known.

use super::positions::{PairPositions, Runs};
use super::signs::signed;
use crate::geometry::place;
use crate::model::fast::ordered_signs;
use crate::model::reflectance_map::quantise;
use crate::stress::interval::{shade_bounds, DirBox};
use crate::stress::{class_of, class_range, classes, Setup, WorstError};
use anyhow::Result;
use rayon::prelude::*;
use serde::Serialize;

/// How the exact maximum intensity error was found, and the time of each step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SearchStats {
    /// Cells (class, axis, signs, p_u, p_v) whose reference intensity was bounded.
    pub cells: u64,
    /// Cells whose bound could exceed the worst error found so far, evaluated input by input.
    pub cells_evaluated: u64,
    /// Inputs evaluated against the reference in those cells.
    pub reference_evaluations: u64,
    pub seconds_positions: f64,
    pub seconds_inputs: f64,
    pub seconds_search: f64,
}

/// One cell of the error search: the output is `out` for every input in it.
#[derive(Clone, Copy, Debug)]
struct Cell {
    class: u32,
    axis: u32,
    code: u32,
    p_u: u32,
    p_v: u32,
    out: u32,
    /// No input of the cell has |model - reference| above this.
    bound: i64,
}

/// Cells evaluated per parallel wave of the search.
const WAVE: usize = 16;

/// The exact worst error of every class, by bounding and then evaluating cells.
pub(super) fn search(
    setup: &Setup,
    pos: &PairPositions,
) -> Result<(Vec<Option<WorstError>>, SearchStats)> {
    let cfg = &setup.cfg;
    let full = 1u32 << (cfg.grad_bits - 1);
    let pm = cfg.pos_max() as usize;
    let runs = Runs::new(cfg, pos)?;
    // Tangent range covered by each (class, position).
    let nclass = classes(cfg) as usize;
    let mut tbox = vec![(f64::INFINITY, f64::NEG_INFINITY); nclass * (pm + 1)];
    for max in 1..=full {
        let class = class_of(cfg, max) as usize;
        for p in 0..=pm as u32 {
            let (lo, hi) = runs.get(max, p);
            if lo <= hi {
                let b = &mut tbox[class * (pm + 1) + p as usize];
                *b = (
                    b.0.min(lo as f64 / max as f64),
                    b.1.max(hi as f64 / max as f64),
                );
            }
        }
    }
    let scene = setup.scene.prepared();
    let mut stats = SearchStats {
        cells: 0,
        cells_evaluated: 0,
        reference_evaluations: 0,
        seconds_positions: 0.0,
        seconds_inputs: 0.0,
        seconds_search: 0.0,
    };
    let mut worst = vec![None; nclass];
    for class in 0..nclass as u32 {
        let boxes: Vec<(u32, (f64, f64))> = (0..=pm as u32)
            .map(|p| (p, tbox[class as usize * (pm + 1) + p as usize]))
            .filter(|(_, b)| b.0 <= b.1)
            .collect();
        let boxes = &boxes;
        let scene = &scene;
        let mut cells: Vec<Cell> = (0..24u32)
            .into_par_iter()
            .flat_map_iter(|k| {
                let (axis, code) = (k / 8, k % 8);
                boxes.iter().flat_map(move |&(p_u, bu)| {
                    boxes.iter().map(move |&(p_v, bv)| {
                        let out = setup.fast.intensity_at(axis, code, p_u, p_v);
                        let bound = error_bound(setup, scene, axis, code, bu, bv, out);
                        Cell {
                            class,
                            axis,
                            code,
                            p_u,
                            p_v,
                            out,
                            bound,
                        }
                    })
                })
            })
            .collect();
        stats.cells += cells.len() as u64;
        cells.sort_unstable_by_key(|c| (-c.bound, c.axis, c.code, c.p_u, c.p_v));
        let mut best: Option<WorstError> = None;
        let mut i = 0;
        let floor = |best: &Option<WorstError>| best.map_or(-1, |w| w.abs() as i64);
        while i < cells.len() && cells[i].bound > floor(&best) {
            let mut j = i;
            while j < cells.len() && j - i < WAVE && cells[j].bound > floor(&best) {
                j += 1;
            }
            // Every cell of a wave prunes against the same floor, so results do not depend on
            // scheduling.
            let f = floor(&best);
            let found: Vec<(Option<WorstError>, u64)> = cells[i..j]
                .par_iter()
                .map(|c| evaluate_cell(setup, scene, &runs, full, c, f))
                .collect();
            for (w, n) in found {
                stats.cells_evaluated += 1;
                stats.reference_evaluations += n;
                if let Some(w) = w {
                    if best.is_none_or(|b| w.abs() > b.abs()) {
                        best = Some(w);
                    }
                }
            }
            i = j;
        }
        worst[class as usize] = best;
    }
    Ok((worst, stats))
}

/// No input whose direction lies in the box (tangent ranges `tu`, `tv` on the face of
/// `axis`, signs `code`) has |out - reference| above this.
fn error_bound(
    setup: &Setup,
    scene: &crate::scene::PreparedScene,
    axis: u32,
    code: u32,
    tu: (f64, f64),
    tv: (f64, f64),
    out: u32,
) -> i64 {
    let b = shade_bounds(
        scene,
        &DirBox::on_face(axis, ordered_signs(axis, code), tu, tv),
    );
    let (lo, hi) = (
        quantise(&setup.cfg, b.lo) as i64,
        quantise(&setup.cfg, b.hi) as i64,
    );
    (out as i64 - lo).max(hi - out as i64)
}

/// The inputs of one cell against the reference, one max magnitude M at a time: each M's
/// slice is bounded first and evaluated only if its bound exceeds `floor`. Returns the
/// worst error above `floor` (if any) and the inputs evaluated.
fn evaluate_cell(
    setup: &Setup,
    scene: &crate::scene::PreparedScene,
    runs: &Runs,
    full: u32,
    c: &Cell,
    floor: i64,
) -> (Option<WorstError>, u64) {
    let cfg = &setup.cfg;
    let (s_max, s_u, s_v) = ordered_signs(c.axis, c.code);
    let (lo, hi) = class_range(cfg, c.class);
    let mut worst: Option<WorstError> = None;
    let mut n = 0u64;
    for max in lo..=hi {
        if max == full && s_max == 0 {
            continue;
        }
        // The run of c with this position, cut to what the tie rule and signs allow: a lower
        // axis holds less than M, a negative component is not 0, a positive one not 2^(G-1).
        let run = |p: u32, strict: bool, s: u32| {
            let (mut a, mut b) = runs.get(max, p);
            if strict {
                b = b.min(max.saturating_sub(1));
            }
            if s == 1 {
                a = a.max(1);
            } else {
                b = b.min(full - 1);
            }
            (a, b)
        };
        let (u0, u1) = run(c.p_u, c.axis >= 1, s_u);
        let (v0, v1) = run(c.p_v, c.axis == 2, s_v);
        if u0 > u1 || v0 > v1 || (c.axis >= 1 && max == 0) {
            continue;
        }
        let m = max as f64;
        let bound = error_bound(
            setup,
            scene,
            c.axis,
            c.code,
            (u0 as f64 / m, u1 as f64 / m),
            (v0 as f64 / m, v1 as f64 / m),
            c.out,
        );
        if bound <= floor {
            continue;
        }
        for c_v in v0..=v1 {
            for c_u in u0..=u1 {
                let g = signed(place(c.axis, max, c_u, c_v), c.code);
                n += 1;
                let reference = setup.reference.intensity(g);
                let error = c.out as i64 - reference as i64;
                if error.abs() > floor && worst.is_none_or(|w| error.unsigned_abs() > w.abs()) {
                    let exact = setup.reference.exact(g).expect("not the zero gradient");
                    debug_assert_eq!(setup.fast.shade(g), c.out, "{g:?}");
                    worst = Some(WorstError {
                        error,
                        gradient: g,
                        model: c.out,
                        reference,
                        reference_exact: exact * cfg.map_max() as f64,
                    });
                }
            }
        }
    }
    (worst, n)
}
