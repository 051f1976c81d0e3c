//! The Khronos glTF-Validator report shape: `uri`, `mimeType`, `validatorVersion`,
//! `issues {numErrors, numWarnings, numInfos, numHints, messages[{code, message, severity,
//! pointer}], truncated}` and `info`. Severities are numbers (0 error … 3 hint).
//!
//! The shape is a set of borrowing structs serialised straight to text: a report with tens of
//! thousands of findings is written without first being copied into a JSON tree.

use super::display_path;
use crate::validate::{AssetInfo, FileReport};
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

const VALIDATOR_VERSION: &str = concat!("velvet ", env!("CARGO_PKG_VERSION"));

fn shape(report: &FileReport) -> ReportShape<'_> {
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
            messages: report
                .findings
                .iter()
                .map(|f| MessageShape {
                    code: f.diagnostic.code,
                    message: &f.diagnostic.message,
                    severity: f.diagnostic.severity as u8,
                    pointer: &f.diagnostic.pointer,
                })
                .collect(),
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
    }
}

/// One file's report, pretty-printed (two-space indent, no final newline).
pub fn report_pretty(report: &FileReport) -> String {
    serde_json::to_string_pretty(&shape(report)).expect("a report serialises")
}

/// One report as an object, pretty-printed and followed by a newline, written straight to
/// `out` (a report of tens of thousands of findings is never held as text).
pub fn write_pretty(out: &mut impl std::io::Write, report: &FileReport) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *out, &shape(report))?;
    out.write_all(b"\n")
}

/// One report as an object; several as an array.
pub fn render(reports: &[FileReport]) -> String {
    let mut text = match reports {
        [one] => report_pretty(one),
        many => serde_json::to_string_pretty(&many.iter().map(shape).collect::<Vec<_>>())
            .expect("a report serialises"),
    };
    text.push('\n');
    text
}

/// One compact JSON report per line.
pub fn render_lines(reports: &[FileReport]) -> String {
    reports
        .iter()
        .map(|r| serde_json::to_string(&shape(r)).expect("a report serialises") + "\n")
        .collect()
}
