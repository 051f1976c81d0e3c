//! One file, planned then written: load, plan the materials ([`plan_document`]) and the
//! relocation of resources ([`relocate`]), bake the textures the plan needs, then write the
//! edits as splices into the loaded text (with bakes, through the part of the document they
//! change, [`BakePart`]), or where that cannot be done, apply them to the whole document; the
//! output is written atomically.
//!
//! A file whose document comes out as it went in is written as the input's own bytes (and,
//! in place, not written at all). A file the loader could not read cleanly is not migrated:
//! rewriting it would hide the fault (a truncated BIN chunk would come out "fixed").

use super::bake_part::BakePart;
use super::plan::{plan_document, DocumentPlan};
use super::textures;
use super::Options;
use crate::asset::{self, Asset, FileBytes};
use crate::bake::apply::{apply as bake_apply, ApplyOptions, OutputReport};
use crate::bake::engine::Baked;
use crate::bake::plan::BakePlan;
use crate::bake::{bake_into, BakeOptions, KernelOptions};
use crate::edit;
use crate::edit::write;
use crate::edit::write::Output;
use crate::output::files::{copy_resources, create_parent, file_sink, stage_new_files};
use crate::output::files::{Claims, FileNames};
use crate::output::interrupt;
use crate::output::paths::{check_links, relocate, Job, Relocation};
use crate::output::staging::Staging;
use crate::output::{load_input, Input};
use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::Mutex;

/// Everything known about one file before anything is written.
#[derive(Debug)]
pub struct FilePlan {
    pub input: PathBuf,
    /// The input as it was read, and its resources, compared before anything is written for
    /// it.
    pub snapshot: crate::output::InputSnapshot,
    pub output: Option<PathBuf>,
    /// The input's bytes, kept when the plan changes nothing (then written as they are).
    pub bytes: Option<FileBytes>,
    pub asset: Asset,
    pub document: DocumentPlan,
    pub relocation: Relocation,
    /// .gltf: store baked textures as `data:` URIs.
    pub embed: bool,
    /// After writing: the textures baked, with their quantisation error.
    pub baked: Vec<OutputReport>,
}

impl FilePlan {
    pub fn in_place(&self) -> bool {
        self.output.as_deref() == Some(self.input.as_path())
    }

    /// True when the output's document differs from the input's (materials or URIs).
    pub fn changes(&self) -> bool {
        !self.document.is_empty() || !self.relocation.edits.is_empty()
    }
}

/// What writing a file did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Written {
    /// The edited document was written.
    Changed,
    /// Nothing changed: the input's bytes were written to the output.
    Copied,
    /// Nothing changed and the output is the input: nothing was written.
    Untouched,
}

/// Loads and plans one file. Errors name the file and what is wrong.
pub fn plan_file(job: &Job, options: &Options) -> Result<FilePlan, String> {
    let Input {
        asset,
        bytes,
        snapshot,
    } = load_input(&job.input, &options.load, "migrated")
        .map_err(|e| format!("{} {e}", job.input.display()))?;
    check_links(&asset).map_err(|e| format!("{}: {e}", job.input.display()))?;
    let document = plan_document(&asset, options);
    if let Some(dangling) = dangling_layer_texture(&asset, &document) {
        return Err(format!(
            "{} cannot be migrated: {dangling}",
            job.input.display()
        ));
    }
    let relocation = match &job.output {
        Some(output) if output != &job.input => relocate(&asset, output, options.rewrite_uris)
            .map_err(|e| format!("{}: {e}", job.input.display()))?,
        _ => Relocation::default(),
    };
    // The input's bytes are written as they are only when the plan changes nothing; a large
    // document that changes does not keep them. A .gltf's are the asset's text.
    let bytes = match bytes {
        Some(bytes) if document.is_empty() && relocation.edits.is_empty() => Some(bytes),
        _ => None,
    };
    Ok(FilePlan {
        input: job.input.clone(),
        snapshot,
        output: job.output.clone(),
        bytes,
        asset,
        document,
        relocation,
        embed: options.embed,
        baked: Vec::new(),
    })
}

