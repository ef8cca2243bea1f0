//! What a long command is doing, on standard error, wherever that goes.
//!
//! - On a terminal: one line, redrawn in place (indicatif) and cleared when the command ends:
//!   the elapsed time and the current step (`00:00:12 placing and routing: nextpnr-ice40
//!   ...`) or count (`[=====>   ] 41% 6,881,280/16,777,216 inputs, eta 12s`).
//! - Anywhere else (a CI log, a pipe, a file): one plain line every [`DEFAULT_EVERY`]
//!   seconds, as build tools print in a CI log, so that a `fit` of 15 minutes or a `prove` of
//!   16 is not silent: `rmapgen prove: 00:01:10 6,881,280 of 16,777,216 inputs (41 %),
//!   98,304/s`. The first line comes after one period, so a short run prints nothing more
//!   than it did. [`ENV`] sets the period in seconds (`0`: no lines).
//!
//! Standard output keeps only what the command prints: these lines are standard error's.

use anyhow::{bail, Result};
use indicatif::{HumanCount, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc::{channel, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

/// The environment variable that sets the period of the plain lines, in whole seconds; `0`
/// turns them off.
pub const ENV: &str = "RMAPGEN_PROGRESS";
/// Seconds between two plain lines when [`ENV`] is not set.
pub const DEFAULT_EVERY: u64 = 10;
/// The longest period [`ENV`] may set: a day.
pub const MAX_EVERY: u64 = 86_400;

/// The period of the plain lines that [`ENV`] sets (None: no lines); a value that is not a
/// whole number of seconds in 0..=[`MAX_EVERY`] is refused, naming the variable. `main`
/// calls it before any command runs, so a bad value is bad input (exit 2) before any work.
pub fn every() -> Result<Option<Duration>> {
    let Some(v) = std::env::var_os(ENV) else {
        return Ok(Some(Duration::from_secs(DEFAULT_EVERY)));
    };
    let s = v.to_string_lossy();
    match s.trim().parse::<u64>() {
        Ok(0) => Ok(None),
        Ok(n) if n <= MAX_EVERY => Ok(Some(Duration::from_secs(n))),
        _ => bail!(
            "{ENV}={s:?} is not a number of seconds in 0..={MAX_EVERY} (the period of the progress lines on a standard error that is not a terminal; 0 turns them off)"
        ),
    }
}

/// What the line counts.
#[derive(Clone, Copy)]
enum Shape {
    /// Named steps (the message is the line).
    Steps,
    /// Items of a known total, in `unit`s.
    Total(&'static str),
    /// Items without a total, in `unit`s, with their rate.
    Count(&'static str),
    /// Tasks of a total set as the work goes, each with a message.
    Tasks,
}

/// A progress display of one command; cleared (on a terminal) and silenced when dropped.
pub struct Progress {
    bar: ProgressBar,
    ticker: Option<(Sender<()>, JoinHandle<()>)>,
}

impl Progress {
    /// A spinner of named steps ([`Progress::step`]).
    pub fn steps(cmd: &'static str) -> Progress {
        Progress::new(
            cmd,
            Shape::Steps,
            None,
            "{elapsed_precise} {spinner} {msg}",
            0,
        )
    }

    /// A bar of `len` items in `unit`s ([`Progress::inc`]).
    pub fn total(cmd: &'static str, len: u64, unit: &'static str) -> Progress {
        let t = format!(
            "{{elapsed_precise}} [{{bar:40}}] {{percent}}% {{human_pos}}/{{human_len}} {unit}, eta {{eta}} {{msg}}"
        );
        Progress::new(cmd, Shape::Total(unit), Some(len), &t, 0)
    }

    /// A count of items in `unit`s with no total, and their rate ([`Progress::inc`]).
    pub fn count(cmd: &'static str, unit: &'static str) -> Progress {
        let t = format!("{{elapsed_precise}} {{human_pos}} {unit} ({{per_sec}})");
        Progress::new(cmd, Shape::Count(unit), None, &t, 0)
    }

    /// A bar of tasks whose total is set as the work goes ([`Progress::task`]); on a
    /// terminal it appears only after `quiet` seconds, so a quick run does not flash.
    pub fn tasks(cmd: &'static str, quiet: u64) -> Progress {
        let t = "{elapsed_precise} [{bar:40}] {pos}/{len} {msg}";
        Progress::new(cmd, Shape::Tasks, Some(0), t, quiet)
    }

    fn new(
        cmd: &'static str,
        shape: Shape,
        len: Option<u64>,
        template: &str,
        quiet: u64,
    ) -> Progress {
        let bar = ProgressBar::with_draw_target(len, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(template)
                .expect("valid template")
                .progress_chars("=> "),
        );
        let terminal = std::io::stderr().is_terminal();
        // A bad value was refused in main; a library caller gets the default.
        let every = every().unwrap_or(Some(Duration::from_secs(DEFAULT_EVERY)));
        let show = |bar: &ProgressBar| {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            // The clock moves while one step takes long.
            bar.enable_steady_tick(Duration::from_millis(250));
        };
        let wait = match (terminal, every) {
            (true, _) if quiet == 0 => {
                show(&bar);
                return Progress { bar, ticker: None };
            }
            (true, _) => Duration::from_secs(quiet),
            (false, Some(d)) => d,
            (false, None) => return Progress { bar, ticker: None },
        };
        let (stop, stopped) = channel::<()>();
        let b = bar.clone();
        let ticker = std::thread::spawn(move || loop {
            match stopped.recv_timeout(wait) {
                Err(RecvTimeoutError::Timeout) if terminal => {
                    show(&b);
                    // Shown until the command ends.
                    let _ = stopped.recv();
                    return;
                }
                Err(RecvTimeoutError::Timeout) => {
                    crate::errln!("rmapgen {cmd}: {}", line(&b, shape));
                }
                _ => return,
            }
        });
        Progress {
            bar,
            ticker: Some((stop, ticker)),
        }
    }

    /// The step now under way.
    pub fn step(&self, what: &str) {
        self.bar.set_message(what.to_string());
    }

    /// `n` more items done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// `done` of `total` tasks finished, the current one `what`.
    pub fn task(&self, done: u64, total: u64, what: &str) {
        self.bar.set_length(total);
        self.bar.set_position(done);
        self.bar.set_message(what.to_string());
    }

    /// Runs `f` with the line cleared, for output to the same terminal (stdout).
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some((stop, ticker)) = self.ticker.take() {
            drop(stop);
            let _ = ticker.join();
        }
        self.bar.finish_and_clear();
    }
}

/// The plain line of a display: the elapsed time, then what it counts.
fn line(bar: &ProgressBar, shape: Shape) -> String {
    let t = bar.elapsed().as_secs();
    let clock = format!("{:02}:{:02}:{:02}", t / 3600, t / 60 % 60, t % 60);
    let (pos, msg) = (bar.position(), bar.message());
    let what = match shape {
        Shape::Steps if msg.is_empty() => "working".to_string(),
        Shape::Steps => msg,
        Shape::Total(unit) => {
            let len = bar.length().unwrap_or(0);
            let head = format!(
                "{} of {} {unit} ({} %)",
                HumanCount(pos),
                HumanCount(len),
                (pos * 100).checked_div(len).unwrap_or(0)
            );
            with(head, &msg)
        }
        Shape::Count(unit) => format!(
            "{} {unit} ({}/s)",
            HumanCount(pos),
            HumanCount(bar.per_sec() as u64)
        ),
        Shape::Tasks => {
            let len = bar.length().unwrap_or(0);
            with(format!("{pos} of {len}"), &msg)
        }
    };
    format!("{clock} {what}")
}

/// `head`, then the message after a colon when there is one.
fn with(head: String, msg: &str) -> String {
    if msg.is_empty() {
        head
    } else {
        format!("{head}: {msg}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_says_the_time_and_what_is_counted() {
        let b = ProgressBar::hidden();
        b.set_message("placing and routing");
        assert!(line(&b, Shape::Steps).ends_with(" placing and routing"));
        assert!(line(&b, Shape::Steps).starts_with("00:00:0"));
        let b = ProgressBar::with_draw_target(Some(16_777_216), ProgressDrawTarget::hidden());
        b.inc(6_881_280);
        assert!(
            line(&b, Shape::Total("inputs")).ends_with(" 6,881,280 of 16,777,216 inputs (41 %)")
        );
        let b = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden());
        assert!(line(&b, Shape::Total("inputs")).ends_with(" 0 of 0 inputs (0 %)"));
        b.set_message("sphere, lsq");
        assert!(line(&b, Shape::Total("steps")).ends_with(" 0 of 0 steps (0 %): sphere, lsq"));
        let b = ProgressBar::hidden();
        b.set_length(40);
        b.set_position(3);
        assert!(line(&b, Shape::Tasks).ends_with(" 3 of 40"));
        b.set_message("index_bits 4");
        assert!(line(&b, Shape::Tasks).ends_with(" 3 of 40: index_bits 4"));
        b.inc(1234);
        assert!(line(&b, Shape::Count("inputs")).contains(" 1,237 inputs ("));
    }
}
