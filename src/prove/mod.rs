//! `rmapgen prove`: the generated RTL of a design equals its model on every one of its
//! 2^(3G) gradients, shown by simulating the generated Verilog itself (Verilator) and
//! factored by the pipeline's structure (docs/VERIFICATION.md, "Every input"):
//!
//! 1. **structure** ([`structure`]): from the design's own netlist (Yosys), the gradient
//!    reaches only the front modules, and every path from a sample input to an output is a
//!    chain of the same number of registers: so the top's result for a sample is a function
//!    of the front's outputs for that sample alone;
//! 2. **front** ([`front`]): the front (zero detect, sort & shift) over every gradient,
//!    against the model, and every gradient's sort & shift state among those of part 3;
//! 3. **states** ([`states`], [`top`]): the whole top on one representative gradient of
//!    every sort & shift state of a non-zero gradient;
//! 4. **zero**: the zero gradient through the top.
//!
//! `--direct` instead drives every gradient through the top (2^24 at G = 8). A run can be
//! one shard of N ([`Shard`]): each part's inputs are split into N contiguous ranges, and
//! [`report::merge`] combines the shards' reports into one verdict.

pub mod aig;
pub mod build;
pub mod ffi;
pub mod front;
pub mod gates;
pub mod mult;
pub mod report;
pub mod slurm;
pub mod states;
pub mod structure;
pub mod top;

use crate::config::Config;
use crate::design_dir::DesignDir;
use crate::model::{MapSet, Model};
use anyhow::{bail, ensure, Context, Result};
use report::{Part, Report};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The widest gradient a factored run takes: 2^36 gradients through the front.
pub const MAX_GRAD_BITS: u32 = 12;
/// The widest gradient a whole `--direct` run takes: 2^27 gradients through the top on each
/// of the four passes, 2^29 samples. A wider design (up to [`MAX_GRAD_BITS`]) takes
/// `--direct` in shards of at most as many samples each ([`direct_shards`]).
pub const MAX_DIRECT_BITS: u32 = 9;

/// The fewest shards a `--direct` run of gradients `grad_bits` wide is split into: 1 up to
/// [`MAX_DIRECT_BITS`], then enough that no shard drives more top samples than a whole run
/// of that width (512 for the default G = 12: 2^29 samples a shard, about two minutes).
pub fn direct_shards(grad_bits: u32) -> u64 {
    1 << (3 * grad_bits.saturating_sub(MAX_DIRECT_BITS))
}
/// Failure messages a report keeps (all are counted).
pub const KEEP_FAILURES: usize = 20;

/// One shard of a run: `index` in 1..=`count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    pub index: u64,
    pub count: u64,
}

/// The most shards a run is split into.
pub const MAX_SHARDS: u64 = 1 << 20;

impl Shard {
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// `K/N`.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| "a shard is K/N (such as 1/4)".to_string())?;
        let k: u64 = k
            .trim()
            .parse()
            .map_err(|_| "K is not a whole number".to_string())?;
        let n: u64 = n
            .trim()
            .parse()
            .map_err(|_| "N is not a whole number".to_string())?;
        if n == 0 || n > MAX_SHARDS {
            return Err(format!("N must be in 1..={MAX_SHARDS}"));
        }
        if k == 0 || k > n {
            return Err(format!("K must be in 1..={n}"));
        }
        Ok(Shard { index: k, count: n })
    }

    /// This shard's part of 0..total: the (index-1)-th of `count` contiguous ranges whose
    /// sizes differ by at most one.
    pub fn range(&self, total: u64) -> std::ops::Range<u64> {
        let at = |k: u64| ((total as u128 * k as u128) / self.count as u128) as u64;
        at(self.index - 1)..at(self.index)
    }

    pub fn is_first(&self) -> bool {
        self.index == 1
    }
}