/// The first texture reference of a layer the plan converts that names no texture (an index
/// past the textures, at any size: `18446744073709551617` included), worded as validate's
/// UNRESOLVED_REFERENCE. A conversion would carry it into the new layer as it is: an output
/// that repeats the input's dangling reference under another name, with a clean report. A
/// draft sheen is left out: its upgrade checks its texture and drops one that names nothing,
/// saying so.
fn dangling_layer_texture(asset: &Asset, document: &DocumentPlan) -> Option<String> {
    let root = asset.root();
    let textures = root
        .get("textures")
        .and_then(|t| t.as_array())
        .map_or(0, |t| t.len());
    let materials = root.get("materials")?;
    document
        .materials
        .iter()
        .filter(|m| {
            !m.conversions.is_empty() && !m.conversions.contains(&super::Conversion::LegacyUpgrade)
        })
        .find_map(|m| {
            let extensions = materials.get(m.index)?.get("extensions")?;
            ["KHR_materials_sheen", "KHR_materials_fuzz"]
                .into_iter()
                .filter_map(|name| Some((name, extensions.get(name)?.as_object()?)))
                .find_map(|(name, layer)| {
                    layer.iter().find_map(|(key, info)| {
                        if !key.ends_with("Texture") {
                            return None;
                        }
                        let index = info.get("index")?;
                        let i = crate::layers::as_index(index)?;
                        (i >= textures as u64).then(|| {
                            format!(
                                "{key} names texture {}, but the asset has {textures} \
                                 texture{} (UNRESOLVED_REFERENCE at \
                                 /materials/{}/extensions/{name}/{key}/index)",
                                index.raw(),
                                if textures == 1 { "" } else { "s" },
                                m.index
                            )
                        })
                    })
                })
        })
}

/// How a file's plan is written. The spine chooses one per file ([`WriteStrategy::choose`]);
/// a strategy that cannot take a plan hands it to [`WriteStrategy::Rewrite`], which takes any.
/// Each writes the same document (tests compare them), differing in what they read and in
/// which bytes they keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WriteStrategy {
    /// No textures to bake: the edits as splices into the loaded text, reading only the
    /// values they touch; every other byte is kept.
    Splice,
    /// Bakes whose new images are files already: the bake applied to the part of the document
    /// it reads and changes ([`BakePart`]), then spliced like the edits.
    BakePart,
    /// The plan applied to the whole document, written anew in the input's own style: for a
    /// bake that drops a texture, a GLB, `--embed`, or a text the splicer does not take.
    Rewrite,
}

impl WriteStrategy {
    /// The strategy for a plan with `bakes`, once they are baked (`baked`): `streamed` says new
    /// images are files next to a .gltf, written as they are encoded.
    pub fn choose(bakes: &BakePlan, streamed: bool, baked: &[Baked]) -> WriteStrategy {
        if bakes.is_empty() {
            WriteStrategy::Splice
        } else if streamed
            && baked
                .iter()
                .all(|b| b.stored.is_some() || b.encoded.is_none())
        {
            WriteStrategy::BakePart
        } else {
            WriteStrategy::Rewrite
        }
    }
}

/// Applies a file's plan and writes its output (and resource copies), by the strategy the
/// spine chooses. On failure the output is as it was: every file written for it is staged and
/// put in place with the document (see output::staging). The document is edited where it lies
/// (a large one is not copied), so the plan's asset holds the edited document afterwards when
/// it was rewritten.
pub fn execute(plan: &mut FilePlan, claims: &Claims) -> Result<Written, String> {
    execute_by(plan, claims, false).map(|(written, _)| written)
}

