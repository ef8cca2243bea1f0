//! nextpnr-ice40: places and routes a Yosys `synth_ice40` netlist on an iCE40.

use std::path::Path;
use std::process::Command;

/// `NEXTPNR`, else `nextpnr-ice40`.
pub fn nextpnr() -> String {
    super::program("NEXTPNR", "nextpnr-ice40")
}

/// Whether nextpnr-ice40 runs (`--version`).
pub fn available() -> bool {
    Command::new(nextpnr())
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The part and what the placer aims at.
#[derive(Clone, Copy, Debug)]
pub struct Target<'a> {
    /// The device flag without its dashes: hx8k, hx4k, up5k, ...
    pub device: &'a str,
    /// ct256, tq144, sg48, ...
    pub package: &'a str,
    pub freq_mhz: f64,
    pub seed: u64,
}

/// `nextpnr-ice40 --DEVICE --package PACKAGE` without a design: nextpnr checks the device and
/// package names in milliseconds and fails on one it does not know.
pub fn check_part(t: &Target) -> Command {
    let mut c = Command::new(nextpnr());
    c.arg(format!("--{}", t.device))
        .args(["--package", t.package]);
    c
}

/// `nextpnr-ice40 --DEVICE --package PACKAGE --json JSON --asc ASC --freq MHZ --seed S
/// --timing-allow-fail --report REPORT --log LOG`: a missed target is a figure in the log, not
/// a failure.
pub fn place_and_route(t: &Target, json: &Path, asc: &Path, report: &Path, log: &Path) -> Command {
    let mut c = check_part(t);
    c.arg("--json")
        .arg(json)
        .arg("--asc")
        .arg(asc)
        .args(["--freq", &t.freq_mhz.to_string()])
        .args(["--seed", &t.seed.to_string()])
        .arg("--timing-allow-fail")
        .arg("--report")
        .arg(report)
        .arg("--log")
        .arg(log);
    c
}
