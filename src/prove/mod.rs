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

pub mod build;
pub mod ffi;
pub mod front;
pub mod gates;
pub mod report;
pub mod states;
pub mod structure;
pub mod top;

use crate::design_dir::DesignDir;
use crate::model::{MapSet, Model};
use anyhow::{bail, ensure, Context, Result};
use report::{Part, Report};
use std::path::Path;
use std::time::Instant;

/// The widest gradient a factored run takes: 2^36 gradients through the front.
pub const MAX_GRAD_BITS: u32 = 12;
/// The widest gradient `--direct` takes: 2^27 gradients through the top.
pub const MAX_DIRECT_BITS: u32 = 9;
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
            .ok_or_else(|| format!("a shard is K/N (such as 1/4), not {text:?}"))?;
        let k: u64 = k
            .trim()
            .parse()
            .map_err(|_| format!("shard {text:?}: K is not a whole number"))?;
        let n: u64 = n
            .trim()
            .parse()
            .map_err(|_| format!("shard {text:?}: N is not a whole number"))?;
        if n == 0 || n > MAX_SHARDS {
            return Err(format!("shard {text:?}: N must be in 1..={MAX_SHARDS}"));
        }
        if k == 0 || k > n {
            return Err(format!("shard {text:?}: K must be in 1..={n}"));
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

/// What went wrong in a part: every failure counted, the first [`KEEP_FAILURES`] kept.
#[derive(Default)]
pub struct Failures {
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
}

/// Checks that `rmapgen prove` takes this design.
pub fn check_design(d: &DesignDir, direct: bool) -> Result<()> {
    let g = d.config.grad_bits;
    if direct {
        ensure!(
            g <= MAX_DIRECT_BITS,
            "--direct drives all 2^(3 grad_bits) gradients through the top; grad_bits = {g} is above {MAX_DIRECT_BITS} (drop --direct for the factored proof)"
        );
    } else {
        ensure!(
            g <= MAX_GRAD_BITS,
            "rmapgen prove covers 2^(3 grad_bits) gradients; grad_bits = {g} is above {MAX_GRAD_BITS}"
        );
        ensure!(
            d.config.red_bits <= states::MAX_RED_BITS,
            "rmapgen prove keeps one bit per sort & shift state (24 x 2^(3 red_bits - 1)); red_bits = {} is above {}",
            d.config.red_bits,
            states::MAX_RED_BITS
        );
    }
    Ok(())
}

/// The parts of a factored run, in the order they run.
pub const FACTORED: [&str; 4] = ["structure", "states", "zero", "front"];
/// The parts of a `--direct` run.
pub const DIRECT: [&str; 2] = ["structure", "direct"];

/// Runs one shard on design `d`, building in `build` (a directory rmapgen owns).
pub fn run(d: &DesignDir, build: &Path, opts: &Options, progress: &Progress) -> Result<Report> {
    check_design(d, opts.direct)?;
    let names: &[&str] = if opts.direct { &DIRECT } else { &FACTORED };
    for p in &opts.parts {
        if !names.contains(&p.as_str()) {
            bail!(
                "--part {p}: a {} run has the parts {}",
                if opts.direct { "--direct" } else { "factored" },
                names.join(", ")
            );
        }
    }
    let wanted = |name: &str| opts.parts.is_empty() || opts.parts.iter().any(|p| p == name);
    let start = Instant::now();
    let cfg = &d.config;
    let model = Model::new(cfg);
    let maps = MapSet::from_dir(cfg, d.path())
        .with_context(|| format!("the maps of {}", d.path().display()))?;
    let maps = maps.buffer(0);
    let total = 1u64 << (3 * cfg.grad_bits);
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

    let needs_top = ["direct", "states", "zero"]
        .iter()
        .any(|p| names.contains(p) && wanted(p));
    let t = report::now();
    let top_lib = if needs_top {
        Some(ffi::Library::open(&build::top(d, build)?)?)
    } else {
        None
    };
    let mut top = top_lib.as_ref().map(ffi::Top::new).transpose()?;
    if let (true, Some(top)) = (opts.direct, top.as_mut()) {
        let range = opts.shard.range(total);
        let mut fails = Failures::default();
        let mut batch = top::Batch::new(top, &model, maps, "direct");
        for idx in range.clone() {
            let g = front::gradient(cfg, idx).map(|v| crate::vectors::inputs::dec_grad(cfg, v));
            batch.push(idx, g, &mut fails, progress)?;
        }
        batch.flush(&mut fails, progress)?;
        parts.push(Part::new("direct", range, total, fails).since(t));
    }
    if !opts.direct {
        // The states' enumeration also gives the set the front checks every state against.
        let mut count = 0;
        let set = states::enumerate(cfg, |_, _| {
            count += 1;
            Ok(())
        })?;
        if let (true, Some(top)) = (wanted("states"), top.as_mut()) {
            let range = opts.shard.range(count);
            let mut fails = Failures::default();
            let mut batch = top::Batch::new(top, &model, maps, "states");
            states::enumerate(cfg, |ord, g| {
                if range.contains(&ord) {
                    batch.push(ord, g, &mut fails, progress)?;
                }
                Ok(())
            })?;
            batch.flush(&mut fails, progress)?;
            parts.push(Part::new("states", range, count, fails).since(t));
        }
        if let (true, Some(top)) = (wanted("zero"), top.as_mut()) {
            let t = report::now();
            let range = opts.shard.range(1);
            let mut fails = Failures::default();
            if !range.is_empty() {
                let mut batch = top::Batch::new(top, &model, maps, "zero");
                batch.push(0, [0, 0, 0], &mut fails, progress)?;
                batch.flush(&mut fails, progress)?;
            }
            parts.push(Part::new("zero", range, 1, fails).since(t));
        }
        if wanted("front") {
            let t = report::now();
            let range = opts.shard.range(total);
            let mut fails = Failures::default();
            match opts.front_engine {
                FrontEngine::Gates => {
                    let gf = gates::build(d, build)?;
                    gates::check(&gf, cfg, &set, range.clone(), &mut fails, progress)?;
                }
                FrontEngine::Verilator => {
                    let front_lib = ffi::Library::open(&build::front(d, build)?)?;
                    let mut fr = ffi::Front::new(&front_lib)?;
                    front::check(&mut fr, cfg, &set, range.clone(), &mut fails, progress)?;
                }
            }
            let part = Part::new("front", range, total, fails).since(t);
            parts.push(part.engine(opts.front_engine.name()));
        }
    }
    Report::new(d, opts, parts, start.elapsed().as_secs_f64())
}
