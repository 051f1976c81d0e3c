//! SARIF 2.1.0 output, as GitHub code scanning and other SARIF consumers read it.
//!
//! One run: the tool's driver lists every code of the registry as a rule (id, description,
//! default level); each finding is a result with its level (error, warning, or note for info
//! and hint), message, and one physical location. The location's URI is relative to the working
//! directory (the repository root, in CI) when the file lies below it, else an absolute
//! `file:` URI. A .gltf finding whose pointer names a value gets `region.startLine` and
//! `startColumn` (columns count Unicode code points, declared by `columnKind`); a .glb is
//! binary, so its region is the `byteOffset` of the value in the file instead, with
//! `startLine` 1 because GitHub code scanning requires a line on every result. The JSON pointer
//! goes in each result's `properties.pointer`.
//!
//! A finding that a fix repairs carries it in `fixes` (SARIF 2.1.0 §3.55): its description and
//! one artifactChange whose replacements give each `deletedRegion` both as lines and columns
//! (`startLine`, `startColumn`, `endLine`, `endColumn`: an empty region is an insertion point)
//! and as bytes (`byteOffset`, `byteLength`), with the `insertedContent` text. A .glb's fixes
//! are not given (its JSON chunk cannot be edited as text; `velvet validate --fix` repacks it).
//!
//! Each file's missing resources are one result (see [`super::Listing`]), at the place of the
//! first, and these results follow every other result of the run.

use crate::asset::Container;
use crate::diagnostics::Severity;
use crate::validate::{FileReport, Finding};
use percent_encoding::{utf8_percent_encode, AsciiSet, NON_ALPHANUMERIC};
use serde::Serialize;
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Component, Path};

/// The schema URI written into the log.
pub const SCHEMA_URI: &str = "https://json.schemastore.org/sarif-2.1.0.json";

/// The codes table (docs/codes.md, anchor `<a id="codes">`) in the repository that Cargo.toml's
/// `repository` field names, where each rule's `helpUri` leads; None while the package names no
/// repository, and the rules then carry no `helpUri` rather than a link that may lead nowhere.
/// GitHub gives table rows no anchors of their own, so every rule links to the table, which
/// lists every code with its meaning.
pub fn codes_table_url() -> Option<String> {
    codes_table_url_in(env!("CARGO_PKG_REPOSITORY"))
}

