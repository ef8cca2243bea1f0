//! The one way rmapgen starts a child process (a tool, a built simulation, a copy of itself):
//! [`spawn`], then one of [`Running`]'s waits. Every child
//!
//! - runs in a process group of its own (its id the group's), registered with
//!   [`signals`] as [`Undo::KillGroup`] while it runs: SIGINT, SIGTERM or SIGHUP to rmapgen
//!   kill the whole group (the tool and everything it started: Verilator's `make`, `g++`,
//!   `cc1plus`), and so does rmapgen's guardian when rmapgen is killed outright (SIGKILL);
//! - gets SIGKILL from the kernel if the thread that started it dies
//!   (`prctl(PR_SET_PDEATHSIG)`). The parent-death signal is tied to the spawning *thread*:
//!   it is safe here because the thread that calls [`spawn`] is the one that waits for the
//!   child (the waits take the [`Running`] by value; dropping it kills the child), so it
//!   lives at least as long as the child;
//! - has `TMPDIR` pointed at a scratch directory of its own, registered for removal, so
//!   the temporary files of compilers killed mid-run (`/tmp/cc*.s`) go with it.
//!
//! When the child ends, whatever it left running in its group is killed too.
//!
//! The guardian itself ([`signals`]) is the one process started elsewhere: it must outlive
//! rmapgen.

use crate::output::signals::{self, Token, Undo};
use crate::output::Scratch;
use anyhow::Result;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

/// A child started by [`spawn`].
pub struct Running {
    child: Option<Child>,
    pid: u32,
    token: Option<Token>,
    _tmp: Scratch,
}

/// Starts `cmd` as described in the module documentation. An error names the program and
/// how to install it.
pub fn spawn(cmd: &mut Command) -> Result<Running> {
    let tmp = Scratch::new()?;
    let parent = std::process::id() as libc::pid_t;
    cmd.env("TMPDIR", tmp.path()).process_group(0);
    // SAFETY: the closure runs in the child between fork and exec and only makes
    // async-signal-safe system calls (prctl, getppid).
    unsafe {
        cmd.pre_exec(move || {
            if libc::prctl(
                libc::PR_SET_PDEATHSIG,
                libc::SIGKILL as libc::c_ulong,
                0,
                0,
                0,
            ) != 0
            {
                return Err(std::io::Error::last_os_error());
            }
            // rmapgen died before the line above: the signal will never come.
            if libc::getppid() != parent {
                return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
            }
            Ok(())
        });
    }
    // Held from before the fork until the group is registered: an interrupt in between
    // waits, and then finds the child registered.
    let mut held = signals::hold();
    let child = cmd.spawn().map_err(|e| super::start_error(cmd, e))?;
    let token = held.register(Undo::KillGroup(child.id()));
    drop(held);
    Ok(Running {
        pid: child.id(),
        child: Some(child),
        token: Some(token),
        _tmp: tmp,
    })
}

impl Running {
    /// The child's process id (and its group's).
    pub fn id(&self) -> u32 {
        self.pid
    }

    /// Waits for the child to end.
    pub fn wait(mut self) -> Result<ExitStatus> {
        let status = self.child.as_mut().expect("not yet waited for").wait();
        self.finish();
        Ok(status?)
    }

    /// Waits for the child to end, collecting its stdout and stderr (set them to
    /// [`Stdio::piped`] before [`spawn`]).
    pub fn wait_with_output(mut self) -> Result<Output> {
        let out = self
            .child
            .take()
            .expect("not yet waited for")
            .wait_with_output();
        self.finish();
        Ok(out?)
    }

    /// Waits for the child to end, at most `timeout`: then it is killed with its group and
    /// the result is None.
    pub fn wait_timeout(mut self, timeout: Duration) -> Result<Option<ExitStatus>> {
        let start = Instant::now();
        let child = self.child.as_mut().expect("not yet waited for");
        let status = loop {
            if let Some(s) = child.try_wait()? {
                break Some(s);
            }
            if start.elapsed() > timeout {
                Undo::KillGroup(child.id()).run_now();
                child.wait()?;
                break None;
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        self.finish();
        Ok(status)
    }

    /// The child has ended: what it left running in its group goes too, and the group is
    /// no longer registered.
    fn finish(&mut self) {
        // The group outlives its leader only through what the child left behind; its id
        // cannot be reused while any of them is alive.
        if let Some(t) = self.token.take() {
            Undo::KillGroup(self.pid).run_now();
            t.release();
        }
        self.child = None;
    }
}

impl Drop for Running {
    /// A child not waited for (an error or a panic on the way) is killed with its group.
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            Undo::KillGroup(c.id()).run_now();
            c.wait().ok();
        }
        if let Some(t) = self.token.take() {
            t.release();
        }
    }
}

/// Runs `cmd` to the end with its stdout and stderr captured (stdin empty).
pub fn output(cmd: &mut Command) -> Result<Output> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    spawn(cmd)?.wait_with_output()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The state letter of process `pid` (None when it is gone).
    fn state(pid: &str) -> Option<char> {
        let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
        stat[stat.rfind(')')? + 2..].chars().next()
    }

    #[test]
    fn a_child_has_its_own_tmpdir_removed_when_it_ends() {
        let mut c = Command::new("sh");
        c.args([
            "-c",
            "echo \"$TMPDIR\"; : > \"$TMPDIR/ccX.s\"; ls \"$TMPDIR\"",
        ]);
        let out = output(&mut c).unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let mut lines = text.lines();
        let tmp = lines.next().unwrap();
        assert!(tmp.contains("rmapgen-"), "{text}");
        assert_eq!(lines.next(), Some("ccX.s"), "{text}");
        assert!(!std::path::Path::new(tmp).exists(), "{tmp} removed");
    }

    #[test]
    fn what_a_child_leaves_running_in_its_group_is_killed_when_it_ends() {
        let mut c = Command::new("sh");
        c.args(["-c", "sleep 100 >/dev/null 2>&1 & echo $!"]);
        let out = output(&mut c).unwrap();
        let pid = String::from_utf8_lossy(&out.stdout).trim().to_string();
        let start = Instant::now();
        while state(&pid).is_some_and(|s| s != 'Z') && start.elapsed() < Duration::from_secs(3) {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert!(
            !matches!(state(&pid), Some(s) if s != 'Z'),
            "sleep {pid} still running"
        );
    }

    #[test]
    fn a_timed_out_child_is_killed_with_its_group() {
        let mut c = Command::new("sh");
        c.args(["-c", "sleep 100 & sleep 100"])
            .stdout(Stdio::null());
        let start = Instant::now();
        let r = spawn(&mut c)
            .unwrap()
            .wait_timeout(Duration::from_millis(200))
            .unwrap();
        assert!(r.is_none(), "timed out");
        assert!(start.elapsed() < Duration::from_secs(5));
    }
}