/// [`execute`], by [`WriteStrategy::Rewrite`] whatever the choice when `rewrite` is set (which
/// tests compare the chosen strategies with); returns what was written and the strategy that
/// wrote it.
pub fn execute_by(
    plan: &mut FilePlan,
    claims: &Claims,
    rewrite: bool,
) -> Result<(Written, WriteStrategy), String> {
    let Some(output) = plan.output.clone() else {
        return Err(format!("{}: no output path", plan.input.display()));
    };
    // Textures are baked first, from the document as loaded (its URIs not yet relocated).
    let bake_plan = textures::bake_plan(plan.document.materials.iter().flat_map(|m| &m.bakes))
        .map_err(|e| format!("{}: {e}", plan.input.display()))?;
    // Names for new image files, from the document's URIs before they are relocated. In a
    // .gltf whose new images are files, each is written as soon as it is encoded, so the run
    // holds only the images in flight, however many there are.
    // Every file written for this output is staged and put in place with the document; an
    // error or a stop drops them all (see output::staging).
    interrupt::check()?;
    let staging = Staging::default();
    let names = Mutex::new(FileNames::next_to(
        claims,
        &plan.asset,
        &plan.input,
        &output,
        &plan.relocation,
    ));
    let mut baked = Vec::with_capacity(bake_plan.recipes.len());
    // A .gltf whose new images are files: each is written as it is encoded.
    let streamed = plan.asset.container == asset::Container::Gltf && !plan.embed;
    if !bake_plan.is_empty() {
        let options = BakeOptions {
            kernel: KernelOptions {
                exact: false,
                measure: true,
            },
            max_image_pixels: crate::bake::engine::MaxImagePixels(
                plan.asset.options.max_image_pixels,
            ),
            max_memory: crate::bake::engine::MaxMemory(plan.asset.options.max_memory),
            ..BakeOptions::default()
        };
        // The images as loaded, read alone (the whole document is not built for them).
        let images = plan
            .asset
            .root()
            .get("images")
            .map_or(serde_json::Value::Null, |images| images.to_value());
        let results = {
            let sink = file_sink(&names, &images, &bake_plan, &staging);
            bake_into(
                &bake_plan.recipes,
                &plan.asset,
                &options,
                streamed.then_some(&*sink as crate::bake::Sink),
            )
        };
        for (info, result) in bake_plan.outputs.iter().zip(results) {
            baked.push(result.map_err(|e| bake_failed(&plan.input, info, e))?);
        }
    }
    let mut names = names.into_inner().unwrap_or_else(|e| e.into_inner());
    let strategy = match rewrite {
        true => WriteStrategy::Rewrite,
        false => WriteStrategy::choose(&bake_plan, streamed, &baked),
    };
    let fail = |e: edit::EditError| format!("{}: {e}", plan.input.display());
    // Without bakes no edit touches a URI that is copied (resources are copied or their URIs
    // rewritten, never both), so the document as loaded names what the output uses: the
    // copies are staged while the document is spliced. A document that turns out unchanged
    // and stays in place drops them with the staging, unwritten.
    let mut copied = None;
    let spliced: Option<PartWritten> = match strategy {
        WriteStrategy::Splice => {
            let edits = plan.document.edits().chain(&plan.relocation.edits);
            let (spliced, copies) = rayon::join(
                || write::spliced_bytes(&plan.asset, edits),
                || {
                    bake_plan
                        .is_empty()
                        .then(|| copy_resources(&plan.relocation, plan.asset.root(), &staging))
                },
            );
            copied = copies;
            spliced
                .map_err(fail)?
                .map(|(out, changed)| (out, changed, Vec::new()))
        }
        WriteStrategy::BakePart => baked_by_part(
            &plan.asset,
            &plan.document,
            &plan.relocation,
            &plan.input,
            plan.embed,
            &bake_plan,
            &mut baked,
            &mut names,
            &staging,
        )?,
        WriteStrategy::Rewrite => None,
    };
    let Some((out, changed, outputs)) = spliced else {
        let written = write_rewritten(plan, &output, &bake_plan, baked, names, staging, copied)?;
        return Ok((written, WriteStrategy::Rewrite));
    };
    // A spliced output is put in place (with, without bakes, the resource copies it needs).
    if !changed && plan.in_place() {
        return Ok((Written::Untouched, strategy));
    }
    create_parent(&output)?;
    let out = if bake_plan.is_empty() {
        copied.unwrap_or_else(|| copy_resources(&plan.relocation, plan.asset.root(), &staging))?;
        match changed {
            true => out,
            false => Output::Bytes(input_bytes(plan)?),
        }
    } else {
        out
    };
    staging.stage_document(&output, &out)?;
    plan.snapshot.unchanged(&plan.input)?;
    staging.commit()?;
    plan.baked = outputs;
    let written = if changed {
        Written::Changed
    } else {
        Written::Copied
    };
    Ok((written, strategy))
}

