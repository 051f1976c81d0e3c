//! Integration tests for `velvet validate --fix`, `--unsafe-fixes` and `--diff`, and for the
//! fixes the JSON and SARIF reports carry.
//!
//! Every fixable code's triggering fixture (fixtures/validate/<CODE>/triggers.gltf) is fixed to
//! the bytes of fixed.gltf beside it, and then validates without the code; `--diff` shows that
//! change, and the JSON and SARIF fixes, applied by the small appliers here (which share no
//! code with velvet's), make the same bytes. Set VELVET_BLESS=1 to rewrite fixed.gltf after a
//! deliberate change (and read the diff).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use velvet::diagnostics::{Code, Safety, Settings};
use velvet::rules::all_codes;
use velvet::validate::Validator;

const FIXTURES: &str = "fixtures/validate";

fn velvet_in(dir: &Path, args: &[&str]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_velvet"));
    cmd.current_dir(dir).args(args);
    for var in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE", "TERM", "CI"] {
        cmd.env_remove(var);
    }
    cmd.output().expect("velvet runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 output")
}

fn fixable_codes() -> Vec<&'static Code> {
    all_codes()
        .into_iter()
        .filter(|c| c.fix.is_some())
        .collect()
}

/// The file extension of `code`'s fixtures: "glb" for a container's codes, else "gltf".
fn extension_of(code: &str) -> &'static str {
    if Path::new(FIXTURES)
        .join(code)
        .join("triggers.glb")
        .is_file()
    {
        "glb"
    } else {
        "gltf"
    }
}

/// The fixable codes whose fixtures are .gltf text (a .glb's are binary: no diff, no text).
fn text_fixable_codes() -> Vec<&'static Code> {
    fixable_codes()
        .into_iter()
        .filter(|c| extension_of(c.name) == "gltf")
        .collect()
}

/// The fixture folder of `code`, copied into a temporary folder (the resources its trigger
/// names come along).
fn case_copy(code: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for entry in std::fs::read_dir(Path::new(FIXTURES).join(code)).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, dir.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    dir
}

/// The flags that apply the fix of `code`.
fn fix_flags(code: &Code) -> Vec<&'static str> {
    match code.fix {
        Some(Safety::Unsafe) => vec!["--fix", "--unsafe-fixes"],
        _ => vec!["--fix"],
    }
}

fn expected_fixed(code: &str) -> Vec<u8> {
    let path = Path::new(FIXTURES)
        .join(code)
        .join(format!("fixed.{}", extension_of(code)));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn codes_in(path: &Path) -> Vec<&'static str> {
    let report = Validator::builtin(Settings::default()).validate_file(path);
    report.findings.iter().map(|f| f.diagnostic.code).collect()
}

#[test]
fn every_fixable_code_has_its_trigger_fixed_to_the_expected_bytes_and_no_longer_reported() {
    let codes = fixable_codes();
    assert!(codes.len() >= 5, "{} fixable codes", codes.len());
    for code in codes {
        let dir = case_copy(code.name);
        let ext = extension_of(code.name);
        let trigger = format!("triggers.{ext}");
        let file = dir.path().join(&trigger);
        let before = std::fs::read(&file).unwrap();
        assert!(codes_in(&file).contains(&code.name), "{}", code.name);
        let mut args = vec!["validate"];
        args.extend(fix_flags(code));
        args.push(&trigger);
        let o = velvet_in(dir.path(), &args);
        let out = stdout(&o);
        let after = std::fs::read(&file).unwrap();
        let golden = Path::new(FIXTURES)
            .join(code.name)
            .join(format!("fixed.{ext}"));
        if std::env::var_os("VELVET_BLESS").is_some() {
            std::fs::write(&golden, &after).unwrap();
        }
        assert_ne!(after, before, "{}: nothing was fixed\n{out}", code.name);
        assert_eq!(
            String::from_utf8_lossy(&after),
            String::from_utf8_lossy(&expected_fixed(code.name)),
            "{}: the fixed file differs from fixed.{ext}",
            code.name
        );
        assert!(
            out.contains(": fixed: "),
            "{}: the output names the fix\n{out}",
            code.name
        );
        if code.fix == Some(Safety::Unsafe) {
            assert!(
                out.contains("(unsafe, "),
                "{}: said unsafe\n{out}",
                code.name
            );
        }
        assert!(
            !codes_in(&file).contains(&code.name),
            "{}: still reported after the fix",
            code.name
        );
        // A second run has nothing left to do: the file is not written again.
        let modified = std::fs::metadata(&file).unwrap().modified().unwrap();
        let o = velvet_in(dir.path(), &args);
        assert_eq!(std::fs::read(&file).unwrap(), after, "{}", code.name);
        assert_eq!(
            std::fs::metadata(&file).unwrap().modified().unwrap(),
            modified,
            "{}: written again",
            code.name
        );
        assert!(!stdout(&o).contains(": fixed: "), "{}", code.name);
    }
}

