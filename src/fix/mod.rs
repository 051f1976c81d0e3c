//! `velvet validate --fix`: findings repaired in place, as splices into the file's text.
//!
//! A [`Fix`] is a plain value: the edits that repair one or more findings (their codes and
//! pointers) and how safe they are. Each fixer ([`fixers::FIXERS`], one table from code to
//! fixer, one small unit per fixer) proposes the edits for one finding; [`plan`] merges the
//! proposals that make the same edits into one fix. A file is then checked once
//! ([`Fixing::check`]): its fixes are applied together through the same splice editor as
//! migrate, in one pass, and the fixed text is validated again; a fix that would leave its
//! finding, or bring another, is refused with the reason and the others are tried without it.
//! That one plan is every view of the run: the fixes written by `--fix`, the diff `--diff`
//! prints, the text edits of the JSON and SARIF reports and the "fixable" counts.
//!
//! Which codes are fixable, and how safely, is said by the code registry itself
//! ([`crate::diagnostics::Code::fix`]), from which `velvet codes` and docs/codes.md are
//! written; a test holds the registry and this table to each other.

pub mod buffer_view_target;
pub mod byte_order_mark;
pub mod clamp;
pub mod container;
pub mod declare;
pub mod fixers;
pub mod fuzz_roughness;
pub mod legacy;
pub mod prune;
pub mod texcoord;
pub mod text;
pub mod texture;
pub mod tidy;

use crate::asset::tape::Node;
use crate::asset::{self, Asset, Container};
use crate::diagnostics::fixes::{FileFixes, FixStatus, FixView, Repair, TextEdit};
use crate::diagnostics::{codes::IO_ERROR, Diagnostic, Safety, Settings};
use crate::edit::Edit;
use crate::validate::{FileReport, Finding, Validator};
use fixers::{Fixer, Proposal};
use rayon::prelude::*;
// foldhash's maps: a document's fixes are keyed by thousands of pointers, where std's SipHash
// was a twentieth of a fix-heavy validation.
use foldhash::{HashMap, HashMapExt, HashSet, HashSetExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// One fix: the findings it repairs, how safe it is, what it does and its edits.
#[derive(Debug, Clone, PartialEq)]
pub struct Fix {
    pub repairs: Vec<Repair>,
    pub safety: Safety,
    pub title: String,
    pub edits: Vec<Edit>,
    /// Why this fix waits for the next run: it touches what a fix of other safety changes
    /// (see [`separate`]). A deferred fix is neither applied nor given edits in this run.
    pub deferred: Option<String>,
    /// The fix removes the byte-order mark before the JSON text (which no edit of the text
    /// can say).
    pub drops_byte_order_mark: bool,
    /// The fix rebuilds a .glb's container (which no edit of the JSON text can say).
    pub rebuilds_container: bool,
}

/// The fixes for `findings` of `asset`, in the order of the findings they first repair. Fixes
/// that make the same edits are one fix repairing each of their findings.
pub fn plan(asset: &Asset, findings: &[Finding]) -> Vec<Fix> {
    let planning = fixers::Planning::new(asset);
    // Each finding's fixer proposes on its own (side by side: a document may have a fix per
    // material, and a draft sheen's upgrade plans the material as migrate does); the proposals
    // are then merged in the findings' order.
    let proposals: Vec<Option<(&Fixer, Proposal)>> = findings
        .par_iter()
        .with_min_len(PROPOSALS_PER_TASK)
        .map(|finding| {
            let fixer = fixers::fixer_for(finding.diagnostic.code)?;
            Some((fixer, (fixer.propose)(&planning, &finding.diagnostic)?))
        })
        .collect();
    let mut fixes: Vec<Fix> = Vec::new();
    // Each fix by the places its edits name; fixes that name the same places are compared
    // whole.
    let mut by_places: HashMap<u64, Vec<usize>> = HashMap::new();
    for (finding, proposed) in findings.iter().zip(proposals) {
        let Some((fixer, proposal)) = proposed else {
            continue;
        };
        let d: &Diagnostic = &finding.diagnostic;
        let repair = Repair {
            code: fixer.code.name,
            pointer: d.pointer.clone(),
            message: d.message.clone(),
        };
        let drops_byte_order_mark = fixer.code.name == crate::diagnostics::codes::BOM_PRESENT.name;
        let rebuilds_container = container::CODES.contains(&fixer.code.name);
        let places = places_key(&proposal.edits);
        let same = by_places.get(&places).and_then(|candidates| {
            candidates.iter().copied().find(|&i| {
                let f = &fixes[i];
                f.safety == fixer.safety
                    && f.drops_byte_order_mark == drops_byte_order_mark
                    && f.rebuilds_container == rebuilds_container
                    && f.edits == proposal.edits
            })
        });
        match same {
            Some(i) => fixes[i].repairs.push(repair),
            None => {
                by_places.entry(places).or_default().push(fixes.len());
                fixes.push(Fix {
                    repairs: vec![repair],
                    safety: fixer.safety,
                    title: proposal.title,
                    edits: proposal.edits,
                    deferred: None,
                    drops_byte_order_mark,
                    rebuilds_container,
                });
            }
        }
    }
    separate(asset.root(), fixes)
}

/// How many findings' fixes one task of the thread pool proposes at least: a proposal takes a
/// microsecond or two, a task's hand-over about as long.
const PROPOSALS_PER_TASK: usize = 64;

/// The kind of an edit and the place it names.
fn place_of(edit: &Edit) -> (u8, &str) {
    match edit {
        Edit::Set { pointer, .. } => (0, pointer),
        Edit::Replace { pointer, .. } => (1, pointer),
        Edit::Remove { pointer } => (2, pointer),
        Edit::DeclareUsed { extension } => (3, extension),
    }
}

/// The JSON pointer of the value `edit` changes.
fn edited_pointer(edit: &Edit) -> &str {
    match edit {
        Edit::Set { pointer, .. } | Edit::Replace { pointer, .. } | Edit::Remove { pointer } => {
            pointer
        }
        Edit::DeclareUsed { .. } => "/extensionsUsed",
    }
}

/// The path of `edit` to the document `root`, with whether it keeps every extension object
/// where it was ([`crate::rules::EditPath::keeping_extensions`]): what it sets and what was
/// there hold no `extensions` member, and it removes no array element (which would move the
/// elements after it).
fn edit_path<'e>(root: Node, edit: &'e Edit) -> crate::rules::EditPath<'e> {
    let pointer = edited_pointer(edit);
    let path = crate::rules::EditPath::of(pointer);
    let old = root.pointer(pointer);
    let old_keeps = || old.is_none_or(|old| old.members_named("extensions").next().is_none());
    let keeps = match edit {
        Edit::Set { value, .. } => {
            let new_keeps = match value {
                // Compact text that velvet wrote quotes a key as it is: a member named
                // `extensions` is the text `"extensions"` in it.
                crate::edit::SetValue::Text(text) => !text.contains("\"extensions\""),
                crate::edit::SetValue::Value(value) => !value_holds_key(value, "extensions"),
            };
            new_keeps && old_keeps()
        }
        Edit::Replace { value, .. } => !value_holds_key(value, "extensions") && old_keeps(),
        Edit::Remove { .. } => {
            let parent = pointer.rsplit_once('/').map_or("", |(parent, _)| parent);
            old_keeps() && !root.pointer(parent).is_some_and(|p| p.is_array())
        }
        Edit::DeclareUsed { .. } => false,
    };
    path.keeping_extensions(keeps)
}

/// Whether `value` has an object member named `key` at any depth.
pub(crate) fn value_holds_key(value: &serde_json::Value, key: &str) -> bool {
    match value {
        serde_json::Value::Object(members) => members
            .iter()
            .any(|(k, v)| k == key || value_holds_key(v, key)),
        serde_json::Value::Array(elements) => elements.iter().any(|v| value_holds_key(v, key)),
        _ => false,
    }
}

/// A key of the places `edits` name, in order: edits with equal keys are then compared whole,
/// so two lists whose keys collide are still told apart.
fn places_key(edits: &[Edit]) -> u64 {
    use std::hash::{BuildHasher, Hash, Hasher};
    let mut hasher = foldhash::fast::FixedState::with_seed(0).build_hasher();
    for edit in edits {
        place_of(edit).hash(&mut hasher);
    }
    hasher.finish()
}

/// Where one edit acts: the value it targets, the value holding that one, and whether it
/// changes the holder's members (a removal, a member or element added), which moves what lies
/// beside it in the text. An element's removal also reshapes what holds its array, since an
/// array emptied goes whole ([`combined`]): that second site targets no value of its own.
struct Site {
    target: Option<String>,
    holder: String,
    reshapes: bool,
}

