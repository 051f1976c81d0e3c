//! Human-readable report: one line per finding, `file:line:column: severity CODE message`,
//! then the pointer; a summary line at the end. Colour (ANSI, via anstyle) only when asked.

use super::{display_path, Options};
use crate::asset::Container;
use crate::diagnostics::Severity;
use crate::validate::FileReport;
use anstyle::{AnsiColor, Style};
use std::fmt::Write;

/// Renders findings of every report, then a summary, without colour.
pub fn render(reports: &[FileReport]) -> String {
    render_with(reports, &Options::default())
}

fn severity_style(severity: Severity) -> Style {
    let color = match severity {
        Severity::Error => AnsiColor::Red,
        Severity::Warning => AnsiColor::Yellow,
        Severity::Info => AnsiColor::Cyan,
        Severity::Hint => AnsiColor::Blue,
    };
    Style::new().fg_color(Some(color.into())).bold()
}

/// Renders with the given options: colour, and no summary line when quiet.
pub fn render_with(reports: &[FileReport], options: &Options) -> String {
    let paint = |style: Style, text: &str| {
        if options.color {
            format!("{style}{text}{style:#}")
        } else {
            text.to_string()
        }
    };
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
            let _ = writeln!(
                out,
                "{}: {} {}: {}",
                paint(Style::new().bold(), &place),
                paint(severity_style(d.severity), d.severity.as_str()),
                paint(Style::new().bold(), d.code),
                d.message
            );
            if !d.pointer.is_empty() {
                let _ = writeln!(
                    out,
                    "    {}",
                    paint(Style::new().dimmed(), &format!("at {}", d.pointer))
                );
            }
        }
        if report.truncated {
            let _ = writeln!(out, "{file}: {}", super::omitted_note(report.omitted));
        }
        let c = report.counts;
        for (t, n) in totals
            .iter_mut()
            .zip([c.errors, c.warnings, c.infos, c.hints])
        {
            *t += n;
        }
    }
    if options.quiet {
        return out;
    }
    out += &summary(reports.len(), totals);
    out
}

/// The closing line: files checked and findings per severity (`totals`: errors, warnings,
/// infos, hints).
pub fn summary(files: usize, totals: [usize; 4]) -> String {
    format!(
        "{files} file{} checked: {} error{}, {} warning{}, {} info, {} hint{}\n",
        if files == 1 { "" } else { "s" },
        totals[0],
        if totals[0] == 1 { "" } else { "s" },
        totals[1],
        if totals[1] == 1 { "" } else { "s" },
        totals[2],
        totals[3],
        if totals[3] == 1 { "" } else { "s" },
    )
}
