//! Runs the self-checking testbenches of a generated design under Icarus Verilog and
//! Verilator, the Verilator C++ harness `tb/top_stream.cpp` on a long random stream of
//! top vectors, and the top's testbench on the gate-level netlist of Yosys `synth_ice40`
//! (`rmapgen sim`, the Makefile's sim targets and gate-sim).
//!
//! The gate-level run (`--gate`) synthesises the top as `rmapgen fpga` does
//! ([`yosys::synth_ice40`], one flat netlist of iCE40 cells, written with `write_verilog
//! -noattr`) and compiles the top's testbench, unchanged, with that netlist and Yosys's iCE40
//! cell models in place of the design files ([`icarus::compile_gate`]). The testbench reaches
//! the design through its ports only, so it runs on the flat netlist as on the RTL. It is
//! the check that synthesis kept the behaviour: the block RAMs' contents taken from the
//! `$readmemh` files at synthesis, their read and write ports, the reset and the flip-flops'
//! start.
//!
//! Simulations run in the build directory, never in the design directory: every file a
//! testbench or the design reads is passed as an absolute path (the testbench's file
//! parameters, which it hands to the top's init-file parameters, and `+vectors=`), as an
//! integrator's simulation from another directory would. A run passes when the simulator exits 0 and its last line is `N
//! passed, 0 failed` with N > 0: the testbenches print that verdict last, and both simulators
//! exit 1 on `$stop` and `$fatal`, so either check alone could be fooled by a crash or by a
//! testbench that ran nothing. A failure is reported with the command and the last lines of
//! its output, and the other runs go on; [`Outcome::failed`] lists them.

pub mod verilated;

use crate::design_dir::DesignDir;
use crate::model::map_set::{buffer_names, map_file};
use crate::stages::TOP;
use crate::toolchain::{self, icarus, verilator, yosys, Ran};
use crate::vectors::{self, MapSet};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The harness's source: one sample a clock, every output checked (and random backpressure
/// with the handshake).
const HARNESS: &str = include_str!("../../tb/top_stream.cpp");

/// Lines of a failed step's output shown.
const FAIL_TAIL: usize = 60;

/// Seed of the random streams: `rmapgen vectors`' default, so a stream here equals the file
/// `rmapgen vectors --maps DIR --count N` writes.
pub const STREAM_SEED: u64 = 1;

/// What to run.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Every testbench under Icarus.
    pub icarus: bool,
    /// Every testbench under Verilator.
    pub verilator: bool,
    /// Random top vectors through the C++ harness (0: no harness run).
    pub stream: u64,
    /// Random top vectors also through the top's testbench in each simulator selected (0: none).
    pub tb_stream: u64,
    /// Only the testbench of this module.
    pub only: Option<String>,
    /// A VCD of each Icarus testbench run, into the build directory.
    pub vcd: bool,
    /// The top's testbench on the gate-level netlist in Icarus (and on the `tb_stream`).
    pub gate: bool,
    /// With `gate`: simulate this netlist (a `write_verilog` of `synth_ice40`) instead of
    /// synthesising the design.
    pub netlist: Option<PathBuf>,
}

impl Options {
    /// Whether anything would run.
    pub fn runs_something(&self) -> bool {
        self.icarus || self.verilator || self.gate || self.stream > 0
    }

    /// The programs the runs need that cannot be found, by name.
    pub fn missing_tools(&self) -> Vec<String> {
        let mut need = Vec::new();
        if self.icarus || self.gate {
            need.extend([icarus::iverilog(), icarus::vvp()]);
        }
        if self.gate && self.netlist.is_none() {
            need.push(yosys::yosys());
        }
        if self.verilator || self.stream > 0 {
            need.push(verilator::verilator());
        }
        need.retain(|p| !toolchain::installed(p));
        need
    }

    /// Bytes of the vector streams written into the build directory for `design`.
    pub fn stream_bytes(&self, design: &DesignDir) -> u64 {
        let cfg = &design.config;
        let tb = if self.icarus || self.verilator || self.gate {
            self.tb_stream
        } else {
            0
        };
        [self.stream, tb]
            .iter()
            .filter(|&&n| n > 0)
            .map(|&n| vectors::top_stream_bytes(cfg, n))
            .fold(0u64, u64::saturating_add)
    }
}

/// A run that passed.
#[derive(Clone, Debug)]
pub struct Passed {
    pub name: String,
    pub vectors: u64,
    /// Vectors a second, wall clock.
    pub rate: f64,
}

/// What the runs gave.
#[derive(Clone, Debug, Default)]
pub struct Outcome {
    pub passed: Vec<Passed>,
    /// The names of the steps that failed (`icarus rmap_top_tb`, `verilator sort_shift_tb
    /// (build)`, ...).
    pub failed: Vec<String>,
}

