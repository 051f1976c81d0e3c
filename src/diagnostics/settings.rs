//! What a run does with diagnostics once the rules have produced them: codes to ignore,
//! severity overrides, the issue cap, and the severity at which a file fails.

use super::Severity;
use std::collections::{BTreeMap, BTreeSet};

/// The lowest severity that makes a file fail (exit status 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FailOn {
    #[default]
    Error,
    Warning,
    Info,
    /// Any finding fails, hints included.
    Hint,
}

impl FailOn {
    pub fn fails(self, severity: Severity) -> bool {
        let limit = match self {
            FailOn::Error => Severity::Error,
            FailOn::Warning => Severity::Warning,
            FailOn::Info => Severity::Info,
            FailOn::Hint => Severity::Hint,
        };
        severity <= limit
    }
}

#[derive(Debug, Clone, Default)]
pub struct Settings {
    /// Codes dropped from reports.
    pub ignore: BTreeSet<String>,
    /// Per-code severity replacing the default.
    pub severity_overrides: BTreeMap<String, Severity>,
    /// Cap on messages per file; the report says `truncated` when it applied.
    pub max_issues: Option<usize>,
    pub fail_on: FailOn,
    /// Whether the checks that read accessor data and image bytes are left out (`--no-data`,
    /// `data = false`): the JSON-level checks alone, for hooks that want them fast.
    pub skip_data: bool,
}
