//! velvet against the Khronos glTF-Validator's own test suite: every asset of
//! `../shared/reference/glTF-Validator/test` that has a golden report (`*.report.json`) is
//! validated, and each golden error and warning is looked for in velvet's findings with the same
//! code, severity and pointer: all of them, and apart the JSON-level ones (every section of the
//! reference's ISSUES.md but DataError, which needs accessor contents and image bytes).
//!
//! The suite is not part of velvet's repository: where the folder is absent (a user's clone),
//! the test says it was skipped and passes. `VELVET_REFERENCE_SUITE` names another folder.
//!
//! What it holds velvet to:
//! - no error on an asset the reference finds free of errors;
//! - at least [`FLOOR`] of the golden errors and warnings reproduced, and of the JSON-level ones;
//! - every code the two disagree on (one missed, or an error or warning velvet reports that the
//!   reference does not) listed in docs/codes.md's table of differences, with its reason.

#[path = "support/one_pass.rs"]
mod one_pass;

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use velvet::diagnostics::Settings;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

/// The share of the golden errors and warnings (all, and the JSON-level ones) velvet must
/// reproduce; raised as rules join (docs/codes.md gives today's figures).
const FLOOR: f64 = 0.97;

fn suite() -> Option<PathBuf> {
    let folder = std::env::var_os("VELVET_REFERENCE_SUITE")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/reference/glTF-Validator")
        });
    folder.join("ISSUES.md").is_file().then_some(folder)
}

/// Each code of ISSUES.md with its section (`SchemaError`, `DataError`, …).
fn sections(issues: &str) -> HashMap<String, String> {
    let mut section = String::new();
    let mut out = HashMap::new();
    for line in issues.lines() {
        if let Some(name) = line.strip_prefix("## ") {
            section = name.trim().to_string();
        } else if let Some(row) = line.strip_prefix('|') {
            let code = row.split('|').next().unwrap_or_default().trim();
            if !code.is_empty() && code != "Code" && !code.starts_with('-') {
                out.insert(code.to_string(), section.clone());
            }
        }
    }
    out
}

/// The suite's assets that have a golden report.
fn assets(dir: &Path, out: &mut Vec<PathBuf>) {
    out.extend(one_pass::files_under(dir, &|path| {
        let asset = PathBuf::from(path.to_str()?.strip_suffix(".report.json")?);
        asset.is_file().then_some(asset)
    }));
}

/// The codes docs/codes.md lists as differences from the reference.
fn documented_differences() -> BTreeSet<String> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/codes.md"))
        .expect("docs/codes.md is readable");
    let (_, after) = text
        .split_once("## Where velvet differs from the Khronos validator")
        .expect("docs/codes.md has its table of differences");
    let table = after.split("\n## ").next().unwrap_or_default();
    table
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .map(str::to_string)
        .collect()
}

type Finding = (String, u8, String);

