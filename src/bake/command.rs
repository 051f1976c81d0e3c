//! `velvet bake` over many files: pairs inputs with outputs (`-o`, `--out-dir`, `--in-place`,
//! or a dry run), refuses a bad request before anything is read, then loads, plans, bakes,
//! applies and writes each file independently and in parallel. One failing file does not stop
//! the others; nothing is written for a file that fails, and every write is atomic (a temporary
//! file renamed into place). An input is never written unless `--in-place` is asked, and a file
//! with nothing to bake is copied byte for byte (or, in place, not written at all).

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::io::IsTerminal;
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::Serialize;
use serde_json::Value;

use super::apply::{apply, ApplyOptions, Names, OutputReport};
use super::codec::{EncodeOptions, PngCompression};
use super::engine::{bake, BakeOptions, ImageSource};
use super::kernel::KernelOptions;
use super::plan::{plan, BakePlan, Note, PlanOptions};
use super::prune::Dropped;
use super::recipe::ImageId;
use crate::asset::{self, discover, resource, write, Asset, Container};

/// Where outputs go.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// Nowhere: only with `dry_run`.
    None,
    /// Over each input.
    InPlace,
    /// One output file for one input file.
    File(PathBuf),
    /// A folder mirroring the inputs' trees.
    Dir(PathBuf),
}

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

/// A request that cannot run.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum UsageError {
    /// No input.
    #[error("no input files")]
    NoInputs,
    /// Neither an output nor a dry run.
    #[error("say where outputs go: -o FILE, --out-dir DIR or --in-place (or --dry-run)")]
    NoDestination,
    /// `-o` for several inputs.
    #[error("-o names one output but {0} inputs were given; use --out-dir")]
    OutputForMany(usize),
    /// `-o` for a folder.
    #[error("-o names one output but {0} is a folder; use --out-dir")]
    OutputForFolder(String),
    /// An output that is an input.
    #[error("the output {output} is the input {input}; use --in-place to overwrite inputs")]
    OutputIsInput {
        /// The output.
        output: String,
        /// The input it equals.
        input: String,
    },
    /// Two inputs to one output.
    #[error("{first} and {second} would both be written to {output}")]
    OutputCollision {
        /// The output.
        output: String,
        /// One input.
        first: String,
        /// Another input.
        second: String,
    },
    /// `-o` with another container.
    #[error("{input} is a {container} file; the output {output} must end in .{extension}")]
    ContainerMismatch {
        /// The input.
        input: String,
        /// The output.
        output: String,
        /// GLB or .gltf.
        container: &'static str,
        /// The extension the output needs.
        extension: &'static str,
    },
}

/// What became of one file.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "status", rename_all = "kebab-case")]
pub enum Outcome {
    /// Baked and written.
    Changed,
    /// Nothing to bake: the input's bytes were written to the output.
    Copied,
    /// Nothing to bake in place: not written.
    Untouched,
    /// Dry run.
    Planned {
        /// Whether a real run would change the file.
        changes: bool,
    },
    /// Not baked; nothing written for it.
    Failed {
        /// Why.
        error: String,
    },
}

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

/// The report for one file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FileResult {
    /// The input.
    pub input: PathBuf,
    /// The output, if any.
    pub output: Option<PathBuf>,
    /// What happened.
    #[serde(flatten)]
    pub outcome: Outcome,
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

impl FileResult {
    fn new(input: &Path, output: Option<&Path>, outcome: Outcome) -> FileResult {
        FileResult {
            input: input.to_path_buf(),
            output: output.map(Path::to_path_buf),
            outcome,
            slots: Vec::new(),
            outputs: Vec::new(),
            dropped_images: Vec::new(),
            dropped_bin_bytes: 0,
            notes: Vec::new(),
        }
    }

    /// Whether the file failed.
    pub fn failed(&self) -> bool {
        matches!(self.outcome, Outcome::Failed { .. })
    }
}

