//! The report of one shard of `rmapgen prove` (JSON, `--report FILE`) and the merge of a
//! run's shard reports into one verdict (`rmapgen prove --merge`).
//!
//! A report names what was proven: the configuration and the SHA-256 of every file the
//! proof read (each marked as generated or edited, against the design's `.rmapgen-files`);
//! and each part's range and the inputs it checked. So the merge refuses shards of different
//! designs or files, a part or shard missing or repeated, totals the configuration does not
//! give and parts that checked less than they claim.

use super::{Failures, Options, Shard};
use crate::design_dir::DesignDir;
use anyhow::{bail, ensure, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The report format's name, which the merge checks.
pub const FORMAT: &str = "rmapgen-prove-2";

/// One part of the proof in one shard: inputs `first..end` of `total`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Part {
    pub name: String,
    pub first: u64,
    pub end: u64,
    pub total: u64,
    /// Inputs the part checked: driven through the simulation or the gates and compared
    /// with the model, counted where that happened. A part whose count differs from its
    /// range failed.
    pub ran: u64,
    pub failures: u64,
    pub examples: Vec<String>,
    /// Wall-clock seconds the part took (its builds included).
    #[serde(default)]
    pub seconds: f64,
    /// CPU seconds of this process in the part (not the builds', which run in children).
    #[serde(default)]
    pub cpu_seconds: f64,
    /// What evaluated the part, when it has a choice (the front: gates or verilator).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub engine: String,
}

impl Part {
    /// The part over `range` of its `total` inputs; it fails unless it checked exactly the
    /// inputs of its range.
    pub fn new(name: &str, range: std::ops::Range<u64>, total: u64, mut f: Failures) -> Part {
        let claimed = range.end - range.start;
        if f.checked != claimed {
            f.add(format!(
                "{name}: checked {} inputs, not the {claimed} of its range [{}..{})",
                f.checked, range.start, range.end
            ));
        }
        Part {
            name: name.into(),
            first: range.start,
            end: range.end,
            total,
            ran: f.checked,
            failures: f.count,
            examples: f.kept,
            seconds: 0.0,
            cpu_seconds: 0.0,
            engine: String::new(),
        }
    }

    /// The part, evaluated by `engine`.
    pub fn engine(mut self, engine: &str) -> Part {
        self.engine = engine.into();
        self
    }

    /// The part, timed from `start`.
    pub fn since(mut self, start: (std::time::Instant, f64)) -> Part {
        self.seconds = start.0.elapsed().as_secs_f64();
        self.cpu_seconds = cpu_seconds() - start.1;
        self
    }
}

/// Now, for [`Part::since`]: the wall clock and this process's CPU seconds.
pub fn now() -> (std::time::Instant, f64) {
    (std::time::Instant::now(), cpu_seconds())
}

/// User and system CPU seconds of this process so far, from /proc/self/stat (Linux; 0
/// elsewhere), in clock ticks of 1/100 s.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which may hold spaces) start at state, field 3.
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// One file of the design that the proof read (the simulation, the netlist or the model),
/// with its SHA-256 when the run started and whether it is as `rmapgen generate` wrote it
/// (its digest in the design's `.rmapgen-files`).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub struct FileHash {
    pub name: String,
    pub sha256: String,
    /// False: edited since it was generated (or not listed in `.rmapgen-files`).
    pub as_generated: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub format: String,
    /// The design directory as given.
    pub design: String,
    /// The configuration proven, from the design's manifest.
    pub config: crate::config::Config,
    pub config_summary: String,
    /// Every file the proof read, by name, with its SHA-256: what was proven.
    pub files: Vec<FileHash>,
    pub mode: String,
    pub shard: Shard,
    pub parts: Vec<Part>,
    pub seconds: f64,
    pub passed: bool,
}

/// The files of design `d` that a proof reads: the manifest, the Verilog (the manifest's
/// modules: the simulation, the netlist and the gates), every `$readmemh` file of the top
/// (the simulation's memories) and the map files the model reads (both buffers), sorted.
pub fn read_files(d: &DesignDir) -> Vec<String> {
    let cfg = &d.config;
    let mut names: Vec<String> = d.file_names().to_vec();
    names.push(crate::emit::manifest::FILE.to_string());
    names.extend(
        crate::emit::tb::top_files(cfg)
            .into_iter()
            .map(|f| f.default),
    );
    for buf in 0..2 {
        for name in crate::model::map_set::buffer_names(cfg) {
            names.push(crate::model::map_set::map_file(cfg, buf, name));
        }
    }
    names.sort();
    names.dedup();
    names
}

/// The SHA-256 of every file in `names` of design `d`, each marked as generated or edited
/// against the design's `.rmapgen-files`.
pub fn hash_files(d: &DesignDir, names: &[String]) -> Result<Vec<FileHash>> {
    let stamp = crate::output::stamp::read(d.path()).unwrap_or_default();
    names
        .iter()
        .map(|n| {
            let sha256 = crate::output::stamp::digest(&d.path().join(n))?;
            let as_generated = stamp.get(n) == Some(&sha256);
            Ok(FileHash {
                name: n.clone(),
                sha256,
                as_generated,
            })
        })
        .collect()
}

