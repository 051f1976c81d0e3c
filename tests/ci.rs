//! velvet in CI and pre-commit: golden output for every format, SARIF checked against the
//! SARIF 2.1.0 schema and GitHub's code-scanning requirements, velvet.toml discovery and
//! precedence, the pre-commit hook run as pre-commit runs it, colour, quiet, completions and
//! the man page. Everything runs the real binary on fixtures/ci/.
//!
//! Golden outputs are insta snapshots in tests/snapshots/. When a message or a rule changes on
//! purpose, `INSTA_UPDATE=always cargo test --test ci` rewrites them; review the diff.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn project() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/ci/project")
}

/// The binary, run in `dir`, with the environment that steers colour removed.
fn velvet_in(dir: &Path, args: &[&str]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_velvet"));
    cmd.current_dir(dir).args(args);
    for var in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE", "TERM", "CI"] {
        cmd.env_remove(var);
    }
    cmd.output().expect("velvet runs")
}

fn velvet(args: &[&str]) -> Output {
    velvet_in(&project(), args)
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("UTF-8 output")
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("UTF-8 output")
}

const INPUTS: [&str; 2] = ["assets", "nested"];

fn validate(format: &str) -> Output {
    let mut args = vec!["validate", "--color", "never", "--format", format];
    args.extend(INPUTS);
    velvet(&args)
}

// ---------------------------------------------------------------- golden output per format

#[test]
fn text_output_is_golden() {
    let o = validate("text");
    assert_eq!(o.status.code(), Some(1));
    insta::assert_snapshot!("text", stdout(&o));
}

#[test]
fn json_output_is_golden() {
    let o = validate("json");
    assert_eq!(o.status.code(), Some(1));
    insta::assert_snapshot!("json", stdout(&o));
}

#[test]
fn jsonl_output_is_golden() {
    let o = validate("jsonl");
    assert_eq!(o.status.code(), Some(1));
    insta::assert_snapshot!("jsonl", stdout(&o));
}

#[test]
fn sarif_output_is_golden() {
    let o = validate("sarif");
    assert_eq!(o.status.code(), Some(1));
    // The rule list and rule indices follow the code registry, checked rule by rule in
    // `sarif_meets_github_code_scanning_requirements`; leaving them out keeps this snapshot
    // about the results when codes are added.
    let mut log: Value = serde_json::from_str(&stdout(&o)).unwrap();
    log["runs"][0]["tool"]["driver"]["rules"] =
        Value::String("one rule per registered code".into());
    for r in log["runs"][0]["results"].as_array_mut().unwrap() {
        r["ruleIndex"] = Value::String("the index of ruleId in rules".into());
    }
    let shown = serde_json::to_string_pretty(&log).unwrap();
    insta::assert_snapshot!("sarif", shown);
}

#[test]
fn github_output_is_golden() {
    let o = validate("github");
    assert_eq!(o.status.code(), Some(1));
    insta::assert_snapshot!("github", stdout(&o));
}

#[test]
fn coloured_text_output_is_golden() {
    let o = velvet(&["validate", "--color", "always", "assets/mixed.gltf"]);
    insta::assert_snapshot!("text_color", stdout(&o));
}

// ---------------------------------------------------------------- SARIF

fn sarif_log() -> Value {
    serde_json::from_str(&stdout(&validate("sarif"))).expect("SARIF is JSON")
}

#[test]
fn sarif_validates_against_the_sarif_2_1_0_schema() {
    let schema_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/ci/sarif-schema-2.1.0.json");
    let schema: Value = serde_json::from_slice(&std::fs::read(schema_path).unwrap()).unwrap();
    let validator = jsonschema::validator_for(&schema).expect("the SARIF schema compiles");
    let log = sarif_log();
    let errors: Vec<String> = validator
        .iter_errors(&log)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    // The schema check can fail: a result without its message is rejected.
    let mut broken = log.clone();
    broken["runs"][0]["results"][0]
        .as_object_mut()
        .unwrap()
        .remove("message");
    assert!(!validator.is_valid(&broken));
}

