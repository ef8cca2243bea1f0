//! The error a design must meet ([`Target`]): whether a measurement meets it, and the limits
//! a measurement may stop at. Separate from the search because the outcome, the measuring
//! context and the lowest-error search all judge candidates against it.

use super::measure::{Errors, Limits};
use serde::Serialize;

/// The error a design must meet; at least one field is set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Target {
    /// Largest absolute error of any output, in its LSBs.
    pub max_error: Option<u32>,
    /// RMS intensity error in output LSBs.
    pub rmse: Option<f64>,
}

impl Target {
    pub fn met_by(&self, e: &Errors) -> bool {
        e.complete
            && self.max_error.is_none_or(|m| e.max_any() <= m)
            && self.rmse.is_none_or(|r| e.rmse <= r)
    }

    pub(super) fn limits(&self, pixels: usize) -> Limits {
        Limits {
            max: self.max_error,
            // The RMSE bound as a sum of squares, with a hair of slack for rounding.
            sse: self
                .rmse
                .map(|r| r * r * pixels as f64 * (1.0 + 1e-12) + 1e-9),
        }
    }

    /// "max error <= 3 LSB and RMSE <= 0.9 LSB".
    pub fn describe(&self) -> String {
        let mut v = Vec::new();
        if let Some(m) = self.max_error {
            v.push(format!("max abs error <= {m} LSB"));
        }
        if let Some(r) = self.rmse {
            v.push(format!("RMSE <= {r} LSB"));
        }
        v.join(" and ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_checks_every_output_and_needs_a_complete_measurement() {
        let e = Errors {
            max_abs_error: 3,
            rmse: 1.0,
            color_max_abs_error: Some(4),
            complete: true,
            pixels_seen: 10,
        };
        let t = |m, r| Target {
            max_error: m,
            rmse: r,
        };
        assert!(t(Some(4), None).met_by(&e));
        assert!(!t(Some(3), None).met_by(&e));
        assert!(t(None, Some(1.0)).met_by(&e));
        assert!(!t(Some(4), Some(0.99)).met_by(&e));
        assert!(!t(Some(4), None).met_by(&Errors {
            complete: false,
            ..e
        }));
    }
}
