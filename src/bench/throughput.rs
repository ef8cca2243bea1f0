//! `rmapgen bench --throughput` (`make fpga-throughput`): shaded samples per second on real
//! parts. For every lane count × family × multiplier style, the design (the default
//! configuration with `lanes` set, generated with `--target ice40`, as `rmapgen fpga` builds
//! it) is synthesised once and placed and routed once per seed; the row gives the median
//! post-route Fmax over the seeds, samples/s = lanes × that median, logic cells, LUT4s,
//! flip-flops, block RAMs and DSP blocks, and the critical path of the median seed. A design
//! that needs more of the part than it has is a row saying so ("does not fit"), not an error.
//!
//! The ECP5 rows are placed out of context ([`fpga::Options::out_of_context`]): eight lanes
//! have more port bits than any ECP5 package has pins, and an IP core is timed without its
//! pins; every ECP5 row is placed the same way so the rows compare. The iCE40 rows are placed
//! in context (nextpnr-ice40 has no out-of-context mode), on the HX8K in ct256.
//!
//! The multiplier style is a column so that the products a DSP block can absorb (`--mult
//! infer`, not in this tree yet) become more rows of the same table; today every product is an
//! adder tree (`tree`).

use crate::config::{Config, Target};
use crate::output::StagedDir;
use crate::rtl::fpga::{self, Family, FpgaReport};
use anyhow::{Context, Result};
use serde::Serialize;
use std::path::Path;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub lanes: Vec<u32>,
    pub families: Vec<Family>,
    /// Placer seeds; the row's Fmax is their median.
    pub seeds: Vec<u64>,
    /// The clock the placer aims at, MHz.
    pub freq_mhz: f64,
}

/// The lane counts of the full sweep.
pub const LANES: [u32; 4] = [1, 2, 4, 8];
/// The families of the full sweep.
pub const FAMILIES: [Family; 2] = [Family::Ice40, Family::Ecp5];
/// Seeds of the full sweep: 1..=SEEDS.
pub const SEEDS: u64 = 5;
/// The placer's target in the sweep, MHz: above what either part reaches with this design,
/// so that the placer keeps pushing for timing on every seed.
pub const FREQ_MHZ: f64 = 200.0;
/// The multiplier style of every product today (adder trees of partial products, rtl/sum.rs).
pub const MULT: &str = "tree";

impl Default for Sweep {
    fn default() -> Self {
        Sweep {
            lanes: LANES.to_vec(),
            families: FAMILIES.to_vec(),
            seeds: (1..=SEEDS).collect(),
            freq_mhz: FREQ_MHZ,
        }
    }
}

/// One placed seed.
#[derive(Clone, Debug, Serialize)]
pub struct Seed {
    pub seed: u64,
    pub fmax_mhz: f64,
}

/// One configuration of the sweep.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub family: Family,
    pub device: String,
    pub package: String,
    pub out_of_context: bool,
    pub lanes: u32,
    pub mult: String,
    /// nextpnr's complaint when the design needs more of the part than it has.
    pub does_not_fit: Option<String>,
    pub seeds: Vec<Seed>,
    /// Median post-route Fmax over the seeds, MHz.
    pub fmax_mhz: Option<f64>,
    /// lanes × the median Fmax.
    pub samples_per_s: Option<f64>,
    /// The median seed's report (resources and critical path).
    pub report: Option<FpgaReport>,
    /// Memory bits of the design and of one lane (every lane holds a copy of every memory).
    pub memory_bits: u64,
    pub memory_bits_per_lane: u64,
}

/// The median of `v` (the middle of an odd count, the mean of the middle two of an even one).
fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    }
}

/// The part each family is swept on, and whether out of context.
fn options(family: Family, freq_mhz: f64) -> fpga::Options {
    fpga::Options {
        freq_mhz,
        out_of_context: family == Family::Ecp5,
        ..fpga::Options::for_family(family)
    }
}

