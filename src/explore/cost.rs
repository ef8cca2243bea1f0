//! What a render will cost, from its fields, before it runs: the explorer refuses a render
//! whose predicted work exceeds [`CORE_SECONDS`] or whose predicted memory exceeds [`BYTES`],
//! naming the fields that make it so ([`judge`]). What it admits still runs under the
//! runner's time and memory limits (`explore::LIMITS`), which cancel a render the model
//! underestimated.
//!
//! **Measured, not derived.** The expensive parts are the `minimax` and `table` map fits;
//! their core-seconds (CPU time over all threads) were measured over every index_bits and
//! interp_bits at the default configuration and the standard scene (`cargo run --release
//! --example explore_costs`, on the 2-core machine of docs/EXPLORE.md) and are the tables
//! [`MINIMAX`] and [`TABLE`]. The other fields scale them by factors measured the same way:
//! the lights ([`LIGHT_FACTOR`] per light beyond the first, per fit), map_bits above 8
//! ([`MAP_BITS_FACTOR`] per bit), grad_bits above 12 ([`GRAD_BITS_FACTOR`] per bit), and the
//! position pairs a fit covers (more fraction codes reach more positions). The table fit's
//! descent grows with the square of its fraction codes, and so does the memory of its states
//! (24 quadrants of 2^(2 frac_bits) ranges, 16 bytes each). `sample`, `lsq` and the renders
//! themselves cost well under a second at every size the page offers (measured the same way:
//! [`SPHERE_PIXEL`], [`VOLUME_PIXEL`], [`VOLUME_PREPARE`]).

use crate::config::Config;
use crate::model::map_fit::MapFit;
use crate::scene::Scene;
use anyhow::{bail, Result};

/// The most work a render may be predicted to take, in core-seconds: about 15 s of wall
/// time on the 2 cores of the machine measured.
pub const CORE_SECONDS: f64 = 30.0;
/// The most memory a render may be predicted to hold (bytes).
pub const BYTES: u64 = 1 << 30;

/// Stands for a fit stopped past the measurement's limit (120 s of wall time, at least 40
/// core-seconds), or one the configuration refuses before any cost is judged.
const OVER: f64 = f64::INFINITY;
/// The least a fit marked [`OVER`] takes, core-seconds.
pub const OVER_AT_LEAST: f64 = 40.0;

/// Core-seconds of the `minimax` fit, `[index_bits - 2][interp_bits]` (0: no interpolation),
/// at the default configuration otherwise and the standard scene: the larger of two
/// measurements, rounded up.
pub const MINIMAX: [[f64; 6]; 5] = [
    [0.11, 0.13, 0.16, 0.22, 0.40, 0.82],
    [0.17, 0.25, 0.36, 0.66, 1.2, 4.6],
    [0.39, 0.69, 1.8, 2.7, 4.2, 8.1],
    [1.6, 4.8, OVER, 27.0, 79.0, OVER],
    [8.8, OVER, OVER, OVER, OVER, OVER],
];

/// Core-seconds of the `table` fit (with `comp_table = ram`), as [`MINIMAX`].
pub const TABLE: [[f64; 6]; 5] = [
    [OVER, OVER, OVER, OVER, OVER, OVER],
    [3.9, 4.4, 8.8, 9.5, 14.0, 30.0],
    [3.1, 6.3, 12.0, 24.0, 36.0, OVER],
    [12.0, 22.0, OVER, OVER, OVER, OVER],
    [44.0, OVER, OVER, OVER, OVER, OVER],
];

/// The factor of each light beyond the first, per fit: 8 different lights took 2.1 times
/// one on `minimax`, 1.3 times on `table`.
pub const LIGHT_FACTOR: [(MapFit, f64); 2] = [(MapFit::Minimax, 0.16), (MapFit::Table, 0.05)];
/// The factor of each map bit above 8 (map_bits 12: from 1.1 to 2.9 times 8 in four
/// measurements).
pub const MAP_BITS_FACTOR: f64 = 1.2;
/// The added factor of each gradient bit above 12 (grad_bits 16: 0.9 to 1.9 times 12).
pub const GRAD_BITS_FACTOR: f64 = 0.15;
/// Core-seconds per sphere pixel (512², 8 lights: 0.06 core-seconds; 256², one: 0.02).
pub const SPHERE_PIXEL: f64 = 3e-7;
/// Core-seconds per volume pixel, the reference's frame included (512², 8 lights: 0.35).
pub const VOLUME_PIXEL: f64 = 2e-6;
/// Core-seconds of the engine block's build and its gradients for a new grad_bits (0.5).
pub const VOLUME_PREPARE: f64 = 0.6;
/// Bytes a render holds per pixel (its arrays and images), and per voxel of the volume (its
/// gradients and bricks).
pub const PIXEL_BYTES: f64 = 256.0;
pub const VOXEL_BYTES: f64 = 10.0;

