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
    let registry = velvet::rules::all_codes();
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

/// Each rule carries what a SARIF viewer shows beside an alert: the code's meaning, its help
/// (meaning, default severity, how --fix repairs it) and, once Cargo.toml names the repository,
/// a link to the codes table.
#[test]
fn sarif_rules_carry_full_descriptions_help_and_a_help_uri_only_with_a_named_repository() {
    let log = sarif_log();
    let rules = log["runs"][0]["tool"]["driver"]["rules"]
        .as_array()
        .unwrap();
    let registry = velvet::rules::all_codes();
    assert_eq!(rules.len(), registry.len());
    for (rule, code) in rules.iter().zip(&registry) {
        let text = |v: &Value| v.as_str().unwrap_or_default().to_string();
        assert_eq!(text(&rule["fullDescription"]["text"]), code.doc);
        let help = text(&rule["help"]["text"]);
        let markdown = text(&rule["help"]["markdown"]);
        assert!(!help.is_empty() && !markdown.is_empty(), "{rule}");
        let severity = format!("Default severity: {}.", code.severity.as_str());
        for h in [&help, &markdown] {
            assert!(h.contains(code.doc), "{h}");
            assert!(h.contains(&severity), "{h}");
            let says_fix = match velvet::fix::fixers::fixer_for(code.name) {
                Some(fixer) => h.contains(fixer.about) && h.contains("repairs it"),
                None => h.contains("does not repair it"),
            };
            assert!(says_fix, "{}: {h}", code.name);
        }
        // Cargo.toml names no repository yet: no link that may lead nowhere, and the
        // help points at `velvet codes` instead.
        assert_eq!(rule.get("helpUri"), None);
        assert!(markdown.ends_with("`velvet codes` lists every code; docs/codes.md explains them."));
    }
    assert_eq!(
        velvet::report::sarif::codes_table_url_in("https://example.org/team/velvet.git/"),
        Some("https://example.org/team/velvet/blob/main/docs/codes.md#codes".to_string())
    );
    assert_eq!(velvet::report::sarif::codes_table_url_in(" "), None);
    // The anchor the link names is in docs/codes.md, before the table.
    let codes_md =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/codes.md"))
            .unwrap();
    assert!(codes_md.contains("<a id=\"codes\"></a>\n<!-- codes:start -->"));
    let fixed = rules
        .iter()
        .find(|r| r["id"] == "KHR_MATERIALS_FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS")
        .unwrap();
    assert_eq!(
        fixed["help"]["text"],
        "KHR_MATERIALS_FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS: ".to_string()
            + fixed["fullDescription"]["text"].as_str().unwrap()
            + "\nDefault severity: hint.\nvelvet validate --fix repairs it (a safe fix): it \
               writes fuzzRoughnessFactor 0.5, the value velvet assumes."
    );
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

/// What validate says of fixtures/ci/project/assets/drafts/wip.gltf named on its command line.
fn skipped_note() -> String {
    format!(
        "velvet: assets/drafts/wip.gltf: skipped, excluded by the exclude patterns of {}\n",
        project().join("velvet.toml").display()
    )
}

/// pre-commit names the staged files one by one: those velvet.toml excludes are skipped, each
/// said on standard error, and a run left with nothing passes.
#[test]
fn an_excluded_file_named_alone_is_skipped_with_a_note_and_passes() {
    let o = velvet(&["validate", "assets/drafts/wip.gltf"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        stdout(&o),
        "0 files checked: 0 errors, 0 warnings, 0 info, 0 hints\n"
    );
    assert_eq!(stderr(&o), skipped_note());
    // Named beside a file that is checked: the same note, the other file's report.
    let o = velvet(&[
        "validate",
        "--format",
        "jsonl",
        "assets/drafts/wip.gltf",
        "assets/clean.gltf",
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(stderr(&o), skipped_note());
    assert_eq!(stdout(&o).lines().count(), 1);
    // A list (`--files-from`, as `git diff --name-only` writes it) names files as the command
    // line does.
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("staged.txt");
    std::fs::write(&list, "assets/drafts/wip.gltf\n").unwrap();
    let o = velvet(&["validate", "--files-from", list.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), skipped_note());
}

/// A folder whose every asset is excluded stays a usage error: a typo'd pattern must not
/// turn the gate off, even when the folder is named beside an excluded file.
#[test]
fn a_folder_whose_every_file_is_excluded_still_exits_2() {
    // The count is of files found: the folder's file, and the same file named again.
    for (args, found) in [
        (vec!["validate", "assets/drafts"], 1),
        (
            vec!["validate", "assets/drafts", "assets/drafts/wip.gltf"],
            2,
        ),
    ] {
        let o = velvet(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert_eq!(stdout(&o), "", "{args:?}");
        assert_eq!(
            stderr(&o),
            format!(
                "velvet: no asset left to check: {found} found, all excluded by the exclude \
                 patterns of {}; a run that checks nothing fails\n",
                project().join("velvet.toml").display()
            ),
            "{args:?}"
        );
    }
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
fn config_command_refuses_a_path_that_does_not_exist() {
    let o = velvet(&["config", "assets/missing.gltf"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stdout(&o), "");
    assert_eq!(
        stderr(&o),
        "velvet: assets/missing.gltf: no such file or folder\n"
    );
    // The same words validate uses for it.
    let o = velvet(&["validate", "assets/missing.gltf"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "velvet: assets/missing.gltf: no such file or folder\n"
    );
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
             data = true  # default\n\
             fail-on-visible = false  # default (migrate --check)\n\
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
fn hooks_file_declares_every_hook_for_gltf_and_glb() {
    let hooks = hooks();
    let ids: Vec<&str> = hooks.iter().map(|h| h.id.as_str()).collect();
    assert_eq!(
        ids,
        [
            "velvet-validate",
            "velvet-migrate-check",
            "velvet-validate-fix"
        ]
    );
    assert_eq!(hooks[0].entry, "velvet validate");
    assert_eq!(hooks[1].entry, "velvet migrate --check");
    assert_eq!(
        hooks[2].entry,
        "velvet validate --fix --exit-non-zero-on-fix"
    );
    for h in &hooks {
        assert_eq!(h.language, "rust");
        let p = regex::Regex::new(&h.files).unwrap();
        assert!(p.is_match("a/b.gltf") && p.is_match("b.glb"));
        assert!(p.is_match("UPPER.GLTF") && p.is_match("a/Mixed.Glb"));
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
            "Exit status:\n  0  validate: no file has an issue at or above --fail-on (with --fix: none is left after fixing); migrate, bake: "
        ),
        "{top}"
    );
    let validate = stdout(&velvet(&["validate", "--help"]));
    assert!(
        validate.contains(
            "Exit status:\n  0  no file has an issue at or above --fail-on (with --fix: none is left after fixing)\n"
        ),
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
        page.contains(".SH \"EXIT STATUS\"\n.TP\n\\fB0\\fR\nvalidate: no file has an issue"),
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
    // Every page the printed page lists under SUBCOMMANDS is one --dir writes.
    let listed: Vec<String> = page
        .lines()
        .filter_map(|l| l.strip_prefix("velvet\\-")?.strip_suffix("(1)"))
        .map(|name| format!("velvet-{name}.1"))
        .collect();
    assert_eq!(listed.len(), 8, "{listed:?}");
    for name in &listed {
        assert!(
            names.contains(name),
            "{name} is listed but not written: {names:?}"
        );
    }
    let validate_page =
        std::fs::read_to_string(dir.path().join("pages/velvet-validate.1")).unwrap();
    assert!(
        validate_page.contains("\\-\\-format") && validate_page.contains(".SH \"EXIT STATUS\"")
    );
}

// ---------------------------------------------------------------- at scale: shards and lists

/// A library of `n` generated assets in nested folders, of different sizes (padding in
/// extras), names in mixed case, about half with findings (a switched-off sheen that is
/// textured, an unknown property, a legacy draft property), and a file that is not an asset.
fn library(dir: &Path, n: usize) {
    for i in 0..n {
        let folder = dir
            .join(format!("set{}", i % 3))
            .join(format!("part{}", i % 2));
        std::fs::create_dir_all(&folder).unwrap();
        let sheen = match i % 4 {
            0 => r#""sheenColorFactor":[0.5,0.4,0.3]"#.to_string(),
            1 => format!(r#""sheenColorFactor":[0.5,0.4,0.3],"odd{i}":1"#),
            2 => r#""sheenColorFactor":[1,1,1],"sheenFactor":0.5"#.to_string(),
            _ => r#""sheenColorFactor":[0.2,0.2,0.2],"sheenRoughnessFactor":2"#.to_string(),
        };
        let text = format!(
            "{{\n  \"asset\": {{\"version\": \"2.0\"}},\n  \"extensionsUsed\": [\"KHR_materials_sheen\"],\n  \"materials\": [{{\"extensions\": {{\"KHR_materials_sheen\": {{{sheen}}}}}}}],\n  \"extras\": {{\"pad\": \"{}\"}}\n}}\n",
            "x".repeat((i * 7919) % 20_000)
        );
        let ext = if i % 5 == 0 { "GLTF" } else { "gltf" };
        std::fs::write(folder.join(format!("asset {i:02}.{ext}")), text).unwrap();
    }
    std::fs::write(dir.join("set0/readme.txt"), "not an asset").unwrap();
}

/// Reports of a `--format jsonl` run by file name relative to `base`, in output order.
fn jsonl_by_name(out: &str, base: &str) -> Vec<(String, Value)> {
    out.lines()
        .map(|l| {
            let mut report: Value = serde_json::from_str(l).unwrap();
            let uri = report["uri"].as_str().unwrap().to_string();
            let name = uri
                .strip_prefix(base)
                .unwrap_or_else(|| panic!("{uri} lies under {base}"))
                .trim_start_matches('/')
                .to_string();
            report["uri"] = Value::String(name.clone());
            (name, report)
        })
        .collect()
}

#[test]
fn four_shards_report_every_file_once_exactly_as_one_run_does() {
    let dir = tempfile::tempdir().unwrap();
    library(&dir.path().join("lib"), 30);
    let whole = velvet_in(dir.path(), &["validate", "--format", "jsonl", "lib"]);
    assert_eq!(whole.status.code(), Some(1), "the library has errors");
    let whole = jsonl_by_name(&stdout(&whole), "lib");
    assert_eq!(whole.len(), 30);
    let mut union: Vec<(String, Value)> = Vec::new();
    let mut bytes = Vec::new();
    for k in 1..=4 {
        let shard = format!("{k}/4");
        let o = velvet_in(
            dir.path(),
            &["validate", "--format", "jsonl", "--shard", &shard, "lib"],
        );
        assert!(o.status.code() == Some(0) || o.status.code() == Some(1));
        let part = jsonl_by_name(&stdout(&o), "lib");
        assert!(!part.is_empty(), "shard {shard} has files");
        // The same shard from another working directory, by an absolute path, holds the
        // same files: the split depends on paths below the argument, not on how it is named.
        let absolute = dir.path().join("lib");
        let elsewhere = velvet_in(
            &project(),
            &[
                "validate",
                "--format",
                "jsonl",
                "--shard",
                &shard,
                absolute.to_str().unwrap(),
            ],
        );
        let names = |r: &[(String, Value)]| r.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!(
            names(&jsonl_by_name(
                &stdout(&elsewhere),
                absolute.to_str().unwrap()
            )),
            names(&part),
            "shard {shard}"
        );
        bytes.push(
            part.iter()
                .map(|(n, _)| {
                    std::fs::metadata(dir.path().join("lib").join(n))
                        .unwrap()
                        .len()
                })
                .sum::<u64>(),
        );
        union.extend(part);
    }
    union.sort_by(|a, b| a.0.cmp(&b.0));
    let mut expected = whole.clone();
    expected.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        union, expected,
        "every file once, with the report of the single run"
    );
    // Balanced by bytes: no shard carries more than another plus the largest file and the
    // per-file allowance.
    let largest = whole
        .iter()
        .map(|(n, _)| {
            std::fs::metadata(dir.path().join("lib").join(n))
                .unwrap()
                .len()
        })
        .max()
        .unwrap();
    let (max, min) = (bytes.iter().max().unwrap(), bytes.iter().min().unwrap());
    assert!(max - min <= largest + 4096, "{bytes:?}, largest {largest}");
}

#[test]
fn shards_of_migrate_write_together_what_one_run_writes() {
    let dir = tempfile::tempdir().unwrap();
    library(&dir.path().join("lib"), 12);
    let o = velvet_in(dir.path(), &["migrate", "lib", "--out-dir", "one"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let o = velvet_in(
            dir.path(),
            &["migrate", "lib", "--out-dir", "sharded", "--shard", &shard],
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let one = snapshot_tree(&dir.path().join("one"));
    assert_eq!(one.len(), 12);
    assert_eq!(snapshot_tree(&dir.path().join("sharded")), one);
    // Bake's dry run over shards lists each file once.
    let mut listed = Vec::new();
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let o = velvet_in(
            dir.path(),
            &[
                "bake",
                "lib",
                "--dry-run",
                "--format",
                "json",
                "--shard",
                &shard,
            ],
        );
        let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
        for f in report["files"].as_array().unwrap() {
            listed.push(f["input"].as_str().unwrap().to_string());
        }
    }
    listed.sort();
    let mut all: Vec<String> = all_files(&dir.path().join("lib"))
        .into_iter()
        .filter(|f| !f.ends_with(".txt"))
        .map(|f| format!("lib/{f}"))
        .collect();
    all.sort();
    assert_eq!(listed, all);
}

#[test]
fn a_bad_shard_is_a_usage_error() {
    let o = velvet(&["validate", "--shard", "5/4", "assets"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("5/4: expected K/N with 1 <= K <= N, e.g. 2/4"),
        "{}",
        stderr(&o)
    );
}

/// Runs velvet in `dir` with `input` on standard input.
fn velvet_stdin(dir: &Path, args: &[&str], input: &[u8]) -> Output {
    use std::io::Write as _;
    let mut child = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .current_dir(dir)
        .args(args)
        .env_remove("NO_COLOR")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

#[test]
fn files_from_standard_input_takes_nul_separated_names_with_spaces_and_newlines() {
    let dir = tempfile::tempdir().unwrap();
    let clean = std::fs::read(project().join("assets/clean.gltf")).unwrap();
    std::fs::create_dir_all(dir.path().join("sub dir")).unwrap();
    for name in [
        "a b.gltf",
        "new\nline.gltf",
        "sub dir/c.GLTF",
        "unlisted.gltf",
    ] {
        std::fs::write(dir.path().join(name), &clean).unwrap();
    }
    std::fs::write(dir.path().join("notes.txt"), "not an asset").unwrap();
    // As `git diff --name-only -z` prints them: NUL after each, other files among them.
    let list = b"a b.gltf\0notes.txt\0new\nline.gltf\0deleted.txt\0sub dir/c.GLTF\0";
    let o = velvet_stdin(
        dir.path(),
        &["validate", "--format", "jsonl", "--files-from", "-"],
        list,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let uris: Vec<String> = stdout(&o)
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["uri"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    assert_eq!(uris, ["a b.gltf", "new\nline.gltf", "sub dir/c.GLTF"]);
    // One per line, from a file, with command-line paths besides.
    std::fs::write(dir.path().join("list.txt"), "a b.gltf\r\nsub dir\n").unwrap();
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "-q",
            "--files-from",
            "list.txt",
            "unlisted.gltf",
        ],
    );
    assert_eq!(o.status.code(), Some(0));
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "--format",
            "jsonl",
            "--files-from",
            "list.txt",
            "unlisted.gltf",
        ],
    );
    let uris: Vec<String> = stdout(&o)
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["uri"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    assert_eq!(uris, ["unlisted.gltf", "a b.gltf", "sub dir/c.GLTF"]);
    // A listed asset that does not exist is named; a list with no asset checks nothing and
    // passes (a change that touched no asset).
    let o = velvet_stdin(
        dir.path(),
        &["validate", "--files-from", "-"],
        b"gone.glb\n",
    );
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "velvet: --files-from -: gone.glb (entry 1) does not exist\n"
    );
    let o = velvet_stdin(
        dir.path(),
        &["validate", "--files-from", "-"],
        b"notes.txt\n",
    );
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        stdout(&o),
        "0 files checked: 0 errors, 0 warnings, 0 info, 0 hints\n"
    );
    // migrate and bake take lists too.
    let o = velvet_stdin(
        dir.path(),
        &[
            "migrate",
            "--dry-run",
            "--format",
            "json",
            "--files-from",
            "-",
        ],
        b"new\nline.gltf\0",
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["files"][0]["input"], "new\nline.gltf");
    assert_eq!(report["files"].as_array().unwrap().len(), 1);
    let o = velvet_stdin(
        dir.path(),
        &["bake", "--dry-run", "--format", "json", "--files-from", "-"],
        b"a b.gltf\n",
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["files"][0]["input"], "a b.gltf");
}

// ---------------------------------------------------------------- paths and exit status

#[test]
fn missing_paths_and_folders_without_assets_are_usage_errors_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("empty")).unwrap();
    std::fs::create_dir_all(dir.path().join("docs/deeper")).unwrap();
    std::fs::write(dir.path().join("docs/deeper/notes.txt"), "not an asset").unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["validate", "asets"], "asets: no such file or folder"),
        (
            &["validate", "empty"],
            "empty: no .gltf or .glb file in this folder or below",
        ),
        (
            &["validate", "docs"],
            "docs: no .gltf or .glb file in this folder or below",
        ),
        (
            &["migrate", "--dry-run", "nope.gltf"],
            "nope.gltf: no such file or folder",
        ),
        (
            &["bake", "--dry-run", "empty"],
            "empty: no .gltf or .glb file in this folder or below",
        ),
        (
            &["bake", "--dry-run", "nope"],
            "nope: no such file or folder",
        ),
    ];
    for (args, message) in cases {
        let o = velvet_in(dir.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert_eq!(stderr(&o), format!("velvet: {message}\n"), "{args:?}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn fail_on_hint_fails_a_file_whose_only_findings_are_hints() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("fuzz.gltf"),
        r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_fuzz"],"materials":[{"extensions":{"KHR_materials_fuzz":{"fuzzFactor":1}}}]}"#,
    )
    .unwrap();
    let status = |args: &[&str]| velvet_in(dir.path(), args).status.code();
    let o = velvet_in(dir.path(), &["validate", "fuzz.gltf"]);
    assert!(stdout(&o).ends_with(
        "1 file checked: 0 errors, 0 warnings, 0 info, 2 hints; 1 fixable with --fix\n"
    ));
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        status(&["validate", "--fail-on", "info", "fuzz.gltf"]),
        Some(0)
    );
    assert_eq!(
        status(&["validate", "--fail-on", "hint", "fuzz.gltf"]),
        Some(1)
    );
    std::fs::write(dir.path().join("velvet.toml"), "fail-on = \"hint\"\n").unwrap();
    assert_eq!(status(&["validate", "fuzz.gltf"]), Some(1));
    assert_eq!(
        status(&["validate", "--fail-on", "error", "fuzz.gltf"]),
        Some(0)
    );
}

#[test]
fn command_line_ignore_adds_to_the_files_ignore() {
    // nested/velvet.toml ignores VALUE_NOT_IN_RANGE; the command line adds UNEXPECTED_PROPERTY.
    let codes = |args: &[&str]| -> Vec<String> {
        let (_, r) = json_reports(args);
        let mut codes: Vec<String> = r[0]["issues"]["messages"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["code"].as_str().unwrap().to_string())
            .collect();
        codes.dedup();
        codes
    };
    let file_only = codes(&["nested/minified.gltf"]);
    assert!(
        file_only.contains(&"UNEXPECTED_PROPERTY".to_string()),
        "{file_only:?}"
    );
    assert!(!file_only.contains(&"VALUE_NOT_IN_RANGE".to_string()));
    let both = codes(&["--ignore", "UNEXPECTED_PROPERTY", "nested/minified.gltf"]);
    assert!(
        !both.contains(&"UNEXPECTED_PROPERTY".to_string()),
        "{both:?}"
    );
    assert!(
        !both.contains(&"VALUE_NOT_IN_RANGE".to_string()),
        "{both:?}"
    );
    let o = velvet(&["config", "nested", "--ignore", "UNEXPECTED_PROPERTY"]);
    assert!(stdout(&o).contains(
        "ignore = [\"UNEXPECTED_PROPERTY\", \"VALUE_NOT_IN_RANGE\"]  # velvet.toml and command line\n"
    ));
    let help = stdout(&velvet(&["validate", "--help"]));
    assert!(
        help.contains("adds to the codes velvet.toml ignores"),
        "{help}"
    );
}

#[test]
fn bench_is_not_in_the_users_help_and_runs_only_in_a_bench_build() {
    let help = stdout(&velvet(&["--help"]));
    assert!(!help.contains("bench"), "{help}");
    assert!(help.contains("validate") && help.contains("migrate") && help.contains("bake"));
    let o = velvet(&["bench", "--help"]);
    if cfg!(feature = "bench") {
        assert_eq!(o.status.code(), Some(0));
        assert!(stdout(&o).contains("accuracy"));
    } else {
        assert_eq!(o.status.code(), Some(2));
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("unrecognized subcommand 'bench'"),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

// ---------------------------------------------------------------- folded, ordered text output

#[test]
fn text_output_folds_a_repeated_finding_and_lists_findings_in_file_order() {
    let dir = tempfile::tempdir().unwrap();
    // The same unexpected property in eight sheen objects, one other unexpected property (the
    // same code, another message: not folded with them), a legacy draft property, and an
    // out-of-range roughness before them in the file.
    let others: Vec<String> = (1..8)
        .map(|i| format!("{{\"extensions\": {{\"KHR_materials_sheen\": {{\"odd\": {i}}}}}}}"))
        .collect();
    let text = format!(
        "{{\n\"asset\": {{\"version\": \"2.0\"}},\n\"extensionsUsed\": [\"KHR_materials_sheen\"],\n\"materials\": [{{\"extensions\": {{\"KHR_materials_sheen\": {{\n\"sheenRoughnessFactor\": 3,\n\"sheenFactor\": 1,\n\"odd\": 0,\n\"strange\": 0\n}}}}}},\n{}\n]\n}}\n",
        others.join(",\n")
    );
    std::fs::write(dir.path().join("many.gltf"), text).unwrap();
    let o = velvet_in(dir.path(), &["validate", "--color", "never", "many.gltf"]);
    assert_eq!(o.status.code(), Some(1));
    let p = "/materials/0/extensions/KHR_materials_sheen";
    assert_eq!(
        stdout(&o),
        format!(
            "many.gltf:5:25: error VALUE_NOT_IN_RANGE: 3 is greater than the maximum of 1.0\n    at {p}/sheenRoughnessFactor\n    fix (unsafe, --fix --unsafe-fixes): clamp sheenRoughnessFactor to 1\n\
             many.gltf:6:16: warning KHR_MATERIALS_SHEEN_LEGACY_DRAFT: sheenFactor belongs to the pre-ratification KHR_materials_sheen draft and is ignored by ratified loaders; `velvet migrate` upgrades it\n    at {p}/sheenFactor\n\
             many.gltf:7:8: warning UNEXPECTED_PROPERTY: unexpected property 'odd'\n    at {p}/odd\n\
             \x20   and 7 more at 10:48, 11:48, 12:48, 13:48, 14:48, … (8 in all; --no-fold prints each)\n\
             many.gltf:8:12: warning UNEXPECTED_PROPERTY: unexpected property 'strange'\n    at {p}/strange\n\
             1 file checked: 1 error, 10 warnings, 0 info, 0 hints; 1 fixable with --fix --unsafe-fixes\n"
        )
    );
    let o = velvet_in(
        dir.path(),
        &["validate", "--color", "never", "--no-fold", "many.gltf"],
    );
    let lines: Vec<String> = stdout(&o)
        .lines()
        .filter(|l| !l.starts_with(' '))
        .map(|l| l.split(": ").take(2).collect::<Vec<_>>().join(": "))
        .collect();
    let mut expected = vec![
        "many.gltf:5:25: error VALUE_NOT_IN_RANGE".to_string(),
        "many.gltf:6:16: warning KHR_MATERIALS_SHEEN_LEGACY_DRAFT".to_string(),
        "many.gltf:7:8: warning UNEXPECTED_PROPERTY".to_string(),
        "many.gltf:8:12: warning UNEXPECTED_PROPERTY".to_string(),
    ];
    expected.extend((10..17).map(|l| format!("many.gltf:{l}:48: warning UNEXPECTED_PROPERTY")));
    expected.push(
        "1 file checked: 1 error, 10 warnings, 0 info, 0 hints; 1 fixable with --fix --unsafe-fixes"
            .to_string(),
    );
    assert_eq!(lines, expected);
    // -v, the flag migrate and bake take for "show everything", prints the same.
    let verbose = velvet_in(
        dir.path(),
        &["validate", "--color", "never", "-v", "many.gltf"],
    );
    assert_eq!(stdout(&verbose), stdout(&o));
}

// ---------------------------------------------------------------- the README's snippets

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap()
}

/// The first fenced block of `lang` after the heading line `heading` in `text`.
fn block_after(text: &str, heading: &str, lang: &str) -> String {
    let at = text
        .find(&format!("\n{heading}\n"))
        .unwrap_or_else(|| panic!("{heading} is in the text"));
    let fence = format!("```{lang}\n");
    let start = at + text[at..].find(&fence).unwrap() + fence.len();
    let end = start + text[start..].find("```\n").unwrap();
    text[start..end].to_string()
}

/// A copy of `from` at `to`, folders included.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let target = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &target);
        } else {
            std::fs::copy(&p, &target).unwrap();
        }
    }
}

/// Runs a shell command line in `dir` with the velvet under test first on PATH.
fn shell(dir: &Path, line: &str) -> Output {
    let bin = Path::new(env!("CARGO_BIN_EXE_velvet")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut cmd = Command::new("sh");
    cmd.current_dir(dir).arg("-c").arg(line).env("PATH", path);
    for var in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE", "TERM", "CI"] {
        cmd.env_remove(var);
    }
    cmd.output().unwrap()
}

const INSTALL: &str = "cargo install --locked --git \"$VELVET_GIT_URL\" velvet";

#[test]
fn readme_pre_commit_snippet_runs_as_pre_commit_runs_it_with_mixed_case_names() {
    let text = block_after(&readme(), "### pre-commit", "yaml");
    let config: Value = serde_yaml_ng::from_str(&text).expect("the snippet is YAML");
    let repo = &config["repos"][0];
    assert_eq!(
        repo["repo"], "local",
        "no rev to name: the hook runs the installed velvet"
    );
    let hook = &repo["hooks"][1];
    assert_eq!(hook["language"], "system");
    let hook = Hook {
        id: hook["id"].as_str().unwrap().to_string(),
        entry: hook["entry"].as_str().unwrap().to_string(),
        language: hook["language"].as_str().unwrap().to_string(),
        files: hook["files"].as_str().unwrap().to_string(),
    };
    assert_eq!(hook.id, "velvet-validate");
    // The hooks velvet's repository ships select the same files.
    for shipped in hooks() {
        assert_eq!(shipped.files, hook.files, "{}", shipped.id);
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("models")).unwrap();
    std::fs::copy(
        project().join("assets/mixed.gltf"),
        dir.path().join("models/UPPER.GLTF"),
    )
    .unwrap();
    std::fs::copy(
        project().join("assets/clean.gltf"),
        dir.path().join("models/Chair.Gltf"),
    )
    .unwrap();
    std::fs::write(dir.path().join("models/notes.txt"), "not an asset").unwrap();
    let (ok, out) = run_hook(&hook, dir.path(), 100);
    assert!(!ok, "{out}");
    assert!(
        out.contains("models/UPPER.GLTF:10:43: error UNRESOLVED_REFERENCE"),
        "{out}"
    );
    assert!(
        out.ends_with(
            "2 files checked: 2 errors, 2 warnings, 0 info, 2 hints; 2 fixable with --fix (1 more with --unsafe-fixes)\n"
        ),
        "{out}"
    );
    std::fs::remove_file(dir.path().join("models/UPPER.GLTF")).unwrap();
    let (ok, out) = run_hook(&hook, dir.path(), 100);
    assert!(ok, "{out}");
    assert_eq!(
        out,
        "1 file checked: 0 errors, 0 warnings, 0 info, 0 hints\n"
    );
}

#[test]
fn readme_github_actions_snippet_runs_as_written() {
    let text = block_after(
        &readme(),
        "### GitHub Actions, with findings in code scanning",
        "yaml",
    );
    let workflow: Value = serde_yaml_ng::from_str(&text).expect("the workflow is YAML");
    let job = &workflow["jobs"]["velvet"];
    assert_eq!(job["permissions"]["security-events"], "write");
    assert_eq!(job["env"]["VELVET_GIT_URL"], "${{ vars.VELVET_GIT_URL }}");
    let steps = job["steps"].as_array().unwrap();
    let runs: Vec<&str> = steps.iter().filter_map(|s| s["run"].as_str()).collect();
    assert_eq!(runs[0], INSTALL);
    let dir = tempfile::tempdir().unwrap();
    copy_tree(&project(), dir.path());
    let o = shell(dir.path(), runs[1]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "the project has errors: the step fails"
    );
    let log: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("velvet.sarif")).unwrap()).unwrap();
    assert_eq!(log["version"], "2.1.0");
    assert_eq!(log["runs"][0]["results"].as_array().unwrap().len(), 12);
    let upload = steps
        .iter()
        .find(|s| {
            s["uses"]
                .as_str()
                .is_some_and(|u| u.starts_with("github/codeql-action/upload-sarif@"))
        })
        .expect("an upload step");
    assert_eq!(
        upload["if"], "always()",
        "findings are uploaded when the step failed"
    );
    assert_eq!(upload["with"]["sarif_file"], "velvet.sarif");
    assert_eq!(upload["with"]["category"], "velvet");
}

#[test]
fn ci_docs_gitlab_snippet_runs_as_written() {
    let docs =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ci.md")).unwrap();
    let text = block_after(&docs, "## GitLab CI", "yaml");
    let config: Value = serde_yaml_ng::from_str(&text).expect("the job is YAML");
    let job = &config["velvet"];
    let script: Vec<&str> = job["script"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert_eq!(script[0], INSTALL);
    let dir = tempfile::tempdir().unwrap();
    copy_tree(&project(), dir.path());
    let o = shell(dir.path(), script[1]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "the SARIF line never fails the job"
    );
    let log: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("velvet.sarif")).unwrap()).unwrap();
    assert_eq!(log["runs"][0]["results"].as_array().unwrap().len(), 12);
    let o = shell(dir.path(), script[2]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "the coloured run sets the job's status"
    );
    assert!(stdout(&o).contains(ESC));
    assert_eq!(job["artifacts"]["when"], "always");
    assert_eq!(job["artifacts"]["paths"][0], "velvet.sarif");
}

#[test]
fn readme_output_example_is_what_velvet_prints() {
    assert_readme_example_is_what_velvet_prints("$ velvet validate assets/mixed.gltf");
}

/// The README's `text` block that opens with `command` (`$ velvet …`, run in the CI project)
/// shows exactly what that command prints, and the command exits 1 (it finds errors).
fn assert_readme_example_is_what_velvet_prints(command: &str) {
    let readme = readme();
    let start = readme
        .find(&format!("```text\n{command}\n"))
        .unwrap_or_else(|| panic!("the README shows `{command}`"));
    let body = &readme[start + "```text\n".len()..];
    let body = &body[..body.find("```\n").unwrap()];
    let (command, shown) = body.split_once('\n').unwrap();
    let args: Vec<&str> = command.split_whitespace().skip(2).collect();
    let o = velvet(&args);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stdout(&o), shown);
}

#[test]
fn every_yaml_snippet_in_the_readme_and_ci_docs_parses() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ci.md");
    for (name, text) in [
        ("README.md", readme()),
        ("docs/ci.md", std::fs::read_to_string(docs).unwrap()),
    ] {
        let mut rest = text.as_str();
        let mut blocks = 0;
        while let Some(at) = rest.find("```yaml\n") {
            let body = &rest[at + 8..];
            let end = body.find("```\n").unwrap();
            let snippet = &body[..end];
            serde_yaml_ng::from_str::<Value>(snippet)
                .unwrap_or_else(|e| panic!("{name}: {e}\n{snippet}"));
            let revs: Vec<&str> = snippet.lines().filter(|l| l.contains("rev:")).collect();
            assert!(
                revs.is_empty(),
                "{name}: a snippet names a rev, which would have to exist: {revs:?}"
            );
            blocks += 1;
            rest = &body[end..];
        }
        assert!(blocks >= 2, "{name}");
    }
}

