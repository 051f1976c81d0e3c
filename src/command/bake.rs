//! `velvet bake` over many files, with the output rules it shares with `velvet migrate`
//! ([`crate::output::paths`] pairs inputs with outputs and refuses a bad request before
//! anything is read, and relocates the relative URIs of an output written to another folder):
//! each file is loaded, planned, baked, applied and written independently and in parallel.
//! One failing file does not stop the others; nothing is written for a file that fails, and
//! every write is atomic (a temporary file renamed into place). An input is never written
//! unless `--in-place` is asked, and a file with nothing to bake is copied byte for byte (or,
//! in place, not written at all). A file the loader reports errors for is not baked.

use std::borrow::Cow;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde::Serialize;
use serde_json::Value;

use crate::asset;
use crate::asset::discover::Shard;
use crate::bake::apply::{apply, ApplyOptions, OutputReport};
use crate::bake::codec::{EncodeOptions, PngCompression};
use crate::bake::engine::{bake_into, BakeOptions, MaxImagePixels};
use crate::bake::kernel::KernelOptions;
use crate::bake::plan::{plan, BakePlan, Note, PlanOptions};
use crate::bake::prune::Dropped;
use crate::edit::write;
use crate::output::files::{copy_resources, create_parent, file_sink, stage_new_files};
use crate::output::files::{Claims, FileNames};
use crate::output::interrupt;
use crate::output::paths::{check_links, relocate, Destination, Job, Relocation};
use crate::output::result::{Account, Totals};
use crate::output::staging::Staging;
use crate::output::summary::{added, bytes, files_line, plural, Detail};
use crate::output::{load_input, run_each, Input, Scope, UsageError};
use crate::report::escape::push_line;

/// What a run does besides where it writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Options {
    /// Planning choices.
    pub plan: PlanOptions,
    /// .gltf: embed new images as `data:` URIs.
    pub embed: bool,
    /// Turn textures whose texels are all equal after baking into factors.
    pub collapse_uniform: bool,
    /// Keep JPEG as JPEG instead of lossless PNG.
    pub keep_format: bool,
    /// Measure each output's quantisation error.
    pub report: bool,
    /// PNG compression effort.
    pub png: PngCompression,
    /// An output in another folder refers back to the input's resources (URIs rewritten)
    /// instead of getting its own copies (the default: a self-contained output).
    pub rewrite_uris: bool,
    /// Limits and URI policy for reading inputs and their images.
    pub load: asset::LoadOptions,
}

/// One `velvet bake` invocation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Request {
    /// Files and folders (walked for .gltf and .glb).
    pub inputs: Vec<PathBuf>,
    /// Where outputs go.
    pub destination: Destination,
    /// Plan and report; write nothing.
    pub dry_run: bool,
    /// Everything else.
    pub options: Options,
    /// Draw a progress bar on a terminal.
    pub progress: bool,
}

/// What became of one file: the outcome `velvet migrate` reports too.
pub use crate::output::Outcome;

/// One baked slot, for reports.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlotReport {
    /// Material index.
    pub material: usize,
    /// Pointer to the textureInfo.
    pub pointer: String,
    /// The factor baked in.
    pub factor: Vec<f64>,
    /// The outputs it reads (names).
    pub outputs: Vec<String>,
}

/// What `velvet bake` says of one file besides its outcome.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BakeDetail {
    /// Slots baked (or planned).
    pub slots: Vec<SlotReport>,
    /// Outputs written (empty in a dry run).
    pub outputs: Vec<OutputReport>,
    /// Images dropped (indices in the input).
    pub dropped_images: Vec<usize>,
    /// Bytes cut from the GLB BIN chunk.
    pub dropped_bin_bytes: usize,
    /// Remarks.
    pub notes: Vec<Note>,
}

impl Account for BakeDetail {
    fn added(&self, outcome: &Outcome) -> (usize, usize) {
        if matches!(outcome, Outcome::Planned { .. }) {
            // Slots that share a combination share its output.
            let planned = self.slots.iter().flat_map(|s| &s.outputs);
            return (planned.collect::<HashSet<_>>().len(), 0);
        }
        let written = self.outputs.iter().filter(|o| o.image.is_some());
        (written.clone().count(), written.map(|o| o.bytes).sum())
    }

