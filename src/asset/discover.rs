//! Finding the assets to work on: files named on the command line are taken as they are;
//! folders are walked recursively for `*.gltf` and `*.glb` (case-insensitive), in sorted order,
//! without following links to folders (so a link loop cannot hang a run). A link named like an
//! asset whose target is missing is kept, so that the loader reports it rather than the run
//! skipping it in silence; so is a file that vanishes between the walk and its loading.

use std::io;
use std::path::{Path, PathBuf};

/// True for a path whose extension is .gltf or .glb.
pub fn is_asset_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// The asset files under `inputs`. Folders that cannot be read are returned with their error.
pub fn collect(inputs: &[PathBuf]) -> (Vec<PathBuf>, Vec<(PathBuf, io::Error)>) {
    let mut files = Vec::new();
    let mut errors = Vec::new();
    for input in inputs {
        if input.is_dir() {
            walk(input, &mut files, &mut errors);
        } else {
            // A named file is taken whatever its name; a missing one is reported by the loader.
            files.push(input.clone());
        }
    }
    (files, errors)
}

fn walk(dir: &Path, files: &mut Vec<PathBuf>, errors: &mut Vec<(PathBuf, io::Error)>) {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) => {
            errors.push((dir.to_path_buf(), e));
            return;
        }
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for path in paths {
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            walk(&path, files, errors);
        } else if is_asset_path(&path)
            && (meta.is_file()
                || (meta.is_symlink() && std::fs::metadata(&path).map_or(true, |m| m.is_file())))
        {
            files.push(path);
        }
    }
}