#[test]
fn a_safe_fix_is_not_applied_without_unsafe_fixes_and_an_unsafe_one_is_said_to_need_it() {
    for code in fixable_codes()
        .into_iter()
        .filter(|c| c.fix == Some(Safety::Unsafe))
    {
        let dir = case_copy(code.name);
        let trigger = format!("triggers.{}", extension_of(code.name));
        let file = dir.path().join(&trigger);
        let before = std::fs::read(&file).unwrap();
        let o = velvet_in(dir.path(), &["validate", "--fix", &trigger]);
        assert_eq!(std::fs::read(&file).unwrap(), before, "{}", code.name);
        let out = stdout(&o);
        assert!(
            out.contains("fix (unsafe, --fix --unsafe-fixes): "),
            "{}: {out}",
            code.name
        );
        assert!(out.contains("fixable with --fix --unsafe-fixes"), "{out}");
    }
}

/// `source` with the unified diff `patch` applied (hunks in order, context checked).
fn apply_unified_diff(source: &str, patch: &str) -> String {
    let lines: Vec<&str> = source.split_inclusive('\n').collect();
    let mut out = String::new();
    let mut at = 0; // lines of the source copied or consumed so far
    let mut patch_lines = patch.split_inclusive('\n').peekable();
    while let Some(line) = patch_lines.next() {
        if line.starts_with("---") || line.starts_with("+++") {
            continue;
        }
        let header = line
            .strip_prefix("@@ -")
            .unwrap_or_else(|| panic!("a hunk header, not {line:?}"));
        let old_start: usize = header.split([',', ' ']).next().unwrap().parse().unwrap();
        let start = old_start.saturating_sub(1);
        while at < start {
            out.push_str(lines[at]);
            at += 1;
        }
        while let Some(next) = patch_lines.peek() {
            if next.starts_with("@@") {
                break;
            }
            let next = patch_lines.next().unwrap();
            if next.starts_with('\\') {
                // "\ No newline at end of file": the line before has none.
                if out.ends_with('\n') {
                    out.pop();
                }
                continue;
            }
            let (kind, text) = next.split_at(1);
            match kind {
                " " => {
                    assert_eq!(
                        lines[at].trim_end_matches('\n'),
                        text.trim_end_matches('\n')
                    );
                    out.push_str(lines[at]);
                    at += 1;
                }
                "-" => {
                    assert_eq!(
                        lines[at].trim_end_matches('\n'),
                        text.trim_end_matches('\n')
                    );
                    at += 1;
                }
                "+" => out.push_str(text),
                other => panic!("unexpected diff line kind {other:?}"),
            }
        }
    }
    while at < lines.len() {
        out.push_str(lines[at]);
        at += 1;
    }
    out
}

#[test]
fn diff_prints_the_change_that_fix_writes_and_writes_nothing() {
    for code in text_fixable_codes() {
        let dir = case_copy(code.name);
        let file = dir.path().join("triggers.gltf");
        let before = std::fs::read_to_string(&file).unwrap();
        let mut args = vec!["validate", "--diff"];
        if code.fix == Some(Safety::Unsafe) {
            args.push("--unsafe-fixes");
        }
        args.push("triggers.gltf");
        let o = velvet_in(dir.path(), &args);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{}: a diff fails the run",
            code.name
        );
        let diff = stdout(&o);
        assert!(
            diff.starts_with("--- a/triggers.gltf\n+++ b/triggers.gltf\n@@ "),
            "{}: {diff}",
            code.name
        );
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            before,
            "{}: --diff wrote the file",
            code.name
        );
        assert_eq!(
            apply_unified_diff(&before, &diff),
            String::from_utf8(expected_fixed(code.name)).unwrap(),
            "{}: the diff is not the fix",
            code.name
        );
    }
}

/// `source` with `edits` made in one pass by the applier written apart from velvet
/// (`support/one_pass.rs`), which refuses edits that overlap or insert at one place.
fn apply_replacements(source: &[u8], edits: Vec<one_pass::Edit>) -> Vec<u8> {
    one_pass::apply(source, edits).unwrap_or_else(|e| panic!("{e}"))
}

/// The byte offset of 1-based `line` and character `column` in `text`.
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    text[start..]
        .char_indices()
        .nth(column - 1)
        .map_or(text.len(), |(i, _)| start + i)
}

fn applicable(code: &Code, applicability: &str) -> bool {
    applicability == "safe" || code.fix == Some(Safety::Unsafe)
}

