//! The validate pipeline: find the files, load each, run every registered rule, apply the run's
//! settings, and place each finding in the source text. Files run in parallel; each file's
//! report is independent of the others. A run over many files under their velvet.toml files
//! (exclusions, batches, whether the run failed) is the command's, in
//! `command::validate::batch`, as migrate's is in `command::migrate::batch`.

use crate::asset::tape::Node;
use crate::asset::{self, discover, position::Position, Container};
use crate::diagnostics::{Diagnostic, Settings, Severity};
use crate::layers;
use crate::rules::{self, schema::Schemas, Context};
use rayon::prelude::*;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Documents from this size (bytes of JSON text) up run their rules in parallel; below it the
/// files of a run are the parallel unit and splitting a small file only adds overhead.
const PARALLEL_RULES_FROM: usize = 1 << 20;

/// A finding with where it stands in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    pub diagnostic: Diagnostic,
    /// Line and column in the JSON text (for a .glb, within the JSON chunk), when the pointer
    /// names a value.
    pub position: Option<Position>,
}

/// Counts per severity, before the issue cap.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    pub errors: usize,
    pub warnings: usize,
    pub infos: usize,
    pub hints: usize,
}

impl Counts {
    fn add(&mut self, severity: Severity) {
        match severity {
            Severity::Error => self.errors += 1,
            Severity::Warning => self.warnings += 1,
            Severity::Info => self.infos += 1,
            Severity::Hint => self.hints += 1,
        }
    }
}

/// What the report's `info` section says about an asset.
#[derive(Debug, Clone, PartialEq)]
pub struct AssetInfo {
    pub version: Option<String>,
    pub generator: Option<String>,
    pub extensions_used: Vec<String>,
    pub extensions_required: Vec<String>,
    pub material_count: usize,
    pub sheen_material_count: usize,
    pub fuzz_material_count: usize,
}

/// The resource files a document names and those of them that do not exist, for the report
/// formats that list a file's FILE_NOT_FOUND findings as one entry (text, GitHub, SARIF).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MissingResources {
    /// How many distinct files the buffer and image URIs name (data: URIs and URLs aside).
    pub named: usize,
    /// The distinct URIs of the FILE_NOT_FOUND findings, in the order the rules found them
    /// (the findings' own, before a `--max-issues` cap; none when the code is ignored).
    pub uris: Vec<String>,
}

/// The report for one file.
#[derive(Debug, Clone)]
pub struct FileReport {
    pub path: PathBuf,
    pub container: Option<Container>,
    /// Byte offset of the JSON text in the file (for GLB positions).
    pub json_offset: usize,
    pub findings: Vec<Finding>,
    pub counts: Counts,
    /// How many findings `--max-issues` left out of the listing (they are counted all the same).
    pub omitted: usize,
    pub info: Option<AssetInfo>,
    pub missing: MissingResources,
    /// The fixes planned for the file (see `crate::fix`); empty when none were planned.
    pub fixes: crate::diagnostics::fixes::FileFixes,
    /// Where each group of findings lies in `findings`: the loader's, then each registered
    /// rule's in registry order; empty when a `--max-issues` cap reordered them. A trial of
    /// the file's fixes takes from here the findings of the rules the fixes leave alone.
    pub rule_spans: Vec<std::ops::Range<usize>>,
}

/// What a trial of a file's fixes may take from the file's report instead of running a rule
/// again: the findings of each rule whose reads ([`rules::Reads`]) the fixes' edits do not
/// touch. The file's report is of every finding (uncapped), under the trial's settings.
pub struct Reuse<'r> {
    pub report: &'r FileReport,
    /// Whether the edits touch what a rule reads.
    pub touched: &'r (dyn Fn(&rules::Reads) -> bool + Sync),
    /// The elements the edits lie inside, when every edit lies inside an element the file has
    /// of a top-level array: a rule whose reads they touch may still find its findings hold
    /// by judging those elements again ([`rules::findings_hold_inside`]).
    pub elements: Option<&'r [rules::ElementPlace]>,
}

