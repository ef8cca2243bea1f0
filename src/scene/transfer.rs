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
//!
//! Two optional keys classify like VolPack's examples:
//! - `gradient = [[magnitude, factor], ...]`: a piecewise-linear ramp on the gradient
//!   magnitude (value units per world unit, magnitudes strictly increasing, factors in
//!   0..=1) that multiplies the value's opacity, so flat noisy regions stay transparent;
//! - `min_opacity = a`: a sample whose opacity (per unit length, after the ramp) is below
//!   `a` is transparent, and so skipped.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transfer {
    /// Breakpoints `[value, opacity]`, values strictly increasing, opacities in 0..=1.
    pub points: Vec<[f64; 2]>,
    /// Breakpoints `[gradient magnitude, factor]` of the opacity ramp on the gradient
    /// magnitude (value units per world unit), magnitudes strictly increasing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gradient: Option<Vec<[f64; 2]>>,
    /// Opacity (per unit length) below which a sample is transparent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_opacity: Option<f64>,
}

/// Checks the gradient-magnitude ramp: at least two breakpoints, magnitudes finite, >= 0
/// and strictly increasing, factors in 0..=1.
pub fn validate_ramp(points: &[[f64; 2]]) -> Result<()> {
    if points.len() < 2 {
        bail!(
            "gradient-magnitude ramp has {} breakpoint(s); give at least two [magnitude, opacity] pairs",
            points.len()
        );
    }
    for (i, &[m, o]) in points.iter().enumerate() {
        if !m.is_finite() || !(0.0..=f32::MAX as f64).contains(&m) {
            bail!(
                "gradient-magnitude ramp breakpoint {} has magnitude {m}; give a finite number >= 0",
                i + 1
            );
        }
        if !(0.0..=1.0).contains(&o) {
            bail!(
                "gradient-magnitude ramp breakpoint {} has opacity {o}; opacities must be in 0..=1",
                i + 1
            );
        }
    }
    for (i, w) in points.windows(2).enumerate() {
        if w[1][0] as f32 <= w[0][0] as f32 {
            bail!(
                "gradient-magnitude ramp is not increasing: breakpoint {} (magnitude {}) does not come after breakpoint {} (magnitude {}); magnitudes must increase strictly",
                i + 2,
                w[1][0],
                i + 1,
                w[0][0]
            );
        }
    }
    Ok(())
}

/// Parses `a:b,c:d,...` into pairs; `flag` names the option in messages.
fn pairs(flag: &str, text: &str) -> Result<Vec<[f64; 2]>> {
    let mut points = Vec::new();
    for (i, item) in text.split(',').enumerate() {
        let Some((v, o)) = item.split_once(':') else {
            bail!("{flag} item {} '{item}' is not value:opacity", i + 1);
        };
        let num = |s: &str| {
            s.trim().parse::<f64>().map_err(|_| {
                anyhow::anyhow!(
                    "{flag} item {} '{item}': '{}' is not a number",
                    i + 1,
                    s.trim()
                )
            })
        };
        points.push([num(v)?, num(o)?]);
    }
    Ok(points)
}

/// Parses the command-line form of the gradient-magnitude ramp, `magnitude:opacity,...`.
pub fn parse_ramp(text: &str) -> Result<Vec<[f64; 2]>> {
    let p = pairs("--gradient-ramp", text)?;
    validate_ramp(&p)?;
    Ok(p)
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
        if let Some(g) = &self.gradient {
            validate_ramp(g)?;
        }
        if let Some(m) = self.min_opacity {
            if !(0.0..=1.0).contains(&m) {
                bail!("minimum opacity {m} is out of range; allowed 0..=1");
            }
        }
        Ok(())
    }

    /// A transfer function with breakpoints only (no gradient ramp, no minimum opacity).
    pub fn new(points: Vec<[f64; 2]>) -> Transfer {
        Transfer {
            points,
            ..Transfer::default()
        }
    }

    /// Parses the command-line form `value:opacity,value:opacity,...` and validates it.
    pub fn parse(text: &str) -> Result<Transfer> {
        let t = Transfer::new(pairs("--transfer", text)?);
        t.validate()?;
        Ok(t)
    }

    /// The breakpoints as `value:opacity,...`, the command-line form.
    pub fn points_text(&self) -> String {
        let v: Vec<String> = self
            .points
            .iter()
            .map(|p| format!("{}:{}", p[0], p[1]))
            .collect();
        v.join(",")
    }

    /// The form the renderer evaluates (f32, with slopes), for samples `step` voxels apart;
    /// `grad_scale` converts gradient magnitudes (value units per world unit) into the
    /// quantised gradients' LSBs ([`crate::volume::gradient::Gradients::scale`]).
    pub fn compile(&self, step: f32, grad_scale: f64) -> Tf {
        Tf {
            value: Piecewise::new(&self.points, 1.0),
            ramp: self
                .gradient
                .as_ref()
                .map(|g| Piecewise::new(g, grad_scale)),
            min: self.min_opacity.unwrap_or(0.0) as f32,
            step,
        }
    }
}

/// A piecewise-linear function in f32, constant beyond its first and last breakpoint.
#[derive(Clone, Debug)]
struct Piecewise {
    xs: Vec<f32>,
    ys: Vec<f32>,
    slopes: Vec<f32>,
}