fn sites(root: Node, edit: &Edit) -> Vec<Site> {
    let (target, reshapes) = match edit {
        Edit::Set { pointer, .. } | Edit::Replace { pointer, .. } => {
            (pointer.clone(), root.pointer(pointer).is_none())
        }
        Edit::Remove { pointer } => (pointer.clone(), true),
        // An extension is appended to the array, or the array added to the root.
        Edit::DeclareUsed { .. } => match root.pointer("/extensionsUsed") {
            Some(_) => ("/extensionsUsed/-".to_string(), true),
            None => ("/extensionsUsed".to_string(), true),
        },
    };
    let holder = fixers::parent(&target).to_string();
    let mut out = Vec::with_capacity(2);
    if matches!(edit, Edit::Remove { .. }) && root.pointer(&holder).is_some_and(|h| h.is_array()) {
        out.push(Site {
            target: None,
            holder: fixers::parent(&holder).to_string(),
            reshapes: true,
        });
    }
    out.push(Site {
        target: Some(target),
        holder,
        reshapes,
    });
    out
}

/// `fixes` with no two touching the same text, so that every fix's edits apply together in
/// one pass, in any consumer, and give what `--fix` writes. Two fixes touch when an edit of
/// one targets a value holding (or equal to) a value the other's edit targets, or when both
/// add or remove members of one value (two members added to one object are inserted at the
/// same place; two neighbours removed share a comma; a value replaced beside them is its own
/// span). Touching
/// fixes of one safety become one fix repairing all their findings; of a group holding both
/// safe and unsafe fixes, the unsafe ones wait for the next run (`deferred`, with the reason),
/// so that `--fix` alone applies exactly the safe part.
fn separate(root: Node, fixes: Vec<Fix>) -> Vec<Fix> {
    if fixes.len() < 2 {
        return fixes;
    }
    let mut group: Vec<usize> = (0..fixes.len()).collect();
    fn find(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    fn join(group: &mut [usize], a: usize, b: usize) {
        let (a, b) = (find(group, a), find(group, b));
        if a != b {
            group[a.max(b)] = a.min(b);
        }
    }
    let sites: Vec<Vec<Site>> = fixes
        .iter()
        .map(|f| f.edits.iter().flat_map(|e| sites(root, e)).collect())
        .collect();
    let mut by_target: HashMap<&str, usize> = HashMap::new();
    // The fixes that add or remove members of each value.
    let mut by_holder: HashMap<&str, Vec<usize>> = HashMap::new();
    for (i, fix_sites) in sites.iter().enumerate() {
        for s in fix_sites {
            if let Some(target) = &s.target {
                if let Some(&j) = by_target.get(target.as_str()) {
                    join(&mut group, i, j);
                }
                by_target.entry(target).or_insert(i);
            }
            if s.reshapes {
                by_holder.entry(&s.holder).or_default().push(i);
            }
        }
    }
    for (i, fix_sites) in sites.iter().enumerate() {
        for s in fix_sites.iter().filter(|s| s.target.is_some()) {
            // A value that holds this one and that another fix targets.
            let mut at = s.holder.as_str();
            loop {
                if let Some(&j) = by_target.get(at) {
                    join(&mut group, i, j);
                }
                if at.is_empty() {
                    break;
                }
                at = fixers::parent(at);
            }
        }
    }
    for reshapers in by_holder.values() {
        for &i in &reshapers[1..] {
            join(&mut group, reshapers[0], i);
        }
    }
    let roots: Vec<usize> = (0..fixes.len()).map(|i| find(&mut group, i)).collect();
    if roots.iter().enumerate().all(|(i, &r)| r == i) {
        return fixes;
    }
    let mut out: Vec<Fix> = Vec::with_capacity(fixes.len());
    // Each group's fix of each safety, by the place it has in `out`.
    let mut merged: HashMap<(usize, Safety), usize> = HashMap::new();
    let mut safe_title: HashMap<usize, String> = HashMap::new();
    for (fix, &r) in fixes.iter().zip(&roots) {
        if fix.safety == Safety::Safe {
            safe_title.entry(r).or_insert_with(|| fix.title.clone());
        }
    }
    for (fix, &r) in fixes.into_iter().zip(&roots) {
        match merged.get(&(r, fix.safety)) {
            Some(&k) => {
                let into = &mut out[k];
                into.repairs.extend(fix.repairs);
                if !into.title.split("; ").any(|t| t == fix.title) {
                    into.title = format!("{}; {}", into.title, fix.title);
                }
                into.edits.extend(fix.edits);
            }
            None => {
                merged.insert((r, fix.safety), out.len());
                out.push(fix);
            }
        }
    }
    for (&(r, safety), &k) in &merged {
        if safety == Safety::Unsafe {
            if let Some(title) = safe_title.get(&r) {
                out[k].deferred = Some(format!(
                    "it touches what the safe fix \"{title}\" changes: run --fix again once that one is applied"
                ));
            }
        }
    }
    out
}

/// The edits of `fixes` as one plan for the splice editor: each distinct edit once; removals of
/// array elements last, the highest index of each array first, so that each names the element
/// it meant; and an array all of whose elements are removed (which glTF does not allow empty)
/// removed whole, unless another edit adds to it.
pub fn combined(root: Node, fixes: &[&Fix]) -> Vec<Edit> {
    let mut edits: Vec<Edit> = Vec::new();
    // The edits kept by the place they name; an edit at a place already named is compared
    // with those before it there.
    let mut at_place: HashMap<(u8, &str), Vec<usize>> = HashMap::new();
    for edit in fixes.iter().flat_map(|f| &f.edits) {
        let kept = at_place.entry(place_of(edit)).or_default();
        if !kept.iter().any(|&k| edits[k] == *edit) {
            kept.push(edits.len());
            edits.push(edit.clone());
        }
    }
    let element_removal = |edit: &Edit| -> Option<(String, usize)> {
        let Edit::Remove { pointer } = edit else {
            return None;
        };
        let index = crate::asset::pointer::array_index(&fixers::last_token(pointer)?)?;
        let parent = fixers::parent(pointer);
        root.pointer(parent)?.as_array()?;
        Some((parent.to_string(), index))
    };
    let (mut removals, rest): (Vec<(String, usize)>, Vec<Edit>) = {
        let mut removals = Vec::new();
        let mut rest = Vec::new();
        for edit in edits {
            match element_removal(&edit) {
                Some(r) => removals.push(r),
                None => rest.push(edit),
            }
        }
        (removals, rest)
    };
    removals.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
    let mut out = rest;
    let mut i = 0;
    while i < removals.len() {
        let parent = removals[i].0.clone();
        let count = removals[i..].iter().take_while(|r| r.0 == parent).count();
        let len = root
            .pointer(&parent)
            .and_then(|a| a.as_array())
            .map_or(0, |a| a.len());
        let added_to = out.iter().any(|e| match e {
            Edit::DeclareUsed { .. } => parent == "/extensionsUsed",
            Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer } => pointer.starts_with(&format!("{parent}/")),
        });
        if count == len && !added_to && !parent.is_empty() {
            out.push(Edit::remove(parent.clone()));
        } else {
            out.extend(
                removals[i..i + count]
                    .iter()
                    .map(|(p, k)| Edit::remove(format!("{p}/{k}"))),
            );
        }
        i += count;
    }
    out
}

/// What a validate run does with fixes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Mode {
    /// `--fix`: write the fixes into the files.
    pub apply: bool,
    /// `--diff`: show the fixes as a unified diff; write nothing.
    pub diff: bool,
    /// `--unsafe-fixes`: apply unsafe fixes too.
    pub unsafe_fixes: bool,
    /// Give each fix its edits of the text (the JSON and SARIF reports show them; a text
    /// report does not, and a document with thousands of fixes is spared working them out).
    pub edits: bool,
}

impl Mode {
    fn changes(self) -> bool {
        self.apply || self.diff
    }

    /// Whether a fix of `safety` is applied in this mode (when it changes anything).
    pub fn applies(self, safety: Safety) -> bool {
        safety == Safety::Safe || self.unsafe_fixes
    }
}

/// The UTF-8 byte-order mark, the only thing a .gltf's JSON text may follow in its file.
const BYTE_ORDER_MARK: [u8; 3] = [0xEF, 0xBB, 0xBF];

/// The most fixes of one file tried one by one when they fail together.
const TRIED_ONE_BY_ONE: usize = 32;

/// The most rounds of fixes tried together, each without the fixes the last round's offending
/// findings were laid to.
const ROUNDS_LAID_TO_FIXES: usize = 4;

