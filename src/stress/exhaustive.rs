//! The exhaustive run: every gradient of a configuration (2^(3G)), factored so that each
//! piece of work is done once for everything that shares it.
//!
//! The model's output depends on a gradient only through sort & shift's result: the max axis,
//! the three sign bits and the reduced magnitudes (m, a, b), which are fixed by the sorted
//! magnitude triple (M, c_u, c_v) (M the largest). The position of a component depends only on
//! the pair (M, c); the output only on (axis, signs, p_u, p_v). So:
//!
//! 1. **positions**, once per pair (M, c), from `Model::trace` (4.2M pairs at 12 bits), each
//!    checked against the fast path's fused position table;
//! 2. **every input**, in the order (M, c_u, c_v, axis, signs): the sort & shift stage function
//!    itself, checked against the enumeration's axis, signs, shift and reduced magnitudes
//!    (which is what makes steps 1 and 3 valid for that input), then the output read from the
//!    fused intensity table (counted for saturation). The angular error is computed once per
//!    sorted triple, as it does not depend on signs or axis placement;
//! 3. **intensity error**: the reference is a smooth function of direction and the output is
//!    constant on each cell (class, axis, signs, p_u, p_v). The reference is bounded on every
//!    cell by interval arithmetic over the box of tangents c / M that the cell's pairs cover
//!    ([`super::interval`]); cells are then evaluated gradient by gradient against
//!    `Reference::intensity`, largest bound first, until no remaining cell's bound can exceed
//!    the worst error found. The result is the exact maximum over every input, per class.

use super::interval::{shade_bounds, DirBox};
use super::{angle_deg, WorstError};
use super::{
    class_of, class_range, classes, encoded_direction, encoded_tangent, Acc, Report, Setup,
};
use crate::geometry::place;
use crate::model::fast::ordered_signs;
use crate::model::reflectance_map::quantise;
use crate::model::sort_shift::{self, SortShift};
use anyhow::{ensure, Result};
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// Widest gradient an exhaustive run accepts: 2^36 inputs.
pub const MAX_GRAD_BITS: u32 = 12;

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

/// Positions of every pair (M, c), 1 <= M <= 2^(G-1), 0 <= c <= M.
struct PairPositions {
    stride: usize,
    p: Vec<u16>,
}

impl PairPositions {
    fn row(&self, max: u32) -> &[u16] {
        let s = max as usize * self.stride;
        &self.p[s..s + max as usize + 1]
    }
}

/// Valid sign codes (x | y << 1 | z << 2) of a magnitude triple: a zero component is never
/// negative and a component of 2^(G-1) always is.
fn sign_codes(mags: [u32; 3], full: u32) -> impl Iterator<Item = u32> {
    (0..8u32).filter(move |code| {
        (0..3).all(|k| {
            let neg = (code >> k) & 1 == 1;
            // Zero is never negative; 2^(G-1) is always negative.
            (mags[k] != 0 || !neg) && (mags[k] != full || neg)
        })
    })
}

fn signed(mags: [u32; 3], code: u32) -> [i32; 3] {
    [0, 1, 2].map(|k| {
        if (code >> k) & 1 == 1 {
            -(mags[k] as i32)
        } else {
            mags[k] as i32
        }
    })
}

/// A gradient with these magnitudes, positive where the range allows: where an angle was
/// found (signs do not change it).
fn representative(mags: [u32; 3], full: u32) -> [i32; 3] {
    signed(
        mags,
        sign_codes(mags, full)
            .next()
            .expect("some sign code is valid"),
    )
}

