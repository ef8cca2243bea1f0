//! What commands print. `println!` panics when standard output cannot be written (a reader
//! that closed the pipe, `> /dev/full`), which is exit 101; every command prints through
//! [`out!`](crate::out) and [`outln!`](crate::outln) instead, which return the failure:
//!
//! - A closed pipe (`rmapgen compare a.png b.png | head -c 10`, `| true`) is [`StdoutClosed`]:
//!   the reader wants no more, so the command stops at that write and `main` ends quietly
//!   with exit 0, as `yes | head` ends for its reader (no message, no 141). Output staged but
//!   not committed is removed as on any failure; an output already in place stays.
//! - Any other failure (`No space left on device`) is one line naming standard output, exit 2.
//!
//! Messages to standard error ([`errln!`](crate::errln)) are best effort: a standard error
//! that cannot be written is ignored, so it can never turn a result into a panic.

use std::fmt;
use std::io::Write;

/// Standard output was closed by its reader (EPIPE): the command stops and exits 0, quietly.
#[derive(Debug)]
pub struct StdoutClosed;

impl fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("standard output was closed by its reader")
    }
}

impl std::error::Error for StdoutClosed {}

/// Whether an error (anywhere in its chain) is a closed standard output.
pub fn is_stdout_closed(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<StdoutClosed>())
}

/// Writes to standard output and flushes, so a failure is seen at this write, not lost at
/// exit. Use through [`out!`](crate::out) and [`outln!`](crate::outln).
pub fn write_out(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut o = std::io::stdout().lock();
    match o.write_fmt(args).and_then(|()| o.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("cannot write to standard output")),
    }
}

/// Writes to standard error, ignoring a failure. Use through [`errln!`](crate::errln).
pub fn write_err(args: fmt::Arguments<'_>) {
    let mut e = std::io::stderr().lock();
    let _ = e.write_fmt(args).and_then(|()| e.flush());
}

/// `print!` that returns `anyhow::Result<()>` instead of panicking (see [`console`](self)).
#[macro_export]
macro_rules! out {
    ($($t:tt)*) => {
        $crate::output::console::write_out(format_args!($($t)*))
    };
}

/// `println!` that returns `anyhow::Result<()>` instead of panicking (see [`console`](self)).
#[macro_export]
macro_rules! outln {
    () => {
        $crate::output::console::write_out(format_args!("\n"))
    };
    ($($t:tt)*) => {
        $crate::output::console::write_out(format_args!("{}\n", format_args!($($t)*)))
    };
}

/// `eprintln!` that never panics: a standard error that cannot be written is ignored.
#[macro_export]
macro_rules! errln {
    ($($t:tt)*) => {
        $crate::output::console::write_err(format_args!("{}\n", format_args!($($t)*)))
    };
}

/// `eprint!` that never panics.
#[macro_export]
macro_rules! err {
    ($($t:tt)*) => {
        $crate::output::console::write_err(format_args!($($t)*))
    };
}
