//! A campaign: every mutant of a draw judged, `jobs` at a time, each outcome recorded in the
//! journal as soon as it is known and reused from it when an earlier run of the same binary
//! judged it ([`super::journal`]). The null mutant goes first, alone: if the flow itself
//! changes the design, nothing else means much.

use super::journal::Journal;
use super::{judge, Mutant, Outcome, Plan};
use crate::design_dir::DesignDir;
use anyhow::Result;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// What a campaign found.
pub enum Judged {
    /// Every mutant's outcome, by id.
    All(Vec<Outcome>),
    /// The null mutant (the design through Yosys, no mutation) failed these methods: the
    /// flow is broken, and nothing else was judged.
    BrokenFlow(Vec<String>),
}

/// Judges `list` (the null mutant first) on `design` under `plan`, in `work`, `jobs` at a
/// time, reusing the journal's outcomes; `said` is told each outcome as it is known, with
/// `" (journal)"` for a reused one.
pub fn run(
    design: &DesignDir,
    list: &[Mutant],
    plan: &Plan,
    work: &Path,
    journal: &Journal,
    jobs: usize,
    said: &(dyn Fn(&Outcome, &str) -> Result<()> + Sync),
) -> Result<Judged> {
    let one = |m: &Mutant| -> Result<Outcome> {
        if let Some(o) = journal.earlier.get(&m.id) {
            said(o, " (journal)")?;
            return Ok(o.clone());
        }
        let o = judge(design, m, plan, work)?;
        journal.record(&o)?;
        said(&o, "")?;
        Ok(o)
    };
    let Some(first) = list.first() else {
        return Ok(Judged::All(Vec::new()));
    };
    let null = one(first)?;
    let broken: Vec<String> = null
        .verdicts
        .iter()
        .filter(|(_, v)| v.kills())
        .map(|(m, v)| format!("{} {v:?}", m.name()))
        .collect();
    if !broken.is_empty() {
        return Ok(Judged::BrokenFlow(broken));
    }
    // The journal's outcomes are printed first, in order, then the rest as they come.
    for m in list.iter().skip(1) {
        if journal.earlier.contains_key(&m.id) {
            one(m)?;
        }
    }
    let next = AtomicUsize::new(1);
    let results: Mutex<Vec<Result<Outcome>>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1) {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(m) = list.get(k) else { break };
                // A line that cannot be printed, or a journal that cannot be written, is the
                // mutant's error.
                let r = match journal.earlier.get(&m.id) {
                    Some(o) => Ok(o.clone()),
                    None => one(m),
                };
                results.lock().unwrap_or_else(|e| e.into_inner()).push(r);
            });
        }
    });
    let mut outcomes = vec![null];
    for r in results.into_inner().unwrap_or_else(|e| e.into_inner()) {
        outcomes.push(r?);
    }
    outcomes.sort_by_key(|o| o.mutant.id);
    Ok(Judged::All(outcomes))
}
