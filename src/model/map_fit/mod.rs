//! Map entries fitted to the light model: instead of sampling the light model at each entry's
//! direction ([`reflectance_map::contents`], the paper's map), choose the entries whose
//! interpolated values best match the light model over a dense grid of directions, then round
//! and clamp them. The result is an ordinary [`Maps`]: it loads into the same RTL and the same
//! model unchanged.
//!
//! Each quadrant of a cube face (max axis, its sign and the signs of u and v) is an independent
//! N x N grid of entries (N = 2^index_bits). Its dense grid has K = (N - 1) Q + 1 tangents per
//! component (Q = [`SAMPLES_PER_ENTRY`] per entry spacing, at the encoded tangents of evenly
//! spaced positions), so K^2 directions per quadrant, none of them a test image's. The model's
//! value at a direction is linear in the entries. Its weights are measured through the
//! pipeline: for each dense tangent, the position the model computes for a component of that
//! tangent under [`PIPELINE_MAXES`] largest magnitudes spread over the top magnitude class
//! (every other class shades as a subset of it), and the bilinear (or nearest-entry) weights of
//! those positions, averaged. So the fit sees the pipeline's rounding and truncation of
//! directions, not ideal positions.
//!
//! 1. **Least squares** with uniform weights: the basis is a tensor product, so the normal
//!    matrix is A (x) A for the N x N matrix A = P^T P of one component (P: K x N), and the
//!    solution is E = A^-1 P^T F P A^-1 for the K x K light-model values F. A^-1 and P depend
//!    only on the configuration ([`LsqFit::new`], once); a frame costs K^2 light-model
//!    evaluations and small matrix products per quadrant ([`LsqFit::fit`]).
//! 2. **Peak refinement**: in a quadrant whose fit misses some dense sample by more than
//!    [`REFINE_TAU`] LSB (a highlight narrower than the entry spacing), the samples are
//!    reweighted by 1 + (|residual| / tau)^[`REFINE_POWER`] and the full N^2 x N^2 weighted
//!    problem is solved again, [`REFINE_ITERATIONS`] times (iteratively reweighted least
//!    squares towards the minimax fit). This trades a little RMS error for a lower maximum at
//!    highlights; quadrants without a sharp feature skip it, and a refinement is kept only if
//!    it lowers the quadrant's worst residual at a cost of at most [`REFINE_RMS_GROWTH`] times
//!    its RMS residual (with few entries it can trade badly). It is off without interpolation,
//!    where it was measured to raise the maximum. [`MapFit::LsqPlain`] leaves it out.

pub mod minimax;
pub mod table_fit;

use super::{reflectance_map, Maps};
use crate::config::Config;
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the host fills the maps.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum MapFit {
    /// The light model at each entry's direction (the paper).
    #[default]
    Sample,
    /// Least squares over a dense grid of directions with peak refinement, then rounded.
    Lsq,
    /// Least squares over a dense grid of directions with uniform weights, then rounded.
    LsqPlain,
    /// The smallest largest error over every direction the pipeline can produce: a linear
    /// program per face quadrant, then integer entries polished on the hardware's rounding
    /// ([`minimax`]).
    Minimax,
    /// The compensation table and the minimax maps fitted together to the scene, so that the
    /// entries bunch where the intensity turns fastest ([`table_fit`]); the table is loaded
    /// with the maps, so the design needs `comp_table = ram`.
    Table,
}

impl MapFit {
    pub fn name(self) -> &'static str {
        match self {
            MapFit::Sample => "sample",
            MapFit::Lsq => "lsq",
            MapFit::LsqPlain => "lsq-plain",
            MapFit::Minimax => "minimax",
            MapFit::Table => "table",
        }
    }

    /// Whether `cfg` can hold what this fit makes: `table` needs a table the host loads.
    pub fn check(self, cfg: &Config) -> anyhow::Result<()> {
        if self == MapFit::Table && cfg.comp_table.is_rom() {
            anyhow::bail!(
                "map_fit table fits the compensation table, which this design holds in a ROM; generate it with --comp-table ram (comp_table = \"ram\"), or use another map_fit"
            );
        }
        Ok(())
    }
}

/// Dense samples per entry spacing along each component.
pub const SAMPLES_PER_ENTRY: u32 = 4;
/// Largest magnitudes at which the basis weights are measured through the pipeline.
pub const PIPELINE_MAXES: u32 = 16;
/// Residual (output LSBs) above which a quadrant is refined.
pub const REFINE_TAU: f64 = 4.0;
/// Exponent of the refinement's reweighting.
pub const REFINE_POWER: i32 = 2;
/// Largest growth of a quadrant's RMS residual that a refinement may cost.
pub const REFINE_RMS_GROWTH: f64 = 1.5;
/// Reweighted solves of a refined quadrant.
pub const REFINE_ITERATIONS: u32 = 4;