#[test]
fn json_and_sarif_fixes_applied_apart_from_velvet_give_the_fixed_bytes() {
    for code in text_fixable_codes() {
        let dir = case_copy(code.name);
        let source = std::fs::read_to_string(dir.path().join("triggers.gltf")).unwrap();
        let expected = expected_fixed(code.name);

        let o = velvet_in(
            dir.path(),
            &["validate", "--format", "json", "triggers.gltf"],
        );
        let report: Value = serde_json::from_slice(&o.stdout).unwrap();
        let mut replacements = Vec::new();
        for message in report["issues"]["messages"].as_array().unwrap() {
            let fix = &message["fix"];
            if fix.is_null() || !applicable(code, fix["applicability"].as_str().unwrap()) {
                continue;
            }
            for edit in fix["edits"].as_array().unwrap() {
                let (start, end) = (&edit["location"], &edit["endLocation"]);
                let r = one_pass::Edit::of_json_edit(edit);
                // Rows and columns name the same places as the offsets.
                let place = |l: &Value| {
                    offset_of(
                        &source,
                        l["row"].as_u64().unwrap() as usize,
                        l["column"].as_u64().unwrap() as usize,
                    )
                };
                assert_eq!(
                    (place(start), place(end)),
                    (r.start, r.end),
                    "{}",
                    code.name
                );
                replacements.push(r);
            }
        }
        assert!(
            report["fixes"]["fixable"].as_u64().unwrap()
                + report["fixes"]["fixableUnsafe"].as_u64().unwrap()
                > 0
        );
        assert_eq!(
            String::from_utf8(apply_replacements(source.as_bytes(), replacements)).unwrap(),
            String::from_utf8_lossy(&expected),
            "{}: the JSON report's fixes",
            code.name
        );

        let o = velvet_in(
            dir.path(),
            &["validate", "--format", "sarif", "triggers.gltf"],
        );
        let log: Value = serde_json::from_slice(&o.stdout).unwrap();
        let mut replacements = Vec::new();
        for result in log["runs"][0]["results"].as_array().unwrap() {
            let Some(fixes) = result["fixes"].as_array() else {
                continue;
            };
            let safety = all_codes()
                .into_iter()
                .find(|c| c.name == result["ruleId"].as_str().unwrap())
                .and_then(|c| c.fix)
                .unwrap();
            if safety == Safety::Unsafe && code.fix != Some(Safety::Unsafe) {
                continue;
            }
            for fix in fixes {
                for change in fix["artifactChanges"].as_array().unwrap() {
                    assert_eq!(change["artifactLocation"]["uri"], "triggers.gltf");
                    for r in change["replacements"].as_array().unwrap() {
                        let region = &r["deletedRegion"];
                        let start = region["byteOffset"].as_u64().unwrap() as usize;
                        let end = start + region["byteLength"].as_u64().unwrap() as usize;
                        let at = |line: &str, column: &str| {
                            offset_of(
                                &source,
                                region[line].as_u64().unwrap() as usize,
                                region[column].as_u64().unwrap() as usize,
                            )
                        };
                        assert_eq!(
                            (at("startLine", "startColumn"), at("endLine", "endColumn")),
                            (start, end),
                            "{}",
                            code.name
                        );
                        replacements.push(one_pass::Edit {
                            start,
                            end,
                            text: r["insertedContent"]["text"]
                                .as_str()
                                .unwrap_or_default()
                                .to_string(),
                        });
                    }
                }
            }
        }
        assert_eq!(
            String::from_utf8(apply_replacements(source.as_bytes(), replacements)).unwrap(),
            String::from_utf8_lossy(&expected),
            "{}: the SARIF log's fixes",
            code.name
        );
    }
}

#[test]
fn a_safe_fix_leaves_what_migrate_plans_for_the_file_as_it_was() {
    for code in fixable_codes()
        .into_iter()
        .filter(|c| c.fix == Some(Safety::Safe))
    {
        let case = Path::new(FIXTURES).join(code.name);
        let plan = |path: PathBuf| {
            let loaded = velvet::asset::load(&path);
            let asset = loaded.asset.expect("the fixture loads");
            // The materials' plans: every value the migration reads and sets. (Its declarations
            // follow extensionsUsed, which a safe fix may change: a migration of a file whose
            // unused fuzz declaration was removed declares fuzz again.)
            velvet::migrate::plan_document(&asset, &velvet::migrate::Options::default()).materials
        };
        let ext = extension_of(code.name);
        assert_eq!(
            plan(case.join(format!("triggers.{ext}"))),
            plan(case.join(format!("fixed.{ext}"))),
            "{}: the safe fix changed what the file renders as",
            code.name
        );
    }
}

