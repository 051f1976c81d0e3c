//! The file commands as the command line runs them, on one spine: find → load → plan →
//! (check | dry run | preview | write) → result → report → exit status. `main.rs` parses the
//! arguments into the requests here and maps the [`Status`] a command returns to the process's
//! exit status; everything between is here, callable from tests without a process.
//!
//! [`validate`] runs the rules over many files and streams their reports; [`migrate`] and
//! [`bake`] are two planners on the same spine: each file goes through
//! [`crate::output::run_each`] (destinations, name claims, progress), becomes one
//! [`crate::output::result::FileResult`] with one [`crate::output::Outcome`], and the run is
//! summed up by one [`crate::output::result::Totals`] in the words of
//! [`crate::output::summary`]. [`preview`] draws what migrate's plan writes. The engines
//! below (migrate's planner, bake, edit, asset) know nothing of commands or reports.

pub mod bake;
pub mod migrate;
pub mod preview;
pub mod validate;

use std::io::Write;

/// How a command ended; `main` makes it the process's exit status ([`Status::code`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// 0: done; nothing at or above `--fail-on`.
    Done,
    /// 1: a finding at or above `--fail-on`, a file that failed, or under `--check` a file that
    /// would change.
    Failed,
    /// 2: a usage or configuration error; nothing was written.
    Usage,
    /// 128 + the signal: stopped by SIGINT or SIGTERM (finished outputs complete, nothing left
    /// of the others).
    Stopped(i32),
}

impl Status {
    /// The process's exit status.
    pub fn code(self) -> u8 {
        match self {
            Status::Done => 0,
            Status::Failed => 1,
            Status::Usage => 2,
            Status::Stopped(signal) => (128 + signal).clamp(0, 255) as u8,
        }
    }

    /// [`Status::Failed`] when `failed`, else [`Status::Done`].
    pub fn failed_if(failed: bool) -> Status {
        if failed {
            Status::Failed
        } else {
            Status::Done
        }
    }
}

/// A request refused before anything was read or written: the message on standard error.
pub fn usage_error(message: impl std::fmt::Display) -> Status {
    note(format_args!("velvet: {message}"));
    Status::Usage
}

/// Standard output as every command writes it: each write goes to the process's standard
/// output and a failure is recorded (see [`finish`]), so that a report lost to a full disk or a
/// closed descriptor cannot end in exit status 0. A closed pipe (`velvet … | head`) is not a
/// failure: the reader chose to stop, as `cat` and other tools take it.
pub struct Stdout;

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let written = std::io::stdout().lock().write(buf);
        recorded(Stream::Output, written)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let flushed = std::io::stdout().lock().flush();
        recorded(Stream::Output, flushed)
    }
}

/// Writes to standard output; a failure other than a closed pipe fails the run (see [`Stdout`]).
pub fn emit(text: &[u8]) {
    let _ = Stdout.write_all(text);
}

/// Writes one line to standard error. `eprintln!` would panic when standard error cannot be
/// written (exit status 101); a failure here is recorded and fails the run instead.
/// The line is escaped as reports escape an asset's text (file names, messages quoting an
/// asset): a control character in a folder's name must not act on the terminal.
pub fn note(line: std::fmt::Arguments) {
    let line = line.to_string();
    let mut err = std::io::stderr().lock();
    let written = writeln!(err, "{}", crate::report::escape::terminal(&line));
    let _ = recorded(Stream::Error, written);
}

/// Records the result of a write to standard output made by other code (clap's help text).
pub fn stdout_written(result: std::io::Result<()>) {
    let _ = recorded(Stream::Output, result);
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stream {
    Output,
    Error,
}

/// The first failed write to standard output or standard error, other than a closed pipe.
static WRITE_FAILURE: std::sync::OnceLock<(Stream, String)> = std::sync::OnceLock::new();

fn recorded<T>(stream: Stream, result: std::io::Result<T>) -> std::io::Result<T> {
    if let Err(e) = &result {
        if e.kind() != std::io::ErrorKind::BrokenPipe && e.kind() != std::io::ErrorKind::Interrupted
        {
            let _ = WRITE_FAILURE.set((stream, e.to_string()));
        }
    }
    result
}

/// The status a command ends with once its output is flushed: a run whose standard output or
/// standard error could not be written is status 2 ("velvet: cannot write to standard output:
/// …" on standard error, when that can be written), whatever it found; a run stopped by a
/// signal keeps its 130 or 143.
pub fn finish(status: Status) -> Status {
    let _ = Stdout.flush();
    let _ = recorded(Stream::Error, std::io::stderr().lock().flush());
    match (WRITE_FAILURE.get(), status) {
        (_, Status::Stopped(_)) | (None, _) => status,
        (Some((stream, error)), _) => {
            if *stream == Stream::Output {
                let _ = writeln!(
                    std::io::stderr().lock(),
                    "velvet: cannot write to standard output: {error}"
                );
            }
            Status::Usage
        }
    }
}

/// When SIGINT or SIGTERM stopped a migrate or bake run: the one line saying what was finished
/// (`finished` says it of each file) and the status, 128 + the signal. Files that failed for
/// another reason are counted with those not finished: nothing of either was written.
fn stopped(finished: impl Iterator<Item = bool>) -> Option<Status> {
    let signal = crate::output::interrupt::requested()?;
    let (mut done, mut total) = (0usize, 0usize);
    for finished in finished {
        total += 1;
        done += usize::from(finished);
    }
    note(format_args!(
        "velvet: stopped by {}: {done} of {total} {} finished (their outputs are complete); \
         nothing was written for the other {}",
        crate::output::interrupt::name(signal),
        if total == 1 { "file" } else { "files" },
        total - done
    ));
    Some(Status::Stopped(signal))
}

/// The report format of `velvet migrate` and `velvet bake`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum ReportFormat {
    /// A line per file, then a summary.
    #[default]
    Text,
    /// One JSON document: every file with what was planned and done, and the summary.
    Json,
}

#[cfg(test)]
mod tests {
    use super::Status;

    #[test]
    fn each_status_is_its_documented_exit_code() {
        assert_eq!(
            [
                Status::Done,
                Status::Failed,
                Status::Usage,
                Status::Stopped(2),
                Status::Stopped(15)
            ]
            .map(Status::code),
            [0, 1, 2, 130, 143]
        );
        assert_eq!(Status::failed_if(true), Status::Failed);
        assert_eq!(Status::failed_if(false), Status::Done);
    }
}