impl Outcome {
    /// The closing report: the configuration, every passed run's vectors and rate, and the
    /// verdict.
    pub fn summary(&self, design: &DesignDir) -> String {
        let mut s = format!("---- {}: {}\n", design.name(), design.config.summary());
        for p in &self.passed {
            s += &format!(
                "  {:<30} {:>9} vectors  {:>10.0} vectors/s\n",
                p.name, p.vectors, p.rate
            );
        }
        let dir = design.path().display();
        if self.failed.is_empty() {
            s += &format!("sim: all passed in {dir}\n");
        } else {
            s += &format!("sim: {} FAILED in {dir}:\n", self.failed.len());
            for f in &self.failed {
                s += &format!("  {f}\n");
            }
        }
        s
    }
}

/// The vector count of a passing verdict, `N passed, 0 failed` with N > 0.
pub fn passed_count(verdict: &str) -> Option<u64> {
    let n = verdict.strip_suffix(" passed, 0 failed")?;
    if n.is_empty() || !n.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    n.parse().ok().filter(|&n| n > 0)
}

/// Where a run reports: the lines of each finished step, and the step now starting (for a
/// progress display; nothing by default).
pub trait Report {
    fn say(&mut self, line: &str);
    fn starting(&mut self, _step: &str) {}
}

/// A closure that takes the lines (and no progress).
impl<F: FnMut(&str)> Report for F {
    fn say(&mut self, line: &str) {
        self(line)
    }
}

/// Runs what `opts` asks for on `design`, with build products and logs in `build` (created if
/// missing); `shown` is the name messages give `build` (where it will be moved to). Each step
/// is reported through `say`, a line at a time, and announced as it starts; a failed
/// simulation is in the outcome, an error only what stops the runs (a file that cannot be
/// written, a tool that cannot start).
pub fn run(
    design: &DesignDir,
    build: &Path,
    shown: &Path,
    opts: &Options,
    say: &mut dyn Report,
) -> Result<Outcome> {
    // The shading pipeline's top (inside rmap_axis with `axis`): its testbench takes the
    // long stream and the C++ harness drives it.
    let top = TOP.module(&design.config);
    let top_tb = format!("{top}_tb");
    let tbs = match &opts.only {
        Some(m) if design.testbench(m).is_file() => vec![format!("{m}_tb")],
        Some(m) => anyhow::bail!(
            "--only {m}: no testbench {} in {}",
            design.testbench(m).display(),
            design.path().display()
        ),
        None => design.testbenches()?,
    };
    let mut r = Runner {
        design,
        build: build.to_path_buf(),
        shown: shown.to_string_lossy().into_owned(),
        say,
        outcome: Outcome::default(),
    };
    // The testbenches that read the top's vectors, and so take the stream: the top's, and
    // the lanes top's (rmap_lanes reads the same file).
    let streamed = |m: &String| *m == top_tb || *m == format!("{}_tb", design.top);
    let simulating = opts.icarus || opts.verilator || opts.gate;
    let tb_stream = if opts.tb_stream > 0 && simulating && tbs.iter().any(streamed) {
        Some(r.stream(opts.tb_stream, "tb_stream.hex")?)
    } else {
        None
    };
    let stream_arg = |p: &Path| format!("+vectors={}", p.display());
    for m in &tbs {
        let mut files = vec![design.path().join("tb").join(format!("{m}.v"))];
        files.extend(design.files());
        let (strings, vectors) = design.testbench_files(m)?;
        if opts.icarus {
            let dir = r.dir("icarus")?;
            let vvp = dir.join(format!("{m}.vvp"));
            let log = dir.join(format!("{m}.compile.log"));
            if let Some(ran) = r.step(
                &format!("icarus {m} (compile)"),
                &mut icarus::compile(m, &vvp, &files, &strings),
                &log,
            )? {
                for l in ran.output.lines() {
                    r.say(&format!("  iverilog: {l}"));
                }
                let mut args = vec![stream_arg(&vectors)];
                let vcd = dir.join(format!("{m}.vcd"));
                if opts.vcd {
                    args.push(format!("+vcd={}", vcd.display()));
                }
                let run = icarus::simulate(&dir, &vvp, &args);
                if r.simulation(&format!("icarus {m}"), run, &dir.join(format!("{m}.log")))?
                    && opts.vcd
                {
                    let vcd = r.show(&vcd.display().to_string());
                    r.say(&format!("  vcd: {vcd}"));
                }
                if let (true, Some(s)) = (streamed(m), &tb_stream) {
                    let run = icarus::simulate(&dir, &vvp, &[stream_arg(s)]);
                    let log = dir.join(format!("{m}.stream.log"));
                    r.simulation(&format!("icarus {m} (stream)"), run, &log)?;
                }
            }
        }
        if opts.verilator {
            let mdir = r.dir(&format!("verilator/{m}"))?;
            let build_cmd = &mut verilator::binary(m, &mdir, &files, &strings)?;
            let name = format!("verilator {m} (build)");
            if r.step(&name, build_cmd, &mdir.join("build.log"))?.is_some() {
                let exe = mdir.join(verilator::BINARY_EXE);
                let run = executable(&mdir, &exe, &[stream_arg(&vectors)]);
                r.simulation(&format!("verilator {m}"), run, &mdir.join("run.log"))?;
                if let (true, Some(s)) = (streamed(m), &tb_stream) {
                    let run = executable(&mdir, &exe, &[stream_arg(s)]);
                    let log = mdir.join("stream.log");
                    r.simulation(&format!("verilator {m} (stream)"), run, &log)?;
                }
            }
        }
    }
    if opts.gate {
        r.gate(opts.netlist.as_deref(), tb_stream.as_deref())?;
    }
    if opts.stream > 0 {
        let sdir = r.dir("verilator/top_stream")?;
        let vec = r.stream(opts.stream, "top_stream.hex")?;
        let harness = sdir.join("top_stream.cpp");
        std::fs::write(&harness, HARNESS)
            .with_context(|| format!("cannot write {}", harness.display()))?;
        let mut build_cmd = verilator::harness(
            &top,
            &sdir,
            "top_stream",
            &design.files(),
            &harness,
            &design.path().join("tb"),
            &design.top_files()?,
        );
        let name = "verilator top_stream (build)";
        if r.step(name, &mut build_cmd, &sdir.join("build.log"))?
            .is_some()
        {
            let exe = sdir.join("top_stream");
            // The harness loads the design's second map through the host port
            // (tb/top_stream.cpp): its files by name, as the configuration (prefix) has them.
            let mut args = vec![vec.display().to_string()];
            args.extend(buffer_names(&design.config).iter().map(|a| {
                let f = map_file(&design.config, 1, a);
                design.path().join(f).display().to_string()
            }));
            let run = executable(design.path(), &exe, &args);
            r.simulation("verilator top_stream (C++)", run, &sdir.join("run.log"))?;
        }
    }
    Ok(r.outcome)
}

