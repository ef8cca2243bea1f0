//! The states of sort & shift: every value (axis, s_max, s_u, s_v, m, a, b) its model gives a
//! non-zero gradient, each with one gradient that produces it (its representative). The rest
//! of the pipeline sees a gradient only through this state (and the zero flag), so `rmapgen
//! prove` drives the top once per state instead of once per gradient
//! (docs/VERIFICATION.md, "Every input").
//!
//! The enumeration is derived from the model, and nothing here has to be right for the proof
//! to hold: each representative is run through the model's sort & shift and must give its
//! state ([`enumerate`] fails otherwise), and the front part checks, for every gradient, that
//! the model's state of that gradient is in the set ([`StateSet::contains`]). A state missed
//! here fails the proof; it cannot be skipped.

use crate::config::Config;
use crate::model::sort_shift::{self, SortShift};
use anyhow::{bail, ensure, Result};

/// The widest reduced magnitude `rmapgen prove` takes: the set keeps one bit per possible
/// state, 24 · 2^(3R − 1) bits (200 MB at R = 9).
pub const MAX_RED_BITS: u32 = 9;

/// Every possible state as one bit: (axis, three signs, m with its MSB set, a, b).
pub struct StateSet {
    red_bits: u32,
    bits: Vec<u64>,
    count: u64,
}

impl StateSet {
    pub(super) fn new(cfg: &Config) -> Result<StateSet> {
        ensure!(
            cfg.red_bits <= MAX_RED_BITS,
            "rmapgen prove keeps one bit per sort & shift state (24 x 2^(3 red_bits - 1)); red_bits = {} is above {MAX_RED_BITS}",
            cfg.red_bits
        );
        let n = 24u64 << (3 * cfg.red_bits - 1);
        Ok(StateSet {
            red_bits: cfg.red_bits,
            bits: vec![0; n.div_ceil(64) as usize],
            count: 0,
        })
    }

    /// The state's bit, or None for a value outside the key space (an axis above 2 or an m
    /// without its MSB: no non-zero gradient's state, so not in the set).
    #[inline]
    fn index(&self, s: &SortShift) -> Option<u64> {
        let r = self.red_bits;
        let top = 1u32 << (r - 1);
        if s.axis > 2 || s.m < top || s.m >= 2 * top || s.a >= 2 * top || s.b >= 2 * top {
            return None;
        }
        let head = (s.axis * 8 + s.s_max * 4 + s.s_u * 2 + s.s_v) as u64;
        let hm = (head << (r - 1)) | (s.m - top) as u64;
        Some((hm << (2 * r)) | ((s.a as u64) << r) | s.b as u64)
    }

    #[inline]
    pub fn contains(&self, s: &SortShift) -> bool {
        self.index(s)
            .is_some_and(|i| self.bits[(i / 64) as usize] >> (i % 64) & 1 == 1)
    }

    /// Adds the state; false if it was there. (Written with an explicit test and branch:
    /// the earlier branch-free form, `count += new as u64` after a combined read and write
    /// of the word, was compiled by rustc 1.95 at opt-level 2 and 3 without overflow checks
    /// into code that never counted, so the release build visited every state with ordinal
    /// u64::MAX and the states part drove nothing: docs/VERIFICATION.md, "The false proof".)
    fn insert(&mut self, i: u64) -> bool {
        let (word, bit) = ((i / 64) as usize, 1u64 << (i % 64));
        if self.bits[word] & bit != 0 {
            return false;
        }
        self.bits[word] |= bit;
        self.count += 1;
        true
    }

