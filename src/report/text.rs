//! Human-readable report: one line per finding, `file:line:column: severity CODE message`,
//! then the pointer; a summary line at the end. Colour (ANSI, via anstyle) only when asked.
//! Paths, messages and pointers hold an asset's text and are escaped for the terminal
//! ([`super::escape`]): they cannot start a line of their own nor send a control sequence.
//!
//! A file's findings are printed in file order, and a finding (code and message) found more
//! than once in a file is printed once, followed by a line with how many more there are and
//! where the first [`SHOWN`] of them stand (see [`fold`]); `--no-fold` prints each one. A
//! file's missing resources are one entry after its other findings (see [`super::Listing`]).

use super::escape::terminal;
use super::{display_path, fold, Options};
use crate::asset::Container;
use crate::diagnostics::fixes::{FileFixes, FixStatus, FixView};
use crate::diagnostics::{Safety, Severity};
use crate::validate::{FileReport, Finding};
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
    let mut fix_totals = FixTotals::default();
    for report in reports {
        fix_totals.add(&report.fixes);
        let file = terminal(&display_path(&report.path)).into_owned();
        let place = |f: &Finding| match (f.position, report.container) {
            (Some(p), Some(Container::Glb)) => {
                format!("{file}: byte {}", report.json_offset + p.offset)
            }
            (Some(p), _) => format!("{file}:{}:{}", p.line, p.column),
            (None, _) => file.clone(),
        };
        // --no-fold prints every finding as the rules gave it, each missing file too.
        let listing = if options.no_fold {
            super::Listing {
                others: report.findings.iter().collect(),
                missing: None,
            }
        } else {
            super::listing(report)
        };
        let sorted = fold::by_position_of(&listing.others);
        let mut groups = if options.no_fold {
            sorted
                .iter()
                .map(|f| fold::Group {
                    first: f,
                    rest: Vec::new(),
                })
                .collect()
        } else {
            fold::fold(&sorted)
        };
        // The missing files come last, whatever their place in the file.
        groups.extend(listing.missing.as_ref().map(|first| fold::Group {
            first,
            rest: Vec::new(),
        }));
        for group in groups {
            let d = &group.first.diagnostic;
            let _ = writeln!(
                out,
                "{}: {} {}: {}",
                paint(Style::new().bold(), &place(group.first)),
                paint(severity_style(d.severity), d.severity.as_str()),
                paint(Style::new().bold(), d.code),
                terminal(&d.message)
            );
            if !d.pointer.is_empty() {
                let _ = writeln!(
                    out,
                    "    {}",
                    paint(
                        Style::new().dimmed(),
                        &format!("at {}", terminal(&d.pointer))
                    )
                );
            }
            if let Some(fix) = report.fixes.fix_of(d) {
                if fix.status != FixStatus::Applied {
                    let _ = writeln!(
                        out,
                        "    {}",
                        paint(Style::new().dimmed(), &terminal(&fix_line(fix)))
                    );
                }
            }
            if !group.rest.is_empty() {
                let line = folded_line(&group.rest, report.container, report.json_offset);
                let _ = writeln!(
                    out,
                    "    {}",
                    paint(Style::new().dimmed(), &terminal(&line))
                );
            }
        }
        if report.truncated() {
            let _ = writeln!(out, "{file}: {}", super::omitted_note(report.omitted));
        }
        if !options.fix_only {
            out += &fixes_done(&file, &report.fixes);
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
    out += &summary_with(reports.len(), totals, &fix_totals);
    out
}

/// The closing line with the run's fixes at its end (see [`FixTotals::summary`]).
pub fn summary_with(files: usize, totals: [usize; 4], fixes: &FixTotals) -> String {
    let line = summary(files, totals);
    format!("{}{}\n", line.trim_end_matches('\n'), fixes.summary())
}

/// The line under a finding that a fix repairs: how safe the fix is and what it does, or why
/// it was not applied.
fn fix_line(fix: &FixView) -> String {
    match (&fix.status, fix.safety) {
        (FixStatus::Refused(reason), safety) => format!(
            "fix ({}) not applied: {}: {reason}",
            safety.as_str(),
            fix.title
        ),
        (_, Safety::Safe) => format!("fix (safe, --fix): {}", fix.title),
        (_, Safety::Unsafe) => format!("fix (unsafe, --fix --unsafe-fixes): {}", fix.title),
    }
}

/// A file's lines about the fixes applied: each with the findings it repaired (an unsafe one
/// said so).
fn fixes_done(file: &str, fixes: &FileFixes) -> String {
    let mut out = String::new();
    for fix in fixes.fixes() {
        let codes: Vec<&str> = fix.repairs.iter().map(|r| r.code).collect();
        let mut codes_list: Vec<&str> = Vec::new();
        for c in codes {
            if !codes_list.contains(&c) {
                codes_list.push(c);
            }
        }
        let what = format!(
            "{} ({}, {} finding{} of {})",
            fix.title,
            fix.safety.as_str(),
            fix.repairs.len(),
            if fix.repairs.len() == 1 { "" } else { "s" },
            codes_list.join(", ")
        );
        match &fix.status {
            FixStatus::Applied => {
                let _ = writeln!(out, "{file}: fixed: {}", terminal(&what));
            }
            // A refused fix is said under its finding, which stays.
            FixStatus::Refused(_) | FixStatus::Available => {}
        }
    }
    out
}

/// A run's fixes counted by finding: available safe and unsafe, and applied.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FixTotals {
    pub safe: usize,
    pub unsafe_: usize,
    pub applied: usize,
}

