//! Human-readable report: one line per finding, `file:line:column: severity CODE message`,
//! then the pointer; a summary line at the end.

use super::display_path;
use crate::asset::Container;
use crate::validate::FileReport;
use std::fmt::Write;

/// Renders findings of every report, then a summary.
pub fn render(reports: &[FileReport]) -> String {
    let mut out = String::new();
    let mut totals = [0usize; 4];
    for report in reports {
        let file = display_path(&report.path);
        for f in &report.findings {
            let d = &f.diagnostic;
            let place = match (f.position, report.container) {
                (Some(p), Some(Container::Glb)) => {
                    format!("{file}: byte {}", report.json_offset + p.offset)
                }
                (Some(p), _) => format!("{file}:{}:{}", p.line, p.column),
                (None, _) => file.clone(),
            };
            let _ = writeln!(out, "{place}: {} {}: {}", d.severity, d.code, d.message);
            if !d.pointer.is_empty() {
                let _ = writeln!(out, "    at {}", d.pointer);
            }
        }
        if report.truncated {
            let _ = writeln!(out, "{file}: further issues not shown (--max-issues)");
        }
        let c = report.counts;
        for (t, n) in totals
            .iter_mut()
            .zip([c.errors, c.warnings, c.infos, c.hints])
        {
            *t += n;
        }
    }
    let files = reports.len();
    let _ = writeln!(
        out,
        "{files} file{} checked: {} error{}, {} warning{}, {} info, {} hint{}",
        if files == 1 { "" } else { "s" },
        totals[0],
        if totals[0] == 1 { "" } else { "s" },
        totals[1],
        if totals[1] == 1 { "" } else { "s" },
        totals[2],
        totals[3],
        if totals[3] == 1 { "" } else { "s" },
    );
    out
}
