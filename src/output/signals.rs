//! Clean interrupts: every staging directory, partial file and scratch directory rmapgen is
//! writing is registered here while it exists. On SIGINT, SIGTERM or SIGHUP a watcher thread
//! removes them all, puts back a previous output that was being replaced, and ends the
//! process by the signal's default action (so a shell sees 130 for Ctrl-C, 143 for SIGTERM).
//!
//! Writers that change the registered paths hold [`hold`] while they do, so the watcher never
//! removes a directory half-way through a file being created in it, and never sees a target
//! between the two renames that replace it.
//!
//! A signal that cannot be caught (SIGKILL, the OOM killer) ends rmapgen before the watcher
//! can run. For that, the `rmapgen` binary starts a guardian ([`install_guardian`]): a copy
//! of itself in a process group of its own, started at the first registration, to which every
//! registration and release is sent over a pipe. When rmapgen ends, however it ends, the
//! pipe closes; the guardian then undoes whatever is still registered (kills the children's
//! process groups, removes staging and scratch directories) and exits.

use std::io::Write;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once};
use std::time::{Duration, Instant};

/// How long an undo waits for processes it killed to go, or retries removing a directory
/// they were still writing into.
const SETTLE: Duration = Duration::from_secs(3);

/// What to undo for one registered path.
#[derive(Debug, Clone)]
pub enum Undo {
    /// A staging directory (a single file's partial file is written inside one) or scratch
    /// directory: remove it whole. Anything else at its path (a file or a symbolic link that
    /// took the name) was not made by rmapgen, and stays.
    Remove(PathBuf),
    /// A directory rmapgen created as the parent of its output: remove it if it is empty.
    RemoveIfEmpty(PathBuf),
    /// A previous output moved aside while the new one takes its place: move it back to
    /// `to` if nothing is there yet, else remove it.
    Restore { from: PathBuf, to: PathBuf },
    /// A child process started in a process group of its own (its id the group's): kill
    /// the group, so no tool it started outlives rmapgen.
    KillGroup(u32),
    /// Work rmapgen handed to another system (jobs submitted to Slurm): run this command
    /// (`scancel` and the job ids), its output discarded, and wait for it.
    Run(Vec<String>),
}

impl Undo {
    /// Does it now (a child past its time limit is killed the way an interrupt kills it).
    pub fn run_now(&self) {
        self.run()
    }

