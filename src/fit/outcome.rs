//! What a search returns ([`Outcome`]): the measured candidates, the decision with its text
//! table, or the lowest error reachable when nothing meets the target. Separate from the
//! search itself: these are the report types that `rmapgen fit` prints and writes.

use super::measure::Errors;
use super::space::CostKind;
use super::target::Target;
use crate::config::Config;
use crate::model::map_fit::MapFit;
use serde::Serialize;

/// One measured candidate.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    pub config: Config,
    pub summary: String,
    pub bits: u64,
    pub cells: Option<u64>,
    pub errors: Errors,
    pub meets_target: bool,
    /// With the part checked (`fit --family/--device`): whether its design, synthesised and
    /// packed, fits the part; what it needs more of than the part has, when it does not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fits: Option<bool>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shortage: Option<String>,
}

/// The part a search had to fit, and the passing candidates it turned away.
#[derive(Clone, Debug, Serialize)]
pub struct Part {
    pub family: crate::flow::fpga::Family,
    pub device: String,
    pub package: String,
    /// Passing candidates synthesised and packed that do not fit.
    pub too_big: usize,
    /// The first of them (cheapest in the order of the choice).
    pub first_too_big: Option<Candidate>,
}

/// The result of a successful search.
#[derive(Clone, Debug, Serialize)]
pub struct Decision {
    pub target: Target,
    pub cost: CostKind,
    /// The family whose synthesis counted the cells; left out of fit.json for the iCE40 (the
    /// default), so a default fit writes what it wrote before the flag.
    #[serde(skip_serializing_if = "is_default_family")]
    pub family: crate::flow::fpga::Family,
    /// With `--family`/`--device`: the part every chosen or listed candidate fits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub part: Option<Part>,
    pub image_size: u32,
    pub pixels: usize,
    pub map_fit: MapFit,
    /// What building the maps evaluates ([`Scene::terms`](crate::scene::Scene::terms)).
    pub scene_terms: String,
    pub chosen: Candidate,
    /// The next passing candidates (by cost).
    pub runners_up: Vec<Candidate>,
    /// The most expensive candidates cheaper than the choice, all rejected, measured in full.
    pub rejected_below: Vec<Candidate>,
    /// The paper's design with the same interface.
    pub paper: Candidate,
    /// Candidates in the space, measured, and cheaper (in bits) than the choice.
    pub space: usize,
    /// The searched fields the caller fixed (none: the whole space).
    #[serde(skip_serializing_if = "super::space::Fixed::is_empty")]
    pub fixed: super::space::Fixed,
    pub measured: usize,
    pub cheaper_rejected: usize,
    /// Candidates synthesised (cost in cells; 0 otherwise), besides the paper's.
    pub synthesised: usize,
    pub seconds: f64,
}

/// Whether `f` is the default family (left out of the JSON then).
fn is_default_family(f: &crate::flow::fpga::Family) -> bool {
    *f == Default::default()
}

/// The lowest error reachable, when nothing meets the target.
#[derive(Clone, Debug, Serialize)]
pub struct Unreachable {
    pub target: Target,
    pub space: usize,
    /// The candidate with the lowest max error (when the target has one).
    pub best_max: Option<Candidate>,
    /// The candidate with the lowest RMSE (when the target has one).
    pub best_rmse: Option<Candidate>,
}

impl Unreachable {
    /// One line: what was asked, and the best reachable with its configuration.
    pub fn message(&self, scene: &str) -> String {
        let mut parts = Vec::new();
        if let Some(c) = &self.best_max {
            parts.push(format!(
                "the lowest max error reachable is {} LSB (RMSE {:.3}) with {}",
                c.errors.max_any(),
                c.errors.rmse,
                c.summary
            ));
        }
        if let Some(c) = &self.best_rmse {
            parts.push(format!(
                "the lowest RMSE reachable is {:.3} LSB (max error {}) with {}",
                c.errors.rmse,
                c.errors.max_any(),
                c.summary
            ));
        }
        format!(
            "no configuration meets {} on {scene} ({} configurations searched); {}",
            self.target.describe(),
            self.space,
            parts.join("; ")
        )
    }
}

pub enum Outcome {
    Found(Box<Decision>),
    Unreachable(Box<Unreachable>),
}

impl Decision {
    /// The decision as a text table: the choice, the runners-up, the nearest rejected
    /// candidates below it and the paper's design.
    pub fn table(&self) -> String {
        let cells = self.cost == CostKind::Cells;
        let mut s = String::new();
        s.push_str(&format!(
            "{:<14} {:<62} {:>7} {:>7} {:>7} {:>9}{}\n",
            "",
            "configuration",
            "max err",
            "RMSE",
            "colour",
            "bits",
            if cells { "     cells" } else { "" }
        ));
        let mut row = |label: &str, c: &Candidate| {
            let e = &c.errors;
            let lb = if e.complete { "" } else { ">=" };
            s.push_str(&format!(
                "{:<14} {:<62} {:>7} {:>7.3} {:>7} {:>9}{}{}\n",
                label,
                c.summary,
                format!("{lb}{}", e.max_abs_error),
                e.rmse,
                e.color_max_abs_error
                    .map_or("-".to_string(), |x| x.to_string()),
                c.bits,
                if cells {
                    format!(" {:>9}", c.cells.map_or("-".into(), |x| x.to_string()))
                } else {
                    String::new()
                },
                match (c.meets_target, c.fits) {
                    (false, _) => "  (misses)",
                    (true, Some(false)) => "  (does not fit)",
                    _ => "",
                }
            ));
        };
        row("chosen", &self.chosen);
        for (k, c) in self.runners_up.iter().enumerate() {
            row(&format!("runner-up {}", k + 1), c);
        }
        for c in &self.rejected_below {
            row("cheaper", c);
        }
        row("paper", &self.paper);
        s
    }
}
