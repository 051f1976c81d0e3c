//! A `velvet validate` run over many inputs: find the asset files, give each the configuration
//! found for it (see [`crate::config`]), leave out excluded files, validate the rest in
//! parallel, and decide whether the run failed. A configuration error stops the run before any
//! file is read: a broken velvet.toml is a usage error, not a finding.

use crate::asset::discover;
use crate::config::{ConfigError, Resolver};
use crate::validate::{FileReport, Validator};
use rayon::prelude::*;
use std::path::PathBuf;

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
    let (files, walk_errors) = discover::collect(inputs);
    let mut planned = Vec::with_capacity(files.len());
    let mut excluded = Vec::new();
    for file in files {
        let config = resolver.for_path(&file)?;
        if config.excludes(&crate::config::absolute(&file)) {
            excluded.push(file);
        } else {
            planned.push((file, config));
        }
    }
    let mut reports = Vec::with_capacity(planned.len() + walk_errors.len());
    let mut failed = false;
    for (folder, error) in walk_errors {
        let config = resolver.for_path(&folder)?;
        let report = validator.unreadable_folder(folder, &error, config.settings());
        failed |= report.fails(config.settings());
        reports.push(report);
    }
    if let Some(bar) = progress {
        bar.set_length(planned.len() as u64);
    }
    let checked: Vec<(FileReport, bool)> = planned
        .par_iter()
        .map(|(file, config)| {
            let report = validator.validate_file_with(file, config.settings());
            let fails = report.fails(config.settings());
            if let Some(bar) = progress {
                bar.inc(1);
            }
            (report, fails)
        })
        .collect();
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    for (report, fails) in checked {
        failed |= fails;
        reports.push(report);
    }
    Ok(Outcome {
        reports,
        excluded,
        failed,
    })
}
