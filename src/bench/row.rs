//! One measured row of the bench ([`Row`]): a design on a scene with one map fit, its error,
//! speed and cost. Separate because the Pareto marking, the tables and the plots all read it.

use crate::flow::fpga::Family;
use serde::Serialize;

/// One measured row.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub scene: String,
    /// A short name of the configuration (or the octahedral map).
    pub design: String,
    pub config: String,
    pub map_fit: String,
    pub entries: u32,
    pub max_abs_error: u32,
    pub rmse: f64,
    pub psnr_db: f64,
    pub msamples_1_thread: f64,
    pub msamples_all_cores: f64,
    /// All-core throughput over the float reference's, same inputs.
    pub float_ratio: f64,
    pub map_build_us: f64,
    /// Bits of the fixed ROMs (reciprocal, and the atan compensation ROM when it is one).
    pub rom_bits: u64,
    /// Bits the host loads per frame: the maps, and a loaded compensation table
    /// (`comp_table = ram`).
    pub map_bits: u64,
    /// The part after place and route (with the tools): logic cells, block RAMs, Fmax. The
    /// part is the iCE40 HX8K unless `family` says ECP5 (the LFE5U-85F); the names are the
    /// iCE40's because it is the default, whose output is as before `bench --family`.
    pub ice40_cells: Option<u32>,
    pub ice40_brams: Option<u32>,
    pub fmax_mhz: Option<f64>,
    /// The flow ran and the design does not fit the part (the cells, RAMs and Fmax are then
    /// None).
    pub ice40_too_big: bool,
    /// The family placed (`bench --family`); left out of bench.json for the iCE40.
    #[serde(skip_serializing_if = "is_default_family")]
    pub family: Family,
    /// Lanes of the placed design (`bench --lanes`); the error and model speed are the same
    /// for every lane. Left out of bench.json when 1.
    #[serde(skip_serializing_if = "is_one")]
    pub lanes: u32,
    /// DSP blocks of the placed design (ECP5 MULT18X18D; None on the iCE40 HX, which has
    /// none, and left out of bench.json then).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dsps: Option<u32>,
    pub pareto_cost: bool,
    pub pareto_speed: bool,
}

/// Whether `f` is the default family (left out of bench.json then).
fn is_default_family(f: &Family) -> bool {
    *f == Family::default()
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

impl Row {
    pub fn bits(&self) -> u64 {
        self.rom_bits + self.map_bits
    }

    /// Shaded samples per second of the placed design: lanes x post-route Fmax.
    pub fn samples_per_s(&self) -> Option<f64> {
        self.fmax_mhz.map(|f| f64::from(self.lanes) * f * 1e6)
    }

    /// Whether the FPGA columns are the default's (iCE40, one lane): the tables then have the
    /// columns they had before `bench --family` and `--lanes`.
    pub fn default_fpga(&self) -> bool {
        self.family == Family::default() && self.lanes == 1
    }
}