/// The maps for a light model given as a function of the unit normal, filled as `fit` says:
/// used by the model, the hex writer and every command.
pub fn contents(cfg: &Config, fit: MapFit, shade: impl Fn(DVec3) -> f64 + Sync) -> Maps {
    match fit {
        MapFit::Sample => reflectance_map::contents(cfg, shade),
        MapFit::Lsq => LsqFit::new(cfg).fit(shade),
        MapFit::LsqPlain => LsqFit::plain(cfg).fit(shade),
        MapFit::Minimax => minimax::MinimaxFit::new(cfg).fit(shade),
        MapFit::Table => {
            MapFit::Table
                .check(cfg)
                .expect("map_fit table is checked against the configuration first");
            let (table, maps, _) = table_fit::TableFit::new(cfg).fit(shade);
            maps.with_table(cfg, table)
                .expect("a fitted table is a table of the configuration")
        }
    }
}

/// The per-configuration part of the least-squares fit.
#[derive(Clone, Debug)]
pub struct LsqFit {
    cfg: Config,
    n: usize,
    /// For each dense sample along one component: its tangent, and its basis weights as
    /// (entry, weight) pairs.
    tangent: Vec<f64>,
    basis: Vec<Vec<(usize, f64)>>,
    /// A^-1, n x n row-major.
    a_inv: Vec<f64>,
    /// Reweighted solves of a quadrant that misses by more than `refine_tau` (0: none).
    pub refine_iterations: u32,
    pub refine_tau: f64,
    pub refine_power: i32,
    /// Bandwidth of the quadrant's normal matrix in entry order i_u * n + i_v.
    band: usize,
}

impl LsqFit {
    /// Precomputes the dense grid and the inverse normal matrix of a configuration.
    pub fn new(cfg: &Config) -> LsqFit {
        LsqFit::with(cfg, SAMPLES_PER_ENTRY, PIPELINE_MAXES)
    }

    /// [`LsqFit::new`] without the peak refinement ([`MapFit::LsqPlain`]).
    pub fn plain(cfg: &Config) -> LsqFit {
        LsqFit {
            refine_iterations: 0,
            ..LsqFit::new(cfg)
        }
    }

    /// [`LsqFit::new`] with `q` samples per entry spacing, and the basis weights measured
    /// through the pipeline at `maxes` largest magnitudes (0: ideal positions).
    pub fn with(cfg: &Config, q: u32, maxes: u32) -> LsqFit {
        let n = cfg.entries() as usize;
        let k = (n - 1) * q as usize + 1;
        let model = super::Model::new(cfg);
        let blank = Maps::from_data(cfg, vec![0; 3 * cfg.map_entries() as usize]);
        let full = 1u32 << (cfg.grad_bits - 1);
        let mut tangent = Vec::with_capacity(k);
        let mut basis = Vec::with_capacity(k);
        let weights = |p: f64| -> Vec<(usize, f64)> {
            if cfg.interpolation {
                let x = p / cfg.step() as f64;
                let base = (x.floor() as usize).min(n - 2);
                let w = x - base as f64;
                vec![(base, 1.0 - w), (base + 1, w)]
            } else {
                vec![((p + 0.5).floor() as usize, 1.0)]
            }
        };
        for j in 0..k {
            crate::cancel::point();
            // Position in entry spacings, 0..=n-1.
            let x = j as f64 / q as f64;
            let t = tangent_at(cfg, x);
            tangent.push(t);
            let mut acc = vec![0.0; n];
            if maxes == 0 {
                for (i, w) in weights(x * cfg.step() as f64) {
                    acc[i] += w;
                }
            } else {
                for s in 0..maxes {
                    // Largest magnitudes spread over the top class (every other class shades
                    // as a subset of it), the component rounded to the nearest integer.
                    let max = full / 2 + ((2 * s + 1) * (full / 2)) / (2 * maxes);
                    let c = (t * max as f64).round() as i32;
                    let p = model.trace(&blank, [max as i32, c, 0], [0; 3]).p_u;
                    for (i, w) in weights(p as f64) {
                        acc[i] += w / maxes as f64;
                    }
                }
            }
            let nz: Vec<(usize, f64)> = acc
                .iter()
                .copied()
                .enumerate()
                .filter(|&(_, w)| w != 0.0)
                .collect();
            basis.push(nz);
        }
        let mut a = vec![0.0; n * n];
        for b in &basis {
            for &(i, wi) in b {
                for &(j, wj) in b {
                    a[i * n + j] += wi * wj;
                }
            }
        }
        // Entries a sample couples lie within `spread` of each other along a component.
        let spread = basis
            .iter()
            .map(|b| b.iter().map(|e| e.0).max().unwrap() - b.iter().map(|e| e.0).min().unwrap())
            .max()
            .unwrap_or(0);
        LsqFit {
            cfg: cfg.clone(),
            n,
            tangent,
            basis,
            a_inv: invert_spd(&a, n),
            band: spread * n + spread,
            refine_iterations: if cfg.interpolation {
                REFINE_ITERATIONS
            } else {
                0
            },
            refine_tau: REFINE_TAU,
            refine_power: REFINE_POWER,
        }
    }

    /// The fitted maps of one frame (the 24 quadrants in parallel).
    pub fn fit(&self, shade: impl Fn(DVec3) -> f64 + Sync) -> Maps {
        let cfg = &self.cfg;
        let n = self.n;
        let quadrants: Vec<Vec<f64>> = (0..24u32)
            .into_par_iter()
            .map(|q| self.fit_quadrant(q, &shade))
            .collect();
        let top = cfg.map_max() as f64;
        let rounded: Vec<Vec<u32>> = quadrants
            .iter()
            .map(|e| {
                e.iter()
                    .map(|&v| {
                        if v.is_nan() {
                            0
                        } else {
                            (v + 0.5).floor().clamp(0.0, top) as u32
                        }
                    })
                    .collect()
            })
            .collect();
        debug_assert!(rounded.iter().all(|e| e.len() == n * n));
        pack(cfg, &rounded)
    }

