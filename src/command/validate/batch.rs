//! `velvet validate`'s runner over many inputs, as `command/migrate/batch.rs` is migrate's (one
//! document is validated by [`crate::validate`]): find the asset files (with `--shard`, one part of
//! them; see [`crate::asset::discover`]), give each the configuration
//! found for it (see [`crate::config`]), leave out excluded files, validate the rest in
//! parallel, and decide whether the run failed. A configuration error stops the run before any
//! file is read: a broken velvet.toml is a usage error, not a finding.
//!
//! Files are validated in parallel a batch at a time and each report is handed on in input
//! order as soon as its batch is done, so that a run over ten thousand files holds one batch of
//! reports, not ten thousand (see [`validate_each`]).

use crate::asset::discover::{self, Shard};
use crate::config::{ConfigError, Resolver};
use crate::diagnostics::Settings;
use crate::validate::{FileReport, Validator};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// What a run produced.
#[derive(Debug)]
pub struct Outcome {
    /// One report per file checked (folders that could not be read included), in input order.
    pub reports: Vec<FileReport>,
    /// Files left out by an exclude pattern.
    pub excluded: Vec<PathBuf>,
    /// True when a report has a finding at or above its configuration's fail-on severity.
    pub failed: bool,
}

/// Validates `inputs` with the configuration `resolver` finds for each file. `progress`, when
/// given, is told the number of files and advanced as each is done.
pub fn validate(
    validator: &Validator,
    inputs: &[PathBuf],
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
) -> Result<Outcome, ConfigError> {
    let mut reports = Vec::new();
    let each = validate_each(validator, inputs, resolver, progress, &mut |r| {
        reports.push(r)
    })?;
    Ok(Outcome {
        reports,
        excluded: each.excluded,
        failed: each.failed,
    })
}

/// What a run produced besides its reports.
#[derive(Debug)]
pub struct Totals {
    /// Files left out by an exclude pattern.
    pub excluded: Vec<PathBuf>,
    /// The excluded files that were named as inputs (not found in a folder), each with the
    /// configuration that excludes it ("the exclude patterns of …"): the run says it skipped
    /// them, since whoever named them (pre-commit, a list) may expect them checked.
    pub named_excluded: Vec<(PathBuf, String)>,
    /// True when a report has a finding at or above its configuration's fail-on severity.
    pub failed: bool,
}

/// Files validated in parallel before their reports are handed on: enough to keep every core
/// busy, few enough that the reports in hand stay small.
const BATCH: usize = 256;

/// Validates like [`validate`], handing each report to `sink` in input order as soon as its
/// batch is done instead of keeping them.
pub fn validate_each(
    validator: &Validator,
    inputs: &[PathBuf],
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    sink: &mut dyn FnMut(FileReport),
) -> Result<Totals, ConfigError> {
    validate_shard_each(validator, inputs, None, resolver, progress, sink)
}

/// Validates like [`validate_each`], only the files of `shard` when one is given (see
/// [`Shard`]): N runs over shards 1/N … N/N together report every file exactly once.
pub fn validate_shard_each(
    validator: &Validator,
    inputs: &[PathBuf],
    shard: Option<Shard>,
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    sink: &mut dyn FnMut(FileReport),
) -> Result<Totals, ConfigError> {
    let check = |file: &Path, settings: &Settings| validator.validate_file_with(file, settings);
    check_shard_each(validator, inputs, shard, resolver, progress, &check, sink)
}

/// Runs like [`validate_shard_each`], each file's report made by `check` (given the file and
/// its configuration's settings) instead of a plain validation: `velvet validate --fix`
/// checks, fixes and validates again (see `crate::fix`).
pub fn check_shard_each(
    validator: &Validator,
    inputs: &[PathBuf],
    shard: Option<Shard>,
    resolver: &mut Resolver,
    progress: Option<&indicatif::ProgressBar>,
    check: &(dyn Fn(&Path, &Settings) -> FileReport + Sync),
    sink: &mut dyn FnMut(FileReport),
) -> Result<Totals, ConfigError> {
    let (found, walk_errors) = discover::find(inputs, shard);
    let mut planned = Vec::with_capacity(found.len());
    let mut excluded = Vec::new();
    let mut named_excluded = Vec::new();
    // What excluded the first file found in a folder (not named itself), if any was.
    let mut walked_excluded_by = None;
    for found in found {
        // A file named as an input is found as itself; one found in a folder is below it.
        let named = inputs.get(found.input) == Some(&found.path);
        let file = found.path;
        // Made absolute once: its configuration is searched from its folder, and its
        // exclusion read, from the same path.
        let absolute = crate::config::absolute(&file);
        let config = resolver.for_file(&absolute)?;
        if config.excludes(&absolute) {
            let by = match &config.file {
                Some(file) => format!("the exclude patterns of {}", file.display()),
                None => "the exclude patterns".to_string(),
            };
            if named {
                named_excluded.push((file.clone(), by));
            } else if walked_excluded_by.is_none() {
                walked_excluded_by = Some(by);
            }
            excluded.push(file);
        } else {
            planned.push((file, config));
        }
    }
    // A configuration may leave files out, but not every file of a folder given: the folders
    // were checked to hold assets (discover::check_inputs), and a run that checks none of them
    // must not pass (a typo'd exclude pattern would turn the gate off). Files named one by one
    // (pre-commit passes the staged files) are another matter: skipping the excluded ones is
    // what the exclude patterns are for, so a run left with nothing from them passes.
    // A shard may be left with nothing by the split alone, so only a whole run is held to it.
    if shard.is_none() && planned.is_empty() && walk_errors.is_empty() {
        if let Some(by) = walked_excluded_by {
            return Err(ConfigError::AllExcluded {
                found: excluded.len(),
                by,
            });
        }
    }
    // Every configuration is resolved before the first report goes out: a configuration error
    // stops the run with nothing written.
    let mut unreadable = Vec::with_capacity(walk_errors.len());
    for (folder, error) in walk_errors {
        let config = resolver.for_path(&folder)?;
        unreadable.push((folder, error, config));
    }
    let mut failed = false;
    for (folder, error, config) in unreadable {
        let report = validator.unreadable_folder(folder, &error, config.settings());
        failed |= report.fails(config.settings());
        sink(report);
    }
    if let Some(bar) = progress {
        // One file is shown as itself before the length would draw "0/1".
        if let [(file, _)] = planned.as_slice() {
            crate::output::show_one_file(bar, file);
        }
        bar.set_length(planned.len() as u64);
    }
    for batch in planned.chunks(BATCH) {
        let checked: Vec<(FileReport, bool)> = batch
            .par_iter()
            .map(|(file, config)| {
                let report = check(file, config.settings());
                let fails = report.fails(config.settings());
                if let Some(bar) = progress {
                    bar.inc(1);
                }
                (report, fails)
            })
            .collect();
        for (report, fails) in checked {
            failed |= fails;
            sink(report);
        }
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    Ok(Totals {
        excluded,
        named_excluded,
        failed,
    })
}
