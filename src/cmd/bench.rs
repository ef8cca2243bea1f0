//! `rmapgen bench`: error against run time and hardware cost, as a Markdown table, a CSV and
//! plots.

use crate::bench::{self, Options};
use crate::output::StagedDir;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Smallest sphere image side of the error figures (`--size`); the largest is
/// [`crate::render::MAX_SIZE`].
pub const MIN_SIZE: u32 = 16;
/// Longest time spent timing one throughput figure (`--seconds`): a bench times about 60
/// figures, so 60 s each is already an hour.
pub const MAX_SECONDS: f64 = 60.0;

/// Most placer seeds of the throughput sweep (`--seeds`): one place and route of eight lanes
/// on the ECP5 takes minutes, so a hundred seeds is already days.
pub const MAX_SEEDS: u64 = 100;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Output directory for bench.md, bench.csv, bench.json and the plots (replaced whole).
    #[arg(long, value_name = "DIR", default_value = "out/bench")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
    /// Sphere image side for the error figures [16..=4096].
    #[arg(long, value_name = "N", default_value_t = 512, value_parser = super::parse::count::<u32>())]
    pub size: u32,
    /// Seconds spent timing each throughput figure (0, 60].
    #[arg(long, value_name = "S", default_value_t = 0.3, value_parser = super::parse::positive())]
    pub seconds: f64,
    /// Skip the FPGA place and route (Yosys, nextpnr) even when they are installed.
    #[arg(long)]
    pub no_yosys: bool,
    /// Only the paper's configuration (and the octahedral map).
    #[arg(long)]
    pub quick: bool,
    /// Measure only this scene (--scene, named by its file's stem) and this map fit
    /// (--map-fit) [default: the standard, two-lights and diffuse scenes, sample and lsq].
    #[command(flatten)]
    pub map: super::map_args::MapArgs,
    /// Instead of the error/cost table: the FPGA throughput sweep (make fpga-throughput).
    /// Each lane count x family x multiplier style is synthesised once and placed and routed
    /// per seed; the table (throughput.md, .csv, .json in --out, rewritten after every row)
    /// gives the median post-route Fmax, samples/s = lanes x Fmax, logic cells, block RAMs and
    /// DSP blocks, and the best row's critical path. Rows are placed in context; an ECP5 row
    /// with more port bits than pins out of context (fpga --ooc), and says so. Slow: hours for
    /// the full sweep.
    #[arg(long)]
    pub throughput: bool,
    /// Lane counts of the throughput sweep [default: 1,2,4,8]; without --throughput, the one
    /// lane count each configuration is placed with (its FPGA columns then add samples/s =
    /// lanes x Fmax) [1..=8, default 1].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = super::parse::field("lanes"))]
    pub lanes: Vec<u32>,
    /// Families of the throughput sweep [default: ice40,ecp5,gowin]; without --throughput, the
    /// one family each configuration is placed on (its default part: iCE40 HX8K, ECP5-85F,
    /// Gowin GW2A-18) [default: ice40].
    #[arg(long, value_enum, value_delimiter = ',')]
    pub family: Vec<crate::flow::fpga::Family>,
    /// Multiplier styles of the throughput sweep [default: tree,infer].
    #[arg(long, value_enum, value_delimiter = ',', requires = "throughput")]
    pub mult: Vec<crate::config::Mult>,
    /// Placer seeds of the throughput sweep, 1..=N [default: 5].
    #[arg(long, value_name = "N", requires = "throughput", value_parser = super::parse::whole::<u64>(1, MAX_SEEDS))]
    pub seeds: Option<u64>,
    /// The design each row of the throughput sweep places: every ROM read with a copy of its
    /// own on every family (replicated), or the family's own `--target` design, the one
    /// `rmapgen fpga --family F` places (family) [default: replicated].
    #[arg(long, value_enum, requires = "throughput")]
    pub layout: Option<crate::bench::throughput::Layout>,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if a.throughput {
        return throughput(a);
    }
    let max_size = crate::render::MAX_SIZE;
    anyhow::ensure!(
        (MIN_SIZE..=max_size).contains(&a.size),
        "size {} is out of range; allowed {MIN_SIZE}..={max_size}",
        a.size
    );
    anyhow::ensure!(
        a.seconds > 0.0 && a.seconds <= MAX_SECONDS,
        "seconds {} is out of range; allowed (0, {MAX_SECONDS}]",
        a.seconds
    );
    let scenes = match &a.map.scene {
        Some(p) => {
            let name = p.file_stem().unwrap_or(p.as_os_str()).to_string_lossy();
            vec![(name.into_owned(), a.map.scene()?)]
        }
        None => bench::scenes(),
    };
    // One FPGA for the bench's columns; the lists are the throughput sweep's.
    anyhow::ensure!(
        a.lanes.len() <= 1,
        "--lanes takes one lane count without --throughput (a list is the throughput sweep's)"
    );
    anyhow::ensure!(
        a.family.len() <= 1,
        "--family takes one family without --throughput (a list is the throughput sweep's)"
    );
    let d = Options::default();
    let out = StagedDir::new(&a.out, &a.force.policy(&[a.map.input()]))?;
    // The loaded table's configuration is not among --quick's.
    anyhow::ensure!(
        !(a.quick && a.map.map_fit == Some(crate::model::map_fit::MapFit::Table)),
        "--quick measures the paper's design, whose compensation table is a ROM, and map_fit table needs a loaded table; leave out --quick or give another --map-fit"
    );
    let opts = Options {
        size: a.size,
        seconds: a.seconds,
        yosys: !a.no_yosys,
        family: a.family.first().copied().unwrap_or(d.family),
        lanes: a.lanes.first().copied().unwrap_or(d.lanes),
        quick: a.quick,
        scenes,
        fits: a.map.map_fit.map_or(bench::FITS.to_vec(), |f| vec![f]),
    };
    let bar = super::progress::Progress::total("bench", opts.steps() as u64, "steps");
    let rows = bench::run(&opts, &|msg| {
        bar.step(msg);
        bar.inc(1);
    });
    drop(bar);
    let rows = rows?;
    bench::write(&rows, &out)?;
    let p = out.commit()?;
    crate::out!("{}", bench::table::markdown(&rows))?;
    crate::errln!(
        "rmapgen: wrote bench.md, bench.csv, bench.json and plots to {}",
        p.display()
    );
    Ok(())
}