impl Reuse<'_> {
    /// Rule `index`'s findings in the file's report, when they hold for the edited text `cx`
    /// too.
    fn findings_of(&self, index: usize, cx: &Context) -> Option<Vec<Diagnostic>> {
        let spans = &self.report.rule_spans;
        if spans.len() != rules::REGISTRY.len() + 1 {
            return None;
        }
        let rule = rules::REGISTRY[index];
        let found = &self.report.findings[spans[index + 1].clone()];
        let found_inside =
            |element: &rules::ElementPlace| found.iter().any(|f| element.holds(&f.diagnostic));
        let holds = !(self.touched)(&rule.reads())
            || self.elements.is_some_and(|elements| {
                rules::findings_hold_inside(rule, cx, elements, &found_inside)
            });
        holds.then(|| found.iter().map(|f| f.diagnostic.clone()).collect())
    }
}

impl FileReport {
    /// True when a finding is at or above the run's fail-on severity.
    /// True when `--max-issues` left findings out of the listing.
    pub fn truncated(&self) -> bool {
        self.omitted > 0
    }

    /// Judged on every finding, also those a `--max-issues` cap left out of the listing.
    pub fn fails(&self, settings: &Settings) -> bool {
        let c = self.counts;
        [
            (Severity::Error, c.errors),
            (Severity::Warning, c.warnings),
            (Severity::Info, c.infos),
            (Severity::Hint, c.hints),
        ]
        .into_iter()
        .any(|(severity, n)| n > 0 && settings.fail_on.fails(severity))
    }
}

/// A validator for one run: schemas compiled once, settings applied to every file, every file
/// loaded under the same limits.
pub struct Validator {
    /// The schemas of a run: given, or compiling on the workers of the thread pool while the
    /// first file is read (compiling the core schemas takes about as long as reading a large
    /// file). Filled by that worker, or by whoever needs them before the worker has started on
    /// them (a pool of one thread, busy with the file): no one waits on work that cannot run.
    schemas: Arc<OnceLock<Schemas>>,
    /// Where the built-in schemas' core schema compiles (on a worker of its own), for
    /// whoever fills `schemas` (unused when the schemas were given).
    core: Arc<OnceLock<crate::rules::core::CoreSchema>>,
    pub settings: Settings,
    pub load: asset::LoadOptions,
    /// Whether findings are placed in the source text (line and column); a report format that
    /// does not show them skips the scan.
    pub positions: bool,
    /// What the file system said of the resources of each folder's documents, this run.
    folders: asset::FolderLookups,
}

impl Validator {
    pub fn new(schemas: Schemas, settings: Settings) -> Validator {
        Validator::with_compiled(
            Arc::new(OnceLock::from(schemas)),
            Arc::new(OnceLock::new()),
            settings,
        )
    }