#[test]
fn readme_first_commands_are_the_ci_test_command_and_the_binary_it_builds() {
    let block = block_after(&readme(), "## From a clone: the first two commands", "sh");
    let commands: Vec<&str> = block
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .collect();
    assert_eq!(commands.len(), 2);
    assert_eq!(commands[0], "cargo test --locked");
    let ci =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(".ci/run")).unwrap();
    assert_eq!(
        ci.lines().last(),
        Some(commands[0]),
        ".ci/run runs the README's test command"
    );
    // The second runs the binary the test build made, on a file that exists.
    let words: Vec<&str> = commands[1].split_whitespace().collect();
    assert_eq!(words[0], "target/debug/velvet");
    let o = velvet_in(Path::new(env!("CARGO_MANIFEST_DIR")), &words[1..]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
}

/// Runs a shell line in `dir` with extra environment variables.
fn shell_with(dir: &Path, line: &str, env: &[(&str, String)]) -> Output {
    let bin = Path::new(env!("CARGO_BIN_EXE_velvet")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    Command::new("sh")
        .current_dir(dir)
        .arg("-c")
        .arg(line)
        .env("PATH", path)
        .envs(env.iter().map(|(k, v)| (*k, v.as_str())))
        .output()
        .unwrap()
}

/// The sorted lines of the jsonl reports in `text`, each report's `uri` kept.
fn sorted_lines(text: &str) -> Vec<String> {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines.sort();
    lines
}

#[test]
fn ci_docs_shard_recipes_cover_the_library_once_as_written() {
    let docs =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/ci.md")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    library(&dir.path().join("assets"), 17);
    let whole = velvet_in(dir.path(), &["validate", "--format", "jsonl", "assets/"]);
    let whole = sorted_lines(&stdout(&whole));
    assert_eq!(whole.len(), 17);

    // GitLab `parallel:`: each copy's script with its CI_NODE_INDEX, then the report job.
    let gitlab: Value =
        serde_yaml_ng::from_str(&block_after(&docs, "### GitLab `parallel:`", "yaml")).unwrap();
    let total = gitlab["velvet"]["parallel"].as_u64().unwrap();
    let script: Vec<&str> = gitlab["velvet"]["script"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap())
        .collect();
    assert_eq!(script[0], INSTALL);
    for k in 1..=total {
        let env = [
            ("CI_NODE_INDEX", k.to_string()),
            ("CI_NODE_TOTAL", total.to_string()),
        ];
        assert_eq!(
            shell_with(dir.path(), script[1], &env).status.code(),
            Some(0)
        );
        let status = shell_with(dir.path(), script[2], &env).status.code();
        assert!(status == Some(0) || status == Some(1), "{status:?}");
    }
    let report = gitlab["velvet-report"]["script"][0].as_str().unwrap();
    assert_eq!(shell_with(dir.path(), report, &[]).status.code(), Some(0));
    let merged = std::fs::read_to_string(dir.path().join("velvet.jsonl")).unwrap();
    assert_eq!(
        sorted_lines(&merged),
        whole,
        "the parts' reports are the whole run's"
    );

    // GitHub Actions matrix: one SARIF log per part, every file's results once among them.
    let github: Value =
        serde_yaml_ng::from_str(&block_after(&docs, "### GitHub Actions matrix", "yaml")).unwrap();
    let job = &github["jobs"]["velvet"];
    let shards: Vec<u64> = job["strategy"]["matrix"]["shard"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    let steps = job["steps"].as_array().unwrap();
    let run = steps
        .iter()
        .filter_map(|s| s["run"].as_str())
        .nth(1)
        .unwrap();
    assert!(run.contains(&format!("/{} ", shards.len())), "{run}");
    let mut results = 0;
    let mut categories = Vec::new();
    for k in &shards {
        let line = run.replace("${{ matrix.shard }}", &k.to_string());
        shell_with(dir.path(), &line, &[]);
        let log: Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("velvet.sarif")).unwrap())
                .unwrap();
        results += log["runs"][0]["results"].as_array().unwrap().len();
        let upload = steps
            .iter()
            .find(|s| s["with"]["category"].is_string())
            .unwrap();
        categories.push(
            upload["with"]["category"]
                .as_str()
                .unwrap()
                .replace("${{ matrix.shard }}", &k.to_string()),
        );
    }
    let single = velvet_in(dir.path(), &["validate", "--format", "sarif", "assets/"]);
    let single: Value = serde_json::from_str(&stdout(&single)).unwrap();
    assert_eq!(
        results,
        single["runs"][0]["results"].as_array().unwrap().len()
    );
    categories.dedup();
    assert_eq!(categories.len(), shards.len(), "a category per part");

    // Kubernetes Indexed Job: each index's command, the volumes' paths put in a temporary
    // folder, writes its part; the parts together are the whole run.
    let k8s: Value =
        serde_yaml_ng::from_str(&block_after(&docs, "### Kubernetes Indexed Job", "yaml")).unwrap();
    let completions = k8s["spec"]["completions"].as_u64().unwrap();
    let container = &k8s["spec"]["template"]["spec"]["containers"][0];
    assert_eq!(container["command"][1], "-c");
    let line = container["args"][0].as_str().unwrap();
    assert!(line.contains(&format!("+ 1))/{completions}\"")), "{line}");
    let reports = dir.path().join("reports");
    std::fs::create_dir(&reports).unwrap();
    let line = line
        .replace("/library/", &format!("{}/", dir.path().display()))
        .replace("/reports/", &format!("{}/", reports.display()));
    for index in 0..completions {
        shell_with(
            dir.path(),
            &line,
            &[("JOB_COMPLETION_INDEX", index.to_string())],
        );
    }
    let mut merged = String::new();
    for index in 0..completions {
        merged += &std::fs::read_to_string(reports.join(format!("velvet-{index}.jsonl"))).unwrap();
    }
    // The reports name files by the absolute path the pods were given.
    let absolute = sorted_lines(&stdout(&velvet_in(
        dir.path(),
        &[
            "validate",
            "--format",
            "jsonl",
            dir.path().join("assets").to_str().unwrap(),
        ],
    )));
    assert_eq!(sorted_lines(&merged), absolute);
}

