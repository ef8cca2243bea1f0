//! Error statistics of one image against another, in output LSBs. Pure functions of the two
//! value lists, so tests, benchmarks and the RTL render share them.

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Samples compared (the inside pixels of a render).
    pub pixels: usize,
    /// Peak value of the PSNR, 2^map_bits - 1.
    pub peak: u32,
    /// Largest |a - b|.
    pub max_abs_error: u32,
    pub mean_abs_error: f64,
    /// Mean of a - b: a bias of the first list against the second.
    pub mean_error: f64,
    pub rmse: f64,
    /// 20 log10(peak / rmse); `None` (JSON null) when the lists are equal.
    pub psnr_db: Option<f64>,
    /// How many samples have |a - b| = 0, 1, 2, ..., up to `max_abs_error`.
    pub abs_error_histogram: Vec<usize>,
    /// Index of the first sample with the largest error; `None` for empty lists.
    pub worst_index: Option<usize>,
}

/// Compares `a` (the design under test) with `b` (the reference) sample by sample; `peak` is
/// the largest value of the output range.
pub fn metrics(a: &[u32], b: &[u32], peak: u32) -> Metrics {
    assert_eq!(a.len(), b.len(), "metrics of lists of different lengths");
    let mut acc = Accumulator::new(peak);
    for (&x, &y) in a.iter().zip(b) {
        acc.add(x, y);
    }
    acc.finish()
}

/// [`metrics`] one sample pair at a time, for images too large to hold as value lists
/// (`rmapgen compare` streams rows): the same figures in the same order of samples.
#[derive(Clone, Debug)]
pub struct Accumulator {
    peak: u32,
    n: usize,
    hist: Vec<usize>,
    sum: i64,
    sum_abs: u64,
    sum_sq: u64,
    worst: Option<(usize, u32)>,
}

impl Accumulator {
    pub fn new(peak: u32) -> Accumulator {
        Accumulator {
            peak,
            n: 0,
            hist: vec![0],
            sum: 0,
            sum_abs: 0,
            sum_sq: 0,
            worst: None,
        }
    }

    /// The next sample: `x` under test, `y` the reference.
    pub fn add(&mut self, x: u32, y: u32) {
        let e = x as i64 - y as i64;
        let ae = e.unsigned_abs() as u32;
        self.sum += e;
        self.sum_abs += ae as u64;
        self.sum_sq += ae as u64 * ae as u64;
        if ae as usize >= self.hist.len() {
            self.hist.resize(ae as usize + 1, 0);
        }
        self.hist[ae as usize] += 1;
        if self.worst.is_none_or(|(_, w)| ae > w) {
            self.worst = Some((self.n, ae));
        }
        self.n += 1;
    }

    pub fn finish(self) -> Metrics {
        let n = self.n;
        let mean = |s: f64| if n == 0 { 0.0 } else { s / n as f64 };
        let rmse = mean(self.sum_sq as f64).sqrt();
        Metrics {
            pixels: n,
            peak: self.peak,
            max_abs_error: self.worst.map_or(0, |w| w.1),
            mean_abs_error: mean(self.sum_abs as f64),
            mean_error: mean(self.sum as f64),
            rmse,
            psnr_db: (rmse > 0.0).then(|| 20.0 * (self.peak as f64 / rmse).log10()),
            abs_error_histogram: if n == 0 { Vec::new() } else { self.hist },
            worst_index: self.worst.map(|w| w.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn by_hand() {
        let m = metrics(&[10, 12, 7, 9], &[10, 10, 10, 9], 255);
        assert_eq!(m.pixels, 4);
        assert_eq!(m.max_abs_error, 3);
        assert_eq!(m.worst_index, Some(2));
        assert_eq!(m.mean_abs_error, 5.0 / 4.0);
        assert_eq!(m.mean_error, -1.0 / 4.0);
        assert_eq!(m.rmse, (13.0f64 / 4.0).sqrt());
        let psnr = m.psnr_db.unwrap();
        assert!((psnr - 20.0 * (255.0 / m.rmse).log10()).abs() < 1e-12);
        assert_eq!(m.abs_error_histogram, vec![2, 0, 1, 1]);
    }

    #[test]
    fn equal_and_empty() {
        let m = metrics(&[1, 2, 3], &[1, 2, 3], 255);
        assert_eq!(
            (m.max_abs_error, m.rmse, m.psnr_db, m.worst_index),
            (0, 0.0, None, Some(0))
        );
        assert_eq!(m.abs_error_histogram, vec![3]);
        let e = metrics(&[], &[], 255);
        assert_eq!((e.pixels, e.rmse, e.worst_index), (0, 0.0, None));
        assert!(e.abs_error_histogram.is_empty());
    }

    #[test]
    fn first_worst_wins() {
        let m = metrics(&[0, 5, 0, 5], &[0, 0, 5, 0], 255);
        assert_eq!((m.max_abs_error, m.worst_index), (5, Some(1)));
    }
}