    fn run(&self) {
        match self {
            Undo::Remove(p) => {
                // A killed child may still be writing into a directory for a moment (SIGKILL
                // is delivered, not awaited): try again until it is gone.
                let start = Instant::now();
                loop {
                    match std::fs::symlink_metadata(p) {
                        Ok(m) if m.is_dir() => std::fs::remove_dir_all(p).ok(),
                        _ => break,
                    };
                    if std::fs::symlink_metadata(p).is_err() || start.elapsed() > SETTLE {
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }
            Undo::RemoveIfEmpty(p) => {
                std::fs::remove_dir(p).ok();
            }
            Undo::KillGroup(pgid) => {
                // SAFETY: kill(2) with a negative pid signals the process group; no memory
                // is touched.
                unsafe {
                    libc::kill(-(*pgid as i32), libc::SIGKILL);
                }
            }
            Undo::Run(words) => {
                if let Some((program, args)) = words.split_first() {
                    std::process::Command::new(program)
                        .args(args)
                        .stdin(std::process::Stdio::null())
                        .stdout(std::process::Stdio::null())
                        .stderr(std::process::Stdio::null())
                        .status()
                        .ok();
                }
            }
            Undo::Restore { from, to } => {
                if std::fs::symlink_metadata(to).is_err() {
                    std::fs::rename(from, to).ok();
                } else {
                    std::fs::remove_dir_all(from).ok();
                }
            }
        }
    }
}

struct Registry {
    next: u64,
    live: Vec<(u64, Undo)>,
    guardian: Guardian,
}

/// The guardian's state, as seen from rmapgen.
enum Guardian {
    /// Not asked for (a library user, a unit test): nothing outlives an uncatchable signal.
    Off,
    /// Asked for; started at the first registration.
    Wanted,
    /// Running: every registration and release is written here.
    Running(std::process::ChildStdin),
    /// Could not be started, or its pipe broke: the watcher still works.
    Failed,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    live: Vec::new(),
    guardian: Guardian::Off,
});

impl Registry {
    /// Tells the guardian one line (starting it if it is wanted and not yet running).
    fn tell(&mut self, line: &str) {
        if matches!(self.guardian, Guardian::Wanted) {
            self.guardian = start_guardian();
        }
        if let Guardian::Running(pipe) = &mut self.guardian {
            if pipe.write_all(line.as_bytes()).is_err() {
                self.guardian = Guardian::Failed;
            }
        }
    }
}

/// A registration; dropping it does not undo anything, [`Token::release`] forgets it.
#[derive(Debug)]
pub struct Token(u64);

/// The watcher held off: a writer changes registered paths while it holds this.
pub struct Held(MutexGuard<'static, Registry>);

/// Holds off the watcher until the result is dropped.
pub fn hold() -> Held {
    Held(REGISTRY.lock().unwrap_or_else(|e| e.into_inner()))
}

impl Held {
    /// Replaces what `token` undoes, as part of the change this hold covers.
    pub fn replace(&mut self, token: &Token, undo: Undo) {
        let line = encode(token.0, &undo);
        if let Some(e) = self.0.live.iter_mut().find(|(i, _)| *i == token.0) {
            e.1 = undo;
            self.0.tell(&line);
        }
    }
}

/// Registers `undo`, to be run if a signal ends the process before it is released.
pub fn register(undo: Undo) -> Token {
    hold().register(undo)
}

impl Held {
    /// Registers `undo` as part of the change this hold covers (a child started and
    /// registered with no interrupt in between).
    pub fn register(&mut self, undo: Undo) -> Token {
        self.0.next += 1;
        let id = self.0.next;
        let line = encode(id, &undo);
        self.0.live.push((id, undo));
        self.0.tell(&line);
        Token(id)
    }
}

impl Token {
    /// Forgets the registration: the path is finished or already cleaned up.
    pub fn release(self) {
        let mut h = hold();
        h.0.live.retain(|(i, _)| *i != self.0);
        h.0.tell(&format!("-{}\n", self.0));
    }
}

/// Starts the watcher (once per process). Commands call this through `main`; library users
/// who want the same behaviour call it themselves.
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    static ONCE: Once = Once::new();
    let mut result = Ok(());
    ONCE.call_once(|| {
        result = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]).map(|mut s| {
            std::thread::spawn(move || {
                if let Some(sig) = s.forever().next() {
                    // Keep the lock until the process ends: no writer starts anything new.
                    let mut h = hold();
                    for (_, undo) in h.0.live.drain(..).rev() {
                        undo.run();
                    }
                    // Done here: the guardian has nothing left to undo.
                    h.0.tell("clear\n");
                    signal_hook::low_level::emulate_default_handler(sig).ok();
                    std::process::exit(128 + sig);
                }
            });
        });
    });
    result
}

/// The argument that makes the `rmapgen` binary the guardian ([`guardian_main`]).
pub const GUARDIAN_ARG: &str = "--rmapgen-guardian";

/// Asks for the guardian: from the first registration on, a copy of this binary (run with
/// [`GUARDIAN_ARG`], which its `main` must hand to [`guardian_main`]) undoes what is still
/// registered when this process ends by a signal it cannot catch.
pub fn install_guardian() {
    let mut h = hold();
    if matches!(h.0.guardian, Guardian::Off) {
        h.0.guardian = Guardian::Wanted;
    }
}

/// Starts the guardian: this very binary (through `/proc/self/exe` if it was removed
/// meanwhile) in a process group of its own (a Ctrl-C to the terminal's group
/// leaves it to see the cleanup through), reading the registrations on its stdin. It is the
/// one child not started through `toolchain::child`: it must outlive rmapgen, and
/// it exits by itself when rmapgen's end closes the pipe.
fn start_guardian() -> Guardian {
    use std::os::unix::process::CommandExt;
    use std::process::{Command, Stdio};
    // The binary by name (as `ps` shows it), else through /proc when it was removed.
    let exe = std::env::current_exe()
        .ok()
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from("/proc/self/exe"));
    let started = Command::new(exe)
        .arg(GUARDIAN_ARG)
        .arg(std::process::id().to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .current_dir("/")
        .process_group(0)
        .spawn();
    match started.map(|mut c| c.stdin.take()) {
        Ok(Some(pipe)) => Guardian::Running(pipe),
        _ => Guardian::Failed,
    }
}

