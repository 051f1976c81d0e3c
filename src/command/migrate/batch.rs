//! Many files: refuse a bad request up front, then plan and write every file in parallel
//! (rayon), each independently — one failing file does not stop the others — with a progress
//! bar on a terminal, and sum up what happened.

use crate::asset::discover::Shard;
use crate::edit::Edit;
use crate::migrate::apply::{execute, plan_file, Written};
use crate::migrate::material::MaterialPlan;
use crate::migrate::note::{Conversion, Level, Note, Skip};
use crate::migrate::verdict::LabelCounts;
use crate::migrate::Options;
use crate::output::files::Claims;
use crate::output::paths::{Destination, Job, ResourceCopy};
use crate::output::result::{Account, Totals};
use crate::output::{run_each, Scope, UsageError};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One `velvet migrate` invocation.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    pub inputs: Vec<PathBuf>,
    pub destination: Destination,
    pub options: Options,
    /// Plan and report, write nothing.
    pub dry_run: bool,
    /// Show a progress bar (only ever drawn when stderr is a terminal).
    pub progress: bool,
}

/// What became of one file: the outcome `velvet bake` reports too.
pub use crate::output::Outcome as FileOutcome;

/// What `velvet migrate` says of one file besides its outcome: the plan it carried out (or, in
/// a dry run, would carry out).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct MigrateDetail {
    pub materials: Vec<MaterialPlan>,
    /// Edits outside the materials: declarations and URI rewrites.
    pub edits: Vec<Edit>,
    /// A dry run's edits of the bakes, applied after the materials' edits and `edits`: the
    /// new `images` and `textures` entries (under the names they will have) and the slots
    /// that read them (see [`crate::migrate::apply::dry_run_bake_edits`]). Empty in a run
    /// that writes: the bakes' outcome is in `textures_added` and the notes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bake_edits: Vec<Edit>,
    pub copies: Vec<ResourceCopy>,
    #[serde(serialize_with = "crate::migrate::material::notes_json")]
    pub notes: Vec<Note>,
    /// New textures (distinct baked images) the output gains; in a dry run, those planned.
    pub textures_added: usize,
    /// Their encoded size in bytes (0 in a dry run: nothing is encoded).
    pub bytes_added: usize,
    /// `--preview`: the materials as the sheets show them, read from this file's plan before
    /// it was written (so `--in-place` shows them as they were).
    #[serde(skip)]
    pub sheets: Option<Vec<crate::preview::material::Material>>,
}

impl Account for MigrateDetail {
    fn added(&self, _: &FileOutcome) -> (usize, usize) {
        (self.textures_added, self.bytes_added)
    }

    fn warnings(&self) -> usize {
        let warning = |n: &&Note| n.level() == Level::Warning;
        let of_materials = self.materials.iter().flat_map(|m| &m.notes);
        self.notes.iter().filter(warning).count() + of_materials.filter(warning).count()
    }
}

/// The report for one file.
pub type FileResult = crate::output::result::FileResult<MigrateDetail>;

/// Totals over a run: those every file command counts, and the materials' conversions.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Summary {
    #[serde(flatten)]
    pub totals: Totals,
    pub materials_migrated: usize,
    pub conversions: BTreeMap<Conversion, usize>,
    pub skipped: BTreeMap<Skip, usize>,
    /// The migrated materials by their plan's verdict (those measured).
    pub verdicts: LabelCounts,
}

/// The outcome of a run: every file in input order, and the totals.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunReport {
    pub dry_run: bool,
    pub files: Vec<FileResult>,
    pub summary: Summary,
}

impl RunReport {
    /// True when a file failed (exit status 1).
    pub fn failed(&self) -> bool {
        self.summary.totals.failed > 0
    }
}

