//! The Khronos glTF-Validator report shape: `uri`, `mimeType`, `validatorVersion`,
//! `issues {numErrors, numWarnings, numInfos, numHints, messages[{code, message, severity,
//! pointer}], truncated}` and `info`. Severities are numbers (0 error … 3 hint).
//!
//! A finding that a fix repairs carries it as `fix {applicability, message, edits[{content,
//! location {row, column, offset}, endLocation}]}`: the replacements of the JSON text as read
//! (rows and columns 1-based, columns in characters, offsets in bytes of the file). No two
//! fixes of a report touch the same text, so all their edits apply together in one pass; a fix
//! that repairs several findings gives its edits with the first of them, and the others name
//! that message (`editsWithMessage`, its place in `messages`). Fixes of a .glb edit its JSON
//! chunk's text (`in: "glb JSON chunk"`, offsets and rows in the chunk's text): apply them
//! there and rebuild the container's lengths and padding, as `--fix` does. A report with fixes ends with `fixes {fixable, fixableUnsafe, changed, applied[],
//! refused[], diff}`: the findings a fix repairs (with `--fix`, those it did), the fixes refused
//! with the reason, and with `--diff` the change as a unified diff. After `--fix` wrote a file,
//! the fixes left are given against its new text.
//!
//! The shape is a set of borrowing structs serialised straight to text: a report with tens of
//! thousands of findings is written without first being copied into a JSON tree.

use super::display_path;
use crate::asset::json_text::push_quoted;
use crate::diagnostics::fixes::{FileFixes, FixStatus, FixView};
use crate::diagnostics::Safety;
use crate::validate::{AssetInfo, FileReport};
use foldhash::{HashMap, HashMapExt};
use serde::Serialize;

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct ReportShape<'a> {
    uri: String,
    mime_type: Option<&'static str>,
    validator_version: &'static str,
    issues: IssuesShape<'a>,
    #[serde(skip_serializing_if = "Option::is_none")]
    info: Option<InfoShape<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    fixes: Option<FixesShape<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct FixesShape<'a> {
    fixable: usize,
    fixable_unsafe: usize,
    changed: bool,
    applied: Vec<DoneShape<'a>>,
    refused: Vec<DoneShape<'a>>,
    /// With `--diff`: the change as a unified diff.
    #[serde(skip_serializing_if = "Option::is_none")]
    diff: Option<&'a str>,
}

#[derive(Serialize)]
struct DoneShape<'a> {
    message: &'a str,
    applicability: &'static str,
    repairs: Vec<RepairShape<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'a str>,
}

#[derive(Serialize)]
struct RepairShape<'a> {
    code: &'a str,
    pointer: &'a str,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct FixShape<'a> {
    applicability: &'static str,
    message: &'a str,
    edits: Vec<EditShape<'a>>,
    /// For a fix that repairs several findings: the message (its place in `messages`) that
    /// carries its edits; this one's are empty, so that each edit is given once.
    #[serde(skip_serializing_if = "Option::is_none")]
    edits_with_message: Option<usize>,
    /// For a .glb: the text the edits apply to, its JSON chunk's.
    #[serde(rename = "in", skip_serializing_if = "Option::is_none")]
    edits_in: Option<&'static str>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct EditShape<'a> {
    content: &'a str,
    location: LocationShape,
    end_location: LocationShape,
}

#[derive(Serialize)]
struct LocationShape {
    row: usize,
    column: usize,
    offset: usize,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct IssuesShape<'a> {
    num_errors: usize,
    num_warnings: usize,
    num_infos: usize,
    num_hints: usize,
    messages: Vec<MessageShape<'a>>,
    truncated: bool,
}

#[derive(Serialize)]
struct MessageShape<'a> {
    code: &'a str,
    message: &'a str,
    severity: u8,
    pointer: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    fix: Option<FixShape<'a>>,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct InfoShape<'a> {
    version: &'a Option<String>,
    generator: &'a Option<String>,
    extensions_used: &'a [String],
    extensions_required: &'a [String],
    material_count: usize,
    sheen_material_count: usize,
    fuzz_material_count: usize,
}

/// What a .glb's fix edits: the text of its JSON chunk.
pub const GLB_JSON_CHUNK: &str = "glb JSON chunk";

const VALIDATOR_VERSION: &str = concat!("velvet ", env!("CARGO_PKG_VERSION"));

/// For each fix that repairs several listed findings, the place in the listing of the first:
/// the one message that carries its edits.
fn carriers(report: &FileReport) -> HashMap<usize, usize> {
    let mut carriers = HashMap::new();
    if report.fixes.fixes().iter().all(|f| f.repairs.len() < 2) {
        return carriers;
    }
    for (at, f) in report.findings.iter().enumerate() {
        if let Some(i) = report.fixes.index_of(&f.diagnostic) {
            if report.fixes.fixes()[i].repairs.len() > 1 {
                carriers.entry(i).or_insert(at);
            }
        }
    }
    carriers
}

/// The message of finding `f`, the `at`-th listed.
fn message_shape<'a>(
    report: &'a FileReport,
    f: &'a crate::validate::Finding,
    at: usize,
    carriers: &HashMap<usize, usize>,
) -> MessageShape<'a> {
    let fix = report.fixes.index_of(&f.diagnostic).and_then(|i| {
        let fix = report.fixes.for_finding(&f.diagnostic)?;
        let mut shape = fix_shape(report, fix);
        if let Some(&carrier) = carriers.get(&i).filter(|&&c| c != at) {
            shape.edits.clear();
            shape.edits_with_message = Some(carrier);
        }
        Some(shape)
    });
    MessageShape {
        code: f.diagnostic.code,
        message: &f.diagnostic.message,
        severity: f.diagnostic.severity as u8,
        pointer: &f.diagnostic.pointer,
        fix,
    }
}