impl FixTotals {
    pub fn add(&mut self, fixes: &FileFixes) {
        self.safe += fixes.available(Safety::Safe);
        self.unsafe_ += fixes.available(Safety::Unsafe);
        self.applied += fixes.applied();
    }

    /// What ends the summary line when there are fixes: how many findings were fixed, and how
    /// many more a fix repairs ("; N fixable with --fix"); nothing when there are none.
    pub fn summary(&self) -> String {
        let mut out = String::new();
        if self.applied > 0 {
            out += &format!("; {} fixed", self.applied);
        }
        match (self.safe, self.unsafe_) {
            (0, 0) => {}
            (s, 0) => out += &format!("; {s} fixable with --fix"),
            (0, u) => out += &format!("; {u} fixable with --fix --unsafe-fixes"),
            (s, u) => out += &format!("; {s} fixable with --fix ({u} more with --unsafe-fixes)"),
        }
        out
    }
}

/// Positions listed on a folded entry's line before it ends in `…`.
pub const SHOWN: usize = 5;

/// The line under a folded entry: how many more findings of its code the file has, and where
/// the first [`SHOWN`] of them stand (`line:column`, `byte N` in a .glb, or the pointer of a
/// finding without a position).
fn folded_line(rest: &[&Finding], container: Option<Container>, json_offset: usize) -> String {
    let mut places: Vec<String> = rest
        .iter()
        .take(SHOWN)
        .map(|f| match (f.position, container) {
            (Some(p), Some(Container::Glb)) => format!("byte {}", json_offset + p.offset),
            (Some(p), _) => format!("{}:{}", p.line, p.column),
            (None, _) if !f.diagnostic.pointer.is_empty() => f.diagnostic.pointer.clone(),
            (None, _) => "the whole file".to_string(),
        })
        .collect();
    if rest.len() > SHOWN {
        places.push("…".to_string());
    }
    format!(
        "and {} more at {} ({} in all; --no-fold prints each)",
        rest.len(),
        places.join(", "),
        rest.len() + 1
    )
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::position::Position;
    use crate::diagnostics::Diagnostic;
    use crate::validate::Counts;

    fn finding(code: &'static str, pointer: &str, at: Option<(usize, usize, usize)>) -> Finding {
        Finding {
            diagnostic: Diagnostic {
                code,
                message: format!("{code} found"),
                severity: Severity::Warning,
                pointer: pointer.to_string(),
                position: None,
            },
            position: at.map(|(line, column, offset)| Position {
                line,
                column,
                offset,
            }),
        }
    }

    fn report(container: Container, findings: Vec<Finding>) -> FileReport {
        FileReport {
            path: "x/a.glb".into(),
            container: Some(container),
            json_offset: 20,
            counts: Counts {
                warnings: findings.len(),
                ..Counts::default()
            },
            findings,
            omitted: 0,
            info: None,
            missing: Default::default(),
            fixes: Default::default(),
            rule_spans: Vec::new(),
        }
    }

    #[test]
    fn a_folded_glb_entry_lists_byte_offsets_and_pointers_of_findings_without_a_position() {
        let findings: Vec<Finding> = (0..7)
            .map(|i| finding("A", &format!("/p/{i}"), Some((1, 1, 100 - i * 10))))
            .chain([finding("A", "/absent", None), finding("B", "", None)])
            .collect();
        let text = render(&[report(Container::Glb, findings)]);
        assert_eq!(
            text,
            "x/a.glb: warning A: A found\n    at /absent\n\
             \x20   and 7 more at byte 60, byte 70, byte 80, byte 90, byte 100, … (8 in all; --no-fold prints each)\n\
             x/a.glb: warning B: B found\n\
             1 file checked: 0 errors, 9 warnings, 0 info, 0 hints\n"
        );
        let short = vec![
            finding("A", "/p/1", Some((3, 4, 30))),
            finding("A", "/p/0", Some((2, 5, 10))),
        ];
        let text = render(&[report(Container::Gltf, short)]);
        assert_eq!(
            text,
            "x/a.glb:2:5: warning A: A found\n    at /p/0\n    and 1 more at 3:4 (2 in all; --no-fold prints each)\n\
             1 file checked: 0 errors, 2 warnings, 0 info, 0 hints\n"
        );
    }
}
