//! Printing a run: text for people and JSON for tools (the same values, serialised). The text
//! gives one line per file, the materials with something to say (in a dry run every material,
//! with its edits) and their notes, then the summary.

use super::batch::{FileOutcome, FileResult, RunReport, Summary};
use super::note::Level;
use super::plan::MaterialPlan;
use std::fmt::Write;

fn level(l: Level) -> &'static str {
    match l {
        Level::Info => "info",
        Level::Warning => "warning",
    }
}

fn material_line(m: &MaterialPlan) -> String {
    let name = m
        .name
        .as_deref()
        .map(|n| format!(" \"{n}\""))
        .unwrap_or_default();
    let what = if m.conversions.is_empty() {
        format!(
            "skipped: {}",
            m.skipped.map_or("nothing to do", |s| s.as_str())
        )
    } else {
        m.conversions
            .iter()
            .map(|c| c.as_str())
            .collect::<Vec<_>>()
            .join(", then ")
    };
    format!("material {}{name}: {what}", m.index)
}

fn file_line(f: &FileResult, dry_run: bool) -> String {
    let target = match &f.output {
        Some(o) if o != &f.input => format!(" → {}", o.display()),
        _ => String::new(),
    };
    let status = match &f.outcome {
        FileOutcome::Changed => "migrated".to_string(),
        FileOutcome::Copied => "nothing to migrate, copied as it is".to_string(),
        FileOutcome::Untouched => "nothing to migrate, left as it is".to_string(),
        FileOutcome::Planned { changes: true } => "would change".to_string(),
        FileOutcome::Planned { changes: false } if dry_run => "nothing to change".to_string(),
        FileOutcome::Planned { .. } => "planned".to_string(),
        FileOutcome::Failed { error } => format!("FAILED: {error}"),
    };
    format!("{}{target}: {status}", f.input.display())
}

/// The text report of one file. `plan` lists every material with its edits (a dry run);
/// otherwise only the materials something is said about are listed.
pub fn file_text(f: &FileResult, plan: bool) -> String {
    let mut out = file_line(f, plan);
    out.push('\n');
    for m in &f.materials {
        if !plan && m.notes.is_empty() {
            continue;
        }
        let _ = writeln!(out, "  {}", material_line(m));
        for note in &m.notes {
            let _ = writeln!(out, "    {}: {}", level(note.level()), note.message());
        }
        if plan {
            for edit in &m.edits {
                let _ = writeln!(out, "    {edit}");
            }
            for bake in &m.bakes {
                let _ = writeln!(out, "    {bake}");
            }
        }
    }
    for note in &f.notes {
        let _ = writeln!(out, "  {}: {}", level(note.level()), note.message());
    }
    if plan {
        for edit in &f.edits {
            let _ = writeln!(out, "  {edit}");
        }
        for copy in &f.copies {
            let _ = writeln!(
                out,
                "  copy {} → {}",
                copy.from.display(),
                copy.to.display()
            );
        }
    }
    out
}

fn counted<K: Copy>(
    items: &std::collections::BTreeMap<K, usize>,
    name: impl Fn(K) -> &'static str,
) -> String {
    items
        .iter()
        .map(|(k, n)| format!("{n} {}", name(*k)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The closing summary.
pub fn summary_text(s: &Summary, dry_run: bool) -> String {
    let plural = |n: usize, one: &str, many: &str| {
        if n == 1 {
            format!("{n} {one}")
        } else {
            format!("{n} {many}")
        }
    };
    let mut out = if dry_run {
        format!(
            "{}: {} would change, {} unchanged",
            plural(s.files, "file", "files"),
            s.would_change,
            s.unchanged
        )
    } else {
        format!(
            "{}: {} changed, {} unchanged",
            plural(s.files, "file", "files"),
            s.changed,
            s.unchanged
        )
    };
    let _ = writeln!(out, ", {} failed", s.failed);
    let _ = write!(out, "materials: {} migrated", s.materials_migrated);
    if !s.conversions.is_empty() {
        let _ = write!(out, " ({})", counted(&s.conversions, |c| c.as_str()));
    }
    let skipped: usize = s.skipped.values().sum();
    let _ = write!(out, "; {skipped} skipped");
    if skipped > 0 {
        let _ = write!(out, " ({})", counted(&s.skipped, |k| k.as_str()));
    }
    let _ = writeln!(out, "; {}", plural(s.warnings, "warning", "warnings"));
    out
}

/// The whole run as text: files that have something to say, then the summary.
pub fn text(report: &RunReport) -> String {
    let mut out = String::new();
    for f in &report.files {
        if f.materials.is_empty()
            && f.notes.is_empty()
            && !matches!(f.outcome, FileOutcome::Failed { .. })
            && !report.dry_run
        {
            continue;
        }
        out += &file_text(f, report.dry_run);
    }
    out += &summary_text(&report.summary, report.dry_run);
    out
}

/// The whole run as pretty JSON.
pub fn json(report: &RunReport) -> String {
    let mut out = serde_json::to_string_pretty(report).expect("reports serialise");
    out.push('\n');
    out
}