#[test]
fn sarif_meets_github_code_scanning_requirements() {
    let log = sarif_log();
    assert_eq!(log["version"], "2.1.0");
    let run = &log["runs"][0];
    let driver = &run["tool"]["driver"];
    assert_eq!(driver["name"], "velvet");
    let rules = driver["rules"].as_array().unwrap();
    let registry = velvet::diagnostics::all_codes();
    assert_eq!(rules.len(), registry.len(), "one rule per registered code");
    for (rule, code) in rules.iter().zip(&registry) {
        assert_eq!(rule["id"], code.name);
        assert_eq!(rule["shortDescription"]["text"], code.doc);
        assert_eq!(
            rule["defaultConfiguration"]["level"],
            velvet::report::sarif::level(code.severity)
        );
    }
    let results = run["results"].as_array().unwrap();
    assert!(!results.is_empty());
    for r in results {
        let index = r["ruleIndex"].as_u64().unwrap() as usize;
        assert_eq!(
            rules[index]["id"], r["ruleId"],
            "ruleIndex points at the result's rule"
        );
        assert!(["error", "warning", "note"].contains(&r["level"].as_str().unwrap()));
        assert!(!r["message"]["text"].as_str().unwrap().is_empty());
        let locations = r["locations"].as_array().unwrap();
        assert_eq!(locations.len(), 1);
        let uri = locations[0]["physicalLocation"]["artifactLocation"]["uri"]
            .as_str()
            .unwrap();
        assert!(
            !uri.contains(':') && !uri.starts_with('/') && !uri.split('/').any(|s| s == ".."),
            "{uri} is relative to the checkout"
        );
        assert!(r["properties"]["pointer"].is_string());
    }
}

/// The JSON text of the value a pointer names starts with this byte.
fn first_byte(value: &Value) -> u8 {
    serde_json::to_string(value).unwrap().as_bytes()[0]
}

#[test]
fn sarif_regions_point_at_the_named_values_in_gltf_and_glb() {
    let log = sarif_log();
    let mut gltf_regions = 0;
    let mut glb_regions = 0;
    for r in log["runs"][0]["results"].as_array().unwrap() {
        let physical = &r["locations"][0]["physicalLocation"];
        let uri = physical["artifactLocation"]["uri"].as_str().unwrap();
        let pointer = r["properties"]["pointer"].as_str().unwrap();
        let bytes = std::fs::read(project().join(uri)).unwrap();
        let region = &physical["region"];
        if uri.ends_with(".glb") {
            let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            let doc: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
            let Some(value) = doc.pointer(pointer).filter(|_| !pointer.is_empty()) else {
                continue;
            };
            let offset = region["byteOffset"]
                .as_u64()
                .expect("a .glb region has byteOffset") as usize;
            assert_eq!(
                region["startLine"], 1,
                "GitHub requires a line; a .glb has one"
            );
            assert_eq!(bytes[offset], first_byte(value), "{uri} {pointer}");
            glb_regions += 1;
        } else {
            let text = String::from_utf8(bytes).unwrap();
            let doc: Value = serde_json::from_str(&text).unwrap();
            let Some(value) = doc.pointer(pointer).filter(|_| !pointer.is_empty()) else {
                continue;
            };
            let line = region["startLine"].as_u64().unwrap() as usize;
            let column = region["startColumn"].as_u64().unwrap() as usize;
            let at: String = text
                .lines()
                .nth(line - 1)
                .unwrap()
                .chars()
                .skip(column - 1)
                .collect();
            assert_eq!(
                at.as_bytes()[0],
                first_byte(value),
                "{uri} {pointer} at {line}:{column}"
            );
            gltf_regions += 1;
        }
    }
    assert!(
        gltf_regions >= 3 && glb_regions >= 3,
        "{gltf_regions} .gltf and {glb_regions} .glb regions checked"
    );
}

#[test]
fn sarif_columns_count_characters_after_non_ascii_text() {
    // Minified: the material's name with multi-byte characters stands on the value's line.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("a.gltf"),
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_sheen\"],\"materials\":[{\"name\":\"ü–ü\",\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,1,1],\"x\":1}}}]}",
    )
    .unwrap();
    let o = velvet_in(dir.path(), &["validate", "--format", "sarif", "a.gltf"]);
    let log: Value = serde_json::from_slice(&o.stdout).unwrap();
    let result = log["runs"][0]["results"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["ruleId"] == "UNEXPECTED_PROPERTY")
        .expect("the unknown property is reported");
    assert_eq!(
        result["properties"]["pointer"],
        "/materials/0/extensions/KHR_materials_sheen/x"
    );
    // Before the value: 167 bytes but 163 characters ('ü' twice and '–' take 7 bytes for 3).
    assert_eq!(
        result["locations"][0]["physicalLocation"]["region"]["startColumn"],
        164
    );
    assert_eq!(log["runs"][0]["columnKind"], "unicodeCodePoints");
}

