//! `velvet preview`: contact sheets that show, per material that has or gets a sheen or fuzz
//! layer, the material as authored, as migrated (fuzz with the fitted and with the copied
//! roughness) and as a loader without KHR_materials_fuzz sees it, under a white furnace and a
//! directional light, with the difference image, the report's figures and a verdict; and index
//! pages (`index.html`, `index-2.html`, …) that list them worst first, for a file or a library.
//!
//! This module owns the previews from reading a material to writing its PNG: [`material`]
//! reads a material's values and decides the columns (what migrate writes), [`shade`] shades a
//! sphere exactly from `shading`'s formulas, [`sheet`] lays out and encodes a sheet with the
//! built-in [`font`], [`overview`] draws the run's histogram of verdicts with its worst sheets,
//! [`index`] writes the HTML pages and `index.json`, and [`verdict`] measures the plan's
//! perceptual verdict on each material and writes it into migrate's plan. A run is planned
//! first ([`plan`]: every material read and judged, materials with the same appearance sharing
//! one sheet, the sheets ranked by the plan's verdict), so `--worst N` picks its sheets before
//! anything is drawn; [`write`] then draws the chosen sheets in parallel and
//! writes each as soon as it is drawn (memory holds the sheets in flight, one per thread), every
//! file through `edit::write::write_atomic`. A stop (SIGINT, SIGTERM) ends the run between
//! sheets: those written stay, complete, and no partial file is left. The same inputs give the
//! same bytes at any thread count: every value is computed by one task from its inputs alone,
//! and names come from the inputs.

pub mod font;
pub mod index;
pub mod material;
pub mod overview;
pub mod shade;
pub mod sheet;
pub mod verdict;

use crate::asset::discover;
use crate::edit::write::write_atomic;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// A file that could not be previewed, with the reason.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    pub file: PathBuf,
    pub message: String,
}

/// One material of the run: where it is and which sheet shows it.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub file: PathBuf,
    /// The asset's label (see [`label`]).
    pub label: String,
    pub index: usize,
    pub name: Option<String>,
    /// The sheet that shows it, an index into [`Plan::sheets`].
    pub sheet: usize,
}

impl Entry {
    /// "label: material 3 \"Velvet\"".
    pub fn title(&self) -> String {
        match &self.name {
            Some(n) => format!("{}: material {} \"{n}\"", self.label, self.index),
            None => format!("{}: material {}", self.label, self.index),
        }
    }
}

/// One sheet to draw: the material it is drawn from (the first of those that share it), its
/// file name, its title and the plan's measure of how far the migration moves it.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetPlan {
    pub name: String,
    pub title: String,
    pub material: material::Material,
    /// The entries it shows, in input order.
    pub entries: Vec<usize>,
    /// The plan's verdict on the material ([`verdict`]): the sheet's label and its rank.
    pub verdict: crate::migrate::verdict::Verdict,
}

/// What a preview run draws, decided before anything is drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    /// Every material with a sheen or fuzz layer, in input then document order.
    pub entries: Vec<Entry>,
    /// One per distinct appearance, worst first (by metric, then input order).
    pub sheets: Vec<SheetPlan>,
    /// Files read that have no material with a sheen or fuzz layer.
    pub without_layers: Vec<PathBuf>,
    pub failures: Vec<Failure>,
}

/// A sheet drawn and written.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawn {
    /// Its index in [`Plan::sheets`].
    pub sheet: usize,
    pub path: PathBuf,
    pub summary: sheet::Summary,
}

/// What [`write`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Written {
    /// The sheets drawn and written, worst first.
    pub drawn: Vec<Drawn>,
    /// The index pages, first page first; none when the run was stopped.
    pub pages: Vec<PathBuf>,
    /// `overview.png`; none when the run was stopped.
    pub overview: Option<PathBuf>,
    /// `index.json`, written by a finished run and by a stopped one (then listing the sheets
    /// it finished as drawn).
    pub index_json: Option<PathBuf>,
    /// Sheets an earlier run's index.json listed that this run does not write, removed.
    pub removed: Vec<PathBuf>,
    /// Stopped by SIGINT or SIGTERM before every chosen sheet was drawn.
    pub stopped: bool,
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