/// The absolute form of a path with links resolved as far as it exists, so that two
/// spellings of one file compare equal.
fn identity(path: &Path) -> PathBuf {
    if let Ok(c) = path.canonicalize() {
        return c;
    }
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    while let (Some(parent), Some(name)) = (existing.parent(), existing.file_name()) {
        rest.push(name.to_os_string());
        existing = parent;
        if let Ok(c) = existing.canonicalize() {
            return rest.iter().rev().fold(c, |p, n| p.join(n));
        }
    }
    absolute
}

fn container_extension(path: &Path) -> Option<&'static str> {
    match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "gltf" => Some("gltf"),
        "glb" => Some("glb"),
        _ => None,
    }
}

/// Input files paired with their outputs (none in a dry run without a destination).
pub type Jobs = Vec<(PathBuf, Option<PathBuf>)>;

/// Folders that could not be read, with the error.
pub type WalkErrors = Vec<(PathBuf, std::io::Error)>;

/// Every input file with its output, or the reason the request cannot run.
pub fn jobs(request: &Request) -> Result<(Jobs, WalkErrors), UsageError> {
    let inputs = &request.inputs;
    let destination = &request.destination;
    if inputs.is_empty() {
        return Err(UsageError::NoInputs);
    }
    if *destination == Destination::None && !request.dry_run {
        return Err(UsageError::NoDestination);
    }
    if let Destination::File(output) = destination {
        if inputs.len() != 1 {
            return Err(UsageError::OutputForMany(inputs.len()));
        }
        if inputs[0].is_dir() {
            return Err(UsageError::OutputForFolder(inputs[0].display().to_string()));
        }
        if let Some(extension) = container_extension(&inputs[0]) {
            if container_extension(output) != Some(extension) {
                return Err(UsageError::ContainerMismatch {
                    input: inputs[0].display().to_string(),
                    output: output.display().to_string(),
                    container: if extension == "glb" { "GLB" } else { ".gltf" },
                    extension,
                });
            }
        }
    }
    let mut jobs = Vec::new();
    let mut walk_errors = Vec::new();
    for input in inputs {
        let (files, errors) = discover::collect(std::slice::from_ref(input));
        walk_errors.extend(errors);
        for file in files {
            let output = match destination {
                Destination::None => None,
                Destination::InPlace => Some(file.clone()),
                Destination::File(output) => Some(output.clone()),
                Destination::Dir(dir) => Some(match file.strip_prefix(input) {
                    Ok(relative) if !relative.as_os_str().is_empty() => dir.join(relative),
                    _ => dir.join(file.file_name().unwrap_or(file.as_os_str())),
                }),
            };
            jobs.push((file, output));
        }
    }
    if *destination != Destination::InPlace {
        let by_identity: HashMap<PathBuf, &Path> = jobs
            .iter()
            .map(|(i, _)| (identity(i), i.as_path()))
            .collect();
        for (_, output) in &jobs {
            let Some(output) = output else { continue };
            if let Some(input) = by_identity.get(&identity(output)) {
                return Err(UsageError::OutputIsInput {
                    output: output.display().to_string(),
                    input: input.display().to_string(),
                });
            }
        }
    }
    let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
    for (input, output) in &jobs {
        let Some(output) = output else { continue };
        if let Some(first) = seen.insert(identity(output), input) {
            return Err(UsageError::OutputCollision {
                output: output.display().to_string(),
                first: first.display().to_string(),
                second: input.display().to_string(),
            });
        }
    }
    Ok((jobs, walk_errors))
}

/// Serves an asset's images to the engine.
struct AssetImages<'a>(&'a Asset);

impl ImageSource for AssetImages<'_> {
    fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String> {
        self.0.image_bytes(image.0).map_err(|d| d.message)
    }
}

/// File names claimed in one run, across files (several assets may write into one folder).
#[derive(Default)]
struct Claims {
    claimed: Mutex<HashMap<PathBuf, Vec<u8>>>,
}

