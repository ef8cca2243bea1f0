//! A compensation table fitted to the scene (issue 33, the first lever): the position table
//! that the atan ROM holds today, chosen together with the maps so that the largest error
//! over every direction the pipeline can produce is as small as it can be made.
//!
//! **Why it helps.** The atan table spreads a quadrant's entries evenly over angle; a sharp
//! highlight needs them bunched where the intensity turns fastest. The table decides where
//! the entries sit (which tangents each position stands for), the maps decide their values.
//!
//! **What is searched.** One table shared by u and v of every face, as the ROM is today: for
//! each fraction code c a position t(c) in 0..=pos_max, **monotone** (t(c) <= t(c + 1)), so
//! every position stands for one contiguous range of tangents and the minimax fit's ranges
//! stay exact. The state of a sample is its quadrant and its code pair (c_u, c_v); the
//! pipeline shades it `interpolate(maps, t(c_u), t(c_v))`, and the light model over the
//! rectangle of tangents the pair stands for lies in [lo, hi] (sampled as in
//! [`super::minimax`], `light_over`). Its error is max(v - lo, hi - v).
//!
//! **How.** Rounds of two steps, starting from the atan table: (1) the maps by
//! [`MinimaxFit`] for the current table (position ranges from the code ranges, no tracing);
//! (2) the table by coordinate descent with the maps fixed: each code's position moves within
//! its neighbours' (and by at most [`RADIUS_STEPS`] interpolation steps) to the value that minimises the sum of (error / bound)^[`POWER`] over the states it reaches (a
//! smooth stand-in for the largest error, dominated by the states near it). The best
//! (table, maps) by the minimax bound is kept, so the fit is never worse than the atan
//! table's minimax maps.

use super::minimax::{entries_value, FitReport, MinimaxFit, TracePlan};
use super::{light, light_over, unpack, widen};
use crate::config::Config;
use crate::model::{Maps, Model};
use crate::stages::map_lookup::model::split;
use glam::DVec3;
use rayon::prelude::*;

/// Rounds of (maps, table) after the first maps.
pub const ROUNDS: usize = 6;
/// Coordinate-descent sweeps over the table per round (fewer when nothing moves).
pub const SWEEPS: usize = 3;
/// The exponent of the descent's objective.
pub const POWER: i32 = 12;
/// How far a position may move in one step, in interpolation steps (2^interp_bits positions).
pub const RADIUS_STEPS: u32 = 1;

/// The per-configuration part: the tangent range of every fraction code.
#[derive(Clone, Debug)]
pub struct TableFit {
    cfg: Config,
    /// For each fraction code: the smallest and largest tangent (component / max) that the
    /// pipeline's sort and normalise stages give it, or None when no gradient reaches it.
    range: Vec<Option<(f64, f64)>>,
    /// The reachable codes, ascending.
    codes: Vec<usize>,
}

/// What one frame's table fit did.
#[derive(Clone, Debug, PartialEq)]
pub struct TableFitReport {
    /// The minimax bound (output LSBs) of the atan table with its minimax maps.
    pub atan_bound: f64,
    /// The minimax bound of the fitted table with its maps.
    pub bound: f64,
    /// Table entries that differ from the atan table.
    pub changed: usize,
}

/// The light model's range over every state of one quadrant: [c_u * codes + c_v] -> (lo, hi).
struct Quadrant {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl TableFit {
    /// The code ranges of `cfg` (compensation on), from the (max, component) pairs the
    /// minimax fit traces (every pair up to G = 12; the code does not depend on the table).
    pub fn new(cfg: &Config) -> TableFit {
        assert!(
            cfg.compensation,
            "a fitted table replaces the compensation table"
        );
        let model = Model::new(cfg);
        let blank = Maps::from_data(cfg, vec![0; 3 * cfg.map_entries() as usize]);
        let n = cfg.frac_max() as usize + 1;
        let plan = TracePlan::new(cfg.grad_bits);
        let parts: Vec<Vec<Option<(f64, f64)>>> = plan
            .maxes
            .par_iter()
            .map(|&m| {
                crate::cancel::point();
                let mut r = vec![None; n];
                for c in plan.components(m) {
                    let u = model.trace(&blank, [m as i32, c as i32, 0], [0; 3]).norm.u;
                    let t = c as f64 / m as f64;
                    widen(&mut r[u as usize], (t, t));
                }
                r
            })
            .collect();
        let mut range = vec![None; n];
        for r in parts {
            for (acc, x) in range.iter_mut().zip(r) {
                if let Some(x) = x {
                    widen(acc, x);
                }
            }
        }
        let codes = (0..n).filter(|&c| range[c].is_some()).collect();
        TableFit {
            cfg: cfg.clone(),
            range,
            codes,
        }
    }