/// The sheet file name of an entry: "stem-m3-name.png".
fn sheet_name(entry: &Entry) -> String {
    let stem = entry
        .label
        .rsplit_once('.')
        .map_or(entry.label.as_str(), |(stem, _)| stem);
    let mut name = format!("{}-m{}", file_safe(stem, 80), entry.index);
    if let Some(n) = &entry.name {
        name += "-";
        name += &file_safe(n, 40);
    }
    name + ".png"
}

/// The folders a search for assets could not read, with why.
pub type WalkErrors = Vec<(PathBuf, std::io::Error)>;

/// One file's part of a preview: its path, its label and its materials as migrate's plan of it
/// writes them, or why it has none.
pub struct FileMaterials {
    pub file: PathBuf,
    pub label: String,
    pub materials: Result<Vec<material::Material>, String>,
}

/// The labels of the files `velvet preview` or `migrate --preview` finds under `inputs` (the
/// files of `shard`), by path, and the folders it could not read.
pub fn labels(
    inputs: &[PathBuf],
    shard: Option<discover::Shard>,
) -> (Vec<(PathBuf, String)>, WalkErrors) {
    let (found, walk_errors) = discover::find(inputs, shard);
    let labels = found
        .iter()
        .map(|f| (f.path.clone(), label(f, inputs)))
        .collect();
    (labels, walk_errors)
}

/// Reads every asset under `inputs` and plans its sheets; draws and writes nothing. Each
/// asset's migration is planned with `options` (`velvet preview`'s defaults), and the sheets
/// show what that plan writes (`migrate --preview` hands [`assemble`] the materials of the
/// plans it writes instead).
pub fn plan(inputs: &[PathBuf], options: &crate::migrate::Options) -> Plan {
    let (labels, walk_errors) = labels(inputs, None);
    // Load and read the materials of each file (in parallel over files).
    let files: Vec<FileMaterials> = labels
        .into_par_iter()
        .map(|(file, label)| {
            let loaded = crate::asset::load_with(&file, &options.load);
            let materials = match loaded.asset {
                Some(asset) => {
                    let mut plan = crate::migrate::plan_document(&asset, options);
                    Ok(verdict::judge(&asset, &mut plan, options))
                }
                None => Err(loaded
                    .diagnostics
                    .iter()
                    .map(|d| d.message.clone())
                    .collect::<Vec<_>>()
                    .join("; ")),
            };
            FileMaterials {
                file,
                label,
                materials,
            }
        })
        .collect();
    assemble(files, walk_errors)
}