#[test]
fn truncation_is_reported_in_github_and_sarif_output() {
    let o = velvet(&[
        "validate",
        "--format",
        "github",
        "--max-issues",
        "1",
        "assets/mixed.gltf",
    ]);
    assert_eq!(
        stdout(&o),
        "::error file=assets/mixed.gltf,line=18,col=31,title=UNDECLARED_EXTENSION::KHR_materials_fuzz is used but not declared in extensionsUsed \
         (at /materials/1/extensions/KHR_materials_fuzz)\n\
         ::notice file=assets/mixed.gltf,title=velvet::5 more issues not shown (--max-issues)\n"
    );
    let o = velvet(&[
        "validate",
        "--format",
        "sarif",
        "--max-issues",
        "1",
        "assets/mixed.gltf",
    ]);
    let log: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(log["runs"][0]["results"].as_array().unwrap().len(), 1);
    let notes = &log["runs"][0]["invocations"][0]["toolExecutionNotifications"];
    assert_eq!(
        notes[0]["message"]["text"],
        "5 more issues not shown (--max-issues)"
    );
    assert_eq!(
        notes[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
        "assets/mixed.gltf"
    );
}

// ---------------------------------------------------------------- GitHub workflow commands

#[test]
fn github_commands_have_one_line_per_finding_with_escaped_properties() {
    let o = validate("github");
    let line = regex::Regex::new(
        r"^::(error|warning|notice) file=[^,:%]+(,line=\d+,col=\d+)?,title=[A-Z0-9_]+::[^\r\n]+$",
    )
    .unwrap();
    let text = stdout(&o);
    for l in text.lines() {
        assert!(line.is_match(l), "{l}");
    }
    let json: Value = serde_json::from_str(&stdout(&validate("json"))).unwrap();
    let findings: usize = json
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["issues"]["messages"].as_array().unwrap().len())
        .sum();
    assert_eq!(text.lines().count(), findings);
}

#[test]
fn github_escapes_a_file_name_with_comma_colon_and_percent() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        project().join("assets/mixed.gltf"),
        dir.path().join("a,b:c%d.gltf"),
    )
    .unwrap();
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "--format",
            "github",
            "--only",
            "UNRESOLVED_REFERENCE",
            "a,b:c%d.gltf",
        ],
    );
    assert_eq!(
        stdout(&o),
        "::error file=a%2Cb%3Ac%25d.gltf,line=10,col=43,title=UNRESOLVED_REFERENCE::\
         sheenColorTexture names texture 5, but the asset has 0 textures \
         (at /materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index)\n"
    );
}

// ---------------------------------------------------------------- configuration

fn json_reports(args: &[&str]) -> (Option<i32>, Vec<Value>) {
    let mut all = vec!["validate", "--format", "jsonl"];
    all.extend(args);
    let o = velvet(&all);
    let reports = stdout(&o)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (o.status.code(), reports)
}