/// What a part found: the inputs it checked (each driven through the simulation or the
/// gates and compared with the model: counted where that happens, never from loop bounds),
/// and what went wrong, every failure counted, the first [`KEEP_FAILURES`] kept.
#[derive(Default)]
pub struct Failures {
    pub checked: u64,
    pub count: u64,
    pub kept: Vec<String>,
}

impl Failures {
    pub fn add(&mut self, msg: String) {
        self.count += 1;
        if self.kept.len() < KEEP_FAILURES {
            self.kept.push(msg);
        }
    }
}

/// Called with the number of inputs done since its last call.
pub type Progress<'a> = dyn Fn(u64) + 'a;

/// What evaluates the front (part `front`) on every gradient. Both read the generated
/// `zero_detect.v` and `sort_shift.v` themselves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FrontEngine {
    /// Yosys's gates of the front, its registers made wires, evaluated 512 gradients at a
    /// time on all cores ([`gates`]); about 4 times faster.
    Gates,
    /// The front Verilated and clocked, four copies side by side ([`front`]).
    Verilator,
}

impl FrontEngine {
    pub fn name(self) -> &'static str {
        match self {
            FrontEngine::Gates => "gates",
            FrontEngine::Verilator => "verilator",
        }
    }
}

/// How a run goes.
pub struct Options {
    pub shard: Shard,
    pub direct: bool,
    pub front_engine: FrontEngine,
    /// Only these parts (all when empty); a report without every part does not merge.
    pub parts: Vec<String>,
    /// Simulate what a `--build-only` run built in this directory (for the same files)
    /// instead of building it again: every shard of a cluster run shares one build.
    pub reuse: Option<PathBuf>,
}

/// Checks that `rmapgen prove` takes this design.
/// `shards` is the number of shards the run is split into (a `--direct` run of a design wider
/// than [`MAX_DIRECT_BITS`] must be split: [`direct_shards`]).
pub fn check_design(d: &DesignDir, direct: bool, shards: u64) -> Result<()> {
    check_limits(&d.config, direct, shards)
}

/// Checks that `rmapgen prove` takes a design of configuration `cfg` in a run split into
/// `shards` (the bounds of every allocation and loop of a run or a merge).
pub fn check_limits(cfg: &Config, direct: bool, shards: u64) -> Result<()> {
    let g = cfg.grad_bits;
    // The proof drives one rmap_top; in a lanes design the lanes' rmap_tops share ROMs
    // through ports of their own, so no single rmap_top of it stands alone.
    ensure!(
        cfg.lanes == 1,
        "rmapgen prove proves one rmap_top; this design has lanes = {} (rmap_lanes, ROMs shared between lanes): prove the single-lane design of the same configuration (generate without --lanes), and check the lanes with `rmapgen sim --icarus --verilator --only {}`",
        cfg.lanes,
        crate::stages::top(cfg).module(cfg)
    );
    ensure!(
        g <= MAX_GRAD_BITS,
        "rmapgen prove covers 2^(3 grad_bits) gradients; grad_bits = {g} is above {MAX_GRAD_BITS}"
    );
    if direct {
        let least = direct_shards(g);
        ensure!(
            shards >= least,
            "--direct drives all 2^(3 grad_bits) gradients through the top; grad_bits = {g} is above {MAX_DIRECT_BITS}, so split the run into at least {least} shards (--shard K/{least} or --slurm --shards {least}, each at most the {} top samples of a whole grad_bits = {MAX_DIRECT_BITS} run; or drop --direct for the factored proof)",
            part_total("direct", MAX_DIRECT_BITS, 0)
        );
    } else {
        ensure!(
            cfg.red_bits <= states::MAX_RED_BITS,
            "rmapgen prove keeps one bit per sort & shift state (24 x 2^(3 red_bits - 1)); red_bits = {} is above {}",
            cfg.red_bits,
            states::MAX_RED_BITS
        );
    }
    Ok(())
}

