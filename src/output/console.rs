//! Lines for the terminal (stdout for results, stderr for progress, warnings and errors)
//! written so that a closed reader never costs a run its files.
//!
//! Rust ignores SIGPIPE, so a write to a pipe whose reader has gone (`impact run ... | head
//! -1`) returns an error, and `println!` turns that error into a panic: exit 101 after the
//! steps, summary.json never written. These functions write the line to the locked handle
//! and drop any error: the console is a courtesy to the reader, the files in the output
//! folder are the record, and the exit code stays the run's own.

use std::fmt::Arguments;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// `impact run --verbose`: the iterations' residuals on stderr (`iteration`).
static VERBOSE: AtomicBool = AtomicBool::new(false);

/// Turns the per-iteration lines on or off (the CLI's `--verbose`; off by default).
pub fn set_verbose(on: bool) {
    VERBOSE.store(on, Ordering::Relaxed);
}

/// Whether the per-iteration lines are on.
pub fn verbose() -> bool {
    VERBOSE.load(Ordering::Relaxed)
}

/// A line of the iteration log on stderr, when `--verbose` turned it on.
pub fn iteration(line: Arguments) {
    if verbose() {
        err(line);
    }
}

/// `line` and a newline on stdout; a closed or failing stdout is ignored.
pub fn out(line: Arguments) {
    let mut handle = std::io::stdout().lock();
    let _ = handle
        .write_fmt(line)
        .and_then(|()| handle.write_all(b"\n"));
}

/// `text` on stdout as it is (no newline added); a closed or failing stdout is ignored.
pub fn out_text(text: &str) {
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

/// `line` and a newline on stderr; a closed or failing stderr is ignored.
pub fn err(line: Arguments) {
    let mut handle = std::io::stderr().lock();
    let _ = handle
        .write_fmt(line)
        .and_then(|()| handle.write_all(b"\n"));
}
