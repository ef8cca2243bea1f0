//! A long run whose standard error is not a terminal prints a plain progress line every
//! period (issue 60: `fit`, `fpga` and `prove` were silent for minutes in CI logs); the
//! period comes from RMAPGEN_PROGRESS, `0` silences it, a bad value is refused before any
//! work.

use crate::helpers::{self, assert_error};

/// `stress` on `samples` samples with RMAPGEN_PROGRESS=`every`: stdout and stderr.
fn stress(samples: &str, every: &str) -> (String, String, std::process::ExitStatus) {
    let out = helpers::rmapgen()
        .args(["stress", "--samples", samples])
        .env("RMAPGEN_PROGRESS", every)
        .output()
        .expect("rmapgen runs");
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        out.status,
    )
}

#[test]
fn a_long_run_in_a_log_says_every_period_how_far_it_is() {
    // 10 million samples: several seconds on the 2-core CI machine (2 to 3 million a second
    // measured there).
    let (out, err, status) = stress("10000000", "1");
    assert!(status.success(), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert!(
        !lines.is_empty(),
        "no progress line on stderr; stdout: {out}"
    );
    for l in &lines {
        // `rmapgen stress: 00:00:03 4,718,592 of 10,000,000 samples (47 %)`
        let rest = l
            .strip_prefix("rmapgen stress: 00:0")
            .unwrap_or_else(|| panic!("not a progress line: {l:?}"));
        assert!(
            rest.ends_with(" %)") && rest.contains(" of 10,000,000 samples ("),
            "{l:?}"
        );
    }
    // Standard output is the command's own: the summary, no progress.
    assert!(!out.contains("rmapgen stress:"), "{out}");
    let (quiet_out, quiet_err, status) = stress("10000000", "0");
    assert!(status.success());
    assert_eq!(quiet_err, "", "RMAPGEN_PROGRESS=0 prints no line");
    // The same result either way (but for the time it took).
    let untimed = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
    assert_eq!(untimed(&quiet_out), untimed(&out));
}

#[test]
fn a_bad_progress_period_is_refused_before_any_work() {
    for bad in ["x", "-1", "1.5", "86401"] {
        let out = helpers::rmapgen()
            .args(["stress", "--samples", "10"])
            .env("RMAPGEN_PROGRESS", bad)
            .output()
            .unwrap();
        assert_error(
            &out,
            &format!("RMAPGEN_PROGRESS=\"{bad}\" is not a number of seconds"),
        );
        assert!(out.stdout.is_empty());
    }
}
