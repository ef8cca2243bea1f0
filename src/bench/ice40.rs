//! The iCE40 figures of the bench's configurations: each design placed and routed on the
//! HX8K when Yosys and nextpnr-ice40 are installed. Separate because it is the bench's one
//! step that runs outside tools.

use crate::config::Config;
use crate::rtl::fpga::{self, FpgaReport};
use anyhow::Result;
use rayon::prelude::*;

/// What the iCE40 flow gave for one configuration.
#[derive(Clone, Debug)]
pub enum Ice40 {
    /// Yosys or nextpnr-ice40 is not installed (or the flow was not asked for).
    NotRun,
    /// The design needs more of the device than it has (nextpnr's complaint).
    DoesNotFit(String),
    Placed(Box<FpgaReport>),
}

/// The iCE40 figures of each configuration (in parallel, one flow per core); `NotRun` for
/// all when Yosys or nextpnr-ice40 is missing. A design too big for the HX8K is a figure, any
/// other failure an error.
pub fn ice40_figures(configs: &[Config]) -> Result<Vec<Ice40>> {
    let opts = fpga::Options::default();
    if !fpga::tools_available(&opts) {
        return Ok(vec![Ice40::NotRun; configs.len()]);
    }
    configs
        .par_iter()
        .map(|c| match fpga::ice40_report(c, &opts) {
            Ok(r) => Ok(Ice40::Placed(Box::new(r))),
            Err(e) => match e.downcast_ref::<fpga::DoesNotFit>() {
                Some(d) => Ok(Ice40::DoesNotFit(d.message.clone())),
                None => Err(e.context(format!("iCE40 flow of {}", c.summary()))),
            },
        })
        .collect()
}