/// The files of `files` that differ from what rmapgen generated, for messages.
pub fn edited(files: &[FileHash]) -> Vec<&str> {
    files
        .iter()
        .filter(|f| !f.as_generated)
        .map(|f| f.name.as_str())
        .collect()
}

impl Report {
    /// The report of a run of `d` that read `files` (hashed when it started).
    pub fn new(
        d: &DesignDir,
        opts: &Options,
        files: Vec<FileHash>,
        parts: Vec<Part>,
        seconds: f64,
    ) -> Result<Report> {
        let passed = parts.iter().all(|p| p.failures == 0);
        Ok(Report {
            format: FORMAT.into(),
            design: d.path().display().to_string(),
            config: d.config.clone(),
            config_summary: d.config.summary(),
            files,
            mode: if opts.direct { "direct" } else { "factored" }.into(),
            shard: opts.shard,
            parts,
            seconds,
            passed,
        })
    }

    /// Lines for the terminal: one per part, then the failures kept.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "prove {} ({}, shard {}/{}, {}):\n",
            self.design, self.config_summary, self.shard.index, self.shard.count, self.mode
        );
        let outer = crate::stages::top(&self.config);
        if outer.name() != crate::stages::TOP.name() {
            // What the verdict covers: the proof drives rmap_top, not the module around it
            // (the AXI4-Stream wrapper, the bus slave), and names what does check that one
            // (it does not run it).
            let what = if self.config.bus.is_none() {
                "the AXI4-Stream wrapper"
            } else {
                "the bus slave"
            };
            s += &format!(
                "  scope             {} inside {} (the proof does not drive {what}: {} checks it)\n",
                crate::stages::TOP.module(&self.config),
                outer.module(&self.config),
                crate::stages::checked_by(&self.config)
            );
        }
        for p in &self.parts {
            let name = if p.engine.is_empty() {
                p.name.clone()
            } else {
                format!("{} ({})", p.name, p.engine)
            };
            // What the part checked (counted as it ran), of its total, and its range.
            s += &format!(
                "  {:<17} {:>14} of {:>14} inputs [{}..{}) {:>7.1} s ({:.1} s CPU): {}\n",
                name,
                p.ran,
                p.total,
                p.first,
                p.end,
                p.seconds,
                p.cpu_seconds,
                if p.failures == 0 {
                    "pass".to_string()
                } else {
                    format!("{} FAILED", p.failures)
                }
            );
            for e in &p.examples {
                s += &format!("    {e}\n");
            }
        }
        let edited = edited(&self.files);
        s += &format!(
            "  files             {} read, SHA-256 in the report; {}\n",
            self.files.len(),
            if edited.is_empty() {
                "all as generated (.rmapgen-files)".to_string()
            } else {
                format!(
                    "edited since generated (not as in .rmapgen-files): {}",
                    edited.join(", ")
                )
            }
        );
        s += &format!(
            "{} in {:.1} s\n",
            if self.passed { "PASSED" } else { "FAILED" },
            self.seconds
        );
        s
    }
}

/// The verdict of a whole run.
pub struct Merged {
    pub passed: bool,
    pub text: String,
}

/// The most report files `--merge` reads (as many as [`super::MAX_SHARDS`]), and the largest
/// report it reads (a report is a few kilobytes: its parts and at most
/// [`super::KEEP_FAILURES`] messages each).
const MAX_REPORT_BYTES: u64 = 4 << 20;

