//! Yosys: `synth_ice40` and `synth_ecp5` for place and route ([`synth_ice40`], [`synth_ecp5`]: what `rmapgen fpga`, bench and
//! `fit --cost cells` measure, and the netlist `rmapgen sim --gate` simulates) and the
//! synthesis check of `rmapgen synth` ([`check`]: no latch, the memories inferred, the cells
//! mapped for the iCE40 or to generic gates). Both run in the generated directory, so that
//! `$readmemh` finds the hex files, and write their logs, statistics and netlist to a log
//! directory, never into the design. [`ice40_cell_models`] finds the simulation models of the
//! iCE40 cells that Yosys ships, for simulating its netlist.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The log every run writes into its log directory.
pub const LOG: &str = "yosys.log";

/// `YOSYS`, else `yosys` ([`crate::family::YOSYS`]).
pub fn yosys() -> String {
    super::tool(&crate::family::YOSYS)
}

/// Whether Yosys runs (`yosys -V`).
pub fn available() -> bool {
    super::capture(Command::new(yosys()).arg("-V")).is_ok_and(|r| r.success())
}

/// `yosys -q -l LOGS/yosys.log -p SCRIPT`, run from `dir`.
fn command(dir: &Path, logs: &Path, script: &str) -> Command {
    let mut c = Command::new(yosys());
    c.args(["-q", "-l"])
        .arg(logs.join(LOG))
        .args(["-p", script])
        .current_dir(dir);
    c
}

/// What a family's synthesis pass (`synth_ice40`, `synth_ecp5`) mapped the design to, in the
/// family's cells ([`crate::family::Names`]).
#[derive(Clone, Debug, PartialEq)]
pub struct SynthStat {
    /// Every cell, each block RAM one.
    pub cells: u32,
    /// LUT4s (SB_LUT4; ECP5 LUT4, its PFUMX and L6MUX21 wide-function muxes not counted).
    pub luts: u32,
    /// Carry cells: SB_CARRY (one bit), ECP5 CCU2C (two bits).
    pub carries: u32,
    /// Flip-flops: SB_DFF* of every kind, TRELLIS_FF.
    pub flip_flops: u32,
    /// Block RAMs: SB_RAM40_4K, DP16KD, Gowin's BSRAM cells (SP, SDPB, DPB, their X9 forms).
    pub block_rams: u32,
    /// DSP multipliers: ECP5 MULT18X18D (0 on the iCE40 HX).
    pub dsps: u32,
}

/// The Verilog netlist [`synthesise`] writes for the iCE40 into its log directory `logs` for
/// `top`: `<top>_netlist.v`, a flat module `top` of iCE40 cells (SB_LUT4, SB_CARRY, SB_DFF*,
/// SB_RAM40_4K with the memories' contents in its INIT_0..INIT_F parameters).
pub fn netlist(logs: &Path, top: &str) -> PathBuf {
    logs.join(format!("{top}_netlist.v"))
}

/// `synth_ice40` for place and route and for `rmapgen sim --gate`: [`synthesise`] for the
/// iCE40, which also writes the netlist as Verilog ([`netlist`]).
pub fn synth_ice40(dir: &Path, top: &str, files: &[String], logs: &Path) -> Result<SynthStat> {
    synthesise(crate::family::Family::Ice40.get(), dir, top, files, logs)
}