/// Applies the plan (and its bakes) to the whole document and writes it anew; `copied`: how
/// staging the resource copies went, when they were staged already.
fn write_rewritten(
    plan: &mut FilePlan,
    output: &std::path::Path,
    bake_plan: &BakePlan,
    mut baked: Vec<Baked>,
    mut names: FileNames,
    staging: Staging,
    copied: Option<Result<(), String>>,
) -> Result<Written, String> {
    let input = plan.input.clone();
    let fail = |e: edit::EditError| format!("{}: {e}", input.display());
    // The edits are applied where they lie in the plan (a large document's are not copied).
    let mut changed = false;
    for edits in edit_groups(&plan.document, &plan.relocation.edits) {
        changed |= edit::apply(plan.asset.json_mut(), edits).map_err(fail)?;
    }
    if !changed && plan.in_place() {
        return Ok(Written::Untouched);
    }
    if changed {
        // The input's bytes are written only when nothing changed.
        plan.bytes = None;
    }
    create_parent(output)?;
    let bytes = if bake_plan.is_empty() {
        copied.unwrap_or_else(|| copy_resources(&plan.relocation, plan.asset.root(), &staging))?;
        match changed {
            true => Cow::Owned(write::to_bytes(
                &plan.asset,
                plan.asset.json(),
                plan.asset.bin.as_deref(),
            )),
            false => input_bytes(plan)?,
        }
    } else {
        let names_dir = names.dir().to_path_buf();
        let json = plan.asset.take_json();
        let applied = bake_apply(
            json,
            plan.asset.bin.take(),
            plan.asset.container,
            bake_plan,
            &mut baked,
            ApplyOptions { embed: plan.embed },
            &mut names,
        );
        copy_resources(&plan.relocation, &applied.json, &staging)?;
        stage_new_files(&names_dir, &applied.files, &staging)?;
        let bytes = Cow::Owned(write::to_bytes(
            &plan.asset,
            &applied.json,
            applied.bin.as_deref(),
        ));
        plan.asset.set_json(applied.json);
        plan.asset.bin = applied.bin;
        plan.baked = applied.outputs;
        bytes
    };
    staging.stage_document(output, &Output::Bytes(bytes))?;
    plan.snapshot.unchanged(&plan.input)?;
    staging.commit()?;
    Ok(if changed {
        Written::Changed
    } else {
        Written::Copied
    })
}

/// The input's own bytes, for an output whose edits set what was there already: a .gltf's
/// are the asset's text; a GLB's are kept from loading when the plan changes nothing, else
/// read again.
fn input_bytes(plan: &mut FilePlan) -> Result<Cow<'_, [u8]>, String> {
    if plan.bytes.is_none() && plan.asset.file_bytes().is_none() {
        let read = asset::read(&plan.input, &plan.asset.options)
            .map_err(|d| format!("cannot read {}: {}", plan.input.display(), d.message))?;
        plan.bytes = Some(read);
    }
    Ok(Cow::Borrowed(match &plan.bytes {
        Some(bytes) => bytes,
        None => plan.asset.file_bytes().unwrap_or_default(),
    }))
}