fn severity_of(report: &Value, code: &str) -> Option<u64> {
    report["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["code"] == code)
        .map(|m| m["severity"].as_u64().unwrap())
}

#[test]
fn severity_override_command_line_beats_file_beats_default() {
    // Default: UNEXPECTED_PROPERTY is a warning (1). Under an empty config file: still 1.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("empty.toml"), "").unwrap();
    let empty = dir.path().join("empty.toml");
    let (_, r) = json_reports(&["--config", empty.to_str().unwrap(), "assets/mixed.gltf"]);
    assert_eq!(severity_of(&r[0], "UNEXPECTED_PROPERTY"), Some(1));
    // The project's velvet.toml overrides it to info (2).
    let (_, r) = json_reports(&["assets/mixed.gltf"]);
    assert_eq!(severity_of(&r[0], "UNEXPECTED_PROPERTY"), Some(2));
    // The command line overrides the file.
    let (_, r) = json_reports(&[
        "--override",
        "UNEXPECTED_PROPERTY=hint",
        "assets/mixed.gltf",
    ]);
    assert_eq!(severity_of(&r[0], "UNEXPECTED_PROPERTY"), Some(3));
}

#[test]
fn max_issues_command_line_beats_file_beats_default() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("v.toml"), "").unwrap();
    let cfg = dir.path().join("v.toml");
    let count = |r: &Value| {
        (
            r["issues"]["messages"].as_array().unwrap().len(),
            r["issues"]["truncated"].as_bool().unwrap(),
        )
    };
    let (_, r) = json_reports(&["--config", cfg.to_str().unwrap(), "assets/mixed.gltf"]);
    let all = count(&r[0]).0;
    assert!(all >= 4, "mixed.gltf has {all} findings");
    assert_eq!(count(&r[0]), (all, false));
    std::fs::write(&cfg, "max-issues = 3\n").unwrap();
    let (_, r) = json_reports(&["--config", cfg.to_str().unwrap(), "assets/mixed.gltf"]);
    assert_eq!(count(&r[0]), (3, true));
    let (_, r) = json_reports(&[
        "--config",
        cfg.to_str().unwrap(),
        "--max-issues",
        "1",
        "assets/mixed.gltf",
    ]);
    assert_eq!(count(&r[0]), (1, true));
    let (_, r) = json_reports(&[
        "--config",
        cfg.to_str().unwrap(),
        "--max-issues",
        "0",
        "assets/mixed.gltf",
    ]);
    assert_eq!(count(&r[0]), (all, false), "0 lifts the file's limit");
}

#[test]
fn nearest_velvet_toml_wins_and_fail_on_command_line_beats_file() {
    // nested/velvet.toml ignores VALUE_NOT_IN_RANGE and fails on warnings; the project's
    // override (UNEXPECTED_PROPERTY → info) does not reach it.
    let (code, r) = json_reports(&["nested/minified.gltf"]);
    assert_eq!(severity_of(&r[0], "VALUE_NOT_IN_RANGE"), None);
    assert_eq!(severity_of(&r[0], "UNEXPECTED_PROPERTY"), Some(1));
    assert_eq!(code, Some(1), "fail-on = warning from nested/velvet.toml");
    let (code, _) = json_reports(&["--fail-on", "error", "nested/minified.gltf"]);
    assert_eq!(code, Some(0), "--fail-on error beats the file");
    // --config replaces discovery: the project's file applies to nested/ too.
    let (code, r) = json_reports(&["--config", "velvet.toml", "nested/minified.gltf"]);
    assert_eq!(severity_of(&r[0], "VALUE_NOT_IN_RANGE"), Some(0));
    assert_eq!(severity_of(&r[0], "UNEXPECTED_PROPERTY"), Some(2));
    assert_eq!(code, Some(1));
}