/// `<synth pass> -top TOP` of `files` (names in `dir`) with the family's Yosys, for place and
/// route: the netlist `LOGS/<top>.json` for nextpnr, `yosys.log` and the statistics
/// `yosys_stat.txt` in `logs`, and for a family whose cells `sim --gate` simulates the same
/// netlist as Verilog ([`netlist`], `write_verilog -noattr`: no source attributes, so it is a
/// third of the size and simulators read only cells; the one that is placed and routed, from
/// the same run, at no measurable cost beside the synthesis). The flow `rmapgen fpga`, bench
/// and `fit --cost cells` measure (figures in docs/RESULTS.md come from it). Yosys runs in
/// `dir` (where `$readmemh` finds the hex files) and is given every path relative to it: the
/// YoWASP build maps a scratch directory of its own over /tmp.
pub fn synthesise(
    family: &crate::family::Descriptor,
    dir: &Path,
    top: &str,
    files: &[String],
    logs: &Path,
) -> Result<SynthStat> {
    let dir = dir
        .canonicalize()
        .with_context(|| format!("cannot read {}", dir.display()))?;
    let logs = &logs
        .canonicalize()
        .with_context(|| format!("cannot read {}", logs.display()))?;
    let rel = super::relative(&dir, logs);
    let verilog = if family.verilog_netlist {
        format!(
            " write_verilog -noattr {};",
            super::relative(&dir, &netlist(logs, top)).display()
        )
    } else {
        String::new()
    };
    let pass = family.synth_pass;
    let script = format!(
        "read_verilog {}; {pass} -top {top} -json {};{verilog} tee -q -o {} stat",
        files.join(" "),
        rel.join(format!("{top}.json")).display(),
        rel.join("yosys_stat.txt").display()
    );
    let mut c = Command::new(super::tool(&family.yosys));
    c.args(["-q", "-l"])
        .arg(rel.join(LOG))
        .args(["-p", &script])
        .current_dir(&dir);
    let mut ran = super::capture(&mut c)?;
    let log = || std::fs::read_to_string(logs.join(LOG)).unwrap_or_default();
    if !ran.success() && abc_aborted(&format!("{}\n{}", log(), ran.output)) {
        // Debian's berkeley-abc has aborted now and then under load (seen once in make test, on
        // a design that synthesised in every run before and after): once more, and said.
        crate::errln!(
            "rmapgen: Yosys's ABC aborted (return code 134) in {}; synthesising once more",
            family.synth_pass
        );
        ran = super::capture(&mut c)?;
    }
    stat_of(ran, family, logs)
}

/// Whether a failed Yosys run's output says that ABC aborted (SIGABRT: return code 134),
/// rather than failed on the design.
fn abc_aborted(output: &str) -> bool {
    output
        .lines()
        .any(|l| l.contains("ABC: execution of command") && l.contains("failed: return code 134"))
}

/// Whether the family's Yosys runs (`-V`).
pub fn available_for(family: &crate::family::Descriptor) -> bool {
    super::capture(Command::new(super::tool(&family.yosys)).arg("-V")).is_ok_and(|r| r.success())
}

/// The statistics a synthesis run for place and route wrote to `logs/yosys_stat.txt`, or the
/// error quoting Yosys's complaint.
fn stat_of(ran: super::Ran, family: &crate::family::Descriptor, logs: &Path) -> Result<SynthStat> {
    if !ran.success() {
        let log = std::fs::read_to_string(logs.join(LOG)).unwrap_or_default();
        bail!(
            "yosys {} failed: {}",
            family.synth_pass,
            super::complaint(&format!("{log}\n{}", ran.output))
        );
    }
    let stat = logs.join("yosys_stat.txt");
    let text = std::fs::read_to_string(&stat)
        .with_context(|| format!("cannot read {}", stat.display()))?;
    let counts = cell_counts(&text);
    let n = &family.names;
    let sum = |is: &dyn Fn(&str) -> bool| -> u32 {
        counts.iter().filter(|(t, _)| is(t)).map(|c| c.1).sum()
    };
    let one_of = |names: &'static [&'static str]| move |t: &str| names.contains(&t);
    // stat prints the top module last; the flat netlist has only the top.
    Ok(SynthStat {
        cells: last_number(&text, "Number of cells:")
            .or_else(|| counts.iter().rev().find(|c| c.0 == "cells").map(|c| c.1))
            .context("yosys printed no cell count")?,
        luts: last_count(&counts, one_of(n.luts)),
        carries: last_count(&counts, one_of(n.carries)),
        flip_flops: sum(&|t| n.flip_flops.iter().any(|p| t.starts_with(p))),
        block_rams: last_count(&counts, |t| family.block_ram.cells.contains(&t)),
        dsps: last_count(&counts, one_of(n.dsps)),
    })
}

/// The file of Yosys's simulation models of the iCE40 cells, relative to its data directory.
pub const ICE40_CELL_MODELS: &str = "ice40/cells_sim.v";