    fn warnings(&self) -> usize {
        self.notes
            .iter()
            .filter(|n| n.level == crate::bake::plan::Level::Warning)
            .count()
    }
}

/// The report for one file.
pub type FileResult = crate::output::result::FileResult<BakeDetail>;

fn file_result(input: &Path, output: Option<&Path>, outcome: Outcome) -> FileResult {
    FileResult {
        input: input.to_path_buf(),
        output: output.map(Path::to_path_buf),
        outcome,
        detail: BakeDetail::default(),
    }
}

fn slot_reports(plan: &BakePlan, names: &[String]) -> Vec<SlotReport> {
    plan.slots
        .iter()
        .map(|s| SlotReport {
            material: s.material,
            pointer: s.texture_pointer(),
            factor: s.factor.clone(),
            outputs: s
                .sources
                .iter()
                .map(|src| names[src.output.0].clone())
                .collect(),
        })
        .collect()
}

/// Bakes one file; errors name what is wrong (the caller adds the file).
fn bake_file(job: &Job, request: &Request, claims: &Claims) -> Result<FileResult, String> {
    interrupt::check()?;
    let input = job.input.as_path();
    let options = request.options;
    let Input {
        mut asset,
        bytes,
        snapshot,
    } = load_input(input, &options.load, "baked")?;
    check_links(&asset)?;
    let plan = plan(&asset, options.plan);
    let planned_names: Vec<String> = plan
        .outputs
        .iter()
        .map(|o| format!("image {}: {}", o.image, o.labels.join(" + ")))
        .collect();
    let relocation = match &job.output {
        Some(output) if output != &job.input => relocate(&asset, output, options.rewrite_uris)?,
        _ => Relocation::default(),
    };
    if request.dry_run {
        let mut result = file_result(
            input,
            job.output.as_deref(),
            Outcome::Planned {
                changes: !plan.is_empty(),
            },
        );
        result.detail.slots = slot_reports(&plan, &planned_names);
        result.detail.notes = plan.notes;
        return Ok(result);
    }
    let output = job.output.as_deref().ok_or("no output path")?;
    if plan.is_empty() {
        let mut result = file_result(input, Some(output), Outcome::Untouched);
        result.detail.notes = plan.notes;
        if output == input {
            return Ok(result);
        }
        interrupt::check()?;
        let staging = Staging::default();
        copy_resources(&relocation, asset.json(), &staging)?;
        create_parent(output)?;
        let out_bytes = if relocation.edits.is_empty() {
            Cow::Borrowed(match &bytes {
                Some(bytes) => &bytes[..],
                None => asset.file_bytes().unwrap_or_default(),
            })
        } else {
            let mut json = asset.take_json();
            crate::edit::apply(&mut json, &relocation.edits).map_err(|e| e.to_string())?;
            Cow::Owned(write::to_bytes(&asset, &json, asset.bin.as_deref()))
        };
        staging.stage_document(output, &write::Output::Bytes(out_bytes))?;
        snapshot.unchanged(input)?;
        staging.commit()?;
        result.outcome = Outcome::Copied;
        return Ok(result);
    }
    drop(bytes);
    let bake_options = BakeOptions {
        keep_format: options.keep_format,
        collapse_uniform: options.collapse_uniform,
        kernel: KernelOptions {
            exact: false,
            measure: options.report,
        },
        encode: EncodeOptions {
            png: options.png,
            ..EncodeOptions::default()
        },
        max_image_pixels: MaxImagePixels(options.load.max_image_pixels),
        max_memory: crate::bake::engine::MaxMemory(options.load.max_memory),
    };
    // File names next to the output that the document already uses are not free. New image
    // files are written as they are encoded (a .gltf with file images), so a run holds only
    // the images in flight.
    interrupt::check()?;
    let staging = Staging::default();
    let names = Mutex::new(FileNames::next_to(
        claims,
        &asset,
        input,
        output,
        &relocation,
    ));
    let images = asset.json().get("images").cloned().unwrap_or(Value::Null);
    let streamed = asset.container == asset::Container::Gltf && !options.embed;
    let mut baked = Vec::with_capacity(plan.recipes.len());
    let results = {
        let sink = file_sink(&names, &images, &plan, &staging);
        bake_into(
            &plan.recipes,
            &asset,
            &bake_options,
            streamed.then_some(&*sink as crate::bake::Sink),
        )
    };
    for (name, result) in planned_names.iter().zip(results) {
        baked.push(result.map_err(|e| format!("cannot bake {name}: {e}"))?);
    }
    let mut names = names.into_inner().unwrap_or_else(|e| e.into_inner());
    let out_dir = names.dir().to_path_buf();
    // The document as it will stand next to the output.
    let mut json = asset.take_json();
    crate::edit::apply(&mut json, &relocation.edits).map_err(|e| e.to_string())?;
    let bin = asset.bin.take();
    let applied = apply(
        json,
        bin,
        asset.container,
        &plan,
        &mut baked,
        ApplyOptions {
            embed: options.embed,
        },
        &mut names,
    );
    copy_resources(&relocation, &applied.json, &staging)?;
    stage_new_files(&out_dir, &applied.files, &staging)?;
    let out_bytes = write::to_bytes(&asset, &applied.json, applied.bin.as_deref());
    staging.stage_document(output, &write::Output::Bytes(out_bytes.into()))?;
    snapshot.unchanged(input)?;
    staging.commit()?;
    let names: Vec<String> = applied.outputs.iter().map(|o| o.name.clone()).collect();
    let mut result = file_result(input, Some(output), Outcome::Changed);
    result.detail.slots = slot_reports(&plan, &names);
    result.detail.outputs = applied.outputs;
    let Dropped {
        images, bin_bytes, ..
    } = applied.dropped;
    result.detail.dropped_images = images;
    result.detail.dropped_bin_bytes = bin_bytes;
    result.detail.notes = plan.notes.into_iter().chain(applied.notes).collect();
    Ok(result)
}