    /// The minimax maps for `table`: each position's range is the union of its codes'.
    pub fn maps(&self, table: &[u32], shade: &(impl Fn(DVec3) -> f64 + Sync)) -> (Maps, FitReport) {
        let mut pos: Vec<Option<(f64, f64)>> = vec![None; self.cfg.pos_max() as usize + 1];
        for &c in &self.codes {
            widen(
                &mut pos[table[c] as usize],
                self.range[c].expect("reachable"),
            );
        }
        MinimaxFit::with_ranges(&self.cfg, pos)
            .rms_slack(0.0)
            .fit_report(shade)
    }

    /// The fitted table and its maps for one frame.
    pub fn fit(&self, shade: impl Fn(DVec3) -> f64 + Sync) -> (Vec<u32>, Maps, TableFitReport) {
        let cfg = &self.cfg;
        let atan = crate::model::atan_rom::contents(cfg);
        let (maps, first) = self.maps(&atan, &shade);
        let quadrants = self.states(&shade);
        let mut best = (first.bound, atan.clone(), maps.clone());
        let (mut table, mut maps, mut bound) = (atan.clone(), maps, first.bound);
        for _ in 0..ROUNDS {
            let ents: Vec<Vec<u32>> = (0..24).map(|q| unpack(cfg, &maps, q)).collect();
            let mut moved = 0;
            for _ in 0..SWEEPS {
                let m = self.sweep(&quadrants, &mut table, &ents, bound.max(1.0));
                moved += m;
                if m == 0 {
                    break;
                }
            }
            if moved == 0 {
                break;
            }
            let (m, r) = self.maps(&table, &shade);
            (maps, bound) = (m, r.bound);
            if bound < best.0 {
                best = (bound, table.clone(), maps.clone());
            }
        }
        let (bound, mut table, maps) = best;
        // A code no gradient reaches keeps the position of the reachable code below it (0
        // below the first), so the whole table is monotone; the hardware never reads it.
        let mut last = 0;
        for (c, t) in table.iter_mut().enumerate() {
            if self.range[c].is_some() {
                last = *t;
            } else {
                *t = last;
            }
        }
        let changed = table.iter().zip(&atan).filter(|(a, b)| a != b).count();
        let report = TableFitReport {
            atan_bound: first.bound,
            bound,
            changed,
        };
        (table, maps, report)
    }

    /// The light model's range over every (quadrant, code pair) state.
    fn states(&self, shade: &(impl Fn(DVec3) -> f64 + Sync)) -> Vec<Quadrant> {
        let n = self.range.len();
        (0..24u32)
            .into_par_iter()
            .map(|q| {
                let light = light(&self.cfg, q, shade);
                let mut lo = vec![f64::NAN; n * n];
                let mut hi = vec![f64::NAN; n * n];
                for &cu in &self.codes {
                    crate::cancel::point();
                    let u = self.range[cu].expect("reachable");
                    for &cv in &self.codes {
                        let v = self.range[cv].expect("reachable");
                        let (l, h, _) = light_over(&light, u, v);
                        lo[cu * n + cv] = l;
                        hi[cu * n + cv] = h;
                    }
                }
                Quadrant { lo, hi }
            })
            .collect()
    }

    /// The hardware's value of quadrant entries `e` at positions (p_u, p_v).
    fn value(&self, e: &[u32], pu: u32, pv: u32) -> u32 {
        let ((bu, wu), (bv, wv)) = (split(&self.cfg, pu), split(&self.cfg, pv));
        entries_value(&self.cfg, e, (bu as usize, bv as usize), (wu, wv))
    }