/// Runs the sweep; logs of each configuration under `out/<family>-l<lanes>-<mult>/` (the
/// netlist, yosys.log, nextpnr_seed<N>.log and its report). `progress` hears each step.
pub fn run(sweep: &Sweep, out: &StagedDir, progress: &dyn Fn(&str)) -> Result<Vec<Row>> {
    anyhow::ensure!(!sweep.seeds.is_empty(), "the sweep has no seeds");
    let mut rows = Vec::new();
    for &family in &sweep.families {
        for &lanes in &sweep.lanes {
            let cfg = Config {
                lanes,
                ..Config::default()
            }
            .for_target(Target::Ice40);
            cfg.validate()?;
            let name = format!("{}-l{lanes}-{MULT}", family.name());
            let logs = out.path().join(&name);
            progress(&format!("{name}: synthesis"));
            rows.push(
                configuration(&cfg, family, sweep, &logs, &name, progress)
                    .with_context(|| format!("throughput sweep, {name}"))?,
            );
        }
    }
    Ok(rows)
}

/// One configuration: generate, synthesise once, place per seed.
fn configuration(
    cfg: &Config,
    family: Family,
    sweep: &Sweep,
    logs: &Path,
    name: &str,
    progress: &dyn Fn(&str),
) -> Result<Row> {
    let tmp = crate::output::Scratch::new()?;
    let rtl = StagedDir::new(&tmp.path().join("rtl"), &Default::default())?;
    let design = crate::design::Design::standard(cfg)?;
    crate::rtl::write_design(&design, &rtl)?;
    let dir = rtl.commit()?;
    let memories = crate::rtl::manifest::memories(cfg);
    let memory_bits: u64 = memories.iter().map(|m| m.bits).sum();
    let mut opts = options(family, sweep.freq_mhz);
    opts.logs = Some(logs.to_path_buf());
    let mut row = Row {
        family,
        device: opts.device.clone(),
        package: opts.package.clone(),
        out_of_context: opts.out_of_context,
        lanes: cfg.lanes,
        mult: MULT.into(),
        does_not_fit: None,
        seeds: Vec::new(),
        fmax_mhz: None,
        samples_per_s: None,
        report: None,
        memory_bits,
        memory_bits_per_lane: memory_bits / u64::from(cfg.lanes),
    };
    let syn = fpga::synthesise(&dir, &opts)?;
    let mut reports = Vec::new();
    for &seed in &sweep.seeds {
        progress(&format!("{name}: seed {seed}"));
        opts.seed = seed;
        match fpga::place(&syn, &opts) {
            Ok(r) => reports.push(r),
            Err(e) => match e.downcast_ref::<fpga::DoesNotFit>() {
                // Another seed does not change what the part has.
                Some(d) => {
                    row.does_not_fit = Some(d.message.clone());
                    return Ok(row);
                }
                None => return Err(e),
            },
        }
        // Each seed's log and report kept beside the others. `logs` lies inside the sweep's
        // staging directory (`run`'s `out`, created empty by rmapgen and refused over a
        // user's directory by its policy), and these two files were just written there by
        // `fpga::place`; the seeds are distinct, so no earlier seed's file is replaced.
        for f in [
            crate::toolchain::nextpnr::LOG,
            crate::toolchain::nextpnr::REPORT,
        ] {
            let (stem, ext) = f.rsplit_once('.').unwrap_or((f, ""));
            std::fs::rename(logs.join(f), logs.join(format!("{stem}_seed{seed}.{ext}")))?;
        }
    }
    let fmaxes: Vec<f64> = reports.iter().map(|r| r.fmax_mhz).collect();
    let m = median(&fmaxes);
    row.seeds = reports
        .iter()
        .map(|r| Seed {
            seed: r.seed,
            fmax_mhz: r.fmax_mhz,
        })
        .collect();
    row.fmax_mhz = Some(m);
    row.samples_per_s = Some(f64::from(cfg.lanes) * m * 1e6);
    // The seed closest to the median (the median itself with an odd count).
    row.report = reports
        .into_iter()
        .min_by(|a, b| (a.fmax_mhz - m).abs().total_cmp(&(b.fmax_mhz - m).abs()));
    Ok(row)
}

/// The row with the most samples/s.
pub fn best(rows: &[Row]) -> Option<&Row> {
    rows.iter()
        .filter(|r| r.samples_per_s.is_some())
        .max_by(|a, b| {
            a.samples_per_s
                .unwrap()
                .total_cmp(&b.samples_per_s.unwrap())
        })
}