    /// The number of states.
    pub fn len(&self) -> u64 {
        self.count
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// Values of one reduced magnitude over a run of equal reductions: a magnitude that gives it
/// as a positive component (below 2^(G−1)) and one that gives it as a negative component (at
/// least 1), where they exist.
struct Run {
    a: u32,
    pos: Option<u32>,
    neg: Option<u32>,
}

/// The reduced values of a component c in 0..=lim beside the max magnitude `max`, from the
/// model (component u of a gradient whose max is x).
fn runs(cfg: &Config, max: u32, lim: u32) -> Vec<Run> {
    let half = 1u32 << (cfg.grad_bits - 1);
    let mut out: Vec<Run> = Vec::new();
    for c in 0..=lim {
        // Negative: -c is a valid component for every c up to 2^(G-1).
        let a = sort_shift::eval(cfg, [-(max as i32), -(c as i32), 0]).a;
        if out.last().map(|r| r.a) != Some(a) {
            out.push(Run {
                a,
                pos: None,
                neg: None,
            });
        }
        let r = out.last_mut().expect("pushed");
        if c < half && r.pos.is_none() {
            r.pos = Some(c);
        }
        if c >= 1 && r.neg.is_none() {
            r.neg = Some(c);
        }
    }
    out
}

/// What a run list offers the states: each reduced value with its sign choices.
type Sig = (u32, bool, bool);

fn signature(runs: &[Run]) -> Vec<Sig> {
    runs.iter()
        .map(|r| (r.a, r.pos.is_some(), r.neg.is_some()))
        .collect()
}

/// The signed values a run offers for a sign bit: (sign, value).
fn signed(r: &Run) -> impl Iterator<Item = (u32, i32)> + '_ {
    r.pos
        .map(|c| (0, c as i32))
        .into_iter()
        .chain(r.neg.map(|c| (1, -(c as i32))))
}

/// Visits a representative gradient of every state, in a fixed order, each state once, with
/// its ordinal (0, 1, ...); returns the set. Each representative is checked against the model.
pub fn enumerate(
    cfg: &Config,
    mut visit: impl FnMut(u64, [i32; 3]) -> Result<()>,
) -> Result<StateSet> {
    let mut set = StateSet::new(cfg)?;
    let half = 1u32 << (cfg.grad_bits - 1);
    let mut last: Option<(u32, Vec<Sig>, Vec<Sig>, usize)> = None;
    for max in 1..=half {
        // Ties go to the lowest axis: a component before the max's axis must be smaller.
        let m = sort_shift::eval(cfg, [-(max as i32), 0, 0]).m;
        let le = runs(cfg, max, max);
        let lt = runs(cfg, max, max - 1);
        let max_signs: &[(u32, i32)] = if max < half {
            &[(0, max as i32), (1, -(max as i32))]
        } else {
            &[(1, -(max as i32))]
        };
        // A max with the same m, sign choices and reduced values as the one before it gives
        // only states already visited: skipped (the front's check would find any state
        // this loses).
        let key = (m, signature(&le), signature(&lt), max_signs.len());
        if last.as_ref() == Some(&key) {
            continue;
        }
        last = Some(key);
        for axis in 0..3u32 {
            let (us, vs) = match axis {
                0 => (&le, &le),
                1 => (&lt, &le),
                _ => (&lt, &lt),
            };
            for &(s_max, gm) in max_signs {
                for u in us {
                    for (s_u, gu) in signed(u) {
                        for v in vs {
                            for (s_v, gv) in signed(v) {
                                let key = SortShift {
                                    axis,
                                    s_max,
                                    s_u,
                                    s_v,
                                    shift: 0,
                                    m,
                                    a: u.a,
                                    b: v.a,
                                };
                                let Some(i) = set.index(&key) else {
                                    bail!("state enumeration: {key:?} is outside the state space");
                                };
                                if !set.insert(i) {
                                    continue;
                                }
                                // A new state: its representative must give it.
                                let g = match axis {
                                    0 => [gm, gu, gv],
                                    1 => [gu, gm, gv],
                                    _ => [gu, gv, gm],
                                };
                                let s = sort_shift::eval(cfg, g);
                                if (SortShift { shift: 0, ..s }) != key {
                                    bail!("state enumeration: gradient {g:?} gives {s:?}, not {key:?}");
                                }
                                visit(set.count - 1, g)?;
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 8 bits every gradient is cheap: the set is exactly the model's image. On the
    /// narrowest row (R6) the shift truncates, so neighbouring magnitudes share their states;
    /// with nothing truncated (R = G = 8) every magnitude has states of its own, so a state
    /// lost at a tie (a component equal to the max) or added at the edge (a positive
    /// 2^(G-1), which no G-bit component is) shows.
    #[test]
    fn the_set_is_the_image_of_sort_shift() {
        for row in ["narrowest", "grad8_red8"] {
            is_the_image(&crate::grid::row(row).unwrap().config);
        }
    }

    fn is_the_image(cfg: &Config) {
        let cfg = cfg.clone();
        let mut reps = 0;
        let set = enumerate(&cfg, |ord, _| {
            // The ordinals count the states from 0, in order (the release build of
            // rmapgen 0.1.0 numbered them all u64::MAX: docs/VERIFICATION.md, "The false
            // proof").
            assert_eq!(ord, reps, "ordinal");
            reps += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(reps, set.len());
        let mut image = StateSet::new(&cfg).unwrap();
        let h = 1i32 << (cfg.grad_bits - 1);
        for x in -h..h {
            for y in -h..h {
                for z in -h..h {
                    if [x, y, z] != [0, 0, 0] {
                        let s = sort_shift::eval(&cfg, [x, y, z]);
                        assert!(set.contains(&s), "{:?} missing", [x, y, z]);
                        image.insert(image.index(&s).unwrap());
                    }
                }
            }
        }
        assert_eq!(image.len(), set.len(), "a state no gradient produces");
    }

    /// The runs of a component's reduced values, at the edge c = 2^(G-1) that only a negative
    /// component reaches: with nothing truncated (R = G) the magnitude 2^(G-1) is a run of its
    /// own, which offers a negative sign only. Each run offers the smallest magnitude of each
    /// sign it holds, so the representatives are the first gradients of their states.
    #[test]
    fn a_runs_signs_are_its_smallest_magnitudes_and_the_edge_is_negative_only() {
        let cfg = crate::grid::row("grad8_red8").unwrap().config;
        let half = 1u32 << (cfg.grad_bits - 1);
        for (max, lim) in [
            (half, half),
            (half, half - 1),
            (half - 1, half - 1),
            (37, 37),
        ] {
            let runs = runs(&cfg, max, lim);
            // Every magnitude, grouped by hand into its runs of equal reduced values.
            let a = |c: u32| sort_shift::eval(&cfg, [-(max as i32), -(c as i32), 0]).a;
            let mut groups: Vec<Vec<u32>> = Vec::new();
            for c in 0..=lim {
                match groups.last_mut() {
                    Some(g) if a(g[0]) == a(c) => g.push(c),
                    _ => groups.push(vec![c]),
                }
            }
            assert_eq!(runs.len(), groups.len(), "max {max} lim {lim}: runs");
            for (r, g) in runs.iter().zip(&groups) {
                assert_eq!(r.a, a(g[0]), "max {max}: the run's reduced value");
                let pos = g.iter().copied().find(|&c| c < half);
                let neg = g.iter().copied().find(|&c| c >= 1);
                assert_eq!((r.pos, r.neg), (pos, neg), "max {max}: the run of {g:?}");
            }
            if lim == half {
                let last = runs.last().unwrap();
                assert_eq!((last.pos, last.neg), (None, Some(half)), "the edge");
            }
        }
    }

    /// A state outside the key space (an axis above 2, an m without its top bit or wider than
    /// red_bits, an a or b wider than red_bits) has no index and is never in the set, even a
    /// full one: no non-zero gradient gives it.
    #[test]
    fn a_state_outside_the_key_space_has_no_index_and_is_not_in_the_set() {
        let cfg = crate::grid::row("narrowest").unwrap().config;
        let set = enumerate(&cfg, |_, _| Ok(())).unwrap();
        let r = cfg.red_bits;
        let top = 1u32 << (r - 1);
        let ok = SortShift {
            axis: 1,
            s_max: 0,
            s_u: 1,
            s_v: 0,
            shift: 0,
            m: top,
            a: 0,
            b: 1,
        };
        assert!(set.index(&ok).is_some() && set.contains(&ok));
        assert!(!set.is_empty() && StateSet::new(&cfg).unwrap().is_empty());
        for bad in [
            SortShift { axis: 3, ..ok },
            SortShift { m: top - 1, ..ok },
            SortShift { m: 2 * top, ..ok },
            SortShift { a: 2 * top, ..ok },
            SortShift { b: 2 * top, ..ok },
        ] {
            assert_eq!(set.index(&bad), None, "{bad:?}");
            assert!(!set.contains(&bad), "{bad:?}");
        }
    }
}