/// A validate run's files checked, fixed or shown with their fixes (see the module comment).
pub struct Fixing<'v> {
    validator: &'v Validator,
    mode: Mode,
    changed: AtomicUsize,
    /// Whether the run was asked to stop (the command's SIGINT and SIGTERM handling): a file
    /// not yet written is then abandoned, one already written stays as it is.
    stop: fn() -> bool,
    /// Files abandoned because the run was asked to stop.
    abandoned: AtomicUsize,
    /// The file each check writes, held while it is checked: a folder holding a link and its
    /// target fixes the target once, the second check reading what the first wrote.
    writing: Mutex<HashMap<PathBuf, Arc<Mutex<()>>>>,
}

/// The write error of a file abandoned because the run was asked to stop (nothing of it was
/// written); its report is left out of the output.
pub const ABANDONED: &str = "stopped before it was written (nothing of it was written)";

/// The file a write to `path` must replace: for a symbolic link, the file it leads to, so that
/// the link stays a link and its target is the file fixed (renaming a temporary file over the
/// link would replace the link with a regular file and leave its target as it was). A link
/// leading out of the folders given is refused before the run (`command::validate`).
fn written_file(path: &Path) -> PathBuf {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.is_symlink());
    match is_link.then(|| path.canonicalize()) {
        Some(Ok(target)) => target,
        _ => path.to_path_buf(),
    }
}

/// A file with fixes applied, validated again.
struct Fixed {
    /// Whether the edits changed the document (a GLB's bytes are repacked either way).
    changed: bool,
    /// The fixed file's bytes, unless they are the fixed document's text as it is (a .gltf
    /// in plain UTF-8, whose text the loader took without a copy).
    kept_bytes: Option<Vec<u8>>,
    /// The fixed document, loaded, and its report (of every finding).
    asset: Asset,
    report: FileReport,
}

impl Fixed {
    /// The fixed file's bytes.
    fn bytes(&self) -> &[u8] {
        match &self.kept_bytes {
            Some(bytes) => bytes,
            None => self.asset.json_text.as_bytes(),
        }
    }
}

impl<'v> Fixing<'v> {
    pub fn new(validator: &'v Validator, mode: Mode) -> Fixing<'v> {
        Fixing {
            validator,
            mode,
            changed: AtomicUsize::new(0),
            stop: || false,
            abandoned: AtomicUsize::new(0),
            writing: Mutex::new(HashMap::new()),
        }
    }

    /// The same, abandoning the files not yet written once `stop` says so.
    pub fn stopping_when(self, stop: fn() -> bool) -> Fixing<'v> {
        Fixing { stop, ..self }
    }

    /// How many files were abandoned because the run was asked to stop.
    pub fn files_abandoned(&self) -> usize {
        self.abandoned.load(Ordering::Relaxed)
    }

    /// The report of a file abandoned before it was written.
    fn abandoned(&self, path: &Path) -> FileReport {
        self.abandoned.fetch_add(1, Ordering::Relaxed);
        let mut fixes = FileFixes::new(Vec::new());
        fixes.write_error = Some(ABANDONED.to_string());
        FileReport {
            path: path.to_path_buf(),
            container: None,
            json_offset: 0,
            findings: Vec::new(),
            counts: Default::default(),
            omitted: 0,
            info: None,
            missing: Default::default(),
            fixes,
            rule_spans: Vec::new(),
        }
    }

    /// How many files the run changed (or, with `--diff`, would change).
    pub fn files_changed(&self) -> usize {
        self.changed.load(Ordering::Relaxed)
    }

    /// The file at `path` validated under `settings`, its fixes planned and, as the mode says,
    /// applied: the report of the file as it is after the run, with its fixes.
    pub fn check(&self, path: &Path, settings: &Settings) -> FileReport {
        if !self.mode.apply {
            return self.check_unlocked(path, settings);
        }
        if (self.stop)() {
            return self.abandoned(path);
        }
        let lock = {
            let mut writing = self.writing.lock().unwrap_or_else(|e| e.into_inner());
            writing.entry(written_file(path)).or_default().clone()
        };
        let _held = lock.lock().unwrap_or_else(|e| e.into_inner());
        self.check_unlocked(path, settings)
    }

    fn check_unlocked(&self, path: &Path, settings: &Settings) -> FileReport {
        let load = &self.validator.load;
        let (loaded, snapshot) = if self.mode.apply {
            match asset::read_for_writing(path, load) {
                Ok((bytes, snapshot)) => (asset::load_read(path, bytes, load).0, Some(snapshot)),
                Err(_) => (asset::load_with(path, load), None),
            }
        } else {
            (asset::load_with(path, load), None)
        };
        self.check_loaded(path, loaded, snapshot, settings, self.mode)
    }

    /// [`Fixing::check`] of a file loaded (`snapshot`: what it was when read, for writing it),
    /// in `mode`.
    fn check_loaded(
        &self,
        path: &Path,
        loaded: asset::Loaded,
        snapshot: Option<asset::Snapshot>,
        settings: &Settings,
        mode: Mode,
    ) -> FileReport {
        let Some(mut source) = loaded.asset else {
            return self.validator.validate_loaded_with(path, loaded, settings);
        };
        self.validator.share_folder_lookups(&mut source);
        // Every finding is planned for and compared, also those a --max-issues cap leaves out
        // of the listing.
        let unlimited = Settings {
            max_issues: None,
            ..settings.clone()
        };
        let before = self
            .validator
            .validate_asset(path, &source, loaded.diagnostics, &unlimited);
        self.check_validated(path, source, before, snapshot, settings, mode)
    }