/// The number of inputs of part `name` of a run of a configuration whose gradient has
/// `grad_bits` bits and whose sort & shift has `states` states: the one formula a run
/// reports and a merge requires.
fn part_total(name: &str, grad_bits: u32, states: u64) -> u64 {
    let gradients = 1u64 << (3 * grad_bits);
    let passes = PASSES.len() as u64;
    match name {
        "structure" | "zero" => 1,
        "front" => gradients,
        "direct" => passes * gradients,
        "states" => passes * states,
        _ => unreachable!("a part of FACTORED or DIRECT"),
    }
}

/// Every part of a run of `cfg` (factored or `--direct`) with its number of inputs.
pub fn totals(cfg: &Config, direct: bool) -> Result<Vec<(&'static str, u64)>> {
    let names: &[&'static str] = if direct { &DIRECT } else { &FACTORED };
    let states = if direct { 0 } else { state_count(cfg)? };
    Ok(names
        .iter()
        .map(|&n| (n, part_total(n, cfg.grad_bits, states)))
        .collect())
}

/// The sort & shift states of `cfg` and their set, each visited once, in order.
fn state_set(cfg: &Config) -> Result<(u64, states::StateSet)> {
    let mut count = 0u64;
    let set = states::enumerate(cfg, |ord, _| {
        ensure!(
            ord == count,
            "state enumeration: state {ord} where {count} was due"
        );
        count += 1;
        Ok(())
    })?;
    ensure!(
        set.len() == count,
        "state enumeration: {count} states visited, {} in the set",
        set.len()
    );
    Ok((count, set))
}

fn state_count(cfg: &Config) -> Result<u64> {
    Ok(state_set(cfg)?.0)
}

/// What the harness does to the map buffers before a pass of the top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Exchange the front and back buffers (`swap_i`).
    Swap,
    /// Write every entry of the design's second map into the back buffer through the host
    /// port (`wr_en_i`, in [`crate::map_stream::writes`] order).
    WriteSecond,
}

/// One pass of the top's samples over one map buffer: the steps before it, and the map the
/// front buffer must then hold (0: the scene's, the initial contents of both buffers; 1:
/// the second map).
#[derive(Clone, Copy, Debug)]
pub struct Pass {
    pub label: &'static str,
    pub before: &'static [Step],
    pub expect: u64,
}

/// The passes of the top, in order: each buffer as loaded at reset, and each buffer written
/// through the host port. The second pass writes into buffer 0 while buffer 1 is read
/// (writes must reach only the back buffer); the fourth writes buffer 1. So every entry of
/// both buffers' init contents, the write port into either buffer and the swap are observed
/// at the outputs (docs/VERIFICATION.md, "Both map buffers").
pub const PASSES: [Pass; 4] = [
    Pass {
        label: "buffer 0 as loaded",
        before: &[],
        expect: 0,
    },
    Pass {
        label: "buffer 1 as loaded",
        before: &[Step::Swap, Step::WriteSecond],
        expect: 0,
    },
    Pass {
        label: "buffer 0 written",
        before: &[Step::Swap],
        expect: 1,
    },
    Pass {
        label: "buffer 1 written",
        before: &[Step::WriteSecond, Step::Swap],
        expect: 1,
    },
];