#[test]
fn command_line_only_replaces_the_files_ignore() {
    let (_, r) = json_reports(&["--only", "VALUE_NOT_IN_RANGE", "nested/minified.gltf"]);
    let codes: Vec<&str> = r[0]["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["code"].as_str().unwrap())
        .collect();
    assert_eq!(codes, ["VALUE_NOT_IN_RANGE"]);
}

#[test]
fn excluded_files_are_skipped_when_walked_and_when_named() {
    let (_, r) = json_reports(&["assets"]);
    let uris: Vec<&str> = r.iter().map(|r| r["uri"].as_str().unwrap()).collect();
    assert_eq!(
        uris,
        ["assets/clean.gltf", "assets/mixed.glb", "assets/mixed.gltf"]
    );
    let (code, r) = json_reports(&["assets/drafts/wip.gltf", "assets/clean.gltf"]);
    assert_eq!(r.len(), 1);
    assert_eq!(r[0]["uri"], "assets/clean.gltf");
    assert_eq!(code, Some(0));
}

#[test]
fn unknown_key_in_velvet_toml_is_a_configuration_error_naming_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        project().join("assets/clean.gltf"),
        dir.path().join("a.gltf"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("velvet.toml"),
        "max-issues = 3\nignored = [\"TYPE_MISMATCH\"]\n",
    )
    .unwrap();
    let o = velvet_in(dir.path(), &["validate", "a.gltf"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    let err = stderr(&o);
    assert!(err.starts_with("velvet: "), "{err}");
    assert!(
        err.contains("velvet.toml: line 2, column 1: unknown key `ignored`, expected one of"),
        "{err}"
    );
}

#[test]
fn bad_command_line_settings_exit_2() {
    let o = velvet(&[
        "validate",
        "--override",
        "UNEXPECTED_PROPERTY=loud",
        "assets",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "velvet: --override UNEXPECTED_PROPERTY=loud: loud is not a severity (error, warning, info, hint or 0-3)\n"
    );
    let o = velvet(&["validate", "--ignore", "NOPE", "assets"]);
    assert_eq!(
        stderr(&o),
        "velvet: --ignore: no such code NOPE (`velvet codes` lists them)\n"
    );
    assert_eq!(o.status.code(), Some(2));
    let o = velvet(&[
        "validate",
        "--ignore",
        "TYPE_MISMATCH",
        "--only",
        "TYPE_MISMATCH",
        "assets",
    ]);
    assert_eq!(o.status.code(), Some(2), "clap rejects the conflict");
}

#[test]
fn config_command_prints_the_effective_configuration_with_sources() {
    let o = velvet(&["config", "assets/mixed.gltf"]);
    assert_eq!(o.status.code(), Some(0));
    insta::assert_snapshot!("config_project", stdout(&o));
    let o = velvet(&[
        "config",
        "nested",
        "--max-issues",
        "4",
        "--override",
        "TYPE_MISMATCH=1",
    ]);
    insta::assert_snapshot!("config_nested_with_flags", stdout(&o));
    let o = velvet(&["config", "assets/drafts/wip.gltf"]);
    assert!(stdout(&o).starts_with("# assets/drafts/wip.gltf is excluded by this configuration\n"));
}

#[test]
fn config_command_without_any_file_shows_defaults() {
    let dir = tempfile::tempdir().unwrap();
    let o = velvet_in(dir.path(), &["config"]);
    let text = stdout(&o);
    // A velvet.toml above the temporary folder would be found; there is none on a clean machine.
    if text.starts_with("# no velvet.toml") {
        assert_eq!(
            text,
            "# no velvet.toml in force: built-in defaults and the command line\n\
             max-issues = 0  # default (0: no limit)\n\
             ignore = []  # default\n\
             fail-on = \"error\"  # default\n\
             exclude = []  # default\n\
             \n[override]\n"
        );
    }
}

// ---------------------------------------------------------------- pre-commit hook

#[derive(serde::Deserialize)]
struct Hook {
    id: String,
    entry: String,
    language: String,
    files: String,
}

fn hooks() -> Vec<Hook> {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join(".pre-commit-hooks.yaml"),
    )
    .unwrap();
    serde_yaml_ng::from_str(&text).expect(".pre-commit-hooks.yaml parses")
}

/// Every file below `dir`, relative to it, sorted (as `git ls-files` lists a checkout).
fn all_files(dir: &Path) -> Vec<String> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(
                    p.strip_prefix(base)
                        .unwrap()
                        .to_string_lossy()
                        .replace('\\', "/"),
                );
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Runs a hook's entry as pre-commit does: the files its `files` pattern selects, passed as
/// arguments after the entry, in batches; the hook fails when any batch exits non-zero.
fn run_hook(hook: &Hook, dir: &Path, batch: usize) -> (bool, String) {
    let pattern = regex::Regex::new(&hook.files).unwrap();
    let files: Vec<String> = all_files(dir)
        .into_iter()
        .filter(|f| pattern.is_match(f))
        .collect();
    let words: Vec<&str> = hook.entry.split_whitespace().collect();
    assert_eq!(words[0], "velvet");
    let mut ok = true;
    let mut output = String::new();
    for chunk in files.chunks(batch) {
        let mut args: Vec<&str> = words[1..].to_vec();
        args.extend(chunk.iter().map(String::as_str));
        let o = velvet_in(dir, &args);
        ok &= o.status.success();
        output += &stdout(&o);
    }
    (ok, output)
}

#[test]
fn hooks_file_declares_both_hooks_for_gltf_and_glb() {
    let hooks = hooks();
    let ids: Vec<&str> = hooks.iter().map(|h| h.id.as_str()).collect();
    assert_eq!(ids, ["velvet-validate", "velvet-migrate-check"]);
    assert_eq!(hooks[0].entry, "velvet validate");
    assert_eq!(hooks[1].entry, "velvet migrate --check");
    for h in &hooks {
        assert_eq!(h.language, "rust");
        let p = regex::Regex::new(&h.files).unwrap();
        assert!(p.is_match("a/b.gltf") && p.is_match("b.glb"));
        assert!(!p.is_match("a.gltf.bak") && !p.is_match("a.bin") && !p.is_match("velvet.toml"));
    }
}

#[test]
fn validate_hook_fails_on_the_fixture_project_and_passes_on_clean_files() {
    let hook = hooks()
        .into_iter()
        .find(|h| h.id == "velvet-validate")
        .unwrap();
    // The whole project, one file per batch and all files in one batch, agree.
    let (ok_single, out_single) = run_hook(&hook, &project(), 1);
    let (ok_all, out_all) = run_hook(&hook, &project(), 100);
    assert!(!ok_single && !ok_all);
    for out in [&out_single, &out_all] {
        assert!(
            out.contains("assets/mixed.gltf:10:43: error UNRESOLVED_REFERENCE"),
            "{out}"
        );
        assert!(out.contains("assets/mixed.glb: byte "), "{out}");
        assert!(
            !out.contains("drafts/wip.gltf"),
            "excluded by velvet.toml although named: {out}"
        );
    }
    // A checkout holding only clean assets passes.
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("models")).unwrap();
    std::fs::copy(
        project().join("assets/clean.gltf"),
        dir.path().join("models/clean.gltf"),
    )
    .unwrap();
    std::fs::write(dir.path().join("models/notes.txt"), "not an asset").unwrap();
    let (ok, out) = run_hook(&hook, dir.path(), 4);
    assert!(ok, "{out}");
    assert_eq!(
        out,
        "1 file checked: 0 errors, 0 warnings, 0 info, 0 hints\n"
    );
}

/// The bytes of every file below `dir`, to show that a hook left them as they were.
fn snapshot_tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    all_files(dir)
        .into_iter()
        .map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap()))
        .collect()
}