/// A built simulation executable with its arguments, run from `dir`.
fn executable(dir: &Path, exe: &Path, args: &[String]) -> Command {
    let mut c = Command::new(exe);
    c.args(args).current_dir(dir);
    c
}

struct Runner<'a> {
    design: &'a DesignDir,
    build: PathBuf,
    shown: String,
    say: &'a mut dyn Report,
    outcome: Outcome,
}

impl Runner<'_> {
    fn say(&mut self, line: &str) {
        self.say.say(line)
    }

    /// `text` with the build directory named as it will be after the run.
    fn show(&self, text: &str) -> String {
        text.replace(&*self.build.to_string_lossy(), &self.shown)
    }

    /// The build subdirectory `rel`, made.
    fn dir(&self, rel: &str) -> Result<PathBuf> {
        let d = self.build.join(rel);
        std::fs::create_dir_all(&d).with_context(|| format!("cannot create {}", d.display()))?;
        Ok(d)
    }

    /// `count` random top vectors for the design's configuration and maps into the build
    /// directory's `file`.
    fn stream(&mut self, count: u64, file: &str) -> Result<PathBuf> {
        let cfg = &self.design.config;
        let maps = MapSet::from_dir(cfg, self.design.path())?;
        let path = self.build.join(file);
        let random = usize::try_from(count).context("the stream does not fit in memory")?;
        vectors::write_top_stream(cfg, &maps, &path, random, STREAM_SEED)?;
        Ok(path)
    }

    /// Reports a failed step: its name, why, the command and the tail of its output.
    fn fail(&mut self, headline: &str, name: &str, cmd: &Command, ran: &Ran) {
        let command = self.show(&toolchain::shell_line(cmd));
        self.say(headline);
        self.say(&format!("  command: {command}"));
        for l in toolchain::tail(&ran.output, FAIL_TAIL) {
            self.say(&format!("  | {l}"));
        }
        self.outcome.failed.push(name.to_string());
    }

    /// The gate-level run: `netlist`, else the design synthesised with `synth_ice40` into
    /// `gate/`, compiled with the top's testbench and the iCE40 cell models, run on the top's
    /// vectors and on `stream` when given.
    fn gate(&mut self, netlist: Option<&Path>, stream: Option<&Path>) -> Result<()> {
        let design = self.design;
        let dir = self.dir("gate")?;
        let m = format!("{}_tb", design.top);
        let cells = yosys::ice40_cell_models()?;
        let netlist = match netlist {
            Some(n) => n.to_path_buf(),
            None => {
                let name = "gate yosys synth_ice40";
                self.say.starting(name);
                let t0 = std::time::Instant::now();
                match yosys::synth_ice40(design.path(), &design.top, design.file_names(), &dir) {
                    Ok(st) => self.say(&format!(
                        "ok:   {name}: {} cells ({} SB_LUT4, {} SB_CARRY, {} flip-flops, {} SB_RAM40_4K) in {:.1} s",
                        st.cells,
                        st.luts,
                        st.carries,
                        st.flip_flops,
                        st.block_rams,
                        t0.elapsed().as_secs_f64()
                    )),
                    Err(e) => {
                        let why = self.show(&format!("{e:#}"));
                        self.say(&format!("FAIL: {name}: {why}"));
                        let log = self.show(&dir.join(yosys::LOG).display().to_string());
                        self.say(&format!("  log: {log}"));
                        self.outcome.failed.push(name.to_string());
                        return Ok(());
                    }
                }
                yosys::netlist(&dir, &design.top)
            }
        };
        let shown = self.show(&netlist.display().to_string());
        self.say(&format!("  netlist: {shown}"));
        let tb = design.testbench(&design.top);
        let vvp = dir.join(format!("{m}.vvp"));
        // The testbench's files by absolute path, as for the RTL runs; the netlist itself
        // holds the memories' contents.
        let (strings, vectors) = design.testbench_files(&m)?;
        let mut compile = icarus::compile_gate(&m, &vvp, &tb, &netlist, &cells, &strings);
        let log = dir.join(format!("{m}.compile.log"));
        let Some(ran) = self.step(&format!("gate {m} (compile)"), &mut compile, &log)? else {
            return Ok(());
        };
        for l in ran.output.lines() {
            self.say(&format!("  iverilog: {l}"));
        }
        let run = icarus::simulate(&dir, &vvp, &[format!("+vectors={}", vectors.display())]);
        self.simulation(&format!("gate {m}"), run, &dir.join(format!("{m}.log")))?;
        if let Some(s) = stream {
            let run = icarus::simulate(&dir, &vvp, &[format!("+vectors={}", s.display())]);
            let log = dir.join(format!("{m}.stream.log"));
            self.simulation(&format!("gate {m} (stream)"), run, &log)?;
        }
        Ok(())
    }

    /// A build step: its run if it succeeded, None (reported) if not.
    fn step(&mut self, name: &str, cmd: &mut Command, log: &Path) -> Result<Option<Ran>> {
        self.say.starting(name);
        let ran = toolchain::run_logged(cmd, log)?;
        if ran.success() {
            return Ok(Some(ran));
        }
        self.fail(&format!("FAIL: {name}"), name, cmd, &ran);
        Ok(None)
    }

    /// A simulation, judged by its exit and its verdict line; whether it passed.
    fn simulation(&mut self, name: &str, mut cmd: Command, log: &Path) -> Result<bool> {
        self.say.starting(name);
        let ran = toolchain::run_logged(&mut cmd, log)?;
        if name.ends_with("(C++)") {
            for l in ran.output.lines().filter(|l| l.contains("vectors/s")) {
                self.say(&format!("  {l}"));
            }
        }
        let last = ran.last_line().to_string();
        match passed_count(&last).filter(|_| ran.success()) {
            Some(n) => {
                let rate = n as f64 / ran.seconds.max(1e-6);
                self.say(&format!("ok:   {name}: {last} ({rate:.0} vectors/s)"));
                self.outcome.passed.push(Passed {
                    name: name.to_string(),
                    vectors: n,
                    rate,
                });
                Ok(true)
            }
            None => {
                let headline = format!("FAIL: {name} ({}, last line: {last})", ran.exit());
                self.fail(&headline, name, &cmd, &ran);
                Ok(false)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::passed_count;

    #[test]
    fn only_a_clean_verdict_with_vectors_passes() {
        assert_eq!(passed_count("2221 passed, 0 failed"), Some(2221));
        for bad in [
            "0 passed, 0 failed",
            "2220 passed, 1 failed",
            " 5 passed, 0 failed",
            "x5 passed, 0 failed",
            "5 passed, 0 failed ",
            "passed, 0 failed",
            "",
        ] {
            assert_eq!(passed_count(bad), None, "{bad:?}");
        }
    }
}