/// Runs every input; `progress` is called with the number of inputs done since its last call.
pub fn run(setup: &Setup, progress: &(dyn Fn(u64) + Sync)) -> Result<Report> {
    let cfg = &setup.cfg;
    ensure!(
        cfg.grad_bits <= MAX_GRAD_BITS,
        "an exhaustive run covers 2^(3 grad_bits) inputs; grad_bits = {} is above {MAX_GRAD_BITS} (use --samples)",
        cfg.grad_bits
    );
    let start = Instant::now();
    let full = 1u32 << (cfg.grad_bits - 1);
    let mut acc = Acc::new(cfg);

    // 1. Positions of every pair.
    let stride = full as usize + 1;
    let rows: Vec<(Vec<u16>, Acc)> = (0..=full)
        .into_par_iter()
        .map(|max| {
            let mut a = Acc::new(cfg);
            let row = (0..=max)
                .map(|c| {
                    if max == 0 {
                        return 0;
                    }
                    let g = [-(max as i32), -(c as i32), 0];
                    let t = setup.model.trace(&setup.maps, g, [0; 3]);
                    if setup.fast.position(t.sort.m, t.sort.a) != t.p_u {
                        a.mismatch(0, g);
                    }
                    t.p_u as u16
                })
                .collect();
            (row, a)
        })
        .collect();
    let mut p = vec![0u16; stride * stride];
    for (max, (row, a)) in rows.into_iter().enumerate() {
        p[max * stride..max * stride + row.len()].copy_from_slice(&row);
        acc = acc.merge(a);
    }
    let pos = PairPositions { stride, p };
    let seconds_positions = start.elapsed().as_secs_f64();

    // 2. Every input, and the angle once per sorted triple.
    let t_inputs = Instant::now();
    let tan: Vec<f64> = (0..=cfg.pos_max())
        .map(|p| encoded_tangent(cfg, p))
        .collect();
    let drop = cfg.grad_bits - cfg.red_bits;
    // The fused output table's flags, [axis][sign code][p_u][p_v]: zero + full scale << 16.
    let ps = cfg.pos_max() as usize + 1;
    let flags: Vec<u32> = (0..24 * ps * ps)
        .map(|k| {
            let (ac, pu, pv) = (
                (k / (ps * ps)) as u32,
                ((k / ps) % ps) as u32,
                (k % ps) as u32,
            );
            let o = setup.fast.intensity_at(ac / 8, ac % 8, pu, pv);
            (o == 0) as u32 | ((o == cfg.map_max()) as u32) << 16
        })
        .collect();
    let no_flags = vec![0u32; ps];
    type AngleBest = Vec<Option<(f64, [u32; 3])>>;
    let (inputs_acc, angles) = (1..=full)
        .into_par_iter()
        .map(|max| {
            let mut a = Acc::new(cfg);
            let mut angles: AngleBest = vec![None; classes(cfg) as usize];
            let shift = class_of(cfg, max);
            let red = |c: u32| (c << shift) >> drop;
            let m = red(max);
            let row = pos.row(max);
            let trow: Vec<f64> = row.iter().map(|&p| tan[p as usize]).collect();
            let mut s2 = vec![0f64; max as usize + 1];
            let mf = max as f64;
            let class = &mut a.classes[shift as usize];
            let mut mismatch: Option<[i32; 3]> = None;
            let (mut mismatches, mut inputs, mut zero, mut saturated) = (0u64, 0u64, 0u64, 0u64);
            for c_u in 0..=max {
                let (p_u, t_u, a_red, cu) = (
                    row[c_u as usize] as u32,
                    trow[c_u as usize],
                    red(c_u),
                    c_u as f64,
                );
                // sin^2 of the angle between (M, c_u, c_v) and (1, t_u, t_v), for every c_v.
                for (c_v, (s, &t_v)) in s2.iter_mut().zip(&trow).enumerate() {
                    let cv = c_v as f64;
                    let (x, y, z) = (cu * t_v - cv * t_u, cv - mf * t_v, mf * t_u - cu);
                    *s = (x * x + y * y + z * z)
                        / ((mf * mf + cu * cu + cv * cv) * (1.0 + t_u * t_u + t_v * t_v));
                }
                let (c_v, &s) =
                    s2.iter()
                        .enumerate()
                        .fold((0, &-1.0), |b, x| if x.1 > b.1 { x } else { b });
                let best = &mut angles[shift as usize];
                if best.map_or(true, |(b, _)| s > b) {
                    *best = Some((s, [max, c_u, c_v as u32]));
                }
                for axis in 0..3u32 {
                    // The tie rule: the max axis is the lowest one holding M.
                    if axis >= 1 && c_u == max {
                        break;
                    }
                    let c_v_top = if axis == 2 { max - 1 } else { max };
                    // Sort & shift once per magnitude triple (signs only pass through it).
                    for c_v in 0..=c_v_top {
                        let mags = place(axis, max, c_u, c_v);
                        let code = sign_codes(mags, full).next().expect("a valid sign code");
                        let g = signed(mags, code);
                        let (s_max, s_u, s_v) = ordered_signs(axis, code);
                        let want = SortShift {
                            axis,
                            s_max,
                            s_u,
                            s_v,
                            shift,
                            m,
                            a: a_red,
                            b: red(c_v),
                        };
                        if sort_shift::eval(cfg, g) != want {
                            mismatches += 1;
                            mismatch.get_or_insert(g);
                        }
                    }
                    // Every input: each sign pattern of each triple reads its own output's
                    // flags from the fused table at its address (axis, signs, p_u, p_v).
                    let valid = |c: u32, s: u32| (c != 0 || s == 0) && (c != full || s == 1);
                    let mut live = [false; 8];
                    let blocks: [&[u32]; 8] = std::array::from_fn(|code| {
                        let (s_max, s_u, _) = ordered_signs(axis, code as u32);
                        live[code] = valid(max, s_max) && valid(c_u, s_u);
                        if live[code] {
                            &flags[((axis as usize * 8 + code) * ps + p_u as usize) * ps..][..ps]
                        } else {
                            &no_flags[..]
                        }
                    });
                    // c_v = 0 and c_v = 2^(G-1) allow one sign; the rest allow both.
                    let top = c_v_top.min(full - 1);
                    let mut sum = 0u32;
                    for &p_v in &row[1..=top as usize] {
                        let p = (p_v as usize).min(ps - 1);
                        sum += blocks.iter().map(|b| b[p]).sum::<u32>();
                    }
                    let n_live = live.iter().filter(|&&l| l).count() as u64;
                    inputs += n_live * top as u64;
                    for (c_v, s_v_needed) in [(0, 0), (full, 1)] {
                        if c_v > c_v_top {
                            continue;
                        }
                        let p = row[c_v as usize] as usize;
                        for code in 0..8 {
                            if live[code] && ordered_signs(axis, code as u32).2 == s_v_needed {
                                sum += blocks[code][p];
                                inputs += 1;
                            }
                        }
                    }
                    zero += (sum & 0xffff) as u64;
                    saturated += (sum >> 16) as u64;
                }
            }
            class.inputs = inputs;
            class.zero = zero;
            class.full = saturated;
            let done = class.inputs;
            if let Some(g) = mismatch {
                a.mismatch(0, g);
                a.mismatches += mismatches - 1;
            }
            progress(done);
            (a, angles)
        })
        .reduce(
            || (Acc::new(cfg), vec![None; classes(cfg) as usize]),
            |(a1, g1), (a2, g2)| {
                let angles = g1
                    .into_iter()
                    .zip(g2)
                    .map(|(x, y)| match (x, y) {
                        (Some(x), Some(y)) => Some(if y.0 > x.0 || (y.0 == x.0 && y.1 < x.1) {
                            y
                        } else {
                            x
                        }),
                        (x, y) => x.or(y),
                    })
                    .collect();
                (a1.merge(a2), angles)
            },
        );
    acc = acc.merge(inputs_acc);
    // The zero gradient: flagged, intensity 0 in the model and the fast path.
    let zero = [0, 0, 0];
    if setup.model.intensity(&setup.maps, zero) != 0 || setup.fast.shade(zero) != 0 {
        acc.mismatch(0, zero);
    }
    progress(1);
    for (class, best) in angles.iter().enumerate() {
        if let Some((_, mags)) = best {
            // The exact angle of the worst triple, in the world frame.
            let g = representative(*mags, full);
            let t = setup.model.trace(&setup.maps, g, [0; 3]);
            let s = t.sort;
            let dir = encoded_direction(cfg, s.axis, (s.s_max, s.s_u, s.s_v), t.p_u, t.p_v);
            let deg = angle_deg(
                dir,
                DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64).normalize(),
            );
            acc.classes[class].angle(deg, 0, g);
        }
    }
    let seconds_inputs = t_inputs.elapsed().as_secs_f64();

    // 3. The exact maximum intensity error per class.
    let t_search = Instant::now();
    let (worst, stats) = search(setup, &pos)?;
    for (class, w) in worst.into_iter().enumerate() {
        if let Some(w) = w {
            acc.classes[class].error(w, 0);
        }
    }
    let mut report = acc.report(cfg, "exhaustive", 1, start.elapsed().as_secs_f64());
    report.map_fit = setup.scene.map_fit;
    report.search = Some(SearchStats {
        seconds_positions,
        seconds_inputs,
        seconds_search: t_search.elapsed().as_secs_f64(),
        ..stats
    });
    ensure!(
        report.inputs == 1u64 << (3 * cfg.grad_bits),
        "internal error: enumerated {} inputs, expected 2^{}",
        report.inputs,
        3 * cfg.grad_bits
    );
    Ok(report)
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

