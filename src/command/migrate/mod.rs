//! `velvet migrate` as the command line runs it: migrate's planner over many files on the
//! shared spine ([`batch`]: one result and one summary per run), the run's report in text or
//! JSON ([`render`]), `--check`, and `--preview`, whose sheets are drawn from the same plans.

pub mod batch;
pub mod render;

pub use batch::{
    run, run_shard, FileOutcome, FileResult, MigrateDetail, Request, RunReport, Summary,
};

use super::{stopped, ReportFormat, Status};
use crate::asset::discover::{self, Shard};
use crate::output::summary::Detail;
use std::path::PathBuf;

/// How a run is shown and judged besides what it writes.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    pub format: ReportFormat,
    pub detail: Detail,
    /// `--check`: a file that would change fails the run (the request is a dry run).
    pub check: bool,
    /// `--preview DIR`: contact sheets of the inputs' materials, written there.
    pub preview: Option<PathBuf>,
}

/// Runs `velvet migrate`: the files of `shard`, the report on standard output, then the sheets.
pub fn command(request: &Request, shard: Option<Shard>, view: &View) -> Status {
    // Before anything is read or written: a signal from here on stops the run cleanly.
    crate::output::interrupt::install();
    // The sheets are planned from the inputs before they are migrated (--in-place overwrites
    // them), and drawn after.
    let previews = view.preview.as_ref().map(|_| {
        let inputs: Vec<PathBuf> = match shard {
            None => request.inputs.clone(),
            Some(shard) => discover::find(&request.inputs, Some(shard))
                .0
                .into_iter()
                .map(|f| f.path)
                .collect(),
        };
        crate::preview::plan(&inputs, &request.options)
    });
    // A list that names no asset (a change that touched none) is nothing to do, not an error.
    let report = if request.inputs.is_empty() {
        RunReport {
            dry_run: request.dry_run,
            files: Vec::new(),
            summary: Summary::default(),
        }
    } else {
        match run_shard(request, shard) {
            Ok(report) => report,
            Err(e) => return super::usage_error(e),
        }
    };
    if let Some(stopped) = stopped(report.files.iter().map(|f| !f.is_failed())) {
        return stopped;
    }
    super::emit(
        match view.format {
            ReportFormat::Text => render::text(&report, view.detail),
            ReportFormat::Json => render::json(&report),
        }
        .as_bytes(),
    );
    let mut preview_failed = false;
    if let (Some(dir), Some(previews)) = (&view.preview, &previews) {
        preview_failed = super::preview::report_failures(previews, "preview: ");
        // The sheets are drawn from the plans made before the inputs were migrated.
        match super::preview::write(previews, dir, None, true) {
            Some(Status::Stopped(signal)) => return Status::Stopped(signal),
            Some(_) => preview_failed = true,
            None => {}
        }
    }
    let failed =
        report.failed() || preview_failed || (view.check && report.summary.totals.would_change > 0);
    // The command line exits after this: a library's report (a plan for every material) is
    // left to the exit rather than freed value by value.
    std::mem::forget(report);
    Status::failed_if(failed)
}
