//! The Khronos glTF-Validator report shape: `uri`, `mimeType`, `validatorVersion`,
//! `issues {numErrors, numWarnings, numInfos, numHints, messages[{code, message, severity,
//! pointer}], truncated}` and `info`. Severities are numbers (0 error … 3 hint).

use super::display_path;
use crate::validate::FileReport;
use serde_json::{json, Value};

/// One file's report as a JSON value.
pub fn report_value(report: &FileReport) -> Value {
    let messages: Vec<Value> = report
        .findings
        .iter()
        .map(|f| {
            let d = &f.diagnostic;
            json!({ "code": d.code, "message": d.message, "severity": d.severity as u8, "pointer": d.pointer })
        })
        .collect();
    let c = report.counts;
    let mut value = json!({
        "uri": display_path(&report.path),
        "mimeType": report.container.map(|c| c.mime_type()),
        "validatorVersion": format!("velvet {}", env!("CARGO_PKG_VERSION")),
        "issues": {
            "numErrors": c.errors,
            "numWarnings": c.warnings,
            "numInfos": c.infos,
            "numHints": c.hints,
            "messages": messages,
            "truncated": report.truncated(),
        },
    });
    if let Some(info) = &report.info {
        value["info"] = json!({
            "version": info.version,
            "generator": info.generator,
            "extensionsUsed": info.extensions_used,
            "extensionsRequired": info.extensions_required,
            "materialCount": info.material_count,
            "sheenMaterialCount": info.sheen_material_count,
            "fuzzMaterialCount": info.fuzz_material_count,
        });
    }
    value
}

/// One report as an object; several as an array.
pub fn render(reports: &[FileReport]) -> String {
    let value = match reports {
        [one] => report_value(one),
        many => Value::Array(many.iter().map(report_value).collect()),
    };
    let mut text = serde_json::to_string_pretty(&value).expect("a report serialises");
    text.push('\n');
    text
}

/// One compact JSON report per line.
pub fn render_lines(reports: &[FileReport]) -> String {
    reports
        .iter()
        .map(|r| report_value(r).to_string() + "\n")
        .collect()
}
