//! Nothing left running, nothing left behind (issue 32 §3): a signal to rmapgen's own process
//! id (what `kill`, CI timeouts and batch schedulers send), SIGTERM or SIGKILL, ends every
//! process rmapgen started, however deep (Verilator's make, g++, cc1plus), and leaves no
//! scratch file in the temporary directory.
//!
//! Each run is started in a session of its own (setsid), so every process of its tree, even
//! one that was re-parented when its parent died, is found by its session id in /proc.
//!
//! Bad input to a command that makes a build or log directory (`fpga`, `prove`, `sim`,
//! `synth`, `prove-mult`, `mutants`) is refused before the directory is made.

use crate::{hdl, helpers};
use rmapgen::grid;
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

/// One process as /proc/PID/stat shows it.
#[derive(Debug, Clone)]
struct Proc {
    pid: i32,
    comm: String,
    state: char,
    session: i32,
}

fn processes() -> Vec<Proc> {
    let mut v = Vec::new();
    for e in std::fs::read_dir("/proc").expect("/proc").flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            continue;
        };
        // pid (comm) state ppid pgrp session ...; comm may hold spaces and parentheses.
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let comm = stat[open + 1..close].to_string();
        let rest: Vec<&str> = stat[close + 2..].split(' ').collect();
        if rest.len() < 4 {
            continue;
        }
        v.push(Proc {
            pid,
            comm,
            state: rest[0].chars().next().unwrap_or('?'),
            session: rest[3].parse().unwrap_or(-1),
        });
    }
    v
}

/// The live (not zombie) processes of session `sid`.
fn session(sid: i32) -> Vec<Proc> {
    processes()
        .into_iter()
        .filter(|p| p.session == sid && p.state != 'Z')
        .collect()
}

/// Starts rmapgen with `args` as the leader of a new session, its TMPDIR `tmp`.
fn start(args: &[&str], tmp: &Path) -> Child {
    start_with(args, tmp, &[])
}

