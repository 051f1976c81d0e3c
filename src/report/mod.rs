//! Renderers for validation reports: human text and the Khronos glTF-Validator JSON shape
//! (one report, an array, or JSON lines). Renderers only format; they decide nothing.

pub mod json;
pub mod text;

use std::path::Path;

/// A path as reports show it: relative to the working directory when it lies below it, with
/// forward slashes.
pub fn display_path(path: &Path) -> String {
    let shown = std::env::current_dir()
        .ok()
        .and_then(|cwd| path.strip_prefix(&cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf());
    shown.to_string_lossy().replace('\\', "/")
}
