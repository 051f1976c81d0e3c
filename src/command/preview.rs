//! `velvet preview` as the command line runs it: the plan of every sheen or fuzz material of
//! the inputs (migrate's plan with its default options), the chosen sheets drawn and written
//! into a folder as they are drawn, worst first, with index pages, and a line per sheet.

use super::Status;
use crate::asset::{discover, LoadOptions};
use crate::report::escape::push_line;
use std::path::{Path, PathBuf};

/// One `velvet preview` invocation.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub inputs: Vec<PathBuf>,
    /// The folder the sheets and index pages are written into.
    pub output: PathBuf,
    /// `--worst N`: draw only the N sheets the plan ranks worst.
    pub worst: Option<usize>,
    pub load: LoadOptions,
    /// No line per sheet, no progress bar.
    pub quiet: bool,
}

/// Plans, draws and writes the sheets of `request.inputs`.
pub fn command(request: &Request) -> Status {
    if let Err(e) = discover::check_inputs(&request.inputs) {
        return super::usage_error(e);
    }
    // Before anything is written: a signal from here on stops the run between sheets.
    crate::output::interrupt::install();
    let plan = crate::preview::plan(
        &request.inputs,
        &crate::migrate::Options {
            load: request.load,
            ..crate::migrate::Options::default()
        },
    );
    // A stop during planning (the verdicts take a library seconds) writes nothing.
    if let Some(signal) = crate::output::interrupt::requested() {
        super::note(format_args!(
            "velvet: stopped by {} while planning: nothing written",
            crate::output::interrupt::name(signal)
        ));
        return Status::Stopped(signal);
    }
    let failed = report_failures(&plan, "");
    match write(&plan, &request.output, request.worst, request.quiet) {
        Some(status) => status,
        None => Status::failed_if(failed),
    }
}

/// From how many sheets a run says, before it draws, what it will cost.
pub const LARGE_RUN: usize = 1000;

/// What a run of `sheets` sheets will cost, said before it starts when it is large: the size
/// and time are estimates from the library's textured sheets (`preview --worst 1000` of the
/// 20,000-material library, 5 December 2026: 255 MB in 57 s on two cores, so about 0.3 MB and
/// 50 ms a sheet; an untextured sheet is about half of each), with `--worst` as the way to
/// draw fewer.
pub fn large_run_note(sheets: usize) -> Option<String> {
    (sheets >= LARGE_RUN).then(|| {
        let megabytes = sheets as f64 * 0.3;
        let minutes = sheets as f64 * 0.050 / 60.0;
        format!(
            "drawing {sheets} sheets, at most about {:.1} GB in about {:.0} minutes; --worst N \
             draws only the N the plan's verdict ranks worst",
            megabytes / 1000.0,
            minutes.max(1.0)
        )
    })
}

/// Prints the files that could not be previewed (each line after `prefix`); true if any.
pub(super) fn report_failures(plan: &crate::preview::Plan, prefix: &str) -> bool {
    for f in &plan.failures {
        super::note(format_args!(
            "velvet: {prefix}{}: {}",
            f.file.display(),
            f.message
        ));
    }
    !plan.failures.is_empty()
}

/// Draws and writes `plan`'s sheets into `output` and says what was written; `Some` status
/// when the run failed to write or was stopped.
pub(super) fn write(
    plan: &crate::preview::Plan,
    output: &Path,
    worst: Option<usize>,
    quiet: bool,
) -> Option<Status> {
    let chosen = worst.map_or(plan.sheets.len(), |n| n.min(plan.sheets.len()));
    if let Some(line) = large_run_note(chosen) {
        super::note(format_args!("velvet: {line}"));
    }
    let written = match crate::preview::write(plan, output, worst, !quiet) {
        Ok(written) => written,
        Err(e) => {
            super::note(format_args!("velvet: {e}"));
            return Some(Status::Failed);
        }
    };
    if written.stopped {
        let signal = crate::output::interrupt::requested().unwrap_or(2);
        super::note(format_args!(
            "velvet: stopped by {}: {} of {} sheets written (each complete), listed in index.json",
            crate::output::interrupt::name(signal),
            written.drawn.len(),
            worst.map_or(plan.sheets.len(), |n| n.min(plan.sheets.len()))
        ));
        return Some(Status::Stopped(signal));
    }
    if !quiet {
        // Material names and file names come from the assets: each line is escaped (see
        // report::escape), so that ESC or U+202E in a name does not act on the terminal.
        let mut out = String::new();
        for d in &written.drawn {
            push_line(
                &mut out,
                &format!(
                    "{}: {} ({})",
                    d.path.display(),
                    d.summary.title,
                    d.summary.verdict.label.text()
                ),
            );
        }
        if !written.removed.is_empty() {
            push_line(
                &mut out,
                &format!(
                    "{} sheet(s) of an earlier run that this one does not write removed",
                    written.removed.len()
                ),
            );
        }
        for f in &plan.without_layers {
            push_line(
                &mut out,
                &format!("{}: no material with a sheen or fuzz layer", f.display()),
            );
        }
        if let Some(index) = written.pages.first() {
            push_line(
                &mut out,
                &format!(
                    "{} material(s) on {} sheet(s), {} drawn; index: {}",
                    plan.entries.len(),
                    plan.sheets.len(),
                    written.drawn.len(),
                    index.display()
                ),
            );
        }
        super::emit(out.as_bytes());
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_of_thousands_of_sheets_says_what_it_costs_and_suggests_worst() {
        assert_eq!(large_run_note(LARGE_RUN - 1), None);
        assert_eq!(
            large_run_note(20_000).as_deref(),
            Some(
                "drawing 20000 sheets, at most about 6.0 GB in about 17 minutes; --worst N \
                 draws only the N the plan's verdict ranks worst"
            )
        );
    }
}