/// Runs a request: every file in parallel; folders that cannot be read become failed results.
pub fn run(request: &Request) -> Result<Vec<FileResult>, UsageError> {
    run_shard(request, None)
}

/// Runs like [`run`] over the files of one shard only (see [`Shard`]).
pub fn run_shard(request: &Request, shard: Option<Shard>) -> Result<Vec<FileResult>, UsageError> {
    let scope = Scope {
        inputs: &request.inputs,
        destination: &request.destination,
        dry_run: request.dry_run,
        shard,
        progress: request.progress,
    };
    run_each(
        &scope,
        |path, e| {
            file_result(
                &path,
                None,
                Outcome::Failed {
                    error: format!("cannot read folder: {e}"),
                },
            )
        },
        |job, claims| {
            bake_file(job, request, claims).unwrap_or_else(|error| {
                file_result(&job.input, job.output.as_deref(), Outcome::Failed { error })
            })
        },
    )
}

/// Totals over a run: those every file command counts, and the slots baked.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Summary {
    #[serde(flatten)]
    pub totals: Totals,
    /// Slots baked (or planned).
    pub slots: usize,
}

/// Sums up results.
pub fn summary(results: &[FileResult]) -> Summary {
    Summary {
        totals: Totals::of(results),
        slots: results
            .iter()
            .filter(|r| !r.is_failed())
            .map(|r| r.detail.slots.len())
            .sum(),
    }
}