/// Yosys's simulation models of the iCE40 cells (`<datdir>/ice40/cells_sim.v`), what a
/// simulator needs beside a [`netlist`]. The data directory is YOSYS_DATDIR when set, else what
/// `yosys-config --datdir` prints (Debian ships `yosys-config` only in yosys-dev), else
/// `../share/yosys` beside the Yosys program (YOSYS, else `yosys` on PATH, links followed),
/// where Yosys itself looks for it. An error names the places tried.
pub fn ice40_cell_models() -> Result<PathBuf> {
    let mut tried = Vec::new();
    let env = std::env::var_os("YOSYS_DATDIR").filter(|v| !v.is_empty());
    let config = || {
        super::child::output(Command::new("yosys-config").arg("--datdir"))
            .ok()
            .filter(|o| o.status.success())
            .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()))
    };
    let beside = || {
        let exe = super::locate(&yosys())?.canonicalize().ok()?;
        Some(exe.parent()?.parent()?.join("share/yosys"))
    };
    let candidates: Vec<PathBuf> = match env {
        Some(d) => vec![PathBuf::from(d)],
        None => config().into_iter().chain(beside()).collect(),
    };
    for d in candidates {
        let f = d.join(ICE40_CELL_MODELS);
        if f.is_file() {
            return Ok(f);
        }
        tried.push(f.display().to_string());
    }
    bail!(
        "cannot find Yosys's iCE40 cell models ({ICE40_CELL_MODELS}){}; set YOSYS_DATDIR to Yosys's data directory (yosys-config --datdir)",
        if tried.is_empty() {
            " (no yosys-config, no yosys on PATH)".to_string()
        } else {
            format!(": not at {}", tried.join(", "))
        }
    )
}

/// What [`check`] maps the design to after its checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// `synth_ice40`, also writing the netlist `<top>.json`.
    Ice40,
    /// Yosys's own `synth` without its memory mapping: memories stay memory cells (`$mem_v2`),
    /// as an ASIC flow maps them to SRAM macros, so any width can be checked, also designs far
    /// larger than an FPGA; everything else goes to generic gates.
    Generic,
}

/// What [`check`] found.
#[derive(Clone, Debug)]
pub struct Check {
    /// Yosys exited 0: no latch and the synthesis ran through.
    pub passed: bool,
    /// The log, for people.
    pub log: PathBuf,
    /// The log's lines with `ERROR`, `Assertion` or `Warning` (what went wrong, on failure).
    pub problems: Vec<String>,
    /// The final statistics from `Number of cells` on.
    pub cells_report: String,
    pub cells: u32,
    /// Memory bits before memory mapping.
    pub memory_bits: u64,
    /// SB_RAM40_4K block RAMs (iCE40) or `$mem_v2` memories kept (generic).
    pub memories: u32,
}

/// The synthesis check of a generated design: `read_verilog FILES; hierarchy -check -top TOP;
/// proc; flatten`, the memory statistics, `select -assert-none` on every kind of latch (`proc`
/// turns an incomplete combinational assignment into one), then `flow`, its cell statistics
/// and (generic) `check -assert`. Logs and statistics go to `logs`. A failure of Yosys is a
/// [`Check`] with `passed` false; an error only when Yosys cannot run.
pub fn check(dir: &Path, top: &str, files: &[String], logs: &Path, flow: Flow) -> Result<Check> {
    let memory = logs.join("memory.txt");
    let cells = logs.join("cells.txt");
    let front = format!(
        "read_verilog {}; hierarchy -check -top {top}; proc; flatten;
tee -q -o {} stat;
select -assert-none t:$dlatch t:$adlatch t:$dlatchsr t:$_DLATCH_* t:$_DLATCHSR_*;",
        files.join(" "),
        memory.display()
    );
    let script = match flow {
        // synth's own script without memory_map: the coarse pass infers the memories, the
        // fine steps map everything else to gates.
        Flow::Generic => format!(
            "{front}
synth -top {top} -run coarse:fine;
opt -fast -full; opt -full; techmap; opt -fast; abc -fast; opt -fast;
tee -q -o {} stat; check -assert",
            cells.display()
        ),
        Flow::Ice40 => format!(
            "{front}
synth_ice40 -top {top} -json {};
tee -q -o {} stat",
            logs.join(format!("{top}.json")).display(),
            cells.display()
        ),
    };
    let ran = super::capture(&mut command(dir, logs, &script))?;
    let log = logs.join(LOG);
    if !ran.success() {
        let text = std::fs::read_to_string(&log)
            .ok()
            .filter(|t| !t.is_empty())
            .unwrap_or(ran.output);
        let problems = text
            .lines()
            .filter(|l| {
                ["ERROR", "Assertion", "Warning"]
                    .iter()
                    .any(|w| l.contains(w))
            })
            .map(String::from)
            .collect();
        return Ok(Check {
            passed: false,
            log,
            problems,
            cells_report: String::new(),
            cells: 0,
            memory_bits: 0,
            memories: 0,
        });
    }
    let read = |p: &Path| {
        std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))
    };
    let (memory_text, cells_text) = (read(&memory)?, read(&cells)?);
    let counts = cell_counts(&cells_text);
    let kind = match flow {
        Flow::Ice40 => "SB_RAM40_4K",
        Flow::Generic => "$mem_v2",
    };
    Ok(Check {
        passed: true,
        log,
        problems: Vec::new(),
        cells_report: cells_text
            .find("Number of cells")
            .map(|i| {
                let start = cells_text[..i].rfind('\n').map_or(0, |n| n + 1);
                cells_text[start..].to_string()
            })
            .unwrap_or_default(),
        cells: last_number(&cells_text, "Number of cells:")
            .context("yosys printed no cell count")?,
        memory_bits: memory_text
            .lines()
            .find_map(|l| l.trim().strip_prefix("Number of memory bits:"))
            .and_then(|n| n.trim().parse().ok())
            .context("yosys printed no memory bit count")?,
        memories: last_count(&counts, |t| t == kind),
    })
}