/// Combines the reports of every shard of one run. The reports must together cover every
/// part of the run's mode exactly once, shard by shard, for one configuration and the same
/// files (by SHA-256): each shard given once, each with every part, each part's ranges tiling
/// its total, each total the one the configuration gives, each part having checked every
/// input of its range. Anything else is bad input (an error, one line); a failed part is a
/// verdict.
pub fn merge(files: &[PathBuf]) -> Result<Merged> {
    ensure!(!files.is_empty(), "give the shard reports to merge");
    ensure!(
        files.len() as u64 <= super::MAX_SHARDS,
        "{} reports given; a run has at most {} shards",
        files.len(),
        super::MAX_SHARDS
    );
    let reports: Vec<Report> = files.iter().map(|f| read(f)).collect::<Result<_>>()?;
    let first = &reports[0];
    let n = first.shard.count;
    for (r, f) in reports.iter().zip(files) {
        if r.config != first.config || r.mode != first.mode {
            bail!(
                "{} is a report of another configuration or mode than {} ({} {}, not {} {})",
                f.display(),
                files[0].display(),
                r.config_summary,
                r.mode,
                first.config_summary,
                first.mode
            );
        }
        if r.files != first.files {
            let differ: Vec<&str> = r
                .files
                .iter()
                .filter(|x| !first.files.contains(x))
                .map(|x| x.name.as_str())
                .collect();
            bail!(
                "{} proved other files than {} (they differ in {})",
                f.display(),
                files[0].display(),
                if differ.is_empty() {
                    "the list of files".to_string()
                } else {
                    differ.join(", ")
                }
            );
        }
        if r.shard.count != n {
            bail!(
                "{} is shard {}/{}, not of {n}",
                f.display(),
                r.shard.index,
                r.shard.count
            );
        }
    }
    // n is at most MAX_SHARDS (read checks it), and as many reports were read.
    let mut seen = vec![false; n as usize];
    for (r, f) in reports.iter().zip(files) {
        let k = r.shard.index as usize - 1;
        if seen[k] {
            bail!("shard {}/{n} given twice ({})", r.shard.index, f.display());
        }
        seen[k] = true;
    }
    if let Some(k) = seen.iter().position(|s| !s) {
        bail!("shard {}/{n} is missing", k + 1);
    }
    let direct = match first.mode.as_str() {
        "direct" => true,
        "factored" => false,
        m => bail!(
            "{}: mode {m:?} is neither factored nor direct",
            files[0].display()
        ),
    };
    let cfg = &first.config;
    cfg.validate()
        .with_context(|| format!("{}: config", files[0].display()))?;
    super::check_limits(cfg, direct, n)
        .with_context(|| format!("{}: config", files[0].display()))?;
    let totals = super::totals(cfg, direct)?;
    // Every report has exactly the run's parts, each once.
    for (r, f) in reports.iter().zip(files) {
        let mut names: Vec<&str> = r.parts.iter().map(|p| p.name.as_str()).collect();
        names.sort();
        let mut want: Vec<&str> = totals.iter().map(|t| t.0).collect();
        want.sort();
        if names != want {
            let missing: Vec<&str> = want
                .iter()
                .filter(|w| !names.contains(w))
                .copied()
                .collect();
            bail!(
                "{} (shard {}/{n}) has the parts [{}], not those of a {} run [{}]{}",
                f.display(),
                r.shard.index,
                names.join(", "),
                first.mode,
                want.join(", "),
                if missing.is_empty() {
                    String::new()
                } else {
                    format!(
                        ": {} missing (a --part run does not merge)",
                        missing.join(", ")
                    )
                }
            );
        }
    }
    let mut text = format!(
        "prove {} ({}, {} shards, {}):\n",
        first.design, first.config_summary, n, first.mode
    );
    let mut passed = true;
    for &(name, total) in &totals {
        let mut ranges: Vec<(&Part, u64)> = reports
            .iter()
            .map(|r| {
                let p = r
                    .parts
                    .iter()
                    .find(|p| p.name == name)
                    .expect("checked above");
                (p, r.shard.index)
            })
            .collect();
        ranges.sort_by_key(|(p, _)| (p.first, p.end));
        let mut at = 0;
        for (p, k) in &ranges {
            ensure!(
                p.total == total,
                "part {name} of shard {k}/{n} claims {} inputs; the configuration gives {total}",
                p.total
            );
            ensure!(
                p.first == at && p.end >= p.first,
                "part {name}: the shards' ranges do not tile 0..{total} (a gap or overlap at {at}, shard {k}/{n})"
            );
            ensure!(
                p.ran == p.end - p.first,
                "part {name} of shard {k}/{n} checked {} inputs of its {} ([{}..{}))",
                p.ran,
                p.end - p.first,
                p.first,
                p.end
            );
            at = p.end;
        }
        ensure!(
            at == total,
            "part {name}: the shards stop at {at} of {total}"
        );
        // Saturating: forged counts that wrapped around to 0 would pass.
        let failures = ranges
            .iter()
            .fold(0u64, |n, (p, _)| n.saturating_add(p.failures));
        passed &= failures == 0;
        // The engines the shards used for the part (shards may differ: each proves its range).
        let mut engines: Vec<&str> = ranges
            .iter()
            .map(|(p, _)| p.engine.as_str())
            .filter(|e| !e.is_empty())
            .collect();
        engines.sort();
        engines.dedup();
        let label = if engines.is_empty() {
            name.to_string()
        } else {
            format!("{name} ({})", engines.join(", "))
        };
        text += &format!(
            "  {label:<17} {total:>14} inputs: {}\n",
            if failures == 0 {
                "pass".to_string()
            } else {
                format!("{failures} FAILED")
            }
        );
        for (p, _) in ranges.iter().filter(|(p, _)| p.failures > 0) {
            for e in &p.examples {
                text += &format!("    {e}\n");
            }
        }
    }
    let edited = edited(&first.files);
    text += &format!(
        "  files             {} proven by SHA-256{}\n",
        first.files.len(),
        if edited.is_empty() {
            ", all as generated".to_string()
        } else {
            format!("; edited since generated: {}", edited.join(", "))
        }
    );
    let seconds: f64 = reports.iter().map(|r| r.seconds).sum();
    text += &format!(
        "{}: {} ({} gradients), {:.0} s of shard time\n",
        if passed { "PROVEN" } else { "FAILED" },
        first.config_summary,
        1u64 << (3 * cfg.grad_bits),
        seconds
    );
    Ok(Merged { passed, text })
}