fn migrate_one(
    job: &Job,
    options: &Options,
    dry_run: bool,
    sheets: bool,
    claims: &Claims,
) -> FileResult {
    if let Err(stopped) = crate::output::interrupt::check() {
        return FileResult::failed(&job.input, job.output.as_deref(), stopped);
    }
    let mut plan = match plan_file(job, options) {
        Ok(plan) => plan,
        Err(error) => return FileResult::failed(&job.input, job.output.as_deref(), error),
    };
    // The plan's verdict, measured by the preview's renderer as soon as the plan is made; the
    // materials it reads are the sheets' when `--preview` asks for them.
    let judged = (sheets || !options.skip_verdict)
        .then(|| crate::preview::verdict::judge(&plan.asset, &mut plan.document, options));
    // A stop during the measuring leaves verdicts that are not to be reported.
    if let Err(stopped) = crate::output::interrupt::check() {
        return FileResult::failed(&job.input, job.output.as_deref(), stopped);
    }
    let sheets = judged.filter(|_| sheets);
    let mut bake_edits = Vec::new();
    let outcome = if dry_run {
        match crate::migrate::apply::dry_run_bake_edits(&plan, claims) {
            Ok(edits) => {
                bake_edits = edits;
                FileOutcome::Planned {
                    changes: plan.changes(),
                }
            }
            Err(error) => FileOutcome::Failed { error },
        }
    } else {
        match execute(&mut plan, claims) {
            Ok(Written::Changed) => FileOutcome::Changed,
            Ok(Written::Copied) => FileOutcome::Copied,
            Ok(Written::Untouched) => FileOutcome::Untouched,
            Err(error) => FileOutcome::Failed { error },
        }
    };
    let written: Vec<_> = plan.baked.iter().filter(|o| o.image.is_some()).collect();
    let (textures_added, bytes_added) = if dry_run {
        let planned = crate::migrate::textures::bake_plan(
            plan.document.materials.iter().flat_map(|m| &m.bakes),
        );
        (planned.map_or(0, |p| p.recipes.len()), 0)
    } else {
        (written.len(), written.iter().map(|o| o.bytes).sum())
    };
    let mut notes: Vec<Note> = plan
        .relocation
        .notes
        .iter()
        .cloned()
        .map(Note::from)
        .collect();
    for output in &plan.baked {
        notes.push(Note::BakeError {
            pointer: output
                .image
                .map_or_else(String::new, |i| format!("/images/{i}")),
            image: output.name.clone(),
            max_codes: output.max_error.unwrap_or(0.0),
            clamped: output.clamped,
        });
    }
    if !plan.changes() {
        // Relocation notes matter only when the document is rewritten.
        notes.retain(|n| {
            matches!(
                n,
                Note::ResourcesCopied { .. } | Note::ResourceMissing { .. }
            )
        });
    }
    FileResult {
        input: plan.input.clone(),
        output: plan.output.clone(),
        outcome,
        detail: MigrateDetail {
            edits: plan
                .document
                .declarations
                .iter()
                .chain(&plan.relocation.edits)
                .cloned()
                .collect(),
            bake_edits,
            materials: plan.document.materials,
            copies: plan.relocation.copies,
            notes,
            textures_added,
            bytes_added,
            sheets,
        },
    }
}

/// Runs a request. `Err` is a usage error: nothing was read or written.
pub fn run(request: &Request) -> Result<RunReport, UsageError> {
    run_shard(request, None)
}

/// Runs like [`run`] over the files of one shard only (see [`Shard`]).
pub fn run_shard(request: &Request, shard: Option<Shard>) -> Result<RunReport, UsageError> {
    run_shard_with_sheets(request, shard, false)
}

/// Runs like [`run_shard`]; with `sheets`, each file's result also holds its materials as
/// `--preview` draws them, from the plan that was written.
pub fn run_shard_with_sheets(
    request: &Request,
    shard: Option<Shard>,
    sheets: bool,
) -> Result<RunReport, UsageError> {
    let scope = Scope {
        inputs: &request.inputs,
        destination: &request.destination,
        dry_run: request.dry_run,
        shard,
        progress: request.progress,
    };
    let files = run_each(
        &scope,
        |path, e| {
            FileResult::failed(
                &path,
                None,
                format!("cannot read folder {}: {e}", path.display()),
            )
        },
        |job, claims| migrate_one(job, &request.options, request.dry_run, sheets, claims),
    )?;
    let summary = summarise(&files);
    Ok(RunReport {
        dry_run: request.dry_run,
        files,
        summary,
    })
}

fn summarise(files: &[FileResult]) -> Summary {
    let mut s = Summary {
        totals: Totals::of(files),
        ..Summary::default()
    };
    for file in files.iter().filter(|f| !f.is_failed()) {
        for material in &file.detail.materials {
            if material.migrated() {
                s.materials_migrated += 1;
            }
            for c in &material.conversions {
                *s.conversions.entry(*c).or_default() += 1;
            }
            if let (true, Some(v)) = (material.migrated(), material.verdict) {
                s.verdicts.add(v.label);
            }
            if let Some(why) = material.skipped {
                *s.skipped.entry(why).or_default() += 1;
            }
        }
    }
    s
}