// ---------------------------------------------------------------- missing resources

/// A folder of two assets whose resources are partly missing: a.gltf names three files (one by
/// two images) and a data: URI, two of the files missing, and has a warning besides; b.gltf
/// names one missing image and has an error besides.
fn missing_resources_project() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("a.gltf"),
        "{\n\"asset\": {\"version\": \"2.0\"},\n\"extensionsUsed\": [\"KHR_materials_sheen\"],\n\
         \"buffers\": [{\"uri\": \"Chair.bin\", \"byteLength\": 4}, {\"uri\": \"present.bin\", \"byteLength\": 4}, {\"uri\": \"data:application/octet-stream;base64,AAAAAA==\", \"byteLength\": 4}],\n\
         \"images\": [{\"uri\": \"Chair_base.png\"}, {\"uri\": \"Chair_base.png\"}], \"textures\": [{\"source\": 0}, {\"source\": 1}],\n\
         \"materials\": [{\"extensions\": {\"KHR_materials_sheen\": {\"odd\": 1}}}, {\"normalTexture\": {\"index\": 0}, \"emissiveTexture\": {\"index\": 1}}]\n}\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("present.bin"), [0u8; 4]).unwrap();
    std::fs::write(
        dir.path().join("b.gltf"),
        "{\n\"asset\": {\"version\": \"2.0\"},\n\"scene\": 0,\n\"images\": [{\"uri\": \"gone.png\"}], \"textures\": [{\"source\": 0}], \"materials\": [{\"emissiveTexture\": {\"index\": 0}}]\n}\n",
    )
    .unwrap();
    dir
}

