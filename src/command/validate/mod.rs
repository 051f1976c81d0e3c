//! `velvet validate` as the command line runs it: the files found, each checked under its own
//! configuration (the run over many files in [`batch`]; one document by [`crate::validate`]) and,
//! with `--fix` or `--diff`, fixed through [`crate::fix`], each report written as soon as it is
//! done, the exit status from every finding left. A run that cannot start (a missing path, a bad
//! velvet.toml or schema folder) still writes a report in the format asked for, recording why.

pub mod batch;

use super::Status;
use crate::asset::discover::{self, Shard};
use crate::asset::LoadOptions;
use crate::config::Flags;
use crate::diagnostics::Settings;
use crate::report::{self, ColorChoice, Format};
use crate::rules::schema::Schemas;
use crate::validate::Validator;
use std::path::PathBuf;

/// One `velvet validate` invocation.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub paths: Vec<PathBuf>,
    /// `--files-from FILE` (`-`: standard input).
    pub files_from: Option<PathBuf>,
    pub shard: Option<Shard>,
    pub settings: Flags,
    /// `--schema-dir DIR`: schema files read from there instead of the built-in ones.
    pub schema_dir: Option<PathBuf>,
    pub load: LoadOptions,
    pub format: Format,
    pub color: ColorChoice,
    pub quiet: bool,
    /// Text: every finding, none folded.
    pub no_fold: bool,
    pub fix: FixFlags,
}

/// What `validate` does with the fixes of its findings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixFlags {
    /// `--fix`: write the fixes to the files.
    pub fix: bool,
    /// `--unsafe-fixes`: fixes that change the asset's meaning too.
    pub unsafe_fixes: bool,
    /// `--diff`: print the fixes as a unified diff, write nothing.
    pub diff: bool,
    /// `--exit-non-zero-on-fix`: with `--fix`, a changed file fails the run (pre-commit).
    pub exit_non_zero_on_fix: bool,
    /// `--fix-only`: with `--fix`, the text report leaves out the fixes applied.
    pub fix_only: bool,
}

/// Runs `velvet validate`, its reports on standard output.
pub fn command(request: &Request) -> Status {
    // One report object for a run over one file named on the command line; an array for
    // anything else (folders, several files, a list, a shard), whatever it finds.
    let one_file = request.files_from.is_none()
        && request.shard.is_none()
        && matches!(request.paths.as_slice(), [path] if path.is_file());
    // A run that cannot start still writes a report in its format, recording why (every
    // such error comes before the first report is written).
    let failed = |message: String| {
        super::emit(report::failed_run(request.format, &message, !one_file).as_bytes());
        super::usage_error(message)
    };
    // --unsafe-fixes alone would do nothing, and whoever typed it meant something to change
    // or be shown: refused before anything is read.
    if request.fix.unsafe_fixes && !request.fix.fix && !request.fix.diff {
        return failed(
            "--unsafe-fixes applies only with --fix or --diff (add one of them to fix or show \
             the unsafe fixes too)"
                .to_string(),
        );
    }
    let paths = match discover::resolve(&request.paths, request.files_from.as_deref()) {
        Ok(p) => p,
        Err(e) => return failed(e.to_string()),
    };
    let mut resolver = match request.settings.resolver() {
        Ok(r) => r,
        Err(e) => return failed(e.to_string()),
    };
    let validator = match &request.schema_dir {
        Some(dir) => match Schemas::with_overrides(dir) {
            Ok(schemas) => Validator::new(schemas, Settings::default()),
            Err(e) => return failed(e.to_string()),
        },
        None => Validator::builtin(Settings::default()),
    };
    // Never dropped: the process ends with this command, and freeing the compiled schemas
    // (thousands of small allocations) took a tenth of the instructions of a run over one
    // file, the run a pre-commit hook makes.
    let validator = std::mem::ManuallyDrop::new(
        validator
            .with_load_options(request.load)
            .with_positions(request.format.shows_positions()),
    );
    if request.fix.fix {
        // --fix writes the files in place, as `migrate --in-place` does: a link leading out of
        // the folders given is refused before anything is written, and from here on SIGINT and
        // SIGTERM stop the run cleanly (files already written stay, the others are not).
        if let Err(crate::output::UsageError::LinkOutside { link, target, root }) =
            crate::output::paths::jobs(
                &paths,
                &crate::output::paths::Destination::InPlace,
                false,
                request.shard,
            )
        {
            return failed(format!(
                "--fix: {link} is a symbolic link to {target}, outside {root}; velvet writes \
                 only inside the folders it is given (name the target itself to fix it)"
            ));
        }
        crate::output::interrupt::install();
    }
    let progress = report::progress_bar(request.quiet);
    let options = report::Options {
        color: request.format == Format::Text && request.color.for_stdout(),
        quiet: request.quiet,
        no_fold: request.no_fold,
        diff: request.fix.diff,
        fix_only: request.fix.fix_only,
    };
    let fixing = crate::fix::Fixing::new(
        &validator,
        crate::fix::Mode {
            apply: request.fix.fix,
            diff: request.fix.diff,
            unsafe_fixes: request.fix.unsafe_fixes,
            edits: matches!(request.format, Format::Json | Format::Jsonl | Format::Sarif),
        },
    )
    .stopping_when(|| crate::output::interrupt::requested().is_some());
    let mut finished = 0usize;
    // Each file's report is written as soon as it is done (see report::Stream).
    let stdout = std::io::BufWriter::new(super::Stdout);
    let mut stream = report::Stream::new(request.format, options, stdout).json_array(!one_file);
    let outcome = match batch::check_shard_each(
        &validator,
        &paths,
        request.shard,
        &mut resolver,
        progress.as_ref(),
        &|path, settings| fixing.check(path, settings),
        &mut |r| {
            // A file abandoned by a stop has no report: nothing was done to it.
            if r.fixes.write_error.as_deref() == Some(crate::fix::ABANDONED) {
                return;
            }
            finished += 1;
            match &progress {
                // The bar is cleared while the report is written, so the two do not mix.
                Some(bar) => bar.suspend(|| {
                    stream.push(r);
                    stream.flush();
                }),
                None => stream.push(r),
            }
        },
    ) {
        Ok(o) => o,
        Err(e) => {
            // Nothing has been written (configurations are resolved first); the stream holds
            // standard output, so it goes before the failure's report is written.
            drop(stream);
            return failed(e.to_string());
        }
    };
    stream.finish();
    // A file named on the command line (or in a list) that velvet.toml excludes is skipped, as
    // pre-commit needs; it is said, so that nobody takes it for checked.
    for (file, by) in &outcome.named_excluded {
        super::note(format_args!(
            "velvet: {}: skipped, excluded by {by}",
            file.display()
        ));
    }
    for warning in resolver.warnings() {
        super::note(format_args!("velvet: {warning}"));
    }
    if request.fix.fix {
        let abandoned = fixing.files_abandoned();
        let each = std::iter::repeat_n(true, finished).chain(std::iter::repeat_n(false, abandoned));
        if let Some(stopped) = super::stopped(each) {
            return stopped;
        }
    }
    // Fixed findings do not fail the run; those left do. A change fails it where it is asked to
    // be reviewed (--diff, --exit-non-zero-on-fix).
    let changed =
        fixing.files_changed() > 0 && (request.fix.diff || request.fix.exit_non_zero_on_fix);
    Status::failed_if(outcome.failed || changed)
}