fn fix_shape<'a>(report: &FileReport, fix: &'a FixView) -> FixShape<'a> {
    // The edits' offsets are in the file of a .gltf and in the JSON chunk of a .glb.
    let glb = report.container == Some(crate::asset::Container::Glb);
    let at = |p: &crate::diagnostics::Position| LocationShape {
        row: p.line,
        column: p.column,
        offset: p.offset,
    };
    FixShape {
        edits_with_message: None,
        edits_in: glb.then_some(GLB_JSON_CHUNK),
        applicability: fix.safety.as_str(),
        message: &fix.title,
        edits: fix
            .edits
            .iter()
            .map(|e| EditShape {
                content: &e.content,
                location: at(&e.start),
                end_location: at(&e.end),
            })
            .collect(),
    }
}

fn fixes_shape(fixes: &FileFixes) -> Option<FixesShape<'_>> {
    if fixes.fixes().is_empty() {
        return None;
    }
    Some(FixesShape {
        fixable: fixes.available(Safety::Safe),
        fixable_unsafe: fixes.available(Safety::Unsafe),
        changed: fixes.changed,
        diff: fixes.diff.as_deref(),
        applied: fixes
            .fixes()
            .iter()
            .filter(|f| f.status == FixStatus::Applied)
            .map(done_shape)
            .collect(),
        refused: fixes
            .fixes()
            .iter()
            .filter(|f| matches!(f.status, FixStatus::Refused(_)))
            .map(done_shape)
            .collect(),
    })
}

fn done_shape(fix: &FixView) -> DoneShape<'_> {
    DoneShape {
        message: &fix.title,
        applicability: fix.safety.as_str(),
        repairs: fix
            .repairs
            .iter()
            .map(|r| RepairShape {
                code: r.code,
                pointer: &r.pointer,
            })
            .collect(),
        reason: match &fix.status {
            FixStatus::Refused(reason) => Some(reason),
            _ => None,
        },
    }
}

fn shape(report: &FileReport) -> ReportShape<'_> {
    let mut shape = outline(report);
    let carriers = carriers(report);
    shape.issues.messages = report
        .findings
        .iter()
        .enumerate()
        .map(|(at, f)| message_shape(report, f, at, &carriers))
        .collect();
    shape
}

/// The report's shape with an empty list of messages.
fn outline(report: &FileReport) -> ReportShape<'_> {
    let c = report.counts;
    ReportShape {
        uri: display_path(&report.path),
        mime_type: report.container.map(|c| c.mime_type()),
        validator_version: VALIDATOR_VERSION,
        issues: IssuesShape {
            num_errors: c.errors,
            num_warnings: c.warnings,
            num_infos: c.infos,
            num_hints: c.hints,
            messages: Vec::new(),
            truncated: report.truncated(),
        },
        info: report.info.as_ref().map(|info: &AssetInfo| InfoShape {
            version: &info.version,
            generator: &info.generator,
            extensions_used: &info.extensions_used,
            extensions_required: &info.extensions_required,
            material_count: info.material_count,
            sheen_material_count: info.sheen_material_count,
            fuzz_material_count: info.fuzz_material_count,
        }),
        fixes: fixes_shape(&report.fixes),
    }
}