    /// A validator with the built-in schemas, which compile in the background until the first
    /// file's rules need them, in two jobs: the core schema (some 3 ms), and the layers'
    /// schemas with the kinds of objects the rules walk (some 1.5 ms), which the first file's
    /// worker often compiles itself, having needed them first. They compile on workers of the
    /// pool rather than on threads of their own: a thread beside the pool's workers (one per
    /// core) would share the cores with them. A file that needs a schema before its job has
    /// started compiles it itself (a pool of one thread, busy with the file): no one waits on
    /// work that cannot run.
    pub fn builtin(settings: Settings) -> Validator {
        // The built-in schemas are tested to compile; should a job panic, its OnceLock stays
        // empty and the panic is raised again where the schema is first needed, rather than
        // ending the process from the pool.
        fn in_background(job: impl FnOnce() + Send + 'static) {
            rayon::spawn(move || {
                let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job));
            })
        }
        let core: Arc<OnceLock<crate::rules::core::CoreSchema>> = Arc::new(OnceLock::new());
        let core_job = Arc::clone(&core);
        in_background(move || {
            core_job.get_or_init(crate::rules::core::CoreSchema::builtin);
        });
        let schemas = Arc::new(OnceLock::new());
        let job = Arc::clone(&schemas);
        let job_core = Arc::clone(&core);
        in_background(move || {
            job.get_or_init(|| Schemas::with_core(job_core));
            // The kinds of objects the extension and texture rules walk, read from the
            // schemas once per process: here, rather than in the first file's rules.
            crate::rules::extensions::prepare();
        });
        Validator::with_compiled(schemas, core, settings)
    }

    fn with_compiled(
        schemas: Arc<OnceLock<Schemas>>,
        core: Arc<OnceLock<crate::rules::core::CoreSchema>>,
        settings: Settings,
    ) -> Validator {
        Validator {
            schemas,
            core,
            settings,
            load: asset::LoadOptions::default(),
            positions: true,
            folders: Default::default(),
        }
    }

    /// The same validator, placing findings in the source text or not.
    pub fn with_positions(self, positions: bool) -> Validator {
        Validator { positions, ..self }
    }

    /// The same validator loading files under `load`.
    pub fn with_load_options(self, load: asset::LoadOptions) -> Validator {
        Validator { load, ..self }
    }

    /// Validates every asset found under `inputs`, in parallel, in input order.
    pub fn validate_inputs(&self, inputs: &[PathBuf]) -> Vec<FileReport> {
        let (files, walk_errors) = discover::collect(inputs);
        let mut reports: Vec<FileReport> = walk_errors
            .into_iter()
            .map(|(path, e)| self.unreadable_folder(path, &e, &self.settings))
            .collect();
        reports.extend(
            files
                .par_iter()
                .map(|p| self.validate_file(p))
                .collect::<Vec<_>>(),
        );
        reports
    }

    /// Validates one file.
    pub fn validate_file(&self, path: &Path) -> FileReport {
        self.validate_file_with(path, &self.settings)
    }

    /// Validates one file under `settings` instead of the validator's own (a run whose
    /// configuration differs from folder to folder).
    pub fn validate_file_with(&self, path: &Path, settings: &Settings) -> FileReport {
        let loaded = asset::load_with(path, &self.load);
        self.validate_loaded_with(path, loaded, settings)
    }

    /// The report for a folder that could not be walked.
    pub fn unreadable_folder(
        &self,
        path: PathBuf,
        error: &std::io::Error,
        settings: &Settings,
    ) -> FileReport {
        let d = Diagnostic::new(
            &crate::diagnostics::codes::IO_ERROR,
            "",
            format!("cannot read folder {}: {error}", path.display()),
        );
        self.finish(settings, path, None, 0, vec![vec![d]], None)
    }

    /// Validates a file already loaded (or that failed to load).
    pub fn validate_loaded(&self, path: &Path, loaded: asset::Loaded) -> FileReport {
        self.validate_loaded_with(path, loaded, &self.settings)
    }

    pub fn validate_loaded_with(
        &self,
        path: &Path,
        loaded: asset::Loaded,
        settings: &Settings,
    ) -> FileReport {
        let diagnostics = loaded.diagnostics;
        let Some(mut asset) = loaded.asset else {
            return self.finish(
                settings,
                path.to_path_buf(),
                None,
                0,
                vec![diagnostics],
                None,
            );
        };
        self.share_folder_lookups(&mut asset);
        self.validate_asset(path, &asset, diagnostics, settings)
    }

    /// Gives a document just loaded the resource lookups of the documents of its folder
    /// validated before it in this run ([`asset::Asset::share_folder_lookups`]).
    pub fn share_folder_lookups(&self, asset: &mut asset::Asset) {
        asset.share_folder_lookups(&self.folders);
    }

    /// Validates a loaded document under `settings`; `diagnostics` are the loader's findings
    /// about it. The document is only read: a caller that goes on to edit it (`--fix`) keeps it.
    pub fn validate_asset(
        &self,
        path: &Path,
        asset: &asset::Asset,
        diagnostics: Vec<Diagnostic>,
        settings: &Settings,
    ) -> FileReport {
        let mut report = self.validate_asset_unplaced(path, asset, diagnostics, settings, None);
        self.place_findings(asset, &mut report);
        report
    }

    /// [`Validator::validate_asset`] without the findings' places in the text (line and
    /// column), for a report that only decides something (a fixed text's, compared with the
    /// file's); [`Validator::place_findings`] adds them if it is shown after all. A fixed
    /// text's trial takes from the file's report the findings of the rules its fixes leave
    /// alone (`reuse`, see [`Reuse`]).
    pub fn validate_asset_unplaced(
        &self,
        path: &Path,
        asset: &asset::Asset,
        diagnostics: Vec<Diagnostic>,
        settings: &Settings,
        reuse: Option<&Reuse>,
    ) -> FileReport {
        let schemas = self
            .schemas
            .get_or_init(|| Schemas::with_core(Arc::clone(&self.core)));
        let cx = Context::new(asset, schemas).reading_data(!settings.skip_data);
        // A large text, or (with the data checks) large buffers: a document whose weight is in
        // its data has a small text and megabytes of accessors to read.
        let data_bytes = || {
            asset
                .root()
                .get("buffers")
                .and_then(|b| b.as_array())
                .into_iter()
                .flat_map(|a| a.iter())
                .filter_map(|b| b.get("byteLength")?.as_u64())
                .fold(0u64, u64::saturating_add)
        };
        let parallel = asset.json_text.len() >= PARALLEL_RULES_FROM
            || (!settings.skip_data && data_bytes() >= PARALLEL_RULES_FROM as u64);
        let (found, info) = if parallel {
            rayon::join(|| run_rules(&cx, true, reuse), || asset_info(asset.root()))
        } else {
            (run_rules(&cx, false, reuse), asset_info(asset.root()))
        };
        // The rules' shared reading of the document goes before the findings are listed.
        drop(cx);
        let mut groups = found;
        groups.insert(0, diagnostics);
        let missing = missing_resources(asset.root(), &groups, settings);
        let mut report = self.finish(
            settings,
            path.to_path_buf(),
            Some(asset.container),
            asset.json_offset,
            groups,
            Some(info),
        );
        report.missing = missing;
        report
    }

    /// Each finding's place in `asset`'s text (line and column), where the report shows them
    /// and the finding has none yet.
    pub fn place_findings(&self, asset: &asset::Asset, report: &mut FileReport) {
        if !self.positions || report.findings.is_empty() {
            return;
        }
        let positions = asset::position::locate(
            &asset.json_text,
            asset.root(),
            report
                .findings
                .iter()
                .map(|f| f.diagnostic.pointer.as_str()),
        );
        for (f, position) in report.findings.iter_mut().zip(positions) {
            if !f.diagnostic.pointer.is_empty() && f.position.is_none() {
                f.position = position;
            }
        }
    }

    /// The report of one file from its findings, in groups (the loader's, then each rule's):
    /// each group is moved into the report's list and freed, so the findings are never held
    /// twice over.
    fn finish(
        &self,
        settings: &Settings,
        path: PathBuf,
        container: Option<Container>,
        json_offset: usize,
        groups: Vec<Vec<Diagnostic>>,
        info: Option<AssetInfo>,
    ) -> FileReport {
        let mut findings: Vec<Finding> = Vec::with_capacity(groups.iter().map(Vec::len).sum());
        asset::pages::advise_huge(&mut findings);
        let mut counts = Counts::default();
        let mut rule_spans = Vec::with_capacity(groups.len());
        for group in groups {
            let start = findings.len();
            for mut diagnostic in group {
                if settings.ignore.contains(diagnostic.code) {
                    continue;
                }
                if let Some(s) = settings.severity_overrides.get(diagnostic.code) {
                    diagnostic.severity = *s;
                }
                counts.add(diagnostic.severity);
                findings.push(Finding {
                    position: diagnostic.position,
                    diagnostic,
                });
            }
            rule_spans.push(start..findings.len());
        }
        let mut omitted = 0;
        if let Some(max) = settings.max_issues.filter(|max| findings.len() > *max) {
            rule_spans.clear();
            // The listing keeps the most severe findings: errors before warnings before infos.
            findings.sort_by_key(|f| f.diagnostic.severity);
            omitted = findings.len() - max;
            findings.truncate(max);
        }
        FileReport {
            path,
            container,
            json_offset,
            findings,
            counts,
            omitted,
            info,
            missing: MissingResources::default(),
            fixes: Default::default(),
            rule_spans,
        }
    }
}

