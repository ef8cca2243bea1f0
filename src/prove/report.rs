//! The report of one shard of `rmapgen prove` (JSON, `--report FILE`) and the merge of a
//! run's shard reports into one verdict (`rmapgen prove --merge`).
//!
//! A report names the design by a digest of its manifest, Verilog and memory files, so the
//! merge refuses shards of different designs; and each part's range, so it refuses a run
//! with a shard missing, repeated or from another split.

use super::{Failures, Options, Shard};
use crate::design_dir::DesignDir;
use anyhow::{bail, ensure, Context, Result};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The report format's name, which the merge checks.
pub const FORMAT: &str = "rmapgen-prove-1";

/// One part of the proof in one shard: inputs `first..end` of `total`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Part {
    pub name: String,
    pub first: u64,
    pub end: u64,
    pub total: u64,
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
    pub fn new(name: &str, range: std::ops::Range<u64>, total: u64, f: Failures) -> Part {
        Part {
            name: name.into(),
            first: range.start,
            end: range.end,
            total,
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

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    pub format: String,
    /// The design directory as given.
    pub design: String,
    pub config: String,
    /// SHA-256 of the design's manifest, Verilog and memory files.
    pub digest: String,
    pub mode: String,
    pub shard: Shard,
    pub parts: Vec<Part>,
    pub seconds: f64,
    pub passed: bool,
}

/// The files a design's behaviour depends on: its manifest, its Verilog (the manifest's
/// modules) and every .hex file beside them (the memories' init files).
fn digest(d: &DesignDir) -> Result<String> {
    let mut names: Vec<String> = d.file_names().to_vec();
    names.push(crate::rtl::manifest::FILE.to_string());
    for e in std::fs::read_dir(d.path())? {
        let name = e?.file_name().to_string_lossy().into_owned();
        if name.ends_with(".hex") {
            names.push(name);
        }
    }
    names.sort();
    names.dedup();
    let mut h = Sha256::new();
    for n in &names {
        let bytes = std::fs::read(d.path().join(n))
            .with_context(|| format!("cannot read {}", d.path().join(n).display()))?;
        h.update(n.as_bytes());
        h.update((bytes.len() as u64).to_le_bytes());
        h.update(&bytes);
    }
    Ok(format!("{:x}", h.finalize()))
}

impl Report {
    pub fn new(d: &DesignDir, opts: &Options, parts: Vec<Part>, seconds: f64) -> Result<Report> {
        let passed = parts.iter().all(|p| p.failures == 0);
        Ok(Report {
            format: FORMAT.into(),
            design: d.path().display().to_string(),
            config: d.config.summary(),
            digest: digest(d)?,
            mode: if opts.direct { "direct" } else { "factored" }.into(),
            shard: opts.shard,
            parts,
            seconds,
            passed,
        })
    }

    /// The gradients this report's parts cover between them (front or direct).
    pub fn gradients(&self) -> u64 {
        self.parts
            .iter()
            .filter(|p| p.name == "front" || p.name == "direct")
            .map(|p| p.end - p.first)
            .sum()
    }

    /// Lines for the terminal: one per part, then the failures kept.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "prove {} ({}, shard {}/{}, {}):\n",
            self.design, self.config, self.shard.index, self.shard.count, self.mode
        );
        for p in &self.parts {
            let name = if p.engine.is_empty() {
                p.name.clone()
            } else {
                format!("{} ({})", p.name, p.engine)
            };
            s += &format!(
                "  {:<17} {:>14} of {:>14} inputs [{}..{}) {:>7.1} s ({:.1} s CPU): {}\n",
                name,
                p.end - p.first,
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
        s += &format!(
            "{} in {:.1} s\n",
            if self.passed { "PASSED" } else { "FAILED" },
            self.seconds
        );
        s
    }
}

/// Whether `bytes` is a report this command wrote (so `--report` may replace it).
pub fn is_report(bytes: &[u8]) -> bool {
    serde_json::from_slice::<serde_json::Value>(bytes)
        .is_ok_and(|v| v["format"].as_str() == Some(FORMAT))
}

/// The verdict of a whole run.
pub struct Merged {
    pub passed: bool,
    pub text: String,
}

/// Combines the reports of every shard of one run. Bad input (unreadable, another design,
/// a shard missing or repeated, ranges that do not tile) is an error; a failed part is a
/// verdict.
pub fn merge(files: &[PathBuf]) -> Result<Merged> {
    ensure!(!files.is_empty(), "give the shard reports to merge");
    let reports: Vec<Report> = files.iter().map(|f| read(f)).collect::<Result<_>>()?;
    let first = &reports[0];
    let n = first.shard.count;
    for (r, f) in reports.iter().zip(files) {
        if r.digest != first.digest || r.mode != first.mode {
            bail!(
                "{} is a report of another design or mode than {} ({} {}, not {} {})",
                f.display(),
                files[0].display(),
                r.config,
                r.mode,
                first.config,
                first.mode
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
    // Every part's ranges, over the shards, must tile 0..total.
    let mut names: Vec<&str> = first.parts.iter().map(|p| p.name.as_str()).collect();
    names.sort();
    let mut text = format!(
        "prove {} ({}, {} shards, {}):\n",
        first.design, first.config, n, first.mode
    );
    let mut passed = true;
    for name in names {
        let mut ranges: Vec<&Part> = reports
            .iter()
            .map(|r| {
                r.parts
                    .iter()
                    .find(|p| p.name == name)
                    .with_context(|| format!("shard {}/{n} has no part {name}", r.shard.index))
            })
            .collect::<Result<_>>()?;
        ranges.sort_by_key(|p| (p.first, p.end));
        let total = ranges[0].total;
        let mut at = 0;
        for p in &ranges {
            ensure!(
                p.total == total && p.first == at,
                "part {name}: the shards' ranges do not tile 0..{total} (a gap or overlap at {at})"
            );
            at = p.end;
        }
        ensure!(
            at == total,
            "part {name}: the shards stop at {at} of {total}"
        );
        let failures: u64 = ranges.iter().map(|p| p.failures).sum();
        passed &= failures == 0;
        // The engines the shards used for the part (shards may differ: each proves its range).
        let mut engines: Vec<&str> = ranges
            .iter()
            .map(|p| p.engine.as_str())
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
        for p in ranges.iter().filter(|p| p.failures > 0) {
            for e in &p.examples {
                text += &format!("    {e}\n");
            }
        }
    }
    let seconds: f64 = reports.iter().map(|r| r.seconds).sum();
    text += &format!(
        "{}: {} gradients, {:.0} s of shard time\n",
        if passed { "PROVEN" } else { "FAILED" },
        reports.iter().map(Report::gradients).sum::<u64>(),
        seconds
    );
    Ok(Merged { passed, text })
}

fn read(f: &Path) -> Result<Report> {
    let text =
        std::fs::read_to_string(f).with_context(|| format!("cannot read {}", f.display()))?;
    let r: Report = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a report of rmapgen prove", f.display()))?;
    ensure!(
        r.format == FORMAT,
        "{} is a report of format {:?}, not {FORMAT}",
        f.display(),
        r.format
    );
    ensure!(
        r.shard.count >= 1 && (1..=r.shard.count).contains(&r.shard.index),
        "{}: shard {}/{} is not a shard",
        f.display(),
        r.shard.index,
        r.shard.count
    );
    Ok(r)
}