/// One registration as the guardian reads it: `+ID KIND HEX [HEX]`, paths absolute and in
/// hex (any byte may be in a path).
fn encode(id: u64, undo: &Undo) -> String {
    let bytes = |b: &[u8]| -> String { b.iter().map(|b| format!("{b:02x}")).collect() };
    let hex = |p: &Path| -> String {
        let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        bytes(abs.as_os_str().as_bytes())
    };
    match undo {
        Undo::Remove(p) => format!("+{id} R {}\n", hex(p)),
        Undo::RemoveIfEmpty(p) => format!("+{id} E {}\n", hex(p)),
        Undo::Restore { from, to } => format!("+{id} S {} {}\n", hex(from), hex(to)),
        Undo::KillGroup(g) => format!("+{id} K {g}\n"),
        Undo::Run(words) => {
            let hexes: Vec<String> = words.iter().map(|w| bytes(w.as_bytes())).collect();
            format!("+{id} X {}\n", hexes.join(" "))
        }
    }
}

/// The registration `line` holds ([`encode`]'s `+` lines), or None when it is not one.
fn decode(line: &str) -> Option<(u64, Undo)> {
    let mut w = line.strip_prefix('+')?.split(' ');
    let id = w.next()?.parse().ok()?;
    let kind = w.next()?;
    let mut path = || -> Option<PathBuf> {
        let h = w.next()?.as_bytes();
        if h.len() % 2 != 0 || h.is_empty() {
            return None;
        }
        let bytes: Option<Vec<u8>> = h
            .chunks(2)
            .map(|c| u8::from_str_radix(std::str::from_utf8(c).ok()?, 16).ok())
            .collect();
        Some(PathBuf::from(std::ffi::OsString::from_vec(bytes?)))
    };
    let undo = match kind {
        "R" => Undo::Remove(path()?),
        "E" => Undo::RemoveIfEmpty(path()?),
        "S" => {
            let from = path()?;
            Undo::Restore { from, to: path()? }
        }
        "K" => Undo::KillGroup(w.next()?.parse().ok()?),
        "X" => {
            let mut words = Vec::new();
            while let Some(p) = path() {
                words.push(p.into_os_string().into_string().ok()?);
            }
            if words.is_empty() {
                return None;
            }
            Undo::Run(words)
        }
        _ => return None,
    };
    Some((id, undo))
}

/// The guardian (refused unless started by rmapgen, its parent's pid given after
/// [`GUARDIAN_ARG`]): reads registrations (`+`), releases (`-ID`) and `clear` from stdin until it
/// closes (rmapgen has ended), then undoes what is still registered, last first, and returns.
/// Process groups it kills are waited for (a bounded time), so a directory their tools were
/// writing into is removed after they stop.
pub fn guardian_main() {
    // Only as rmapgen started it: its parent's pid as the argument after GUARDIAN_ARG.
    let parent = std::env::args().nth(2).and_then(|p| p.parse::<i32>().ok());
    // SAFETY: getppid has no preconditions.
    let ours = parent == Some(unsafe { libc::getppid() })
        // rmapgen died before this line ran: its registrations still wait on the pipe.
        || parent.is_some_and(|p| !Path::new(&format!("/proc/{p}")).exists() && stdin_is_pipe());
    if !ours {
        eprintln!("rmapgen: error: {GUARDIAN_ARG} is started by rmapgen itself, not by hand");
        std::process::exit(2);
    }
    // SAFETY: setting a signal's disposition to ignore touches no memory of ours.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_IGN);
        libc::signal(libc::SIGHUP, libc::SIG_IGN);
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
    }
    let mut live: Vec<(u64, Undo)> = Vec::new();
    let mut input = std::io::stdin().lock();
    let mut line = Vec::new();
    loop {
        line.clear();
        match std::io::BufRead::read_until(&mut input, b'\n', &mut line) {
            Ok(0) | Err(_) => break,
            Ok(_) => {}
        }
        let text = String::from_utf8_lossy(&line);
        let text = text.trim_end();
        if text == "clear" {
            live.clear();
        } else if let Some(id) = text.strip_prefix('-').and_then(|i| i.parse::<u64>().ok()) {
            live.retain(|(i, _)| *i != id);
        } else if let Some((id, undo)) = decode(text) {
            match live.iter_mut().find(|(i, _)| *i == id) {
                Some(e) => e.1 = undo,
                None => live.push((id, undo)),
            }
        }
    }
    for (_, undo) in live.into_iter().rev() {
        undo.run();
        if let Undo::KillGroup(g) = undo {
            wait_group_gone(g);
        }
    }
}