    /// [`Fixing::check_loaded`] of a document whose report (`before`, of every finding, under
    /// `settings` uncapped) is known.
    fn check_validated(
        &self,
        path: &Path,
        source: Asset,
        before: FileReport,
        snapshot: Option<asset::Snapshot>,
        settings: &Settings,
        mode: Mode,
    ) -> FileReport {
        let unlimited = Settings {
            max_issues: None,
            ..settings.clone()
        };
        crate::progress::stage("planning fixes", 0);
        let fixes = plan(&source, &before.findings);
        if fixes.is_empty() {
            return capped(before, settings);
        }
        crate::progress::stage("trying fixes", 0);
        // The fixes this run would apply, tried together on the file (each try validates the
        // fixed text again): a report carries a fix only if `--fix` would apply it, and says
        // why it refuses the others. A run without --fix tries every fix, as --fix
        // --unsafe-fixes would apply them; a deferred fix waits for the next run.
        let wanted: Vec<usize> = (0..fixes.len())
            .filter(|&i| fixes[i].deferred.is_none())
            .filter(|&i| !mode.changes() || mode.applies(fixes[i].safety))
            .collect();
        // The fixes' text edits (for the JSON and SARIF reports) do not depend on which are
        // accepted: they are worked out on the other core while the fixes are tried.
        let ((accepted, mut refused, fixed), edits) = rayon::join(
            || self.choose(path, &source, &before, &fixes, &wanted, &unlimited),
            || {
                if mode.edits {
                    all_text_edits(&source, &fixes)
                } else {
                    vec![Vec::new(); fixes.len()]
                }
            },
        );
        for (i, fix) in fixes.iter().enumerate() {
            if let Some(reason) = &fix.deferred {
                refused.push((i, reason.clone()));
            }
        }
        let changed = fixed
            .as_ref()
            .filter(|f| {
                mode.changes()
                    && !accepted.is_empty()
                    && f.changed
                    && !same_as_read(&source, f.bytes())
            })
            .is_some();
        if mode.changes() && !changed {
            // The fixes this mode does not apply (unsafe ones without --unsafe-fixes), tried
            // on the file as it stays, for the report. Once the file changes, the fixes left
            // are planned and tried against its new text.
            let untried: Vec<usize> = (0..fixes.len())
                .filter(|&i| fixes[i].deferred.is_none() && !mode.applies(fixes[i].safety))
                .collect();
            let (_, more, _) = self.choose(path, &source, &before, &fixes, &untried, &unlimited);
            refused.extend(more);
        }
        let mut statuses = vec![FixStatus::Available; fixes.len()];
        if changed {
            for &i in &accepted {
                statuses[i] = FixStatus::Applied;
            }
        }
        for (i, reason) in refused {
            statuses[i] = FixStatus::Refused(reason);
        }
        let views: Vec<FixView> = fixes
            .into_iter()
            .zip(edits)
            .zip(statuses)
            .map(|((fix, edits), status)| FixView {
                repairs: fix.repairs,
                safety: fix.safety,
                title: fix.title,
                edits,
                status,
            })
            .collect();
        let mut file_fixes = FileFixes::new(views);
        file_fixes.changed = changed;
        let Some(mut fixed) = fixed.filter(|_| changed) else {
            let mut report = capped(before, settings);
            report.fixes = file_fixes;
            return report;
        };
        self.validator
            .place_findings(&fixed.asset, &mut fixed.report);
        if mode.diff {
            let name = crate::asset::discover::display_path(path);
            file_fixes.diff = Some(match source.container {
                // The files' texts, a byte-order mark (U+FEFF) and its removal included.
                Container::Gltf => text::unified_diff(
                    &name,
                    &format!(
                        "{}{}",
                        if source.byte_order_mark {
                            "\u{feff}"
                        } else {
                            ""
                        },
                        source.json_text.as_str()
                    ),
                    &String::from_utf8_lossy(fixed.bytes()),
                ),
                Container::Glb => text::glb_not_diffed(&name),
            });
        } else {
            if (self.stop)() {
                return self.abandoned(path);
            }
            let written = match &snapshot {
                Some(snapshot) => snapshot.unchanged(path),
                None => Err(format!("{} could not be read for writing", path.display())),
            }
            .and_then(|()| {
                crate::edit::write::write_atomic(&written_file(path), fixed.bytes())
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))
            });
            if let Err(e) = written {
                // Nothing was written: the file's findings stand, and the run fails.
                let mut report = capped(before, settings);
                file_fixes.refuse_applied(&format!("not written: {e}"));
                file_fixes.write_error = Some(e.clone());
                report.findings.push(Finding {
                    diagnostic: Diagnostic::new(&IO_ERROR, "", e),
                    position: None,
                });
                report.counts.errors += 1;
                report.fixes = file_fixes;
                return report;
            }
        }
        self.changed.fetch_add(1, Ordering::Relaxed);
        if mode.diff {
            // The file is as it was: the fixes left are given against its text.
            let mut report = capped(fixed.report, settings);
            report.fixes = file_fixes;
            return report;
        }
        // The report of the file as written: its findings, and the fixes left for them planned
        // against its new text (an unsafe fix not asked for, a refused one), with this run's.
        // The fixed document was loaded and validated before it was written: its report
        // stands for the file as written.
        let review = Mode {
            apply: false,
            diff: false,
            ..mode
        };
        let mut report =
            self.check_validated(path, fixed.asset, fixed.report, None, settings, review);
        let mut all: Vec<FixView> = file_fixes
            .fixes()
            .iter()
            .filter(|f| f.status == FixStatus::Applied)
            .cloned()
            .collect();
        all.extend(report.fixes.fixes().iter().cloned());
        report.fixes = FileFixes::new(all);
        report.fixes.changed = true;
        report
    }

    /// The fixes of `wanted` that can be applied together, the refused ones with the reason,
    /// and the file with the accepted ones applied. All are tried at once first; when that
    /// fails, the fixes each offending finding is laid to ([`culprits`]) are refused and the
    /// rest tried again (a few rounds); when a failure cannot be laid to a fix, one by one (the
    /// first [`TRIED_ONE_BY_ONE`]), each kept if the file with it and those kept before is
    /// still as meant.
    #[allow(clippy::type_complexity)]
    fn choose(
        &self,
        path: &Path,
        source: &Asset,
        before: &FileReport,
        fixes: &[Fix],
        wanted: &[usize],
        settings: &Settings,
    ) -> (Vec<usize>, Vec<(usize, String)>, Option<Fixed>) {
        let mut trial = wanted.to_vec();
        let mut refused = Vec::new();
        for _round in 0..ROUNDS_LAID_TO_FIXES {
            if trial.is_empty() {
                return (Vec::new(), refused, None);
            }
            let all: Vec<&Fix> = trial.iter().map(|&i| &fixes[i]).collect();
            let offences = match self.attempt(path, source, before, &all, settings) {
                Ok(fixed) => return (trial, refused, Some(fixed)),
                Err(Failed::Findings(offences)) => offences,
                Err(Failed::Other(_)) => break,
            };
            let blame = Blame::new(fixes, &trial);
            let mut laid: Vec<(usize, String)> = Vec::new();
            let mut is_laid = vec![false; fixes.len()];
            for offence in &offences {
                for i in blame.culprits(offence) {
                    if !std::mem::replace(&mut is_laid[i], true) {
                        laid.push((i, offence.reason()));
                    }
                }
            }
            if laid.is_empty() {
                break;
            }
            trial.retain(|&i| !is_laid[i]);
            refused.extend(laid);
        }
        let mut accepted = Vec::new();
        let mut fixed = None;
        for (n, &i) in trial.iter().enumerate() {
            if n >= TRIED_ONE_BY_ONE {
                refused.push((
                    i,
                    "not tried: too many fixes of this file fail together; run --fix again"
                        .to_string(),
                ));
                continue;
            }
            let mut one_more: Vec<&Fix> = accepted.iter().map(|&a| &fixes[a]).collect();
            one_more.push(&fixes[i]);
            match self.attempt(path, source, before, &one_more, settings) {
                Ok(f) => {
                    accepted.push(i);
                    fixed = Some(f);
                }
                Err(failed) => refused.push((i, failed.reason())),
            }
        }
        refused.sort_by_key(|(i, _)| *i);
        (accepted, refused, fixed)
    }

    /// `fixes` applied to `source` in one pass, and the result validated: `Err` with the
    /// reason when it does not load, still has a finding a fix repairs, or has one `before`
    /// did not.
    fn attempt(
        &self,
        path: &Path,
        source: &Asset,
        before: &FileReport,
        fixes: &[&Fix],
        settings: &Settings,
    ) -> Result<Fixed, Failed> {
        let edits = combined(source.root(), fixes);
        let (output, changed) = match crate::edit::write::spliced_bytes(source, &edits) {
            Ok(Some(spliced)) => spliced,
            Ok(None) => {
                return Err(Failed::Other(
                    "its edits could not be spliced into the file's text".into(),
                ))
            }
            Err(e) => return Err(Failed::Other(format!("its edits do not apply: {e}"))),
        };
        let drops_byte_order_mark = fixes.iter().any(|f| f.drops_byte_order_mark);
        let rebuilds_container = fixes.iter().any(|f| f.rebuilds_container);
        let changed = changed
            || (drops_byte_order_mark && source.byte_order_mark)
            || (rebuilds_container && source.container == Container::Glb);
        let (loaded, kept_bytes) = match output {
            // A .gltf's text as spliced, nothing put before it: its index takes the file's for
            // what comes before the first edit (often near the end), copied on the other core
            // while the text is joined (the library's 9.8 MB: each about 2 ms).
            crate::edit::write::Output::Spliced(spliced)
                if source.container == Container::Gltf && source.json_offset == 0 =>
            {
                let (text, resumption) = rayon::join(
                    || spliced.to_text(),
                    || {
                        spliced
                            .first_change()
                            .and_then(|at| source.tape.resumption(at, spliced.len()))
                    },
                );
                // The resumption holds for a text equal to the file's up to its first edit.
                debug_assert!(spliced.first_change().is_none_or(|at| {
                    text.as_bytes().get(..at) == source.json_text.as_bytes().get(..at)
                }));
                let (loaded, back) =
                    asset::load_joined_resuming(path, text, &self.validator.load, resumption);
                (loaded, back.map(asset::FileBytes::into_vec))
            }
            output => {
                let mut bytes: Vec<u8> = match output {
                    crate::edit::write::Output::Bytes(bytes) => bytes.into_owned(),
                    crate::edit::write::Output::Spliced(spliced) => spliced.to_text().into_bytes(),
                };
                if source.container == Container::Gltf
                    && source.json_offset > 0
                    && !drops_byte_order_mark
                {
                    // What came before the text (a byte-order mark, which has its own finding)
                    // stays unless its fix is applied: a fix changes only what it says.
                    let mut file = BYTE_ORDER_MARK[..source.json_offset.min(3)].to_vec();
                    file.append(&mut bytes);
                    bytes = file;
                }
                if source.container == Container::Gltf {
                    // A fixed .gltf's bytes become its text as they are: a copy of a large
                    // document costs about as much as indexing it.
                    let (loaded, back) = asset::load_given(
                        path,
                        asset::FileBytes::from_vec(bytes),
                        &self.validator.load,
                    );
                    (loaded, back.map(asset::FileBytes::into_vec))
                } else {
                    (
                        asset::load_bytes_with(path, &bytes, &self.validator.load),
                        Some(bytes),
                    )
                }
            }
        };
        let Some(mut after) = loaded.asset else {
            return Err(Failed::Other("the fixed file would not load".into()));
        };
        // Its resources are the file's: what the file system said of them holds.
        after.share_lookups(source);
        // Placed in the text (line and column) only if it becomes the file's report. The
        // rules that read nothing the edits touch (the data checks, for most fixes) give the
        // file's findings again: they are taken from its report rather than read again. A
        // fix of the byte-order mark or the container changes what lies outside the text.
        let root = source.root();
        let exists = |pointer: &str| root.pointer(pointer).is_some();
        let paths: Vec<crate::rules::EditPath> =
            edits.iter().map(|edit| edit_path(root, edit)).collect();
        let touched = |reads: &crate::rules::Reads| {
            paths.iter().any(|path| reads.touched_by_path(path, exists))
        };
        let mut elements: Option<Vec<crate::rules::ElementPlace>> = edits
            .iter()
            .map(|edit| crate::rules::ElementPlace::of_edit(root, edited_pointer(edit)))
            .collect();
        if let Some(elements) = &mut elements {
            elements.sort_by(|a, b| (&a.property, a.index).cmp(&(&b.property, b.index)));
            elements.dedup();
        }
        let reuse = crate::validate::Reuse {
            report: before,
            touched: &touched,
            elements: elements.as_deref(),
        };
        let outside_the_text = drops_byte_order_mark || rebuilds_container;
        let report = self.validator.validate_asset_unplaced(
            path,
            &after,
            loaded.diagnostics,
            settings,
            (!outside_the_text).then_some(&reuse),
        );
        verdict(&before.findings, &report.findings, fixes).map_err(Failed::Findings)?;
        Ok(Fixed {
            changed,
            kept_bytes,
            asset: after,
            report,
        })
    }
}