/// Runs the [`PASSES`] of a part of the top whose samples are `each` per pass (ordinal
/// `pass * each + k` for sample k of a pass), those in `range`; `samples(ks, visit)` visits
/// a pass's samples in order with their index k, at least those with k in `ks` (the shard's
/// share of the pass; the rest are passed over). Every pass's steps run in every shard, so
/// that the buffers hold what the pass expects.
#[allow(clippy::too_many_arguments)]
fn passes(
    top: &mut ffi::Top,
    model: &Model,
    maps: &MapSet,
    part: &'static str,
    each: u64,
    range: std::ops::Range<u64>,
    fails: &mut Failures,
    progress: &Progress,
    mut samples: impl FnMut(
        std::ops::Range<u64>,
        &mut dyn FnMut(u64, [i32; 3]) -> Result<()>,
    ) -> Result<()>,
) -> Result<()> {
    let second = crate::map_stream::writes(&model.cfg, maps.buffer(1));
    for (p, pass) in PASSES.iter().enumerate() {
        for step in pass.before {
            match step {
                Step::Swap => top.swap(),
                Step::WriteSecond => top.write(&second)?,
            }
        }
        let base = p as u64 * each;
        let mine = range.start.max(base)..range.end.min(base + each);
        if mine.is_empty() {
            continue;
        }
        let mut batch = top::Batch::new(top, model, maps.buffer(pass.expect), part, mine.start);
        batch.pass(pass.label);
        samples(mine.start - base..mine.end - base, &mut |k, g| {
            let ord = base + k;
            if mine.contains(&ord) {
                batch.push(ord, g, fails, progress)?;
            }
            Ok(())
        })?;
        if batch.next() != mine.end {
            fails.add(format!(
                "{part} ({}): samples {}..{} were never driven",
                pass.label,
                batch.next(),
                mine.end
            ));
        }
        batch.flush(fails, progress)?;
    }
    Ok(())
}

/// The parts of a factored run, in the order they run.
pub const FACTORED: [&str; 4] = ["structure", "states", "zero", "front"];
/// The factored parts in two runs, the order in which `rmapgen mutants` judges a mutant by the
/// proof: first the parts that take seconds to minutes, then the front's every gradient, only
/// if they passed. Together they are [`FACTORED`], each once.
pub const STAGED: [&[&str]; 2] = [&["structure", "states", "zero"], &["front"]];
/// The parts of a `--direct` run.
pub const DIRECT: [&str; 2] = ["structure", "direct"];

/// Checks the options of a run (the parts named exist), before anything is made.
pub fn check_options(opts: &Options) -> Result<()> {
    let names = opts.names();
    for p in &opts.parts {
        if !names.contains(&p.as_str()) {
            bail!(
                "--part {p}: a {} run has the parts {}",
                if opts.direct { "--direct" } else { "factored" },
                names.join(", ")
            );
        }
    }
    Ok(())
}

/// The pass whose buffers the top holds after every pass: the zero part's samples run on it.
const LAST_PASS: Pass = PASSES[PASSES.len() - 1];

impl Options {
    /// The parts of this kind of run, in the order they run.
    pub fn names(&self) -> &'static [&'static str] {
        if self.direct {
            &DIRECT
        } else {
            &FACTORED
        }
    }

    /// Whether part `name` runs (every part when `--part` names none).
    pub fn wants(&self, name: &str) -> bool {
        self.parts.is_empty() || self.parts.iter().any(|p| p == name)
    }

    /// Whether a part that drives the top runs (the top's Verilated library is built then).
    pub fn needs_top(&self) -> bool {
        ["direct", "states", "zero"]
            .iter()
            .any(|p| self.names().contains(p) && self.wants(p))
    }
}

/// The first file whose hash differs between two hashings of the same files.
fn changed<'a>(before: &'a [report::FileHash], after: &[report::FileHash]) -> Option<&'a str> {
    before
        .iter()
        .zip(after)
        .find(|(b, a)| b.sha256 != a.sha256)
        .map(|(b, _)| b.name.as_str())
}

/// The file a `--build-only` run leaves in its build directory: what it built, from which
/// files ([`Built`]).
pub const BUILT_FILE: &str = "built.json";

/// What a `--build-only` run built and from what: the configuration, every file the proof
/// reads (by SHA-256), whether the top is built and which front engine's model.
#[derive(Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Built {
    pub config: Config,
    pub files: Vec<report::FileHash>,
    pub top: bool,
    pub front_engine: Option<String>,
}