/// What [`baked_by_part`] wrote: the output, whether it differs from the input, and what became
/// of each baked output.
type PartWritten<'a> = (Output<'a>, bool, Vec<OutputReport>);

/// Applies `bake_plan` and the file's edits to the part of the document the bake reads and
/// changes ([`BakePart`]: the top level without the scene's geometry, and the materials the
/// bake's slots lie in), then writes them into the loaded text as splices, with the edits of
/// every other material, and places the resource copies the output names. Returns the output's
/// bytes, whether they differ from the input and what became of each baked output; `None`
/// when the part cannot take this plan (nothing written, `baked` as it was), and the caller
/// applies it to the whole document. Every new image must be a file already (`baked` holds no
/// bytes), so that the bake can be applied again to the whole document.
#[allow(clippy::too_many_arguments)]
fn baked_by_part<'a>(
    asset: &'a Asset,
    document: &DocumentPlan,
    relocation: &Relocation,
    input: &std::path::Path,
    embed: bool,
    bake_plan: &crate::bake::plan::BakePlan,
    baked: &mut Vec<crate::bake::engine::Baked>,
    names: &mut FileNames,
    staging: &Staging,
) -> Result<Option<PartWritten<'a>>, String> {
    let Some(mut part) = BakePart::new(asset, bake_plan, document) else {
        return Ok(None);
    };
    let fail = |e: edit::EditError| format!("{}: {e}", input.display());
    let edits = document.edits().chain(&relocation.edits);
    let mut json = std::mem::take(&mut part.json);
    let mut others: Vec<&edit::Edit> = Vec::new();
    for e in edits {
        if part.holds(e) {
            edit::apply(&mut json, std::slice::from_ref(e)).map_err(fail)?;
        } else {
            others.push(e);
        }
    }
    let as_baked = baked.clone();
    let applied = bake_apply(
        json,
        None,
        asset.container,
        bake_plan,
        baked,
        ApplyOptions { embed },
        names,
    );
    if applied.dropped != crate::bake::prune::Dropped::default() || !applied.files.is_empty() {
        // Dropping renumbers references the part does not hold; files to write would be
        // images the bake did not write as it encoded them.
        *baked = as_baked;
        return Ok(None);
    }
    copy_resources(relocation, &applied.json, staging)?;
    let part_edits = part.into_edits(asset, applied.json);
    let spliced =
        write::spliced_bytes(asset, others.iter().copied().chain(&part_edits)).map_err(fail)?;
    let (bytes, changed) = match spliced {
        Some(written) => written,
        None => {
            // A text the splicer does not take: the edits on the whole document.
            let mut whole = asset.root().to_value();
            for e in others.iter().copied().chain(&part_edits) {
                edit::apply(&mut whole, std::slice::from_ref(e)).map_err(fail)?;
            }
            let bytes = write::to_bytes(asset, &whole, asset.bin.as_deref());
            (Output::Bytes(bytes.into()), true)
        }
    };
    Ok(Some((bytes, changed, applied.outputs)))
}