/// For every (M, position): the first and last c with that position (positions are
/// monotonic in c for a fixed M, so each is one run), or lo > hi when there is none.
struct Runs {
    ps: usize,
    run: Vec<(u16, u16)>,
}

impl Runs {
    fn new(cfg: &crate::config::Config, pos: &PairPositions) -> Result<Runs> {
        let full = 1u32 << (cfg.grad_bits - 1);
        let ps = cfg.pos_max() as usize + 1;
        let mut run = vec![(1u16, 0u16); (full as usize + 1) * ps];
        for max in 1..=full {
            let row = pos.row(max);
            ensure!(
                row.windows(2).all(|w| w[0] <= w[1]),
                "positions are not monotonic for max {max}"
            );
            for (c, &p) in row.iter().enumerate() {
                let r = &mut run[max as usize * ps + p as usize];
                if r.0 > r.1 {
                    *r = (c as u16, c as u16);
                } else {
                    r.1 = c as u16;
                }
            }
        }
        Ok(Runs { ps, run })
    }

    fn get(&self, max: u32, p: u32) -> (u32, u32) {
        let (lo, hi) = self.run[max as usize * self.ps + p as usize];
        (lo as u32, hi as u32)
    }
}

/// The exact worst error of every class, by bounding and then evaluating cells.
fn search(setup: &Setup, pos: &PairPositions) -> Result<(Vec<Option<WorstError>>, SearchStats)> {
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
                    if best.map_or(true, |b| w.abs() > b.abs()) {
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
                if error.abs() > floor && worst.map_or(true, |w| error.unsigned_abs() > w.abs()) {
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
