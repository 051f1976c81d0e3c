//! What a report says about fixes: how safe a fix is, the text edits it makes and whether it
//! was applied. The fixes themselves are planned by `crate::fix`; these are the plain values
//! every report format reads (the planner's one plan, seen from the report).

use super::{Diagnostic, Position};

/// How much a fix may change an asset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Safety {
    /// Cannot change how a conforming loader renders the asset: applied by `--fix`.
    Safe,
    /// Changes the asset's meaning in the way its finding implies: applied only with
    /// `--unsafe-fixes`.
    Unsafe,
}

impl Safety {
    pub fn as_str(self) -> &'static str {
        match self {
            Safety::Safe => "safe",
            Safety::Unsafe => "unsafe",
        }
    }
}

/// One replacement in the file as it was read (of a .glb, in its JSON chunk): the bytes from
/// `start` to `end` are replaced by `content` (an insertion when they are equal, a deletion
/// when `content` is empty). Positions are 1-based lines and character columns of the JSON
/// text, with byte offsets in the file (or chunk), a byte-order mark included.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextEdit {
    pub start: Position,
    pub end: Position,
    pub content: String,
}

/// What became of a fix in this run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FixStatus {
    /// Planned and checked, not applied (a run without `--fix`, or an unsafe fix without
    /// `--unsafe-fixes`).
    Available,
    /// Written into the file (or, with `--diff`, shown).
    Applied,
    /// Not applied, and why (the fixed file would still have the finding, or another one).
    Refused(String),
}

/// A finding a fix repairs: its code and pointer in the document as read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Repair {
    pub code: &'static str,
    pub pointer: String,
    pub message: String,
}

/// One fix as a report shows it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FixView {
    /// The findings it repairs (one fix may repair several: declaring an extension repairs its
    /// UNDECLARED_EXTENSION and its UNUSED_EXTENSION_REQUIRED).
    pub repairs: Vec<Repair>,
    pub safety: Safety,
    /// What it does, in a few words ("declare KHR_materials_sheen in extensionsUsed").
    pub title: String,
    /// Its edits of the JSON text as read (of a .glb, its JSON chunk's text without the
    /// chunk's padding: `--fix` frames the edited text again). No two fixes of a file touch
    /// the same text.
    pub edits: Vec<TextEdit>,
    pub status: FixStatus,
}

impl FixView {
    /// Whether this fix repairs the finding with `code` at `pointer`.
    pub fn repairs(&self, code: &str, pointer: &str) -> bool {
        self.repairs
            .iter()
            .any(|r| r.code == code && r.pointer == pointer)
    }
}

/// A file's fixes: every fix planned for it, and whether the file was (or, with `--diff`,
/// would be) changed, with the unified diff when one was asked for.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FileFixes {
    /// The fixes; set with [`FileFixes::new`], which indexes them by the findings they repair.
    fixes: Vec<FixView>,
    /// The fixes of each finding, by a hash of its key ([`finding_key`]): a report looks each
    /// finding up, and a document may have a fix per material. The fixes under one hash are
    /// told apart by their repairs.
    by_finding: foldhash::HashMap<u64, Vec<usize>>,
    /// True when the fixes changed the file's bytes (written, or shown by `--diff`).
    pub changed: bool,
    /// With `--diff`: the change as a unified diff.
    pub diff: Option<String>,
    /// Why the fixed file could not be written, when it could not.
    pub write_error: Option<String>,
}

/// A finding's key: its code, pointer and message (findings of one code at one pointer differ
/// by their message: a primitive's material may have several textures that read a missing set).
fn finding_key(code: &str, pointer: &str, message: &str) -> u64 {
    use std::hash::BuildHasher;
    foldhash::fast::FixedState::with_seed(0).hash_one((code, pointer, message))
}

impl FileFixes {
    pub fn new(fixes: Vec<FixView>) -> FileFixes {
        let mut by_finding: foldhash::HashMap<u64, Vec<usize>> = Default::default();
        for (i, fix) in fixes.iter().enumerate() {
            for r in &fix.repairs {
                let at = by_finding
                    .entry(finding_key(r.code, &r.pointer, &r.message))
                    .or_default();
                if at.last() != Some(&i) {
                    at.push(i);
                }
            }
        }
        FileFixes {
            fixes,
            by_finding,
            ..Default::default()
        }
    }

    /// Every fix planned for the file.
    pub fn fixes(&self) -> &[FixView] {
        &self.fixes
    }

    /// Marks every applied fix refused for `reason` (the fixed file could not be written).
    pub fn refuse_applied(&mut self, reason: &str) {
        for fix in &mut self.fixes {
            if fix.status == FixStatus::Applied {
                fix.status = FixStatus::Refused(reason.to_string());
            }
        }
        self.changed = false;
    }

    /// Findings that an available fix of `safety` repairs (each finding once).
    pub fn available(&self, safety: Safety) -> usize {
        self.fixes
            .iter()
            .filter(|f| f.safety == safety && f.status == FixStatus::Available)
            .map(|f| f.repairs.len())
            .sum()
    }

    /// The available fix that repairs the finding `d`, if any.
    pub fn for_finding(&self, d: &Diagnostic) -> Option<&FixView> {
        self.fix_of(d).filter(|f| f.status == FixStatus::Available)
    }

    /// The fix planned for the finding `d`, whatever became of it.
    pub fn fix_of(&self, d: &Diagnostic) -> Option<&FixView> {
        self.index_of(d).map(|i| &self.fixes[i])
    }

    /// The place in [`FileFixes::fixes`] of the fix planned for the finding `d`.
    pub fn index_of(&self, d: &Diagnostic) -> Option<usize> {
        if self.by_finding.is_empty() {
            return None;
        }
        // The first fix that repairs it.
        self.by_finding
            .get(&finding_key(d.code, &d.pointer, &d.message))?
            .iter()
            .copied()
            .find(|&i| {
                self.fixes[i]
                    .repairs
                    .iter()
                    .any(|r| r.code == d.code && r.pointer == d.pointer && r.message == d.message)
            })
    }

    /// Findings repaired by applied fixes.
    pub fn applied(&self) -> usize {
        self.fixes
            .iter()
            .filter(|f| f.status == FixStatus::Applied)
            .map(|f| f.repairs.len())
            .sum()
    }
}
