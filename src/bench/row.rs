//! One measured row of the bench ([`Row`]): a design on a scene with one map fit, its error,
//! speed and cost. Separate because the Pareto marking, the tables and the plots all read it.

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
    pub rom_bits: u64,
    pub map_bits: u64,
    /// iCE40 HX8K after place and route: logic cells, block RAMs, Fmax (with the tools).
    pub ice40_cells: Option<u32>,
    pub ice40_brams: Option<u32>,
    pub fmax_mhz: Option<f64>,
    /// The flow ran and the design does not fit the HX8K (the cells, RAMs and Fmax are then
    /// None).
    pub ice40_too_big: bool,
    pub pareto_cost: bool,
    pub pareto_speed: bool,
}

impl Row {
    pub fn bits(&self) -> u64 {
        self.rom_bits + self.map_bits
    }
}