#[test]
fn fix_leaves_a_clean_file_byte_identical_and_unwritten() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for code in fixable_codes() {
        // The clean twin with the resources it names.
        let case = dir.path().join(code.name);
        std::fs::create_dir(&case).unwrap();
        for entry in std::fs::read_dir(Path::new(FIXTURES).join(code.name)).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_file() && !name.starts_with("triggers") && !name.starts_with("fixed") {
                std::fs::copy(&path, case.join(&name)).unwrap();
            }
        }
        files.push(case.join(format!("clean.{}", extension_of(code.name))));
    }
    let sample = dir.path().join("sample");
    std::fs::create_dir(&sample).unwrap();
    for name in ["velvet-chair.gltf", "velvet-chair.bin", "fabric.png"] {
        std::fs::copy(Path::new("fixtures/sample").join(name), sample.join(name)).unwrap();
    }
    files.push(sample.join("velvet-chair.gltf"));
    // A time in the past, so that a rewrite shows whatever the clock's resolution.
    let past = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    let mut before = Vec::new();
    for f in &files {
        std::fs::File::options()
            .write(true)
            .open(f)
            .unwrap()
            .set_modified(past)
            .unwrap();
        before.push((
            std::fs::read(f).unwrap(),
            std::fs::metadata(f).unwrap().modified().unwrap(),
        ));
    }
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "--fix",
            "--unsafe-fixes",
            "--exit-non-zero-on-fix",
            ".",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    for (f, (bytes, modified)) in files.iter().zip(before) {
        assert_eq!(std::fs::read(f).unwrap(), bytes, "{}", f.display());
        assert_eq!(
            std::fs::metadata(f).unwrap().modified().unwrap(),
            modified,
            "{} was written",
            f.display()
        );
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn the_exit_status_follows_the_findings_left_and_a_pre_commit_run_fails_on_a_change() {
    let dir = case_copy("UNDECLARED_EXTENSION");
    let file = dir.path().join("triggers.gltf");
    let original = std::fs::read(&file).unwrap();
    let status = |args: &[&str]| velvet_in(dir.path(), args).status.code();
    assert_eq!(status(&["validate", "triggers.gltf"]), Some(1));
    // Fixed findings do not fail the run.
    assert_eq!(status(&["validate", "--fix", "triggers.gltf"]), Some(0));
    assert_ne!(std::fs::read(&file).unwrap(), original);
    // As pre-commit's own fixers do: a changed file fails the hook, once.
    std::fs::write(&file, &original).unwrap();
    let args = [
        "validate",
        "--fix",
        "--exit-non-zero-on-fix",
        "triggers.gltf",
    ];
    assert_eq!(status(&args), Some(1));
    assert_eq!(status(&args), Some(0));
    // --diff fails when it shows a change, and passes on a file with nothing to fix.
    std::fs::write(&file, &original).unwrap();
    assert_eq!(status(&["validate", "--diff", "triggers.gltf"]), Some(1));
    assert_eq!(std::fs::read(&file).unwrap(), original);
    assert_eq!(status(&["validate", "--diff", "clean.gltf"]), Some(0));
    assert_eq!(
        stdout(&velvet_in(
            dir.path(),
            &["validate", "--diff", "clean.gltf"]
        )),
        ""
    );

    // An error no fix repairs still fails the run after the others are fixed.
    let text = r#"{"asset":{"version":"2.0"},"materials":[{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[1,1,1],"sheenColorTexture":{"index":3}}}}]}"#;
    std::fs::write(dir.path().join("broken.gltf"), text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--fix", "broken.gltf"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let out = stdout(&o);
    assert!(out.contains("error UNRESOLVED_REFERENCE"), "{out}");
    assert!(
        out.contains("broken.gltf: fixed: declare KHR_materials_sheen"),
        "{out}"
    );
    assert!(
        out.ends_with("1 file checked: 1 error, 0 warnings, 0 info, 0 hints; 1 fixed\n"),
        "{out}"
    );
    // An unsafe fix that is not asked for leaves its error, and the run fails.
    let dir = case_copy("VALUE_NOT_IN_RANGE");
    assert_eq!(
        status_in(dir.path(), &["validate", "--fix", "triggers.gltf"]),
        Some(1)
    );
    assert_eq!(
        status_in(
            dir.path(),
            &["validate", "--fix", "--unsafe-fixes", "triggers.gltf"]
        ),
        Some(0)
    );
}

fn status_in(dir: &Path, args: &[&str]) -> Option<i32> {
    velvet_in(dir, args).status.code()
}

#[test]
fn a_fix_that_would_bring_another_finding_is_refused_with_the_reason_and_not_written() {
    // Clamping sheenRoughnessFactor -1 to 0 would scale the roughness texture to nothing: a
    // KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT the file did not have.
    let dir = tempfile::tempdir().unwrap();
    let text = "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"extensionsUsed\": [\"KHR_materials_sheen\"],\n  \"materials\": [\n    {\"extensions\": {\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1, 1], \"sheenRoughnessFactor\": -1, \"sheenRoughnessTexture\": {\"index\": 0}}}}\n  ],\n  \"textures\": [{\"source\": 0}],\n  \"images\": [{\"uri\": \"rough.png\"}]\n}\n";
    std::fs::write(dir.path().join("m.gltf"), text).unwrap();
    std::fs::copy(
        Path::new(FIXTURES).join("KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT/rough.png"),
        dir.path().join("rough.png"),
    )
    .unwrap();
    let o = velvet_in(
        dir.path(),
        &["validate", "--fix", "--unsafe-fixes", "m.gltf"],
    );
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("m.gltf")).unwrap(),
        text
    );
    assert!(out.contains("error VALUE_NOT_IN_RANGE"), "{out}");
    assert!(
        out.contains("    at /materials/0/extensions/KHR_materials_sheen/sheenRoughnessFactor\n    fix (unsafe) not applied: clamp sheenRoughnessFactor to 0: the fixed file would have KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT"),
        "{out}"
    );
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "--format",
            "json",
            "--fix",
            "--unsafe-fixes",
            "m.gltf",
        ],
    );
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let refused = &report["fixes"]["refused"][0];
    assert_eq!(refused["repairs"][0]["code"], "VALUE_NOT_IN_RANGE");
    assert!(refused["reason"]
        .as_str()
        .unwrap()
        .contains("KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT"));
}

