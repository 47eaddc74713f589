//! Standard output as the commands' result, with its errors returned rather than panicked on.
//!
//! `println!` panics when stdout cannot be written ("failed printing to stdout: Broken pipe",
//! exit 101): `ugl learners | head -1`, `ugl plan ... | true`, `ugl learners > /dev/full`. Every
//! line a command prints goes through [`line`] instead, which writes to the locked stdout and
//! returns the error as a [`StdoutError`]; `main` ends quietly with exit 0 on a closed pipe (the
//! reader has what it wanted, as `ls | head` does) and with one line and exit 2 on any other
//! failure (a full disk).
//!
//! Restoring the default SIGPIPE action instead would kill the process on a closed stdout, but
//! also on a write to any other closed pipe: the external learners' stdin, whose failure the
//! protocol reports as an error naming the program; and it ends with a signal status, not 0.

use std::fmt;
use std::io::{self, Write};

/// Writing to standard output failed.
#[derive(Debug)]
pub(crate) struct StdoutError(pub io::Error);

impl fmt::Display for StdoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot write to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutError {}

impl StdoutError {
    /// The reader closed the pipe: nothing is wrong.
    pub(crate) fn is_closed_pipe(&self) -> bool {
        self.0.kind() == io::ErrorKind::BrokenPipe
    }
}

/// Print `args` and a newline, flushed (stdout is line-buffered), or the error.
pub(crate) fn line(args: fmt::Arguments<'_>) -> Result<(), StdoutError> {
    let mut out = io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .and_then(|()| out.flush())
        .map_err(StdoutError)
}

/// `println!` that returns the error: `outln!("{x}")?`.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::output::line(format_args!($($arg)*))
    };
}
pub(crate) use outln;