    /// The unrounded entries of quadrant q = axis << 3 | s_max << 2 | s_u << 1 | s_v.
    fn fit_quadrant(&self, q: u32, shade: &impl Fn(DVec3) -> f64) -> Vec<f64> {
        let f = self.dense(q, shade);
        let mut e = vec![0.0; self.n * self.n];
        self.solve_uniform(&f, &mut e);
        let (max, rms) = self.residuals(&f, &e);
        if self.refine_iterations > 0 && max > self.refine_tau {
            let mut r = e.clone();
            self.refine(&f, &mut r);
            // Keep the refinement only where it lowers the worst residual without giving up
            // much RMS (it can trade badly when entries are few for the feature).
            let (max_r, rms_r) = self.residuals(&f, &r);
            if max_r < max && rms_r <= REFINE_RMS_GROWTH * rms {
                e = r;
            }
        }
        e
    }

    /// The light model of quadrant q on the dense grid (sample ju * K + jv at tangents
    /// (tangent[ju], tangent[jv])).
    fn dense(&self, q: u32, shade: &impl Fn(DVec3) -> f64) -> Vec<f64> {
        let light = light(&self.cfg, q, shade);
        let mut f = Vec::with_capacity(self.tangent.len().pow(2));
        for &tu in &self.tangent {
            crate::cancel::point();
            for &tv in &self.tangent {
                f.push(light(tu, tv));
            }
        }
        f
    }

    /// E = A^-1 P^T F P A^-1.
    fn solve_uniform(&self, f: &[f64], e: &mut [f64]) {
        let (n, k) = (self.n, self.tangent.len());
        // pf = P^T F (n x k), then b = pf P (n x n).
        let mut pf = vec![0.0; n * k];
        for (ju, bu) in self.basis.iter().enumerate() {
            for &(i, w) in bu {
                for (acc, &v) in pf[i * k..(i + 1) * k]
                    .iter_mut()
                    .zip(&f[ju * k..(ju + 1) * k])
                {
                    *acc += w * v;
                }
            }
        }
        let mut b = vec![0.0; n * n];
        for i in 0..n {
            for (jv, bv) in self.basis.iter().enumerate() {
                let v = pf[i * k + jv];
                for &(j, w) in bv {
                    b[i * n + j] += w * v;
                }
            }
        }
        let mut tmp = vec![0.0; n * n];
        matmul(&self.a_inv, &b, &mut tmp, n);
        matmul(&tmp, &self.a_inv, e, n);
    }

    /// The fitted value at dense sample (ju, jv).
    fn predict(&self, e: &[f64], ju: usize, jv: usize) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for &(i, wi) in &self.basis[ju] {
            for &(j, wj) in &self.basis[jv] {
                s += wi * wj * e[i * n + j];
            }
        }
        s
    }

    /// The largest and the RMS residual over the dense grid.
    fn residuals(&self, f: &[f64], e: &[f64]) -> (f64, f64) {
        let k = self.tangent.len();
        let (mut m, mut sq): (f64, f64) = (0.0, 0.0);
        for ju in 0..k {
            for jv in 0..k {
                let r = self.predict(e, ju, jv) - f[ju * k + jv];
                m = m.max(r.abs());
                sq += r * r;
            }
        }
        (m, (sq / (k * k) as f64).sqrt())
    }

    /// Reweighted least squares over the whole quadrant (n^2 unknowns), from the fit in `e`.
    fn refine(&self, f: &[f64], e: &mut [f64]) {
        let (n, k) = (self.n, self.tangent.len());
        let nn = n * n;
        let mut w = vec![1.0; k * k];
        let mut a = vec![0.0; nn * nn];
        let mut b = vec![0.0; nn];
        let mut phi: Vec<(usize, f64)> = Vec::new();
        for _ in 0..self.refine_iterations {
            for ju in 0..k {
                for jv in 0..k {
                    let r = (self.predict(e, ju, jv) - f[ju * k + jv]).abs();
                    w[ju * k + jv] *= 1.0 + (r / self.refine_tau).powi(self.refine_power);
                }
            }
            a.iter_mut().for_each(|x| *x = 0.0);
            b.iter_mut().for_each(|x| *x = 0.0);
            for ju in 0..k {
                crate::cancel::point();
                for jv in 0..k {
                    let wk = w[ju * k + jv];
                    phi.clear();
                    for &(i, wi) in &self.basis[ju] {
                        for &(j, wj) in &self.basis[jv] {
                            phi.push((i * n + j, wi * wj));
                        }
                    }
                    for &(p, x) in &phi {
                        b[p] += wk * x * f[ju * k + jv];
                        // The lower triangle is all the factorisation reads.
                        for &(q, y) in &phi {
                            if q <= p {
                                a[p * nn + q] += wk * x * y;
                            }
                        }
                    }
                }
            }
            cholesky_solve(&mut a, &mut b, nn, self.band);
            e.copy_from_slice(&b);
        }
    }
}

