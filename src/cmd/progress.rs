//! What a long command is doing, on stderr, only on a terminal: a line with the elapsed time
//! and the current step (`00:00:12 placing and routing: nextpnr-ice40 --hx8k ...`), shown once
//! the command has run for a second and cleared when it ends. In a script (stderr not a
//! terminal) indicatif draws nothing, so output stays what the command prints.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// A spinner of named steps.
pub struct Steps {
    bar: ProgressBar,
    start: Instant,
}

/// How long a command runs before its progress line appears.
const DELAY: Duration = Duration::from_secs(1);

impl Steps {
    pub fn new() -> Steps {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{elapsed_precise} {spinner} {msg}")
                .expect("valid template"),
        );
        Steps {
            bar,
            start: Instant::now(),
        }
    }

    /// The step now under way; the line appears once the command has run for [`DELAY`].
    pub fn step(&self, what: &str) {
        self.bar.set_message(what.to_string());
        if self.bar.is_hidden() && self.start.elapsed() >= DELAY {
            self.show();
        }
    }

    fn show(&self) {
        self.bar.set_draw_target(ProgressDrawTarget::stderr());
        self.bar.enable_steady_tick(Duration::from_millis(250));
    }

    /// Shows the line (on a terminal) whether or not a second has passed: for a step known to
    /// take long, such as place and route.
    pub fn long_step(&self, what: &str) {
        self.bar.set_message(what.to_string());
        if self.bar.is_hidden() {
            self.show();
        }
    }
}

impl Default for Steps {
    fn default() -> Self {
        Steps::new()
    }
}

impl Drop for Steps {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
