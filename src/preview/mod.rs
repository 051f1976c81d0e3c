//! `velvet preview`: contact sheets that show, per material that has or gets a sheen or fuzz
//! layer, the material as authored, as migrated (fuzz with the fitted and with the copied
//! roughness) and as a loader without KHR_materials_fuzz sees it, under a white furnace and a
//! directional light, with the difference image, the report's figures and a verdict; and an
//! index page (`index.html`) that links them for a whole file or folder.
//!
//! This module owns the previews from reading a material to writing its PNG: [`material`]
//! reads a material's values and decides the columns (what migrate would produce),
//! [`shade`] shades a sphere exactly from `shading`'s formulas, [`sheet`] lays out and encodes a
//! sheet with the built-in [`font`], and [`index`] writes the HTML index. [`render`] is pure
//! (files in, images and words out) and runs the materials of a whole library in parallel;
//! [`write()`] alone touches the output folder, every file through `edit::write::write_atomic`.
//! The same inputs give the same bytes at any thread count: every value is computed by one
//! task from its inputs alone, and names come from the inputs.

pub mod font;
pub mod index;
pub mod material;
pub mod shade;
pub mod sheet;

use crate::asset::discover;
use crate::edit::write::write_atomic;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// One sheet ready to be written.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    /// The asset it comes from.
    pub file: PathBuf,
    /// The PNG's file name inside the output folder.
    pub name: String,
    pub png: Vec<u8>,
    pub summary: sheet::Summary,
}

/// A file that could not be previewed, with the reason.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    pub file: PathBuf,
    pub message: String,
}

/// Everything a run produces before anything is written.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Previews {
    pub sheets: Vec<Rendered>,
    /// Files read that have no material with a sheen or fuzz layer.
    pub without_layers: Vec<PathBuf>,
    pub failures: Vec<Failure>,
}

/// The label of an asset in titles and file names: its path relative to the folder it was
/// found under, or its file name when it was named itself.
fn label(found: &discover::Found, inputs: &[PathBuf]) -> String {
    let input = &inputs[found.input];
    let rel = if input.is_dir() {
        found.path.strip_prefix(input).unwrap_or(&found.path)
    } else {
        Path::new(found.path.file_name().unwrap_or(found.path.as_os_str()))
    };
    rel.to_string_lossy().replace('\\', "/")
}

/// `text` reduced to letters, digits, '-' and '_' (others become '_'), at most `max` chars.
fn file_safe(text: &str, max: usize) -> String {
    text.chars()
        .take(max)
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Reads every asset under `inputs` and renders the sheets of their materials, in parallel;
/// writes nothing. Each asset's migration is planned with `options` (`velvet preview`: the
/// defaults; `migrate --preview`: the run's), and the sheets show what that plan writes.
/// Sheets come in input order, then document order.
pub fn render(inputs: &[PathBuf], options: &crate::migrate::Options) -> Previews {
    let (found, walk_errors) = discover::find(inputs, None);
    let mut previews = Previews::default();
    for (path, e) in walk_errors {
        previews.failures.push(Failure {
            file: path,
            message: format!("cannot read this folder: {e}"),
        });
    }
    // Load and read the materials of each file (in parallel over files).
    let files: Vec<(PathBuf, String, Result<Vec<material::Material>, String>)> = found
        .par_iter()
        .map(|f| {
            let loaded = crate::asset::load_with(&f.path, &options.load);
            let result = match loaded.asset {
                Some(asset) => {
                    let plan = crate::migrate::plan_document(&asset, options);
                    Ok(material::materials(&asset, &plan, options.roughness))
                }
                None => Err(loaded
                    .diagnostics
                    .iter()
                    .map(|d| d.message.clone())
                    .collect::<Vec<_>>()
                    .join("; ")),
            };
            (f.path.clone(), label(f, inputs), result)
        })
        .collect();
    let mut jobs = Vec::new();
    for (path, label, result) in files {
        match result {
            Err(message) => previews.failures.push(Failure {
                file: path,
                message: if message.is_empty() {
                    "cannot be read".into()
                } else {
                    message
                },
            }),
            Ok(materials) if materials.is_empty() => previews.without_layers.push(path),
            Ok(materials) => jobs.extend(
                materials
                    .into_iter()
                    .map(|m| (path.clone(), label.clone(), m)),
            ),
        }
    }
    previews.sheets = jobs
        .par_iter()
        .map(|(path, label, m)| {
            let sheet = sheet::render(label, m);
            let stem = label
                .rsplit_once('.')
                .map_or(label.as_str(), |(stem, _)| stem);
            let mut name = format!("{}-m{}", file_safe(stem, 80), m.index);
            if let Some(n) = &m.name {
                name += "-";
                name += &file_safe(n, 40);
            }
            name += ".png";
            Rendered {
                file: path.clone(),
                name,
                png: sheet::to_png(&sheet),
                summary: sheet.summary,
            }
        })
        .collect();
    // Two assets may reduce to one name (a/x.gltf and a_x.gltf, or x.gltf in two folders
    // given): later ones get -2, -3, … in input order.
    let mut used = std::collections::HashSet::new();
    for sheet in &mut previews.sheets {
        let stem = sheet.name.trim_end_matches(".png").to_string();
        let mut k = 1;
        while !used.insert(sheet.name.clone()) {
            k += 1;
            sheet.name = format!("{stem}-{k}.png");
        }
    }
    previews
}

/// Writes the sheets and `index.html` into `out_dir` (created if needed), each atomically.
/// Returns the paths written, in order, or the first write that failed.
pub fn write(previews: &Previews, out_dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create the folder {}: {e}", out_dir.display()))?;
    let mut written = Vec::new();
    for sheet in &previews.sheets {
        let path = out_dir.join(&sheet.name);
        write_atomic(&path, &sheet.png)
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        written.push(path);
    }
    let path = out_dir.join("index.html");
    write_atomic(&path, index::html(previews).as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    written.push(path);
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_keep_letters_digits_and_dashes_only() {
        assert_eq!(file_safe("a b/c-d_é.png", 80), "a_b_c-d___png");
        assert_eq!(file_safe("abcdef", 3), "abc");
    }
}
