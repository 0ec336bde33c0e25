//! Standard output for what commands print. A reader that leaves early
//! (`varspec … | head -1`) is not an error: later lines are dropped and the
//! command runs on, so the files it was asked for are still written. Any
//! other failure (a full disk) is kept, later lines are dropped, and the
//! command fails with it at the end, so its files do not appear
//! (`std::println!` would panic in both cases, stopping the command midway).

use std::fmt;
use std::io::{self, Write};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// What has happened to standard output so far.
enum State {
    Open,
    /// The reader left: nothing more is written, and that is fine.
    Closed,
    /// A write failed otherwise: nothing more is written, and the command
    /// fails.
    Failed(io::Error),
}

static STATE: Mutex<State> = Mutex::new(State::Open);

/// Lines that announce written files ("wrote …"), held back until the
/// command's outputs have been made visible (`io::all_or_nothing`): an
/// output whose final write fails (`-o /dev/full`) must not be announced.
static ANNOUNCEMENTS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Set when an output file is standard output (`-o /dev/stdout`): the
/// command's lines then go to standard error, so the file's bytes reach
/// the reader alone.
static CARRIES_DATA: AtomicBool = AtomicBool::new(false);

/// Standard output carries an output file: lines go to standard error.
pub fn carries_data() {
    CARRIES_DATA.store(true, Ordering::Relaxed);
}

/// Writes `args` and a newline to standard output, or to standard error
/// when standard output carries a file (see the module docs).
pub fn line(args: fmt::Arguments) {
    if CARRIES_DATA.load(Ordering::Relaxed) {
        let _ = writeln!(io::stderr().lock(), "{args}");
        return;
    }
    write(|out| out.write_fmt(args).and_then(|()| out.write_all(b"\n")));
}

/// Writes `bytes` as they are (see [`line`]).
pub fn bytes(bytes: &[u8]) {
    write(|out| out.write_all(bytes));
}

/// Runs `put` on standard output while it is open, and records how a
/// failed write leaves it.
fn write(put: impl FnOnce(&mut io::StdoutLock) -> io::Result<()>) {
    let mut state = STATE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if !matches!(*state, State::Open) {
        return;
    }
    if let Err(e) = put(&mut io::stdout().lock()) {
        *state = if e.kind() == io::ErrorKind::BrokenPipe {
            State::Closed
        } else {
            State::Failed(e)
        };
    }
}

/// Holds `args` as a line to print once the command's outputs are
/// visible (see [`ANNOUNCEMENTS`]).
pub fn announce(args: fmt::Arguments) {
    ANNOUNCEMENTS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .push(args.to_string());
}

/// Prints the held announcements, in the order they were made: call it
/// after the outputs have been made visible.
pub fn release_announcements() {
    let held = std::mem::take(
        &mut *ANNOUNCEMENTS
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner),
    );
    for text in held {
        line(format_args!("{text}"));
    }
}

/// Flushes standard output and returns the failure a write met, if any
/// (a closed reader is none); the failure is returned once.
pub fn finish() -> Option<io::Error> {
    let mut state = STATE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if matches!(*state, State::Open)
        && let Err(e) = io::stdout().lock().flush()
        && e.kind() != io::ErrorKind::BrokenPipe
    {
        return Some(e);
    }
    match std::mem::replace(&mut *state, State::Open) {
        State::Failed(e) => {
            *state = State::Closed;
            Some(e)
        }
        other => {
            *state = other;
            None
        }
    }
}

/// `println!` through [`line`].
macro_rules! outln {
    () => {
        $crate::cli::stdout::line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::cli::stdout::line(format_args!($($arg)*))
    };
}

/// [`announce`] with `format!` arguments: a line about written files,
/// printed once they are visible.
macro_rules! announce {
    ($($arg:tt)*) => {
        $crate::cli::stdout::announce(format_args!($($arg)*))
    };
}

/// "wrote A, B": the files a command wrote, in one line (nothing when
/// there are none), announced once they are visible.
pub fn wrote<P: AsRef<std::path::Path>>(paths: impl IntoIterator<Item = P>) {
    let names: Vec<String> = paths
        .into_iter()
        .map(|p| p.as_ref().display().to_string())
        .collect();
    if !names.is_empty() {
        announce(format_args!("wrote {}", names.join(", ")));
    }
}

/// `n` and the noun, plural unless n = 1: "1 set", "16 sets".
pub fn counted(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}
