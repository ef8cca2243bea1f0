//! The opacity transfer function: piecewise linear in the voxel value, given by breakpoints
//! `[value, opacity]` whose values increase strictly, constant beyond the first and last
//! breakpoint. Opacities are per unit length (one voxel of the smallest spacing); a sample
//! `step` long gets `1 - (1 - opacity)^step` (opacity correction), so the image hardly
//! depends on the step.
//!
//! In a scene file:
//!
//! ```toml
//! [transfer]
//! points = [[1100.0, 0.0], [1900.0, 1.0]]
//! ```
//!
//! Values are in the volume's own units (the stored voxel values: 0..255 for 8-bit data,
//! Hounsfield units for signed CT data, ...).

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transfer {
    /// Breakpoints `[value, opacity]`, values strictly increasing, opacities in 0..=1.
    pub points: Vec<[f64; 2]>,
}

impl Transfer {
    /// Checks the breakpoints: at least two, finite, values strictly increasing (the function
    /// must be monotonic in its breakpoints' positions), opacities in 0..=1.
    pub fn validate(&self) -> Result<()> {
        if self.points.len() < 2 {
            bail!(
                "transfer function has {} breakpoint(s); give at least two [value, opacity] pairs",
                self.points.len()
            );
        }
        for (i, &[v, o]) in self.points.iter().enumerate() {
            if !v.is_finite() || v.abs() > f32::MAX as f64 {
                bail!(
                    "transfer function breakpoint {} has value {v}, which is not a finite number",
                    i + 1
                );
            }
            if !(0.0..=1.0).contains(&o) {
                bail!(
                    "transfer function breakpoint {} has opacity {o}; opacities must be in 0..=1",
                    i + 1
                );
            }
        }
        for (i, w) in self.points.windows(2).enumerate() {
            // Compared as the f32 values the renderer uses, so two values that collapse
            // to one f32 are rejected here rather than making a zero-width segment.
            if w[1][0] as f32 <= w[0][0] as f32 {
                bail!(
                    "transfer function is not monotonic in its breakpoints: breakpoint {} (value {}) does not come after breakpoint {} (value {}); values must increase strictly",
                    i + 2,
                    w[1][0],
                    i + 1,
                    w[0][0]
                );
            }
        }
        Ok(())
    }

    /// Parses the command-line form `value:opacity,value:opacity,...` and validates it.
    pub fn parse(text: &str) -> Result<Transfer> {
        let mut points = Vec::new();
        for (i, item) in text.split(',').enumerate() {
            let Some((v, o)) = item.split_once(':') else {
                bail!("--transfer item {} '{item}' is not value:opacity", i + 1);
            };
            let num = |s: &str| {
                s.trim().parse::<f64>().map_err(|_| {
                    anyhow::anyhow!(
                        "--transfer item {} '{item}': '{}' is not a number",
                        i + 1,
                        s.trim()
                    )
                })
            };
            points.push([num(v)?, num(o)?]);
        }
        let t = Transfer { points };
        t.validate()?;
        Ok(t)
    }

    /// The form the renderer evaluates (f32, with slopes), for samples `step` voxels apart.
    pub fn compile(&self, step: f32) -> Tf {
        let xs: Vec<f32> = self.points.iter().map(|p| p[0] as f32).collect();
        let ys: Vec<f32> = self.points.iter().map(|p| p[1] as f32).collect();
        let slopes = xs
            .windows(2)
            .zip(ys.windows(2))
            .map(|(x, y)| (y[1] - y[0]) / (x[1] - x[0]))
            .collect();
        Tf {
            xs,
            ys,
            slopes,
            step,
        }
    }
}

/// A validated transfer function ready for the hot loop.
#[derive(Clone, Debug)]
pub struct Tf {
    xs: Vec<f32>,
    ys: Vec<f32>,
    slopes: Vec<f32>,
    step: f32,
}

impl Tf {
    /// Opacity per unit length at value `v`. Each segment is evaluated as
    /// `y0 + (v - x0) * slope`, which is monotonic in `v` under IEEE rounding; the result is
    /// clamped to 0..=1. [`Tf::zero_on`] relies on both properties.
    #[inline]
    pub fn opacity(&self, v: f32) -> f32 {
        let n = self.xs.len();
        if v <= self.xs[0] {
            return self.ys[0];
        }
        if v >= self.xs[n - 1] {
            return self.ys[n - 1];
        }
        let mut i = 0;
        while v >= self.xs[i + 1] {
            i += 1;
        }
        (self.ys[i] + (v - self.xs[i]) * self.slopes[i]).clamp(0.0, 1.0)
    }

    /// Opacity of one sample `step` long: `1 - (1 - opacity)^step`, exactly 0 where the
    /// opacity is 0 and exactly 1 where it is 1.
    #[inline]
    pub fn alpha(&self, v: f32) -> f32 {
        let o = self.opacity(v);
        if o <= 0.0 {
            0.0
        } else if o >= 1.0 {
            1.0
        } else if self.step == 1.0 {
            o
        } else if self.step == 0.5 {
            1.0 - (1.0 - o).sqrt()
        } else {
            1.0 - (1.0 - o).powf(self.step)
        }
    }

