//! `velvet migrate` as the command line runs it: migrate's planner over many files on the
//! shared spine ([`batch`]: one result and one summary per run), the run's report in text or
//! JSON ([`render`]), `--check`, and `--preview`, whose sheets are drawn from the same plans.

pub mod batch;
pub mod render;

pub use batch::{
    run, run_shard, run_shard_with_sheets, FileOutcome, FileResult, MigrateDetail, Request,
    RunReport, Summary,
};

use super::{stopped, ReportFormat, Status};
use crate::asset::discover::Shard;
use crate::output::summary::Detail;
use std::path::PathBuf;

/// How a run is shown and judged besides what it writes.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    pub format: ReportFormat,
    pub detail: Detail,
    /// `--check`: a file that would change fails the run (the request is a dry run).
    pub check: bool,
    /// `--fail-on-visible` (with `--check`; also `fail-on-visible = true` in the velvet.toml
    /// found for a file): the check judges appearance instead of change, and fails on a
    /// material the plan's verdict calls "visible" (see [`visible_failures`]).
    pub fail_on_visible: bool,
    /// `--preview DIR`: contact sheets of the inputs' materials, written there.
    pub preview: Option<PathBuf>,
}

/// Runs `velvet migrate`: the files of `shard`, the report on standard output, then the sheets.
pub fn command(request: &Request, shard: Option<Shard>, view: &View) -> Status {
    // Before anything is read or written: a signal from here on stops the run cleanly.
    crate::output::interrupt::install();
    // A list that names no asset (a change that touched none) is nothing to do, not an error.
    let report = if request.inputs.is_empty() {
        RunReport {
            dry_run: request.dry_run,
            files: Vec::new(),
            summary: Summary::default(),
        }
    } else {
        match run_shard_with_sheets(request, shard, view.preview.is_some()) {
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
    let mut report = report;
    let mut preview_failed = false;
    if let Some(dir) = &view.preview {
        let previews = sheets_of(request, shard, &mut report);
        preview_failed = super::preview::report_failures(&previews, "preview: ");
        match super::preview::write(&previews, dir, None, true) {
            Some(Status::Stopped(signal)) => return Status::Stopped(signal),
            Some(_) => preview_failed = true,
            None => {}
        }
    }
    let check_failed = match view.check {
        false => false,
        true => match visible_failures(&report, view.fail_on_visible) {
            Ok(None) => report.summary.totals.would_change > 0,
            Ok(Some(lines)) => {
                for line in &lines {
                    super::note(format_args!("velvet: --check: {line}"));
                }
                !lines.is_empty()
            }
            Err(e) => return super::usage_error(e),
        },
    };
    let failed = report.failed() || preview_failed || check_failed;
    // The command line exits after this: a library's report (a plan for every material) is
    // left to the exit rather than freed value by value.
    std::mem::forget(report);
    Status::failed_if(failed)
}

/// Under `--check`, the materials that fail an appearance gate, one line each (file, material,
/// verdict), or `None` when no file is judged by appearance: the gate is on for a file when
/// `--fail-on-visible` is given or the velvet.toml found for it sets `fail-on-visible`. A gated
/// file fails on a material the migration would change visibly, and on one already migrated
/// (fuzz with its fallback sheen in the file) whose fallback looks visibly different from its
/// fuzz; a change alone does not fail it. Files not gated fail the check when they would change.
pub fn visible_failures(
    report: &RunReport,
    flag: bool,
) -> Result<Option<Vec<String>>, crate::config::ConfigError> {
    let mut resolver = crate::config::Resolver::new(
        None,
        crate::config::Layer {
            fail_on_visible: flag.then_some(true),
            ..crate::config::Layer::default()
        },
    )?;
    let mut gated_any = false;
    let mut lines = Vec::new();
    for file in &report.files {
        let gated = resolver.for_path(&file.input)?.fail_on_visible.0;
        if !gated {
            if file.outcome == (FileOutcome::Planned { changes: true }) {
                lines.push(format!("{}: would change", file.input.display()));
            }
            continue;
        }
        gated_any = true;
        for m in &file.detail.materials {
            let judged = m.migrated() || m.skipped == Some(crate::migrate::Skip::BothPresent);
            match m.verdict {
                Some(v) if judged && v.label == crate::migrate::verdict::Label::Visible => {
                    let name = m
                        .name
                        .as_deref()
                        .map(|n| format!(" \"{n}\""))
                        .unwrap_or_default();
                    lines.push(format!(
                        "{}: material {}{name}: {}",
                        file.input.display(),
                        m.index,
                        v.describe()
                    ));
                }
                _ => {}
            }
        }
    }
    Ok(gated_any.then_some(lines))
}

/// The preview of a run: each file's materials as its plan (the one written) gave them, read
/// before the file was written; a file migrate could not plan has no sheet, and says why.
fn sheets_of(
    request: &Request,
    shard: Option<Shard>,
    report: &mut RunReport,
) -> crate::preview::Plan {
    let (labels, walk_errors) = crate::preview::labels(&request.inputs, shard);
    let mut by_path: std::collections::HashMap<PathBuf, Result<_, String>> = report
        .files
        .iter_mut()
        .map(|f| {
            let sheets = match (f.detail.sheets.take(), &f.outcome) {
                (Some(sheets), _) => Ok(sheets),
                (None, FileOutcome::Failed { error }) => Err(error.clone()),
                (None, _) => Err("not planned".to_string()),
            };
            (f.input.clone(), sheets)
        })
        .collect();
    let files = labels
        .into_iter()
        .map(|(file, label)| crate::preview::FileMaterials {
            materials: by_path
                .remove(&file)
                .unwrap_or_else(|| Err("not planned".to_string())),
            file,
            label,
        })
        .collect();
    crate::preview::assemble(files, walk_errors)
}
