//! What a cast produces: a [`Frame`] (the composited image) or, for a batch shader, the
//! [`Samples`] it composites into one, each with the work counts of the image ([`Stats`]).
//! Separate from the caster: reports and the command line read them after casting.

use anyhow::{bail, Result};
use rayon::prelude::*;
use serde::Serialize;

/// Work counts of one image, summed over its rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Stats {
    /// Rays that pass through the volume's box.
    pub rays: u64,
    /// Samples on those rays inside the box: the work without skipping.
    pub samples: u64,
    /// Samples jumped over in empty bricks.
    pub empty_skipped: u64,
    /// Samples after early ray termination.
    pub terminated: u64,
    /// Samples interpolated (value and opacity).
    pub evaluated: u64,
    /// Samples shaded.
    pub shaded: u64,
}

impl Stats {
    pub(crate) fn add(self, o: Stats) -> Stats {
        Stats {
            rays: self.rays + o.rays,
            samples: self.samples + o.samples,
            empty_skipped: self.empty_skipped + o.empty_skipped,
            terminated: self.terminated + o.terminated,
            evaluated: self.evaluated + o.evaluated,
            shaded: self.shaded + o.shaded,
        }
    }

    fn fraction(&self, n: u64) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            n as f64 / self.samples as f64
        }
    }

    /// Fraction of the samples never interpolated (empty space and after termination).
    pub fn skipped_fraction(&self) -> f64 {
        self.fraction(self.empty_skipped + self.terminated)
    }

    /// Fraction of the samples not shaded.
    pub fn unshaded_fraction(&self) -> f64 {
        self.fraction(self.samples - self.shaded)
    }
}

/// A rendered image before quantisation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    pub size: u32,
    /// Composited intensity per pixel, in output LSBs (row 0 at the top).
    pub value: Vec<f32>,
    /// Accumulated opacity per pixel.
    pub alpha: Vec<f32>,
    pub stats: Stats,
}

impl Frame {
    /// Pixel values: the composited intensity rounded (half up) and clamped to 0..=max.
    pub fn pixels(&self, max: u32) -> Vec<u32> {
        self.value
            .iter()
            .map(|&c| (c.round().max(0.0) as u32).min(max))
            .collect()
    }
}

/// Every contributing sample of an image, for a batch shader.
#[derive(Clone, Debug)]
pub struct Samples {
    pub size: u32,
    /// Accumulated opacity per pixel.
    pub alpha: Vec<f32>,
    /// Pixel p's samples are `start[p]..start[p + 1]`, front to back.
    pub start: Vec<usize>,
    pub weights: Vec<f32>,
    pub gradients: Vec<[i32; 3]>,
    pub stats: Stats,
}

impl Samples {
    /// Composites intensities given for [`Samples::gradients`] in order: the frame the fused
    /// path gives with a shader that returns them.
    pub fn composite(&self, intensities: &[u32]) -> Result<Frame> {
        if intensities.len() != self.gradients.len() {
            bail!(
                "{} intensities for {} samples",
                intensities.len(),
                self.gradients.len()
            );
        }
        let value = (0..self.alpha.len())
            .into_par_iter()
            .map(|p| {
                let range = self.start[p]..self.start[p + 1];
                let mut c = 0.0f32;
                for (w, &i) in self.weights[range.clone()].iter().zip(&intensities[range]) {
                    c += w * i as f32;
                }
                c
            })
            .collect();
        Ok(Frame {
            size: self.size,
            value,
            alpha: self.alpha.clone(),
            stats: self.stats,
        })
    }
}