/// The value of the last `label N` line.
fn last_number(text: &str, label: &str) -> Option<u32> {
    text.lines()
        .rev()
        .find_map(|l| l.trim().strip_prefix(label))
        .and_then(|n| n.trim().parse().ok())
}

/// Every `TYPE N` line of `stat` output (Yosys 0.23), or `N TYPE` (Yosys 0.70: `219 CCU2C`,
/// `2594 cells`), in order.
fn cell_counts(text: &str) -> Vec<(String, u32)> {
    text.lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            let (a, b) = (w.next()?, w.next()?);
            if w.next().is_some() {
                return None;
            }
            match (a.parse::<u32>(), b.parse::<u32>()) {
                (Err(_), Ok(n)) => Some((a.to_string(), n)),
                (Ok(n), Err(_)) => Some((b.to_string(), n)),
                _ => None,
            }
        })
        .collect()
}

/// The cells of the types `is` accepts (0 if none), each type's last count summed: stat prints
/// the top module last, and a family may map one kind to several types (Gowin's LUT1 to LUT4,
/// its BSRAM cells).
fn last_count(counts: &[(String, u32)], is: impl Fn(&str) -> bool) -> u32 {
    let mut seen: Vec<&str> = Vec::new();
    let mut total = 0;
    for (t, n) in counts.iter().rev() {
        if is(t) && !seen.contains(&t.as_str()) {
            seen.push(t);
            total += n;
        }
    }
    total
}

/// The netlists `rmapgen prove` reads the design's structure from, written by Yosys into
/// `logs` from `files` (names in `dir`): `hier.json`, the top with its instances after
/// `proc`, and `flat.json`, the whole design flattened, its memories as `proc` leaves them
/// (`$memrd_v2` asynchronous reads, their data registers `$dff`s as the RTL writes them,
/// `$memwr_v2` write ports), registers as `$dff`-family cells whose hold multiplexers became
/// enables (`opt_dff`; `-nosdff`, so that no data multiplexer becomes a synchronous reset).
/// No memory pass runs: `memory_dff` would fold the data registers into the reads and
/// rewrite their enables as address multiplexers.
///
/// The three netlists: the hierarchy (`hier.json`), the flattened design with constants
/// folded but every register as `proc` wrote it (`folded.json`: a register that is never
/// loaded still has its D wired to its own Q there, where `opt_dff` would replace it by its
/// undefined power-up value), and the flattened design after `opt_dff` (`flat.json`).
pub fn structure(dir: &Path, top: &str, files: &[String], logs: &Path) -> Result<Structure> {
    crate::disk::create_dir_all(logs)?;
    let out = Structure {
        hier: logs.join("hier.json"),
        folded: logs.join("folded.json"),
        flat: logs.join("flat.json"),
    };
    let script = format!(
        "read_verilog {}; hierarchy -check -top {top}; proc; opt_clean; write_json {}; \
         flatten; opt_expr; opt_clean; write_json {}; opt_dff -nosdff; opt_clean; write_json {}",
        files.join(" "),
        super::quoted(&out.hier.to_string_lossy()),
        super::quoted(&out.folded.to_string_lossy()),
        super::quoted(&out.flat.to_string_lossy()),
    );
    let ran = super::run_logged(&mut command(dir, logs, &script), &logs.join("yosys.out"))?;
    if !ran.success() {
        bail!(
            "Yosys could not read the design's structure ({}): {}",
            ran.exit(),
            super::complaint(&ran.output)
        );
    }
    Ok(out)
}