/// Builds in `build` what a run of `opts` (any shard) simulates, without running it: the
/// Verilated top when a part drives it, and the front's gates or Verilated front for the
/// `front` part. Writes [`BUILT_FILE`] last, so a directory that has it holds a whole build.
/// Shards given `reuse` = `build` then load these instead of building their own.
pub fn build_only(d: &DesignDir, build: &Path, opts: &Options) -> Result<Built> {
    // It drives nothing: what its shards drive is checked when each runs.
    check_design(d, opts.direct, MAX_SHARDS)?;
    check_options(opts)?;
    let names = report::read_files(d);
    let files = report::hash_files(d, &names)?;
    let top = opts.needs_top();
    if top {
        build::top(d, build)?;
    }
    let front = !opts.direct && opts.wants("front");
    if front {
        match opts.front_engine {
            FrontEngine::Gates => drop(gates::build(d, build)?),
            FrontEngine::Verilator => drop(build::front(d, build)?),
        }
    }
    if let Some(name) = changed(&files, &report::hash_files(d, &names)?) {
        bail!(
            "{} changed while it was being built; build again",
            d.path().join(name).display()
        );
    }
    let built = Built {
        config: d.config.clone(),
        files,
        top,
        front_engine: front.then(|| opts.front_engine.name().to_string()),
    };
    crate::disk::write(
        &build.join(BUILT_FILE),
        serde_json::to_string_pretty(&built)? + "\n",
    )?;
    Ok(built)
}

/// Checks that `dir` holds a `--build-only` build of design `d` as it is now (`files`, hashed
/// at the start of this run) with everything a run of `opts` loads from it.
fn reusable(d: &DesignDir, dir: &Path, files: &[report::FileHash], opts: &Options) -> Result<()> {
    let at = dir.join(BUILT_FILE);
    let text = std::fs::read_to_string(&at).map_err(|e| {
        anyhow::anyhow!(
            "--reuse {}: no finished `rmapgen prove --build-only` build there ({}: {e})",
            dir.display(),
            at.display()
        )
    })?;
    let built: Built = serde_json::from_str(&text).with_context(|| {
        format!(
            "--reuse {}: {} is not rmapgen's",
            dir.display(),
            at.display()
        )
    })?;
    ensure!(
        built.config == d.config,
        "--reuse {}: built for another configuration ({}, not {})",
        dir.display(),
        built.config.summary(),
        d.config.summary()
    );
    let key = |f: &report::FileHash| (f.name.clone(), f.sha256.clone());
    if let Some(f) = files
        .iter()
        .find(|f| !built.files.iter().any(|b| key(b) == key(f)))
    {
        bail!(
            "--reuse {}: built from other files than {} has now ({} differs): build again with --build-only",
            dir.display(),
            d.path().display(),
            f.name
        );
    }
    ensure!(
        !opts.needs_top() || built.top,
        "--reuse {}: the build has no Verilated top (built with --part that needs none)",
        dir.display()
    );
    let front = !opts.direct && opts.wants("front");
    ensure!(
        !front || built.front_engine.as_deref() == Some(opts.front_engine.name()),
        "--reuse {}: built for front engine {}, not {}",
        dir.display(),
        built.front_engine.as_deref().unwrap_or("none"),
        opts.front_engine.name()
    );
    Ok(())
}

