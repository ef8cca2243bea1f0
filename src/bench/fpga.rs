//! The FPGA figures of the bench's configurations: each design placed and routed on the
//! family's default part (iCE40 HX8K, or ECP5-85F with `--family ecp5`), with `lanes` lanes,
//! when the family's Yosys and nextpnr are installed. Separate because it is the bench's one
//! step that runs outside tools.

use crate::config::Config;
use crate::flow::fpga::{self, Family, FpgaReport};
use anyhow::Result;
use rayon::prelude::*;

/// What the FPGA flow gave for one configuration.
#[derive(Clone, Debug)]
pub enum Flow {
    /// The family's Yosys or nextpnr is not installed (or the flow was not asked for).
    NotRun,
    /// The design needs more of the device than it has (nextpnr's complaint).
    DoesNotFit(String),
    Placed(Box<FpgaReport>),
}

/// The FPGA figures of each configuration built with `lanes` lanes on `family`'s default part
/// (in parallel, one flow per core), in context as `rmapgen fpga` places it; `NotRun` for all
/// when the family's tools are missing. A design too big for the part (its pins included) is
/// a figure, any other failure an error.
pub fn figures(configs: &[Config], family: Family, lanes: u32) -> Result<Vec<Flow>> {
    let opts = fpga::Options::for_family(family);
    if !fpga::tools_available(&opts) {
        return Ok(vec![Flow::NotRun; configs.len()]);
    }
    configs
        .par_iter()
        .map(|c| {
            let c = Config { lanes, ..c.clone() };
            match fpga::report(&c, &opts) {
                Ok(r) => Ok(Flow::Placed(Box::new(r))),
                Err(e) => match e.downcast_ref::<fpga::DoesNotFit>() {
                    Some(d) => Ok(Flow::DoesNotFit(d.message.clone())),
                    None => Err(e.context(format!("{} flow of {}", family.title(), c.summary()))),
                },
            }
        })
        .collect()
}
