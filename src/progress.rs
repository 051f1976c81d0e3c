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
    let done = DONE.load(Ordering::Relaxed).min(total);
    match (what, total) {
        ("", _) => String::new(),
        (what, 0) => what.to_string(),
        (what, total) => format!("{what} {done}/{total}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_is_described_with_its_count_capped_at_its_total() {
        stage("checking rules", 3);
        advance(2);
        assert_eq!(describe(), "checking rules 2/3");
        advance(5);
        assert_eq!(describe(), "checking rules 3/3");
        stage("trying fixes", 0);
        assert_eq!(describe(), "trying fixes");
    }
}