/// The text report, worded as `velvet migrate`'s: a line per file (slots, textures added,
/// warnings), the slots and outputs under it when verbose, failed files only when quiet, then
/// the summary.
pub fn render_text(results: &[FileResult], dry_run: bool, detail: Detail) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    for r in results {
        if detail == Detail::Quiet && !r.is_failed() {
            continue;
        }
        let target = r
            .output
            .as_ref()
            .filter(|o| **o != r.input)
            .map(|o| format!(" → {}", o.display()))
            .unwrap_or_default();
        let warnings = r.detail.warnings();
        let (textures, added_bytes) = r.added();
        let counts = format!(
            " ({}, {}, {})",
            plural(r.detail.slots.len(), "slot", "slots"),
            added(textures, added_bytes, dry_run),
            plural(warnings, "warning", "warnings")
        );
        let warned = if warnings > 0 {
            format!(" ({})", plural(warnings, "warning", "warnings"))
        } else {
            String::new()
        };
        let status = match &r.outcome {
            Outcome::Changed => format!("baked{counts}"),
            Outcome::Copied => format!("nothing to bake, copied as it is{warned}"),
            Outcome::Untouched => format!("nothing to bake, left as it is{warned}"),
            Outcome::Planned { changes: true } => format!("would bake{counts}"),
            Outcome::Planned { changes: false } => format!("nothing to bake{warned}"),
            Outcome::Failed { error } => format!("FAILED: {error}"),
        };
        push_line(
            &mut out,
            &format!("{}{target}: {status}", r.input.display()),
        );
        if detail != Detail::Verbose {
            continue;
        }
        for s in &r.detail.slots {
            push_line(
                &mut out,
                &format!(
                    "  {}: factor {:?} -> {}",
                    s.pointer,
                    s.factor,
                    s.outputs.join(", ")
                ),
            );
        }
        for o in &r.detail.outputs {
            let mut line = format!(
                "  output {}: {}x{} {}-bit {}, {}, {}",
                o.name,
                o.width,
                o.height,
                o.bits,
                o.mime_type.unwrap_or("-"),
                o.stored,
                bytes(o.bytes)
            );
            if let Some(e) = o.max_error {
                let verdict = if e <= 0.5 + 1e-9 {
                    "within the half code rounding allows"
                } else {
                    "more than rounding alone"
                };
                let _ = write!(line, ", max error {e:.4} codes, {verdict}");
            }
            if o.clamped > 0 {
                let _ = write!(
                    line,
                    ", {} texels clamped to the channel's range",
                    o.clamped
                );
            }
            push_line(&mut out, &line);
        }
        if !r.detail.dropped_images.is_empty() {
            push_line(
                &mut out,
                &format!(
                    "  dropped images {:?} ({} cut from the BIN chunk)",
                    r.detail.dropped_images,
                    bytes(r.detail.dropped_bin_bytes)
                ),
            );
        }
        for n in &r.detail.notes {
            let level = match n.level {
                crate::bake::plan::Level::Info => "info",
                crate::bake::plan::Level::Warning => "warning",
            };
            push_line(&mut out, &format!("  {level} {}: {}", n.pointer, n.message));
        }
    }
    if detail == Detail::Quiet {
        return out;
    }
    let s = summary(results).totals;
    let _ = writeln!(
        out,
        "{}; {}",
        files_line(
            s.files,
            s.done(),
            if dry_run { "would bake" } else { "baked" },
            s.unchanged,
            s.failed
        ),
        added(s.textures_added, s.bytes_added, dry_run)
    );
    out
}

/// The JSON report.
pub fn render_json(results: &[FileResult]) -> String {
    let report = serde_json::json!({
        "files": results,
        "summary": summary(results),
    });
    serde_json::to_string_pretty(&report).expect("reports serialise") + "\n"
}

/// How a bake run is shown besides what it writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct View {
    pub format: super::ReportFormat,
    pub detail: Detail,
}

/// Runs `velvet bake`: the files of `shard`, then the report on standard output.
pub fn command(request: &Request, shard: Option<Shard>, view: View) -> super::Status {
    // Before anything is read or written: a signal from here on stops the run cleanly.
    interrupt::install();
    // A list that names no asset (a change that touched none) is nothing to do, not an error.
    let results = if request.inputs.is_empty() {
        Vec::new()
    } else {
        match run_shard(request, shard) {
            Ok(r) => r,
            Err(e) => return super::usage_error(e),
        }
    };
    if let Some(stopped) = super::stopped(results.iter().map(|r| !r.is_failed())) {
        return stopped;
    }
    super::emit(
        match view.format {
            super::ReportFormat::Text => render_text(&results, request.dry_run, view.detail),
            super::ReportFormat::Json => render_json(&results),
        }
        .as_bytes(),
    );
    super::Status::failed_if(results.iter().any(|r| r.is_failed()))
}
