//! GitHub Actions workflow commands: one `::error`, `::warning` or `::notice` line per finding,
//! which the Actions runner turns into annotations on the changed files.
//!
//! `file` is the path relative to the working directory (the checkout, in a workflow); `line`
//! and `col` are given for a .gltf finding whose pointer names a value (a .glb has no lines:
//! its byte offset goes into the message instead). Properties and message are escaped as the
//! runner unescapes them: `%`, CR and LF everywhere, and `:` and `,` in properties too. What
//! came from the asset is first passed through [`super::escape::terminal`], so no character of
//! it can end the command's line or act in the log viewer (ESC), whatever the runner unescapes.
//!
//! Each file's missing resources are one annotation (see [`super::Listing`]), and these come
//! after every other finding of the run: GitHub shows only a step's first ten error
//! annotations, and they go to the findings a checkout with every resource would still have.

use super::display_path;
use super::escape::terminal;
use crate::asset::Container;
use crate::diagnostics::Severity;
use crate::validate::{FileReport, Finding};
use std::fmt::Write;

/// Escapes a command's message.
pub fn escape_data(text: &str) -> String {
    text.replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A")
}

/// Escapes a command property's value.
pub fn escape_property(text: &str) -> String {
    escape_data(text).replace(':', "%3A").replace(',', "%2C")
}

fn command(severity: Severity) -> &'static str {
    match severity {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Info | Severity::Hint => "notice",
    }
}

/// One workflow command per finding, and a notice for each file whose findings were capped;
/// the entries for missing resources last.
pub fn render(reports: &[FileReport]) -> String {
    let mut out = String::new();
    let mut missing = String::new();
    for report in reports {
        let (file, last) = render_file(report);
        out += &file;
        missing += &last;
    }
    out + &missing
}

/// One file's workflow commands: those of its findings but the missing resources, and the
/// one for its missing resources (empty when none is missing), which the run lists last.
pub fn render_file(report: &FileReport) -> (String, String) {
    let listing = super::listing(report);
    let file = escape_property(&terminal(&display_path(&report.path)));
    let mut out = String::new();
    for f in listing.others {
        command_line(&mut out, &file, report, f);
    }
    if report.truncated() {
        let _ = writeln!(
            out,
            "::notice file={file},title=velvet::{}",
            super::omitted_note(report.omitted)
        );
    }
    let mut missing = String::new();
    if let Some(f) = &listing.missing {
        command_line(&mut missing, &file, report, f);
    }
    (out, missing)
}

/// The workflow command of one finding: a .gltf finding's line and column as properties, a
/// .glb finding's byte offset and the pointer in the message.
fn command_line(out: &mut String, file: &str, report: &FileReport, f: &Finding) {
    let d = &f.diagnostic;
    let mut properties = format!("file={file}");
    let mut message = d.message.clone();
    let mut at: Vec<String> = Vec::new();
    if !d.pointer.is_empty() {
        at.push(d.pointer.clone());
    }
    match (f.position, report.container) {
        (Some(p), Some(Container::Glb)) => {
            at.push(format!("byte {}", report.json_offset + p.offset))
        }
        (Some(p), _) => {
            let _ = write!(properties, ",line={},col={}", p.line, p.column);
        }
        (None, _) => {}
    }
    if !at.is_empty() {
        let _ = write!(message, " (at {})", at.join(", "));
    }
    let _ = writeln!(
        out,
        "::{} {properties},title={}::{}",
        command(d.severity),
        escape_property(d.code),
        escape_data(&terminal(&message))
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_percent_first_then_newlines_and_property_separators() {
        assert_eq!(escape_data("50% a\r\nb: c, d"), "50%25 a%0D%0Ab: c, d");
        assert_eq!(escape_property("a:b,c%d\ne"), "a%3Ab%2Cc%25d%0Ae");
        assert_eq!(
            escape_property("%3A"),
            "%253A",
            "an escape sequence in the input stays literal"
        );
    }
}