/// Reads report `f`: at most [`MAX_REPORT_BYTES`] (one byte more is read to tell, never the
/// length a file's metadata claims: a device or a FIFO says 0 and never ends), a report of
/// this format whose fields agree with each other ([`contradiction`]).
fn read(f: &Path) -> Result<Report> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(f)
        .and_then(|file| file.take(MAX_REPORT_BYTES + 1).read_to_end(&mut bytes))
        .with_context(|| format!("cannot read {}", f.display()))?;
    ensure!(
        bytes.len() as u64 <= MAX_REPORT_BYTES,
        "{} is larger than {MAX_REPORT_BYTES} bytes, not a report of rmapgen prove",
        f.display()
    );
    let text = String::from_utf8(bytes)
        .with_context(|| format!("{} is not a report of rmapgen prove", f.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a report of rmapgen prove", f.display()))?;
    ensure!(
        v["format"].as_str() == Some(FORMAT),
        "{} is not a report of rmapgen prove in format {FORMAT} (its format is {}; prove the design again with this rmapgen)",
        f.display(),
        v["format"]
    );
    let r: Report = serde_json::from_value(v)
        .with_context(|| format!("{} is not a report of rmapgen prove", f.display()))?;
    ensure!(
        (1..=super::MAX_SHARDS).contains(&r.shard.count)
            && (1..=r.shard.count).contains(&r.shard.index),
        "{}: shard {}/{} is not a shard (N in 1..={})",
        f.display(),
        r.shard.index,
        r.shard.count,
        super::MAX_SHARDS
    );
    if let Some(c) = contradiction(&r) {
        bail!(
            "{}: {c}; rmapgen prove writes no such report (was it edited?): prove the shard again",
            f.display()
        );
    }
    Ok(r)
}

/// The first field of report `r` that contradicts another, as `field: what`: rmapgen prove
/// writes every report consistent, so such a report was edited or damaged and gives no
/// verdict (the merge refuses it, rather than trust one field over the other).
/// - `passed` is true exactly when no part failed;
/// - a part keeps the first [`super::KEEP_FAILURES`] of its `failures` as `examples`, so
///   there are as many examples as failures, up to that many;
/// - a part without failures checked exactly the inputs of its range (one that checked
///   fewer or more has failed: [`Part::new`]), and its range lies within its `total`;
/// - times are finite and not negative;
/// - `config_summary` is the configuration's, the front names the engine that evaluated it
///   (and no other part names one), and the files are listed once each, sorted, by a
///   SHA-256 (64 lower-case hex digits).
pub fn contradiction(r: &Report) -> Option<String> {
    let time = |field: &str, s: f64| {
        (!(s.is_finite() && s >= 0.0))
            .then(|| format!("{field} is {s}, not a time (finite, at least 0)"))
    };
    if let Some(e) = time("seconds", r.seconds) {
        return Some(e);
    }
    let failed = r.parts.iter().any(|p| p.failures > 0);
    if r.passed == failed {
        return Some(format!(
            "passed is {}, but {} part failed",
            r.passed,
            if failed { "a" } else { "no" }
        ));
    }
    let summary = r.config.summary();
    if r.config_summary != summary {
        return Some(format!(
            "config_summary is {:?}, but its config is {summary:?}",
            r.config_summary
        ));
    }
    for (i, p) in r.parts.iter().enumerate() {
        let at = format!("parts[{i}] ({})", p.name);
        let kept = p.failures.min(super::KEEP_FAILURES as u64);
        if p.examples.len() as u64 != kept {
            return Some(format!(
                "{at}: examples lists {} failures, but failures is {} (the first {} are kept)",
                p.examples.len(),
                p.failures,
                super::KEEP_FAILURES
            ));
        }
        if !(p.first <= p.end && p.end <= p.total) {
            return Some(format!(
                "{at}: the range [{}..{}) is not within its total {}",
                p.first, p.end, p.total
            ));
        }
        if p.failures == 0 && p.ran != p.end - p.first {
            return Some(format!(
                "{at}: ran is {}, not the {} inputs of its range [{}..{}), but failures is 0 (checked other than its range is a failure)",
                p.ran,
                p.end - p.first,
                p.first,
                p.end
            ));
        }
        if let Some(e) = time(&format!("{at}: seconds"), p.seconds)
            .or_else(|| time(&format!("{at}: cpu_seconds"), p.cpu_seconds))
        {
            return Some(e);
        }
        let engine_ok = if p.name == "front" {
            <super::FrontEngine as clap::ValueEnum>::value_variants()
                .iter()
                .any(|e| e.name() == p.engine)
        } else {
            p.engine.is_empty()
        };
        if !engine_ok {
            return Some(format!(
                "{at}: engine {:?} is not what evaluates it",
                p.engine
            ));
        }
    }
    for (i, f) in r.files.iter().enumerate() {
        let hex = f.sha256.len() == 64
            && f.sha256
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
        if !hex {
            return Some(format!(
                "files[{i}] ({}): sha256 {:?} is not a SHA-256 (64 lower-case hex digits)",
                f.name, f.sha256
            ));
        }
        if i > 0 && r.files[i - 1].name >= f.name {
            return Some(format!(
                "files[{i}] ({}) is listed twice or out of order",
                f.name
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    /// The narrowest grid row: 2^24 gradients, 1,872,000 states.
    fn cfg() -> Config {
        crate::grid::narrowest()
    }

    fn files() -> Vec<FileHash> {
        ["manifest.json", "recip_rom.hex", "rmap_top.v"]
            .iter()
            .enumerate()
            .map(|(k, n)| FileHash {
                name: n.to_string(),
                sha256: format!("{k:064x}"),
                as_generated: true,
            })
            .collect()
    }

    #[test]
    fn the_files_read_are_the_designs_verilog_memories_and_manifest_each_hashed() {
        let (_t, d) = crate::prove::tests::design(&cfg());
        let names = read_files(&d);
        // Exactly the design's top-level Verilog and $readmemh files and its manifest: what
        // the simulation, the netlist and the model read (not the testbenches or vectors).
        let mut want: Vec<String> = std::fs::read_dir(d.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.ends_with(".v") || n.ends_with(".hex") || n == "manifest.json")
            .collect();
        want.sort();
        assert_eq!(names, want);
        assert_eq!(names.len(), 23, "{names:?}");
        for n in [
            "rmap_top.v",
            "recip_rom.hex",
            "map_x.hex",
            "map2_z.hex",
            "map_bank_11.hex",
        ] {
            assert!(names.iter().any(|x| x == n), "{n} is read");
        }
        let hashed = hash_files(&d, &names).unwrap();
        assert_eq!(hashed.len(), names.len());
        for (h, n) in hashed.iter().zip(&names) {
            assert_eq!(&h.name, n);
            assert_eq!(
                h.sha256,
                crate::output::stamp::digest(&d.path().join(n)).unwrap()
            );
            assert!(h.as_generated, "{n} is as generated");
        }
        assert!(edited(&hashed).is_empty());
        // One entry of the reciprocal ROM changed: that file alone is edited, its hash new.
        let rom = d.path().join("recip_rom.hex");
        let text = std::fs::read_to_string(&rom).unwrap();
        let changed = text.replacen(|c: char| c.is_ascii_hexdigit(), "f", 1);
        let changed = if changed == text {
            text.replacen('f', "0", 1)
        } else {
            changed
        };
        std::fs::write(&rom, changed).unwrap();
        let after = hash_files(&d, &names).unwrap();
        assert_eq!(edited(&after), ["recip_rom.hex"]);
        for (a, h) in after.iter().zip(&hashed) {
            assert_eq!(
                a.sha256 == h.sha256,
                a.name != "recip_rom.hex",
                "{}",
                a.name
            );
        }
    }

    #[test]
    fn a_part_is_timed_in_wall_and_cpu_seconds_and_names_its_engine() {
        // CPU seconds are this process's user and system time, as getrusage counts them.
        let rusage = || {
            let mut u: libc::rusage = unsafe { std::mem::zeroed() };
            assert_eq!(unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) }, 0);
            let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 / 1e6;
            (s(u.ru_utime), s(u.ru_stime))
        };
        // Enough system time (metadata calls) and user time (a busy loop) that a swapped
        // field, a sign or a scale shows.
        while rusage().1 < 0.05 {
            for _ in 0..1000 {
                let _ = std::fs::metadata("/");
            }
        }
        let start = now();
        assert!(start.1 >= 0.05, "{start:?}");
        let (user0, _) = rusage();
        let mut x = 1u64;
        while rusage().0 < user0 + 0.2 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
        }
        let (user, sys) = rusage();
        let mine = cpu_seconds();
        assert!(
            (mine - (user + sys)).abs() < 0.05,
            "cpu_seconds {mine} against getrusage {user} + {sys}"
        );
        let p = Part::new("front", 0..1, 1, Failures::default())
            .since(start)
            .engine("gates");
        assert_eq!(p.engine, "gates");
        // The part's CPU seconds are those since its start: at least the busy loop's.
        assert!(
            p.cpu_seconds >= 0.15 && (p.cpu_seconds - (mine - start.1)).abs() < 0.021,
            "{p:?} {mine} {start:?}"
        );
        assert!(p.seconds > 0.0 && p.seconds < 600.0, "{p:?}");
        assert_eq!(Part::new("zero", 0..1, 1, Failures::default()).engine, "");
    }

    /// The reports of an honest run of `n` shards that every part passed.
    fn run(n: u64, direct: bool) -> Vec<Report> {
        run_of(&cfg(), n, direct)
    }

    /// The same, of a design of `cfg`.
    fn run_of(cfg: &Config, n: u64, direct: bool) -> Vec<Report> {
        let totals = crate::prove::totals(cfg, direct).unwrap();
        (1..=n)
            .map(|k| {
                let shard = Shard { index: k, count: n };
                let parts = totals
                    .iter()
                    .map(|&(name, total)| {
                        let range = match name {
                            "structure" if k == 1 => 0..1,
                            "structure" => 1..1,
                            _ => shard.range(total),
                        };
                        let f = Failures {
                            checked: range.end - range.start,
                            ..Failures::default()
                        };
                        let p = Part::new(name, range, total, f);
                        if name == "front" {
                            p.engine(if k == 1 { "gates" } else { "verilator" })
                        } else {
                            p
                        }
                    })
                    .collect();
                Report {
                    format: FORMAT.into(),
                    design: "d".into(),
                    config: cfg.clone(),
                    config_summary: cfg.summary(),
                    files: files(),
                    mode: if direct { "direct" } else { "factored" }.into(),
                    shard,
                    parts,
                    seconds: 1.0,
                    passed: true,
                }
            })
            .collect()
    }

    fn merge_reports(reports: &[Report]) -> Result<Merged> {
        let dir = tempfile::tempdir().unwrap();
        let paths: Vec<PathBuf> = reports
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let p = dir.path().join(format!("{k}.json"));
                std::fs::write(&p, serde_json::to_string(r).unwrap()).unwrap();
                p
            })
            .collect();
        merge(&paths)
    }

    fn refused(reports: &[Report], want: &str) {
        match merge_reports(reports) {
            Ok(m) => panic!("merged, should be refused ({want}):\n{}", m.text),
            Err(e) => {
                let e = format!("{e:#}");
                assert!(e.contains(want), "{e:?} should contain {want:?}");
            }
        }
    }

    #[test]
    fn an_honest_run_merges_and_a_failed_part_fails_it() {
        for direct in [false, true] {
            for n in [1, 3] {
                let m = merge_reports(&run(n, direct)).unwrap();
                assert!(m.passed, "{}", m.text);
                assert!(m.text.contains("PROVEN: G8 "), "{}", m.text);
                assert!(m.text.contains("(16777216 gradients)"), "{}", m.text);
                assert!(m.text.contains("3 proven by SHA-256, all as generated"));
                // The engines the shards used, each named once; parts without one bare.
                let want = if n == 1 {
                    "front (gates)"
                } else {
                    "front (gates, verilator)"
                };
                assert_eq!(direct, !m.text.contains(want), "{}", m.text);
                assert!(m.text.contains("  states ") || direct, "{}", m.text);
            }
        }
        let mut r = run(2, false);
        r[1].parts[1].failures = 1;
        r[1].parts[1].examples = vec!["states (buffer 0 as loaded): sample 7".into()];
        r[1].passed = false;
        let m = merge_reports(&r).unwrap();
        assert!(!m.passed && m.text.contains("FAILED") && m.text.contains("sample 7"));
        assert!(
            m.text.contains("  states ") && m.text.contains(": 1 FAILED\n"),
            "{}",
            m.text
        );
        // Failures counted past the kept examples; counts that would wrap around to 0 when
        // summed still fail (saturating at the largest count).
        let mut r = run(2, false);
        for rep in r.iter_mut() {
            rep.parts[3].failures = 1 << 63;
            rep.parts[3].examples = vec!["front: gradient".into(); crate::prove::KEEP_FAILURES];
            rep.passed = false;
        }
        let m = merge_reports(&r).unwrap();
        assert!(!m.passed, "{}", m.text);
        assert!(
            m.text.contains(&format!("{} FAILED", u64::MAX)),
            "{}",
            m.text
        );
        assert!(m.text.ends_with(" s of shard time\n") && m.text.contains("\nFAILED: G8 "));
        // An edited file is named.
        let mut r = run(1, false);
        r[0].files[1].as_generated = false;
        let m = merge_reports(&r).unwrap();
        assert!(
            m.text.contains("edited since generated: recip_rom.hex"),
            "{}",
            m.text
        );
    }

    #[test]
    fn merge_refuses_what_does_not_cover_the_whole_run() {
        // A --direct run of the default design (G = 12) merges from 512 shards or more, as it
        // runs; two shards claiming it are refused.
        let g12 = Config::default();
        assert!(merge_reports(&run_of(&g12, 512, true)).unwrap().passed);
        refused(&run_of(&g12, 2, true), "at least 512 shards");
        let base = run(2, false);
        let edit = |f: &dyn Fn(&mut Vec<Report>)| {
            let mut r = base.clone();
            f(&mut r);
            r
        };
        refused(&base[..1], "shard 2/2 is missing");
        refused(&[base[0].clone(), base[0].clone()], "given twice");
        refused(
            &edit(&|r| r[0].parts.retain(|p| p.name == "structure")),
            "front, states, zero missing",
        );
        refused(&edit(&|r| r[1].parts.clear()), "has the parts []");
        refused(
            &edit(&|r| {
                let p = r[0].parts[0].clone();
                r[0].parts.push(p)
            }),
            "not those of a factored run",
        );
        refused(
            &edit(&|r| {
                for rep in r.iter_mut() {
                    for p in rep.parts.iter_mut().filter(|p| p.name == "front") {
                        p.total = 10;
                        p.first = p.first.min(10);
                        p.end = p.end.min(10);
                        p.ran = p.end - p.first;
                    }
                }
            }),
            "claims 10 inputs; the configuration gives 16777216",
        );
        // A part that checked one input less and says so (a failure) is a verdict of a shard
        // that did not finish its range: refused as a whole.
        refused(
            &edit(&|r| {
                let p = &mut r[0].parts[1];
                p.ran -= 1;
                p.failures = 1;
                p.examples = vec!["states: checked 3743999 inputs".into()];
                r[0].passed = false;
            }),
            "part states of shard 1/2 checked 3743999 inputs of its 3744000",
        );
        refused(
            &edit(&|r| {
                let p = &mut r[1].parts[3];
                p.first += 1;
                p.ran -= 1;
            }),
            "do not tile",
        );
        refused(
            &edit(&|r| {
                let p = &mut r[1].parts[3];
                p.end -= 1;
                p.ran -= 1;
            }),
            "the shards stop at 16777215 of 16777216",
        );
        refused(
            &edit(&|r| r[1].files[2].sha256 = "f".repeat(64)),
            "0.json (they differ in rmap_top.v)",
        );
        refused(
            &edit(&|r| r[1].files.pop().map(|_| ()).unwrap()),
            "proved other files",
        );
        refused(
            &edit(&|r| {
                r[1].config.map_bits += 1;
                r[1].config_summary = r[1].config.summary();
            }),
            "another configuration or mode",
        );
        refused(
            &edit(&|r| r[1].mode = "direct".into()),
            "another configuration or mode",
        );
        refused(
            &edit(&|r| {
                r[0].mode = "sampled".into();
                r[1].mode = "sampled".into();
            }),
            "neither factored nor direct",
        );
        refused(
            &edit(&|r| {
                for rep in r.iter_mut() {
                    rep.config.grad_bits = 14;
                    rep.config_summary = rep.config.summary();
                }
            }),
            "grad_bits = 14 is above 12",
        );
        refused(&edit(&|r| r[1].shard.count = 3), "is shard 2/3, not of 2");
        refused(
            &edit(&|r| {
                r[0].shard.count = 1 << 62;
                r[1].shard.count = 1 << 62;
            }),
            "is not a shard",
        );
        refused(&edit(&|r| r[0].shard.index = 3), "is not a shard");
        refused(
            &edit(&|r| r[0].format = "rmapgen-prove-1".into()),
            "its format is",
        );
    }

    /// Every field that can contradict another, edited as one would edit the JSON: the
    /// merge names the file and the field and gives no verdict.
    #[test]
    fn a_report_that_contradicts_itself_is_refused_naming_its_file_and_field() {
        let base = run(2, false);
        let edit = |f: &dyn Fn(&mut Vec<Report>)| {
            let mut r = base.clone();
            f(&mut r);
            r
        };
        let example = || vec!["states (buffer 0 as loaded): sample 7".to_string()];
        for (r, want) in [
            (
                edit(&|r| r[1].passed = false),
                "1.json: passed is false, but no part failed; rmapgen prove writes no such report (was it edited?)",
            ),
            (
                edit(&|r| {
                    r[0].parts[1].failures = 1;
                    r[0].parts[1].examples = example();
                }),
                "0.json: passed is true, but a part failed",
            ),
            (
                edit(&|r| r[1].parts[1].examples = example()),
                "1.json: parts[1] (states): examples lists 1 failures, but failures is 0",
            ),
            (
                edit(&|r| {
                    r[1].parts[1].failures = 2;
                    r[1].parts[1].examples = example();
                    r[1].passed = false;
                }),
                "parts[1] (states): examples lists 1 failures, but failures is 2 (the first 20 are kept)",
            ),
            (
                edit(&|r| {
                    r[1].parts[1].failures = 1;
                    r[1].passed = false;
                }),
                "parts[1] (states): examples lists 0 failures, but failures is 1",
            ),
            (
                edit(&|r| {
                    r[1].parts[1].failures = 30;
                    r[1].parts[1].examples = vec!["x".into(); 21];
                    r[1].passed = false;
                }),
                "examples lists 21 failures, but failures is 30",
            ),
            (
                edit(&|r| r[1].seconds = -5.0),
                "1.json: seconds is -5, not a time (finite, at least 0)",
            ),
            (
                edit(&|r| r[0].parts[2].seconds = -0.5),
                "0.json: parts[2] (zero): seconds is -0.5, not a time",
            ),
            (
                edit(&|r| r[0].parts[3].cpu_seconds = -1.0),
                "0.json: parts[3] (front): cpu_seconds is -1, not a time",
            ),
            (
                edit(&|r| {
                    let p = &mut r[1].parts[3];
                    p.end = p.total + 1;
                    p.ran = p.end - p.first;
                }),
                "parts[3] (front): the range [8388608..16777217) is not within its total 16777216",
            ),
            (
                edit(&|r| {
                    let p = &mut r[1].parts[3];
                    (p.first, p.end, p.ran) = (p.end, p.first, 0);
                }),
                "parts[3] (front): the range [16777216..8388608) is not within its total",
            ),
            (
                edit(&|r| r[0].parts[1].ran += 1),
                "0.json: parts[1] (states): ran is 3744001, not the 3744000 inputs of its range [0..3744000), but failures is 0",
            ),
            (
                edit(&|r| r[0].config_summary = "G12 R8".into()),
                "0.json: config_summary is \"G12 R8\", but its config is \"G8 ",
            ),
            (
                edit(&|r| r[0].parts[3].engine = "magic".into()),
                "0.json: parts[3] (front): engine \"magic\" is not what evaluates it",
            ),
            (
                edit(&|r| r[0].parts[3].engine = String::new()),
                "parts[3] (front): engine \"\" is not",
            ),
            (
                edit(&|r| r[1].parts[1].engine = "gates".into()),
                "parts[1] (states): engine \"gates\" is not",
            ),
            (
                edit(&|r| r[0].files[1].sha256 = "A".repeat(64)),
                "0.json: files[1] (recip_rom.hex): sha256 \"AAAA",
            ),
            (
                edit(&|r| r[0].files[1].sha256 = "a".repeat(63)),
                "files[1] (recip_rom.hex): sha256",
            ),
            (
                edit(&|r| r[0].files[1].sha256 = "g".repeat(64)),
                "files[1] (recip_rom.hex): sha256",
            ),
            (
                edit(&|r| r[0].files[2].name = "manifest.json".into()),
                "0.json: files[2] (manifest.json) is listed twice or out of order",
            ),
            (
                edit(&|r| r[0].files.swap(1, 2)),
                "files[2] (recip_rom.hex) is listed twice or out of order",
            ),
        ] {
            refused(&r, want);
        }
        // As many examples as failures up to the kept 20, or exactly 20 beyond: a verdict.
        for (failures, examples) in [(1, 1), (20, 20), (21, 20), (1 << 40, 20)] {
            let r = edit(&|r| {
                r[1].parts[1].failures = failures;
                r[1].parts[1].examples = vec!["x".into(); examples];
                r[1].passed = false;
            });
            let m = merge_reports(&r).unwrap();
            assert!(!m.passed, "{}", m.text);
            assert!(m.text.contains(&format!("{failures} FAILED")), "{}", m.text);
        }
        // Times JSON cannot carry (it has no NaN or infinity), as the check sees them; zero
        // times are times.
        for bad in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -f64::MIN_POSITIVE,
        ] {
            let mut r = base[0].clone();
            r.seconds = bad;
            let e = contradiction(&r).expect("refused");
            assert!(
                e.starts_with(&format!("seconds is {bad}, not a time")),
                "{e}"
            );
            let mut r = base[0].clone();
            r.parts[0].cpu_seconds = bad;
            let e = contradiction(&r).expect("refused");
            assert!(e.starts_with("parts[0] (structure): cpu_seconds"), "{e}");
        }
        let mut r = base[0].clone();
        r.seconds = 0.0;
        r.parts[0].seconds = 0.0;
        assert_eq!(contradiction(&r), None);
        for r in &base {
            assert_eq!(contradiction(r), None);
        }
    }

    /// The bound is read, never a file's metadata: a device, a FIFO or a file that grows
    /// is read up to one byte past it.
    #[test]
    fn a_report_is_read_up_to_its_bound_whatever_its_metadata_says() {
        let e = format!("{:#}", read(Path::new("/dev/zero")).unwrap_err());
        assert_eq!(
            e,
            format!(
                "/dev/zero is larger than {MAX_REPORT_BYTES} bytes, not a report of rmapgen prove"
            )
        );
        let dir = tempfile::tempdir().unwrap();
        // A report padded to the bound exactly is read; one byte more is not.
        let mut text = serde_json::to_string(&run(1, false)[0]).unwrap();
        let p = dir.path().join("r.json");
        text.push_str(&" ".repeat(MAX_REPORT_BYTES as usize - text.len()));
        std::fs::write(&p, &text).unwrap();
        assert!(read(&p).is_ok());
        text.push(' ');
        std::fs::write(&p, &text).unwrap();
        let e = format!("{:#}", read(&p).unwrap_err());
        assert!(
            e.ends_with("r.json is larger than 4194304 bytes, not a report of rmapgen prove"),
            "{e}"
        );
        let e = format!("{:#}", read(&dir.path().join("none.json")).unwrap_err());
        assert!(
            e.starts_with("cannot read ") && e.contains("none.json"),
            "{e}"
        );
    }

    #[test]
    fn a_part_that_checked_other_than_its_range_fails() {
        let ok = Part::new(
            "states",
            10..20,
            40,
            Failures {
                checked: 10,
                ..Failures::default()
            },
        );
        assert_eq!((ok.ran, ok.failures), (10, 0));
        for checked in [0, 9, 11] {
            let p = Part::new(
                "states",
                10..20,
                40,
                Failures {
                    checked,
                    ..Failures::default()
                },
            );
            assert_eq!((p.ran, p.failures), (checked, 1));
            assert!(p.examples[0].contains(&format!("checked {checked} inputs, not the 10")));
        }
    }
}