#[test]
fn several_fixes_of_one_file_are_applied_in_one_pass() {
    // Both declarations unused (the whole list goes), a fuzz roughness left to its default, and
    // an undeclared extension elsewhere.
    let dir = tempfile::tempdir().unwrap();
    let text = "{\n  \"asset\": {\n    \"version\": \"2.0\"\n  },\n  \"extensionsUsed\": [\n    \"KHR_materials_sheen\",\n    \"KHR_materials_fuzz\"\n  ],\n  \"materials\": [\n    {\n      \"name\": \"plain\"\n    }\n  ],\n  \"nodes\": [\n    {\n      \"extensions\": {\n        \"EXT_example\": {}\n      }\n    }\n  ]\n}\n";
    std::fs::write(dir.path().join("m.gltf"), text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--fix", "m.gltf"]);
    let out = stdout(&o);
    let fixed = std::fs::read_to_string(dir.path().join("m.gltf")).unwrap();
    assert_eq!(
        fixed,
        "{\n  \"asset\": {\n    \"version\": \"2.0\"\n  },\n  \"extensionsUsed\": [\n    \"EXT_example\"\n  ],\n  \"materials\": [\n    {\n      \"name\": \"plain\"\n    }\n  ],\n  \"nodes\": [\n    {\n      \"extensions\": {\n        \"EXT_example\": {}\n      }\n    }\n  ]\n}\n",
        "{out}"
    );
    // The three fixes edit one array, so they are one fix repairing three findings.
    assert_eq!(out.matches(": fixed: ").count(), 1, "{out}");
    assert!(out.contains("(safe, 3 findings of UNDECLARED_EXTENSION, KHR_MATERIALS_SHEEN_DECLARED_UNUSED, KHR_MATERIALS_FUZZ_DECLARED_UNUSED)"), "{out}");
    assert!(out.contains("; 3 fixed"), "{out}");
    assert!(codes_in(&dir.path().join("m.gltf")).is_empty(), "{out}");
}

/// A GLB of `json` (padded with spaces) and `bin`.
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}