impl Piecewise {
    /// Breakpoints `[x, y]` with x multiplied by `scale`.
    fn new(points: &[[f64; 2]], scale: f64) -> Piecewise {
        let xs: Vec<f32> = points.iter().map(|p| (p[0] * scale) as f32).collect();
        let ys: Vec<f32> = points.iter().map(|p| p[1] as f32).collect();
        let slopes = xs
            .windows(2)
            .zip(ys.windows(2))
            .map(|(x, y)| (y[1] - y[0]) / (x[1] - x[0]))
            .collect();
        Piecewise { xs, ys, slopes }
    }

    /// Each segment is evaluated as `y0 + (v - x0) * slope`, which is monotonic in `v`
    /// under IEEE rounding; the result is clamped to 0..=1.
    #[inline]
    fn at(&self, v: f32) -> f32 {
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

    /// The largest value on `lo..=hi`: at an end or at a breakpoint between them, since
    /// each segment's evaluation is monotonic.
    fn max_on(&self, lo: f32, hi: f32) -> f32 {
        self.xs
            .iter()
            .zip(&self.ys)
            .filter(|(&x, _)| x >= lo && x <= hi)
            .fold(self.at(lo).max(self.at(hi)), |m, (_, &y)| m.max(y))
    }
}

/// A validated transfer function ready for the hot loop.
#[derive(Clone, Debug)]
pub struct Tf {
    value: Piecewise,
    /// The gradient-magnitude ramp, magnitudes in gradient LSBs.
    ramp: Option<Piecewise>,
    /// Opacities below this are 0.
    min: f32,
    step: f32,
}

impl Tf {
    /// Opacity per unit length at value `v` (before the gradient ramp and the minimum).
    /// [`Tf::zero_on`] relies on its segments being monotonic and clamped.
    #[inline]
    pub fn opacity(&self, v: f32) -> f32 {
        self.value.at(v)
    }

    /// Whether a gradient-magnitude ramp applies (the sample's gradient is needed for its
    /// opacity).
    #[inline]
    pub fn has_ramp(&self) -> bool {
        self.ramp.is_some()
    }

    /// The value's opacity with the minimum applied: 0 below it.
    #[inline]
    pub fn value_opacity(&self, v: f32) -> f32 {
        let o = self.value.at(v);
        if o < self.min {
            0.0
        } else {
            o
        }
    }

    /// Opacity `o` (from [`Tf::value_opacity`]) times the ramp at the quantised gradient
    /// `g`, with the minimum applied.
    #[inline]
    pub fn with_gradient(&self, o: f32, g: [i32; 3]) -> f32 {
        let Some(r) = &self.ramp else { return o };
        let [x, y, z] = g.map(|c| c as f32);
        let m = (x * x + y * y + z * z).sqrt();
        let o = o * r.at(m);
        if o < self.min {
            0.0
        } else {
            o
        }
    }

    /// Opacity of one sample `step` long for the opacity per unit length `o`.
    #[inline]
    pub fn correct(&self, o: f32) -> f32 {
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

    /// Whether every sample with a value in `lo..=hi` and a gradient magnitude (LSBs) up to
    /// `grad_max` is transparent: the largest value opacity there, times the ramp's largest
    /// factor up to `grad_max`, is 0 or below the minimum. f32 products are monotonic, so
    /// every sample's product is at most this one.
    pub fn transparent_on(&self, lo: f32, hi: f32, grad_max: f32) -> bool {
        let mut m = self.value.max_on(lo, hi);
        if m < self.min {
            return true;
        }
        if let Some(r) = &self.ramp {
            m *= r.max_on(0.0, grad_max);
        }
        m <= 0.0 || m < self.min
    }

    /// Opacity of one sample `step` long at value `v` (no gradient ramp): `1 - (1 -
    /// opacity)^step`, exactly 0 where the opacity is 0 and exactly 1 where it is 1.
    #[inline]
    pub fn alpha(&self, v: f32) -> f32 {
        self.correct(self.value_opacity(v))
    }

    /// Whether the opacity is 0 for every value in `lo..=hi` as [`Tf::opacity`] evaluates it:
    /// both ends evaluate to 0 and no breakpoint between them has a non-zero opacity. Segment
    /// evaluation is monotonic and clamped at 0, so nothing in between can be non-zero.
    pub fn zero_on(&self, lo: f32, hi: f32) -> bool {
        self.opacity(lo) == 0.0
            && self.opacity(hi) == 0.0
            && self
                .value
                .xs
                .iter()
                .zip(&self.value.ys)
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
        Transfer::new(points.to_vec())
    }

    #[test]
    fn piecewise_linear_and_clamped_at_the_ends() {
        let t = tf(&[[100.0, 0.0], [200.0, 1.0], [300.0, 0.5]]).compile(1.0, 1.0);
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
        let half = t.compile(0.5, 1.0);
        // Two half steps of 0.75 make one full step of 0.75.
        let a = half.alpha(0.75);
        assert!((1.0 - (1.0 - a) * (1.0 - a) - 0.75).abs() < 1e-6);
        let quarter = t.compile(0.25, 1.0);
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
        .compile(1.0, 1.0);
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
