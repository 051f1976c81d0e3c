//! The files a run writes besides each output document: new image files under names no other
//! file of the run holds with other bytes, and the resource copies a relocated output needs.
//! Migrate and bake write them the same way, so they share this module.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde_json::Value;

use super::interrupt;
use super::paths::{folder_of, identity, relative_uris, Relocation};
use super::staging::Staging;
use crate::asset::{self, resource};
use crate::bake::apply::{content_hash, file_candidates, output_name, Names, NewFile};
use crate::bake::plan::BakePlan;
use crate::bake::{Baked, OutputId, StoredFile};

/// File names claimed in one run, across files (several assets may write into one folder),
/// each with the hash and length of what it holds. Names carry a hash of their content, so two
/// files claiming one name mean the same bytes, whichever claims first.
#[derive(Default)]
pub struct Claims {
    claimed: Mutex<HashMap<PathBuf, (String, usize)>>,
}

/// The names one output may use: not a file the document references, not the document
/// itself, and either new or already holding exactly the bytes to be written.
pub(crate) struct FileNames<'a> {
    claims: &'a Claims,
    dir: PathBuf,
    taken: HashSet<PathBuf>,
    /// The new files this output writes, by content (hash and length): identical bytes baked
    /// for two slots are one file.
    written: HashMap<(String, usize), String>,
}

impl<'a> FileNames<'a> {
    /// The names free next to `output` for new images of `asset` (read from `input`, its
    /// resources relocated by `relocation`).
    pub(crate) fn next_to(
        claims: &'a Claims,
        asset: &asset::Asset,
        input: &Path,
        output: &Path,
        relocation: &Relocation,
    ) -> FileNames<'a> {
        let taken: HashSet<PathBuf> = ["buffers", "images"]
            .iter()
            .flat_map(|kind| crate::document::elements(asset.root().get(*kind)))
            .filter_map(|item| item.get("uri").and_then(|u| u.as_str()))
            .filter_map(|uri| match resource::resolve(&uri, asset.base_dir(), "") {
                Ok(resource::Location::File(p)) => Some(identity(&p)),
                _ => None,
            })
            .chain(relocation.copies.iter().map(|c| identity(&c.to)))
            .chain([identity(output), identity(input)])
            .collect();
        FileNames {
            claims,
            dir: folder_of(output).to_path_buf(),
            taken,
            written: HashMap::new(),
        }
    }

    /// The folder new files go to.
    pub(crate) fn dir(&self) -> &Path {
        &self.dir
    }
}

impl Names for FileNames<'_> {
    fn claim(&mut self, name: &str, bytes: &[u8]) -> bool {
        let path = identity(&self.dir.join(name));
        if self.taken.contains(&path) {
            return false;
        }
        let mut claimed = self
            .claims
            .claimed
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let held = (content_hash(bytes), bytes.len());
        if let Some(existing) = claimed.get(&path) {
            return *existing == held;
        }
        if path.exists() && std::fs::read(&path).map_or(true, |b| b != bytes) {
            return false;
        }
        claimed.insert(path.clone(), held);
        self.taken.insert(path);
        true
    }
}

/// What [`file_sink`] returns: a [`Sink`](crate::bake::Sink) it owns.
pub(crate) type FileSink<'s> = Box<dyn Fn(OutputId, &mut Baked) -> Result<(), String> + Sync + 's>;

/// A [`Sink`](crate::bake::Sink) that stages each output as a file into `dir` as soon as it is encoded
/// (named from the source image, the slots and a hash of the bytes, claimed through `names`)
/// and drops its bytes. Only for a .gltf whose new images are files.
pub(crate) fn file_sink<'s, 'c: 's>(
    names: &'s Mutex<FileNames<'c>>,
    images: &'s Value,
    plan: &'s BakePlan,
    staging: &'s Staging,
) -> FileSink<'s> {
    Box::new(move |id, baked| {
        // A run asked to stop writes no further texture; what the file staged is dropped.
        interrupt::check()?;
        let Some((format, bytes)) = baked.encoded.take() else {
            return Ok(());
        };
        let name = output_name(images, &plan.outputs[id.0]);
        let content = (content_hash(&bytes), bytes.len());
        let (dir, file, new) = {
            let mut names = names.lock().unwrap_or_else(|e| e.into_inner());
            // The same bytes already written for this output (another slot's bake came out
            // identical): one file, named by both. Equal hash and length are taken for equal
            // bytes, as the run's name claims take them.
            match names.written.get(&content).cloned() {
                Some(file) => (names.dir().to_path_buf(), file, false),
                None => {
                    let file = file_candidates(&name, format, &bytes)
                        .find(|candidate| names.claim(candidate, &bytes))
                        .expect("some name is free");
                    names.written.insert(content, file.clone());
                    (names.dir().to_path_buf(), file, true)
                }
            }
        };
        if new {
            staging.stage_bytes(&dir, &file, &bytes)?;
        }
        baked.stored = Some(StoredFile {
            name: file,
            format,
            bytes: bytes.len(),
        });
        Ok(())
    })
}

/// Stages new image files for `dir` (one already holding the bytes is left).
pub(crate) fn stage_new_files(
    dir: &Path,
    files: &[NewFile],
    staging: &Staging,
) -> Result<(), String> {
    for file in files {
        staging.stage_bytes(dir, &file.name, &file.bytes)?;
    }
    Ok(())
}

/// Creates the folder `path` goes in, if it has one.
pub(crate) fn create_parent(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create folder {}: {e}", dir.display())),
        _ => Ok(()),
    }
}

/// Places a relocation's resource copies that the written document `json` still names (each a
/// regular file of its own, cloned or copied atomically from the resolved source), for migrate
/// and bake alike.
pub(crate) fn copy_resources<'a>(
    relocation: &Relocation,
    json: impl crate::asset::tape::JsonView<'a>,
    staging: &Staging,
) -> Result<(), String> {
    let used = relative_uris(json);
    let mut copies = Vec::new();
    for copy in relocation
        .copies
        .iter()
        .filter(|c| used.iter().any(|u| u.as_ref() == c.uri.as_str()))
    {
        let from = copy
            .from
            .canonicalize()
            .map_err(|e| format!("cannot read resource {}: {e}", copy.from.display()))?;
        create_parent(&copy.to)?;
        copies.push((from, copy.to.as_path()));
    }
    staging.stage_copies(&copies)
}
