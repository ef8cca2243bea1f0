//! `rmapgen bench --throughput` (`make fpga-throughput`): shaded samples per second on real
//! parts. For every lane count × family × multiplier style, the design (the default
//! configuration with `lanes` set, generated with every ROM read replicated, or with
//! `--layout family` for the family's own `--target`, as `rmapgen fpga` builds it) is
//! synthesised once and placed and routed once per seed; the row gives the median
//! post-route Fmax over the seeds, samples/s = lanes × that median, logic cells, LUT4s,
//! flip-flops, block RAMs and DSP blocks, and the critical path of the median seed. A design
//! that needs more of the part than it has is a row saying so ("does not fit"), not an error.
//!
//! Every row is placed in context (its ports on the package's pins) where it can be. An ECP5
//! or Gowin design with more port bits than the package has pins (eight lanes on CABGA381) is
//! placed out of context ([`fpga::Options::out_of_context`]: an IP core timed without its
//! pins), and its row says so; the first seed decides, from nextpnr's complaint or the Gowin
//! pin file's ([`fpga::DoesNotFit::pins`]), so no pin count is kept here. The iCE40 rows are on the HX8K in ct256 (nextpnr-ice40 has no out-of-context
//! mode, and a design that does not fit its pins does not fit).
//!
//! The multiplier style (`--mult`, [`Mult`]) is a column: adder trees of partial products
//! (`tree`) and plain products a DSP block can absorb (`infer`) of the same lane count and
//! family are rows of the same table.
//!
//! The tables are rewritten after every row, in the sweep's staging directory, and each row is
//! reported as a Markdown line as soon as it is measured: a sweep stopped part-way (it takes
//! hours) still leaves the rows it finished (see [`run`]).

use crate::config::{Config, Mult, Target};
use crate::flow::fpga::{self, Family, FpgaReport};
use crate::output::StagedDir;
use anyhow::{Context, Result};
use serde::Serialize;
use std::path::Path;

/// Which design a row places.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// Every ROM read with a copy of its own, on every family ([`replicated`]): each family's
    /// rows place the same design.
    #[default]
    Replicated,
    /// Each family's own design (`--target <family>`), the one `rmapgen fpga --family F`
    /// places: its block RAM's read ports shared where it has two.
    Family,
}

impl Layout {
    /// As `--layout` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Replicated => "replicated",
            Layout::Family => "family",
        }
    }

    /// The target a row of `family` is generated for.
    pub fn target(self, family: Family) -> Target {
        match self {
            Layout::Replicated => replicated(),
            Layout::Family => Target::Family(family),
        }
    }
}

/// What to sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub lanes: Vec<u32>,
    pub families: Vec<Family>,
    /// Multiplier styles.
    pub mults: Vec<Mult>,
    /// Placer seeds; the row's Fmax is their median.
    pub seeds: Vec<u64>,
    /// The clock the placer aims at, MHz.
    pub freq_mhz: f64,
    /// The design each row places.
    pub layout: Layout,
}

/// The lane counts of the full sweep.
pub const LANES: [u32; 4] = [1, 2, 4, 8];
/// The families of the full sweep.
pub const FAMILIES: [Family; Family::ALL.len()] = Family::ALL;
/// Seeds of the full sweep: 1..=SEEDS.
pub const SEEDS: u64 = 5;
/// The placer's target in the sweep, MHz: above what the iCE40 and ECP5 parts reach with this
/// design, so that the placer keeps pushing for timing on every seed. (The Gowin GW2A-18
/// reaches 243-264 MHz with one lane: above it; the sweep's figures predate the family.)
pub const FREQ_MHZ: f64 = 200.0;
/// The multiplier styles of the full sweep.
pub const MULTS: [Mult; 2] = [Mult::Tree, Mult::Infer];

impl Default for Sweep {
    fn default() -> Self {
        Sweep {
            lanes: LANES.to_vec(),
            families: FAMILIES.to_vec(),
            mults: MULTS.to_vec(),
            seeds: (1..=SEEDS).collect(),
            freq_mhz: FREQ_MHZ,
            layout: Layout::default(),
        }
    }
}

/// One placed seed.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Seed {
    pub seed: u64,
    pub fmax_mhz: f64,
}

/// One configuration of the sweep.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Row {
    pub family: Family,
    /// The design it places (absent in tables written before 2026-12-07: replicated).
    #[serde(default)]
    pub layout: Layout,
    pub device: String,
    pub package: String,
    pub out_of_context: bool,
    pub lanes: u32,
    pub mult: Mult,
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

/// The part each family is swept on, in context.
fn options(family: Family, freq_mhz: f64) -> fpga::Options {
    fpga::Options {
        freq_mhz,
        ..fpga::Options::for_family(family)
    }
}