/// One file's report, pretty-printed (two-space indent, no final newline).
pub fn report_pretty(report: &FileReport) -> String {
    super::pretty::to_string(&shape(report)).expect("a report serialises")
}

/// [`report_pretty`] as an element of a pretty-printed array, every line indented one level,
/// after the array's opening bracket (`first`) or the comma before it, and a line break.
/// Written as a one-element array less its closing bracket, whose opening bracket is the one
/// to keep or becomes the comma: neither indented line by line afterwards (a second pass over
/// the text) nor moved to make room for what goes before it.
pub fn report_pretty_element(report: &FileReport, first: bool) -> String {
    let mut text = super::pretty::to_string(&[shape(report)]).expect("a report serialises");
    // "[\n" and "\n]" around the element. A replacement of the same length moves nothing.
    text.truncate(text.len() - 2);
    if !first {
        text.replace_range(..1, ",");
    }
    text
}

/// How many messages one task of [`write_pretty`] writes.
const MESSAGES_PER_TASK: usize = 1024;
/// How many tasks' text [`write_pretty`] holds at once.
const RUNS_IN_HAND: usize = 8;

/// One report as an object, pretty-printed and followed by a newline, as
/// [`report_pretty`] writes it. The messages, which are nearly all of a large report, are
/// written in parallel, a run of them per task, and joined in order; the rest of the report
/// is written around them.
pub fn write_pretty(out: &mut impl std::io::Write, report: &FileReport) -> std::io::Result<()> {
    use rayon::prelude::*;
    let outline = super::pretty::to_string(&outline(report))?;
    // An empty list is written `[]`; no string value holds this text, as its quotes would be
    // escaped there.
    const EMPTY: &str = "\n    \"messages\": [],";
    let at = match outline.find(EMPTY) {
        Some(at) if !report.findings.is_empty() => at,
        _ => {
            out.write_all(outline.as_bytes())?;
            return out.write_all(b"\n");
        }
    };
    let carriers = carriers(report);
    let write_run = |(text, (first, run)): (&mut String, (usize, &[crate::validate::Finding]))| {
        text.clear();
        for (i, finding) in run.iter().enumerate() {
            if i > 0 {
                text.push_str(",\n      ");
            }
            push_message(text, &message_shape(report, finding, first + i, &carriers));
        }
    };
    // Up to the list's opening bracket, the messages, then from the comma after the list on.
    out.write_all(&outline.as_bytes()[..at + EMPTY.len() - 2])?;
    out.write_all(b"\n      ")?;
    // A few runs at a time, each written into a text of its own that every window reuses, so
    // that the text in hand stays small and no window asks for fresh memory. A message takes
    // some 300 bytes; a text grows past that once at most.
    let findings = report.findings.len();
    let mut runs: Vec<String> = (0..findings.div_ceil(MESSAGES_PER_TASK).min(RUNS_IN_HAND))
        .map(|_| String::with_capacity(findings.min(MESSAGES_PER_TASK) * 320))
        .collect();
    for (w, window) in report
        .findings
        .chunks(MESSAGES_PER_TASK * RUNS_IN_HAND)
        .enumerate()
    {
        let tasks = window.len().div_ceil(MESSAGES_PER_TASK);
        let window_start = w * MESSAGES_PER_TASK * RUNS_IN_HAND;
        runs[..tasks]
            .par_iter_mut()
            .zip(
                window
                    .par_chunks(MESSAGES_PER_TASK)
                    .enumerate()
                    .map(|(k, run)| (window_start + k * MESSAGES_PER_TASK, run)),
            )
            .for_each(write_run);
        for (i, run) in runs[..tasks].iter().enumerate() {
            if w > 0 || i > 0 {
                out.write_all(b",\n      ")?;
            }
            out.write_all(run.as_bytes())?;
        }
    }
    out.write_all(b"\n    ]")?;
    out.write_all(&outline.as_bytes()[at + EMPTY.len() - 1..])?;
    out.write_all(b"\n")
}