const A_MISSING: &str = "2 of 3 resources are missing: Chair.bin, Chair_base.png — a checkout without Git LFS? fetch them, or `--ignore FILE_NOT_FOUND`";
const B_MISSING: &str = "1 of 1 resource is missing: gone.png — a checkout without Git LFS? fetch it, or `--ignore FILE_NOT_FOUND`";

#[test]
fn missing_resources_are_one_text_entry_per_file_after_its_other_findings() {
    let dir = missing_resources_project();
    let o = velvet_in(
        dir.path(),
        &["validate", "--color", "never", "a.gltf", "b.gltf"],
    );
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stdout(&o),
        format!(
            "a.gltf:6:62: warning UNEXPECTED_PROPERTY: unexpected property 'odd'\n\
             \x20   at /materials/0/extensions/KHR_materials_sheen/odd\n\
             a.gltf:4:21: error FILE_NOT_FOUND: {A_MISSING}\n\
             b.gltf:3:10: error UNRESOLVED_REFERENCE: scene names scene 0, but the asset has 0 scenes\n\
             \x20   at /scene\n\
             b.gltf:4:20: error FILE_NOT_FOUND: {B_MISSING}\n\
             2 files checked: 5 errors, 1 warning, 0 info, 0 hints\n"
        )
    );
    // --no-fold prints every finding as it is, each missing file on its own line.
    let o = velvet_in(
        dir.path(),
        &["validate", "--color", "never", "--no-fold", "-q", "a.gltf"],
    );
    let lines: Vec<String> = stdout(&o)
        .lines()
        .filter(|l| !l.starts_with(' '))
        .map(|l| l.split(": ").take(2).collect::<Vec<_>>().join(": "))
        .collect();
    assert_eq!(
        lines,
        [
            "a.gltf:4:21: error FILE_NOT_FOUND",
            "a.gltf:5:20: error FILE_NOT_FOUND",
            "a.gltf:5:47: error FILE_NOT_FOUND",
            "a.gltf:6:62: warning UNEXPECTED_PROPERTY"
        ]
    );
}