/// The files `json` names and the URIs of the FILE_NOT_FOUND findings among `groups`, unless
/// `settings` ignore the code.
fn missing_resources(
    json: Node,
    groups: &[Vec<Diagnostic>],
    settings: &Settings,
) -> MissingResources {
    let code = rules::resources::FILE_NOT_FOUND.name;
    if settings.ignore.contains(code) {
        return MissingResources::default();
    }
    let mut uris: Vec<String> = Vec::new();
    for d in groups.iter().flatten().filter(|d| d.code == code) {
        if let Some(uri) = json.pointer(&d.pointer).and_then(|u| u.as_str()) {
            if !uris.iter().any(|u| *u == uri) {
                uris.push(uri.into_owned());
            }
        }
    }
    if uris.is_empty() {
        return MissingResources::default();
    }
    MissingResources {
        named: rules::resources::file_uris(json).len(),
        uris,
    }
}

/// Every registered rule's findings, in registry order, a list per rule (taken from `reuse`
/// where it holds them). In parallel each rule keeps its own list, so the report does not
/// depend on which rule finished first.
fn run_rules(cx: &Context, parallel: bool, reuse: Option<&Reuse>) -> Vec<Vec<Diagnostic>> {
    crate::progress::stage("checking rules", rules::REGISTRY.len());
    let run = |i: usize| {
        let found = reuse.and_then(|r| r.findings_of(i, cx)).unwrap_or_else(|| {
            let mut out = Vec::new();
            rules::REGISTRY[i].check(cx, &mut out);
            out
        });
        crate::progress::advance(1);
        found
    };
    if parallel {
        // Each rule is a task of its own, taken dearest first by whichever thread is free
        // (split in registry order, three of the four dear rules fell to one core and the
        // fourth ran alone at the end).
        let mut order: Vec<usize> = (0..rules::REGISTRY.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(rules::REGISTRY[i].cost()));
        let next = std::sync::atomic::AtomicUsize::new(0);
        let found: Vec<std::sync::OnceLock<Vec<Diagnostic>>> =
            rules::REGISTRY.iter().map(|_| Default::default()).collect();
        rayon::scope(|s| {
            for _ in 0..rayon::current_num_threads() {
                s.spawn(|_| {
                    while let Some(&i) =
                        order.get(next.fetch_add(1, std::sync::atomic::Ordering::Relaxed))
                    {
                        let _ = found[i].set(run(i));
                    }
                });
            }
        });
        found
            .into_iter()
            .map(|list| list.into_inner().unwrap_or_default())
            .collect()
    } else {
        (0..rules::REGISTRY.len()).map(run).collect()
    }
}

