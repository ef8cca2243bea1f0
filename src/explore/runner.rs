//! Renders off the threads that serve requests, one at a time, each within a time and a
//! memory budget, and cancellable.
//!
//! A render runs on a [`crate::cancel::Pool`] of its own (its parallel loops too), while the
//! connection thread that asked for it waits for the answer; every other connection is
//! served meanwhile. A second render asked for while one runs is answered at once
//! ([`Stopped::Busy`]): the page never asks for two, and a script can try again. A watcher
//! thread looks at the render every [`TICK`]: past its time ([`Limits::seconds`]) or with the
//! process grown by more than its memory ([`Limits::memory`], the resident set from
//! `/proc/self/statm` against its size when the render began), it sets the pool's flag and
//! the render unwinds at its next cancel point. `/api/cancel` sets the same flag.

use crate::cancel::{Cancelled, Pool};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How often the watcher looks at a running render.
pub const TICK: Duration = Duration::from_millis(20);

/// A render's budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Wall-clock time from its start.
    pub seconds: Duration,
    /// Growth of the process's resident memory over its start, in bytes.
    pub memory: u64,
}

/// Why a render gave no result.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Stopped {
    /// Another render was running (its id and how long it had run).
    Busy { id: u64, ran: Duration },
    /// Cancelled past its time.
    Time(Duration),
    /// Cancelled past its memory (the growth seen, bytes).
    Memory(u64),
    /// Cancelled by a request (`/api/cancel`).
    Asked,
}

impl Stopped {
    /// One line for the page.
    pub fn message(&self, limits: &Limits) -> String {
        match self {
            Stopped::Busy { id, ran } => format!(
                "busy: render {id} has run for {:.1} s; the explorer renders one at a time (POST /api/cancel stops it)",
                ran.as_secs_f64()
            ),
            Stopped::Time(t) => format!(
                "cancelled: the render ran past its budget of {} s ({:.1} s)",
                limits.seconds.as_secs(),
                t.as_secs_f64()
            ),
            Stopped::Memory(m) => format!(
                "cancelled: the render grew the explorer by {} MiB, past its budget of {} MiB",
                m >> 20,
                limits.memory >> 20
            ),
            Stopped::Asked => "cancelled: stopped by a request to /api/cancel".into(),
        }
    }
}

/// The running render, if any, and why it is being stopped.
#[derive(Default)]
struct Running {
    job: Option<(u64, Instant)>,
    why: Option<Stopped>,
}

/// One render at a time, on its own pool, under [`Limits`].
pub struct Runner {
    pool: Pool,
    limits: Limits,
    state: Mutex<Running>,
}

impl Runner {
    /// A runner with `threads` workers (0: one per core).
    pub fn new(threads: usize, limits: Limits) -> std::io::Result<Runner> {
        Ok(Runner {
            pool: Pool::new(threads)?,
            limits,
            state: Mutex::new(Running::default()),
        })
    }

    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    fn state(&self) -> std::sync::MutexGuard<'_, Running> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs `f` as render `id` (a number for the messages): its value, or why it gave none.
    pub fn run<R: Send>(&self, id: u64, f: impl FnOnce() -> R + Send) -> Result<R, Stopped> {
        let start = Instant::now();
        {
            let mut s = self.state();
            if let Some((id, began)) = s.job {
                return Err(Stopped::Busy {
                    id,
                    ran: began.elapsed(),
                });
            }
            // The flag of an earlier render's late cancel is cleared under the same lock
            // that a cancel takes: a cancel for this render is never lost.
            self.pool.reset();
            *s = Running {
                job: Some((id, start)),
                why: None,
            };
        }
        let base = resident();
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        let r = std::thread::scope(|scope| {
            scope.spawn(move || {
                // Until the render ends (the sender dropped), every TICK.
                while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
                    done_rx.recv_timeout(TICK)
                {
                    let ran = start.elapsed();
                    let grown = resident()
                        .zip(base)
                        .map_or(0, |(now, b)| now.saturating_sub(b));
                    let why = if ran > self.limits.seconds {
                        Stopped::Time(ran)
                    } else if grown > self.limits.memory {
                        Stopped::Memory(grown)
                    } else {
                        continue;
                    };
                    self.stop(why);
                }
            });
            let r = self.pool.run(f);
            drop(done_tx);
            r
        });
        let mut s = self.state();
        let why = s.why.take();
        s.job = None;
        match r {
            Ok(v) => Ok(v),
            Err(Cancelled) => Err(why.unwrap_or(Stopped::Asked)),
        }
    }

