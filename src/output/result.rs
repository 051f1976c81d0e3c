//! What a file command reports: one result type for every file of `velvet migrate` and `velvet
//! bake` ([`FileResult`], the input, the output, the [`Outcome`] and the command's own account of
//! the file), and one set of totals over a run ([`Totals`]), counted the same way for both. A
//! command's account says what the totals need to know of it through [`Account`]; everything
//! else it reports is its own.

use super::Outcome;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What a command's account of one file tells the run's totals.
pub trait Account: Default {
    /// New textures the output gains (in a dry run, those planned) and their encoded bytes
    /// (0 in a dry run: nothing is encoded).
    fn added(&self, outcome: &Outcome) -> (usize, usize);
    /// Notes at warning level.
    fn warnings(&self) -> usize;
}

/// One file of a migrate or bake run: where it came from, where its output goes, what became
/// of it, and the command's account of what it planned and did (`detail`, whose fields the JSON
/// report lists beside the others).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FileResult<D> {
    #[serde(serialize_with = "lossy_path")]
    pub input: PathBuf,
    #[serde(serialize_with = "lossy_optional_path")]
    pub output: Option<PathBuf>,
    #[serde(flatten)]
    pub outcome: Outcome,
    #[serde(flatten)]
    pub detail: D,
}

/// A path in the JSON report: a file name need not be UTF-8, and serde's own serialisation of
/// a path fails on one that is not (after the outputs were written), so it is written lossily
/// (U+FFFD for each byte that is not UTF-8), as the text report shows it.
fn lossy_path<S: serde::Serializer>(path: &Path, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&path.to_string_lossy())
}

fn lossy_optional_path<S: serde::Serializer>(
    path: &Option<PathBuf>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match path {
        Some(path) => lossy_path(path, s),
        None => s.serialize_none(),
    }
}

impl<D: Account> FileResult<D> {
    /// A file that was not done: nothing was written for it.
    pub fn failed(input: &Path, output: Option<&Path>, error: String) -> FileResult<D> {
        FileResult {
            input: input.to_path_buf(),
            output: output.map(Path::to_path_buf),
            outcome: Outcome::Failed { error },
            detail: D::default(),
        }
    }

    /// Whether the file failed.
    pub fn is_failed(&self) -> bool {
        matches!(self.outcome, Outcome::Failed { .. })
    }

    /// New textures and their bytes, as [`Account::added`] says (none for a failed file).
    pub fn added(&self) -> (usize, usize) {
        match self.outcome {
            Outcome::Failed { .. } => (0, 0),
            _ => self.detail.added(&self.outcome),
        }
    }
}

/// Totals over a run, alike for every file command.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Totals {
    pub files: usize,
    /// Written with changes.
    pub changed: usize,
    /// Nothing to change (copied, left as it was, or in a dry run nothing planned).
    pub unchanged: usize,
    /// Not done: nothing was written for them.
    pub failed: usize,
    /// Dry run: files that would change.
    pub would_change: usize,
    /// Notes at warning level, over the files that did not fail.
    pub warnings: usize,
    /// New textures over all files (in a dry run, those planned), and their bytes.
    pub textures_added: usize,
    pub bytes_added: usize,
}

impl Totals {
    /// Counts `files`.
    pub fn of<D: Account>(files: &[FileResult<D>]) -> Totals {
        let mut t = Totals {
            files: files.len(),
            ..Totals::default()
        };
        for file in files {
            match &file.outcome {
                Outcome::Changed => t.changed += 1,
                Outcome::Copied | Outcome::Untouched | Outcome::Planned { changes: false } => {
                    t.unchanged += 1
                }
                Outcome::Planned { changes: true } => t.would_change += 1,
                Outcome::Failed { .. } => {
                    t.failed += 1;
                    continue;
                }
            }
            let (textures, bytes) = file.added();
            t.textures_added += textures;
            t.bytes_added += bytes;
            t.warnings += file.detail.warnings();
        }
        t
    }

    /// Files changed, or in a dry run that would change: the count the summary line gives.
    pub fn done(&self) -> usize {
        self.changed + self.would_change
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default)]
    struct Baked {
        textures: usize,
        warnings: usize,
    }

    impl Account for Baked {
        fn added(&self, outcome: &Outcome) -> (usize, usize) {
            let planned = matches!(outcome, Outcome::Planned { .. });
            (self.textures, if planned { 0 } else { 100 * self.textures })
        }
        fn warnings(&self) -> usize {
            self.warnings
        }
    }

    fn file(outcome: Outcome, textures: usize, warnings: usize) -> FileResult<Baked> {
        FileResult {
            input: "in.gltf".into(),
            output: None,
            outcome,
            detail: Baked { textures, warnings },
        }
    }

    #[test]
    fn totals_count_each_outcome_once_and_nothing_of_a_failed_file() {
        let files = [
            file(Outcome::Changed, 2, 1),
            file(Outcome::Copied, 0, 0),
            file(Outcome::Untouched, 0, 3),
            file(Outcome::Failed { error: "no".into() }, 5, 7),
        ];
        assert_eq!(
            Totals::of(&files),
            Totals {
                files: 4,
                changed: 1,
                unchanged: 2,
                failed: 1,
                would_change: 0,
                warnings: 4,
                textures_added: 2,
                bytes_added: 200,
            }
        );
    }

    #[test]
    fn a_dry_run_counts_the_files_that_would_change_and_the_textures_planned() {
        let files = [
            file(Outcome::Planned { changes: true }, 3, 0),
            file(Outcome::Planned { changes: false }, 0, 1),
        ];
        let t = Totals::of(&files);
        assert_eq!(
            (t.would_change, t.unchanged, t.changed, t.done()),
            (1, 1, 0, 1)
        );
        assert_eq!((t.textures_added, t.bytes_added, t.warnings), (3, 0, 1));
    }
}