/// The face, max sign and component signs of quadrant q = axis << 3 | s_max << 2 | s_u << 1
/// | s_v (24 in all).
fn quadrant(q: u32) -> (u32, u32, u32, u32) {
    (q >> 3, (q >> 2) & 1, (q >> 1) & 1, q & 1)
}

/// The largest tangent spacing between the points at which `light_over` samples the light
/// model over a position's range of tangents. Most of an interpolating design's positions are
/// narrower than two spacings and are sampled at their ends and middle (the default shape's
/// widest, 2.5 spacings, at 4 points); a wide one (nearest entry, few index bits) at more
/// points, so that a highlight inside it is not missed.
pub const LIGHT_SPACING: f64 = 1.0 / 64.0;

/// The light model of quadrant q at tangents (t_u, t_v), in output LSBs, clamped as the
/// reference clamps it (a NaN, a direction the light model does not define, is 0).
fn light<'a>(
    cfg: &Config,
    q: u32,
    shade: &'a impl Fn(DVec3) -> f64,
) -> impl Fn(f64, f64) -> f64 + 'a {
    let top = cfg.map_max() as f64;
    let (axis, s_max, s_u, s_v) = quadrant(q);
    let sg = |s: u32, t: f64| if s == 1 { -t } else { t };
    move |tu, tv| {
        let [x, y, z] = crate::geometry::place(axis, sg(s_max, 1.0), sg(s_u, tu), sg(s_v, tv));
        let i = shade(crate::geometry::sym_normalize(DVec3::new(x, y, z)));
        if i.is_nan() {
            0.0
        } else {
            i.clamp(0.0, 1.0) * top
        }
    }
}

/// The points at which the light model is sampled over tangents `lo..=hi`: both ends, evenly
/// spread, at most [`LIGHT_SPACING`] apart, and at least the middle between them.
fn light_points(lo: f64, hi: f64) -> impl Iterator<Item = f64> {
    let gaps = (((hi - lo) / LIGHT_SPACING).ceil() as usize).max(2);
    (0..=gaps).map(move |i| {
        let s = i as f64 / gaps as f64;
        lo * (1.0 - s) + hi * s
    })
}

/// The light model's smallest value, largest value and mean over the rectangle of tangents
/// `u` x `v` ([`light_points`] of each).
fn light_over(light: &impl Fn(f64, f64) -> f64, u: (f64, f64), v: (f64, f64)) -> (f64, f64, f64) {
    let (mut lo, mut hi, mut sum, mut count) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0);
    for tu in light_points(u.0, u.1) {
        for tv in light_points(v.0, v.1) {
            let i = light(tu, tv);
            lo = lo.min(i);
            hi = hi.max(i);
            sum += i;
            count += 1;
        }
    }
    (lo, hi, sum / count as f64)
}

/// Widens a range of tangents `acc` (None: empty) to hold `lo..=hi`.
fn widen(acc: &mut Option<(f64, f64)>, (lo, hi): (f64, f64)) {
    let e = acc.get_or_insert((lo, hi));
    e.0 = e.0.min(lo);
    e.1 = e.1.max(hi);
}

/// The maps holding the entries of the 24 quadrants (entry i_u * N + i_v of each).
fn pack(cfg: &Config, quadrants: &[Vec<u32>]) -> Maps {
    let n = cfg.entries();
    let mut data = vec![0u32; 3 * cfg.map_entries() as usize];
    for (q, e) in quadrants.iter().enumerate() {
        let (axis, s_max, s_u, s_v) = quadrant(q as u32);
        for i_u in 0..n {
            for i_v in 0..n {
                let a = crate::model::map_addr::addr(cfg, s_max, s_u, i_u, s_v, i_v);
                data[(axis * cfg.map_entries() + a) as usize] = e[(i_u * n + i_v) as usize];
            }
        }
    }
    Maps::from_data(cfg, data)
}

/// The entries of quadrant q of `maps` (entry i_u * N + i_v), as [`pack`] places them.
fn unpack(cfg: &Config, maps: &Maps, q: u32) -> Vec<u32> {
    let n = cfg.entries();
    let (axis, s_max, s_u, s_v) = quadrant(q);
    let mut e = Vec::with_capacity((n * n) as usize);
    for i_u in 0..n {
        for i_v in 0..n {
            e.push(maps.get(
                axis,
                crate::model::map_addr::addr(cfg, s_max, s_u, i_u, s_v, i_v),
            ));
        }
    }
    e
}

/// The tangent at a position of x entry spacings (0..=entries-1): the tangent the pipeline's
/// positions stand for, exactly 1 on the border.
fn tangent_at(cfg: &Config, x: f64) -> f64 {
    crate::geometry::face_tangent(cfg.compensation, x / (cfg.entries() - 1) as f64)
}

/// c = a b for n x n row-major matrices.
fn matmul(a: &[f64], b: &[f64], c: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = (0..n).map(|k| a[i * n + k] * b[k * n + j]).sum();
        }
    }
}

