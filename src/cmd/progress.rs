//! What a long command is doing, on stderr, only on a terminal: a line with the elapsed time
//! and the current step (`00:00:12 placing and routing: nextpnr-ice40 --hx8k ...`), cleared
//! when the command ends. In a script (stderr not a terminal) indicatif draws nothing, so
//! output stays what the command prints.

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// A spinner of named steps.
pub struct Steps {
    bar: ProgressBar,
}

impl Steps {
    pub fn new() -> Steps {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{elapsed_precise} {spinner} {msg}")
                .expect("valid template"),
        );
        bar.enable_steady_tick(Duration::from_millis(250));
        Steps { bar }
    }

    /// The step now under way.
    pub fn step(&self, what: &str) {
        self.bar.set_message(what.to_string());
    }

    /// Runs `f` with the line cleared, for output to the same terminal (stdout).
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.bar.suspend(f)
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