/// A render's predicted cost.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Work in core-seconds ([`f64::INFINITY`]: past what was measured).
    pub core_seconds: f64,
    /// Memory held at once, in bytes.
    pub bytes: u64,
    /// The fields that decide it, as the refusal names them.
    pub fields: String,
}

/// The position pairs of a quadrant that gradients reach: every position of one component
/// that some fraction code reaches, squared.
fn pairs(cfg: &Config) -> f64 {
    let positions = (cfg.pos_max() as f64 + 1.0).min((cfg.frac_max() as f64) + 1.0);
    positions * positions
}

/// The cost of rendering `size`² of the sphere (or the volume) with `scene`'s fit.
pub fn estimate(cfg: &Config, scene: &Scene, size: u32, volume: bool) -> Estimate {
    let lights = scene.lights.len().max(1) as f64;
    let per_light = LIGHT_FACTOR
        .iter()
        .find(|f| f.0 == scene.map_fit)
        .map_or(0.0, |f| f.1);
    let light = 1.0 + per_light * (lights - 1.0);
    let map = MAP_BITS_FACTOR.powi(cfg.map_bits.saturating_sub(8) as i32);
    let grad = 1.0 + GRAD_BITS_FACTOR * cfg.grad_bits.saturating_sub(12) as f64;
    let (ib, ip) = (
        (cfg.index_bits - 2) as usize,
        (if cfg.interpolation {
            cfg.interp_bits
        } else {
            0
        }) as usize,
    );
    let measured = Config {
        frac_bits: Config::default().frac_bits,
        ..cfg.clone()
    };
    // More fraction codes reach more positions: more pairs to fit (fewer are not cheaper
    // by as much, and are not counted).
    let spread = (pairs(cfg) / pairs(&measured)).max(1.0);
    let scale = light * map * grad * spread;
    let threads = rayon::current_num_threads().max(1) as f64;
    // A pair of the minimax fit holds its range and its taps (about 200 bytes), in each
    // quadrant being fitted.
    let pair_bytes = 200.0 * pairs(cfg) * threads;
    let codes = cfg.frac_max() as f64 + 1.0;
    let (fit, mut bytes, fields) = match scene.map_fit {
        MapFit::Sample | MapFit::Lsq | MapFit::LsqPlain => (0.0, 0.0, String::new()),
        MapFit::Minimax => (
            MINIMAX[ib][ip] * scale,
            pair_bytes,
            format!(
                "map_fit minimax at index_bits {}, interp_bits {}",
                cfg.index_bits, ip
            ),
        ),
        MapFit::Table => {
            // The descent over every pair of codes grows with their square; the rounds of
            // minimax maps do not.
            let descent = (codes / 256.0).powi(2);
            (
                (TABLE[ib][ip] * descent).max(7.0 * MINIMAX[ib][ip]) * scale,
                pair_bytes + 24.0 * codes * codes * 16.0,
                format!(
                    "map_fit table at index_bits {}, interp_bits {}, frac_bits {}",
                    cfg.index_bits, ip, cfg.frac_bits
                ),
            )
        }
    };
    let pixels = size as f64 * size as f64;
    let draw = if volume {
        VOLUME_PREPARE + VOLUME_PIXEL * pixels
    } else {
        SPHERE_PIXEL * pixels
    };
    bytes += PIXEL_BYTES * pixels;
    if volume {
        let d = crate::volume::synthetic::DIMS;
        bytes += VOXEL_BYTES * (d[0] * d[1] * d[2]) as f64;
    }
    let mut fields = fields;
    for (name, v, from) in [
        ("map_bits", cfg.map_bits, 8),
        ("grad_bits", cfg.grad_bits, 12),
    ] {
        if v > from && !fields.is_empty() {
            fields.push_str(&format!(", {name} {v}"));
        }
    }
    if lights > 1.0 && !fields.is_empty() {
        fields.push_str(&format!(", {} lights", lights as usize));
    }
    Estimate {
        core_seconds: fit + draw,
        bytes: bytes.min(u64::MAX as f64) as u64,
        fields,
    }
}