#[test]
fn migrate_check_hook_fails_when_a_file_would_change_and_writes_nothing() {
    let hook = hooks()
        .into_iter()
        .find(|h| h.id == "velvet-migrate-check")
        .unwrap();
    // The project has sheen without fuzz (clean.gltf) and fuzz without a fallback (mixed.gltf).
    let before = snapshot_tree(&project());
    let (ok, out) = run_hook(&hook, &project(), 100);
    assert!(!ok, "{out}");
    assert_eq!(snapshot_tree(&project()), before, "a check writes nothing");
    // A checkout whose assets already carry fuzz with a sheen fallback passes.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/ci/migrated/both.gltf"),
        dir.path().join("both.gltf"),
    )
    .unwrap();
    let (ok, out) = run_hook(&hook, dir.path(), 100);
    assert!(ok, "{out}");
}

// ---------------------------------------------------------------- terminal behaviour

const ESC: &str = "\u{1b}[";

#[test]
fn colour_follows_the_flag_no_color_and_the_terminal() {
    let run = |flag: &str, env: &[(&str, &str)]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_velvet"));
        cmd.current_dir(project())
            .args(["validate", "--color", flag, "assets/mixed.gltf"]);
        for var in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE", "TERM", "CI"] {
            cmd.env_remove(var);
        }
        cmd.envs(env.iter().copied());
        String::from_utf8(cmd.output().unwrap().stdout).unwrap()
    };
    assert!(run("always", &[]).contains(ESC));
    assert!(
        run("always", &[("NO_COLOR", "1")]).contains(ESC),
        "an explicit flag beats NO_COLOR"
    );
    assert!(!run("never", &[("CLICOLOR_FORCE", "1")]).contains(ESC));
    assert!(!run("auto", &[]).contains(ESC), "a pipe is not a terminal");
    assert!(run("auto", &[("CLICOLOR_FORCE", "1")]).contains(ESC));
    assert!(
        !run("auto", &[("CLICOLOR_FORCE", "1"), ("NO_COLOR", "1")]).contains(ESC),
        "NO_COLOR wins in auto"
    );
    assert!(!run("always", &[]).replace(ESC, "").is_empty());
}

