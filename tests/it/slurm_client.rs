//! `prove --slurm` against stand-ins for Slurm's client commands (`SBATCH`, `SQUEUE`,
//! `SCANCEL`): what rmapgen does when one is missing, and when a submission is refused half
//! way, which a working cluster (`make slurm-test`) never shows.

use crate::helpers;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Output;

/// An executable shell script `name` in `dir`.
fn script(dir: &Path, name: &str, body: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

fn design(tmp: &Path) -> PathBuf {
    let d = tmp.join("d");
    let o = helpers::run(&[
        "generate",
        "--grad-bits",
        "8",
        "--red-bits",
        "6",
        "--vectors",
        "0",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", helpers::text(&o));
    d
}

fn prove(design: &Path, build: &Path, env: &[(&str, &Path)]) -> Output {
    let mut c = helpers::rmapgen();
    c.args(["prove", "--slurm", "--shards", "2", "--build"])
        .arg(build)
        .arg(design);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

/// Each client command missing is named, with what --slurm needs, before anything is written
/// or submitted.
#[test]
fn a_missing_slurm_command_is_one_line_and_nothing_is_submitted() {
    let tmp = helpers::tempdir();
    let d = design(tmp.path());
    let log = tmp.path().join("called.log");
    let called = format!("echo \"$0 $*\" >> {}; echo 1", log.display());
    let fakes = [
        ("SBATCH", script(tmp.path(), "sbatch", &called)),
        ("SQUEUE", script(tmp.path(), "squeue", &called)),
        ("SCANCEL", script(tmp.path(), "scancel", &called)),
    ];
    for (var, _) in &fakes {
        let missing = tmp.path().join(format!("no-{var}"));
        let mut env: Vec<(&str, &Path)> = fakes
            .iter()
            .filter(|(v, _)| v != var)
            .map(|(v, p)| (*v, p.as_path()))
            .collect();
        env.push((var, &missing));
        let build = tmp.path().join(format!("build-{var}"));
        let o = prove(&d, &build, &env);
        helpers::assert_error(
            &o,
            &format!(
                "{} not found: --slurm submits to a Slurm cluster",
                missing.display()
            ),
        );
        assert!(!log.exists(), "{var} missing: nothing is called");
        assert!(
            !build.join("slurm").exists(),
            "{var} missing: nothing written"
        );
    }
}

/// sbatch refusing the second or the third job: the jobs it took are cancelled at once (they
/// would wait on a dependency nobody runs), and the refusal is the error.
#[test]
fn a_submission_refused_half_way_cancels_the_jobs_already_submitted() {
    let tmp = helpers::tempdir();
    let d = design(tmp.path());
    let squeue = script(tmp.path(), "squeue", "exit 0");
    for (refused, want) in [(2, "4201"), (3, "4201 4202")] {
        let count = tmp.path().join(format!("count-{refused}"));
        let cancelled = tmp.path().join(format!("cancelled-{refused}.log"));
        let sbatch = script(
            tmp.path(),
            &format!("sbatch-{refused}"),
            &format!(
                "n=$(( $(cat {c} 2>/dev/null || echo 0) + 1 )); echo $n > {c}\n\
                 if [ $n -ge {refused} ]; then echo 'sbatch: error: Batch job submission failed: Invalid partition' >&2; exit 1; fi\n\
                 echo 420$n",
                c = count.display()
            ),
        );
        let scancel = script(
            tmp.path(),
            &format!("scancel-{refused}"),
            &format!("echo \"$*\" >> {}", cancelled.display()),
        );
        let build = tmp.path().join(format!("build-{refused}"));
        let o = prove(
            &d,
            &build,
            &[
                ("SBATCH", &sbatch),
                ("SQUEUE", &squeue),
                ("SCANCEL", &scancel),
            ],
        );
        let t = helpers::text(&o);
        assert!(!o.status.success(), "{t}");
        assert!(
            t.contains("sbatch refused") && t.contains("Invalid partition"),
            "{t}"
        );
        assert_eq!(
            std::fs::read_to_string(&cancelled)
                .unwrap_or_default()
                .trim(),
            want,
            "job {refused} refused: the jobs before it cancelled; {t}"
        );
    }
}

/// Every entry under `dir` (directories too, hidden ones too) with a file's bytes: what a
/// run may leave behind.
fn everything(dir: &Path) -> Vec<(String, Option<Vec<u8>>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let rel = p.strip_prefix(dir).unwrap().display().to_string();
            if p.is_dir() {
                out.push((rel + "/", None));
                stack.push(p);
            } else {
                out.push((rel, Some(std::fs::read(&p).unwrap())));
            }
        }
    }
    out.sort();
    out
}

/// Stand-ins for a cluster: an sbatch that refuses every job as one without a controller does,
/// one that takes every job (and, as the merge job, writes its exit status 1: the other jobs
/// "ran" and wrote nothing), a queue that holds the jobs forever or has none, and a scancel
/// that records what it cancels.
struct Cluster {
    refuse: PathBuf,
    accept: PathBuf,
    queue_empty: PathBuf,
    queue_full: PathBuf,
    scancel: PathBuf,
    cancelled: PathBuf,
}

impl Cluster {
    fn new(dir: &Path) -> Cluster {
        std::fs::create_dir_all(dir).unwrap();
        let cancelled = dir.join("cancelled.log");
        Cluster {
            refuse: script(
                dir,
                "sbatch-refuses",
                "echo 'sbatch: error: Batch job submission failed: Unable to contact slurm controller (connect failure)' >&2\nexit 1",
            ),
            accept: script(
                dir,
                "sbatch-accepts",
                "for a; do s=\"$a\"; done\n\
                 case \"$s\" in */merge.sh) [ -z \"$HOLD\" ] && echo 1 > \"$(dirname \"$s\")/status/merge.exit\";; esac\n\
                 echo 4242",
            ),
            queue_empty: script(dir, "squeue-empty", "exit 0"),
            queue_full: script(dir, "squeue-full", "echo 4242"),
            scancel: script(
                dir,
                "scancel",
                &format!("echo \"$*\" >> {}", cancelled.display()),
            ),
            cancelled,
        }
    }

    /// `rmapgen prove --slurm` of design `d` in `cwd`, with the job directory under the
    /// relative `new/build` (neither exists at first).
    fn prove(&self, cwd: &Path, sbatch: &Path, hold: bool) -> std::process::Command {
        let mut c = helpers::rmapgen();
        c.current_dir(cwd)
            .args([
                "prove",
                "--slurm",
                "--shards",
                "2",
                "--build",
                "new/build",
                "d",
            ])
            .env("SBATCH", sbatch)
            .env(
                "SQUEUE",
                if hold {
                    &self.queue_full
                } else {
                    &self.queue_empty
                },
            )
            .env("SCANCEL", &self.scancel);
        if hold {
            c.env("HOLD", "1");
        }
        c
    }
}

/// Issue 60: a `prove --slurm` whose sbatch cannot reach a controller exited 2 but left the
/// job directory and the parents it made, then refused its own leftovers on every later run
/// ("it holds logs/, which rmapgen did not write"). A refused submission now leaves nothing
/// it made, and a previous run's directory as it was; a run whose jobs ran keeps its
/// directory recorded as rmapgen's, its empty directories gone, so the next run replaces it;
/// messages name the job directory as the user gave it.
#[test]
fn a_refused_submission_leaves_nothing_and_a_run_that_ran_is_replaced_by_the_next() {
    let tmp = helpers::tempdir();
    let work = &tmp.path().join("work");
    design(work);
    let cluster = Cluster::new(&tmp.path().join("cluster"));
    let before = everything(work);
    let refused = "sbatch refused the build job: sbatch: error: Batch job submission failed: Unable to contact slurm controller (connect failure)";
    let o = cluster
        .prove(work, &cluster.refuse, false)
        .output()
        .unwrap();
    helpers::assert_error(&o, refused);
    assert_eq!(
        everything(work),
        before,
        "nothing left: {}",
        helpers::text(&o)
    );
    // The jobs taken and "run": the merge says 1, the build and shards wrote nothing.
    let job = work.join("new/build/d-slurm");
    for round in 0..2 {
        let o = cluster
            .prove(work, &cluster.accept, false)
            .output()
            .unwrap();
        let t = helpers::text(&o);
        assert_eq!(o.status.code(), Some(1), "round {round}: {t}");
        for want in [
            "scripts and logs in new/build/d-slurm\n",
            "the build job 4242 was cancelled or killed before it ended (no exit status; new/build/d-slurm/logs/build.log)",
            "shard 2/2 (task 4242_2) was cancelled or killed before it ended (no exit status; new/build/d-slurm/logs/shard-2.log)",
        ] {
            assert!(t.contains(want), "round {round}: {want:?} in {t}");
        }
        let names: Vec<String> = everything(&job).into_iter().map(|e| e.0).collect();
        assert_eq!(
            names,
            [
                ".rmapgen-files",
                "build.sh",
                "merge.sh",
                "shards.sh",
                "status/",
                "status/merge.exit"
            ],
            "round {round}: the empty logs/ and reports/ are gone"
        );
    }
    // Refused again: the previous run's directory is back, byte for byte, and nothing else.
    let before = everything(work);
    let o = cluster
        .prove(work, &cluster.refuse, false)
        .output()
        .unwrap();
    helpers::assert_error(&o, refused);
    assert_eq!(everything(work), before);
    assert!(
        !cluster.cancelled.exists(),
        "nothing was submitted to cancel"
    );
}

/// Interrupted while it waits for its jobs, `prove --slurm` cancels them and takes back what
/// it made: a fresh job directory and its new parents go, a previous run's comes back.
#[test]
fn an_interrupted_run_cancels_its_jobs_and_leaves_what_was_there() {
    use std::io::BufRead;
    let tmp = helpers::tempdir();
    let work = &tmp.path().join("work");
    design(work);
    let cluster = Cluster::new(&tmp.path().join("cluster"));
    let interrupted = |want: &[(String, Option<Vec<u8>>)]| {
        let mut child = cluster
            .prove(work, &cluster.accept, true)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let mut out = std::io::BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        while !line.contains("slurm: submitted") {
            line.clear();
            assert!(out.read_line(&mut line).unwrap() > 0, "no announcement");
        }
        assert!(
            work.join("new/build/d-slurm/merge.sh").is_file(),
            "the scripts in place while the jobs run"
        );
        assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
        let status = child.wait().unwrap();
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(libc::SIGTERM));
        assert_eq!(everything(work), want);
        let cancelled = std::fs::read_to_string(&cluster.cancelled).unwrap();
        std::fs::remove_file(&cluster.cancelled).unwrap();
        assert_eq!(cancelled.trim(), "4242 4242 4242");
    };
    interrupted(&everything(work));
    // After a run that ended: its directory comes back.
    let o = cluster
        .prove(work, &cluster.accept, false)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", helpers::text(&o));
    interrupted(&everything(work));
}
