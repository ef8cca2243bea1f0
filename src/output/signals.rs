//! Clean interrupts: every staging directory, partial file and scratch directory rmapgen is
//! writing is registered here while it exists. On SIGINT, SIGTERM or SIGHUP a watcher thread
//! removes them all, puts back a previous output that was being replaced, and ends the
//! process by the signal's default action (so a shell sees 130 for Ctrl-C, 143 for SIGTERM).
//!
//! Writers that change the registered paths hold [`hold`] while they do, so the watcher never
//! removes a directory half-way through a file being created in it, and never sees a target
//! between the two renames that replace it.

use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, Once};

extern "C" {
    fn kill(pid: i32, sig: i32) -> i32;
}
const SIGKILL: i32 = 9;

/// What to undo for one registered path.
#[derive(Debug, Clone)]
pub enum Undo {
    /// A staging directory, partial file or scratch directory: remove it whole.
    Remove(PathBuf),
    /// A directory rmapgen created as the parent of its output: remove it if it is empty.
    RemoveIfEmpty(PathBuf),
    /// A previous output moved aside while the new one takes its place: move it back to
    /// `to` if nothing is there yet, else remove it.
    Restore { from: PathBuf, to: PathBuf },
    /// A child process started in a process group of its own (its id the group's): kill
    /// the group, so no tool it started outlives rmapgen.
    KillGroup(u32),
}

impl Undo {
    /// Does it now (a child past its time limit is killed the way an interrupt kills it).
    pub fn run_now(&self) {
        self.run()
    }

    fn run(&self) {
        match self {
            Undo::Remove(p) => {
                let removed = match std::fs::symlink_metadata(p) {
                    Ok(m) if m.is_dir() => std::fs::remove_dir_all(p),
                    Ok(_) => std::fs::remove_file(p),
                    Err(_) => Ok(()),
                };
                removed.ok();
            }
            Undo::RemoveIfEmpty(p) => {
                std::fs::remove_dir(p).ok();
            }
            Undo::KillGroup(pgid) => {
                // SAFETY: kill(2) with a negative pid signals the process group; no memory
                // is touched.
                unsafe {
                    kill(-(*pgid as i32), SIGKILL);
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
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    live: Vec::new(),
});

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
        if let Some(e) = self.0.live.iter_mut().find(|(i, _)| *i == token.0) {
            e.1 = undo;
        }
    }
}

/// Registers `undo`, to be run if a signal ends the process before it is released.
pub fn register(undo: Undo) -> Token {
    let mut h = hold();
    h.0.next += 1;
    let id = h.0.next;
    h.0.live.push((id, undo));
    Token(id)
}

impl Token {
    /// Forgets the registration: the path is finished or already cleaned up.
    pub fn release(self) {
        hold().0.live.retain(|(i, _)| *i != self.0);
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
                    signal_hook::low_level::emulate_default_handler(sig).ok();
                    std::process::exit(128 + sig);
                }
            });
        });
    });
    result
}