/// The names one output may use: not a file the document references, not the document
/// itself, and either new or already holding exactly the bytes to be written.
struct FileNames<'a> {
    claims: &'a Claims,
    dir: PathBuf,
    taken: HashSet<PathBuf>,
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
        if let Some(existing) = claimed.get(&path) {
            return existing == bytes;
        }
        if path.exists() && std::fs::read(&path).map_or(true, |b| b != bytes) {
            return false;
        }
        claimed.insert(path.clone(), bytes.to_vec());
        self.taken.insert(path);
        true
    }
}

/// Characters kept as they are in a URI path segment.
const SEGMENT: &percent_encoding::AsciiSet = &percent_encoding::NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~');

/// The URI prefix leading from folder `from` to folder `to` ("" when equal, else ending in
/// '/'), or `None` when no relative path joins them.
fn relative_prefix(from: &Path, to: &Path) -> Option<String> {
    let (from, to) = (identity(from), identity(to));
    let from: Vec<Component> = from.components().collect();
    let to: Vec<Component> = to.components().collect();
    if from.first() != to.first() {
        return None;
    }
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut prefix = "../".repeat(from.len() - common);
    for component in &to[common..] {
        let Component::Normal(name) = component else {
            return None;
        };
        prefix +=
            &percent_encoding::utf8_percent_encode(&name.to_string_lossy(), SEGMENT).to_string();
        prefix.push('/');
    }
    Some(prefix)
}

/// Pointers of the document's relative-path URIs (buffers and images), with their values.
fn relative_uris(json: &Value) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for key in ["buffers", "images"] {
        for (i, item) in json
            .get(key)
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .enumerate()
        {
            let Some(uri) = item.get("uri").and_then(Value::as_str) else {
                continue;
            };
            if matches!(
                resource::resolve(uri, Path::new(""), ""),
                Ok(resource::Location::File(_))
            ) {
                out.push((format!("/{key}/{i}/uri"), uri.to_owned()));
            }
        }
    }
    out
}

/// Rewrites the relative URIs of a .gltf written to `out_dir` so that they still lead to the
/// input's resources in `in_dir`. Returns false when no relative path joins the folders.
fn rebase_uris(json: &mut Value, in_dir: &Path, out_dir: &Path, skip: &HashSet<String>) -> bool {
    let uris = relative_uris(json);
    if uris.iter().all(|(_, u)| skip.contains(u)) {
        return true;
    }
    let Some(prefix) = relative_prefix(out_dir, in_dir) else {
        return false;
    };
    if prefix.is_empty() {
        return true;
    }
    for (pointer, uri) in uris {
        if skip.contains(&uri) {
            continue;
        }
        if let Some(v) = json.pointer_mut(&pointer) {
            *v = Value::from(format!("{prefix}{uri}"));
        }
    }
    true
}

fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
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