/// [`start`] with more environment variables.
fn start_with(args: &[&str], tmp: &Path, env: &[(&str, &str)]) -> Child {
    let mut c = helpers::rmapgen();
    // A compiler cache would answer Verilator's make without running a compiler to kill.
    c.args(args)
        .env_remove("OBJCACHE")
        .envs(env.iter().copied())
        .env("TMPDIR", tmp)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    // SAFETY: setsid is async-signal-safe and touches no memory.
    unsafe {
        c.pre_exec(|| {
            if libc::setsid() < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    c.spawn().expect("rmapgen starts")
}

/// Waits until a process named one of `names` runs in rmapgen's session (rmapgen's pid is
/// the session id); panics after `limit`.
fn wait_for(child: &mut Child, names: &[&str], limit: Duration) -> Proc {
    let sid = child.id() as i32;
    let start = Instant::now();
    loop {
        if let Some(p) = session(sid).into_iter().find(|p| names.contains(&&*p.comm)) {
            return p;
        }
        if let Some(s) = child.try_wait().unwrap() {
            panic!("rmapgen ended ({s}) before any of {names:?} ran");
        }
        assert!(
            start.elapsed() < limit,
            "none of {names:?} started in {limit:?}: {:?}",
            session(sid)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Sends `sig` to rmapgen's pid only, then checks that within a few seconds nothing of its
/// session runs and `tmp` is empty. Returns how long the session took to empty.
fn kill_and_check(mut child: Child, sig: i32, tmp: &Path, what: &str) -> Duration {
    let sid = child.id() as i32;
    let before = session(sid);
    // SAFETY: kill(2) on the pid of a child we have not reaped.
    assert_eq!(unsafe { libc::kill(sid, sig) }, 0);
    let status = child.wait().unwrap();
    use std::os::unix::process::ExitStatusExt;
    // Ended by the signal (the watcher re-raises it after the cleanup; a shell shows 143).
    assert!(
        status.signal() == Some(sig) || status.code() == Some(128 + sig),
        "{what}: ended by {status} on signal {sig}"
    );
    let start = Instant::now();
    let mut left = session(sid);
    while !left.is_empty() && start.elapsed() < Duration::from_secs(3) {
        std::thread::sleep(Duration::from_millis(20));
        left = session(sid);
    }
    let took = start.elapsed();
    assert!(
        left.is_empty(),
        "{what}, signal {sig}: still running {:.1} s after rmapgen ended: {left:?} (were: {before:?})",
        took.as_secs_f64()
    );
    // The guardian may still be removing the scratch directories as it exits.
    let start = Instant::now();
    while helpers::nonempty(tmp) && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        !helpers::nonempty(tmp),
        "{what}, signal {sig}: left in the temporary directory: {:?}",
        helpers::entries(tmp)
    );
    took
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// `sim --verilator`, killed while Verilator's make runs g++ (a grandchild's grandchild):
/// by SIGTERM, and by SIGKILL.
#[test]
fn a_signal_to_sim_verilator_ends_make_and_the_compilers() {
    if !hdl::require("verilator") {
        return;
    }
    let work = helpers::tempdir();
    let dir = work.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 20);
    for sig in [libc::SIGTERM, libc::SIGKILL] {
        let tmp = work.path().join(format!("tmp{sig}"));
        std::fs::create_dir(&tmp).unwrap();
        let build = work.path().join(format!("build{sig}"));
        let mut child = start(
            &[
                "sim",
                "--verilator",
                "--only",
                "rmap_top",
                "--build",
                s(&build),
                s(&dir),
            ],
            &tmp,
        );
        let p = wait_for(&mut child, &["cc1plus", "cc1"], Duration::from_secs(300));
        eprintln!("killing with {sig} while {} ({}) runs", p.comm, p.pid);
        let took = kill_and_check(child, sig, &tmp, "sim --verilator");
        eprintln!(
            "signal {sig}: session empty {:.2} s after rmapgen",
            took.as_secs_f64()
        );
        assert!(!build.exists(), "no build directory after signal {sig}");
        let left: Vec<String> = helpers::entries(work.path())
            .into_iter()
            .filter(|n| n.starts_with(".build"))
            .collect();
        assert!(left.is_empty(), "staging left: {left:?}");
    }
}

/// A stand-in for Yosys that starts a grandchild and a great-grandchild that would run for
/// five minutes, and leaves a compiler-like temporary file, as `g++` killed mid-run does.
fn fake_tool(dir: &Path) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let p = dir.join("fake-yosys");
    std::fs::write(
        &p,
        "#!/bin/sh\n: > \"${TMPDIR:-/tmp}/ccFAKE.s\"\nsh -c 'sleep 300 & sleep 301' &\nsleep 302\n",
    )
    .unwrap();
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    p
}

/// `synth` with a tool whose descendants would outlive it, killed by SIGTERM, SIGHUP and
/// SIGKILL: every descendant ends within 3 s, the tool's temporary file goes too.
#[test]
fn a_signal_to_synth_ends_every_process_its_tool_started() {
    let work = helpers::tempdir();
    let dir = work.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 20);
    let tool = fake_tool(work.path());
    for sig in [libc::SIGTERM, libc::SIGHUP, libc::SIGKILL] {
        let tmp = work.path().join(format!("tmp{sig}"));
        std::fs::create_dir(&tmp).unwrap();
        let logs = work.path().join(format!("logs{sig}"));
        let mut c = start_with(
            &["synth", "--logs", s(&logs), s(&dir)],
            &tmp,
            &[("YOSYS", s(&tool))],
        );
        // The great-grandchild: `sleep 300` under `sh -c` under the tool.
        let sleeps = |c: &Child| {
            session(c.id() as i32)
                .into_iter()
                .filter(|p| p.comm == "sleep")
                .count()
        };
        let start = Instant::now();
        while sleeps(&c) < 3 {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the tool did not start"
            );
            assert!(c.try_wait().unwrap().is_none(), "rmapgen ended early");
            std::thread::sleep(Duration::from_millis(20));
        }
        kill_and_check(c, sig, &tmp, "synth");
        assert!(!logs.exists(), "no logs directory after signal {sig}");
    }
}

/// `synth`, killed while Yosys runs (SIGKILL: the watcher never runs; the guardian does).
#[test]
fn a_sigkill_to_synth_ends_yosys() {
    if !hdl::require("yosys") {
        return;
    }
    let work = helpers::tempdir();
    let dir = work.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 20);
    let tmp = work.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let mut child = start(&["synth", s(&dir)], &tmp);
    wait_for(&mut child, &["yosys"], Duration::from_secs(60));
    kill_and_check(child, libc::SIGKILL, &tmp, "synth");
}

/// `prove` killed (SIGKILL) while its Verilator build compiles, and `fpga` (SIGTERM) while
/// nextpnr places: nothing of either is left running, no scratch file is left.
#[test]
fn a_signal_to_prove_or_fpga_ends_their_tools() {
    if !hdl::require("verilator") || !hdl::require("nextpnr-ice40") {
        return;
    }
    let work = helpers::tempdir();
    let dir = work.path().join("n");
    hdl::generate_config(&dir, &grid::narrowest(), 5);
    // fpga --dir places only a design made for the family (a generic one is refused after
    // synthesis), so it gets one; its part check runs nextpnr for a moment first, which the
    // wait may or may not catch: either way nextpnr runs when the signal comes.
    let ice40 = work.path().join("i");
    let mut flags = hdl::narrowest_flags();
    flags.extend(["--target".to_string(), "ice40".to_string()]);
    hdl::generate(&ice40, &hdl::strs(&flags), 5);
    let b = work.path().join("B");
    for (args, tools, sig) in [
        (
            vec!["prove", "--build", s(&b), s(&dir)],
            &["cc1plus", "cc1"][..],
            libc::SIGKILL,
        ),
        (
            vec!["fpga", "--dir", s(&ice40), "--logs", s(&b)],
            &["nextpnr-ice40"][..],
            libc::SIGTERM,
        ),
    ] {
        let tmp = work.path().join(format!("tmp-{}", args[0]));
        std::fs::create_dir(&tmp).unwrap();
        let mut child = start(&args, &tmp);
        wait_for(&mut child, tools, Duration::from_secs(300));
        kill_and_check(child, sig, &tmp, args[0]);
        assert!(!b.exists(), "{}: no build or log directory", args[0]);
    }
}

/// Runs rmapgen in `cwd` and checks a one-line refusal naming `needle`, exit 2, and that
/// `cwd` holds nothing but what it held before.
fn refused_leaving_nothing(cwd: &Path, args: &[&str], needle: &str) {
    let before = helpers::entries(cwd);
    let o = helpers::rmapgen()
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    helpers::assert_error(&o, needle);
    assert_eq!(
        helpers::entries(cwd),
        before,
        "rmapgen {args:?} left something behind"
    );
}

/// `fpga` with a bad --device, --package, --dir or configuration makes no --logs directory.
#[test]
fn fpga_bad_input_leaves_no_log_directory() {
    if !hdl::require("nextpnr-ice40") {
        return;
    }
    let work = helpers::tempdir();
    let w = work.path();
    hdl::generate_config(&w.join("n"), &grid::narrowest(), 5);
    for (args, needle) in [
        (vec!["fpga", "--device", "hx9k", "--logs", "L/x"], "--hx9k"),
        (vec!["fpga", "--package", "zz999", "--logs", "L"], "zz999"),
        (
            vec!["fpga", "--dir", "nope", "--logs", "L"],
            "no manifest.json in nope",
        ),
        (
            vec!["fpga", "--dir", "n", "--device", "hx9k", "--logs", "L"],
            "--hx9k",
        ),
        (
            vec!["fpga", "--dir", "n", "--package", "zz999", "--logs", "L"],
            "zz999",
        ),
        (vec!["fpga", "--red-bits", "13", "--logs", "L"], "red"),
    ] {
        refused_leaving_nothing(w, &args, needle);
    }
}

/// `prove --part bogus` makes neither B/<design>-1of1 nor B, nor the --report file.
#[test]
fn prove_bad_part_leaves_no_build_directory() {
    let work = helpers::tempdir();
    let w = work.path();
    hdl::generate_config(&w.join("n"), &grid::narrowest(), 5);
    refused_leaving_nothing(
        w,
        &["prove", "--part", "bogus", "--build", "B", "n"],
        "--part bogus",
    );
    refused_leaving_nothing(
        w,
        &[
            "prove", "--direct", "--part", "states", "--report", "r.json", "--build", "B", "n",
        ],
        "--part states",
    );
}

/// The other commands that make a build or log directory refuse their bad input first.
#[test]
fn other_commands_bad_input_leaves_no_directory() {
    let work = helpers::tempdir();
    let w = work.path();
    hdl::generate_config(&w.join("n"), &grid::narrowest(), 5);
    for (args, needle) in [
        (
            vec!["sim", "--icarus", "--only", "nope", "--build", "B", "n"],
            "--only nope",
        ),
        (
            vec!["sim", "--icarus", "--build", "B", "missing"],
            "missing",
        ),
        (vec!["synth", "--logs", "L", "missing"], "missing"),
        (vec!["prove-mult", "--logs", "L", "missing"], "missing"),
        (
            vec![
                "mutants",
                "--only",
                "99",
                "--count",
                "1",
                "--memories",
                "0",
                "--build",
                "B",
                "n",
            ],
            "--only m99",
        ),
        (
            vec!["mutants", "--timeout", "0", "--build", "B", "n"],
            "--timeout 0",
        ),
    ] {
        refused_leaving_nothing(w, &args, needle);
    }
}

/// The guardian (`--rmapgen-guardian PID`, src/output/signals.rs) undoes what a run left
/// registered when the run ended by a signal it could not catch. It is started by rmapgen
/// alone: its parent's pid is the argument. It also takes over when that parent died before
/// it looked (the pid is gone and the registrations wait on a pipe). Anything else is refused,
/// and it undoes nothing: started by hand with a live pid, a pipe or not, or with a dead pid
/// and no pipe.
#[test]
fn the_guardian_takes_over_from_a_dead_rmapgen_and_is_refused_by_hand() {
    use std::io::Write;
    let t = helpers::tempdir();
    let hex = |p: &Path| -> String {
        use std::os::unix::ffi::OsStrExt;
        p.as_os_str()
            .as_bytes()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    };
    // A pid that is surely gone: a child of this test, reaped.
    let mut gone = std::process::Command::new("true").spawn().unwrap();
    gone.wait().unwrap();
    let dead = gone.id().to_string();
    let guardian = |pid: &str, registrations: Option<&str>| {
        let mut c = helpers::rmapgen();
        c.arg("--rmapgen-guardian").arg(pid).stdout(Stdio::null());
        c.stderr(Stdio::piped());
        c.stdin(if registrations.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        });
        let mut child = c.spawn().unwrap();
        if let Some(text) = registrations {
            let mut pipe = child.stdin.take().unwrap();
            // A refused guardian may have closed its end already.
            pipe.write_all(text.as_bytes()).ok();
        }
        child.wait_with_output().unwrap()
    };
    let refused = "is started by rmapgen itself, not by hand";
    let (undone, released) = (t.path().join("undone"), t.path().join("released"));
    for d in [&undone, &released] {
        std::fs::create_dir(d).unwrap();
        std::fs::write(d.join("f"), "x").unwrap();
    }
    let lines = format!("+1 R {}\n+2 R {}\n-2\n", hex(&undone), hex(&released));
    // By hand: a live process that is not its parent (pid 1), with a pipe and without; a
    // dead pid without a pipe.
    for (pid, regs) in [("1", Some(&*lines)), ("1", None), (&*dead, None)] {
        let o = guardian(pid, regs);
        assert_eq!(o.status.code(), Some(2), "{pid} {regs:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(refused));
        assert!(
            undone.is_dir() && released.is_dir(),
            "{pid}: nothing undone"
        );
    }
    // Its rmapgen died before it looked: it reads the registrations and undoes what is
    // still registered when the pipe closes.
    let o = guardian(&dead, Some(&lines));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!undone.exists(), "a registered directory is removed");
    assert!(released.join("f").is_file(), "a released one is kept");
}