#[test]
fn machine_formats_never_carry_colour() {
    for format in ["json", "jsonl", "sarif", "github"] {
        let o = velvet(&[
            "validate", "--color", "always", "--format", format, "assets",
        ]);
        assert!(!stdout(&o).contains(ESC), "{format}");
    }
}

#[test]
fn quiet_prints_findings_only_and_nothing_for_clean_files() {
    let o = velvet(&["validate", "--quiet", "assets/clean.gltf"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.is_empty() && o.stderr.is_empty());
    let loud = stdout(&velvet(&["validate", "assets/mixed.gltf"]));
    let quiet = stdout(&velvet(&["validate", "-q", "assets/mixed.gltf"]));
    let summary = loud.lines().last().unwrap();
    assert!(summary.starts_with("1 file checked: "));
    assert_eq!(quiet, loud.strip_suffix(&format!("{summary}\n")).unwrap());
}

#[test]
fn no_progress_bar_when_standard_error_is_not_a_terminal() {
    let o = velvet(&["validate", "assets", "nested"]);
    assert!(o.stderr.is_empty(), "{}", stderr(&o));
}

#[test]
fn help_documents_the_exit_status() {
    let top = stdout(&velvet(&["--help"]));
    assert!(
        top.contains(
            "Exit status:\n  0  success: no file has an issue at or above --fail-on (validate)"
        ),
        "{top}"
    );
    let validate = stdout(&velvet(&["validate", "--help"]));
    assert!(
        validate.contains("Exit status:\n  0  no file has an issue at or above --fail-on\n"),
        "{validate}"
    );
    for text in [&top, &validate] {
        assert!(text.contains("  2  usage or configuration error"), "{text}");
    }
}

#[test]
fn completions_for_each_shell_name_the_subcommands_and_flags() {
    // Each shell's own way of declaring the completion, and of naming `--format sarif`.
    let markers = [
        ("bash", "complete -F _velvet", "sarif"),
        ("zsh", "#compdef velvet", "sarif"),
        ("fish", "complete -c velvet", "sarif"),
        ("powershell", "Register-ArgumentCompleter", "--format"),
    ];
    for (shell, marker, format) in markers {
        let o = velvet(&["completions", shell]);
        assert_eq!(o.status.code(), Some(0));
        let text = stdout(&o);
        assert!(text.contains(marker), "{shell}");
        for word in [
            "validate",
            "config",
            "completions",
            "fail-on",
            "override",
            format,
        ] {
            assert!(text.contains(word), "{shell} completion lacks {word}");
        }
    }
    assert_eq!(velvet(&["completions", "tcsh"]).status.code(), Some(2));
}

#[test]
fn man_page_renders_and_writes_one_page_per_command() {
    let o = velvet(&["man"]);
    let page = stdout(&o);
    assert!(page.contains(".TH velvet 1"), "{page}");
    assert!(
        page.contains(".SH SUBCOMMANDS") && page.contains("velvet\\-validate(1)"),
        "{page}"
    );
    assert!(
        page.contains(".SH \"EXIT STATUS\"\n.TP\n\\fB0\\fR\nsuccess: "),
        "{page}"
    );
    let dir = tempfile::tempdir().unwrap();
    let o = velvet_in(dir.path(), &["man", "--dir", "pages"]);
    assert_eq!(o.status.code(), Some(0));
    let mut names: Vec<String> = std::fs::read_dir(dir.path().join("pages"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for expected in [
        "velvet.1",
        "velvet-validate.1",
        "velvet-config.1",
        "velvet-codes.1",
        "velvet-completions.1",
        "velvet-man.1",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} in {names:?}"
        );
    }
    let validate_page =
        std::fs::read_to_string(dir.path().join("pages/velvet-validate.1")).unwrap();
    assert!(
        validate_page.contains("\\-\\-format") && validate_page.contains(".SH \"EXIT STATUS\"")
    );
}