/// The plan of a preview of `files` (in input order) and the folders that could not be read:
/// materials whose appearance is the same ([`material::Material::appearance`]) share one
/// sheet, named and titled after the first of them, and the sheets are ranked worst first.
pub fn assemble(files: Vec<FileMaterials>, walk_errors: WalkErrors) -> Plan {
    let mut plan = Plan::default();
    for (path, e) in walk_errors {
        plan.failures.push(Failure {
            file: path,
            message: format!("cannot read this folder: {e}"),
        });
    }
    let mut materials = Vec::new();
    for FileMaterials {
        file: path,
        label,
        materials: result,
    } in files
    {
        match result {
            Err(message) => plan.failures.push(Failure {
                file: path,
                message: if message.is_empty() {
                    "cannot be read".into()
                } else {
                    message
                },
            }),
            Ok(found) if found.is_empty() => plan.without_layers.push(path),
            Ok(found) => {
                for m in found {
                    plan.entries.push(Entry {
                        file: path.clone(),
                        label: label.clone(),
                        index: m.index,
                        name: m.name.clone(),
                        sheet: 0,
                    });
                    materials.push(m);
                }
            }
        }
    }
    // One sheet per appearance, in order of first use.
    let appearances: Vec<String> = materials.par_iter().map(|m| m.appearance()).collect();
    let mut by_appearance: std::collections::HashMap<&str, usize> = Default::default();
    let mut first_uses: Vec<usize> = Vec::new();
    for (e, appearance) in appearances.iter().enumerate() {
        let sheet = *by_appearance.entry(appearance).or_insert_with(|| {
            first_uses.push(e);
            first_uses.len() - 1
        });
        plan.entries[e].sheet = sheet;
    }
    let mut sheets: Vec<SheetPlan> = first_uses
        .par_iter()
        .map(|&e| SheetPlan {
            name: sheet_name(&plan.entries[e]),
            title: plan.entries[e].title(),
            verdict: materials[e]
                .verdict
                .unwrap_or_else(|| verdict::measure_pairs(&verdict::pairs(&materials[e]))),
            material: materials[e].clone(),
            entries: Vec::new(),
        })
        .collect();
    for (e, entry) in plan.entries.iter().enumerate() {
        sheets[entry.sheet].entries.push(e);
    }
    for sheet in &mut sheets {
        let others = sheet.entries.len() - 1;
        if others > 0 {
            sheet.title += &format!(
                " and {others} other {} with the same values",
                if others == 1 { "material" } else { "materials" }
            );
        }
    }
    // Worst first by the plan's verdict; a NaN (none is expected) ranks as the worst.
    let mut order: Vec<usize> = (0..sheets.len()).collect();
    order.sort_by(|&a, &b| {
        let key = |s: &SheetPlan| {
            if s.verdict.flip.is_nan() {
                f64::INFINITY
            } else {
                s.verdict.flip
            }
        };
        key(&sheets[b]).total_cmp(&key(&sheets[a])).then(a.cmp(&b))
    });
    let mut renumbered = vec![0; sheets.len()];
    for (rank, &old) in order.iter().enumerate() {
        renumbered[old] = rank;
    }
    for entry in &mut plan.entries {
        entry.sheet = renumbered[entry.sheet];
    }
    let mut slots: Vec<Option<SheetPlan>> = sheets.into_iter().map(Some).collect();
    plan.sheets = order
        .iter()
        .map(|&old| slots[old].take().expect("each sheet once"))
        .collect();
    // Two assets may reduce to one name (a/x.gltf and a_x.gltf, or x.gltf in two folders
    // given): later ones in input order get -2, -3, ….
    let mut by_input: Vec<usize> = (0..plan.sheets.len()).collect();
    by_input.sort_by_key(|&s| plan.sheets[s].entries[0]);
    let mut used = std::collections::HashSet::new();
    for s in by_input {
        let sheet = &mut plan.sheets[s];
        let stem = sheet.name.trim_end_matches(".png").to_string();
        let mut k = 1;
        while !used.insert(sheet.name.clone()) {
            k += 1;
            sheet.name = format!("{stem}-{k}.png");
        }
    }
    plan
}