    /// Stops the running render (if any) for `why`; the first reason given stays.
    fn stop(&self, why: Stopped) -> bool {
        let mut s = self.state();
        if s.job.is_none() {
            return false;
        }
        s.why.get_or_insert(why);
        self.pool.cancel();
        true
    }

    /// Cancels the running render (`/api/cancel`): its id, or None when none runs.
    pub fn cancel(&self) -> Option<u64> {
        let id = self.state().job.map(|j| j.0);
        (id.is_some() && self.stop(Stopped::Asked)).then_some(id?)
    }

    /// The running render's id.
    pub fn running(&self) -> Option<u64> {
        self.state().job.map(|j| j.0)
    }

    /// Whether the pool's flag is set (for the tests: a render is being stopped).
    #[cfg(test)]
    fn stopping(&self) -> bool {
        self.pool.flag().load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// The process's resident memory in bytes (Linux: `/proc/self/statm`); None elsewhere.
pub fn resident() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // SAFETY: sysconf has no preconditions.
    let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    Some(pages * u64::try_from(page).ok()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cancel::point;
    use std::sync::Arc;

    const ROOMY: Limits = Limits {
        seconds: Duration::from_secs(600),
        memory: 1 << 40,
    };

    /// Work that polls and would run for ten minutes.
    fn endless() -> u64 {
        let t = Instant::now();
        while t.elapsed() < Duration::from_secs(600) {
            point();
            std::thread::sleep(Duration::from_millis(1));
        }
        0
    }

    #[test]
    fn a_render_past_its_time_is_cancelled() {
        let r = Runner::new(
            1,
            Limits {
                seconds: Duration::from_millis(300),
                ..ROOMY
            },
        )
        .unwrap();
        let t = Instant::now();
        match r.run(1, endless) {
            Err(Stopped::Time(ran)) => assert!(ran > Duration::from_millis(300), "{ran:?}"),
            other => panic!("{other:?}"),
        }
        assert!(t.elapsed() < Duration::from_secs(60), "{:?}", t.elapsed());
        // The next one runs whole.
        assert_eq!(r.run(2, || 5), Ok(5));
        assert!(r.running().is_none());
    }

    #[test]
    fn a_render_past_its_memory_is_cancelled() {
        let r = Runner::new(
            1,
            Limits {
                memory: 64 << 20,
                ..ROOMY
            },
        )
        .unwrap();
        let got = r.run(1, || {
            // 16 MiB at a time, each touched (resident), up to 4 GiB.
            let mut held: Vec<Vec<u8>> = Vec::new();
            for _ in 0..256 {
                held.push(vec![1u8; 16 << 20]);
                std::thread::sleep(Duration::from_millis(5));
                point();
            }
            held.len()
        });
        match got {
            Err(Stopped::Memory(m)) => assert!(m > 64 << 20, "{m}"),
            other => panic!("{other:?}"),
        }
        assert!(r.stopping());
    }

    #[test]
    fn one_render_at_a_time_and_a_cancel_stops_the_running_one() {
        let r = Arc::new(Runner::new(1, ROOMY).unwrap());
        assert_eq!(r.cancel(), None, "nothing to cancel");
        let r2 = r.clone();
        let h = std::thread::spawn(move || r2.run(7, endless));
        while r.running().is_none() {
            std::thread::sleep(Duration::from_millis(5));
        }
        match r.run(8, || 1) {
            Err(Stopped::Busy { id: 7, .. }) => {}
            other => panic!("{other:?}"),
        }
        assert_eq!(r.cancel(), Some(7));
        assert_eq!(h.join().unwrap(), Err(Stopped::Asked));
        // A cancel with nothing running does not stop the next render.
        assert_eq!(r.cancel(), None);
        assert_eq!(r.run(9, || 3), Ok(3));
        let m = Stopped::Busy {
            id: 7,
            ran: Duration::from_millis(1500),
        }
        .message(&ROOMY);
        assert!(m.starts_with("busy: render 7 has run for 1.5 s"), "{m}");
    }
}
