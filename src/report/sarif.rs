//! SARIF 2.1.0 output, as GitHub code scanning and other SARIF consumers read it.
//!
//! One run: the tool's driver lists every code of the registry as a rule (id, description,
//! default level); each finding is a result with its level (error, warning, or note for info
//! and hint), message, and one physical location. The location's URI is relative to the working
//! directory (the repository root, in CI) when the file lies below it, else an absolute
//! `file:` URI. A .gltf finding whose pointer names a value gets `region.startLine` and
//! `startColumn` (columns count Unicode code points, declared by `columnKind`); a .glb is
//! binary, so its region is the `byteOffset` of the value in the file instead. The JSON pointer
//! goes in each result's `properties.pointer`.

use crate::asset::Container;
use crate::diagnostics::{self, Severity};
use crate::validate::FileReport;
use percent_encoding::{utf8_percent_encode, AsciiSet, NON_ALPHANUMERIC};
use serde_json::{json, Map, Value};
use std::collections::HashMap;
use std::path::{Component, Path};

/// The schema URI written into the log.
pub const SCHEMA_URI: &str = "https://json.schemastore.org/sarif-2.1.0.json";

/// Bytes kept as they are in a URI path segment: RFC 3986 unreserved characters.
const SEGMENT: &AsciiSet = &NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~');

/// The SARIF level for a severity.
pub fn level(severity: Severity) -> &'static str {
    match severity {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Info | Severity::Hint => "note",
    }
}

/// The artifact URI of `path` and whether it is relative to the working directory.
pub fn artifact_uri(path: &Path) -> (String, bool) {
    let abs = crate::config::absolute(path);
    let encode =
        |c: &std::ffi::OsStr| utf8_percent_encode(&c.to_string_lossy(), SEGMENT).to_string();
    if let Some(rel) = std::env::current_dir().ok().and_then(|cwd| {
        abs.strip_prefix(crate::config::absolute(&cwd))
            .ok()
            .map(Path::to_path_buf)
    }) {
        let segments: Vec<String> = rel.components().map(|c| encode(c.as_os_str())).collect();
        return (segments.join("/"), true);
    }
    let mut uri = String::from("file://");
    for c in abs.components() {
        match c {
            Component::Prefix(p) => {
                uri.push('/');
                uri.push_str(&p.as_os_str().to_string_lossy());
            }
            Component::RootDir => {}
            other => {
                uri.push('/');
                uri.push_str(&encode(other.as_os_str()));
            }
        }
    }
    (uri, false)
}

fn artifact_location(path: &Path) -> Value {
    match artifact_uri(path) {
        (uri, true) => json!({ "uri": uri, "uriBaseId": "%SRCROOT%" }),
        (uri, false) => json!({ "uri": uri }),
    }
}

/// The SARIF log for `reports`.
pub fn document(reports: &[FileReport]) -> Value {
    let codes = diagnostics::all_codes();
    let index: HashMap<&str, usize> = codes.iter().enumerate().map(|(i, c)| (c.name, i)).collect();
    let rules: Vec<Value> = codes
        .iter()
        .map(|c| {
            json!({
                "id": c.name,
                "shortDescription": { "text": c.doc },
                "defaultConfiguration": { "level": level(c.severity) },
            })
        })
        .collect();
    let mut results = Vec::new();
    let mut notifications = Vec::new();
    for report in reports {
        let location = artifact_location(&report.path);
        for f in &report.findings {
            let d = &f.diagnostic;
            let mut physical = Map::new();
            physical.insert("artifactLocation".into(), location.clone());
            match (f.position, report.container) {
                (Some(p), Some(Container::Glb)) => {
                    physical.insert(
                        "region".into(),
                        json!({ "byteOffset": report.json_offset + p.offset }),
                    );
                }
                (Some(p), _) => {
                    physical.insert(
                        "region".into(),
                        json!({ "startLine": p.line, "startColumn": p.column }),
                    );
                }
                (None, _) => {}
            }
            // Every emitted code is registered; -1 is SARIF's "not in the rules array".
            let rule_index = index.get(d.code).map_or(-1, |&i| i as i64);
            results.push(json!({
                "ruleId": d.code,
                "ruleIndex": rule_index,
                "level": level(d.severity),
                "message": { "text": d.message },
                "locations": [{ "physicalLocation": physical }],
                "properties": { "pointer": d.pointer },
            }));
        }
        if report.truncated {
            notifications.push(json!({
                "level": "note",
                "message": { "text": "further issues not shown (max-issues)" },
                "locations": [{ "physicalLocation": { "artifactLocation": location } }],
            }));
        }
    }
    let mut invocation = json!({ "executionSuccessful": true });
    if !notifications.is_empty() {
        invocation["toolExecutionNotifications"] = Value::Array(notifications);
    }
    json!({
        "$schema": SCHEMA_URI,
        "version": "2.1.0",
        "runs": [{
            "tool": {
                "driver": {
                    "name": "velvet",
                    "version": env!("CARGO_PKG_VERSION"),
                    "semanticVersion": env!("CARGO_PKG_VERSION"),
                    "informationUri": env!("CARGO_PKG_REPOSITORY"),
                    "rules": rules,
                }
            },
            "invocations": [invocation],
            "columnKind": "unicodeCodePoints",
            "results": results,
        }]
    })
}

/// The SARIF log as pretty-printed JSON.
pub fn render(reports: &[FileReport]) -> String {
    let mut text =
        serde_json::to_string_pretty(&document(reports)).expect("a SARIF log serialises");
    text.push('\n');
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_uris_encode_each_segment_and_keep_slashes() {
        let (uri, relative) = artifact_uri(Path::new("assets/a b/ü#1.gltf"));
        assert!(relative);
        assert_eq!(uri, "assets/a%20b/%C3%BC%231.gltf");
    }

    #[test]
    fn paths_outside_the_working_directory_become_file_uris() {
        let (uri, relative) = artifact_uri(Path::new("/nonexistent-root/x y.glb"));
        assert!(!relative);
        assert_eq!(uri, "file:///nonexistent-root/x%20y.glb");
    }

    #[test]
    fn levels_map_info_and_hint_to_note() {
        assert_eq!(
            [
                Severity::Error,
                Severity::Warning,
                Severity::Info,
                Severity::Hint
            ]
            .map(level),
            ["error", "warning", "note", "note"]
        );
    }
}