/// [`codes_table_url`] for a given `repository` field (a GitHub-style repository's web address).
pub fn codes_table_url_in(repository: &str) -> Option<String> {
    let repository = repository.trim().trim_end_matches('/');
    let repository = repository.strip_suffix(".git").unwrap_or(repository);
    if repository.is_empty() {
        return None;
    }
    Some(format!("{repository}/blob/main/docs/codes.md#codes"))
}

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
    let abs = crate::asset::discover::absolute(path);
    let encode =
        |c: &std::ffi::OsStr| utf8_percent_encode(&c.to_string_lossy(), SEGMENT).to_string();
    if let Some(rel) = crate::asset::discover::working_folder().and_then(|cwd| {
        abs.strip_prefix(crate::asset::discover::absolute(cwd))
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

// The log's shape as types: serialised straight to text, borrowing the reports' strings (a
// `serde_json::Value` tree of tens of thousands of results doubled a run's peak memory).

#[derive(Serialize)]
struct Log<'a> {
    #[serde(rename = "$schema")]
    schema: &'static str,
    version: &'static str,
    runs: [Run<'a>; 1],
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Run<'a> {
    tool: Tool,
    invocations: [Invocation<'a>; 1],
    column_kind: &'static str,
    results: Vec<SarifResult<'a>>,
}

#[derive(Serialize)]
struct Tool {
    driver: Driver,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Driver {
    name: &'static str,
    version: &'static str,
    semantic_version: &'static str,
    rules: Vec<Rule>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Rule {
    id: &'static str,
    short_description: Text<'static>,
    full_description: Text<'static>,
    help: Help,
    #[serde(skip_serializing_if = "Option::is_none")]
    help_uri: Option<String>,
    default_configuration: Configuration,
}

/// A rule's help (SARIF 2.1.0 §3.49.13): what the code means, its default severity and how
/// `--fix` repairs it, as plain text and as Markdown.
#[derive(Serialize)]
struct Help {
    text: String,
    markdown: String,
}

#[derive(Serialize)]
struct Text<'a> {
    text: &'a str,
}

#[derive(Serialize)]
struct Configuration {
    level: &'static str,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Invocation<'a> {
    execution_successful: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    exit_code: Option<i32>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    tool_execution_notifications: Vec<Notification<'a>>,
}

#[derive(Serialize, Clone)]
struct OwnedText {
    text: String,
}

#[derive(Serialize)]
struct Notification<'a> {
    level: &'static str,
    message: OwnedText,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    locations: Vec<Location<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct SarifResult<'a> {
    rule_id: &'a str,
    rule_index: i64,
    level: &'static str,
    message: Text<'a>,
    locations: [Location<'a>; 1],
    properties: Properties<'a>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    fixes: Vec<SarifFix<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct SarifFix<'a> {
    description: Text<'a>,
    artifact_changes: [ArtifactChange<'a>; 1],
    properties: FixProperties<'a>,
}

/// What a fix is beside its edits: how safe ("safe": `--fix` applies it; "unsafe": only with
/// `--unsafe-fixes`) and every finding it repairs (a fix repairing several is given with the
/// first of them only, so that each edit is given once).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct FixProperties<'a> {
    applicability: &'static str,
    repairs: Vec<FixRepair<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct FixRepair<'a> {
    rule_id: &'a str,
    pointer: &'a str,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct ArtifactChange<'a> {
    artifact_location: ArtifactLocation,
    replacements: Vec<Replacement<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Replacement<'a> {
    deleted_region: DeletedRegion,
    #[serde(skip_serializing_if = "Option::is_none")]
    inserted_content: Option<Text<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct DeletedRegion {
    start_line: usize,
    start_column: usize,
    end_line: usize,
    end_column: usize,
    byte_offset: usize,
    byte_length: usize,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Location<'a> {
    physical_location: PhysicalLocation<'a>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PhysicalLocation<'a> {
    artifact_location: &'a ArtifactLocation,
    #[serde(skip_serializing_if = "Option::is_none")]
    region: Option<Region>,
}

#[derive(Serialize, Clone)]
#[serde(rename_all = "camelCase")]
struct ArtifactLocation {
    uri: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    uri_base_id: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    description: Option<OwnedText>,
}

#[derive(Serialize)]
#[serde(untagged, rename_all_fields = "camelCase")]
enum Region {
    /// A value in a .gltf: line and column (code points).
    Text {
        start_line: usize,
        start_column: usize,
    },
    /// A value in a .glb: its byte offset in the file, and line 1 (GitHub code scanning
    /// requires `startLine` on every result; a GLB has no lines of its own, and its JSON chunk
    /// sits on the first "line" of the file as a text viewer splits it).
    Binary {
        start_line: usize,
        byte_offset: usize,
    },
}

#[derive(Serialize)]
struct Properties<'a> {
    pointer: &'a str,
}

fn artifact_location(path: &Path) -> ArtifactLocation {
    let (uri, relative) = artifact_uri(path);
    ArtifactLocation {
        uri,
        uri_base_id: relative.then_some("%SRCROOT%"),
        description: None,
    }
}

/// What a .glb's fixes change: its JSON chunk's text, named as an artifact of its own (the
/// file's URI with the fragment `#json-chunk`). Its replacements are of that text, not of the
/// file's bytes: a consumer applies them to the chunk's text and frames it again (lengths and
/// padding), as `velvet validate --fix` does.
fn json_chunk_location(file: &ArtifactLocation) -> ArtifactLocation {
    ArtifactLocation {
        uri: format!("{}#json-chunk", file.uri),
        uri_base_id: file.uri_base_id,
        description: Some(OwnedText {
            text: format!(
                "the JSON chunk of {}, as text without its padding; the GLB header's and the \
                 chunk's lengths follow from it",
                file.uri
            ),
        }),
    }
}

/// The result of one finding of `report`.
fn result<'a>(
    report: &'a FileReport,
    artifact: &'a ArtifactLocation,
    f: &'a Finding,
    index: &HashMap<&str, usize>,
    shown: &mut std::collections::HashSet<usize>,
) -> SarifResult<'a> {
    let d = &f.diagnostic;
    let region = f.position.map(|p| match report.container {
        Some(Container::Glb) => Region::Binary {
            start_line: 1,
            byte_offset: report.json_offset + p.offset,
        },
        _ => Region::Text {
            start_line: p.line,
            start_column: p.column,
        },
    });
    SarifResult {
        rule_id: d.code,
        // Every emitted code is registered; -1 is SARIF's "not in the rules array".
        rule_index: index.get(d.code).map_or(-1, |&i| i as i64),
        level: level(d.severity),
        message: Text { text: &d.message },
        locations: [Location {
            physical_location: PhysicalLocation {
                artifact_location: artifact,
                region,
            },
        }],
        properties: Properties {
            pointer: &d.pointer,
        },
        fixes: report
            .fixes
            .index_of(d)
            .filter(|&i| shown.insert(i))
            .and_then(|_| report.fixes.for_finding(d))
            .filter(|fix| !fix.edits.is_empty())
            .map(|fix| {
                let glb = report.container == Some(Container::Glb);
                vec![SarifFix {
                    description: Text { text: &fix.title },
                    properties: FixProperties {
                        applicability: fix.safety.as_str(),
                        repairs: fix
                            .repairs
                            .iter()
                            .map(|r| FixRepair {
                                rule_id: r.code,
                                pointer: &r.pointer,
                            })
                            .collect(),
                    },
                    artifact_changes: [ArtifactChange {
                        artifact_location: if glb {
                            json_chunk_location(artifact)
                        } else {
                            artifact.clone()
                        },
                        replacements: fix
                            .edits
                            .iter()
                            .map(|e| Replacement {
                                deleted_region: DeletedRegion {
                                    start_line: e.start.line,
                                    start_column: e.start.column,
                                    end_line: e.end.line,
                                    end_column: e.end.column,
                                    byte_offset: e.start.offset,
                                    byte_length: e.end.offset - e.start.offset,
                                },
                                inserted_content: (!e.content.is_empty())
                                    .then_some(Text { text: &e.content }),
                            })
                            .collect(),
                    }],
                }]
            })
            .unwrap_or_default(),
    }
}

/// Each report's entry for its missing resources, if it has one.
fn missing_entries(reports: &[FileReport]) -> Vec<Option<Finding>> {
    reports.iter().map(|r| super::listing(r).missing).collect()
}

fn log<'a>(
    reports: &'a [FileReport],
    artifacts: &'a [ArtifactLocation],
    missing: &'a [Option<Finding>],
) -> Log<'a> {
    let codes = crate::rules::all_codes();
    let index: HashMap<&str, usize> = codes.iter().enumerate().map(|(i, c)| (c.name, i)).collect();
    let mut results = Vec::new();
    let mut notifications = Vec::new();
    for (report, artifact) in reports.iter().zip(artifacts) {
        // The fixes already given with a result (a fix repairing several findings is given
        // with the first).
        let mut shown = std::collections::HashSet::new();
        for f in super::listing(report).others {
            results.push(result(report, artifact, f, &index, &mut shown));
        }
        if report.truncated() {
            notifications.push(Notification {
                level: "note",
                message: OwnedText {
                    text: super::omitted_note(report.omitted),
                },
                locations: vec![Location {
                    physical_location: PhysicalLocation {
                        artifact_location: artifact,
                        region: None,
                    },
                }],
            });
        }
    }
    for ((report, artifact), entry) in reports.iter().zip(artifacts).zip(missing) {
        if let Some(f) = entry {
            let mut shown = std::collections::HashSet::new();
            results.push(result(report, artifact, f, &index, &mut shown));
        }
    }
    Log {
        schema: SCHEMA_URI,
        version: "2.1.0",
        runs: [Run {
            tool: tool(),
            invocations: [Invocation {
                execution_successful: true,
                exit_code: None,
                tool_execution_notifications: notifications,
            }],
            column_kind: "unicodeCodePoints",
            results,
        }],
    }
}

/// The tool: velvet, with every code of the registry as a rule.
fn tool() -> Tool {
    let docs = codes_table_url();
    let rules = crate::rules::all_codes()
        .iter()
        .map(|c| Rule {
            id: c.name,
            short_description: Text { text: c.doc },
            full_description: Text { text: c.doc },
            help: help(c, docs.as_deref()),
            help_uri: docs.clone(),
            default_configuration: Configuration {
                level: level(c.severity),
            },
        })
        .collect();
    Tool {
        driver: Driver {
            name: "velvet",
            version: env!("CARGO_PKG_VERSION"),
            semantic_version: env!("CARGO_PKG_VERSION"),
            rules,
        },
    }
}

/// A rule's help: the code's meaning, its default severity, and whether and how `velvet
/// validate --fix` repairs it (from the fixers' table, which says what each fix does).
fn help(code: &crate::diagnostics::Code, docs: Option<&str>) -> Help {
    let fix = |quote: &str| match crate::fix::fixers::fixer_for(code.name) {
        Some(fixer) => match fixer.safety {
            crate::diagnostics::Safety::Safe => format!(
                "{quote}velvet validate --fix{quote} repairs it (a safe fix): it {}.",
                fixer.about
            ),
            crate::diagnostics::Safety::Unsafe => format!(
                "{quote}velvet validate --fix --unsafe-fixes{quote} repairs it (an unsafe fix, \
                 which changes the asset's meaning as the finding implies): it {}.",
                fixer.about
            ),
        },
        None => format!("{quote}velvet validate --fix{quote} does not repair it."),
    };
    let severity = code.severity.as_str();
    let table = match docs {
        Some(url) => format!("See [the codes table]({url})."),
        None => "`velvet codes` lists every code; docs/codes.md explains them.".to_string(),
    };
    Help {
        text: format!(
            "{}: {}\nDefault severity: {severity}.\n{}",
            code.name,
            code.doc,
            fix("")
        ),
        markdown: format!(
            "**{}**: {}\n\nDefault severity: {severity}.\n\n{}\n\n{table}",
            code.name,
            code.doc,
            fix("`")
        ),
    }
}

/// The SARIF log of a run that could not start: its invocation failed with exit code 2 and
/// `message`, and it has no results.
pub fn render_failed(message: &str) -> String {
    let log = Log {
        schema: SCHEMA_URI,
        version: "2.1.0",
        runs: [Run {
            tool: tool(),
            invocations: [Invocation {
                execution_successful: false,
                exit_code: Some(2),
                tool_execution_notifications: vec![Notification {
                    level: "error",
                    message: OwnedText {
                        text: message.to_string(),
                    },
                    locations: Vec::new(),
                }],
            }],
            column_kind: "unicodeCodePoints",
            results: Vec::new(),
        }],
    };
    let mut text = super::pretty::to_string(&log).expect("a SARIF log serialises");
    text.push('\n');
    text
}

/// The SARIF log for `reports` as a JSON value.
pub fn document(reports: &[FileReport]) -> Value {
    let artifacts: Vec<ArtifactLocation> =
        reports.iter().map(|r| artifact_location(&r.path)).collect();
    let missing = missing_entries(reports);
    serde_json::to_value(log(reports, &artifacts, &missing)).expect("a SARIF log serialises")
}

/// The SARIF log as pretty-printed JSON.
pub fn render(reports: &[FileReport]) -> String {
    let mut text = Vec::new();
    write(&mut text, reports).expect("writing to memory cannot fail");
    String::from_utf8(text).expect("serde_json writes UTF-8")
}

/// Writes the SARIF log, pretty-printed and followed by a newline, straight into `out` (a log
/// of many results is some three times the size of the JSON report, and is not held whole).
pub fn write(out: &mut impl std::io::Write, reports: &[FileReport]) -> std::io::Result<()> {
    let artifacts: Vec<ArtifactLocation> =
        reports.iter().map(|r| artifact_location(&r.path)).collect();
    let missing = missing_entries(reports);
    super::pretty::to_writer(&mut *out, &log(reports, &artifacts, &missing))?;
    out.write_all(b"\n")
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
