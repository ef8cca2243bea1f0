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

pub mod error_search;
mod positions;
mod signs;

use super::{angle_deg, class_of, classes, encoded_direction, Acc, Report, Setup};
use crate::geometry::place;
use crate::model::fast::ordered_signs;
use crate::model::sort_shift::{self, SortShift};
use anyhow::{ensure, Result};
use error_search::{search, SearchStats};
use glam::DVec3;
use positions::PairPositions;
use rayon::prelude::*;
use signs::{representative, sign_codes, signed};
use std::time::Instant;

/// Widest gradient an exhaustive run accepts: 2^36 inputs.
pub const MAX_GRAD_BITS: u32 = 12;

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
    let tan = &setup.tangents;
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
                if best.is_none_or(|(b, _)| s > b) {
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
            let dir = encoded_direction(
                &setup.tangents,
                s.axis,
                (s.s_max, s.s_u, s.s_v),
                t.p_u,
                t.p_v,
            );
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