/// Bakes one file.
fn bake_file(
    input: &Path,
    output: Option<&Path>,
    request: &Request,
    claims: &Claims,
) -> FileResult {
    let fail = |error: String| FileResult::new(input, output, Outcome::Failed { error });
    let loaded = asset::load(input);
    let Some(asset) = loaded.asset else {
        let reasons: Vec<String> = loaded
            .diagnostics
            .iter()
            .map(|d| d.message.clone())
            .collect();
        return fail(format!("cannot load: {}", reasons.join("; ")));
    };
    let options = request.options;
    let plan = plan(&asset, options.plan);
    let planned_names: Vec<String> = plan
        .outputs
        .iter()
        .map(|o| format!("image {}: {}", o.image, o.labels.join(" + ")))
        .collect();
    if request.dry_run {
        let mut result = FileResult::new(
            input,
            output,
            Outcome::Planned {
                changes: !plan.is_empty(),
            },
        );
        result.slots = slot_reports(&plan, &planned_names);
        result.notes = plan.notes;
        return result;
    }
    let output = output.expect("a destination is set outside dry runs");
    let same_place = identity(output) == identity(input);
    let in_dir = folder_of(input);
    let out_dir = folder_of(output);
    if plan.is_empty() {
        let mut result = FileResult::new(input, Some(output), Outcome::Untouched);
        result.notes = plan.notes;
        if same_place {
            return result;
        }
        // A .gltf moved to another folder needs its relative URIs to follow.
        let mut json = asset.json.clone();
        let bytes = if asset.container == Container::Gltf
            && identity(&in_dir) != identity(&out_dir)
            && !relative_uris(&json).is_empty()
        {
            if !rebase_uris(&mut json, &in_dir, &out_dir, &HashSet::new()) {
                return fail(format!(
                    "no relative path leads from {} to the input's resources",
                    out_dir.display()
                ));
            }
            write::to_bytes(&asset, &json, asset.bin.as_deref())
        } else {
            match std::fs::read(input) {
                Ok(b) => b,
                Err(e) => return fail(format!("cannot read: {e}")),
            }
        };
        if let Err(e) =
            std::fs::create_dir_all(&out_dir).and_then(|_| write::write_atomic(output, &bytes))
        {
            return fail(format!("cannot write {}: {e}", output.display()));
        }
        result.outcome = Outcome::Copied;
        return result;
    }
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
    };
    let mut baked = Vec::with_capacity(plan.recipes.len());
    for (i, result) in bake(&plan.recipes, &AssetImages(&asset), &bake_options)
        .into_iter()
        .enumerate()
    {
        match result {
            Ok(b) => baked.push(b),
            Err(e) => {
                return fail(format!(
                    "cannot bake {}: {e}",
                    planned_names.get(i).map_or("an output", String::as_str)
                ))
            }
        }
    }
    // Names the document already uses next to the output.
    let taken: HashSet<PathBuf> = relative_uris(&asset.json)
        .into_iter()
        .filter_map(|(_, uri)| match resource::resolve(&uri, &in_dir, "") {
            Ok(resource::Location::File(p)) => Some(identity(&p)),
            _ => None,
        })
        .chain([identity(output), identity(input)])
        .collect();
    let mut names = FileNames {
        claims,
        dir: out_dir.clone(),
        taken,
    };
    let applied = apply(
        &asset,
        &plan,
        &baked,
        ApplyOptions {
            embed: options.embed,
        },
        &mut names,
    );
    let mut json = applied.json;
    if asset.container == Container::Gltf {
        let new_uris: HashSet<String> =
            json.get("images")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
                .filter_map(|i| i.get("uri").and_then(Value::as_str))
                .filter(|u| {
                    applied.files.iter().any(|f| {
                        percent_encoding::percent_decode_str(u).decode_utf8_lossy() == f.name
                    })
                })
                .map(str::to_owned)
                .collect();
        if !rebase_uris(&mut json, &in_dir, &out_dir, &new_uris) {
            return fail(format!(
                "no relative path leads from {} to the input's resources",
                out_dir.display()
            ));
        }
    }
    let bytes = write::to_bytes(&asset, &json, applied.bin.as_deref());
    if let Err(e) = std::fs::create_dir_all(&out_dir) {
        return fail(format!("cannot create {}: {e}", out_dir.display()));
    }
    for file in &applied.files {
        let path = out_dir.join(&file.name);
        if std::fs::read(&path).is_ok_and(|b| b == file.bytes) {
            continue;
        }
        if let Err(e) = write::write_atomic(&path, &file.bytes) {
            return fail(format!("cannot write {}: {e}", path.display()));
        }
    }
    if let Err(e) = write::write_atomic(output, &bytes) {
        return fail(format!("cannot write {}: {e}", output.display()));
    }
    let names: Vec<String> = applied.outputs.iter().map(|o| o.name.clone()).collect();
    let mut result = FileResult::new(input, Some(output), Outcome::Changed);
    result.slots = slot_reports(&plan, &names);
    result.outputs = applied.outputs;
    let Dropped {
        images, bin_bytes, ..
    } = applied.dropped;
    result.dropped_images = images;
    result.dropped_bin_bytes = bin_bytes;
    result.notes = plan.notes.into_iter().chain(applied.notes).collect();
    result
}

