//! `rmapgen prove --slurm`: the proof as jobs of a Slurm cluster. Three submissions, each a
//! script written into the run's job directory (`BUILD/<design>-slurm`, replaced whole):
//!
//! 1. **build** (one job): `rmapgen prove DIR --build-only` builds the Verilated top and the
//!    front's gates once, into the job directory ([`super::build_only`]);
//! 2. **shards** (an array job of N tasks, after the build succeeded:
//!    `--dependency=afterok`): task K runs `rmapgen prove DIR --shard K/N --reuse BUILD
//!    --report reports/shard-K-of-N.json`, loading the build instead of compiling its own;
//! 3. **merge** (one job, after every task ended, however: `afterany`): `rmapgen prove
//!    --merge` of the N reports ([`super::report::merge`]).
//!
//! Each script writes its command's exit status into `status/` when the command ends; a task
//! that Slurm cancelled or killed (time limit, node failure, `scancel`) writes none. rmapgen
//! waits for the merge job, then gives the verdict: the merge's text, and a line for every
//! job that did not end well, naming the shard and its log. The run passes only when the
//! build, every shard and the merge exited 0. An interrupted rmapgen cancels every job it
//! submitted (`scancel`, also by its guardian when it is killed outright).
//!
//! The design directory, the job directory and rmapgen itself must be at the same paths on
//! every node (a shared file system), as on any cluster that runs one build for many tasks.

use super::{FrontEngine, MAX_SHARDS};
use crate::design_dir::DesignDir;
use crate::output::signals::{self, Undo};
use crate::output::InPlace;
use crate::toolchain::{self, shell_word, slurm};
use anyhow::{ensure, Context, Result};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How the run is spread.
#[derive(Clone, Debug)]
pub struct Options {
    pub shards: u64,
    /// `--partition` of every job (the cluster's default when None).
    pub partition: Option<String>,
    /// More sbatch options for every job (`--time=30`, `--cpus-per-task=8`, `--account=x`).
    pub sbatch_args: Vec<String>,
    pub direct: bool,
    pub front_engine: FrontEngine,
}

/// Slurm's own limit on an array's task index (its default `MaxArraySize` is 1001): more
/// shards than this are refused before anything is submitted.
pub const MAX_ARRAY: u64 = 1000;

/// The job directory: the scripts, the logs, the exit statuses, the reports and the builds.
pub struct Layout {
    /// Absolute: what the scripts name, on every node.
    pub root: PathBuf,
    /// As the user gave it: what messages name.
    pub shown: PathBuf,
}

impl Layout {
    /// A path below [`Layout::root`] as messages name it: below [`Layout::shown`].
    pub fn as_given(&self, p: &Path) -> PathBuf {
        p.strip_prefix(&self.root)
            .map_or_else(|_| p.to_path_buf(), |rel| self.shown.join(rel))
    }

    pub fn script(&self, job: &str) -> PathBuf {
        self.root.join(format!("{job}.sh"))
    }
    /// The log of `job` (`shard-K` for a task).
    pub fn log(&self, job: &str) -> PathBuf {
        self.root.join("logs").join(format!("{job}.log"))
    }
    /// The exit status file of `job`.
    pub fn status(&self, job: &str) -> PathBuf {
        self.root.join("status").join(format!("{job}.exit"))
    }
    pub fn report(&self, k: u64, n: u64) -> PathBuf {
        self.root
            .join("reports")
            .join(format!("shard-{k}-of-{n}.json"))
    }
    /// Where the build job builds (`--build-only --build ROOT` makes `ROOT/<design>-build`).
    pub fn build(&self, d: &DesignDir) -> PathBuf {
        self.root.join(format!("{}-build", d.name()))
    }
    /// The shards' own build directories (each `<design>-KofN`: the structure part's logs).
    pub fn shard_builds(&self) -> PathBuf {
        self.root.join("shards")
    }
}