/// The rows as a Markdown table, then the critical path of the best row.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| family | part | lanes | mult | Fmax median (MHz) | Fmax per seed (MHz) | samples/s | logic cells | LUT4 | flip-flops | block RAMs | DSP | memory bits per lane |\n\
         |---|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let part = format!(
            "{} {}{}",
            r.device,
            r.package,
            if r.out_of_context { ", OOC" } else { "" }
        );
        let head = format!(
            "| {} | {part} | {} | {} |",
            r.family.title(),
            r.lanes,
            r.mult
        );
        match (&r.report, r.fmax_mhz, r.samples_per_s) {
            (Some(p), Some(f), Some(sps)) => {
                let seeds: Vec<String> = r
                    .seeds
                    .iter()
                    .map(|x| format!("{:.1}", x.fmax_mhz))
                    .collect();
                s += &format!(
                    "{head} {f:.1} | {} | {:.3e} | {} | {} | {} | {} | {} | {} |\n",
                    seeds.join(", "),
                    sps,
                    p.logic_cells,
                    p.luts,
                    p.flip_flops,
                    p.block_rams,
                    p.dsps,
                    r.memory_bits_per_lane
                );
            }
            _ => {
                s += &format!(
                    "{head} does not fit | | | | | | | | {} |\n",
                    r.memory_bits_per_lane
                );
            }
        }
    }
    if let Some(b) = best(rows) {
        if let Some(c) = b.report.as_ref().and_then(|p| p.critical_path.as_ref()) {
            s += &format!(
                "\nBest: {} {} lanes ({}), {:.3e} samples/s; critical path of seed {} ({:.1} ns logic, {:.1} ns routing): {}\n",
                b.family.title(),
                b.lanes,
                b.mult,
                b.samples_per_s.unwrap_or(0.0),
                b.report.as_ref().map_or(0, |p| p.seed),
                c.logic_ns,
                c.routing_ns,
                c.through.join(" -> ")
            );
        }
    }
    for r in rows.iter().filter(|r| r.does_not_fit.is_some()) {
        s += &format!(
            "\n{} {} lanes does not fit: {}\n",
            r.family.title(),
            r.lanes,
            r.does_not_fit.as_deref().unwrap_or("")
        );
    }
    s
}

/// The rows as CSV with a header line.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("family,device,package,out_of_context,lanes,mult,fits,fmax_mhz_median,fmax_mhz_seeds,samples_per_s,logic_cells,luts,flip_flops,block_rams,dsps,memory_bits,memory_bits_per_lane\n");
    for r in rows {
        let p = r.report.as_ref();
        let seeds: Vec<String> = r
            .seeds
            .iter()
            .map(|x| format!("{:.2}", x.fmax_mhz))
            .collect();
        let n = |f: fn(&FpgaReport) -> u32| p.map_or(String::new(), |p| f(p).to_string());
        s += &format!(
            "{},{},{},{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{}\n",
            r.family.name(),
            r.device,
            r.package,
            r.out_of_context,
            r.lanes,
            r.mult,
            r.does_not_fit.is_none(),
            r.fmax_mhz.map_or(String::new(), |f| format!("{f:.2}")),
            seeds.join(" "),
            r.samples_per_s.map_or(String::new(), |v| format!("{v:.0}")),
            n(|p| p.logic_cells),
            n(|p| p.luts),
            n(|p| p.flip_flops),
            n(|p| p.block_rams),
            n(|p| p.dsps),
            r.memory_bits,
            r.memory_bits_per_lane
        );
    }
    s
}

/// Writes throughput.md, throughput.csv and throughput.json.
pub fn write(rows: &[Row], out: &StagedDir) -> Result<()> {
    out.write_text("throughput.md", &markdown(rows))?;
    out.write_text("throughput.csv", &csv(rows))?;
    out.write_text("throughput.json", &serde_json::to_string_pretty(rows)?)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[150.0, 140.0, 145.0, 160.0, 130.0]), 145.0);
        assert_eq!(median(&[150.0, 140.0]), 145.0);
    }
}