/// `--throughput`: the FPGA sweep of [`bench::throughput`].
fn throughput(a: &BenchArgs) -> Result<()> {
    use bench::throughput::{self, Sweep};
    let d = Sweep::default();
    let sweep = Sweep {
        lanes: if a.lanes.is_empty() {
            d.lanes
        } else {
            a.lanes.clone()
        },
        families: if a.family.is_empty() {
            d.families
        } else {
            a.family.clone()
        },
        mults: if a.mult.is_empty() {
            d.mults
        } else {
            a.mult.clone()
        },
        seeds: a.seeds.map_or(d.seeds, |n| (1..=n).collect()),
        freq_mhz: d.freq_mhz,
        layout: a.layout.unwrap_or(d.layout),
    };
    // A value named twice would be a row measured twice into the same log directory.
    fn once<T: PartialEq + std::fmt::Debug>(flag: &str, v: &[T]) -> Result<()> {
        for (i, x) in v.iter().enumerate() {
            anyhow::ensure!(
                !v[..i].contains(x),
                "{flag} names {} twice",
                format!("{x:?}").to_lowercase()
            );
        }
        Ok(())
    }
    once("--lanes", &sweep.lanes)?;
    once("--family", &sweep.families)?;
    once("--mult", &sweep.mults)?;
    let out = StagedDir::new(&a.out, &a.force.policy(&[]))?;
    let result = throughput::run(&sweep, &out, &|m| crate::errln!("rmapgen: throughput: {m}"));
    // The logs are kept also when a configuration fails, so that they can be read.
    let rows = match result {
        Ok(rows) => rows,
        Err(e) => {
            let shown = a.out.display().to_string();
            return Err(out.commit_failed(e).context(format!("logs in {shown}")));
        }
    };
    throughput::write(&rows, &out)?;
    let p = out.commit()?;
    crate::out!("{}", throughput::markdown(&rows))?;
    crate::errln!(
        "rmapgen: wrote throughput.md, throughput.csv, throughput.json and the logs to {}",
        p.display()
    );
    Ok(())
}