    /// One sweep of coordinate descent over the table, maps fixed; returns the entries moved.
    fn sweep(
        &self,
        quadrants: &[Quadrant],
        table: &mut [u32],
        ents: &[Vec<u32>],
        scale: f64,
    ) -> usize {
        let n = self.range.len();
        let pmax = self.cfg.pos_max();
        let radius = RADIUS_STEPS * self.cfg.step().max(1);
        let mut moved = 0;
        for (i, &c) in self.codes.iter().enumerate() {
            crate::cancel::point();
            let cost = |pc: u32| -> f64 {
                let mut sum = 0.0;
                for (qd, e) in quadrants.iter().zip(ents) {
                    for &o in &self.codes {
                        let po = if o == c { pc } else { table[o] };
                        let k = c * n + o;
                        sum +=
                            (error(self.value(e, pc, po), qd.lo[k], qd.hi[k]) / scale).powi(POWER);
                        if o != c {
                            let k = o * n + c;
                            sum += (error(self.value(e, po, pc), qd.lo[k], qd.hi[k]) / scale)
                                .powi(POWER);
                        }
                    }
                }
                sum
            };
            let cur = table[c];
            let below = if i == 0 { 0 } else { table[self.codes[i - 1]] };
            let above = self.codes.get(i + 1).map_or(pmax, |&next| table[next]);
            let lo = cur.saturating_sub(radius).max(below);
            let hi = (cur + radius).min(above).min(pmax);
            // The lowest cost; among equal costs the position nearest the current one.
            let (_, best) = (lo..=hi)
                .into_par_iter()
                .map(|p| (cost(p), p))
                .min_by(|a, b| {
                    a.0.total_cmp(&b.0)
                        .then(a.1.abs_diff(cur).cmp(&b.1.abs_diff(cur)))
                        .then(a.1.cmp(&b.1))
                })
                .expect("lo <= cur <= hi");
            if best != cur {
                table[c] = best;
                moved += 1;
            }
        }
        moved
    }
}

fn error(v: u32, lo: f64, hi: f64) -> f64 {
    let v = v as f64;
    (v - lo).max(hi - v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// A G = 8 design (R = 6): every (max, component) pair traced in milliseconds.
    fn small() -> Config {
        let cfg = Config {
            grad_bits: 8,
            red_bits: 6,
            ..Config::default()
        };
        cfg.validate().unwrap();
        cfg
    }

    /// On a G = 8 design and the standard scene: the fitted table is monotone, within the
    /// positions, never worse than the atan table by the minimax bound and, on this sharp
    /// enough scene, better; and the model with the table and maps shades within that bound
    /// of the light model on every sphere pixel (plus 1 LSB: the bound samples each state's
    /// rectangle of directions, `light_over`).
    #[test]
    fn the_fitted_table_is_monotone_and_lowers_the_bound() {
        let cfg = small();
        let scene = Scene::standard();
        let p = scene.prepared();
        let fit = TableFit::new(&cfg);
        let (table, maps, r) = fit.fit(|n| p.shade(n));
        assert_eq!(table.len(), cfg.frac_max() as usize + 1);
        assert!(table.windows(2).all(|w| w[0] <= w[1]), "{table:?}");
        assert!(table.iter().all(|&t| t <= cfg.pos_max()));
        assert!(r.bound < r.atan_bound - 1.0, "{r:?}");
        let atan = crate::model::atan_rom::contents(&cfg);
        assert_eq!(
            r.changed,
            table.iter().zip(&atan).filter(|(a, b)| a != b).count()
        );
        assert!(r.changed > 0);
        // The fitted bits, recorded (a change to what the fit makes must be deliberate).
        assert_eq!(
            super::super::bits_digest(&[&table, &maps.data]),
            "6393e865dddec996fd9ee9fbb877c3c7fe9456e570babdc269dd001132aef529"
        );
        // The report is of the table and maps returned: the maps are the minimax maps of the
        // table, with that bound, and the atan bound is the atan table's.
        let (again, ra) = fit.maps(&table, &|n| p.shade(n));
        assert_eq!((again.data, ra.bound), (maps.data.clone(), r.bound));
        assert_eq!(fit.maps(&atan, &|n| p.shade(n)).1.bound, r.atan_bound);
        // A code no gradient reaches holds the position of the code below it (0 at code 0).
        let unreached: Vec<usize> = (0..table.len())
            .filter(|&c| fit.range[c].is_none())
            .collect();
        assert!(
            !unreached.is_empty() && unreached.len() < table.len() / 2,
            "{unreached:?}"
        );
        for c in unreached {
            assert_eq!(table[c], if c == 0 { 0 } else { table[c - 1] }, "code {c}");
        }
        let mut model = Model::new(&cfg);
        model.atan = Some(table);
        let (worst, at) = super::super::sphere_error(&model, &maps, &scene);
        assert!(
            worst <= r.bound + 1.0,
            "{at:?}: the model is {worst} from the light model, over the bound {}",
            r.bound
        );
    }

    /// One sweep of the descent on a G = 8 design under the sharp scene, with the maps fixed at
    /// the atan table's minimax maps: what the sweep tests start from.
    struct Descent {
        cfg: Config,
        fit: TableFit,
        atan: Vec<u32>,
        states: Vec<Quadrant>,
        ents: Vec<Vec<u32>>,
        scale: f64,
    }

    impl Descent {
        fn new() -> Self {
            let cfg = small();
            let p = super::super::sharp().prepared();
            let shade = |n: DVec3| p.shade(n);
            let fit = TableFit::new(&cfg);
            let atan = crate::model::atan_rom::contents(&cfg);
            let (maps, first) = fit.maps(&atan, &shade);
            let ents = (0..24).map(|q| unpack(&cfg, &maps, q)).collect();
            let states = fit.states(&shade);
            let scale = first.bound.max(1.0);
            Descent {
                cfg,
                fit,
                atan,
                states,
                ents,
                scale,
            }
        }

        /// One sweep from `table`: the table it leaves and the entries it moved.
        fn sweep(&self, table: &[u32]) -> (Vec<u32>, usize) {
            let mut table = table.to_vec();
            let moved = self
                .fit
                .sweep(&self.states, &mut table, &self.ents, self.scale);
            (table, moved)
        }
    }

    /// One sweep of the descent moves each reachable code's position by at most
    /// `RADIUS_STEPS` interpolation steps, keeps the table monotone, and counts what it moved
    /// (here at most 3 positions: the neighbours bound a move before the radius of 8 does).
    #[test]
    fn a_sweep_moves_each_position_at_most_the_radius_and_keeps_the_order() {
        let d = Descent::new();
        let (table, moved) = d.sweep(&d.atan);
        let radius = RADIUS_STEPS * d.cfg.step();
        let steps: Vec<u32> = d
            .fit
            .codes
            .iter()
            .map(|&c| table[c].abs_diff(d.atan[c]))
            .collect();
        assert_eq!(moved, steps.iter().filter(|&&d| d > 0).count());
        assert!(steps.iter().all(|&d| d <= radius), "{steps:?}");
        assert!(steps.iter().any(|&d| d > 1), "{steps:?}");
        let reached: Vec<u32> = d.fit.codes.iter().map(|&c| table[c]).collect();
        assert!(reached.windows(2).all(|w| w[0] <= w[1]), "{reached:?}");
    }

    /// The radius binds, down and up. From the atan table shifted four interpolation steps up
    /// (clamped at the last position), one sweep moves the reachable codes back down, each by
    /// at most the radius, and most of them (the lowest first: their neighbours below moved
    /// first) by exactly the radius; near the top, where the shift was clamped, by less. From
    /// the atan table with its lower half of codes collapsed to position 0, the highest of
    /// them moves up by exactly the radius (the next code holds each of the others at 0).
    #[test]
    fn a_sweep_from_a_shifted_table_moves_by_the_radius_and_no_more() {
        let d = Descent::new();
        let (codes, atan) = (&d.fit.codes, &d.atan);
        let radius = RADIUS_STEPS * d.cfg.step();
        let shifted: Vec<u32> = atan
            .iter()
            .map(|&t| (t + 4 * radius).min(d.cfg.pos_max()))
            .collect();
        let (table, _) = d.sweep(&shifted);
        let down: Vec<i64> = codes
            .iter()
            .map(|&c| shifted[c] as i64 - table[c] as i64)
            .collect();
        assert!(
            down.iter().all(|&d| (0..=radius as i64).contains(&d)),
            "{down:?}"
        );
        assert!(down[..4].iter().all(|&d| d == radius as i64), "{down:?}");
        let whole = down.iter().filter(|&&d| d == radius as i64).count();
        assert!(2 * whole > down.len(), "{down:?}");

        let half = codes.len() / 2;
        let mut collapsed = atan.clone();
        for &c in &codes[..half] {
            collapsed[c] = 0;
        }
        let (table, _) = d.sweep(&collapsed);
        let up: Vec<u32> = codes[..half].iter().map(|&c| table[c]).collect();
        let mut expected = vec![0; half];
        expected[half - 1] = radius;
        assert_eq!(up, expected);
        assert!(atan[codes[half - 1]] > 2 * radius);
    }
}