    /// Whether the opacity is 0 for every value in `lo..=hi` as [`Tf::opacity`] evaluates it:
    /// both ends evaluate to 0 and no breakpoint between them has a non-zero opacity. Segment
    /// evaluation is monotonic and clamped at 0, so nothing in between can be non-zero.
    pub fn zero_on(&self, lo: f32, hi: f32) -> bool {
        self.opacity(lo) == 0.0
            && self.opacity(hi) == 0.0
            && self
                .xs
                .iter()
                .zip(&self.ys)
                .all(|(&x, &y)| x < lo || x > hi || y == 0.0)
    }

    pub fn step(&self) -> f32 {
        self.step
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tf(points: &[[f64; 2]]) -> Transfer {
        Transfer {
            points: points.to_vec(),
        }
    }

    #[test]
    fn piecewise_linear_and_clamped_at_the_ends() {
        let t = tf(&[[100.0, 0.0], [200.0, 1.0], [300.0, 0.5]]).compile(1.0);
        assert_eq!(t.opacity(0.0), 0.0);
        assert_eq!(t.opacity(100.0), 0.0);
        assert_eq!(t.opacity(150.0), 0.5);
        assert_eq!(t.opacity(200.0), 1.0);
        assert_eq!(t.opacity(250.0), 0.75);
        assert_eq!(t.opacity(1e9), 0.5);
        assert_eq!(t.alpha(150.0), 0.5);
    }

    #[test]
    fn opacity_correction() {
        let t = tf(&[[0.0, 0.0], [1.0, 1.0]]);
        let half = t.compile(0.5);
        // Two half steps of 0.75 make one full step of 0.75.
        let a = half.alpha(0.75);
        assert!((1.0 - (1.0 - a) * (1.0 - a) - 0.75).abs() < 1e-6);
        let quarter = t.compile(0.25);
        let q = quarter.alpha(0.75);
        assert!((1.0 - (1.0 - q).powi(4) - 0.75).abs() < 1e-5);
        assert_eq!(
            (half.alpha(0.0), half.alpha(1.0), quarter.alpha(2.0)),
            (0.0, 1.0, 1.0)
        );
    }

    #[test]
    fn zero_on_intervals() {
        let t = tf(&[
            [100.0, 0.0],
            [200.0, 1.0],
            [300.0, 0.0],
            [400.0, 0.0],
            [500.0, 0.3],
        ])
        .compile(1.0);
        assert!(t.zero_on(-50.0, 100.0));
        assert!(!t.zero_on(-50.0, 100.5));
        assert!(t.zero_on(300.0, 400.0));
        assert!(!t.zero_on(299.0, 400.0));
        assert!(!t.zero_on(350.0, 401.0));
        // A peak strictly inside the interval, with both ends at 0.
        assert!(!t.zero_on(100.0, 300.0));
        // Dense check: zero_on agrees with sampling.
        for lo in (0..600).step_by(7) {
            for hi in (lo..600).step_by(11) {
                let sampled = (lo..=hi).all(|v| t.opacity(v as f32) == 0.0);
                if t.zero_on(lo as f32, hi as f32) {
                    assert!(sampled, "{lo}..{hi}");
                }
            }
        }
    }

    #[test]
    fn validation_names_the_problem() {
        let e = |p: &[[f64; 2]]| tf(p).validate().unwrap_err().to_string();
        assert!(e(&[[1.0, 0.0]]).contains("at least two"));
        let m = e(&[[1.0, 0.0], [3.0, 0.5], [2.0, 1.0]]);
        assert!(
            m.contains("not monotonic") && m.contains("breakpoint 3"),
            "{m}"
        );
        assert!(e(&[[1.0, 0.0], [1.0, 1.0]]).contains("not monotonic"));
        assert!(e(&[[1.0, 0.0], [2.0, 1.5]]).contains("0..=1"));
        assert!(e(&[[f64::NAN, 0.0], [2.0, 1.0]]).contains("not a finite"));
        tf(&[[1.0, 0.0], [2.0, 1.0]]).validate().unwrap();
    }

    #[test]
    fn command_line_form() {
        let t = Transfer::parse("1100:0, 1900:1").unwrap();
        assert_eq!(t.points, vec![[1100.0, 0.0], [1900.0, 1.0]]);
        assert!(Transfer::parse("1100:0,900:1")
            .unwrap_err()
            .to_string()
            .contains("not monotonic"));
        assert!(Transfer::parse("1100;0,900:1")
            .unwrap_err()
            .to_string()
            .contains("value:opacity"));
        assert!(Transfer::parse("1100:x,1900:1")
            .unwrap_err()
            .to_string()
            .contains("not a number"));
    }
}
