//! Stopping a long computation from outside it: `rmapgen explore` cancels a render that
//! overruns its time or memory budget, or that its page cancels.
//!
//! The long loops (the map fits' quadrants, cutting-plane rounds and polish sweeps, the
//! renderers' rows, the volume's slices) call [`point`] between units of work. On a thread
//! that runs for a [`Pool`] whose flag is set, [`point`] unwinds with [`Cancelled`]; on any
//! other thread (every command, the Python package, the tests of the fits) it does nothing
//! but read a thread-local. [`Pool::run`] catches the unwinding and returns `Err(Cancelled)`,
//! so a cancelled computation leaves nothing behind but the memory it frees on the way out.
//!
//! The flag is per pool, not per process: the pool's own threads (rayon workers set up by its
//! start handler) and the thread that [`Pool::run`] runs on see it, and nothing else does, so
//! two explorers (or a test beside them) never stop each other's work.
//!
//! The unwinding is `std::panic::resume_unwind`, which runs no panic hook: a cancel prints
//! nothing. A real panic inside a cancelled computation is still a panic ([`Pool::run`]
//! resumes it).

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

thread_local! {
    static FLAG: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// What [`point`] unwinds with, and what [`Pool::run`] returns for a stopped computation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cancelled;

/// A place where a long computation may be stopped: unwinds with [`Cancelled`] when this
/// thread works for a [`Pool`] whose flag is set.
pub fn point() {
    let stop = FLAG.with(|f| {
        f.borrow()
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    });
    if stop {
        std::panic::resume_unwind(Box::new(Cancelled));
    }
}

/// Worker threads whose computations a flag stops: a rayon pool of its own (the parallel
/// loops of a computation [`Pool::run`] runs stay on it) and the flag its threads see.
pub struct Pool {
    pool: rayon::ThreadPool,
    flag: Arc<AtomicBool>,
}

impl Pool {
    /// A pool of `threads` workers (0: one per core, as rayon's global pool).
    pub fn new(threads: usize) -> std::io::Result<Pool> {
        let flag = Arc::new(AtomicBool::new(false));
        let f = flag.clone();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("rmapgen-cancellable-{i}"))
            .start_handler(move |_| FLAG.with(|slot| *slot.borrow_mut() = Some(f.clone())))
            .build()
            .map_err(std::io::Error::other)?;
        Ok(Pool { pool, flag })
    }

    /// Asks the computation running now (if any) to stop at its next [`point`]. Any thread
    /// may call it.
    pub fn cancel(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }

    /// The flag, for a watcher on another thread to set ([`Pool::cancel`]).
    pub fn flag(&self) -> Arc<AtomicBool> {
        self.flag.clone()
    }

    /// Clears the flag, for the next computation. The flag stays set until then: a cancel
    /// that arrives as a computation ends is not lost, and the caller, which serialises the
    /// computations, decides when the next one starts.
    pub fn reset(&self) {
        self.flag.store(false, Ordering::Relaxed);
    }

    /// Runs `f` on the pool (its parallel loops too): its value, or `Err(Cancelled)` when a
    /// [`point`] found the flag set.
    pub fn run<R: Send>(&self, f: impl FnOnce() -> R + Send) -> Result<R, Cancelled> {
        let r = self
            .pool
            .install(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
        match r {
            Ok(v) => Ok(v),
            Err(payload) if payload.is::<Cancelled>() => Err(Cancelled),
            Err(payload) => std::panic::resume_unwind(payload),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::time::{Duration, Instant};

    /// A parallel loop that polls and would run for a minute.
    fn long(counted: &std::sync::atomic::AtomicU64) -> u64 {
        (0..1_000_000u64)
            .into_par_iter()
            .map(|i| {
                point();
                counted.fetch_add(1, Ordering::Relaxed);
                std::thread::sleep(Duration::from_micros(100));
                i
            })
            .sum()
    }

    fn long_or_none() {
        point();
    }

    #[test]
    fn a_set_flag_stops_the_parallel_loops_of_its_pool_and_no_other() {
        let p = Arc::new(Pool::new(2).unwrap());
        let counted = Arc::new(std::sync::atomic::AtomicU64::new(0));
        let (p2, c2) = (p.clone(), counted.clone());
        let t = Instant::now();
        let h = std::thread::spawn(move || p2.run(|| long(&c2)));
        std::thread::sleep(Duration::from_millis(200));
        p.cancel();
        assert_eq!(h.join().unwrap(), Err(Cancelled));
        let done = counted.load(Ordering::Relaxed);
        assert!(done > 0 && done < 1_000_000, "{done} iterations");
        assert!(t.elapsed() < Duration::from_secs(30), "{:?}", t.elapsed());
        // The flag stays until it is reset; then the next computation runs whole.
        assert_eq!(p.run(long_or_none), Err(Cancelled));
        p.reset();
        assert_eq!(
            p.run(|| (0..1000u64).into_par_iter().sum::<u64>()),
            Ok(499_500)
        );
        // Outside a pool (the global rayon pool, this thread) a point does nothing.
        p.cancel();
        point();
        assert_eq!(
            (0..1000u64)
                .into_par_iter()
                .map(|i| {
                    point();
                    i
                })
                .sum::<u64>(),
            499_500
        );
    }

    #[test]
    fn a_real_panic_is_not_a_cancel() {
        let p = Pool::new(1).unwrap();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            p.run(|| std::panic::resume_unwind(Box::new("boom")))
        }));
        let payload = r.expect_err("the panic goes on");
        assert_eq!(payload.downcast_ref::<&str>(), Some(&"boom"));
        assert_eq!(p.run(|| 7), Ok(7));
    }
}