/// Runs the sweep, family by family, lane count by lane count, multiplier style by style;
/// logs of each configuration under `out/<family>-l<lanes>-<mult>/` (the netlist, yosys.log,
/// nextpnr_seed<N>.log and its report). After every row the tables ([`write`]) are rewritten
/// in `out` with the rows so far, and `progress` hears the row as a Markdown line (it hears
/// each step too): a sweep stopped part-way keeps what it measured.
/// The memory layout of the sweep's designs, on every family: every ROM read has a copy of its
/// own (a family target whose block RAM has one read port: no ROM shared between lanes), which
/// docs/PERFORMANCE.md measured faster than sharing on the ECP5 too (eight lanes, 1.013 against
/// 0.987 x 10^9 samples/s), so each family's rows place the same design.
fn replicated() -> Target {
    Family::ALL
        .into_iter()
        .find(|f| f.get().block_ram.read_ports == 1)
        .map(Target::Family)
        .expect("a family whose block RAM has one read port")
}

pub fn run(sweep: &Sweep, out: &StagedDir, progress: &dyn Fn(&str)) -> Result<Vec<Row>> {
    anyhow::ensure!(!sweep.seeds.is_empty(), "the sweep has no seeds");
    let mut rows = Vec::new();
    for &family in &sweep.families {
        for &lanes in &sweep.lanes {
            for &mult in &sweep.mults {
                let cfg = Config {
                    lanes,
                    mult,
                    ..Config::default()
                }
                .for_target(sweep.layout.target(family));
                cfg.validate()?;
                let name = format!("{}-l{lanes}-{}", family.name(), mult.name());
                let logs = out.path().join(&name);
                progress(&format!("{name}: synthesis"));
                let row = configuration(&cfg, family, sweep, &logs, &name, progress)
                    .with_context(|| format!("throughput sweep, {name}"))?;
                progress(&format!("{name}: {}", line(&row).trim_end()));
                rows.push(row);
                write(&rows, out)?;
            }
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
    crate::emit::write_design(&design, &rtl, None)?;
    let dir = rtl.commit()?;
    let memories = crate::emit::manifest::memories(cfg);
    let memory_bits: u64 = memories.iter().map(|m| m.bits).sum();
    let mut opts = options(family, sweep.freq_mhz);
    opts.logs = Some(logs.to_path_buf());
    let mut row = Row {
        family,
        layout: sweep.layout,
        device: opts.device.clone(),
        package: opts.package.clone(),
        out_of_context: opts.out_of_context,
        lanes: cfg.lanes,
        mult: cfg.mult,
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
        let mut placed = fpga::place(&syn, &opts);
        // Too few pins for the ports (the first seed in context tells): the row is
        // placed out of context from here on, every seed alike. The in-context attempt's log
        // is kept beside the others. Like the seeds' files below, it is renamed only inside
        // `logs`, in the sweep's own staging directory, where `fpga::place` has just written it.
        let short = placed
            .as_ref()
            .err()
            .and_then(|e| e.downcast_ref::<fpga::DoesNotFit>())
            .filter(|d| d.pins)
            .map(|d| d.message.clone());
        if let Some(said) = short.filter(|_| family.get().out_of_context && !opts.out_of_context) {
            progress(&format!(
                "{name}: more port bits than pins; placing out of context"
            ));
            let (stem, ext) = split(crate::toolchain::nextpnr::LOG);
            let to = logs.join(format!("{stem}_in_context.{ext}"));
            let log = logs.join(crate::toolchain::nextpnr::LOG);
            // A Gowin pin file finds too few pins before nextpnr runs: no log but its words.
            if log.exists() {
                std::fs::rename(&log, &to)
            } else {
                std::fs::write(&to, format!("{said}\n"))
            }
            .with_context(|| format!("cannot write {}", to.display()))?;
            opts.out_of_context = true;
            row.out_of_context = true;
            placed = fpga::place(&syn, &opts);
        }
        match placed {
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
            let (stem, ext) = split(f);
            let to = logs.join(format!("{stem}_seed{seed}.{ext}"));
            std::fs::rename(logs.join(f), &to)
                .with_context(|| format!("cannot write {}", to.display()))?;
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

/// A log file's name as stem and extension.
fn split(f: &str) -> (&str, &str) {
    f.rsplit_once('.').unwrap_or((f, ""))
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

/// The header of the Markdown table.
const HEADER: &str = "| family | part | placed | lanes | mult | design | Fmax median (MHz) | Fmax per seed (MHz) | samples/s | logic cells | LUT4 | flip-flops | block RAMs | DSP | memory bits per lane |\n\
     |---|---|---|---:|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|\n";

/// How a row was placed, as its column says it.
fn placed(r: &Row) -> &'static str {
    if r.out_of_context {
        "out of context (more port bits than pins)"
    } else {
        "in context"
    }
}

/// One row of the Markdown table, with its line end.
pub fn line(r: &Row) -> String {
    let head = format!(
        "| {} | {} {} | {} | {} | {} | {} |",
        r.family.title(),
        r.device,
        r.package,
        placed(r),
        r.lanes,
        r.mult.name(),
        r.layout.name()
    );
    match (&r.report, r.fmax_mhz, r.samples_per_s) {
        (Some(p), Some(f), Some(sps)) => {
            let seeds: Vec<String> = r
                .seeds
                .iter()
                .map(|x| format!("{:.1}", x.fmax_mhz))
                .collect();
            format!(
                "{head} {f:.1} | {} | {:.3e} | {} | {} | {} | {} | {} | {} |\n",
                seeds.join(", "),
                sps,
                p.logic_cells,
                p.luts,
                p.flip_flops,
                p.block_rams,
                p.dsps,
                r.memory_bits_per_lane
            )
        }
        _ => format!(
            "{head} does not fit | | | | | | | | {} |\n",
            r.memory_bits_per_lane
        ),
    }
}

/// The rows as a Markdown table, then the critical path of the best row.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(HEADER);
    for r in rows {
        s += &line(r);
    }
    if let Some(b) = best(rows) {
        if let Some(c) = b.report.as_ref().and_then(|p| p.critical_path.as_ref()) {
            s += &format!(
                "\nBest: {} {} lanes ({}, {}), {:.3e} samples/s; critical path of seed {} ({:.1} ns logic, {:.1} ns routing): {}\n",
                b.family.title(),
                b.lanes,
                b.mult.name(),
                placed(b),
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
            "\n{} {} lanes ({}) does not fit: {}\n",
            r.family.title(),
            r.lanes,
            r.mult.name(),
            r.does_not_fit.as_deref().unwrap_or("")
        );
    }
    s
}

/// The rows as CSV with a header line.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("family,device,package,out_of_context,lanes,mult,layout,fits,fmax_mhz_median,fmax_mhz_seeds,samples_per_s,logic_cells,luts,flip_flops,block_rams,dsps,memory_bits,memory_bits_per_lane\n");
    for r in rows {
        let p = r.report.as_ref();
        let seeds: Vec<String> = r
            .seeds
            .iter()
            .map(|x| format!("{:.2}", x.fmax_mhz))
            .collect();
        let n = |f: fn(&FpgaReport) -> u32| p.map_or(String::new(), |p| f(p).to_string());
        s += &format!(
            "{},{},{},{},{},{},{},{},{},\"{}\",{},{},{},{},{},{},{},{}\n",
            r.family.name(),
            r.device,
            r.package,
            r.out_of_context,
            r.lanes,
            r.mult.name(),
            r.layout.name(),
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

    fn row(family: Family, lanes: u32, mult: Mult, out_of_context: bool) -> Row {
        Row {
            family,
            layout: Layout::Replicated,
            device: "85k".into(),
            package: "CABGA381".into(),
            out_of_context,
            lanes,
            mult,
            does_not_fit: None,
            seeds: Vec::new(),
            fmax_mhz: None,
            samples_per_s: None,
            report: None,
            memory_bits: 8,
            memory_bits_per_lane: 1,
        }
    }

    #[test]
    fn a_row_says_how_it_was_placed_and_its_multiplier() {
        let mut r = row(Family::Ecp5, 8, Mult::Infer, true);
        r.does_not_fit = Some("no BELs".into());
        let l = line(&r);
        assert!(
            l.starts_with("| ECP5 | 85k CABGA381 | out of context (more port bits than pins) | 8 | infer | replicated | does not fit |"),
            "{l}"
        );
        let l = line(&row(Family::Ecp5, 1, Mult::Tree, false));
        assert!(l.contains("| in context | 1 | tree | replicated |"), "{l}");
        // Every line has the header's columns.
        let md = markdown(&[r.clone(), row(Family::Ice40, 2, Mult::Tree, false)]);
        let bars: Vec<usize> = md.lines().take(4).map(|x| x.matches('|').count()).collect();
        assert!(bars.iter().all(|&n| n == bars[0]), "{md}");
        assert!(
            md.contains("ECP5 8 lanes (infer) does not fit: no BELs"),
            "{md}"
        );
        let c = csv(&[r]);
        assert!(
            c.lines()
                .nth(1)
                .unwrap()
                .starts_with("ecp5,85k,CABGA381,true,8,infer,replicated,false,"),
            "{c}"
        );
    }

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[150.0, 140.0, 145.0, 160.0, 130.0]), 145.0);
        assert_eq!(median(&[150.0, 140.0]), 145.0);
    }
}
