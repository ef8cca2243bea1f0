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
