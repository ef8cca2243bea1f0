//! How the bench times its figures: the best of three windows for throughput, the median of
//! runs for a map build, and the uniform random gradients the throughput runs on. Separate
//! so every figure of a row is timed the same way.

use crate::rng::SplitMix64;
use std::time::Instant;

/// Seconds per call of `f`: after one warm-up call, the best of three windows of at least
/// `seconds` / 3 each (and at least one call), so a busy moment on the machine counts less.
pub(super) fn time(seconds: f64, mut f: impl FnMut()) -> f64 {
    f();
    (0..3)
        .map(|_| {
            let start = Instant::now();
            let mut n = 0u32;
            while n == 0 || start.elapsed().as_secs_f64() < seconds / 3.0 {
                f();
                n += 1;
            }
            start.elapsed().as_secs_f64() / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Median seconds of `runs` calls.
pub(super) fn median(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[runs / 2]
}

pub(super) fn uniform(n: usize) -> Vec<[i32; 3]> {
    let mut rng = SplitMix64::new(1);
    (0..n)
        .map(|_| [(); 3].map(|_| rng.range(0, 4095) as i32 - 2048))
        .collect()
}