/// Runs a request: every file in parallel; folders that cannot be read become failed results.
pub fn run(request: &Request) -> Result<Vec<FileResult>, UsageError> {
    let (jobs, walk_errors) = jobs(request)?;
    let claims = Claims::default();
    let bar = (request.progress && jobs.len() > 1 && std::io::stderr().is_terminal())
        .then(|| indicatif::ProgressBar::new(jobs.len() as u64));
    let mut results: Vec<FileResult> = walk_errors
        .into_iter()
        .map(|(path, e)| {
            FileResult::new(
                &path,
                None,
                Outcome::Failed {
                    error: format!("cannot read folder: {e}"),
                },
            )
        })
        .collect();
    results.extend(
        jobs.par_iter()
            .map(|(input, output)| {
                let r = bake_file(input, output.as_deref(), request, &claims);
                if let Some(bar) = &bar {
                    bar.inc(1);
                }
                r
            })
            .collect::<Vec<_>>(),
    );
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(results)
}

/// Totals over a run.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Summary {
    /// Files seen.
    pub files: usize,
    /// Files baked and written.
    pub changed: usize,
    /// Files with nothing to bake.
    pub unchanged: usize,
    /// Files that failed.
    pub failed: usize,
    /// Slots baked.
    pub slots: usize,
    /// Outputs written.
    pub textures: usize,
}

/// Sums up results.
pub fn summary(results: &[FileResult]) -> Summary {
    let mut s = Summary {
        files: results.len(),
        ..Summary::default()
    };
    for r in results {
        match &r.outcome {
            Outcome::Changed => s.changed += 1,
            Outcome::Planned { changes: true } => s.changed += 1,
            Outcome::Failed { .. } => s.failed += 1,
            _ => s.unchanged += 1,
        }
        s.slots += r.slots.len();
        s.textures += r.outputs.len();
    }
    s
}

/// The text report.
pub fn render_text(results: &[FileResult], dry_run: bool) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    for r in results {
        let target = r
            .output
            .as_ref()
            .filter(|o| **o != r.input)
            .map(|o| format!(" -> {}", o.display()))
            .unwrap_or_default();
        let status = match &r.outcome {
            Outcome::Changed => "baked".to_owned(),
            Outcome::Copied => "nothing to bake (copied)".to_owned(),
            Outcome::Untouched => "nothing to bake".to_owned(),
            Outcome::Planned { changes: true } => "would bake".to_owned(),
            Outcome::Planned { changes: false } => "nothing to bake".to_owned(),
            Outcome::Failed { error } => format!("failed: {error}"),
        };
        let _ = writeln!(out, "{}{target}: {status}", r.input.display());
        for s in &r.slots {
            let _ = writeln!(
                out,
                "  {}: factor {:?} -> {}",
                s.pointer,
                s.factor,
                s.outputs.join(", ")
            );
        }
        for o in &r.outputs {
            let mut line = format!(
                "  output {}: {}x{} {}-bit {}, {}",
                o.name,
                o.width,
                o.height,
                o.bits,
                o.mime_type.unwrap_or("-"),
                o.stored
            );
            if let Some(e) = o.max_error {
                let _ = write!(line, ", max error {e:.4} codes");
            }
            if o.clamped > 0 {
                let _ = write!(line, ", {} texels clamped", o.clamped);
            }
            let _ = writeln!(out, "{line}");
        }
        if !r.dropped_images.is_empty() {
            let _ = writeln!(
                out,
                "  dropped images {:?} ({} bytes cut from the BIN chunk)",
                r.dropped_images, r.dropped_bin_bytes
            );
        }
        for n in &r.notes {
            let level = match n.level {
                super::plan::Level::Info => "info",
                super::plan::Level::Warning => "warning",
            };
            let _ = writeln!(out, "  {level} {}: {}", n.pointer, n.message);
        }
    }
    let s = summary(results);
    let _ = writeln!(
        out,
        "{} file(s): {} {}, {} unchanged, {} failed; {} slot(s), {} texture(s) written",
        s.files,
        s.changed,
        if dry_run { "to bake" } else { "baked" },
        s.unchanged,
        s.failed,
        s.slots,
        s.textures
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