#[test]
fn github_and_sarif_list_every_other_finding_before_the_missing_resources() {
    let dir = missing_resources_project();
    let o = velvet_in(
        dir.path(),
        &["validate", "--format", "github", "a.gltf", "b.gltf"],
    );
    assert_eq!(o.status.code(), Some(1));
    let titles: Vec<String> = stdout(&o)
        .lines()
        .map(|l| {
            let (head, message) = l.split_once("::").unwrap().1.split_once("::").unwrap();
            let file = head
                .split(',')
                .next()
                .unwrap()
                .trim_start_matches(|c| c != ' ');
            let title = head.rsplit("title=").next().unwrap();
            format!("{} {title}: {message}", file.trim())
        })
        .collect();
    assert_eq!(
        titles,
        [
            "file=a.gltf UNEXPECTED_PROPERTY: unexpected property 'odd' (at /materials/0/extensions/KHR_materials_sheen/odd)".to_string(),
            "file=b.gltf UNRESOLVED_REFERENCE: scene names scene 0, but the asset has 0 scenes (at /scene)".to_string(),
            format!("file=a.gltf FILE_NOT_FOUND: {A_MISSING}"),
            format!("file=b.gltf FILE_NOT_FOUND: {B_MISSING}"),
        ]
    );
    let o = velvet_in(
        dir.path(),
        &["validate", "--format", "sarif", "a.gltf", "b.gltf"],
    );
    assert_eq!(o.status.code(), Some(1));
    let log: Value = serde_json::from_slice(&o.stdout).unwrap();
    let results: Vec<(String, String, Option<u64>)> = log["runs"][0]["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let location = &r["locations"][0]["physicalLocation"];
            (
                location["artifactLocation"]["uri"]
                    .as_str()
                    .unwrap()
                    .to_string(),
                r["ruleId"].as_str().unwrap().to_string(),
                location["region"]["startLine"].as_u64(),
            )
        })
        .collect();
    let row =
        |file: &str, code: &str, line: Option<u64>| (file.to_string(), code.to_string(), line);
    assert_eq!(
        results,
        [
            row("a.gltf", "UNEXPECTED_PROPERTY", Some(6)),
            row("b.gltf", "UNRESOLVED_REFERENCE", Some(3)),
            row("a.gltf", "FILE_NOT_FOUND", Some(4)),
            row("b.gltf", "FILE_NOT_FOUND", Some(4)),
        ]
    );
    assert_eq!(
        log["runs"][0]["results"][2]["message"]["text"].as_str(),
        Some(A_MISSING)
    );
}