/// [`estimate`], refused when it exceeds [`CORE_SECONDS`] or [`BYTES`]: one line naming the
/// fields, the prediction and the bound.
pub fn judge(cfg: &Config, scene: &Scene, size: u32, volume: bool) -> Result<Estimate> {
    let e = estimate(cfg, scene, size, volume);
    if e.bytes > BYTES {
        bail!(
            "too large for the explorer: {} would hold about {} MiB; it renders with at most {} MiB (lower frac_bits, index_bits or interp_bits)",
            e.fields,
            e.bytes >> 20,
            BYTES >> 20
        );
    }
    if e.core_seconds > CORE_SECONDS {
        let about = if e.core_seconds.is_finite() {
            format!("about {:.0}", e.core_seconds)
        } else {
            format!("more than {OVER_AT_LEAST:.0}")
        };
        bail!(
            "too slow for the explorer: {} takes {about} core-seconds; it renders within {CORE_SECONDS:.0} (lower index_bits or interp_bits, or use map_fit sample or lsq)",
            e.fields,
        );
    }
    Ok(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(fit: MapFit, lights: usize) -> Scene {
        let mut s = Scene::standard();
        s.map_fit = fit;
        let l = s.lights[0].clone();
        s.lights = vec![l; lights];
        s
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn the_estimate_is_the_measured_table_scaled_by_the_measured_factors() {
        let d = Config::default();
        // The default sphere, sampled: the image alone.
        let e = estimate(&d, &scene(MapFit::Sample, 1), 256, false);
        assert!(close(e.core_seconds, SPHERE_PIXEL * 65536.0), "{e:?}");
        assert_eq!(e.bytes, (PIXEL_BYTES * 65536.0) as u64);
        assert_eq!(e.fields, "");
        for fit in [MapFit::Lsq, MapFit::LsqPlain] {
            assert_eq!(
                estimate(&d, &scene(fit, 8), 256, false).core_seconds,
                e.core_seconds
            );
        }
        // The volume: its preparation and its pixels, its voxels' memory.
        let v = estimate(&d, &scene(MapFit::Sample, 1), 512, true);
        assert!(
            close(v.core_seconds, VOLUME_PREPARE + VOLUME_PIXEL * 262144.0),
            "{v:?}"
        );
        let voxels = crate::volume::synthetic::DIMS.iter().product::<usize>() as f64;
        assert_eq!(
            v.bytes,
            (PIXEL_BYTES * 262144.0 + VOXEL_BYTES * voxels) as u64
        );
        // minimax, every factor: 8 lights, map_bits 12, grad_bits 16.
        let cfg = Config {
            map_bits: 12,
            grad_bits: 16,
            ..d.clone()
        };
        let m = estimate(&cfg, &scene(MapFit::Minimax, 8), 64, false);
        let want = MINIMAX[1][3] * (1.0 + 0.16 * 7.0) * 1.2f64.powi(4) * (1.0 + 0.15 * 4.0);
        assert!(
            close(m.core_seconds, want + SPHERE_PIXEL * 4096.0),
            "{m:?} {want}"
        );
        assert_eq!(
            m.fields,
            "map_fit minimax at index_bits 3, interp_bits 3, map_bits 12, grad_bits 16, 8 lights"
        );
        let threads = rayon::current_num_threads() as f64;
        assert_eq!(
            m.bytes,
            (200.0 * 57.0 * 57.0 * threads + PIXEL_BYTES * 4096.0) as u64
        );
        // Fewer map and gradient bits than the measured ones are not cheaper.
        let small = Config {
            map_bits: 6,
            grad_bits: 8,
            red_bits: 6,
            ..d.clone()
        };
        let s = estimate(&small, &scene(MapFit::Minimax, 1), 64, false);
        assert!(
            close(s.core_seconds, MINIMAX[1][3] + SPHERE_PIXEL * 4096.0),
            "{s:?}"
        );
        // More fraction codes reach more positions: index 4, interp 5 (481 positions)
        // reaches 256 of them at frac_bits 8 and all of them at 12.
        let wide = Config {
            index_bits: 4,
            interp_bits: 5,
            frac_bits: 12,
            recip_bits: 13,
            ..d.clone()
        };
        let w = estimate(&wide, &scene(MapFit::Minimax, 1), 16, false);
        let spread = (481.0f64 * 481.0) / (256.0 * 256.0);
        assert!(
            close(
                w.core_seconds,
                MINIMAX[2][5] * spread + SPHERE_PIXEL * 256.0
            ),
            "{w:?}"
        );
        // Without interpolation: its column 0.
        let nearest = Config {
            interpolation: false,
            interp_bits: 0,
            ..d.clone()
        };
        let n = estimate(&nearest, &scene(MapFit::Minimax, 1), 16, false);
        assert!(
            close(n.core_seconds, MINIMAX[1][0] + SPHERE_PIXEL * 256.0),
            "{n:?}"
        );
    }

    #[test]
    fn the_table_fit_grows_with_the_square_of_its_codes_and_is_never_below_its_minimax_rounds() {
        let ram = Config {
            comp_table: crate::config::CompTable::Ram,
            ..Config::default()
        };
        let t = estimate(&ram, &scene(MapFit::Table, 2), 16, false);
        assert!(
            close(t.core_seconds, TABLE[1][3] * 1.05 + SPHERE_PIXEL * 256.0),
            "{t:?}"
        );
        assert_eq!(
            t.fields,
            "map_fit table at index_bits 3, interp_bits 3, frac_bits 8, 2 lights"
        );
        let threads = rayon::current_num_threads() as f64;
        let states = 24.0 * 256.0 * 256.0 * 16.0;
        assert_eq!(
            t.bytes,
            (200.0 * 57.0 * 57.0 * threads + states + PIXEL_BYTES * 256.0) as u64
        );
        let nine = Config {
            frac_bits: 9,
            ..ram.clone()
        };
        let t9 = estimate(&nine, &scene(MapFit::Table, 1), 16, false);
        assert!(
            close(t9.core_seconds, TABLE[1][3] * 4.0 + SPHERE_PIXEL * 256.0),
            "{t9:?}"
        );
        // Fewer codes: the rounds of minimax maps still cost their own.
        let six = Config {
            frac_bits: 6,
            ..ram
        };
        let t6 = estimate(&six, &scene(MapFit::Table, 1), 16, false);
        assert!(
            close(t6.core_seconds, 7.0 * MINIMAX[1][3] + SPHERE_PIXEL * 256.0),
            "{t6:?}"
        );
    }

    #[test]
    fn judge_refuses_past_either_bound_naming_the_fields() {
        let d = Config::default();
        assert!(judge(&d, &scene(MapFit::Minimax, 1), 512, true).is_ok());
        // The first case: past the measurement.
        let c = Config {
            index_bits: 6,
            interp_bits: 5,
            map_bits: 12,
            ..d.clone()
        };
        let e = judge(&c, &scene(MapFit::Minimax, 1), 16, false)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "too slow for the explorer: map_fit minimax at index_bits 6, interp_bits 5, map_bits 12 takes more than 40 core-seconds; it renders within 30 (lower index_bits or interp_bits, or use map_fit sample or lsq)"
        );
        // Measured and over the budget: the estimate is named.
        let c = Config {
            index_bits: 5,
            interp_bits: 4,
            ..d.clone()
        };
        let e = judge(&c, &scene(MapFit::Minimax, 1), 16, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("takes about 79 core-seconds"), "{e}");
        // At the bound it renders; just over, it does not.
        let ok = Config {
            index_bits: 5,
            interp_bits: 3,
            ..d.clone()
        };
        let at = estimate(&ok, &scene(MapFit::Minimax, 1), 16, false).core_seconds;
        assert!(at < CORE_SECONDS && judge(&ok, &scene(MapFit::Minimax, 1), 16, false).is_ok());
        let mut two = scene(MapFit::Minimax, 2);
        two.lights[1].intensity = 0.5;
        assert!(estimate(&ok, &two, 16, false).core_seconds > CORE_SECONDS);
        assert!(judge(&ok, &two, 16, false).is_err());
        // Memory: the table fit's states at 4096 codes.
        let big = Config {
            comp_table: crate::config::CompTable::Ram,
            index_bits: 5,
            frac_bits: 12,
            recip_bits: 13,
            ..d
        };
        big.validate().unwrap();
        let e = judge(&big, &scene(MapFit::Table, 1), 16, false)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("too large for the explorer: map_fit table at index_bits 5, interp_bits 3, frac_bits 12 would hold about 6"),
            "{e}"
        );
        assert!(
            e.ends_with(
                "it renders with at most 1024 MiB (lower frac_bits, index_bits or interp_bits)"
            ),
            "{e}"
        );
    }
}
