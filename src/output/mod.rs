//! Where the outputs of `velvet migrate` and `velvet bake` go and what is written besides them:
//! both commands take the same destinations and refuse the same requests, keep an output in
//! another folder loadable the same way, and word their reports alike, so these rules live here
//! once, owned by neither command.
//!
//! [`paths`] pairs inputs with outputs and says what must follow an output (relative URIs,
//! resource copies, link checks); [`files`] writes new image files and resource copies next to
//! an output; [`summary`] holds the wording the two text reports share. [`run_each`] runs a
//! command's files in parallel under one set of name claims and one progress bar.
//! [`UsageError`] is a request either command refuses before anything is read or written, and
//! [`Outcome`] what became of one file, in either command.

pub mod files;
pub mod interrupt;
pub mod paths;
pub mod result;
pub mod staging;
pub mod summary;

use crate::asset::discover::Shard;
use crate::asset::{Asset, FileBytes, LoadOptions, Snapshot};
use rayon::prelude::*;
use std::path::PathBuf;

/// What became of one file in `velvet migrate` or `velvet bake`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
#[serde(tag = "status", rename_all = "kebab-case")]
pub enum Outcome {
    /// Migrated or baked, and written.
    Changed,
    /// Nothing to do: the input's bytes were written to the output.
    Copied,
    /// Nothing to do in place: not written.
    Untouched,
    /// Dry run: what would happen.
    Planned {
        /// Whether a real run would change the file.
        changes: bool,
    },
    /// Not done; nothing was written for it.
    Failed {
        /// Why.
        error: String,
    },
}

/// The files of a migrate or bake request, and how a run over them shows its progress.
pub struct Scope<'a> {
    pub inputs: &'a [PathBuf],
    pub destination: &'a paths::Destination,
    pub dry_run: bool,
    pub shard: Option<Shard>,
    /// A progress bar on a terminal, for runs over more than one file.
    pub progress: bool,
}

/// Runs `each` over every file of `scope` in parallel, under one set of name claims, after one
/// `unreadable` result per folder that could not be read; results come in that order, files in
/// input order. Before any file, the temporary files a killed run left in the output folders
/// are removed. `Err` is a usage error: nothing was read or written.
pub fn run_each<R: Send>(
    scope: &Scope,
    unreadable: impl Fn(PathBuf, std::io::Error) -> R,
    each: impl Fn(&paths::Job, &files::Claims) -> R + Sync,
) -> Result<Vec<R>, UsageError> {
    let (jobs, walk_errors) =
        paths::jobs(scope.inputs, scope.destination, scope.dry_run, scope.shard)?;
    if !scope.dry_run {
        // What a killed run left in the folders this one writes to goes first.
        let folders: std::collections::BTreeSet<&std::path::Path> = jobs
            .iter()
            .filter_map(|job| job.output.as_deref().map(paths::folder_of))
            .collect();
        for folder in folders {
            crate::edit::write::remove_leftovers(folder);
        }
    }
    let claims = files::Claims::default();
    let bar = match jobs.as_slice() {
        [one] if scope.progress && std::io::IsTerminal::is_terminal(&std::io::stderr()) => {
            let bar = indicatif::ProgressBar::with_draw_target(
                Some(1),
                indicatif::ProgressDrawTarget::stderr(),
            );
            show_one_file(&bar, &one.input);
            Some(bar)
        }
        _ => progress_bar(scope.progress, jobs.len(), "files"),
    };
    let mut results: Vec<R> = walk_errors
        .into_iter()
        .map(|(path, e)| unreadable(path, e))
        .collect();
    results.par_extend(jobs.par_iter().map(|job| {
        let result = each(job, &claims);
        if let Some(bar) = &bar {
            bar.inc(1);
        }
        result
    }));
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(results)
}

/// The progress bar of a run over `count` things (`noun`: "files", "sheets"), when `wanted`:
/// on a terminal only (logs and pipes never see one), and only for more than one (a run over
/// one file shows it with [`show_one_file`]).
pub fn progress_bar(wanted: bool, count: usize, noun: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    (wanted && count > 1 && std::io::stderr().is_terminal()).then(|| {
        let bar = indicatif::ProgressBar::new(count as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(&format!(
            "{{bar:40}} {{pos}}/{{len}} {noun} {{msg}}"
        )) {
            bar.set_style(style);
        }
        bar
    })
}

/// Turns `bar` into what a run over one file shows instead of "0/1": a spinner with the file's
/// name and size, the stage the work is at (`crate::progress`: "checking rules 12/61") and the
/// time so far, redrawn ten times a second, so that a large file's minutes on a terminal are
/// visibly work and not a hang. The size is the file's length on disk (one `stat`), not read.
pub fn show_one_file(bar: &indicatif::ProgressBar, file: &std::path::Path) {
    if let Ok(style) = indicatif::ProgressStyle::with_template("{spinner} {msg} {stage}{elapsed}") {
        // The stage with a space after it, or nothing before the first stage.
        bar.set_style(style.with_key(
            "stage",
            |_: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                let stage = crate::progress::describe();
                if !stage.is_empty() {
                    let _ = write!(w, "{stage} ");
                }
            },
        ));
    }
    let size = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
    bar.set_message(format!(
        "{} ({})",
        file.display(),
        indicatif::HumanBytes(size)
    ));
    bar.enable_steady_tick(std::time::Duration::from_millis(100));
}