/// Why fixes tried together were refused.
enum Failed {
    /// The fixed file's findings that refuse them ([`verdict`]).
    Findings(Vec<Offence>),
    /// The edits did not apply, or the fixed file did not load.
    Other(String),
}

impl Failed {
    fn reason(&self) -> String {
        match self {
            Failed::Findings(offences) => offences.first().map(Offence::reason).unwrap_or_default(),
            Failed::Other(reason) => reason.clone(),
        }
    }
}

/// Where `asset`'s JSON text starts in what its fixes' edits are given against: its file (a
/// .gltf, after a byte-order mark) or its JSON chunk (a .glb: after a mark, or at 0).
fn edits_text_start(asset: &Asset) -> usize {
    match asset.container {
        Container::Gltf => asset.json_offset,
        Container::Glb => {
            if asset.byte_order_mark {
                BYTE_ORDER_MARK.len()
            } else {
                0
            }
        }
    }
}

/// Whether `bytes` are the file `asset` was read from: a .gltf's text (after its byte-order
/// mark, if it had one); a .glb's fixed bytes are its container rebuilt, never compared equal.
fn same_as_read(asset: &Asset, bytes: &[u8]) -> bool {
    let text = asset.json_text.as_bytes();
    match asset.container {
        Container::Gltf => {
            let lead = asset.json_offset;
            bytes.len() == lead + text.len()
                && bytes[..lead] == BYTE_ORDER_MARK[..lead.min(3)]
                && &bytes[lead..] == text
        }
        Container::Glb => false,
    }
}

/// A finding of a fixed file that refuses the fixes: one a fix was to repair, still there
/// (`left`), or a new error or warning.
#[derive(Debug, Clone, PartialEq)]
struct Offence {
    code: &'static str,
    message: String,
    pointer: String,
    left: bool,
}

impl Offence {
    fn reason(&self) -> String {
        if self.left {
            format!("the fixed file would still have {}", self.code)
        } else {
            format!("the fixed file would have {} ({})", self.code, self.message)
        }
    }
}

/// Whether the findings `after` fixing are those `before` without the ones `fixes` repair
/// (counted by code and message: a pointer into an array moves when an element before it is
/// removed; and a finding whose message quotes a value a fix changed, at the same code and
/// pointer, is the same finding). More are fine (a fix may repair more than it says); one left
/// is not, nor is a new error or warning. A new info or hint is not a reason to refuse: the
/// default a fix writes may be one a hint notes (as ruff and eslint apply a fix that leaves a
/// note). `Err` holds every offending finding of `after`, in report order.
fn verdict(before: &[Finding], after: &[Finding], fixes: &[&Fix]) -> Result<(), Vec<Offence>> {
    let mut excess: HashMap<(&str, &str), i64> = HashMap::new();
    for f in after {
        *excess
            .entry((f.diagnostic.code, f.diagnostic.message.as_str()))
            .or_default() += 1;
    }
    for f in before {
        *excess
            .entry((f.diagnostic.code, f.diagnostic.message.as_str()))
            .or_default() -= 1;
    }
    let mut repaired: HashSet<(&str, &str)> = HashSet::new();
    for r in fixes.iter().flat_map(|f| &f.repairs) {
        *excess.entry((r.code, r.message.as_str())).or_default() += 1;
        repaired.insert((r.code, r.message.as_str()));
    }
    if excess.values().all(|&n| n <= 0) {
        return Ok(());
    }
    // The findings before that are gone beyond what the fixes repair, by code and pointer: one
    // of them reworded (its message quotes a value a fix changed) is no new finding.
    let mut gone: HashMap<(&str, &str), Vec<&str>> = HashMap::new();
    for f in before {
        let key = (f.diagnostic.code, f.diagnostic.message.as_str());
        if excess.get(&key).copied().unwrap_or(0) < 0 {
            gone.entry((f.diagnostic.code, f.diagnostic.pointer.as_str()))
                .or_default()
                .push(f.diagnostic.message.as_str());
        }
    }
    let mut offences = Vec::new();
    for f in after {
        let key = (f.diagnostic.code, f.diagnostic.message.as_str());
        if excess.get(&key).copied().unwrap_or(0) <= 0 {
            continue;
        }
        let left = repaired.contains(&key);
        if !left {
            let reworded = gone
                .get_mut(&(f.diagnostic.code, f.diagnostic.pointer.as_str()))
                .and_then(|messages| {
                    let at = messages
                        .iter()
                        .position(|m| excess.get(&(key.0, *m)).copied().unwrap_or(0) < 0)?;
                    Some(messages.swap_remove(at))
                });
            if let Some(was) = reworded {
                *excess.entry(key).or_default() -= 1;
                *excess.entry((key.0, was)).or_default() += 1;
                continue;
            }
            if f.diagnostic.severity > crate::diagnostics::Severity::Warning {
                continue;
            }
        }
        *excess.entry(key).or_default() -= 1;
        offences.push(Offence {
            code: f.diagnostic.code,
            message: f.diagnostic.message.clone(),
            pointer: f.diagnostic.pointer.clone(),
            left,
        });
    }
    if offences.is_empty() {
        Ok(())
    } else {
        Err(offences)
    }
}

/// The fixes of a trial by what an offending finding can be laid to (see [`Blame::culprits`]),
/// found once per trial: a document may have thousands of fixes and of offending findings.
struct Blame<'f> {
    /// By the finding each repairs (code and message).
    repairing: HashMap<(&'f str, &'f str), Vec<usize>>,
    /// By the pointer an edit targets.
    at: HashMap<&'f str, Vec<usize>>,
    /// By each pointer that holds a value an edit targets.
    within: HashMap<&'f str, Vec<usize>>,
}