#[test]
fn the_json_report_keeps_one_message_per_missing_file_with_its_pointer() {
    let dir = missing_resources_project();
    let o = velvet_in(
        dir.path(),
        &["validate", "--format", "json", "a.gltf", "b.gltf"],
    );
    assert_eq!(o.status.code(), Some(1));
    let reports: Value = serde_json::from_slice(&o.stdout).unwrap();
    let missing: Vec<&str> = reports[0]["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["code"] == "FILE_NOT_FOUND")
        .map(|m| m["pointer"].as_str().unwrap())
        .collect();
    assert_eq!(
        missing,
        ["/buffers/0/uri", "/images/0/uri", "/images/1/uri"]
    );
    assert_eq!(reports[0]["issues"]["numErrors"], 3);
}

#[test]
fn ignoring_file_not_found_leaves_the_other_findings_and_their_exit_status() {
    let dir = missing_resources_project();
    let o = velvet_in(
        dir.path(),
        &[
            "validate",
            "--color",
            "never",
            "--ignore",
            "FILE_NOT_FOUND",
            "a.gltf",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "a warning alone does not fail");
    assert_eq!(
        stdout(&o),
        "a.gltf:6:62: warning UNEXPECTED_PROPERTY: unexpected property 'odd'\n\
         \x20   at /materials/0/extensions/KHR_materials_sheen/odd\n\
         1 file checked: 0 errors, 1 warning, 0 info, 0 hints\n"
    );
    for format in ["github", "sarif", "json"] {
        let o = velvet_in(
            dir.path(),
            &[
                "validate",
                "--format",
                format,
                "--ignore",
                "FILE_NOT_FOUND",
                "a.gltf",
                "b.gltf",
            ],
        );
        assert_eq!(
            o.status.code(),
            Some(1),
            "{format}: b.gltf's error fails the run"
        );
        let listed = if format == "sarif" {
            let log: Value = serde_json::from_slice(&o.stdout).unwrap();
            serde_json::to_string(&log["runs"][0]["results"]).unwrap()
        } else {
            stdout(&o)
        };
        assert!(listed.contains("UNRESOLVED_REFERENCE"), "{format}");
        assert!(!listed.contains("FILE_NOT_FOUND"), "{format}");
        assert!(!listed.contains("missing"), "{format}");
    }
}

// ---------------------------------------------------------------- runs that cannot start

#[test]
fn a_run_that_cannot_start_writes_a_valid_report_recording_why_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("a.gltf"),
        r#"{"asset": {"version": "2.0"}}"#,
    )
    .unwrap();
    let schema_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/ci/sarif-schema-2.1.0.json");
    let schema: Value = serde_json::from_slice(&std::fs::read(schema_path).unwrap()).unwrap();
    let sarif_schema = jsonschema::validator_for(&schema).expect("the SARIF schema compiles");
    // A path that does not exist, and an unknown code (a configuration error).
    for (args, said) in [
        (&["typo/"][..], "typo/: no such file or folder"),
        (&["--ignore", "NO_SUCH_CODE", "."][..], "NO_SUCH_CODE"),
    ] {
        let run = |format: &str| {
            let mut all = vec!["validate", "--format", format];
            all.extend(args);
            let o = velvet_in(dir.path(), &all);
            assert_eq!(o.status.code(), Some(2), "{format} {args:?}");
            assert!(stderr(&o).contains(said), "{format}: {}", stderr(&o));
            stdout(&o)
        };
        let log: Value = serde_json::from_str(&run("sarif")).expect("SARIF is JSON");
        let errors: Vec<String> = sarif_schema
            .iter_errors(&log)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{errors:#?}");
        let invocation = &log["runs"][0]["invocations"][0];
        assert_eq!(invocation["executionSuccessful"], false);
        assert_eq!(invocation["exitCode"], 2);
        let notification = &invocation["toolExecutionNotifications"][0];
        assert_eq!(notification["level"], "error");
        assert!(
            notification["message"]["text"]
                .as_str()
                .unwrap()
                .contains(said),
            "{notification}"
        );
        assert_eq!(log["runs"][0]["results"], serde_json::json!([]));

        let reports: Value = serde_json::from_str(&run("json")).expect("JSON");
        let lines: Vec<Value> = run("jsonl")
            .lines()
            .map(|l| serde_json::from_str(l).expect("a JSON line"))
            .collect();
        assert_eq!(reports.as_array().map(Vec::len), Some(1), "{reports}");
        assert_eq!(lines, reports.as_array().unwrap().clone());
        let issues = &reports[0]["issues"];
        assert_eq!(issues["numErrors"], 1);
        assert_eq!(issues["messages"][0]["code"], "USAGE_ERROR");
        assert_eq!(issues["messages"][0]["severity"], 0);
        assert!(issues["messages"][0]["message"]
            .as_str()
            .unwrap()
            .contains(said));

        let github = run("github");
        assert!(
            github.starts_with("::error title=velvet::") && github.lines().count() == 1,
            "{github}"
        );
        assert_eq!(
            run("text"),
            "",
            "text output leaves the message to standard error"
        );
    }
}

// ---------------------------------------------------------------- the README against the binary

/// The flags the README gives a command: on each line, every `--flag` and `-x` after a mention
/// of `velvet <command>`, up to the next mention, a pipe, a redirect, `;`, `&&` or a `#`
/// comment; with the command each belongs to.
fn readme_flags(readme: &str, commands: &[&str]) -> Vec<(String, String)> {
    let mention = regex::Regex::new(&format!(r"\bvelvet ({})\b", commands.join("|"))).unwrap();
    let flag = regex::Regex::new(r"(?:^|[\s`(\[])(--[a-z][a-z0-9-]*|-[a-zA-Z])\b").unwrap();
    let mut found = Vec::new();
    for line in readme.lines() {
        let mentions: Vec<_> = mention.captures_iter(line).collect();
        for (i, m) in mentions.iter().enumerate() {
            let whole = m.get(0).unwrap();
            let end = mentions
                .get(i + 1)
                .map_or(line.len(), |next| next.get(0).unwrap().start());
            let segment = &line[whole.end()..end];
            let segment = segment
                .find(['|', '>', ';', '#'])
                .map_or(segment, |cut| &segment[..cut]);
            let segment = segment.split("&&").next().unwrap();
            for f in flag.captures_iter(segment) {
                found.push((m[1].to_string(), f[1].to_string()));
            }
        }
    }
    found.sort();
    found.dedup();
    found
}

#[test]
fn every_flag_the_readme_gives_a_command_is_in_that_commands_help() {
    let commands = [
        "validate",
        "migrate",
        "bake",
        "preview",
        "config",
        "codes",
        "completions",
        "man",
    ];
    let flags = readme_flags(&readme(), &commands);
    assert!(
        flags
            .iter()
            .any(|(c, f)| c == "validate" && f == "--format"),
        "the README's flags are found: {flags:?}"
    );
    let mut unknown = Vec::new();
    for command in commands {
        let help = stdout(&velvet(&[command, "--help"]));
        for (_, flag) in flags.iter().filter(|(c, _)| c == command) {
            // As clap lists them: `  -o, --output <FILE>`, `      --dry-run`.
            let listed = help.lines().any(|l| {
                let l = l.trim_start();
                l.split([',', ' ', '\t'])
                    .filter(|w| !w.is_empty())
                    .take_while(|w| w.starts_with('-'))
                    .any(|w| w == flag)
            });
            if !listed {
                unknown.push(format!("velvet {command} {flag}"));
            }
        }
    }
    assert!(
        unknown.is_empty(),
        "flags in the README that --help does not list: {unknown:?}"
    );
}

#[test]
fn readme_flags_are_read_after_the_command_they_follow_and_not_from_other_tools() {
    let text = "git diff --name-only -z | velvet validate --files-from -\n\
                velvet migrate a/ --dry-run --format json   # or --check\n\
                `velvet bake -o x.gltf` and `velvet validate --shard 2/4` > out; --not-this\n";
    let found = readme_flags(text, &["validate", "migrate", "bake"]);
    let as_str: Vec<(&str, &str)> = found
        .iter()
        .map(|(c, f)| (c.as_str(), f.as_str()))
        .collect();
    assert_eq!(
        as_str,
        [
            ("bake", "-o"),
            ("migrate", "--dry-run"),
            ("migrate", "--format"),
            ("validate", "--files-from"),
            ("validate", "--shard")
        ]
    );
}

#[test]
fn the_readme_states_the_rust_version_cargo_toml_declares() {
    let manifest: toml::Table =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml"))
            .unwrap()
            .parse()
            .unwrap();
    let declared = manifest["package"]["rust-version"]
        .as_str()
        .expect("Cargo.toml declares rust-version");
    let stated: Vec<String> = regex::Regex::new(r"\bRust (\d+\.\d+(?:\.\d+)?)")
        .unwrap()
        .captures_iter(&readme())
        .map(|c| c[1].to_string())
        .collect();
    assert!(!stated.is_empty(), "the README states a Rust version");
    assert!(
        stated.iter().all(|v| v == declared),
        "Cargo.toml: rust-version {declared}; the README: Rust {stated:?}"
    );
}

#[test]
fn velvet_help_gives_each_exit_status_for_each_command() {
    let help = stdout(&velvet(&["--help"]));
    let table = &help[help.find("Exit status:\n").expect("an exit-status section")..];
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert_eq!(rows.len(), 4, "{table}");
    assert!(
        rows[3]
            .trim_start()
            .starts_with("130  migrate, bake: stopped by SIGINT (143: by SIGTERM)"),
        "{table}"
    );
    for (row, status) in rows.iter().zip(["0", "1", "2"]) {
        assert!(
            row.trim_start().starts_with(&format!("{status}  ")),
            "{row}"
        );
        for command in ["validate", "migrate", "bake", "preview"] {
            assert!(
                row.contains(command),
                "status {status} says nothing of {command}: {row}"
            );
        }
    }
}

#[test]
fn a_validate_command_line_clap_refuses_still_writes_the_report_its_format_asks_for() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["validate", "--format", "sarif", "--formt", "x", "."][..],
        &[
            "--color",
            "never",
            "validate",
            "--format=sarif",
            "--fail-on",
            "bogus",
            ".",
        ][..],
    ] {
        let o = velvet_in(dir.path(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let log: Value = serde_json::from_slice(&o.stdout).expect("a SARIF log");
        let invocation = &log["runs"][0]["invocations"][0];
        assert_eq!(invocation["executionSuccessful"], false, "{args:?}");
        let said = invocation["toolExecutionNotifications"][0]["message"]["text"]
            .as_str()
            .unwrap();
        assert!(
            said.contains("--formt") || said.contains("bogus"),
            "{args:?}: {said}"
        );
        assert!(
            stderr(&o).starts_with("error: "),
            "clap's message stays on stderr"
        );
    }
    let o = velvet_in(dir.path(), &["validate", "--formt", "x", "."]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        o.stdout.is_empty(),
        "text output writes nothing but the message"
    );
    let o = velvet_in(dir.path(), &["migrate", "--format", "json", "--bogus"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty(), "only validate writes reports");
}

#[test]
fn the_document_limit_takes_the_byte_suffixes_the_memory_budget_takes() {
    // velvet-chair.gltf is 3,547 bytes: over 3K (3,072), within 4K.
    let chair = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/sample/velvet-chair.gltf"
    );
    let refused = velvet(&["validate", "--max-document-bytes", "3K", chair]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(
        stdout(&refused).contains(
            "error DOCUMENT_TOO_LARGE: the JSON document is 3547 bytes, over the limit of 3072"
        ),
        "{}",
        stdout(&refused)
    );
    let taken = velvet(&["validate", "--max-document-bytes", "4K", chair]);
    assert_eq!(taken.status.code(), Some(0), "{}", stdout(&taken));
    let bad = velvet(&["validate", "--max-document-bytes", "4Q", chair]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn readme_fix_diff_example_is_what_velvet_prints() {
    assert_readme_example_is_what_velvet_prints("$ velvet validate --diff assets/mixed.gltf");
}

#[test]
fn readme_fixing_pre_commit_hook_fixes_fails_once_and_then_passes() {
    let text = block_after(&readme(), "### pre-commit", "yaml");
    let config: Value = serde_yaml_ng::from_str(&text).expect("the snippet is YAML");
    // The fixing hook comes first, as the README's text says.
    let hook = &config["repos"][0]["hooks"][0];
    let hook = Hook {
        id: hook["id"].as_str().unwrap().to_string(),
        entry: hook["entry"].as_str().unwrap().to_string(),
        language: hook["language"].as_str().unwrap().to_string(),
        files: hook["files"].as_str().unwrap().to_string(),
    };
    assert_eq!(hook.id, "velvet-validate-fix");
    // The hook velvet's repository ships runs the same command.
    let shipped = hooks();
    let ours = shipped.iter().find(|h| h.id == hook.id).expect("shipped");
    assert_eq!((&ours.entry, &ours.files), (&hook.entry, &hook.files));
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("models")).unwrap();
    let undeclared = r#"{"asset":{"version":"2.0"},"materials":[{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[1,1,1]}}}]}"#;
    std::fs::write(dir.path().join("models/Cloth.GLTF"), undeclared).unwrap();
    std::fs::copy(
        project().join("assets/clean.gltf"),
        dir.path().join("models/chair.gltf"),
    )
    .unwrap();
    let clean_before = std::fs::read(dir.path().join("models/chair.gltf")).unwrap();
    let (ok, out) = run_hook(&hook, dir.path(), 100);
    assert!(!ok, "a changed file fails the hook: {out}");
    assert!(
        out.contains("models/Cloth.GLTF: fixed: declare KHR_materials_sheen in extensionsUsed"),
        "{out}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("models/Cloth.GLTF")).unwrap(),
        r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_sheen"],"materials":[{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[1,1,1]}}}]}"#
    );
    assert_eq!(
        std::fs::read(dir.path().join("models/chair.gltf")).unwrap(),
        clean_before
    );
    let (ok, out) = run_hook(&hook, dir.path(), 100);
    assert!(ok, "nothing left to fix: {out}");
    // An error no fix repairs fails the hook every time.
    std::fs::copy(
        project().join("assets/mixed.gltf"),
        dir.path().join("models/mixed.gltf"),
    )
    .unwrap();
    for _ in 0..2 {
        let (ok, out) = run_hook(&hook, dir.path(), 100);
        assert!(!ok, "{out}");
        assert!(out.contains("error UNRESOLVED_REFERENCE"), "{out}");
    }
}

// ---------------------------------------------------------------- the build, flags

/// Built from a git checkout, `--version` names the commit (and "modified" when tracked files
/// differed from it at build time); the test is skipped where there is no checkout to ask.
#[test]
fn version_names_the_commit_it_was_built_from() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = velvet(&["--version"]);
    assert_eq!(o.status.code(), Some(0));
    let out = stdout(&o);
    if !manifest.join(".git").exists() {
        eprintln!(
            "skipped the commit check: {} has no .git",
            manifest.display()
        );
        assert_eq!(out, format!("velvet {}\n", env!("CARGO_PKG_VERSION")));
        return;
    }
    let git = Command::new("git")
        .current_dir(manifest)
        .args(["rev-parse", "--short", "HEAD"])
        .output();
    let hash = match git {
        Ok(g) if g.status.success() => String::from_utf8(g.stdout).unwrap().trim().to_string(),
        _ => {
            eprintln!("skipped the commit check: `git rev-parse --short HEAD` failed here");
            return;
        }
    };
    let version = env!("CARGO_PKG_VERSION");
    assert!(
        out == format!("velvet {version} ({hash})\n")
            || out == format!("velvet {version} ({hash}, modified)\n"),
        "{out:?} names {hash}"
    );
}

#[test]
fn unsafe_fixes_without_fix_or_diff_is_a_usage_error() {
    let o = velvet(&["validate", "--unsafe-fixes", "assets/clean.gltf"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stdout(&o), "");
    assert_eq!(
        stderr(&o),
        "velvet: --unsafe-fixes applies only with --fix or --diff (add one of them to fix or \
         show the unsafe fixes too)\n"
    );
    // A machine format still gets its document of a run that could not start.
    let o = velvet(&[
        "validate",
        "--format",
        "sarif",
        "--unsafe-fixes",
        "assets/clean.gltf",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let log: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let invocation = &log["runs"][0]["invocations"][0];
    assert_eq!(invocation["executionSuccessful"], false);
    assert_eq!(invocation["exitCode"], 2);
    // With --diff it is taken: a clean file has nothing to show.
    let o = velvet(&["validate", "--unsafe-fixes", "--diff", "assets/clean.gltf"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// An unknown flag is named with the usage, without clap's tip to pass it as a value after
/// `--` (a mistyped flag is what the user meant); a tip naming a similar flag stays.
#[test]
fn an_unknown_flag_is_refused_without_the_dash_dash_tip() {
    let chair = "fixtures/sample/velvet-chair.gltf";
    let o = velvet(&["validate", "--out-dir", "x", chair]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        stderr(&o),
        "error: unexpected argument '--out-dir' found\n\nUsage: velvet validate [OPTIONS] [PATHS]...\n\nFor more information, try '--help'.\n"
    );
    let similar = velvet(&["migrate", "--out", "x", chair]);
    assert_eq!(similar.status.code(), Some(2));
    assert!(
        stderr(&similar).contains("tip: a similar argument exists: '--output'"),
        "{}",
        stderr(&similar)
    );
}

/// On a terminal, a run over one file shows that file, its size and the time so far (a
/// spinner), not "0/1 files checked" for as long as a large file takes; validate and migrate
/// alike. The terminal is `script`'s pseudo-terminal; without util-linux's `script` the check
/// is skipped.
#[test]
fn one_file_on_a_terminal_is_shown_with_its_size_while_it_runs() {
    let bin = env!("CARGO_BIN_EXE_velvet");
    let chair = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/sample/velvet-chair.gltf");
    // util-linux's script (BSD's takes other options).
    let usable = Command::new("script")
        .args(["-qec", "true", "/dev/null"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !usable {
        eprintln!("skipped: no util-linux `script` here to give velvet a terminal");
        return;
    }
    let size = std::fs::metadata(&chair).unwrap().len();
    assert_eq!(size, 3547, "the sample's size, as the line below gives it");
    for command in ["validate", "migrate --dry-run"] {
        let line = format!("{bin} {command} {}", chair.display());
        let run = Command::new("script")
            .args(["-qec", &line, "/dev/null"])
            .env_remove("NO_COLOR")
            .output()
            .expect("script runs");
        let shown = String::from_utf8_lossy(&run.stdout);
        assert!(
            shown.contains(&format!("{} (3.46 KiB) 0s", chair.display())),
            "{command}: {shown}"
        );
        assert!(!shown.contains("0/1"), "{command}: {shown}");
    }
}