/// The edits a dry run adds for the plan's bakes: the textures baked in memory (nothing is
/// written) and applied to the document the plan's other edits give, then the difference as
/// edits (`set` of each value the bake changes or adds, the new `images` and `textures`
/// entries among them under the names they get, `remove` of what it drops). Applied after the
/// materials' edits, the declarations and the URI rewrites, in that order, they give the
/// document a run writes. A new image is named after a hash of its bytes, so only a bake can
/// say its name. Empty when the plan bakes nothing.
pub fn dry_run_bake_edits(plan: &FilePlan, claims: &Claims) -> Result<Vec<edit::Edit>, String> {
    let bake_plan = textures::bake_plan(plan.document.materials.iter().flat_map(|m| &m.bakes))
        .map_err(|e| format!("{}: {e}", plan.input.display()))?;
    if bake_plan.is_empty() {
        return Ok(Vec::new());
    }
    let options = BakeOptions {
        kernel: KernelOptions {
            exact: false,
            measure: false,
        },
        max_image_pixels: crate::bake::engine::MaxImagePixels(plan.asset.options.max_image_pixels),
        max_memory: crate::bake::engine::MaxMemory(plan.asset.options.max_memory),
        ..BakeOptions::default()
    };
    let mut baked_images = Vec::with_capacity(bake_plan.recipes.len());
    for (info, result) in
        bake_plan
            .outputs
            .iter()
            .zip(bake_into(&bake_plan.recipes, &plan.asset, &options, None))
    {
        baked_images.push(result.map_err(|e| bake_failed(&plan.input, info, e))?);
    }
    let fail = |e: edit::EditError| format!("{}: {e}", plan.input.display());
    // Named as the run names them: next to the output (the input itself without one).
    let output = plan.output.as_deref().unwrap_or(&plan.input);
    // Each way below names anew: a name one claimed is the same name with the same bytes for
    // the run's claims, but taken for the names of one output.
    let names_for =
        || FileNames::next_to(claims, &plan.asset, &plan.input, output, &plan.relocation);
    // New images that are files, as a run writes them: the bake applied to the part of the
    // document it reads and changes, as the run applies it, so that a dry run of a large
    // document does not build it whole.
    if plan.asset.container == asset::Container::Gltf && !plan.embed {
        if let Some(mut part) = BakePart::new(&plan.asset, &bake_plan, &plan.document) {
            let mut json = std::mem::take(&mut part.json);
            for e in plan.document.edits().chain(&plan.relocation.edits) {
                if part.holds(e) {
                    edit::apply(&mut json, std::slice::from_ref(e)).map_err(fail)?;
                }
            }
            let before = json.clone();
            let mut images = baked_images.clone();
            let applied = bake_apply(
                json,
                None,
                plan.asset.container,
                &bake_plan,
                &mut images,
                ApplyOptions { embed: false },
                &mut names_for(),
            );
            if applied.dropped == crate::bake::prune::Dropped::default() {
                let mut edits = Vec::new();
                for e in part.into_edits(&plan.asset, applied.json) {
                    match &e {
                        edit::Edit::Replace { pointer, value } => match before.pointer(pointer) {
                            Some(old) => difference(pointer, old, value, &mut edits),
                            None => edits.push(e),
                        },
                        _ => edits.push(e),
                    }
                }
                return Ok(edits);
            }
        }
    }
    let edited = || -> Result<serde_json::Value, String> {
        let mut before = plan.asset.root().to_value();
        for edits in edit_groups(&plan.document, &plan.relocation.edits) {
            edit::apply(&mut before, edits).map_err(fail)?;
        }
        Ok(before)
    };
    let before = edited()?;
    // What the bake may change, kept to compare with: the members besides the materials, and
    // the materials it bakes into (a whole copy of a large document would double the memory).
    let baked: std::collections::BTreeSet<usize> = plan
        .document
        .materials
        .iter()
        .filter(|m| !m.bakes.is_empty())
        .map(|m| m.index)
        .collect();
    let kept_members: serde_json::Map<String, serde_json::Value> = before
        .as_object()
        .into_iter()
        .flatten()
        .filter(|(key, _)| *key != "materials")
        .map(|(key, value)| (key.clone(), value.clone()))
        .collect();
    let kept_materials: Vec<(usize, serde_json::Value)> = baked
        .iter()
        .filter_map(|&i| Some((i, before.get("materials")?.get(i)?.clone())))
        .collect();
    let materials_before = before
        .get("materials")
        .and_then(serde_json::Value::as_array)
        .map_or(0, Vec::len);
    let applied = bake_apply(
        before,
        plan.asset.bin.clone(),
        plan.asset.container,
        &bake_plan,
        &mut baked_images,
        ApplyOptions { embed: plan.embed },
        &mut names_for(),
    );
    let mut edits = Vec::new();
    let materials_after = applied.json.get("materials");
    if applied.dropped != crate::bake::prune::Dropped::default()
        || materials_after
            .and_then(serde_json::Value::as_array)
            .map_or(0, Vec::len)
            != materials_before
    {
        // A bake that drops a texture renumbers references in any material: the whole
        // document is compared.
        difference("", &edited()?, &applied.json, &mut edits);
        return Ok(edits);
    }
    for (i, material) in &kept_materials {
        if let Some(after) = materials_after.and_then(|m| m.get(*i)) {
            difference(&format!("/materials/{i}"), material, after, &mut edits);
        }
    }
    let empty = serde_json::Map::new();
    let after_members = applied.json.as_object().unwrap_or(&empty);
    for (key, value) in &kept_members {
        let at = crate::asset::pointer::join("", key);
        match after_members.get(key) {
            Some(new) => difference(&at, value, new, &mut edits),
            None => edits.push(edit::Edit::remove(at)),
        }
    }
    for (key, value) in after_members
        .iter()
        .filter(|(k, _)| *k != "materials" && !kept_members.contains_key(*k))
    {
        edits.push(edit::Edit::replace(
            crate::asset::pointer::join("", key),
            value.clone(),
        ));
    }
    Ok(edits)
}