/// The netlists [`structure`] writes.
pub struct Structure {
    pub hier: PathBuf,
    pub folded: PathBuf,
    pub flat: PathBuf,
}

/// The files [`aig`] writes into its directory: the graph and the map of its inputs and
/// outputs.
pub const AIG_FILES: (&str, &str) = ("front.aag", "front.map");

/// The and-inverter graph `rmapgen prove`'s gate-level front evaluates: `top` (a wrapper
/// around design modules, from `files`, absolute paths) with every flip-flop made a wire from
/// D to Q by the techmap file `transparent` (a file name in `logs`: what the value would be at
/// an enabled clock edge without reset), mapped to AND and NOT gates and written as ASCII
/// AIGER with its map (`front.aag`, `front.map` in `logs`, where Yosys runs: `write_aiger`
/// takes its file names unquoted).
///
/// `opt_expr -mux_undef` takes the undefined inputs of multiplexers as "any value": `proc`
/// writes `x` as the default of a variable an `always @*` block assigns on every path, into
/// a multiplexer input no path selects, and AIGER has no `x`. Nothing else is optimised
/// before the gates: the graph is the generated logic as Yosys reads it.
pub fn aig(
    top: &str,
    files: &[String],
    transparent: &str,
    logs: &Path,
) -> Result<(PathBuf, PathBuf)> {
    crate::disk::create_dir_all(logs)?;
    let (aag, map) = AIG_FILES;
    let script = format!(
        "read_verilog {}; hierarchy -check -top {top}; proc; opt_expr -mux_undef; flatten; \
         opt_clean; opt_dff; techmap -map {transparent}; opt_expr -mux_undef; opt_clean; \
         techmap; opt_expr -mux_undef; opt_clean; aigmap; opt_clean; \
         write_aiger -ascii -map {map} {aag}",
        files.join(" "),
    );
    let ran = super::run_logged(&mut command(logs, logs, &script), &logs.join("yosys.out"))?;
    if !ran.success() {
        bail!(
            "Yosys could not map the front to gates ({}): {}",
            ran.exit(),
            super::complaint(&ran.output)
        );
    }
    Ok((logs.join(aag), logs.join(map)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_an_abc_abort_is_taken_for_one() {
        assert!(abc_aborted(
            "x\nERROR: ABC: execution of command \"/usr/bin/yosys-abc -s -f /tmp/yosys-abc-X/abc.script\" failed: return code 134.\n"
        ));
        assert!(!abc_aborted(
            "ERROR: ABC: execution of command \"yosys-abc\" failed: return code 1.\n"
        ));
        assert!(!abc_aborted(
            "ERROR: Module `foo' not found!\nreturn code 134\n"
        ));
    }

    #[test]
    fn statistics_are_read_as_yosys_prints_them() {
        let text = "=== rmap_top ===\n\n   Number of memory bits:        37120\n   Number of cells:               2478\n     SB_CARRY                      376\n     SB_DFF                        825\n     SB_DFFR                        25\n     SB_LUT4                      1182\n     SB_RAM40_4K                    11\n";
        let c = cell_counts(text);
        assert_eq!(last_number(text, "Number of cells:"), Some(2478));
        assert_eq!(last_count(&c, |t| t == "SB_RAM40_4K"), 11);
        assert_eq!(last_count(&c, |t| t == "$mem_v2"), 0);
        let ffs: u32 = c
            .iter()
            .filter(|x| x.0.starts_with("SB_DFF"))
            .map(|x| x.1)
            .sum();
        assert_eq!(ffs, 850);
        // Yosys 0.70 (the venv's, synth_ecp5) puts the count first.
        let text = "=== rmap_top ===\n        +----------Local Count, excluding submodules.\n        | \n     2351 wires\n     2594 cells\n      219   CCU2C\n        4   DP16KD\n     1116   LUT4\n      959   TRELLIS_FF\n";
        let c = cell_counts(text);
        assert_eq!(last_count(&c, |t| t == "cells"), 2594);
        assert_eq!(last_count(&c, |t| t == "DP16KD"), 4);
        assert_eq!(last_count(&c, |t| t == "LUT4"), 1116);
        assert_eq!(last_number(text, "Number of cells:"), None);
    }
}