/// A request velvet cannot carry out as given (exit status 2): nothing is read or written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum UsageError {
    #[error("say where the output goes: -o FILE (one input), --out-dir DIR or --in-place (or use --dry-run)")]
    NoDestination,
    #[error("-o names one output file, but {0} inputs were given; use --out-dir DIR for several")]
    OutputForMany(usize),
    #[error("-o names one output file, but {0} is a folder; use --out-dir DIR")]
    OutputForFolder(String),
    #[error("-o {output}: the input {input} is a {container} file and the output keeps its container; name the output *.{extension}")]
    ContainerMismatch {
        input: String,
        output: String,
        container: &'static str,
        extension: &'static str,
    },
    #[error("the output {output} is the input {input}; use --in-place to overwrite inputs")]
    OutputIsInput { output: String, input: String },
    #[error("{first} and {second} would both be written to {output}")]
    OutputCollision {
        output: String,
        first: String,
        second: String,
    },
    #[error("no inputs given")]
    NoInputs,
    #[error("--in-place: {link} is a symbolic link to {target}, outside {root}; velvet writes only inside the folders it is given (name the target itself to migrate it)")]
    LinkOutside {
        link: String,
        target: String,
        root: String,
    },
}

/// An input loaded by a command that writes an output for it.
pub struct Input {
    pub asset: Asset,
    /// The file's bytes where the loader kept them (a GLB's, for an output with nothing to
    /// change, written as they are); a .gltf's are the asset's text.
    pub bytes: Option<FileBytes>,
    /// The file as it was read, and its resources, compared before anything is written for it.
    pub snapshot: InputSnapshot,
}

/// What an input and the files its URIs name (buffers, images) were when it was loaded: a
/// resource read for its output (baked, copied beside it) is held to it as the document is,
/// so that one deleted or replaced while velvet works fails the file, nothing written for it,
/// rather than give an output without its .bin or baked from another image.
#[derive(Debug, Clone)]
pub struct InputSnapshot {
    document: Snapshot,
    /// Each resource file with what it was (`None`: it did not exist, and must not appear).
    resources: Vec<(std::path::PathBuf, Option<Snapshot>)>,
}

impl InputSnapshot {
    /// The resources `asset` names in files, as they are now.
    fn taken(document: Snapshot, asset: &Asset) -> InputSnapshot {
        let resources = paths::relative_uris(asset.root())
            .iter()
            .filter_map(|uri| match asset.resolve(uri, "") {
                Ok(crate::asset::resource::Location::File(path)) => Some(path),
                _ => None,
            })
            .map(|path| {
                let was = Snapshot::before_reading(&path).ok();
                (path, was)
            })
            .collect();
        InputSnapshot {
            document,
            resources,
        }
    }

    /// `Ok` when the input at `path` and every resource it names are as they were when it was
    /// loaded; otherwise the message naming the one that is not.
    pub fn unchanged(&self, path: &std::path::Path) -> Result<(), String> {
        self.document.unchanged(path)?;
        for (resource, was) in &self.resources {
            match was {
                Some(was) => was
                    .unchanged(resource)
                    .map_err(|e| format!("resource {e}"))?,
                None if std::fs::symlink_metadata(resource).is_ok() => {
                    return Err(format!(
                        "resource {} appeared while velvet worked on {}; nothing was written \
                         for it",
                        resource.display(),
                        path.display()
                    ))
                }
                None => {}
            }
        }
        Ok(())
    }
}

/// Reads and loads `path` for a command that writes its output (`verb`: "migrated", "baked").
/// A file the loader reports errors for is refused, naming them: rewriting it would hide the
/// fault (a truncated BIN chunk would come out "fixed"). The error reads "cannot be `verb`:
/// …", for the caller to put after the file's name.
pub fn load_input(
    path: &std::path::Path,
    options: &LoadOptions,
    verb: &str,
) -> Result<Input, String> {
    let (bytes, snapshot) = crate::asset::read_for_writing(path, options)
        .map_err(|e| format!("cannot be {verb}: {e}"))?;
    // A .gltf's bytes become the asset's text as they are: a copy of a large document cost as
    // much as reading it (a page fault per 4 KiB on first touch).
    let (loaded, bytes) = crate::asset::load_read(path, bytes, options);
    let errors: Vec<String> = loaded
        .diagnostics
        .iter()
        .filter(|d| d.severity == crate::diagnostics::Severity::Error)
        .map(|d| format!("{} ({})", d.message, d.code))
        .collect();
    match loaded.asset {
        Some(asset) if errors.is_empty() => Ok(Input {
            snapshot: InputSnapshot::taken(snapshot, &asset),
            asset,
            bytes,
        }),
        _ => Err(format!("cannot be {verb}: {}", errors.join("; "))),
    }
}