/// The edits that turn `from` into `to` (at `pointer`): members and elements compared one by
/// one, so that each edit names the value it changes; an array that grows keeps its elements
/// and gains the new ones at its end (`set` at its length appends).
fn difference(
    pointer: &str,
    from: &serde_json::Value,
    to: &serde_json::Value,
    out: &mut Vec<edit::Edit>,
) {
    use serde_json::Value;
    match (from, to) {
        _ if from == to => {}
        (Value::Object(a), Value::Object(b)) => {
            for (key, value) in a {
                let at = crate::asset::pointer::join(pointer, key);
                match b.get(key) {
                    Some(new) => difference(&at, value, new, out),
                    None => out.push(edit::Edit::remove(at)),
                }
            }
            for (key, value) in b.iter().filter(|(k, _)| !a.contains_key(*k)) {
                let at = crate::asset::pointer::join(pointer, key);
                out.push(edit::Edit::replace(at, value.clone()));
            }
        }
        (Value::Array(a), Value::Array(b)) if a.len() <= b.len() => {
            for (i, (old, new)) in a.iter().zip(b).enumerate() {
                difference(&format!("{pointer}/{i}"), old, new, out);
            }
            for (i, new) in b.iter().enumerate().skip(a.len()) {
                out.push(edit::Edit::replace(format!("{pointer}/{i}"), new.clone()));
            }
        }
        _ => out.push(edit::Edit::replace(pointer.to_string(), to.clone())),
    }
}

/// A file's plan's edits, group by group in the order they are applied: each material's, the
/// extension declarations, the relocated URIs.
fn edit_groups<'p>(
    document: &'p DocumentPlan,
    relocation: &'p [edit::Edit],
) -> impl Iterator<Item = &'p [edit::Edit]> {
    document
        .materials
        .iter()
        .map(|m| m.edits.as_slice())
        .chain([document.declarations.as_slice(), relocation])
}

/// The error of a bake that failed: the input, the slots and the image.
fn bake_failed(
    input: &std::path::Path,
    info: &crate::bake::plan::OutputInfo,
    e: impl std::fmt::Display,
) -> String {
    format!(
        "{}: cannot bake {} of image {}: {e}",
        input.display(),
        info.labels.join(" + "),
        info.image
    )
}