fn stdin_is_pipe() -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata("/proc/self/fd/0").is_ok_and(|m| m.file_type().is_fifo())
}

/// Waits (at most [`SETTLE`]) until no process is left running in group `pgid`. Zombies do
/// not count: they write nothing, and their reaping (by init, once rmapgen is gone) can take
/// a while.
fn wait_group_gone(pgid: u32) {
    let start = Instant::now();
    while group_running(pgid) && start.elapsed() < SETTLE {
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Whether a process of group `pgid` that is not a zombie exists (if /proc cannot tell,
/// whether any process of the group exists).
fn group_running(pgid: u32) -> bool {
    // SAFETY: kill(2) with signal 0 only checks that the group exists.
    if unsafe { libc::kill(-(pgid as i32), 0) } != 0 {
        return false;
    }
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return true;
    };
    entries.flatten().any(|e| {
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            return false;
        };
        // pid (comm) state ppid pgrp ...; comm may hold spaces and parentheses.
        let Some(close) = stat.rfind(')') else {
            return false;
        };
        let mut w = stat[close + 1..].split_whitespace();
        let state = w.next();
        let pgrp = w.nth(1);
        state != Some("Z") && pgrp == Some(&*pgid.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scratch_directory_is_registered_while_it_lives_and_forgotten_with_it() {
        let registered = |p: &Path| {
            hold()
                .0
                .live
                .iter()
                .any(|(_, u)| matches!(u, Undo::Remove(q) if q == p))
        };
        let s = crate::output::Scratch::new().unwrap();
        let p = s.path().to_path_buf();
        assert!(p.is_dir() && registered(&p), "{}", p.display());
        drop(s);
        // Removed, and no registration left behind to grow the registry or undo a path that
        // another run may hold by then.
        assert!(!p.exists() && !registered(&p), "{}", p.display());
    }

    #[test]
    fn remove_takes_a_directory_whole_and_leaves_a_file_or_link_at_its_path() {
        let t = tempfile::tempdir().unwrap();
        let staging = t.path().join(".d.staging-1");
        std::fs::create_dir_all(staging.join("sub")).unwrap();
        std::fs::write(staging.join("sub/f"), b"x").unwrap();
        let file = t.path().join(".f.staging-2");
        std::fs::write(&file, b"mine").unwrap();
        let kept = t.path().join("kept");
        std::fs::create_dir(&kept).unwrap();
        std::fs::write(kept.join("f"), b"mine").unwrap();
        let link = t.path().join(".l.staging-3");
        std::os::unix::fs::symlink(&kept, &link).unwrap();
        let start = Instant::now();
        for p in [&staging, &file, &link] {
            Undo::Remove(p.clone()).run_now();
        }
        assert!(std::fs::symlink_metadata(&staging).is_err());
        assert_eq!(std::fs::read(&file).unwrap(), b"mine");
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert_eq!(std::fs::read(kept.join("f")).unwrap(), b"mine");
        // Left at once, not retried until the settling time is over.
        assert!(start.elapsed() < SETTLE, "{:?}", start.elapsed());
    }

    /// A replacement changes what its own registration undoes, and no other: a commit that
    /// moves an old output aside then removes it leaves an interrupt the old output to
    /// remove, not the staging directory that has become the output.
    #[test]
    fn a_replacement_changes_its_own_registration_alone() {
        let undoes = |t: &Token| {
            let h = hold();
            let e = h.0.live.iter().find(|(i, _)| *i == t.0);
            e.map(|(_, u)| format!("{u:?}"))
        };
        let a = register(Undo::Remove(PathBuf::from("/nonexistent/rmapgen-a")));
        let b = register(Undo::Remove(PathBuf::from("/nonexistent/rmapgen-b")));
        let old = PathBuf::from("/nonexistent/rmapgen-b.old");
        hold().replace(&b, Undo::Remove(old.clone()));
        assert_eq!(undoes(&b), Some(format!("{:?}", Undo::Remove(old))));
        assert_eq!(
            undoes(&a),
            Some(format!(
                "{:?}",
                Undo::Remove(PathBuf::from("/nonexistent/rmapgen-a"))
            ))
        );
        a.release();
        b.release();
    }

    /// A directory that cannot be removed (here one of /proc, where nothing can be) is tried
    /// again for [`SETTLE`] and then left: the cleanup of an interrupt ends.
    #[test]
    fn a_directory_that_cannot_be_removed_is_given_up_after_the_settling_time() {
        let p = PathBuf::from("/proc/self/fdinfo");
        let (tx, rx) = std::sync::mpsc::channel();
        let start = Instant::now();
        let q = p.clone();
        std::thread::spawn(move || {
            Undo::Remove(q).run_now();
            tx.send(()).ok();
        });
        rx.recv_timeout(SETTLE * 3)
            .expect("the removal gave up within the settling time");
        assert!(
            start.elapsed() >= SETTLE && p.is_dir(),
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn registrations_reach_the_guardian_as_they_were() {
        let odd = PathBuf::from("/tmp/a b\nc/\u{e9}");
        for undo in [
            Undo::Remove(odd.clone()),
            Undo::RemoveIfEmpty(PathBuf::from("/x")),
            Undo::Restore {
                from: PathBuf::from("/a/.o.old"),
                to: odd.clone(),
            },
            Undo::KillGroup(4242),
            Undo::Run(vec!["scancel".into(), "12".into(), "a b\nc".into()]),
        ] {
            let line = encode(7, &undo);
            let (id, back) = decode(line.trim_end()).expect("decodes");
            assert_eq!(id, 7);
            assert_eq!(format!("{back:?}"), format!("{undo:?}"));
        }
        assert!(decode("+1 R 6").is_none());
        assert!(decode("+1 Q 00").is_none());
        assert!(decode("+1 X").is_none());
        assert!(decode("+1 X 7").is_none());
    }

    /// A child in a process group of its own, as every tool rmapgen starts is.
    fn in_own_group(args: &[&str]) -> std::process::Child {
        use std::os::unix::process::CommandExt;
        std::process::Command::new(args[0])
            .args(&args[1..])
            .stdout(std::process::Stdio::piped())
            .process_group(0)
            .spawn()
            .unwrap()
    }

    /// What the guardian waits on after it kills a tool's group: a group whose leader is
    /// gone but whose member still runs is running (the group, not the leader's pid, is
    /// asked, and the member is found by its group in /proc); a group left with a zombie
    /// alone is not.
    #[test]
    fn a_group_runs_while_a_member_does_and_not_as_a_zombie() {
        use std::io::BufRead;
        // The leader starts a member and exits; once the leader is reaped its pid is free,
        // and only the member holds the group.
        let mut leader = in_own_group(&["sh", "-c", "sleep 30 & echo $!"]);
        let pgid = leader.id();
        let mut line = String::new();
        std::io::BufReader::new(leader.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let member: i32 = line.trim().parse().unwrap();
        leader.wait().unwrap();
        let running = group_running(pgid);
        // SAFETY: kill(2) on the member this test started.
        unsafe { libc::kill(member, libc::SIGKILL) };
        assert!(
            running,
            "a group whose member runs ({member}) was seen as gone"
        );

        let mut z = in_own_group(&["sleep", "30"]);
        let pgid = z.id();
        assert!(group_running(pgid), "a running leader was seen as gone");
        z.kill().unwrap();
        // Wait for its end without reaping it (WNOWAIT): a zombie, which the kernel still
        // counts in the group.
        // SAFETY: waitid(2) on the child this test started; `info` is written by the call.
        let mut info: libc::siginfo_t = unsafe { std::mem::zeroed() };
        let r =
            unsafe { libc::waitid(libc::P_PID, pgid, &mut info, libc::WEXITED | libc::WNOWAIT) };
        assert_eq!(r, 0, "waitid");
        // SAFETY: kill(2) with signal 0 only checks that the group exists.
        assert_eq!(
            unsafe { libc::kill(-(pgid as i32), 0) },
            0,
            "the zombie's group"
        );
        assert!(
            !group_running(pgid),
            "a group of one zombie was seen as running"
        );
        z.wait().unwrap();
        assert!(!group_running(pgid), "a reaped group was seen as running");
    }

    /// The guardian's wait ends when the group's last process does (here a half-second
    /// sleep): not before, and not at the end of the settling time either.
    #[test]
    fn the_wait_for_a_group_lasts_until_it_is_gone() {
        let mut c = in_own_group(&["sleep", "0.5"]);
        let start = Instant::now();
        wait_group_gone(c.id());
        let gone = !group_running(c.id());
        let waited = start.elapsed();
        c.wait().unwrap();
        assert!(gone, "returned after {waited:?} with the group running");
        assert!(
            waited < SETTLE,
            "waited the whole settling time, {waited:?}"
        );
    }
}