/// A shell script that runs `command` (its words, already shell words), writes its exit
/// status to `status` and exits with it.
fn script(what: &str, design: &Path, command: &str, status: &str) -> String {
    format!(
        "#!/bin/sh\n\
         # Written by `rmapgen prove --slurm` for {}: {what}.\n\
         # Submitted by it with the dependencies between the jobs (docs/VERIFICATION.md,\n\
         # \"On a cluster\"). The exit status goes to a file: a job Slurm cancels writes none.\n\
         {command}\n\
         status=$?\n\
         echo \"$status\" > {status}\n\
         exit \"$status\"\n",
        design.display()
    )
}

/// `rmapgen prove` with `args`, as shell words.
fn rmapgen(exe: &Path, args: &[String]) -> String {
    std::iter::once(shell_word(&exe.to_string_lossy()))
        .chain(std::iter::once("prove".to_string()))
        .chain(args.iter().map(|a| shell_word(a)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A path with the array task's index spliced in where `{K}` is: `'/a/shard-'"$K"'.json'`.
fn with_task(path: &Path) -> String {
    let text = path.to_string_lossy();
    let (before, after) = text.split_once("{K}").expect("the path has {K}");
    format!(
        "{}\"$SLURM_ARRAY_TASK_ID\"{}",
        shell_word(before),
        shell_word(after)
    )
}

/// The three scripts of a run of design `d`, written into `layout`.
pub fn write_scripts(d: &DesignDir, layout: &Layout, exe: &Path, o: &Options) -> Result<()> {
    for sub in ["logs", "status", "reports"] {
        crate::disk::create_dir_all(&layout.root.join(sub))?;
    }
    let design = d.path().to_string_lossy().into_owned();
    let mut mode = Vec::new();
    if o.direct {
        mode.push("--direct".to_string());
    } else {
        mode.extend([
            "--front-engine".to_string(),
            o.front_engine.name().to_string(),
        ]);
    }
    let path = |p: PathBuf| p.to_string_lossy().into_owned();
    // build
    let mut args = vec![design.clone(), "--build-only".into()];
    args.extend(mode.iter().cloned());
    args.extend(["--build".into(), path(layout.root.clone())]);
    let status = shell_word(&path(layout.status("build")));
    let text = script(
        "the build every shard loads",
        d.path(),
        &rmapgen(exe, &args),
        &status,
    );
    crate::disk::write(&layout.script("build"), text)?;
    // shards: the task index spliced into --shard and the report's and status's names.
    let n = o.shards;
    let mut args = vec![design.clone()];
    args.extend(mode.iter().cloned());
    args.extend([
        "--build".into(),
        path(layout.shard_builds()),
        "--reuse".into(),
        path(layout.build(d)),
    ]);
    let report = layout
        .root
        .join("reports")
        .join(format!("shard-{{K}}-of-{n}.json"));
    let command = format!(
        "{} --shard \"$SLURM_ARRAY_TASK_ID\"/{n} --report {}",
        rmapgen(exe, &args),
        with_task(&report)
    );
    let status = with_task(&layout.root.join("status").join("shard-{K}.exit"));
    let text = script(
        &format!("shard K of {n}, K the array task's index"),
        d.path(),
        &command,
        &status,
    );
    crate::disk::write(&layout.script("shards"), text)?;
    // merge
    let mut args = vec!["--merge".to_string()];
    args.extend((1..=n).map(|k| path(layout.report(k, n))));
    let status = shell_word(&path(layout.status("merge")));
    let text = script(
        &format!("the merge of the {n} shards' reports"),
        d.path(),
        &rmapgen(exe, &args),
        &status,
    );
    crate::disk::write(&layout.script("merge"), text)?;
    Ok(())
}

/// The jobs of a run, as Slurm numbered them.
#[derive(Clone, Debug)]
pub struct Jobs {
    pub build: String,
    pub shards: String,
    pub merge: String,
}

impl Jobs {
    fn all(&self) -> Vec<String> {
        vec![self.build.clone(), self.shards.clone(), self.merge.clone()]
    }
}

/// The verdict of a run.
pub struct Outcome {
    pub passed: bool,
    pub text: String,
}

/// Checks the options before anything is written or submitted.
pub fn check(o: &Options) -> Result<()> {
    ensure!(
        (1..=MAX_ARRAY.min(MAX_SHARDS)).contains(&o.shards),
        "--shards {}: a Slurm run has 1 to {MAX_ARRAY} shards (Slurm's default MaxArraySize)",
        o.shards
    );
    Ok(())
}

/// Submits the three jobs of the scripts in `layout` (each with the partition and the user's
/// sbatch options), registering their cancellation for an interrupt as each is submitted.
pub fn submit(layout: &Layout, o: &Options) -> Result<(Jobs, signals::Token)> {
    let common = |job: &str| -> Vec<String> {
        let mut a = vec![
            format!("--job-name=rmapgen-prove-{job}"),
            format!("--output={}", layout.log(job).display()),
        ];
        if let Some(p) = &o.partition {
            a.push(format!("--partition={p}"));
        }
        a.extend(o.sbatch_args.iter().cloned());
        a
    };
    let build = slurm::submit(&common("build"), &layout.script("build"), "the build job")?;
    let token = signals::register(Undo::Run(slurm::cancel_words(std::slice::from_ref(&build))));
    let cancel_all = |ids: &[String]| {
        signals::hold().replace(&token, Undo::Run(slurm::cancel_words(ids)));
    };
    let mut args = common("shards");
    // %a: the task index in the log's name.
    args[1] = format!("--output={}", layout.log("shard-%a").display());
    args.extend([
        format!("--array=1-{}", o.shards),
        format!("--dependency=afterok:{build}"),
        "--kill-on-invalid-dep=yes".into(),
    ]);
    let shards = match slurm::submit(&args, &layout.script("shards"), "the shards' array job") {
        Ok(id) => id,
        Err(e) => {
            // Cancelled now, and no longer for an interrupt or the guardian to cancel.
            cancel(std::slice::from_ref(&build));
            token.release();
            return Err(e);
        }
    };
    cancel_all(&[build.clone(), shards.clone()]);
    let mut args = common("merge");
    args.extend([
        format!("--dependency=afterany:{shards}"),
        "--kill-on-invalid-dep=yes".into(),
    ]);
    let merge = match slurm::submit(&args, &layout.script("merge"), "the merge job") {
        Ok(id) => id,
        Err(e) => {
            cancel(&[build, shards]);
            token.release();
            return Err(e);
        }
    };
    let jobs = Jobs {
        build,
        shards,
        merge,
    };
    cancel_all(&jobs.all());
    Ok((jobs, token))
}

/// Cancels the jobs `ids` now (a submission that failed half-way).
fn cancel(ids: &[String]) {
    Undo::Run(slurm::cancel_words(ids)).run_now();
}

/// What a job's status file says: its command's exit code, or None when the job wrote none
/// (not yet ended, or cancelled or killed by Slurm).
fn exit_of(path: &Path) -> Option<i32> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// The shards whose tasks have ended and how many of them failed, from the status files.
fn shards_ended(layout: &Layout) -> (u64, u64) {
    let Ok(dir) = std::fs::read_dir(layout.root.join("status")) else {
        return (0, 0);
    };
    let mut ended = 0;
    let mut failed = 0;
    for e in dir.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with("shard-") && name.ends_with(".exit") {
            ended += 1;
            if exit_of(&e.path()) != Some(0) {
                failed += 1;
            }
        }
    }
    (ended, failed)
}

/// How often the status files are looked at, and how often Slurm is asked whether the jobs
/// are still there (a merge job cancelled before it ran writes no status).
const LOOK: Duration = Duration::from_millis(500);
const ASK: Duration = Duration::from_secs(5);

/// Waits until the merge job has ended (its status file) or none of the jobs is left in
/// Slurm's queue; `progress` gets a line whenever the count of ended shards changes.
pub fn wait(layout: &Layout, jobs: &Jobs, n: u64, progress: &dyn Fn(&str)) -> Result<()> {
    let mut last = None;
    let mut asked = Instant::now();
    loop {
        if layout.status("merge").exists() {
            return Ok(());
        }
        let now = shards_ended(layout);
        let build = exit_of(&layout.status("build"));
        if last != Some((build, now)) {
            last = Some((build, now));
            let b = match build {
                None => "build running or queued".to_string(),
                Some(0) => "built".to_string(),
                Some(c) => format!("build failed (exit {c})"),
            };
            progress(&format!(
                "slurm: {b}; {} of {n} shards ended ({} failed)",
                now.0, now.1
            ));
        }
        if asked.elapsed() >= ASK {
            asked = Instant::now();
            if slurm::live(&jobs.all())? == 0 {
                // The merge may have written its status just before it left the queue.
                return Ok(());
            }
        }
        std::thread::sleep(LOOK);
    }
}

/// The last non-empty line of a job's log, for a message.
fn last_line(log: &Path) -> String {
    std::fs::read_to_string(log)
        .ok()
        .and_then(|t| {
            t.lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .map(String::from)
        })
        .unwrap_or_else(|| "no output".into())
}

/// The most shards named one by one in a verdict (all are counted).
const NAMED: usize = 20;

/// The verdict once the jobs have ended: the merge's text, and a line for each job that did
/// not end with exit 0 (a shard that failed the proof, failed to run, or was cancelled).
pub fn verdict(layout: &Layout, jobs: &Jobs, n: u64) -> Outcome {
    // Paths as the user gave them.
    let log = |job: &str| layout.as_given(&layout.log(job)).display().to_string();
    let mut problems = Vec::new();
    match exit_of(&layout.status("build")) {
        Some(0) => {}
        Some(c) => problems.push(format!(
            "the build job {} failed (exit {c}): {} ({})",
            jobs.build,
            last_line(&layout.log("build")),
            log("build")
        )),
        None => problems.push(format!(
            "the build job {} was cancelled or killed before it ended (no exit status; {})",
            jobs.build,
            log("build")
        )),
    }
    let mut bad = 0usize;
    for k in 1..=n {
        let job = format!("shard-{k}");
        let line = match exit_of(&layout.status(&job)) {
            Some(0) => continue,
            Some(1) => format!(
                "shard {k}/{n} (task {}_{k}) found inputs where the design differs from its model ({})",
                jobs.shards,
                layout.as_given(&layout.report(k, n)).display()
            ),
            Some(c) => format!(
                "shard {k}/{n} (task {}_{k}) failed (exit {c}): {} ({})",
                jobs.shards,
                last_line(&layout.log(&job)),
                log(&job)
            ),
            None => format!(
                "shard {k}/{n} (task {}_{k}) was cancelled or killed before it ended (no exit status; {})",
                jobs.shards,
                log(&job)
            ),
        };
        bad += 1;
        if bad <= NAMED {
            problems.push(line);
        }
    }
    if bad > NAMED {
        problems.push(format!("... and {} more shards", bad - NAMED));
    }
    let merge_log = layout.log("merge");
    let merged = std::fs::read_to_string(&merge_log).unwrap_or_default();
    let merge = exit_of(&layout.status("merge"));
    match merge {
        Some(0) | Some(1) => {}
        Some(c) => problems.push(format!(
            "the merge job {} failed (exit {c}): {} ({})",
            jobs.merge,
            last_line(&merge_log),
            log("merge")
        )),
        None => problems.push(format!(
            "the merge job {} was cancelled or killed before it ended (no exit status; {})",
            jobs.merge,
            log("merge")
        )),
    }
    let passed = problems.is_empty() && merge == Some(0);
    let mut text = String::new();
    if matches!(merge, Some(0) | Some(1)) {
        text.push_str(merged.trim_end());
        text.push('\n');
    }
    if passed {
        text.push_str(&format!(
            "slurm: PASSED: build, {n} shards and merge (jobs {}, {}, {}) all exited 0",
            jobs.build, jobs.shards, jobs.merge
        ));
    } else {
        text.push_str("slurm: FAILED:");
        for p in &problems {
            text.push_str("\n  ");
            text.push_str(p);
        }
        if problems.is_empty() {
            text.push_str(" the merge found a failure");
        }
    }
    Outcome { passed, text }
}

/// The whole run in `job_dir` (put in place, provisional, by [`crate::output::StagedDir`]),
/// which messages name as `shown`: the scripts written, the jobs submitted, waited for, and
/// the verdict. `exe` is the rmapgen every job runs.
///
/// Until the jobs are submitted and announced, a failure (sbatch refusing a job: no
/// controller, a bad partition) or an interrupt leaves nothing behind: the jobs already
/// submitted are cancelled, the job directory is taken back with the parents made for it,
/// and a previous run's directory is put back. Once the jobs have run, their directory is
/// kept, recorded as rmapgen's (the jobs are rmapgen), so that the next run replaces it.
#[allow(clippy::too_many_arguments)]
pub fn run(
    d: &DesignDir,
    job_dir: InPlace,
    shown: &Path,
    exe: &Path,
    o: &Options,
    announce: &dyn Fn(&str) -> Result<()>,
    progress: &dyn Fn(&str),
) -> Result<Outcome> {
    check(o)?;
    let layout = Layout {
        root: crate::output::absolute(job_dir.path()),
        shown: shown.to_path_buf(),
    };
    write_scripts(d, &layout, exe, o)?;
    // An interrupt cancels the jobs (registered after the job directory, so undone first),
    // then takes the job directory back.
    let (jobs, token) = submit(&layout, o)?;
    let announced = announce(&format!(
        "slurm: submitted build job {}, shards job {} (array 1-{}), merge job {}; scripts and logs in {}",
        jobs.build,
        jobs.shards,
        o.shards,
        jobs.merge,
        shown.display()
    ));
    if let Err(e) = announced {
        // Nobody to tell the verdict to (a closed standard output): as on an interrupt.
        cancel(&jobs.all());
        token.release();
        return Err(e);
    }
    let waited = wait(&layout, &jobs, o.shards, progress);
    if waited.is_err() {
        // Waiting failed (squeue broke): the jobs are not left behind.
        cancel(&jobs.all());
    }
    token.release();
    job_dir.keep()?;
    waited.context("waiting for the Slurm jobs")?;
    Ok(verdict(&layout, &jobs, o.shards))
}

/// The programs a run needs, checked before anything is written.
pub fn check_tools() -> Result<()> {
    for p in [slurm::sbatch(), slurm::squeue(), slurm::scancel()] {
        ensure!(
            toolchain::installed(&p),
            "{p} not found: --slurm submits to a Slurm cluster (sbatch, squeue and scancel on PATH, or SBATCH, SQUEUE, SCANCEL); make slurm-test starts a one-node cluster"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_task_splices_its_index_into_a_quoted_path() {
        let p = Path::new("/a b/shard-{K}-of-4.json");
        assert_eq!(
            with_task(p),
            "'/a b/shard-'\"$SLURM_ARRAY_TASK_ID\"-of-4.json"
        );
    }

    /// A job directory whose status files and logs say `exits` (None: no status file).
    fn ended(
        build: Option<i32>,
        shards: &[Option<i32>],
        merge: Option<i32>,
    ) -> (tempfile::TempDir, Outcome) {
        let tmp = tempfile::tempdir().unwrap();
        // Messages name the directory as the user gave it.
        let layout = Layout {
            root: tmp.path().to_path_buf(),
            shown: PathBuf::from("build/prove/d-slurm"),
        };
        for sub in ["logs", "status", "reports"] {
            std::fs::create_dir_all(tmp.path().join(sub)).unwrap();
        }
        let put = |job: &str, exit: Option<i32>| {
            std::fs::write(layout.log(job), format!("{job} says\n\nits last line\n")).unwrap();
            if let Some(c) = exit {
                std::fs::write(layout.status(job), format!("{c}\n")).unwrap();
            }
        };
        put("build", build);
        for (k, e) in shards.iter().enumerate() {
            put(&format!("shard-{}", k + 1), *e);
        }
        put("merge", merge);
        // A merge that ended well, or did not end, has the proof's verdict as its last line;
        // a failed one its error.
        if merge.is_none_or(|c| c == 0) {
            std::fs::write(layout.log("merge"), "prove d:\nPROVEN: G8\n").unwrap();
        }
        let jobs = Jobs {
            build: "7".into(),
            shards: "8".into(),
            merge: "9".into(),
        };
        let n = shards.len() as u64;
        (tmp, verdict(&layout, &jobs, n))
    }

    #[test]
    fn the_verdict_passes_only_when_every_job_exited_0_and_names_each_that_did_not() {
        let (_t, v) = ended(Some(0), &[Some(0), Some(0)], Some(0));
        assert!(v.passed, "{}", v.text);
        assert!(
            v.text.starts_with(
                "prove d:\nPROVEN: G8\nslurm: PASSED: build, 2 shards and merge (jobs 7, 8, 9)"
            ),
            "{}",
            v.text
        );
        // A shard that found a difference, one that failed to run, one cancelled.
        let (_t, v) = ended(Some(0), &[Some(1), Some(2), None, Some(0)], Some(1));
        assert!(!v.passed);
        for want in [
            "\n  shard 1/4 (task 8_1) found inputs where the design differs from its model (build/prove/d-slurm/reports/shard-1-of-4.json)",
            "\n  shard 2/4 (task 8_2) failed (exit 2): its last line (build/prove/d-slurm/logs/shard-2.log)",
            "\n  shard 3/4 (task 8_3) was cancelled or killed before it ended (no exit status; build/prove/d-slurm/logs/shard-3.log)",
        ] {
            assert!(v.text.contains(want), "{want:?} in {}", v.text);
        }
        assert!(!v.text.contains("shard 4/4"), "{}", v.text);
        // Every shard passed but the merge was cancelled, or the build failed.
        let (_t, v) = ended(Some(0), &[Some(0)], None);
        assert!(!v.passed);
        assert!(
            v.text.contains(
                "the merge job 9 was cancelled or killed before it ended (no exit status; build/prove/d-slurm/logs/merge.log)"
            ),
            "{}",
            v.text
        );
        assert!(
            !v.text.contains("PROVEN"),
            "a merge that did not end says nothing: {}",
            v.text
        );
        let (_t, v) = ended(Some(2), &[None], Some(2));
        assert!(!v.passed);
        assert!(
            v.text.contains(
                "the build job 7 failed (exit 2): its last line (build/prove/d-slurm/logs/build.log)"
            ),
            "{}",
            v.text
        );
        assert!(
            v.text
                .contains("the merge job 9 failed (exit 2): its last line (build/prove/d-slurm/logs/merge.log)"),
            "{}",
            v.text
        );
        // A merge that passed does not pass a run whose shard did not end well.
        let (_t, v) = ended(Some(0), &[Some(0), Some(3)], Some(0));
        assert!(!v.passed, "{}", v.text);
        // Many failed shards: the first 20 named, the rest counted.
        let (_t, v) = ended(Some(0), &[None; 25], Some(2));
        assert!(v.text.contains("shard 20/25") && !v.text.contains("shard 21/25"));
        assert!(v.text.contains("... and 5 more shards"), "{}", v.text);
        // Exactly 20: all named, none left to count.
        let (_t, v) = ended(Some(0), &[None; NAMED], Some(2));
        assert!(v.text.contains("shard 20/20"), "{}", v.text);
        assert!(!v.text.contains("more shards"), "{}", v.text);
    }

    /// A job directory with its three subdirectories, as `write_scripts` makes it.
    fn job_dir() -> (tempfile::TempDir, Layout) {
        let tmp = tempfile::tempdir().unwrap();
        for sub in ["logs", "status", "reports"] {
            std::fs::create_dir_all(tmp.path().join(sub)).unwrap();
        }
        let layout = Layout {
            root: tmp.path().to_path_buf(),
            shown: tmp.path().to_path_buf(),
        };
        (tmp, layout)
    }

    /// Only the shards' status files count, each once, and a shard failed unless its file
    /// says 0 (an unreadable one too).
    #[test]
    fn the_ended_shards_are_their_status_files_and_the_failed_those_not_0() {
        let (_t, layout) = job_dir();
        assert_eq!(shards_ended(&layout), (0, 0));
        for (job, text) in [
            ("build", "0"),
            ("merge", "1"),
            ("shard-1", "0"),
            ("shard-2", "1"),
            ("shard-3", "2\n"),
            ("shard-4", "not a number"),
            ("shard-5", "0\n"),
        ] {
            std::fs::write(layout.status(job), text).unwrap();
        }
        std::fs::write(layout.root.join("status").join("shard-6.log"), "0").unwrap();
        assert_eq!(shards_ended(&layout), (5, 3));
        let none = Layout {
            root: layout.root.join("no such dir"),
            shown: layout.root.join("no such dir"),
        };
        assert_eq!(shards_ended(&none), (0, 0));
    }

    #[test]
    fn a_runs_jobs_are_its_three_ids_in_order() {
        let jobs = Jobs {
            build: "7".into(),
            shards: "8".into(),
            merge: "9".into(),
        };
        assert_eq!(jobs.all(), ["7", "8", "9"]);
    }

    /// `wait` reports each change of the status files, in the words of the build's and the
    /// shards' state, and returns once the merge has written its status, not before (the
    /// files change well within the 5 s after which it would ask Slurm's queue).
    #[test]
    fn waiting_reports_each_change_and_ends_when_the_merge_has_ended() {
        let (_t, layout) = job_dir();
        let jobs = Jobs {
            build: "7".into(),
            shards: "8".into(),
            merge: "9".into(),
        };
        let merged = std::sync::atomic::AtomicBool::new(false);
        let lines = std::sync::Mutex::new(Vec::<String>::new());
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(Duration::from_millis(1000));
                std::fs::write(layout.status("build"), "0\n").unwrap();
                std::thread::sleep(Duration::from_millis(700));
                std::fs::write(layout.status("shard-1"), "0\n").unwrap();
                std::fs::write(layout.status("shard-2"), "1\n").unwrap();
                std::thread::sleep(Duration::from_millis(700));
                merged.store(true, std::sync::atomic::Ordering::SeqCst);
                std::fs::write(layout.status("merge"), "1\n").unwrap();
            });
            wait(&layout, &jobs, 2, &|l: &str| {
                lines.lock().unwrap().push(l.to_string())
            })
            .unwrap();
            assert!(
                merged.load(std::sync::atomic::Ordering::SeqCst),
                "wait returned before the merge ended"
            );
        });
        let lines = lines.into_inner().unwrap();
        assert_eq!(
            lines.first().map(String::as_str),
            Some("slurm: build running or queued; 0 of 2 shards ended (0 failed)")
        );
        assert_eq!(
            lines.last().map(String::as_str),
            Some("slurm: built; 2 of 2 shards ended (1 failed)"),
            "{lines:?}"
        );
        assert!(lines.windows(2).all(|w| w[0] != w[1]), "{lines:?}");
        assert!(lines.len() <= 3, "a line for each change only: {lines:?}");
        // A build that failed says so; a merge that has ended returns at once, silent.
        let (_t, layout) = job_dir();
        std::fs::write(layout.status("build"), "2\n").unwrap();
        let lines = std::sync::Mutex::new(Vec::<String>::new());
        std::thread::scope(|s| {
            s.spawn(|| {
                std::thread::sleep(Duration::from_millis(800));
                std::fs::write(layout.status("merge"), "2\n").unwrap();
            });
            wait(&layout, &jobs, 3, &|l: &str| {
                lines.lock().unwrap().push(l.to_string())
            })
            .unwrap();
        });
        assert_eq!(
            lines.into_inner().unwrap(),
            ["slurm: build failed (exit 2); 0 of 3 shards ended (0 failed)"]
        );
        let lines = std::sync::Mutex::new(Vec::<String>::new());
        wait(&layout, &jobs, 3, &|l: &str| {
            lines.lock().unwrap().push(l.to_string())
        })
        .unwrap();
        assert!(lines.into_inner().unwrap().is_empty());
    }

    /// The scripts run as Slurm runs them (`sh`, the task index in the environment) against a
    /// stand-in rmapgen that records its arguments and exits 3: each job calls rmapgen with
    /// the paths the others read (spelled out here, not taken from `Layout`), and writes the
    /// exit status where `verdict` looks for it.
    #[test]
    fn the_scripts_chain_the_build_the_shards_and_the_merge_through_their_paths() {
        let tmp = tempfile::tempdir().unwrap();
        let design = tmp.path().join("my design");
        std::fs::create_dir_all(&design).unwrap();
        let manifest = serde_json::json!({
            "top": "rmap_top",
            "config": crate::config::Config::default(),
            "modules": [],
        });
        std::fs::write(design.join("manifest.json"), manifest.to_string()).unwrap();
        let d = DesignDir::open(&design).unwrap();
        let root = tmp.path().join("job dir");
        let exe = tmp.path().join("fake rmapgen");
        let calls = tmp.path().join("calls");
        std::fs::write(
            &exe,
            format!(
                "#!/bin/sh\nfor a in \"$@\"; do printf '%s|' \"$a\"; done >> {}\necho >> {0}\nexit 3\n",
                shell_word(&calls.to_string_lossy())
            ),
        )
        .unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
        let layout = Layout {
            root: root.clone(),
            shown: root.clone(),
        };
        let o = Options {
            shards: 4,
            partition: None,
            sbatch_args: vec![],
            direct: false,
            front_engine: FrontEngine::Gates,
        };
        write_scripts(&d, &layout, &exe, &o).unwrap();
        for (script, task) in [("build.sh", ""), ("shards.sh", "2"), ("merge.sh", "")] {
            let s = std::process::Command::new("sh")
                .arg(root.join(script))
                .env("SLURM_ARRAY_TASK_ID", task)
                .status()
                .unwrap();
            assert_eq!(s.code(), Some(3), "{script} exits with rmapgen's status");
        }
        let r = |p: &str| root.join(p).to_string_lossy().into_owned();
        let dp = d.path().to_string_lossy().into_owned();
        let want = [
            format!(
                "prove|{dp}|--build-only|--front-engine|gates|--build|{}|",
                root.display()
            ),
            format!(
                "prove|{dp}|--front-engine|gates|--build|{}|--reuse|{}|--shard|2/4|--report|{}|",
                r("shards"),
                r("my design-build"),
                r("reports/shard-2-of-4.json")
            ),
            format!(
                "prove|--merge|{}|{}|{}|{}|",
                r("reports/shard-1-of-4.json"),
                r("reports/shard-2-of-4.json"),
                r("reports/shard-3-of-4.json"),
                r("reports/shard-4-of-4.json")
            ),
        ];
        let got = std::fs::read_to_string(&calls).unwrap();
        assert_eq!(got.lines().collect::<Vec<_>>(), want, "{got}");
        for status in ["build.exit", "shard-2.exit", "merge.exit"] {
            let text = std::fs::read_to_string(root.join("status").join(status)).unwrap();
            assert_eq!(text, "3\n", "{status}");
        }
        // The build job writes where the shards reuse it from: `--build-only --build ROOT`
        // makes ROOT/<design>-build.
        assert_eq!(layout.build(&d), root.join("my design-build"));
        assert_eq!(layout.script("merge"), root.join("merge.sh"));
    }

    #[test]
    fn the_shard_count_is_bounded_by_slurms_array_size() {
        let o = |shards| Options {
            shards,
            partition: None,
            sbatch_args: vec![],
            direct: false,
            front_engine: FrontEngine::Gates,
        };
        assert!(check(&o(1)).is_ok());
        assert!(check(&o(MAX_ARRAY)).is_ok());
        let e = check(&o(0)).unwrap_err().to_string();
        assert!(
            e.starts_with("--shards 0: a Slurm run has 1 to 1000 shards"),
            "{e}"
        );
        assert!(check(&o(MAX_ARRAY + 1)).is_err());
    }
}
