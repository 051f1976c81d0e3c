//! Where the work on a file stands, for the one-file progress line on a terminal: the stage
//! (reading, checking, trying fixes, planning materials…) and, where the stage counts, how
//! much of it is done. Any layer reports to it; only the terminal's progress line reads it
//! (`output::show_one_file`). A run over many files shows files done instead and ignores it.
//!
//! The state is one process-wide value: velvet draws one progress line at a time, and a count
//! is an atomic add, cheap enough for a stage's every unit of work.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The stage's name and how many units it has (0: it does not count).
static STAGE: Mutex<(&str, usize)> = Mutex::new(("", 0));
static DONE: AtomicUsize = AtomicUsize::new(0);

/// A stage begins: `what` ("checking rules"), of `total` units (0 when it does not count).
pub fn stage(what: &'static str, total: usize) {
    *STAGE.lock().unwrap_or_else(|e| e.into_inner()) = (what, total);
    DONE.store(0, Ordering::Relaxed);
}

/// `n` more units of the stage are done.
pub fn advance(n: usize) {
    DONE.fetch_add(n, Ordering::Relaxed);
}

/// The stage as the progress line shows it: "checking rules 12/61", "trying fixes", or
/// nothing before the first stage.
pub fn describe() -> String {
    let (what, total) = *STAGE.lock().unwrap_or_else(|e| e.into_inner());
    text(what, total, DONE.load(Ordering::Relaxed))
}

/// A stage's words: its name, and its count of `total` when it counts (`done` capped there).
fn text(what: &str, total: usize, done: usize) -> String {
    match (what, total) {
        ("", _) => String::new(),
        (what, 0) => what.to_string(),
        (what, total) => format!("{what} {}/{total}", done.min(total)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The stage itself is one process-wide value that every test validating a document
    // changes: its words are tested apart from it.
    #[test]
    fn a_stage_is_described_with_its_count_capped_at_its_total() {
        assert_eq!(text("checking rules", 3, 2), "checking rules 2/3");
        assert_eq!(text("checking rules", 3, 7), "checking rules 3/3");
        assert_eq!(text("trying fixes", 0, 4), "trying fixes");
        assert_eq!(text("", 5, 1), "");
    }
}