#[test]
fn a_glb_is_fixed_in_its_json_chunk_and_keeps_its_bin_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let json =
        std::fs::read_to_string(Path::new(FIXTURES).join("UNDECLARED_EXTENSION/triggers.gltf"))
            .unwrap()
            .replace(
                "\"materials\"",
                "\"buffers\": [\n    {\n      \"byteLength\": 8\n    }\n  ],\n  \"materials\"",
            );
    let bin = [1u8, 2, 3, 4, 5, 6, 7, 8];
    let path = dir.path().join("m.glb");
    std::fs::write(&path, glb(json.as_bytes(), &bin)).unwrap();
    assert!(codes_in(&path).contains(&"UNDECLARED_EXTENSION"));
    let o = velvet_in(dir.path(), &["validate", "--fix", "m.glb"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(codes_in(&path).is_empty());
    let loaded = velvet::asset::load(&path);
    let asset = loaded.asset.unwrap();
    assert_eq!(asset.bin.as_deref(), Some(&bin[..]));
    let chunk = asset.json_text.trim_end_matches(' ');
    assert!(
        chunk.contains("  \"extensionsUsed\": [\n    \"KHR_materials_sheen\"\n  ],\n"),
        "{chunk}"
    );
    // Every other byte of the JSON as it was.
    assert_eq!(
        chunk.replace(
            "  \"extensionsUsed\": [\n    \"KHR_materials_sheen\"\n  ],\n",
            ""
        ),
        json
    );
}

#[test]
fn the_fixers_table_in_the_docs_names_every_fixable_code_with_its_safety() {
    let doc = std::fs::read_to_string("docs/codes.md").unwrap();
    let start = doc
        .find("| code | fix | what it does |")
        .expect("the fixers table");
    let mut named: Vec<(String, String)> = Vec::new();
    for row in doc[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
    {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        for code in cells[1].split(", ") {
            named.push((code.trim_matches('`').to_string(), cells[2].to_string()));
        }
    }
    named.sort();
    let mut registry: Vec<(String, String)> = fixable_codes()
        .iter()
        .map(|c| (c.name.to_string(), c.fix_label().to_string()))
        .collect();
    registry.sort();
    assert_eq!(named, registry);
}

#[test]
fn the_json_fixes_of_many_materials_applied_together_are_what_fix_writes() {
    // A fix per material (found and spliced together), one shared by several findings, and a
    // declaration: applied apart from velvet they give the bytes --fix writes.
    let dir = tempfile::tempdir().unwrap();
    let materials: Vec<String> = (0..40)
        .map(|i| {
            format!(
                "    {{\n      \"name\": \"m{i}\",\n      \"extensions\": {{\n        \"KHR_materials_fuzz\": {{\n          \"fuzzFactor\": 1\n        }},\n        \"EXT_made_up\": {{}}\n      }}\n    }}"
            )
        })
        .collect();
    let text = format!(
        "{{\n  \"asset\": {{\n    \"version\": \"2.0\"\n  }},\n  \"extensionsUsed\": [\n    \"KHR_materials_fuzz\"\n  ],\n  \"materials\": [\n{}\n  ]\n}}\n",
        materials.join(",\n")
    );
    std::fs::write(dir.path().join("m.gltf"), &text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--format", "json", "m.gltf"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["fixes"]["fixable"], 41);
    let replacements = one_pass::json_edits(&report);
    let applied = apply_replacements(text.as_bytes(), replacements);
    let o = velvet_in(dir.path(), &["validate", "--fix", "m.gltf"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let fixed = std::fs::read(dir.path().join("m.gltf")).unwrap();
    assert_eq!(
        String::from_utf8(applied).unwrap(),
        String::from_utf8(fixed).unwrap()
    );
}

#[test]
fn after_fix_the_fixes_left_are_given_against_the_text_written() {
    // A safe fix (applied) and an unsafe one (left): the JSON report of the --fix run gives the
    // unsafe fix's edits in the file as written, where applying them does what
    // --unsafe-fixes does.
    let dir = tempfile::tempdir().unwrap();
    let text = "{\n  \"asset\": {\n    \"version\": \"2.0\"\n  },\n  \"materials\": [\n    {\n      \"extensions\": {\n        \"KHR_materials_sheen\": {\n          \"sheenColorFactor\": [1, 1, 1],\n          \"sheenRoughnessFactor\": 1.5\n        }\n      }\n    }\n  ]\n}\n";
    std::fs::write(dir.path().join("m.gltf"), text).unwrap();
    let o = velvet_in(
        dir.path(),
        &["validate", "--fix", "--format", "json", "m.gltf"],
    );
    assert_eq!(o.status.code(), Some(1));
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        report["fixes"]["applied"][0]["repairs"][0]["code"],
        "UNDECLARED_EXTENSION"
    );
    assert_eq!(report["fixes"]["changed"], true);
    assert_eq!(report["fixes"]["fixableUnsafe"], 1);
    let written = std::fs::read(dir.path().join("m.gltf")).unwrap();
    let messages = report["issues"]["messages"].as_array().unwrap();
    assert_eq!(messages.len(), 1, "{messages:?}");
    let replacements: Vec<one_pass::Edit> = messages[0]["fix"]["edits"]
        .as_array()
        .unwrap()
        .iter()
        .map(one_pass::Edit::of_json_edit)
        .collect();
    let applied = apply_replacements(&written, replacements);
    let o = velvet_in(
        dir.path(),
        &["validate", "--fix", "--unsafe-fixes", "m.gltf"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert_eq!(applied, std::fs::read(dir.path().join("m.gltf")).unwrap());
}

#[test]
fn the_codes_command_says_how_each_code_is_fixed() {
    let o = velvet_in(Path::new("."), &["codes"]);
    let out = stdout(&o);
    for code in all_codes() {
        let line = out
            .lines()
            .find(|l| l.split_whitespace().next() == Some(code.name))
            .unwrap();
        assert_eq!(
            line.split_whitespace().nth(2),
            Some(code.fix_label()),
            "{line}"
        );
    }
    let fixable = fixable_codes();
    assert!(fixable.iter().any(|c| c.fix == Some(Safety::Safe)));
    assert!(fixable.iter().any(|c| c.fix == Some(Safety::Unsafe)));
}

#[test]
fn a_byte_order_mark_is_removed_by_its_fix_and_the_reports_edit_the_bytes_before_the_text() {
    let dir = case_copy("UNDECLARED_EXTENSION");
    let mut bytes = b"\xEF\xBB\xBF".to_vec();
    bytes.extend(std::fs::read(dir.path().join("triggers.gltf")).unwrap());
    std::fs::write(dir.path().join("bom.gltf"), &bytes).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--format", "json", "bom.gltf"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let bom = report["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["code"] == "BOM_PRESENT")
        .unwrap();
    assert_eq!(
        bom["fix"],
        serde_json::json!({"applicability": "safe", "message": "remove the byte-order mark",
            "edits": [{"content": "", "location": {"row": 1, "column": 1, "offset": 0},
                       "endLocation": {"row": 1, "column": 2, "offset": 3}}]})
    );
    // The report's edits, the mark's and the declaration's (counted after the mark), give
    // the fixed file; so do the SARIF log's.
    let replacements = one_pass::json_edits(&report);
    assert_eq!(
        apply_replacements(&bytes, replacements),
        expected_fixed("UNDECLARED_EXTENSION")
    );
    assert_eq!(one_pass::check(&dir.path().join("bom.gltf")), Ok(true));
    std::fs::write(dir.path().join("bom.gltf"), &bytes).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--fix", "bom.gltf"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert_eq!(
        std::fs::read(dir.path().join("bom.gltf")).unwrap(),
        expected_fixed("UNDECLARED_EXTENSION")
    );
}

#[path = "support/one_pass.rs"]
mod one_pass;

#[test]
fn every_fixtures_report_edits_applied_in_one_pass_give_what_fix_unsafe_fixes_writes() {
    let assets = one_pass::files_under(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures"),
        &|path| matches!(path.extension()?.to_str()?, "gltf" | "glb").then(|| path.to_path_buf()),
    );
    let mut with_edits = Vec::new();
    let mut failures = Vec::new();
    for path in &assets {
        match one_pass::check(path) {
            Ok(true) => with_edits.push(path),
            Ok(false) => {}
            Err(e) => failures.push(e),
        }
    }
    println!(
        "fix edits applied in one pass: {} of {} fixtures with fixes give what --fix --unsafe-fixes writes ({} assets)",
        with_edits.len(),
        with_edits.len() + failures.len(),
        assets.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    // The fixable codes' triggers, the CI fixtures' .glb and the migrate fixtures with fixes.
    let glbs = with_edits
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .count();
    assert!(
        with_edits.len() >= 20,
        "{} files with edits",
        with_edits.len()
    );
    assert!(glbs >= 1, "{glbs} .glb files with edits");
}

#[test]
fn findings_of_one_code_at_one_pointer_each_carry_their_own_fix() {
    // One primitive without TEXCOORD_1 and two textures that read it: two findings at the
    // primitive's material, each fix pointing its own texture at TEXCOORD_0.
    let dir = tempfile::tempdir().unwrap();
    let text = r#"{"asset":{"version":"2.0"},"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":1}},"normalTexture":{"index":0,"texCoord":1}}],"textures":[{}],"meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0}]}],"accessors":[{"count":1,"componentType":5126,"type":"VEC3","min":[0,0,0],"max":[0,0,0]},{"count":1,"componentType":5126,"type":"VEC2"}]}"#;
    std::fs::write(dir.path().join("m.gltf"), text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--format", "json", "m.gltf"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let fixed: Vec<(String, usize)> = report["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["code"] == "MESH_PRIMITIVE_TOO_FEW_TEXCOORDS")
        .map(|m| {
            let edits = m["fix"]["edits"].as_array().unwrap();
            assert_eq!(edits.len(), 1, "{m}");
            (
                edits[0]["content"].as_str().unwrap().to_string(),
                edits[0]["location"]["offset"].as_u64().unwrap() as usize,
            )
        })
        .collect();
    let at = |key: &str| {
        text.find(key).unwrap()
            + text[text.find(key).unwrap()..]
                .find("\"texCoord\":1")
                .unwrap()
            + "\"texCoord\":".len()
    };
    assert_eq!(
        fixed,
        [
            ("0".to_string(), at("baseColorTexture")),
            ("0".to_string(), at("normalTexture"))
        ]
    );
}

#[test]
fn fixes_that_edit_one_new_array_are_one_fix_whose_edits_are_given_once() {
    // Two extensions used and none declared: both declarations create extensionsUsed.
    let dir = tempfile::tempdir().unwrap();
    let text = "{\n  \"asset\": {\n    \"version\": \"2.0\"\n  },\n  \"materials\": [\n    {\n      \"extensions\": {\n        \"KHR_materials_sheen\": {},\n        \"KHR_materials_fuzz\": {\n          \"fuzzRoughnessFactor\": 0.5\n        }\n      }\n    }\n  ]\n}\n";
    std::fs::write(dir.path().join("m.gltf"), text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--format", "json", "m.gltf"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let messages = report["issues"]["messages"].as_array().unwrap();
    let undeclared: Vec<(usize, &Value)> = messages
        .iter()
        .enumerate()
        .filter(|(_, m)| m["code"] == "UNDECLARED_EXTENSION")
        .collect();
    assert_eq!(undeclared.len(), 2, "{report}");
    let (first, second) = (undeclared[0], undeclared[1]);
    assert_eq!(
        first.1["fix"]["message"],
        "declare KHR_materials_sheen in extensionsUsed; declare KHR_materials_fuzz in extensionsUsed"
    );
    assert_eq!(first.1["fix"]["edits"].as_array().unwrap().len(), 1);
    assert_eq!(
        first.1["fix"]["edits"][0]["content"],
        ",\n  \"extensionsUsed\": [\n    \"KHR_materials_sheen\",\n    \"KHR_materials_fuzz\"\n  ]"
    );
    assert_eq!(second.1["fix"]["edits"], serde_json::json!([]));
    assert_eq!(second.1["fix"]["editsWithMessage"], first.0);
    assert_eq!(report["fixes"]["fixable"], 2);
    // The SARIF log gives the fix once, with both findings it repairs and its safety.
    let o = velvet_in(dir.path(), &["validate", "--format", "sarif", "m.gltf"]);
    let log: Value = serde_json::from_slice(&o.stdout).unwrap();
    let fixes: Vec<&Value> = log["runs"][0]["results"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r["fixes"].as_array().into_iter().flatten())
        .collect();
    assert_eq!(fixes.len(), 1, "{log}");
    assert_eq!(fixes[0]["properties"]["applicability"], "safe");
    assert_eq!(
        fixes[0]["properties"]["repairs"],
        serde_json::json!([
            {"ruleId": "UNDECLARED_EXTENSION", "pointer": "/materials/0/extensions/KHR_materials_sheen"},
            {"ruleId": "UNDECLARED_EXTENSION", "pointer": "/materials/0/extensions/KHR_materials_fuzz"}
        ])
    );
}

#[test]
fn a_read_only_file_is_not_fixed_and_the_run_fails() {
    use std::os::unix::fs::PermissionsExt;
    let dir = case_copy("UNDECLARED_EXTENSION");
    let file = dir.path().join("triggers.gltf");
    let before = std::fs::read(&file).unwrap();
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o444)).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--fix", "triggers.gltf"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("the file is read-only; velvet does not replace it"),
        "{}",
        stdout(&o)
    );
    assert_eq!(std::fs::read(&file).unwrap(), before);
    assert_eq!(
        std::fs::metadata(&file).unwrap().permissions().mode() & 0o777,
        0o444
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_diff_of_a_path_with_spaces_is_taken_by_patch() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("my assets");
    std::fs::create_dir(&folder).unwrap();
    let source = Path::new(FIXTURES).join("UNDECLARED_EXTENSION/triggers.gltf");
    std::fs::copy(&source, folder.join("a chair.gltf")).unwrap();
    let o = velvet_in(
        dir.path(),
        &["validate", "--diff", "my assets/a chair.gltf"],
    );
    let diff = stdout(&o);
    assert!(
        diff.starts_with("--- a/my assets/a chair.gltf\t\n+++ b/my assets/a chair.gltf\t\n"),
        "{diff}"
    );
    let mut patch = Command::new("patch")
        .args(["-p1", "--batch", "--silent"])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::piped())
        .spawn()
        .expect("patch runs");
    use std::io::Write;
    patch
        .stdin
        .take()
        .unwrap()
        .write_all(diff.as_bytes())
        .unwrap();
    assert!(patch.wait().unwrap().success());
    assert_eq!(
        std::fs::read(folder.join("a chair.gltf")).unwrap(),
        expected_fixed("UNDECLARED_EXTENSION")
    );
}

#[test]
fn a_glb_is_not_diffed_and_patch_leaves_it_whole() {
    let dir = tempfile::tempdir().unwrap();
    let json =
        std::fs::read(Path::new(FIXTURES).join("UNDECLARED_EXTENSION/triggers.gltf")).unwrap();
    let bytes = glb(&json, &[]);
    std::fs::write(dir.path().join("m.glb"), &bytes).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--diff", "m.glb"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stdout(&o),
        "# m.glb: not shown as a diff (a .glb is binary; patch would break it): `velvet validate --fix m.glb` applies its fixes, and --format json gives its JSON chunk's edits\n"
    );
    let mut patch = Command::new("patch")
        .args(["-p1", "--batch", "--silent"])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("patch runs");
    use std::io::Write;
    patch.stdin.take().unwrap().write_all(&o.stdout).unwrap();
    patch.wait().unwrap();
    assert_eq!(std::fs::read(dir.path().join("m.glb")).unwrap(), bytes);
    // The JSON report's edits of its chunk, applied and framed, are what --fix writes.
    assert_eq!(one_pass::check(&dir.path().join("m.glb")), Ok(true));
}

#[test]
fn fix_only_prints_the_findings_left_and_not_the_fixes_applied() {
    let dir = case_copy("UNDECLARED_EXTENSION");
    let o = velvet_in(dir.path(), &["validate", "--fix-only", "triggers.gltf"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert_eq!(
        stdout(&o),
        "1 file checked: 0 errors, 0 warnings, 0 info, 0 hints; 1 fixed\n"
    );
    assert_eq!(
        std::fs::read(dir.path().join("triggers.gltf")).unwrap(),
        expected_fixed("UNDECLARED_EXTENSION")
    );
}