/// Solves a x = b in place (x in b) for a symmetric positive definite n x n matrix a whose
/// entries vanish more than `band` off the diagonal; only its lower triangle is read, and it is
/// overwritten by its Cholesky factor (which has the same band).
fn cholesky_solve(a: &mut [f64], b: &mut [f64], n: usize, band: usize) {
    for j in 0..n {
        let lo = j.saturating_sub(band);
        let mut d = a[j * n + j];
        for k in lo..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        assert!(d > 0.0, "weighted normal matrix not positive definite");
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..(j + band + 1).min(n) {
            let mut s = a[i * n + j];
            for k in i.saturating_sub(band)..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in i.saturating_sub(band)..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..(i + band + 1).min(n) {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
}

/// The inverse of a symmetric positive definite n x n matrix, by Cholesky factorisation.
fn invert_spd(a: &[f64], n: usize) -> Vec<f64> {
    // a = L L^T.
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = a[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            if i == j {
                assert!(s > 0.0, "normal matrix not positive definite");
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    // Solve L L^T x = e_c for every column c.
    let mut inv = vec![0.0; n * n];
    for c in 0..n {
        let mut y = vec![0.0; n];
        for i in 0..n {
            let e = if i == c { 1.0 } else { 0.0 };
            y[i] = (e - (0..i).map(|k| l[i * n + k] * y[k]).sum::<f64>()) / l[i * n + i];
        }
        for i in (0..n).rev() {
            let s = y[i]
                - (i + 1..n)
                    .map(|k| l[k * n + i] * inv[k * n + c])
                    .sum::<f64>();
            inv[i * n + c] = s / l[i * n + i];
        }
    }
    inv
}

/// The SHA-256 of lists of entries (each entry as 4 little-endian bytes, each list
/// prefixed by its length): the fitted bits that the tests record, so that a change to what
/// a fit makes is deliberate.
#[cfg(test)]
fn bits_digest(parts: &[&[u32]]) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for p in parts {
        h.update((p.len() as u64).to_le_bytes());
        p.iter().for_each(|v| h.update(v.to_le_bytes()));
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The standard scene with a sharp highlight (shininess 120): the scene the fits' tests use,
/// which the uniform fit misses by far more than `REFINE_TAU` at the default shape.
#[cfg(test)]
fn sharp() -> crate::scene::Scene {
    let mut scene = crate::scene::Scene::standard();
    scene.material.shininess = 120.0;
    scene
}

/// The model's largest difference, in output LSBs, from the float light model of `scene`
/// (clamped as the reference clamps it) over the pixels of a 128-pixel sphere, and the
/// gradient where it is: what a fit's reported bound is checked against.
#[cfg(test)]
fn sphere_error(
    model: &crate::model::Model,
    maps: &Maps,
    scene: &crate::scene::Scene,
) -> (f64, [i32; 3]) {
    let cfg = &model.cfg;
    let reference = crate::reference::Reference::new(cfg, scene);
    let mut worst = (0.0, [0; 3]);
    for (_, _, g) in crate::render::sphere_gradients(cfg, 128, 0) {
        let m = model.intensity(maps, g) as f64;
        let exact = reference.exact(g).unwrap().clamp(0.0, 1.0) * cfg.map_max() as f64;
        if (m - exact).abs() > worst.0 {
            worst = ((m - exact).abs(), g);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_4;

    #[test]
    fn inverse_is_an_inverse() {
        let cfg = Config::default();
        let fit = LsqFit::new(&cfg);
        let n = fit.n;
        let mut a = vec![0.0; n * n];
        for b in &fit.basis {
            for &(i, wi) in b {
                for &(j, wj) in b {
                    a[i * n + j] += wi * wj;
                }
            }
        }
        let mut id = vec![0.0; n * n];
        matmul(&a, &fit.a_inv, &mut id, n);
        for i in 0..n {
            for j in 0..n {
                assert!(
                    (id[i * n + j] - (i == j) as u8 as f64).abs() < 1e-12,
                    "{i} {j}"
                );
            }
        }
    }

    /// A light model that is itself bilinear in the positions is reproduced exactly, entry for
    /// entry, by both fits.
    #[test]
    fn reproduces_a_bilinear_light_model() {
        for cfg in [
            Config::default(),
            Config {
                index_bits: 4,
                interp_bits: 2,
                ..Config::default()
            },
        ] {
            // Ideal positions, so that the fitted model is exactly bilinear in them.
            let fit = LsqFit::with(&cfg, SAMPLES_PER_ENTRY, 0);
            // The light model as a function of the direction: 0.2 + 0.5 * (x_u) * (x_v) / (n-1)^2
            // in entry spacings of the two tangents, on every face.
            let n1 = (cfg.entries() - 1) as f64;
            let pos = |t: f64| t.abs().atan() / FRAC_PI_4 * n1;
            let shade = |d: DVec3| {
                let a = d.abs();
                let (m, u, v) = if a.x >= a.y && a.x >= a.z {
                    (a.x, a.y, a.z)
                } else if a.y >= a.z {
                    (a.y, a.x, a.z)
                } else {
                    (a.z, a.x, a.y)
                };
                0.2 + 0.5 * pos(u / m) * pos(v / m) / (n1 * n1)
            };
            let fitted = fit.fit(shade);
            let sampled = reflectance_map::contents(&cfg, shade);
            let diff = fitted
                .data
                .iter()
                .zip(&sampled.data)
                .filter(|(a, b)| a.abs_diff(**b) > 1)
                .count();
            assert_eq!(diff, 0, "{}", cfg.summary());
        }
    }

    /// Basis weights measured through the pipeline sum to 1, so a constant light model gives
    /// that constant everywhere, in every configuration shape.
    #[test]
    fn constant_light_model_gives_constant_maps() {
        for cfg in [
            Config::default(),
            Config {
                compensation: false,
                ..Config::default()
            },
            Config {
                interpolation: false,
                interp_bits: 0,
                ..Config::default()
            },
            Config {
                index_bits: 2,
                interp_bits: 1,
                map_bits: 10,
                ..Config::default()
            },
        ] {
            let maps = contents(&cfg, MapFit::Lsq, |_| 0.4);
            let want = reflectance_map::quantise(&cfg, 0.4);
            assert!(maps.data.iter().all(|&e| e == want), "{}", cfg.summary());
        }
    }

    /// Each dense sample's basis weights along a component are a partition of unity (positive,
    /// summing to 1), the tangents rise from 0 to exactly 1, and the band of the quadrant's
    /// normal matrix holds every pair of entries a sample couples, in every shape tested here
    /// (the refinement's banded solve reads nothing outside it).
    #[test]
    fn the_basis_is_a_partition_of_unity_within_the_band() {
        for cfg in [
            Config::default(),
            Config {
                index_bits: 2,
                ..Config::default()
            },
            Config {
                index_bits: 4,
                interp_bits: 2,
                ..Config::default()
            },
            Config {
                interpolation: false,
                interp_bits: 0,
                ..Config::default()
            },
        ] {
            for maxes in [0, PIPELINE_MAXES] {
                let fit = LsqFit::with(&cfg, SAMPLES_PER_ENTRY, maxes);
                let what = format!("{} at {maxes} maxes", cfg.summary());
                let (n, k) = (fit.n, fit.tangent.len());
                assert_eq!(k, (n - 1) * SAMPLES_PER_ENTRY as usize + 1, "{what}");
                assert_eq!((fit.tangent[0], fit.tangent[k - 1]), (0.0, 1.0), "{what}");
                assert!(fit.tangent.windows(2).all(|w| w[0] < w[1]), "{what}");
                for b in &fit.basis {
                    assert!(b.iter().all(|&(i, w)| i < n && w > 0.0), "{what}: {b:?}");
                    let sum: f64 = b.iter().map(|e| e.1).sum();
                    assert!((sum - 1.0).abs() < 1e-12, "{what}: {b:?}");
                }
                for bu in &fit.basis {
                    for bv in &fit.basis {
                        let entries: Vec<usize> = bu
                            .iter()
                            .flat_map(|&(i, _)| bv.iter().map(move |&(j, _)| i * n + j))
                            .collect();
                        let (lo, hi) = (entries.iter().min(), entries.iter().max());
                        assert!(hi.unwrap() - lo.unwrap() <= fit.band, "{what}");
                    }
                }
            }
        }
    }

    /// The residuals are the largest and the root-mean-square difference over the dense grid.
    #[test]
    fn the_residuals_are_the_largest_and_the_rms_difference() {
        let fit = LsqFit::new(&Config::default());
        let k = fit.tangent.len();
        let e = vec![0.0; fit.n * fit.n];
        let mut f = vec![3.0; k * k];
        f[k + 2] = -7.0;
        let (max, rms) = fit.residuals(&f, &e);
        let want = ((9.0 * (k * k - 1) as f64 + 49.0) / (k * k) as f64).sqrt();
        assert_eq!(max, 7.0);
        assert!((rms - want).abs() < 1e-12, "{rms} {want}");
    }

    /// The light model's points over a range of tangents: both ends, evenly spread, at most
    /// `LIGHT_SPACING` apart; at least the ends and their exact middle, which is all a range of
    /// up to two spacings gets; and over a rectangle, the smallest, largest and mean value.
    #[test]
    fn a_range_is_sampled_at_its_ends_and_at_most_a_spacing_apart() {
        for (lo, hi) in [
            (0.0, 0.0),
            (0.25, 0.25 + LIGHT_SPACING),
            (0.1, 0.1 + 2.0 * LIGHT_SPACING),
            (0.5, 0.5 + 2.5 * LIGHT_SPACING),
            (0.0, 1.0),
            (0.3, 0.55),
        ] {
            let p: Vec<f64> = light_points(lo, hi).collect();
            let gaps = ((hi - lo) / LIGHT_SPACING).ceil().max(2.0) as usize;
            assert_eq!(p.len(), gaps + 1, "{lo}..{hi}");
            assert_eq!((p[0], p[gaps]), (lo, hi));
            if gaps == 2 {
                assert_eq!(p[1], (lo + hi) / 2.0);
            }
            for w in p.windows(2) {
                assert!(
                    w[0] <= w[1] && w[1] - w[0] <= LIGHT_SPACING + 1e-15,
                    "{lo}..{hi}: {w:?}"
                );
                assert!((w[1] - w[0] - (hi - lo) / gaps as f64).abs() < 1e-12);
            }
        }
        let (lo, hi, mean) = light_over(&|u, v| u + 10.0 * v, (0.0, 1.0), (0.5, 0.75));
        assert_eq!((lo, hi), (5.0, 8.5));
        assert!((mean - (0.5 + 10.0 * 0.625)).abs() < 1e-12, "{mean}");
    }

    /// A random symmetric positive definite n x n matrix, zero more than `band` off the
    /// diagonal (diagonally dominant).
    fn banded_spd(rng: &mut crate::rng::SplitMix64, n: usize, band: usize) -> Vec<f64> {
        let mut unit = || rng.next_u64() as f64 / u64::MAX as f64;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in i.saturating_sub(band)..i {
                let x = 2.0 * unit() - 1.0;
                (a[i * n + j], a[j * n + i]) = (x, x);
            }
        }
        for i in 0..n {
            let off: f64 = (0..n).filter(|&j| j != i).map(|j| a[i * n + j].abs()).sum();
            a[i * n + i] = off + 0.5 + unit();
        }
        a
    }

    /// The banded Cholesky solve: random banded systems (n up to 12, every band, and bands
    /// wider than the matrix) solved to 1e-9, reading only the lower triangle within the band
    /// (everything else is NaN here), and leaving the factor L (A = L L^T) in it.
    #[test]
    fn cholesky_solves_a_banded_system_from_its_lower_band() {
        let mut rng = crate::rng::SplitMix64::new(31);
        for n in 1..=12 {
            for band in (0..n).chain([n + 2]) {
                let a = banded_spd(&mut rng, n, band);
                let x: Vec<f64> = (0..n).map(|i| i as f64 - 3.5).collect();
                let mut b: Vec<f64> = (0..n)
                    .map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum())
                    .collect();
                let mut lower = a.clone();
                for i in 0..n {
                    for j in 0..n {
                        if j > i || i - j > band {
                            lower[i * n + j] = f64::NAN;
                        }
                    }
                }
                cholesky_solve(&mut lower, &mut b, n, band);
                for i in 0..n {
                    assert!((b[i] - x[i]).abs() < 1e-9, "n {n} band {band}: {b:?}");
                    for j in i.saturating_sub(band)..=i {
                        // L is zero more than `band` off its diagonal (NaN stored there).
                        let llt: f64 = (i.saturating_sub(band)..=j)
                            .map(|k| lower[i * n + k] * lower[j * n + k])
                            .sum();
                        assert!((llt - a[i * n + j]).abs() < 1e-9, "n {n} band {band}");
                    }
                }
            }
        }
    }

    /// Both factorisations refuse a matrix that is not positive definite (here singular:
    /// the last pivot is exactly 0).
    #[test]
    #[should_panic(expected = "weighted normal matrix not positive definite")]
    fn cholesky_refuses_a_singular_matrix() {
        cholesky_solve(&mut [1.0, 1.0, 1.0, 1.0], &mut [1.0, 1.0], 2, 1);
    }

    #[test]
    #[should_panic(expected = "normal matrix not positive definite")]
    fn the_inverse_refuses_a_singular_matrix() {
        invert_spd(&[4.0, 2.0, 2.0, 1.0], 2);
    }

    /// The inverse of random dense symmetric positive definite matrices (n up to 10), read
    /// from the lower triangle only (NaN above it), to 1e-9.
    #[test]
    fn the_inverse_of_a_random_matrix_is_its_inverse() {
        let mut rng = crate::rng::SplitMix64::new(7);
        for n in 1..=10 {
            let a = banded_spd(&mut rng, n, n);
            let mut lower = a.clone();
            for i in 0..n {
                for j in i + 1..n {
                    lower[i * n + j] = f64::NAN;
                }
            }
            let inv = invert_spd(&lower, n);
            let mut id = vec![0.0; n * n];
            matmul(&a, &inv, &mut id, n);
            for i in 0..n {
                for j in 0..n {
                    let want = (i == j) as u8 as f64;
                    assert!((id[i * n + j] - want).abs() < 1e-9, "n {n}: {i} {j}");
                }
            }
        }
    }

    /// The uniform fit of every quadrant: (q, light model on the dense grid, entries).
    fn uniform_fits(fit: &LsqFit, shade: &impl Fn(DVec3) -> f64) -> Vec<(u32, Vec<f64>, Vec<f64>)> {
        (0..24)
            .map(|q| {
                let f = fit.dense(q, shade);
                let mut e = vec![0.0; fit.n * fit.n];
                fit.solve_uniform(&f, &mut e);
                (q, f, e)
            })
            .collect()
    }

    /// The refinement is iteratively reweighted least squares. Under an infinite tau every
    /// weight is 1 and it is the uniform fit, reached by the other route (the full N^2 x N^2
    /// problem, banded Cholesky). Under the default tau, after 1, 2 and 3 iterations, its
    /// entries solve the weighted normal equations of the weights 1 + (|r| / tau)^p multiplied
    /// over the fits before each iteration, and each iteration moves them.
    #[test]
    fn the_refinement_solves_the_weighted_problem_of_its_residuals() {
        let cfg = Config::default();
        let scene = sharp();
        let p = scene.prepared();
        let shade = |d: DVec3| p.shade(d);
        let base = LsqFit::new(&cfg);
        let (n, k) = (base.n, base.tangent.len());
        let (_, f, e0) = uniform_fits(&base, &shade)
            .into_iter()
            .max_by(|a, b| {
                base.residuals(&a.1, &a.2)
                    .0
                    .total_cmp(&base.residuals(&b.1, &b.2).0)
            })
            .unwrap();
        assert!(base.residuals(&f, &e0).0 > 2.0 * REFINE_TAU);
        let flat = LsqFit {
            refine_tau: f64::INFINITY,
            refine_iterations: 2,
            ..base.clone()
        };
        let mut r = e0.clone();
        flat.refine(&f, &mut r);
        let far = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        assert!(far(&r, &e0) < 1e-9, "{}", far(&r, &e0));
        let mut w = vec![1.0; k * k];
        let mut prev = e0.clone();
        for iterations in 1..=3 {
            for ju in 0..k {
                for jv in 0..k {
                    let res = (base.predict(&prev, ju, jv) - f[ju * k + jv]).abs();
                    w[ju * k + jv] *= 1.0 + (res / REFINE_TAU).powi(REFINE_POWER);
                }
            }
            let fit = LsqFit {
                refine_iterations: iterations,
                ..base.clone()
            };
            let mut e = e0.clone();
            fit.refine(&f, &mut e);
            // The gradient of the weighted squared error, entry by entry, and its scale.
            let (mut grad, mut scale) = (vec![0.0; n * n], vec![0.0; n * n]);
            for ju in 0..k {
                for jv in 0..k {
                    let s = ju * k + jv;
                    let res = fit.predict(&e, ju, jv) - f[s];
                    for &(i, wi) in &base.basis[ju] {
                        for &(j, wj) in &base.basis[jv] {
                            grad[i * n + j] += w[s] * wi * wj * res;
                            scale[i * n + j] += w[s] * wi * wj * f[s].abs().max(1.0);
                        }
                    }
                }
            }
            for (g, s) in grad.iter().zip(&scale) {
                assert!(g.abs() <= 1e-9 * s, "{iterations} iterations: {g} of {s}");
            }
            assert!(far(&e, &prev) > 0.1, "{iterations} iterations");
            prev = e;
        }
    }

    /// A quadrant's entries are its uniform fit, refined only where that misses some dense
    /// sample by more than tau, and the refinement kept only where it lowers the worst
    /// residual at most `REFINE_RMS_GROWTH` times the RMS one. On the sharp scene all three
    /// cases occur; `LsqFit::plain` and a design without interpolation refine nothing.
    #[test]
    fn a_quadrant_keeps_its_refinement_only_where_it_pays() {
        let scene = sharp();
        let p = scene.prepared();
        let shade = |d: DVec3| p.shade(d);
        // Four entries a side: 15 quadrants miss by at most tau, 8 keep their refinement and
        // one gives it up (at the default shape the one quadrant that misses gives it up).
        let cfg = Config {
            index_bits: 2,
            ..Config::default()
        };
        cfg.validate().unwrap();
        let fit = LsqFit::new(&cfg);
        let mut cases = [0; 3];
        for (q, f, e) in uniform_fits(&fit, &shade) {
            let (max, rms) = fit.residuals(&f, &e);
            let mut r = e.clone();
            fit.refine(&f, &mut r);
            let (max_r, rms_r) = fit.residuals(&f, &r);
            let case = if max <= REFINE_TAU {
                0
            } else if max_r < max && rms_r <= REFINE_RMS_GROWTH * rms {
                1
            } else {
                2
            };
            cases[case] += 1;
            let want = if case == 1 { r } else { e };
            assert_eq!(fit.fit_quadrant(q, &shade), want, "quadrant {q}");
        }
        assert_eq!(cases, [15, 8, 1]);
        let plain = LsqFit::plain(&cfg);
        let nearest = Config {
            interpolation: false,
            interp_bits: 0,
            ..cfg.clone()
        };
        let nearest = LsqFit::new(&nearest);
        for fit in [plain, nearest] {
            assert_eq!(fit.refine_iterations, 0);
            for (q, _, e) in uniform_fits(&fit, &shade) {
                assert_eq!(fit.fit_quadrant(q, &shade), e, "quadrant {q}");
            }
        }
    }

    /// The fitted bits on the sharp scene, recorded (a change to what a fit makes must be
    /// deliberate): the least-squares fit with and without its refinement at the default shape
    /// (where the one quadrant that misses gives its refinement up) and at four entries a side
    /// (where eight keep it), and without interpolation.
    #[test]
    fn the_fitted_bits_are_recorded() {
        let scene = sharp();
        let p = scene.prepared();
        let four = Config {
            index_bits: 2,
            ..Config::default()
        };
        let nearest = Config {
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        };
        let mut digests = Vec::new();
        for cfg in [Config::default(), four, nearest] {
            for fit in [MapFit::Lsq, MapFit::LsqPlain] {
                let maps = contents(&cfg, fit, |d| p.shade(d));
                digests.push(bits_digest(&[&maps.data])[..16].to_string());
            }
        }
        // The first 64 bits of each SHA-256: lsq and lsq-plain, at each shape.
        assert_eq!(
            digests,
            [
                "2acf5e9740d44e63",
                "2acf5e9740d44e63",
                "8c2ff2ef8f439774",
                "a5158b67e9dd82ef",
                "cc920325d70f279c",
                "cc920325d70f279c"
            ]
        );
    }
}
