//! `velvet preview` as the command line runs it: the sheets of every sheen or fuzz material
//! of the inputs, drawn from migrate's plan with its default options, written into a folder
//! with an index, and a line per sheet.

use super::Status;
use crate::asset::{discover, LoadOptions};
use std::path::{Path, PathBuf};

/// Renders and writes the sheets of `inputs` into `output`; `quiet` prints nothing but errors.
pub fn command(inputs: &[PathBuf], output: &Path, load: LoadOptions, quiet: bool) -> Status {
    if let Err(e) = discover::check_inputs(inputs) {
        return super::usage_error(e);
    }
    let previews = crate::preview::render(
        inputs,
        &crate::migrate::Options {
            load,
            ..crate::migrate::Options::default()
        },
    );
    let mut failed = !previews.failures.is_empty();
    for f in &previews.failures {
        eprintln!("velvet: {}: {}", f.file.display(), f.message);
    }
    match crate::preview::write(&previews, output) {
        Ok(written) => {
            if !quiet {
                let mut out = String::new();
                for (sheet, path) in previews.sheets.iter().zip(&written) {
                    out += &format!(
                        "{}: {} ({})\n",
                        path.display(),
                        sheet.summary.title,
                        sheet.summary.verdict.text()
                    );
                }
                for f in &previews.without_layers {
                    out += &format!("{}: no material with a sheen or fuzz layer\n", f.display());
                }
                if let Some(index) = written.last() {
                    out += &format!(
                        "{} sheet(s); index: {}\n",
                        previews.sheets.len(),
                        index.display()
                    );
                }
                super::emit(out.as_bytes());
            }
        }
        Err(e) => {
            eprintln!("velvet: {e}");
            failed = true;
        }
    }
    Status::failed_if(failed)
}