/// Draws the first `count` sheets of `plan` (the worst; all of them when `count` is `None`)
/// in parallel, writing each into `out_dir` (created if needed) as soon as it is drawn, then
/// the overview, the index pages and `index.json`. The sheets an earlier run's index.json in
/// `out_dir` lists and this run does not draw are removed (only those: a file velvet did not
/// list is never touched). `progress` draws a bar on a terminal. A stop (SIGINT, SIGTERM) ends
/// the run between sheets: the sheets written stay, and index.json lists them (index pages
/// and overview are a finished run's). Returns what was written, or the first write that
/// failed.
pub fn write(
    plan: &Plan,
    out_dir: &Path,
    count: Option<usize>,
    progress: bool,
) -> Result<Written, String> {
    // A run stopped before it draws (while its plan was made) writes nothing: its verdicts
    // were left unmeasured.
    if crate::output::interrupt::requested().is_some() {
        return Ok(Written {
            stopped: true,
            ..Written::default()
        });
    }
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create the folder {}: {e}", out_dir.display()))?;
    let chosen = count.map_or(plan.sheets.len(), |n| n.min(plan.sheets.len()));
    let index_path = out_dir.join("index.json");
    let listed = std::fs::read_to_string(&index_path)
        .map(|text| index::listed_sheets(&text))
        .unwrap_or_default();
    let chosen_names: std::collections::HashSet<&str> = plan.sheets[..chosen]
        .iter()
        .map(|s| s.name.as_str())
        .collect();
    let mut written = Written::default();
    // Sheets of the earlier run this one will not draw go first, so that a stop leaves no
    // sheet the new index does not list.
    for name in listed.iter().filter(|n| !chosen_names.contains(n.as_str())) {
        written.removed.extend(remove_sheet(&out_dir.join(name))?);
    }
    let bar = crate::output::progress_bar(progress, chosen, "sheets");
    let worst = overview::WorstSheets::default();
    let drawn: Vec<Result<Option<Drawn>, String>> = (0..chosen)
        .into_par_iter()
        .map(|s| {
            if crate::output::interrupt::requested().is_some() {
                return Ok(None);
            }
            let planned = &plan.sheets[s];
            let sheet = sheet::render(&planned.title, &planned.material);
            let path = out_dir.join(&planned.name);
            write_atomic(&path, &sheet::to_png(&sheet))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            worst.offer(s, &sheet);
            if let Some(bar) = &bar {
                bar.inc(1);
            }
            Ok(Some(Drawn {
                sheet: s,
                path,
                summary: sheet.summary,
            }))
        })
        .collect();
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    for d in drawn {
        match d? {
            Some(d) => written.drawn.push(d),
            None => written.stopped = true,
        }
    }
    if written.stopped {
        // An earlier sheet under a name this run chose but did not reach is stale: removed, so
        // that the folder holds what the new index lists.
        let reached: std::collections::HashSet<&str> = written
            .drawn
            .iter()
            .map(|d| plan.sheets[d.sheet].name.as_str())
            .collect();
        for name in listed
            .iter()
            .filter(|n| chosen_names.contains(n.as_str()) && !reached.contains(n.as_str()))
        {
            written.removed.extend(remove_sheet(&out_dir.join(name))?);
        }
        write_atomic(&index_path, index::json(plan, &written.drawn).as_bytes())
            .map_err(|e| format!("cannot write {}: {e}", index_path.display()))?;
        written.index_json = Some(index_path);
        return Ok(written);
    }
    let flips: Vec<f64> = written
        .drawn
        .iter()
        .map(|d| d.summary.verdict.flip)
        .collect();
    let path = out_dir.join("overview.png");
    let chosen_sheets: Vec<(f64, bool)> = plan
        .sheets
        .iter()
        .enumerate()
        .map(|(s, sheet)| (sheet.verdict.flip, s < chosen))
        .collect();
    write_atomic(
        &path,
        &overview::png(&flips, &chosen_sheets, &worst.into_inner()),
    )
    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    written.overview = Some(path);
    for (page, html) in index::pages(plan, &written.drawn).into_iter().enumerate() {
        let path = out_dir.join(index::page_name(page));
        write_atomic(&path, html.as_bytes())
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        written.pages.push(path);
    }
    write_atomic(&index_path, index::json(plan, &written.drawn).as_bytes())
        .map_err(|e| format!("cannot write {}: {e}", index_path.display()))?;
    written.index_json = Some(index_path);
    Ok(written)
}

/// Removes an earlier run's sheet; `Some` its path when it was there.
fn remove_sheet(path: &Path) -> Result<Option<PathBuf>, String> {
    match std::fs::remove_file(path) {
        Ok(()) => Ok(Some(path.to_path_buf())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("cannot remove {}: {e}", path.display())),
    }
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
