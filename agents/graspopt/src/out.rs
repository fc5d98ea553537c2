//! The commands' standard output. Everything a command prints goes through [`outln!`] (or
//! [`stdout`] for bulk writes), which returns an error instead of panicking when stdout
//! cannot be written. When its reader went away (`graspopt trial ... | head -1`) the error
//! is [`ReaderGone`], and `main` ends the command quietly with status 0.

use std::fmt;
use std::io::{self, Write};

/// Prints a line to stdout; evaluates to an `io::Result<()>` (see the module's notes).
macro_rules! outln {
    () => {
        $crate::out::print(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::out::print(format_args!("{}\n", format_args!($($arg)*)))
    };
}
pub(crate) use outln;

/// Stdout was closed by its reader (a pipe whose other end went away).
#[derive(Debug)]
pub struct ReaderGone;

impl fmt::Display for ReaderGone {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the reader of stdout went away")
    }
}

impl std::error::Error for ReaderGone {}

/// Stdout (locked), whose errors are [`ReaderGone`] for a closed pipe and name stdout
/// otherwise.
pub struct Stdout(io::StdoutLock<'static>);

/// Stdout for bulk writes (see [`Stdout`]); flush it before it is dropped.
pub fn stdout() -> Stdout {
    Stdout(io::stdout().lock())
}

fn named(e: io::Error) -> io::Error {
    if e.kind() == io::ErrorKind::BrokenPipe {
        io::Error::new(io::ErrorKind::BrokenPipe, ReaderGone)
    } else {
        io::Error::new(e.kind(), format!("cannot write to stdout: {e}"))
    }
}

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf).map_err(named)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush().map_err(named)
    }
}

/// Writes `args` to stdout and flushes it (what [`outln!`] calls).
pub fn print(args: fmt::Arguments<'_>) -> io::Result<()> {
    let mut out = stdout();
    out.write_fmt(args)?;
    out.flush()
}

/// Whether `err` comes from writing to a stdout whose reader went away.
pub fn reader_gone(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.is::<ReaderGone>()
            || e.downcast_ref::<io::Error>()
                .and_then(io::Error::get_ref)
                .is_some_and(|inner| inner.is::<ReaderGone>())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_closed_pipe_on_stdout_counts_as_the_reader_gone() {
        let gone = named(io::Error::from(io::ErrorKind::BrokenPipe));
        assert!(reader_gone(&anyhow::Error::from(gone)));
        let gone = named(io::Error::from(io::ErrorKind::BrokenPipe));
        assert!(reader_gone(
            &anyhow::Error::from(gone).context("printing the summary")
        ));
        // A closed socket elsewhere is a real error, and so is a full disk on stdout.
        assert!(!reader_gone(&anyhow::Error::from(io::Error::from(
            io::ErrorKind::BrokenPipe
        ))));
        let full = named(io::Error::from(io::ErrorKind::StorageFull));
        assert!(!reader_gone(&anyhow::Error::from(full)));
    }
}