fn strings(json: Node, key: &str) -> Vec<String> {
    crate::rules::elements(json.get(key))
        .filter_map(|s| s.as_str())
        .map(Cow::into_owned)
        .collect()
}

fn asset_info(json: Node) -> AssetInfo {
    let (mut materials, mut sheen, mut fuzz) = (0, 0, 0);
    let [extensions_key, sheen_key, fuzz_key] =
        ["extensions", layers::SHEEN, layers::FUZZ].map(|key| json.key_id(key));
    for material in crate::rules::materials(json) {
        materials += 1;
        if let Some(extensions) = material.get_by(extensions_key).and_then(|e| e.as_object()) {
            sheen += usize::from(extensions.contains_id(sheen_key));
            fuzz += usize::from(extensions.contains_id(fuzz_key));
        }
    }
    let text = |p: &str| {
        json.pointer(p)
            .and_then(|s| s.as_str())
            .map(Cow::into_owned)
    };
    AssetInfo {
        version: text("/asset/version"),
        generator: text("/asset/generator"),
        extensions_used: strings(json, "extensionsUsed"),
        extensions_required: strings(json, "extensionsRequired"),
        material_count: materials,
        sheen_material_count: sheen,
        fuzz_material_count: fuzz,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A document whose materials trip many rules at once: schema errors, a dangling texture,
    /// legacy draft keys, fuzz without fallback, a switched-off layer with a texture.
    fn many_faults(materials: usize) -> String {
        let mut list = Vec::new();
        for i in 0..materials {
            list.push(match i % 5 {
                0 => r#"{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[1.5,0.0],"sheenRoughnessFactor":"rough"}}}"#.to_string(),
                1 => r#"{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[0,0,0],"sheenColorTexture":{"index":7}}}}"#.to_string(),
                2 => r#"{"extensions":{"KHR_materials_sheen":{"sheenFactor":0.5,"sheenColor":[1,1,1]}}}"#.to_string(),
                3 => r#"{"extensions":{"KHR_materials_fuzz":{"fuzzColorFactor":[0.2,0.2,0.2]}}}"#.to_string(),
                _ => format!(r#"{{"name":"m{i}","extensions":{{"KHR_materials_sheen":{{"sheenColorFactor":[1,1,1],"sheenRoughnessFactor":0.5}}}}}}"#),
            });
        }
        format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_materials_sheen","KHR_materials_fuzz"],"materials":[{}]}}"#,
            list.join(",")
        )
    }

    #[test]
    fn a_pool_of_one_thread_compiles_the_schemas_itself_rather_than_wait_for_them() {
        // The one worker validates the file; the compile job queued behind it cannot run
        // until it is done, so the validation compiles the schemas where it needs them. A
        // validation that waited for the job would never finish: it is given a minute.
        let text = many_faults(5);
        let codes_of = move |validator: &Validator| -> Vec<&'static str> {
            let path = Path::new("faults.gltf");
            let loaded =
                asset::load_bytes_with(path, text.as_bytes(), &asset::LoadOptions::default());
            let report = validator.validate_loaded(path, loaded);
            report.findings.iter().map(|f| f.diagnostic.code).collect()
        };
        let expected = codes_of(&Validator::new(Schemas::builtin(), Settings::default()));
        let (sender, receiver) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap();
            let codes = pool.install(|| codes_of(&Validator::builtin(Settings::default())));
            let _ = sender.send(codes);
        });
        let codes = receiver
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("the validation in a pool of one thread finishes");
        assert!(codes.contains(&"TYPE_MISMATCH"), "{codes:?}");
        assert_eq!(codes, expected);
    }

    #[test]
    fn the_documents_of_one_folder_share_what_the_file_system_said_of_their_resources_in_a_run() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let text = r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"b.bin","byteLength":4}]}"#;
        for file in [
            dir.path().join("one.gltf"),
            dir.path().join("two.gltf"),
            sub.join("three.gltf"),
        ] {
            std::fs::write(file, text).unwrap();
        }
        std::fs::write(sub.join("b.bin"), [0u8; 4]).unwrap();
        let missing = |validator: &Validator, file: &Path| -> Vec<(&'static str, String)> {
            validator
                .validate_file(file)
                .findings
                .iter()
                .filter(|f| f.diagnostic.code == "FILE_NOT_FOUND")
                .map(|f| (f.diagnostic.code, f.diagnostic.pointer.clone()))
                .collect()
        };
        let validator = Validator::builtin(Settings::default());
        let not_found = vec![("FILE_NOT_FOUND", "/buffers/0/uri".to_string())];
        assert_eq!(missing(&validator, &dir.path().join("one.gltf")), not_found);
        // Written after the run asked about it: the run's answer for the folder stands.
        std::fs::write(dir.path().join("b.bin"), [0u8; 4]).unwrap();
        assert_eq!(missing(&validator, &dir.path().join("two.gltf")), not_found);
        // Another folder's document asks about its own file; another run asks again.
        assert_eq!(missing(&validator, &sub.join("three.gltf")), vec![]);
        let next_run = Validator::builtin(Settings::default());
        assert_eq!(missing(&next_run, &dir.path().join("two.gltf")), vec![]);
    }

    #[test]
    fn rules_run_in_parallel_report_exactly_what_they_report_one_after_another() {
        let text = many_faults(400);
        let loaded = asset::load_bytes_with(
            Path::new("faults.gltf"),
            text.as_bytes(),
            &asset::LoadOptions::default(),
        );
        let asset = loaded.asset.expect("the document parses");
        let schemas = Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let sequential: Vec<Diagnostic> = run_rules(&cx, false, None).concat();
        assert!(sequential.len() > 500, "{} findings", sequential.len());
        for _ in 0..4 {
            assert_eq!(run_rules(&cx, true, None).concat(), sequential);
        }
    }

    /// `text` read as the file `path` (whose folder holds its resources) and validated, its
    /// findings not placed in the text; `None` when it does not load.
    fn validated(
        validator: &Validator,
        path: &Path,
        text: &str,
    ) -> Option<(asset::Asset, FileReport)> {
        let loaded = asset::load_bytes_with(path, text.as_bytes(), &validator.load);
        let asset = loaded.asset?;
        let report = validator.validate_asset_unplaced(
            path,
            &asset,
            loaded.diagnostics,
            &Settings::default(),
            None,
        );
        Some((asset, report))
    }

    /// The findings of each rule in `report`, as text.
    fn findings_by_rule(report: &FileReport) -> Vec<Vec<String>> {
        report.rule_spans[1..]
            .iter()
            .map(|span| {
                report.findings[span.clone()]
                    .iter()
                    .map(|f| {
                        let d = &f.diagnostic;
                        format!("{} {:?} {} {}", d.code, d.severity, d.pointer, d.message)
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn a_rule_finds_the_same_in_a_document_that_lacks_what_the_rule_does_not_read() {
        // A fix's trial takes a rule's findings from the file's report when the fix edits
        // nothing the rule says it reads. Each fixture document, less one top-level property at
        // a time or less one member of every element of a top-level array, must give every rule
        // that does not read what went the findings it gave the whole document.
        let validator = Validator::builtin(Settings::default());
        let documents = rules::fixture_documents(&["gltf"]);
        let (mut compared, mut variants) = (0, 0);
        for path in &documents {
            let text = std::fs::read_to_string(path).expect("the fixture reads");
            let Ok(serde_json::Value::Object(whole)) = serde_json::from_str(&text) else {
                continue;
            };
            let Some((_, report)) = validated(&validator, path, &text) else {
                continue;
            };
            let found = findings_by_rule(&report);
            // (what went, as the pointer an edit of it would have; whether what went held no
            // extension object; the document without it)
            let mut lesser: Vec<(String, bool, serde_json::Map<String, serde_json::Value>)> = whole
                .iter()
                .map(|(key, value)| {
                    let mut less = whole.clone();
                    less.shift_remove(key);
                    (
                        format!("/{key}"),
                        !crate::fix::value_holds_key(value, "extensions"),
                        less,
                    )
                })
                .collect();
            // Each member of the elements of each top-level array, gone from every element
            // (the excepted members among them).
            let mut members: Vec<(String, String)> = whole
                .iter()
                .filter_map(|(property, value)| Some((property, value.as_array()?)))
                .flat_map(|(property, elements)| {
                    elements
                        .iter()
                        .filter_map(|e| e.as_object())
                        .flat_map(|e| e.keys())
                        .map(move |member| (property.clone(), member.clone()))
                })
                .collect();
            members.sort();
            members.dedup();
            for (property, member) in members {
                let mut less = whole.clone();
                let Some(serde_json::Value::Array(elements)) = less.get_mut(&property) else {
                    continue;
                };
                let mut keeps_extensions = true;
                for element in elements.iter_mut().filter_map(|e| e.as_object_mut()) {
                    if let Some(gone) = element.shift_remove(&member) {
                        keeps_extensions &= !crate::fix::value_holds_key(&gone, "extensions");
                    }
                }
                // Named as an edit of the first element would name it: what the rule reads
                // is the same for every element.
                lesser.push((format!("/{property}/0/{member}"), keeps_extensions, less));
            }
            for (gone, keeps_extensions, less) in lesser {
                let gone_path = rules::EditPath::of(&gone).keeping_extensions(keeps_extensions);
                let less_text = serde_json::to_string(&less).expect("the document writes");
                let Some((_, report_less)) = validated(&validator, path, &less_text) else {
                    continue;
                };
                let found_less = findings_by_rule(&report_less);
                variants += 1;
                for (i, rule) in rules::REGISTRY.iter().enumerate() {
                    let reads = rule.reads();
                    if matches!(reads, rules::Reads::Document)
                        || reads.touched_by_path(&gone_path, |_| true)
                    {
                        continue;
                    }
                    assert_eq!(
                        found[i],
                        found_less[i],
                        "{}: rule {i} ({:?}) without {gone}",
                        path.display(),
                        rule.codes().iter().map(|c| c.name).collect::<Vec<_>>()
                    );
                    compared += 1;
                }
            }
        }
        assert!(variants > 1000, "{variants} documents compared");
        assert!(compared > 10_000, "{compared} rule findings compared");
    }

    #[test]
    fn a_rule_that_rejudges_edited_elements_says_its_findings_hold_only_when_they_do() {
        // Each member of each element of the root's arrays in every fixture document, removed
        // or given a value of the wrong type: where a rule says its findings on the document
        // hold for the edited one (`rules::findings_hold_inside`), they must be its findings there.
        let validator = Validator::builtin(Settings::default());
        let schemas = Schemas::builtin();
        let documents = rules::fixture_documents(&["gltf"]);
        // For each rule: how often it said its findings hold, and how often not.
        let mut said = vec![(0usize, 0usize); rules::REGISTRY.len()];
        for path in &documents {
            let text = std::fs::read_to_string(path).expect("the fixture reads");
            let Ok(serde_json::Value::Object(whole)) = serde_json::from_str(&text) else {
                continue;
            };
            let Some((source, found)) = validated(&validator, path, &text) else {
                continue;
            };
            let by_rule = findings_by_rule(&found);
            for (property, value) in &whole {
                let Some(elements) = value.as_array() else {
                    continue;
                };
                for (index, element) in elements.iter().enumerate().take(3) {
                    let Some(members) = element.as_object() else {
                        continue;
                    };
                    // Its members, and a member no kind defines.
                    let unknown = "nmae".to_string();
                    for member in members.keys().chain([&unknown]) {
                        for wrong in [None, Some(serde_json::json!({"nmae": [true]}))] {
                            let mut edited = whole.clone();
                            let target =
                                edited[property][index].as_object_mut().expect("an object");
                            match &wrong {
                                None => {
                                    target.shift_remove(member);
                                }
                                Some(value) => {
                                    target.insert(member.clone(), value.clone());
                                }
                            }
                            let edited_text =
                                serde_json::to_string(&edited).expect("the document writes");
                            let loaded = asset::load_bytes_with(
                                path,
                                edited_text.as_bytes(),
                                &validator.load,
                            );
                            let Some(after) = loaded.asset else {
                                continue;
                            };
                            let place = rules::ElementPlace {
                                property: property.clone(),
                                index,
                            };
                            assert_eq!(
                                rules::ElementPlace::of_edit(
                                    source.root(),
                                    &format!("/{property}/{index}/{member}")
                                )
                                .as_ref(),
                                Some(&place)
                            );
                            let cx = Context::new(&after, &schemas);
                            let mut found_after: Option<Vec<Vec<String>>> = None;
                            for i in 0..rules::REGISTRY.len() {
                                let span = found.rule_spans[i + 1].clone();
                                let found_inside = |e: &rules::ElementPlace| {
                                    found.findings[span.clone()]
                                        .iter()
                                        .any(|f| e.holds(&f.diagnostic))
                                };
                                let rule = rules::REGISTRY[i];
                                if !rules::findings_hold_inside(
                                    rule,
                                    &cx,
                                    std::slice::from_ref(&place),
                                    &found_inside,
                                ) {
                                    said[i].1 += 1;
                                    continue;
                                }
                                said[i].0 += 1;
                                let after_found = found_after.get_or_insert_with(|| {
                                    findings_by_rule(&validator.validate_asset_unplaced(
                                        path,
                                        &after,
                                        loaded.diagnostics.clone(),
                                        &Settings::default(),
                                        None,
                                    ))
                                });
                                assert_eq!(
                                    by_rule[i],
                                    after_found[i],
                                    "{}: rule {i} ({:?}) with /{property}/{index}/{member} {}",
                                    path.display(),
                                    rule.codes().iter().map(|c| c.name).collect::<Vec<_>>(),
                                    if wrong.is_some() {
                                        "of the wrong type"
                                    } else {
                                        "removed"
                                    }
                                );
                            }
                        }
                    }
                }
            }
        }
        // The rules that re-judge elements were asked both ways, many times.
        for first_code in ["TYPE_MISMATCH", "UNEXPECTED_PROPERTY"] {
            let i = rules::REGISTRY
                .iter()
                .position(|rule| rule.codes()[0].name == first_code)
                .expect("the rule is registered");
            let (held, refused) = said[i];
            assert!(
                held > 500 && refused > 500,
                "{first_code}'s rule: held {held}, refused {refused}"
            );
        }
    }
}
