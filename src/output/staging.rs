//! A file's outputs, staged and put in place together: the new image files, the resource
//! copies and the document itself are each written completely under a temporary name in their
//! folder ([`write::Staged`]), and only when all of them are, the input is still the one read
//! and the run was not asked to stop, renamed into place, the document last. A file that fails
//! or is abandoned halfway (an error, a full disk, SIGINT) drops its staging, which removes
//! every file it wrote: no texture without its document is left behind. What a kill leaves
//! (only `.velvet-PID-*.tmp` files) the next run into the folder removes
//! ([`write::remove_leftovers`]).

use crate::edit::write::{self, Output, Staged};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The files staged for one output, in the order they were staged.
#[derive(Debug, Default)]
pub struct Staging {
    staged: Mutex<Vec<Staged>>,
}

impl Staging {
    fn push(&self, staged: Staged) {
        self.staged
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(staged);
    }

    /// Stages `bytes` as the file `name` in `dir` (created if need be), unless the file there
    /// holds them already.
    pub fn stage_bytes(&self, dir: &Path, name: &str, bytes: &[u8]) -> Result<(), String> {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create folder {}: {e}", dir.display()))?;
        let path = dir.join(name);
        if std::fs::read(&path).is_ok_and(|b| b == bytes) {
            return Ok(());
        }
        let staged = write::stage_output(&path, &Output::Bytes(bytes.into()))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        self.push(staged);
        Ok(())
    }

    /// Stages a copy of each `(from, to)` (a clone where the filesystem can make one), side by
    /// side: each copy waits for its `fsync`, and the waits overlap (five textures of the
    /// benchmark library: 2.0 ms one after the other). They are staged in the order given; the
    /// first error in that order is the one told.
    pub fn stage_copies(&self, copies: &[(PathBuf, &Path)]) -> Result<(), String> {
        let staged: Vec<Result<Staged, String>> = copies
            .par_iter()
            .map(|(from, to)| {
                write::stage_copy(from, to)
                    .map(|(staged, _)| staged)
                    .map_err(|e| format!("cannot write resource {}: {e}", to.display()))
            })
            .collect();
        for file in staged {
            self.push(file?);
        }
        Ok(())
    }

    /// Stages the output document at `path`, its folder created if need be (`--out-dir NEW`
    /// for a file whose output writes nothing else there first).
    pub fn stage_document(&self, path: &Path, output: &Output) -> Result<(), String> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("cannot create folder {}: {e}", dir.display()))?;
        }
        let staged = write::stage_output(path, output)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        self.push(staged);
        Ok(())
    }

    /// Puts every staged file in place, in the order staged (the document, staged last, goes
    /// last), unless the run was asked to stop: then every one is removed and the error says
    /// so.
    pub fn commit(self) -> Result<(), String> {
        super::interrupt::check()?;
        let staged = self.staged.into_inner().unwrap_or_else(|e| e.into_inner());
        for file in staged {
            let to = file.target().to_path_buf();
            file.put_in_place()
                .map_err(|e| format!("cannot write {}: {e}", to.display()))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_appear_together_on_commit_and_vanish_when_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let names = |dir: &Path| {
            let mut names: Vec<String> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name().into_string().unwrap())
                .collect();
            names.sort();
            names
        };
        let staging = Staging::default();
        staging.stage_bytes(dir.path(), "a.png", b"a").unwrap();
        staging
            .stage_document(
                &dir.path().join("doc.gltf"),
                &Output::Bytes(b"{}".as_slice().into()),
            )
            .unwrap();
        assert!(names(dir.path()).iter().all(|n| n.starts_with(".velvet-")));
        drop(staging);
        assert!(names(dir.path()).is_empty());

        let staging = Staging::default();
        staging.stage_bytes(dir.path(), "a.png", b"a").unwrap();
        staging
            .stage_document(
                &dir.path().join("doc.gltf"),
                &Output::Bytes(b"{}".as_slice().into()),
            )
            .unwrap();
        staging.commit().unwrap();
        assert_eq!(names(dir.path()), ["a.png", "doc.gltf"]);
        assert_eq!(std::fs::read(dir.path().join("a.png")).unwrap(), b"a");
    }
}