/// Runs one shard on design `d`, building in `build` (a directory rmapgen owns).
pub fn run(d: &DesignDir, build: &Path, opts: &Options, progress: &Progress) -> Result<Report> {
    check_design(d, opts.direct, opts.shard.count)?;
    check_options(opts)?;
    let wanted = |name: &str| opts.wants(name);
    let start = Instant::now();
    // What is proven is the files as they are now: hashed before the run and again after it,
    // so that a file changed meanwhile cannot be certified.
    let file_names = report::read_files(d);
    let files = report::hash_files(d, &file_names)?;
    let cfg = &d.config;
    let model = Model::new(cfg);
    let maps = MapSet::from_dir(cfg, d.path())
        .with_context(|| format!("the maps of {}", d.path().display()))?;
    let total = part_total("front", cfg.grad_bits, 0);
    let mut parts = Vec::new();

    if wanted("structure") {
        // The structure is the design's, the same in every shard: the first checks it.
        let t = report::now();
        if opts.shard.is_first() {
            parts.push(structure::check(d, build)?.since(t));
        } else {
            parts.push(Part::new("structure", 1..1, 1, Failures::default()));
        }
    }

    if let Some(dir) = &opts.reuse {
        reusable(d, dir, &files, opts)?;
    }
    let t = report::now();
    let top_lib = if opts.needs_top() {
        let lib = match &opts.reuse {
            Some(dir) => build::top_lib(dir),
            None => build::top(d, build)?,
        };
        Some(ffi::Library::open(&lib)?)
    } else {
        None
    };
    let mut top = top_lib.as_ref().map(ffi::Top::new).transpose()?;
    if let (true, Some(top)) = (opts.direct, top.as_mut()) {
        let all = part_total("direct", cfg.grad_bits, 0);
        let range = opts.shard.range(all);
        let mut fails = Failures::default();
        passes(
            top,
            &model,
            &maps,
            "direct",
            total,
            range.clone(),
            &mut fails,
            progress,
            |ks, visit| {
                for idx in ks {
                    let g =
                        front::gradient(cfg, idx).map(|v| crate::vectors::inputs::dec_grad(cfg, v));
                    visit(idx, g)?;
                }
                Ok(())
            },
        )?;
        parts.push(Part::new("direct", range, all, fails).since(t));
    }
    if !opts.direct {
        // The states' enumeration also gives the set the front checks every state against.
        let (count, set) = state_set(cfg)?;
        if let (true, Some(top)) = (wanted("states"), top.as_mut()) {
            let all = part_total("states", cfg.grad_bits, count);
            let range = opts.shard.range(all);
            let mut fails = Failures::default();
            passes(
                top,
                &model,
                &maps,
                "states",
                count,
                range.clone(),
                &mut fails,
                progress,
                |_, visit| states::enumerate(cfg, &mut *visit).map(|_| ()),
            )?;
            parts.push(Part::new("states", range, all, fails).since(t));
        }
        if let (true, Some(top)) = (wanted("zero"), top.as_mut()) {
            let t = report::now();
            let range = opts.shard.range(1);
            let mut fails = Failures::default();
            if !range.is_empty() {
                let front = maps.buffer(LAST_PASS.expect);
                let mut batch = top::Batch::new(top, &model, front, "zero", 0);
                batch.push(0, [0, 0, 0], &mut fails, progress)?;
                batch.flush(&mut fails, progress)?;
            }
            parts.push(Part::new("zero", range, 1, fails).since(t));
        }
        if wanted("front") {
            let t = report::now();
            let all = part_total("front", cfg.grad_bits, count);
            let range = opts.shard.range(all);
            let mut fails = Failures::default();
            match opts.front_engine {
                FrontEngine::Gates => {
                    let gf = match &opts.reuse {
                        Some(dir) => gates::load(d, dir)?,
                        None => gates::build(d, build)?,
                    };
                    gates::check(&gf, cfg, &set, range.clone(), &mut fails, progress)?;
                }
                FrontEngine::Verilator => {
                    let lib = match &opts.reuse {
                        Some(dir) => build::front_lib(dir),
                        None => build::front(d, build)?,
                    };
                    let front_lib = ffi::Library::open(&lib)?;
                    let mut fr = ffi::Front::new(&front_lib)?;
                    front::check(&mut fr, cfg, &set, range.clone(), &mut fails, progress)?;
                }
            }
            let part = Part::new("front", range, all, fails).since(t);
            parts.push(part.engine(opts.front_engine.name()));
        }
    }
    let after = report::hash_files(d, &file_names)?;
    if let Some(name) = changed(&files, &after) {
        bail!(
            "{} changed while it was being proven; prove the design again",
            d.path().join(name).display()
        );
    }
    Report::new(d, opts, files, parts, start.elapsed().as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shard_is_k_of_n_with_k_in_1_to_n_and_the_shards_tile_the_range() {
        for ok in ["1/1", "2/2", "1/4", " 3 / 4 "] {
            assert!(Shard::parse(ok).is_ok(), "{ok}");
        }
        let max = format!("1/{MAX_SHARDS}");
        assert!(Shard::parse(&max).is_ok());
        for (bad, says) in [
            ("0/2", "K must be in 1..=2"),
            ("3/2", "K must be in 1..=2"),
            ("1/0", "N must be in"),
            (&format!("1/{}", MAX_SHARDS + 1), "N must be in"),
            ("-1/2", "K is not a whole number"),
            ("1/x", "N is not a whole number"),
            ("12", "a shard is K/N"),
        ] {
            let e = Shard::parse(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
        // Ranges: contiguous, sizes differing by at most one, together 0..total.
        for (n, total) in [(1, 10), (3, 10), (4, 3), (7, 1 << 36)] {
            let mut at = 0;
            for k in 1..=n {
                let r = Shard { index: k, count: n }.range(total);
                assert_eq!(r.start, at);
                assert!(r.end - r.start <= total / n + 1 && r.end - r.start >= total / n);
                at = r.end;
            }
            assert_eq!(at, total);
        }
        assert!(Shard::parse("1/3").unwrap().is_first());
        assert!(!Shard::parse("2/3").unwrap().is_first());
    }

    /// A design of `cfg` written into a scratch directory, opened as `prove` opens one.
    /// A design of `cfg`, written as `rmapgen generate` writes it, in a scratch directory.
    pub(super) fn design(cfg: &Config) -> (crate::output::Scratch, DesignDir) {
        let tmp = crate::output::Scratch::new().unwrap();
        let out =
            crate::output::StagedDir::new(&tmp.path().join("d"), &Default::default()).unwrap();
        crate::emit::write_design(&crate::design::Design::standard(cfg).unwrap(), &out, None)
            .unwrap();
        let dir = out.commit().unwrap();
        let d = DesignDir::open(&dir).unwrap();
        (tmp, d)
    }

    #[test]
    fn a_design_is_taken_within_the_bounds_of_its_run() {
        let g8 = Config {
            grad_bits: 8,
            red_bits: 6,
            ..Config::default()
        };
        let (_t, d) = design(&g8);
        assert!(check_design(&d, false, 1).is_ok());
        assert!(check_design(&d, true, 1).is_ok());
        let (_t, d) = design(&Config::default());
        assert!(check_design(&d, false, 1).is_ok());
        // The default design's 2^36 gradients go --direct only in shards of at most 2^27.
        assert_eq!(
            [8, 9, 10, 12].map(direct_shards),
            [1, 1, 8, 512],
            "the fewest --direct shards"
        );
        for few in [1, 2, 511] {
            let e = check_design(&d, true, few).unwrap_err().to_string();
            assert!(
                e.starts_with("--direct drives all 2^(3 grad_bits) gradients")
                    && e.contains("at least 512 shards (--shard K/512"),
                "{e}"
            );
        }
        assert!(check_design(&d, true, 512).is_ok());
        assert!(check_design(&d, true, MAX_SHARDS).is_ok());
        let (_t, d) = design(&Config { lanes: 2, ..g8 });
        let e = check_design(&d, false, 1).unwrap_err().to_string();
        assert!(
            e.starts_with("rmapgen prove proves one rmap_top; this design has lanes = 2"),
            "{e}"
        );
    }

    fn opts(direct: bool, parts: &[&str]) -> Options {
        Options {
            shard: Shard { index: 1, count: 1 },
            direct,
            front_engine: FrontEngine::Gates,
            parts: parts.iter().map(|p| p.to_string()).collect(),
            reuse: None,
        }
    }

    #[test]
    fn the_parts_run_are_those_named_and_the_top_is_built_for_those_that_drive_it() {
        let all = opts(false, &[]);
        assert!(FACTORED.iter().all(|p| all.wants(p)));
        let front = opts(false, &["front"]);
        assert!(front.wants("front") && !front.wants("states") && !front.wants("zero"));
        assert!(!front.needs_top(), "the front alone runs on gates");
        assert!(!opts(false, &["structure"]).needs_top());
        for p in ["states", "zero"] {
            assert!(opts(false, &["front", p]).needs_top(), "{p}");
        }
        assert!(all.needs_top() && opts(true, &[]).needs_top());
        assert!(opts(true, &["direct"]).needs_top());
        assert!(!opts(true, &["structure"]).needs_top());
        assert_eq!(opts(true, &[]).names(), DIRECT);
        assert_eq!(all.names(), FACTORED);
        assert_eq!(
            STAGED.concat(),
            FACTORED,
            "the staged runs are the factored parts, once"
        );
        // The zero part runs on the buffers as the last pass left them: the second map.
        assert_eq!(LAST_PASS.label, "buffer 1 written");
        assert_eq!(LAST_PASS.expect, 1);
    }

    #[test]
    fn a_file_changed_between_two_hashings_is_named() {
        let h = |name: &str, sha: &str| report::FileHash {
            name: name.into(),
            sha256: sha.into(),
            as_generated: true,
        };
        let before = [h("a.v", "1"), h("b.hex", "2"), h("c.hex", "3")];
        assert_eq!(changed(&before, &before.clone()), None);
        let after = [h("a.v", "1"), h("b.hex", "9"), h("c.hex", "8")];
        assert_eq!(changed(&before, &after), Some("b.hex"));
    }

    #[test]
    fn failures_count_every_one_and_keep_the_first_few() {
        let mut f = Failures::default();
        for k in 0..KEEP_FAILURES + 5 {
            f.add(format!("f{k}"));
        }
        assert_eq!(f.count, KEEP_FAILURES as u64 + 5);
        assert_eq!(f.kept.len(), KEEP_FAILURES);
        assert_eq!(f.kept[0], "f0");
        assert_eq!(f.kept[KEEP_FAILURES - 1], format!("f{}", KEEP_FAILURES - 1));
    }

    #[test]
    fn an_engine_is_named_as_its_flag() {
        use clap::ValueEnum;
        for e in FrontEngine::value_variants() {
            assert_eq!(e.name(), e.to_possible_value().unwrap().get_name());
        }
    }

    #[test]
    fn a_part_counts_its_inputs_over_every_pass() {
        let passes = PASSES.len() as u64;
        assert_eq!(passes, 4);
        assert_eq!(part_total("structure", 8, 99), 1);
        assert_eq!(part_total("zero", 8, 99), 1);
        assert_eq!(part_total("front", 8, 99), 1 << 24);
        assert_eq!(part_total("front", 12, 99), 1 << 36);
        assert_eq!(part_total("direct", 8, 0), 4 << 24);
        assert_eq!(part_total("states", 8, 99), 4 * 99);
        assert_eq!(part_total("states", 8, 1 << 20), 4 << 20);
    }

    #[test]
    fn a_run_takes_only_the_parts_of_its_kind() {
        for ok in [
            &[][..],
            &["front"],
            &["structure", "states", "zero", "front"],
        ] {
            assert!(check_options(&opts(false, ok)).is_ok(), "{ok:?}");
        }
        assert!(check_options(&opts(true, &["direct", "structure"])).is_ok());
        for (direct, bad, says) in [
            (
                false,
                "direct",
                "--part direct: a factored run has the parts structure, states, zero, front",
            ),
            (
                true,
                "front",
                "--part front: a --direct run has the parts structure, direct",
            ),
            (false, "fronts", "--part fronts: a factored run"),
        ] {
            let e = check_options(&opts(direct, &["structure", bad]))
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(says), "{e}");
        }
    }
}
