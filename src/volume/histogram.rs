//! A default transfer function from the data, for a volume whose scene gives none: Otsu's
//! threshold on a 256-bin histogram of the values separates background from material, and
//! the opacity ramps from 0 at the threshold to 1 halfway from it to the 99th percentile,
//! so the material's surface renders opaque and the background transparent.

use super::report::percentiles;
use super::Volume;
use crate::scene::transfer::Transfer;

/// Bins of the histogram the threshold is chosen on.
pub const BINS: usize = 256;

/// The value that splits the histogram of `vol` into two classes with the largest
/// between-class variance (Otsu), as the upper edge of the last background bin.
pub fn otsu(vol: &Volume) -> f32 {
    let (lo, hi) = vol.range();
    if hi <= lo {
        return lo;
    }
    let width = (hi as f64 - lo as f64) / BINS as f64;
    let mut h = [0u64; BINS];
    for &v in &vol.data {
        let b = ((v as f64 - lo as f64) / width) as usize;
        h[b.min(BINS - 1)] += 1;
    }
    let total: u64 = h.iter().sum();
    let sum: f64 = h
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    let (mut w0, mut s0) = (0u64, 0.0f64);
    let (mut best, mut at) = (-1.0f64, 0usize);
    for (i, &c) in h.iter().enumerate().take(BINS - 1) {
        w0 += c;
        s0 += i as f64 * c as f64;
        let w1 = total - w0;
        if w0 == 0 || w1 == 0 {
            continue;
        }
        let (m0, m1) = (s0 / w0 as f64, (sum - s0) / w1 as f64);
        let between = w0 as f64 * w1 as f64 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            at = i;
        }
    }
    (lo as f64 + (at + 1) as f64 * width) as f32
}

/// The default transfer function of `vol` and a line saying how it was chosen.
pub fn default_transfer(vol: &Volume) -> (Transfer, String) {
    let t = otsu(vol) as f64;
    let [min, _, p50, p99, max] = percentiles(vol);
    let mut top = t + (p99 as f64 - t) / 2.0;
    if top.partial_cmp(&t) != Some(std::cmp::Ordering::Greater) {
        top = t + (max as f64 - min as f64).max(1.0) / BINS as f64;
    }
    // Values at least one f32 apart, as the transfer function requires.
    if top as f32 <= t as f32 {
        top = t + t.abs() * 1e-6 + 1e-3;
    }
    let tf = Transfer::new(vec![[t, 0.0], [top, 1.0]]);
    let text = format!(
        "transfer function (none given; from the data's histogram): {} (opacity 0 at the Otsu threshold {t} between background and material, 1 halfway to the 99th percentile; values min {min}, median {p50}, p99 {p99}, max {max})",
        tf.points_text()
    );
    (tf, text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::synthetic;

    #[test]
    fn threshold_separates_air_from_metal() {
        // The synthetic part: air about 80, metal about 2900.
        let v = synthetic::engine_block([32, 32, 16], [1.0; 3]).unwrap();
        let t = otsu(&v);
        assert!(t > 500.0 && t < 2500.0, "{t}");
        let (tf, text) = default_transfer(&v);
        tf.validate().unwrap();
        assert!(
            tf.points[0][0] < tf.points[1][0] && text.contains("Otsu"),
            "{text}"
        );
        // A constant volume still gives a valid (increasing) function.
        let c = Volume::new(
            [2, 2, 2],
            [1.0; 3],
            vec![7.0; 8],
            super::super::VolumeInfo {
                source: "c".into(),
                voxel_type: "float".into(),
            },
        )
        .unwrap();
        default_transfer(&c).0.validate().unwrap();
    }
}