#[test]
fn velvet_reproduces_the_reference_suites_json_level_errors_and_warnings() {
    let Some(suite) = suite() else {
        println!(
            "skipped: the Khronos glTF-Validator suite (../shared/reference/glTF-Validator) is not here"
        );
        return;
    };
    let sections = sections(&std::fs::read_to_string(suite.join("ISSUES.md")).unwrap());
    let mut files = Vec::new();
    assets(&suite.join("test"), &mut files);
    assert!(
        files.len() > 300,
        "the suite holds its assets ({})",
        files.len()
    );
    let settings = Settings {
        max_issues: None,
        ..Settings::default()
    };
    let validator = Validator::new(Schemas::builtin(), settings);
    // (reproduced, golden) of every golden error and warning, and of the JSON-level ones.
    let (mut all, mut json_level) = ((0usize, 0usize), (0usize, 0usize));
    let mut missed: BTreeMap<String, usize> = BTreeMap::new();
    let mut extra: BTreeMap<String, usize> = BTreeMap::new();
    let mut false_errors = Vec::new();
    for file in &files {
        let golden: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(format!("{}.report.json", file.display())).unwrap(),
        )
        .unwrap();
        let messages = golden["issues"]["messages"].as_array().unwrap();
        let expected: Vec<Finding> = messages
            .iter()
            .filter(|m| m["severity"].as_u64().unwrap() <= 1)
            .map(|m| {
                (
                    m["code"].as_str().unwrap().to_string(),
                    m["severity"].as_u64().unwrap() as u8,
                    m["pointer"].as_str().unwrap_or_default().to_string(),
                )
            })
            .collect();
        let every_golden: BTreeSet<(String, String)> = messages
            .iter()
            .map(|m| {
                (
                    m["code"].as_str().unwrap().to_string(),
                    m["pointer"].as_str().unwrap_or_default().to_string(),
                )
            })
            .collect();
        let report = validator.validate_file(file);
        let mut mine: Vec<Finding> = report
            .findings
            .iter()
            .map(|f| {
                let d = &f.diagnostic;
                (d.code.to_string(), d.severity as u8, d.pointer.clone())
            })
            .collect();
        for finding in &expected {
            let data = sections.get(&finding.0).map(String::as_str) == Some("DataError");
            let reproduced = match mine.iter().position(|m| m == finding) {
                Some(at) => {
                    mine.swap_remove(at);
                    1
                }
                None => {
                    *missed.entry(finding.0.clone()).or_default() += 1;
                    0
                }
            };
            all = (all.0 + reproduced, all.1 + 1);
            if !data {
                json_level = (json_level.0 + reproduced, json_level.1 + 1);
            }
        }
        for (code, severity, pointer) in &mine {
            if *severity <= 1 && !every_golden.contains(&(code.clone(), pointer.clone())) {
                *extra.entry(code.clone()).or_default() += 1;
            }
        }
        let golden_errors = golden["issues"]["numErrors"].as_u64().unwrap();
        if golden_errors == 0 && report.counts.errors > 0 {
            false_errors.push(file.display().to_string());
        }
    }
    let share = |(found, total): (usize, usize)| found as f64 / total as f64;
    println!(
        "{} of {} golden errors and warnings reproduced ({:.1} %), {} of {} JSON-level ones ({:.1} %), over {} assets",
        all.0,
        all.1,
        100.0 * share(all),
        json_level.0,
        json_level.1,
        100.0 * share(json_level),
        files.len()
    );
    println!("missed: {missed:?}");
    println!("reported where the reference does not: {extra:?}");
    assert!(
        false_errors.is_empty(),
        "errors on assets the reference finds free of errors: {false_errors:#?}"
    );
    for (what, tally) in [("all", all), ("JSON-level", json_level)] {
        assert!(
            share(tally) >= FLOOR,
            "{:.1} % of the {what} golden errors and warnings reproduced, below the floor of {:.1} %",
            100.0 * share(tally),
            100.0 * FLOOR
        );
    }
    let documented = documented_differences();
    let undocumented: Vec<&String> = missed
        .keys()
        .chain(extra.keys())
        .filter(|code| !documented.contains(*code))
        .collect();
    assert!(
        undocumented.is_empty(),
        "codes on which velvet and the reference disagree, missing from docs/codes.md's table of differences: {undocumented:?}"
    );
}

#[test]
fn the_sections_of_issues_md_are_read_by_code() {
    let text = "# t\n## SchemaError\n| Code | Message | Severity |\n|------|---|---|\n|TYPE_MISMATCH|x|Error|\n## DataError\n| Code | Message | Severity |\n|ACCESSOR_INVALID_FLOAT|y|Error|\n";
    let read = sections(text);
    assert_eq!(read.len(), 2);
    assert_eq!(read["TYPE_MISMATCH"], "SchemaError");
    assert_eq!(read["ACCESSOR_INVALID_FLOAT"], "DataError");
}

/// The reports' fixes as a machine applies them: on every asset of the suite, the edits of the
/// JSON report and of the SARIF log, each applied in one pass by an applier written apart from
/// velvet (`support/one_pass.rs`), give the bytes `--fix --unsafe-fixes` writes.
#[test]
fn on_the_reference_suite_every_reports_edits_applied_in_one_pass_are_what_fix_writes() {
    let Some(suite) = suite() else {
        println!(
            "skipped: the Khronos glTF-Validator suite (../shared/reference/glTF-Validator) is not here"
        );
        return;
    };
    let mut files = Vec::new();
    assets(&suite.join("test"), &mut files);
    let mut with_edits = 0;
    let mut failures = Vec::new();
    for path in &files {
        match one_pass::check(path) {
            Ok(true) => with_edits += 1,
            Ok(false) => {}
            Err(e) => failures.push(e),
        }
    }
    println!(
        "fix edits applied in one pass: {with_edits} of {} suite assets with edits give what --fix --unsafe-fixes writes ({} assets)",
        with_edits + failures.len(),
        files.len()
    );
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(with_edits >= 10, "{with_edits} assets with edits");
}
