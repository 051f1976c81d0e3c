//! Printing a run: text for people and JSON for tools (the same values, serialised). The text
//! gives one line per file (what happened, how many materials, textures and warnings) and the
//! summary; [`Detail::Verbose`] (`--verbose`, `--report`) adds the materials with something to
//! say and their notes, and a dry run every material with its edits; [`Detail::Quiet`] (`-q`)
//! prints failed files only. The words `velvet bake` shares ([`files_line`], [`added`]) are in
//! [`crate::output::summary`].

use super::batch::{FileOutcome, FileResult, RunReport, Summary};
use crate::migrate::material::MaterialPlan;
use crate::migrate::note::Level;
use crate::output::result::Account;
use crate::output::summary::{added, files_line, plural, Detail};
use crate::report::escape::push_line;
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
    let verdict = match (m.migrated(), m.verdict) {
        (true, Some(v)) => format!("; verdict {}", v.describe()),
        _ => String::new(),
    };
    format!("material {}{name}: {what}{verdict}", m.index)
}

fn file_line(f: &FileResult, dry_run: bool) -> String {
    let target = match &f.output {
        Some(o) if o != &f.input => format!(" → {}", o.display()),
        _ => String::new(),
    };
    let migrated = f.detail.materials.iter().filter(|m| m.migrated()).count();
    let warnings = f.detail.warnings();
    let (textures, bytes) = f.added();
    let counts = format!(
        " ({}, {}, {})",
        plural(migrated, "material", "materials"),
        added(
            textures,
            bytes,
            matches!(f.outcome, FileOutcome::Planned { .. })
        ),
        plural(warnings, "warning", "warnings")
    );
    let warned = if warnings > 0 {
        format!(" ({})", plural(warnings, "warning", "warnings"))
    } else {
        String::new()
    };
    let status = match &f.outcome {
        FileOutcome::Changed => format!("migrated{counts}"),
        FileOutcome::Copied => format!("nothing to migrate, copied as it is{warned}"),
        FileOutcome::Untouched => format!("nothing to migrate, left as it is{warned}"),
        FileOutcome::Planned { changes: true } => format!("would change{counts}"),
        FileOutcome::Planned { changes: false } if dry_run => format!("nothing to change{warned}"),
        FileOutcome::Planned { .. } => "planned".to_string(),
        FileOutcome::Failed { error } => format!("FAILED: {error}"),
    };
    format!("{}{target}: {status}", f.input.display())
}

/// The text report of one file. `plan` lists every material with its edits (a dry run);
/// otherwise only the materials something is said about are listed.
pub fn file_text(f: &FileResult, plan: bool) -> String {
    let mut out = String::new();
    push_line(&mut out, &file_line(f, plan));
    for m in &f.detail.materials {
        if !plan && m.notes.is_empty() {
            continue;
        }
        push_line(&mut out, &format!("  {}", material_line(m)));
        for note in &m.notes {
            push_line(
                &mut out,
                &format!("    {}: {}", level(note.level()), note.message()),
            );
        }
        if plan {
            for edit in &m.edits {
                push_line(&mut out, &format!("    {edit}"));
            }
            for bake in &m.bakes {
                push_line(&mut out, &format!("    {bake}"));
            }
        }
    }
    for note in &f.detail.notes {
        push_line(
            &mut out,
            &format!("  {}: {}", level(note.level()), note.message()),
        );
    }
    if plan {
        for edit in f.detail.edits.iter().chain(&f.detail.bake_edits) {
            push_line(&mut out, &format!("  {edit}"));
        }
        for copy in &f.detail.copies {
            push_line(
                &mut out,
                &format!("  copy {} → {}", copy.from.display(), copy.to.display()),
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
pub fn summary_text(summary: &Summary, dry_run: bool) -> String {
    let t = &summary.totals;
    let done = if dry_run { "would change" } else { "migrated" };
    let mut out = files_line(t.files, t.done(), done, t.unchanged, t.failed);
    let _ = writeln!(out, "; {}", added(t.textures_added, t.bytes_added, dry_run));
    let s = summary;
    let _ = write!(out, "materials: {} migrated", s.materials_migrated);
    if !s.conversions.is_empty() {
        let _ = write!(out, " ({})", counted(&s.conversions, |c| c.as_str()));
    }
    let skipped: usize = s.skipped.values().sum();
    let _ = write!(out, "; {skipped} skipped");
    if skipped > 0 {
        let _ = write!(out, " ({})", counted(&s.skipped, |k| k.as_str()));
    }
    let _ = writeln!(out, "; {}", plural(t.warnings, "warning", "warnings"));
    let v = &s.verdicts;
    if v.total() > 0 {
        let _ = writeln!(
            out,
            "verdicts: {} same, {} close, {} visible",
            v.same, v.close, v.visible
        );
    }
    out
}

/// The whole run as text: a line per file (with its materials and notes when verbose, its
/// plan in a dry run), then the summary; quiet, failed files only.
pub fn text(report: &RunReport, detail: Detail) -> String {
    let mut out = String::new();
    for f in &report.files {
        let failed = matches!(f.outcome, FileOutcome::Failed { .. });
        match detail {
            Detail::Quiet if !failed => {}
            Detail::Quiet | Detail::Normal if !report.dry_run => {
                push_line(&mut out, &file_line(f, report.dry_run));
            }
            _ => out += &file_text(f, report.dry_run),
        }
    }
    if detail != Detail::Quiet {
        out += &summary_text(&report.summary, report.dry_run);
    }
    out
}

/// The whole run as pretty JSON.
pub fn json(report: &RunReport) -> String {
    let mut out = serde_json::to_string_pretty(report).expect("reports serialise");
    out.push('\n');
    out
}