/// A message as the pretty printer writes it within the report's list (its fields at depth 4,
/// its closing brace at depth 3). Written here rather than by the printer because a large
/// report is nearly all messages, and the printer spent most of its time on them.
fn push_message(out: &mut String, m: &MessageShape) {
    out.push_str("{\n        \"code\": ");
    push_quoted(out, m.code);
    out.push_str(",\n        \"message\": ");
    push_quoted(out, m.message);
    out.push_str(",\n        \"severity\": ");
    // Severities are 0 to 3; the formatter is kept for any other number.
    match m.severity {
        digit @ 0..=9 => out.push(char::from(b'0' + digit)),
        // Writing to a String cannot fail.
        n => drop(std::fmt::Write::write_fmt(out, format_args!("{n}"))),
    }
    out.push_str(",\n        \"pointer\": ");
    push_quoted(out, m.pointer);
    if let Some(fix) = &m.fix {
        // As the printer writes it at this depth: its lines after the first indented by 8.
        let text = super::pretty::to_string(fix).expect("a fix serialises");
        out.push_str(",\n        \"fix\": ");
        for (i, line) in text.lines().enumerate() {
            if i > 0 {
                out.push_str("\n        ");
            }
            out.push_str(line);
        }
    }
    out.push_str("\n      }");
}

/// One report as an object; several as an array.
pub fn render(reports: &[FileReport]) -> String {
    match reports {
        [one] => report_pretty(one) + "\n",
        many => render_array(many),
    }
}

/// The reports as a pretty-printed array, one report or many, as a run of several writes them.
pub fn render_array(reports: &[FileReport]) -> String {
    super::pretty::to_string(&reports.iter().map(shape).collect::<Vec<_>>())
        .expect("a report serialises")
        + "\n"
}

/// One compact JSON report per line.
pub fn render_lines(reports: &[FileReport]) -> String {
    reports
        .iter()
        .map(|r| serde_json::to_string(&shape(r)).expect("a report serialises") + "\n")
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostics::{Diagnostic, Severity};
    use crate::validate::{Counts, Finding};

    fn report(messages: usize, info: bool) -> FileReport {
        let severities = [
            Severity::Error,
            Severity::Warning,
            Severity::Info,
            Severity::Hint,
        ];
        let findings: Vec<Finding> = (0..messages)
            .map(|i| Finding {
                diagnostic: Diagnostic {
                    code: "UNEXPECTED_PROPERTY",
                    message: format!(
                        "finding {i}: \"quoted\", a\nline, a tab\t, \u{1}, \u{8}\u{c}\r\u{1f}\u{7f} \\ / and é"
                    ),
                    severity: severities[i % 4],
                    pointer: format!("/materials/{i}/extensions/a~1b"),
                    position: None,
                },
                position: None,
            })
            .collect();
        FileReport {
            path: "dir/\"odd\" name.gltf".into(),
            container: Some(crate::asset::Container::Gltf),
            json_offset: 0,
            counts: Counts {
                errors: messages,
                ..Counts::default()
            },
            findings,
            omitted: 0,
            info: info.then(|| AssetInfo {
                version: Some("2.0".into()),
                generator: None,
                extensions_used: vec!["KHR_materials_sheen".into()],
                extensions_required: Vec::new(),
                material_count: 3,
                sheen_material_count: 1,
                fuzz_material_count: 0,
            }),
            missing: Default::default(),
            fixes: Default::default(),
            rule_spans: Vec::new(),
        }
    }

    #[test]
    fn the_report_written_in_parallel_is_the_report_serde_writes() {
        for (messages, info) in [
            (0, true),
            (1, false),
            (3, true),
            (MESSAGES_PER_TASK * (RUNS_IN_HAND + 1) + 7, true),
        ] {
            let report = report(messages, info);
            let mut written = Vec::new();
            write_pretty(&mut written, &report).unwrap();
            let expected = report_pretty(&report) + "\n";
            assert!(
                written == expected.as_bytes(),
                "{messages} messages: written differs from serde's"
            );
        }
    }

    #[test]
    fn a_report_with_fixes_is_written_as_serde_writes_it() {
        use crate::diagnostics::fixes::{FileFixes, FixStatus, FixView, Repair, TextEdit};
        use crate::diagnostics::{Position, Safety};
        let mut report = report(3, true);
        let first = &report.findings[0].diagnostic;
        let at = |offset| Position {
            line: 2,
            column: offset + 1,
            offset,
        };
        report.fixes = FileFixes::new(vec![FixView {
            repairs: vec![Repair {
                code: first.code,
                pointer: first.pointer.clone(),
                message: first.message.clone(),
            }],
            safety: Safety::Safe,
            title: "declare \"X\" in extensionsUsed".into(),
            edits: vec![TextEdit {
                start: at(4),
                end: at(4),
                content: ",\n    \"X\"".into(),
            }],
            status: FixStatus::Available,
        }]);
        let mut written = Vec::new();
        write_pretty(&mut written, &report).unwrap();
        let expected = report_pretty(&report) + "\n";
        assert_eq!(String::from_utf8(written).unwrap(), expected);
        assert!(expected.contains("\"fixable\": 1"), "{expected}");
    }
}