impl<'f> Blame<'f> {
    fn new(fixes: &'f [Fix], trial: &[usize]) -> Blame<'f> {
        let mut blame = Blame {
            repairing: HashMap::new(),
            at: HashMap::new(),
            within: HashMap::new(),
        };
        for &i in trial {
            let fix = &fixes[i];
            for r in &fix.repairs {
                blame
                    .repairing
                    .entry((r.code, r.message.as_str()))
                    .or_default()
                    .push(i);
            }
            for edit in &fix.edits {
                let pointer = match edit {
                    Edit::Set { pointer, .. }
                    | Edit::Replace { pointer, .. }
                    | Edit::Remove { pointer } => pointer.as_str(),
                    Edit::DeclareUsed { .. } => "/extensionsUsed",
                };
                blame.at.entry(pointer).or_default().push(i);
                let mut holder = fixers::parent(pointer);
                while !holder.is_empty() {
                    blame.within.entry(holder).or_default().push(i);
                    holder = fixers::parent(holder);
                }
            }
        }
        blame
    }

    /// The fixes `offence` is laid to, each once: for a finding left, those meant to repair
    /// it; for a new one, those editing its value, a value in it or one holding it.
    fn culprits(&self, offence: &Offence) -> Vec<usize> {
        let mut out: Vec<usize> = Vec::new();
        if offence.left {
            out.extend(
                self.repairing
                    .get(&(offence.code, offence.message.as_str()))
                    .into_iter()
                    .flatten(),
            );
        } else {
            let pointer = offence.pointer.as_str();
            out.extend(self.at.get(pointer).into_iter().flatten());
            out.extend(self.within.get(pointer).into_iter().flatten());
            let mut holder = pointer;
            while !holder.is_empty() {
                holder = fixers::parent(holder);
                out.extend(self.at.get(holder).into_iter().flatten());
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

/// The edits of the JSON text each of `fixes` makes alone. Fixes that edit within one element
/// of a top-level array (a material's fixes, of which a document may have thousands) are
/// spliced in rounds of fixes in distinct elements, each round in one pass, and each
/// replacement goes to the fix whose element holds it; the others are spliced one by one.
fn all_text_edits(source: &Asset, fixes: &[Fix]) -> Vec<Vec<TextEdit>> {
    let root = source.root();
    let units: Vec<Option<(String, std::ops::Range<usize>)>> =
        fixes.iter().map(|fix| element_of(root, fix)).collect();
    // Rounds of fixes in distinct elements: the k-th fix of each element goes to round k, so a
    // round's fixes are spliced together and each replacement placed by the element it lies
    // in. A document whose elements each hold a few fixes takes a few passes over its text,
    // not one per fix (which made 4,000 fixes of a 2.5 MB document take over a second, and
    // 20,000 of a 10 MB one twenty).
    let mut rounds: Vec<Vec<usize>> = Vec::new();
    let mut alone: Vec<usize> = Vec::new();
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for (i, unit) in units.iter().enumerate() {
        match unit {
            Some((pointer, _)) => {
                let k = seen.entry(pointer.as_str()).or_default();
                if rounds.len() <= *k {
                    rounds.push(Vec::new());
                }
                rounds[*k].push(i);
                *k += 1;
            }
            None => alone.push(i),
        }
    }
    let mut out = vec![Vec::new(); fixes.len()];
    for round in rounds {
        match placed_together(source, fixes, &units, &round) {
            Some(placed) => {
                for (i, edits) in round.into_iter().zip(placed) {
                    out[i] = edits;
                }
            }
            None => alone.extend(round),
        }
    }
    let done: Vec<(usize, Vec<TextEdit>)> = alone
        .par_iter()
        .map(|&i| (i, fix_text_edits(source, &fixes[i])))
        .collect();
    for (i, edits) in done {
        out[i] = edits;
    }
    out
}

/// The text edits of each fix of `round` (fixes in distinct elements, `units` their elements),
/// spliced together in one pass, each replacement placed by the element it lies in; `None`
/// when the splicer does not take them together or a replacement lies outside every element.
fn placed_together(
    source: &Asset,
    fixes: &[Fix],
    units: &[Option<(String, std::ops::Range<usize>)>],
    round: &[usize],
) -> Option<Vec<Vec<TextEdit>>> {
    let root = source.root();
    let text = crate::edit::write::source(source);
    let together: Vec<&Fix> = round.iter().map(|&i| &fixes[i]).collect();
    let edits = combined(root, &together);
    let Ok(Some((spliced, _))) = crate::edit::splice::splice_edits(text, root, &edits) else {
        return None;
    };
    let replacements = text::replacements(text, &spliced);
    let text_edits = text::text_edits(text, &replacements, edits_text_start(source));
    // The round's elements by where they start, with each one's place in the round.
    let mut by_start: Vec<(std::ops::Range<usize>, usize)> = round
        .iter()
        .enumerate()
        .map(|(k, &i)| (units[i].as_ref().map(|(_, s)| s.clone()), k))
        .map(|(span, k)| span.map(|s| (s, k)))
        .collect::<Option<_>>()?;
    by_start.sort_by_key(|(s, _)| s.start);
    let mut placed = vec![Vec::new(); round.len()];
    for (r, edit) in replacements.iter().zip(text_edits) {
        let k = by_start.partition_point(|(s, _)| s.start <= r.start);
        let (span, slot) = &by_start[k.checked_sub(1)?];
        if r.end > span.end {
            return None;
        }
        placed[*slot].push(edit);
    }
    Some(placed)
}

/// The element of a top-level array (`/materials/3`) within which every edit of `fix` lies,
/// with its span, if there is one.
fn element_of(root: Node, fix: &Fix) -> Option<(String, std::ops::Range<usize>)> {
    let mut unit: Option<(String, std::ops::Range<usize>)> = None;
    for edit in &fix.edits {
        let pointer = match edit {
            Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer } => pointer,
            Edit::DeclareUsed { .. } => return None,
        };
        let mut tokens = pointer.splitn(4, '/');
        tokens.next();
        let (member, index) = (tokens.next()?, tokens.next()?);
        // Within the element, not the element itself.
        tokens.next()?;
        crate::asset::pointer::array_index(index)?;
        let at = format!("/{member}/{index}");
        if unit.as_ref().is_some_and(|(u, _)| *u != at) {
            return None;
        }
        let span = root.pointer(&at)?.span();
        unit = Some((at, span));
    }
    unit
}

/// The edits of the JSON text that `fix` makes alone (with the removal of a byte-order mark
/// before it, for the fix that removes one).
fn fix_text_edits(source: &Asset, fix: &Fix) -> Vec<TextEdit> {
    if fix.drops_byte_order_mark {
        let mut edits = vec![text::lead_removed(edits_text_start(source))];
        if !fix.edits.is_empty() {
            edits.extend(fix_text_edits(
                source,
                &Fix {
                    drops_byte_order_mark: false,
                    ..fix.clone()
                },
            ));
        }
        return edits;
    }
    let edits = combined(source.root(), &[fix]);
    let text = crate::edit::write::source(source);
    match crate::edit::splice::splice_edits(text, source.root(), &edits) {
        Ok(Some((spliced, true))) => text::text_edits(
            text,
            &text::replacements(text, &spliced),
            edits_text_start(source),
        ),
        _ => Vec::new(),
    }
}

/// `report` (of every finding) with `settings`' cap on the listing, as a validation under
/// `settings` lists it: the most severe findings kept.
fn capped(mut report: FileReport, settings: &Settings) -> FileReport {
    if let Some(max) = settings
        .max_issues
        .filter(|max| report.findings.len() > *max)
    {
        report.findings.sort_by_key(|f| f.diagnostic.severity);
        report.omitted = report.findings.len() - max;
        report.findings.truncate(max);
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::all_codes;

    fn load(text: &str) -> Asset {
        asset::load_bytes(Path::new("m.gltf"), text.as_bytes())
            .asset
            .expect("the document loads")
    }

    fn fix(edits: Vec<Edit>) -> Fix {
        Fix {
            repairs: Vec::new(),
            safety: Safety::Safe,
            title: String::new(),
            edits,
            deferred: None,
            drops_byte_order_mark: false,
            rebuilds_container: false,
        }
    }

    fn finding(code: &'static crate::diagnostics::Code, pointer: &str, message: &str) -> Finding {
        Finding {
            diagnostic: Diagnostic::new(code, pointer, message),
            position: None,
        }
    }

    #[test]
    fn removals_from_one_array_go_last_highest_index_first_and_an_emptied_array_goes_whole() {
        let asset = load(r#"{"asset":{"version":"2.0"},"extensionsUsed":["A","B","C"]}"#);
        let (a, b) = (
            fix(vec![Edit::remove("/extensionsUsed/0")]),
            fix(vec![Edit::remove("/extensionsUsed/1")]),
        );
        assert_eq!(
            combined(asset.root(), &[&a, &b]),
            [
                Edit::remove("/extensionsUsed/1"),
                Edit::remove("/extensionsUsed/0")
            ]
        );
        let c = fix(vec![Edit::remove("/extensionsUsed/2")]);
        assert_eq!(
            combined(asset.root(), &[&a, &b, &c]),
            [Edit::remove("/extensionsUsed")]
        );
        // Kept when another fix declares an extension in it; each distinct edit once.
        let d = fix(vec![Edit::declare_used("D")]);
        assert_eq!(
            combined(asset.root(), &[&a, &b, &c, &d, &d]),
            [
                Edit::declare_used("D"),
                Edit::remove("/extensionsUsed/2"),
                Edit::remove("/extensionsUsed/1"),
                Edit::remove("/extensionsUsed/0"),
            ]
        );
    }

    #[test]
    fn fixes_that_touch_one_text_are_merged_and_an_unsafe_one_beside_a_safe_one_waits() {
        let asset = load(
            r#"{"asset":{"version":"2.0"},"materials":[{"name":"m","alphaCutoff":0.5,"emissiveFactor":[2,0,0],"extensions":{"KHR_materials_fuzz":{"fuzzFactor":1,"fuzzTexture":{"index":0}}}}]}"#,
        );
        let with = |safety, title: &str, edits| Fix {
            safety,
            title: title.to_string(),
            ..fix(edits)
        };
        let fuzz = "/materials/0/extensions/KHR_materials_fuzz";
        let fixes = vec![
            // Two declarations into one new extensionsUsed: one fix.
            with(Safety::Safe, "a", vec![Edit::declare_used("A")]),
            with(Safety::Safe, "b", vec![Edit::declare_used("B")]),
            // Values replaced beside a member removed: apart.
            with(
                Safety::Unsafe,
                "clamp",
                vec![Edit::set(
                    "/materials/0/emissiveFactor/0",
                    serde_json::json!(1),
                )],
            ),
            with(
                Safety::Safe,
                "cutoff",
                vec![Edit::remove("/materials/0/alphaCutoff")],
            ),
            // A member added (safe) and one removed (unsafe) in one object: the unsafe waits.
            with(
                Safety::Safe,
                "roughness",
                vec![Edit::set(
                    format!("{fuzz}/fuzzRoughnessFactor"),
                    serde_json::json!(0.5),
                )],
            ),
            with(
                Safety::Unsafe,
                "texture",
                vec![Edit::remove(format!("{fuzz}/fuzzTexture"))],
            ),
        ];
        let out = separate(asset.root(), fixes);
        let titles: Vec<(&str, Option<&str>)> = out
            .iter()
            .map(|f| (f.title.as_str(), f.deferred.as_deref()))
            .collect();
        assert_eq!(
            titles,
            [
                ("a; b", None),
                ("clamp", None),
                ("cutoff", None),
                ("roughness", None),
                (
                    "texture",
                    Some("it touches what the safe fix \"roughness\" changes: run --fix again once that one is applied")
                ),
            ]
        );
        assert_eq!(
            out[0].edits,
            [Edit::declare_used("A"), Edit::declare_used("B")]
        );
    }

    #[test]
    fn an_offending_finding_is_laid_to_the_fixes_that_edit_its_value_or_were_to_repair_it() {
        let mut a = fix(vec![Edit::set("/materials/0/a/b", serde_json::json!(1))]);
        a.repairs.push(Repair {
            code: "X",
            pointer: "/materials/0".into(),
            message: "m".into(),
        });
        let b = fix(vec![Edit::remove("/materials/1/x")]);
        let c = fix(vec![Edit::declare_used("E")]);
        let fixes = [a, b, c];
        let blame = Blame::new(&fixes, &[0, 1, 2]);
        let brought = |pointer: &str| Offence {
            code: "Y",
            message: String::new(),
            pointer: pointer.into(),
            left: false,
        };
        // The value itself, one holding it, one inside it; never a sibling.
        assert_eq!(blame.culprits(&brought("/materials/0/a/b")), [0]);
        assert_eq!(blame.culprits(&brought("/materials/0")), [0]);
        assert_eq!(blame.culprits(&brought("/materials/0/a/b/c")), [0]);
        assert_eq!(
            blame.culprits(&brought("/materials/0/ab")),
            Vec::<usize>::new()
        );
        assert_eq!(blame.culprits(&brought("/materials")), [0, 1]);
        assert_eq!(blame.culprits(&brought("/extensionsUsed/0")), [2]);
        let left = Offence {
            code: "X",
            message: "m".into(),
            pointer: "/elsewhere".into(),
            left: true,
        };
        assert_eq!(blame.culprits(&left), [0]);
    }

    #[test]
    fn findings_one_edit_repairs_are_one_fix() {
        use crate::rules::declaration::{UNDECLARED_EXTENSION, UNUSED_EXTENSION_REQUIRED};
        let asset = load(
            r#"{"asset":{"version":"2.0"},"extensionsRequired":["KHR_materials_sheen"],"materials":[{"extensions":{"KHR_materials_sheen":{}}}]}"#,
        );
        let findings = [
            finding(
                &UNDECLARED_EXTENSION,
                "/materials/0/extensions/KHR_materials_sheen",
                "u",
            ),
            finding(&UNUSED_EXTENSION_REQUIRED, "/extensionsRequired/0", "r"),
        ];
        let fixes = plan(&asset, &findings);
        assert_eq!(fixes.len(), 1, "{fixes:?}");
        assert_eq!(fixes[0].edits, [Edit::declare_used("KHR_materials_sheen")]);
        let codes: Vec<&str> = fixes[0].repairs.iter().map(|r| r.code).collect();
        assert_eq!(
            codes,
            [UNDECLARED_EXTENSION.name, UNUSED_EXTENSION_REQUIRED.name]
        );
    }

    #[test]
    fn the_verdict_names_a_finding_left_or_one_brought() {
        use crate::diagnostics::codes::VALUE_NOT_IN_RANGE;
        use crate::rules::disabled_layer::SHEEN_TEXTURE_WITHOUT_EFFECT;
        let before = [finding(&VALUE_NOT_IN_RANGE, "/a", "too big")];
        let mut f = fix(Vec::new());
        f.repairs.push(Repair {
            code: VALUE_NOT_IN_RANGE.name,
            pointer: "/a".into(),
            message: "too big".into(),
        });
        let reasons = |r: Result<(), Vec<Offence>>| -> Result<(), Vec<String>> {
            r.map_err(|o| o.iter().map(Offence::reason).collect())
        };
        assert_eq!(verdict(&before, &[], &[&f]), Ok(()));
        assert_eq!(
            reasons(verdict(&before, &before, &[&f])),
            Err(vec![
                "the fixed file would still have VALUE_NOT_IN_RANGE".into()
            ])
        );
        let brought = [finding(&SHEEN_TEXTURE_WITHOUT_EFFECT, "/b", "no effect")];
        assert_eq!(
            reasons(verdict(&before, &brought, &[&f])),
            Err(vec![
                "the fixed file would have KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT (no effect)"
                    .into()
            ])
        );
        // A finding at the same code and pointer whose message quotes a value the fix changed
        // is the same finding.
        use crate::diagnostics::codes::ARRAY_LENGTH_NOT_IN_LIST;
        let was = [
            finding(&VALUE_NOT_IN_RANGE, "/a", "too big"),
            finding(&ARRAY_LENGTH_NOT_IN_LIST, "/c", "[1.5,0] has 2 elements"),
        ];
        let reworded = [finding(
            &ARRAY_LENGTH_NOT_IN_LIST,
            "/c",
            "[1,0] has 2 elements",
        )];
        assert_eq!(verdict(&was, &reworded, &[&f]), Ok(()));
        // A new info or hint is no reason to refuse; a new warning is.
        let hint = [finding(
            &crate::rules::fallback::FUZZ_WITHOUT_FALLBACK,
            "/d",
            "no fallback",
        )];
        assert_eq!(verdict(&before, &hint, &[&f]), Ok(()));
        // A finding that moved (an array element before it removed) is the same finding.
        let moved = [finding(&SHEEN_TEXTURE_WITHOUT_EFFECT, "/c/0", "no effect")];
        let was = [finding(&SHEEN_TEXTURE_WITHOUT_EFFECT, "/c/1", "no effect")];
        assert_eq!(verdict(&was, &moved, &[]), Ok(()));
    }

    #[test]
    fn the_registry_says_which_codes_are_fixable_as_the_fixers_table_does() {
        for code in all_codes() {
            let fixer = fixers::fixer_for(code.name);
            assert_eq!(
                code.fix,
                fixer.map(|f| f.safety),
                "{}: the registry and the fixers table disagree",
                code.name
            );
        }
        for fixer in fixers::FIXERS {
            assert!(
                all_codes().iter().any(|c| c.name == fixer.code.name),
                "{} has a fixer but is not registered",
                fixer.code.name
            );
        }
    }

    /// Every finding of a report as code, severity, pointer and message.
    fn listed(findings: &[Finding]) -> Vec<String> {
        findings
            .iter()
            .map(|f| {
                let d = &f.diagnostic;
                format!("{} {:?} {} {}", d.code, d.severity, d.pointer, d.message)
            })
            .collect()
    }

    #[test]
    fn a_trial_takes_from_the_files_report_only_findings_that_hold_for_the_fixed_text() {
        // A document with data findings (a min that is not the data's) and a fix that touches
        // no data (a view's missing target), then every fixture folder's documents: each fix
        // tried alone and all together. The trial's report, which takes the findings of rules
        // whose reads the edits leave alone from the file's report, must be the fixed text's
        // report made whole.
        use base64::Engine;
        let floats: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let data = base64::engine::general_purpose::STANDARD.encode(&floats);
        let with_data = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0.5]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
            "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
        );
        let dir = tempfile::tempdir().expect("a temporary folder");
        let made = dir.path().join("data.gltf");
        std::fs::write(&made, with_data).expect("the document is written");
        let mut documents = vec![made];
        documents.extend(crate::rules::fixture_documents(&["gltf", "glb"]));
        let validator = Validator::new(
            crate::rules::schema::Schemas::builtin(),
            Settings::default(),
        );
        let fixing = Fixing::new(
            &validator,
            Mode {
                apply: false,
                diff: false,
                unsafe_fixes: true,
                edits: false,
            },
        );
        let settings = Settings::default();
        let data_codes: Vec<&str> = crate::rules::REGISTRY
            .iter()
            .filter(|rule| matches!(rule.reads(), crate::rules::Reads::Properties { .. }))
            .flat_map(|rule| rule.codes().iter().map(|c| c.name))
            .collect();
        let (mut trials, mut taken) = (0, 0);
        for path in &documents {
            let loaded = asset::load_with(path, &validator.load);
            let Some(source) = loaded.asset else {
                continue;
            };
            let before = validator.validate_asset(path, &source, loaded.diagnostics, &settings);
            let fixes = plan(&source, &before.findings);
            let all: Vec<&Fix> = fixes.iter().collect();
            let tries = fixes.iter().map(|f| vec![f]).chain([all]);
            for tried in tries.filter(|t| !t.is_empty()) {
                let Ok(fixed) = fixing.attempt(path, &source, &before, &tried, &settings) else {
                    continue;
                };
                let again = asset::load_bytes_with(path, fixed.bytes(), &validator.load);
                let whole = validator.validate_asset_unplaced(
                    path,
                    again.asset.as_ref().expect("the fixed text loads"),
                    again.diagnostics,
                    &settings,
                    None,
                );
                assert_eq!(
                    listed(&fixed.report.findings),
                    listed(&whole.findings),
                    "{}: {:?}",
                    path.display(),
                    tried.iter().map(|f| &f.title).collect::<Vec<_>>()
                );
                trials += 1;
                let edits = combined(source.root(), &tried);
                let exists = |p: &str| source.root().pointer(p).is_some();
                let data_untouched = !tried
                    .iter()
                    .any(|f| f.drops_byte_order_mark || f.rebuilds_container)
                    && !edits.iter().any(|e| {
                        crate::rules::data::DATA_READS.touched_by(edited_pointer(e), exists)
                    });
                let data_found = before
                    .findings
                    .iter()
                    .any(|f| data_codes.contains(&f.diagnostic.code));
                taken += usize::from(data_untouched && data_found);
            }
        }
        // The comparison covered trials whose data findings were taken from the file's report.
        assert!(trials > 100, "{trials} trials");
        assert!(taken >= 1, "{taken} of {trials} trials took data findings");
    }

    #[test]
    fn an_edit_lies_inside_an_element_only_below_one_the_document_has() {
        use crate::rules::ElementPlace;
        let loaded = asset::load_bytes(
            Path::new("t.gltf"),
            br#"{"asset":{"version":"2.0"},"bufferViews":[{"buffer":0,"byteLength":4},{"buffer":0,"byteLength":4}],"extensionsUsed":["A"]}"#,
        );
        let asset = loaded.asset.expect("the document loads");
        let at = |pointer: &str| ElementPlace::of_edit(asset.root(), pointer);
        let view = |index| ElementPlace {
            property: "bufferViews".to_string(),
            index,
        };
        assert_eq!(at("/bufferViews/1/target"), Some(view(1)));
        assert_eq!(at("/bufferViews/0/extensions/X/y"), Some(view(0)));
        // The element itself, one the array does not have, an index as a pointer does not
        // write it, and what is not an array of the root.
        for outside in [
            "/bufferViews/1",
            "/bufferViews/2/target",
            "/bufferViews/-/target",
            "/bufferViews/01/target",
            "/extensionsUsed",
            "/asset/version",
            "",
        ] {
            assert_eq!(at(outside), None, "{outside}");
        }
        let finding =
            |pointer: &str| Diagnostic::new(&crate::diagnostics::codes::TYPE_MISMATCH, pointer, "");
        assert!(view(1).holds(&finding("/bufferViews/1")));
        assert!(view(1).holds(&finding("/bufferViews/1/target")));
        assert!(!view(1).holds(&finding("/bufferViews/10/target")));
        assert!(!view(1).holds(&finding("/bufferViews")));
        assert!(!view(1).holds(&finding("/accessors/1")));
    }

    #[test]
    fn an_edit_touches_the_extension_objects_where_it_brings_takes_or_moves_one_or_edits_inside() {
        let text = r#"{"asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_sheen"],
            "materials": [{"name": "a"},
                          {"extensions": {"KHR_materials_sheen": {"sheenRoughnessFactor": 0.5}}}],
            "bufferViews": [{"buffer": 0, "byteLength": 4}],
            "nodes": [{"extras": {"note": {"extensions": {}}}}]}"#;
        let asset = crate::asset::load_bytes(Path::new("t.gltf"), text.as_bytes())
            .asset
            .unwrap();
        let root = asset.root();
        let set = |pointer: &str, value: serde_json::Value| Edit::Set {
            pointer: pointer.into(),
            value: crate::edit::SetValue::Value(value),
        };
        let set_text = |pointer: &str, text: &str| Edit::Set {
            pointer: pointer.into(),
            value: crate::edit::SetValue::Text(text.into()),
        };
        let remove = |pointer: &str| Edit::Remove {
            pointer: pointer.into(),
        };
        let touched = |edit: &Edit| {
            crate::rules::Reads::Extensions.touched_by_path(&edit_path(root, edit), |_| true)
        };
        // Elsewhere, holding none and moving none: untouched.
        assert!(!touched(&set(
            "/bufferViews/0/target",
            serde_json::json!(34962)
        )));
        assert!(!touched(&set("/materials/0/name", serde_json::json!("b"))));
        assert!(!touched(&set_text(
            "/materials/0/pbrMetallicRoughness",
            r#"{"roughnessFactor":1}"#
        )));
        assert!(!touched(&remove("/materials/0/name")));
        // Inside an extension object, at a list, at the root, or a declaration.
        assert!(touched(&set(
            "/materials/1/extensions/KHR_materials_sheen/sheenRoughnessFactor",
            serde_json::json!(1)
        )));
        assert!(touched(&set("/extensionsRequired", serde_json::json!([]))));
        assert!(touched(&remove("/extensionsUsed/0")));
        assert!(touched(&remove("")));
        assert!(touched(&Edit::DeclareUsed {
            extension: "KHR_materials_fuzz".into()
        }));
        // Bringing one (as a value or as text), replacing or removing a value that holds one
        // (an `extensions` member in extras too), or removing an array element, which moves
        // the elements after it.
        assert!(touched(&set(
            "/materials/0/x",
            serde_json::json!({"extensions": {}})
        )));
        assert!(touched(&set_text(
            "/materials/0/x",
            r#"{"a":[{"extensions":{}}]}"#
        )));
        assert!(touched(&Edit::Replace {
            pointer: "/materials/0/x".into(),
            value: serde_json::json!([{"b": {"extensions": {}}}])
        }));
        assert!(touched(&set(
            "/materials/1",
            serde_json::json!({"name": "c"})
        )));
        assert!(touched(&remove("/nodes/0/extras")));
        assert!(touched(&remove("/materials/0")));
        assert!(touched(&remove("/bufferViews/0")));
        // What an edit path made without the values says: touched.
        assert!(crate::rules::Reads::Extensions.touched_by("/materials/0/name", |_| true));
    }

    #[test]
    fn an_edit_touches_what_a_rule_reads_unless_it_is_elsewhere_or_an_excepted_member_or_beside_its_places(
    ) {
        let reads = crate::rules::data::DATA_READS;
        let exists = |p: &str| p == "/bufferViews/0";
        assert!(reads.touched_by("", exists));
        assert!(reads.touched_by("/accessors/3/min/0", exists));
        assert!(reads.touched_by("/bufferViews/0/byteStride", exists));
        assert!(reads.touched_by("/bufferViews", exists));
        assert!(!reads.touched_by("/materials/0/extensions", exists));
        assert!(!reads.touched_by("/extensionsUsed", exists));
        assert!(!reads.touched_by("/bufferViews/0/target", exists));
        // Setting a member of a view that is not there creates the view.
        assert!(reads.touched_by("/bufferViews/1/target", exists));
        assert!(crate::rules::Reads::Document.touched_by("/materials/0", exists));
        // The references rule reads the indices, and which elements the arrays they index hold.
        let references = crate::rules::Reads::Places {
            values: &["/nodes/*/mesh", "/materials/*/extensions/*/*Texture/index"],
            elements: &["/meshes", "/extensions"],
        };
        let touched = |p: &str| references.touched_by(p, |_| true);
        assert!(touched("/nodes/2/mesh"));
        assert!(touched("/nodes/2"));
        assert!(touched("/nodes"));
        assert!(touched(""));
        assert!(touched("/meshes/-"));
        assert!(touched("/meshes/4"));
        assert!(touched("/materials/0/extensions/KHR_materials_fuzz"));
        assert!(touched(
            "/materials/0/extensions/KHR_materials_fuzz/fuzzColorTexture"
        ));
        assert!(touched("/extensions/KHR_lights_punctual"));
        assert!(!touched("/meshes/4/primitives/0/mode"));
        assert!(!touched("/nodes/2/name"));
        assert!(!touched(
            "/materials/0/extensions/KHR_materials_fuzz/fuzzColorFactor/1"
        ));
        assert!(!touched("/bufferViews/1/target"));
        assert!(!touched("/extensions/KHR_lights_punctual/lights/0/spot"));
    }
}
