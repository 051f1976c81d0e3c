//! Diagnostics: what a finding is (code, severity, message, JSON pointer), the codes that the
//! loader and the schema check own, and the registry that lists every code velvet can emit.
//!
//! Rules declare their own codes next to their logic (see `crate::rules`); `all_codes` gathers
//! them with the loader's and the schema check's into the one list that `velvet codes`, the
//! codes table in docs/codes.md and the SARIF rule list are generated from.

pub mod codes;
pub mod fixes;
pub mod settings;

use serde::Serialize;
use std::fmt;

pub use fixes::Safety;
pub use settings::{FailOn, Settings};

/// Severity, numbered as in the Khronos glTF-Validator report (0 error … 3 hint).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Error = 0,
    Warning = 1,
    Info = 2,
    Hint = 3,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Info => "info",
            Severity::Hint => "hint",
        }
    }

    pub fn parse(text: &str) -> Option<Severity> {
        match text {
            "error" => Some(Severity::Error),
            "warning" => Some(Severity::Warning),
            "info" => Some(Severity::Info),
            "hint" => Some(Severity::Hint),
            _ => None,
        }
    }
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for Severity {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_u8(*self as u8)
    }
}

/// A code velvet can emit: its name, default severity, one line of documentation, and whether
/// `velvet validate --fix` repairs its findings (and how safely).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Code {
    pub name: &'static str,
    pub severity: Severity,
    pub doc: &'static str,
    /// `Some` when a fixer repairs the code's findings (see `crate::fix`, whose table of
    /// fixers a test holds to this).
    pub fix: Option<Safety>,
}

impl Code {
    pub const fn new(name: &'static str, severity: Severity, doc: &'static str) -> Code {
        Code {
            name,
            severity,
            doc,
            fix: None,
        }
    }

    /// The same code, repaired by a fix of `safety`.
    pub const fn fixable(self, safety: Safety) -> Code {
        Code {
            fix: Some(safety),
            ..self
        }
    }

    /// How the code is fixed, as `velvet codes` and docs/codes.md say it: `safe`, `unsafe`
    /// or `-`.
    pub fn fix_label(&self) -> &'static str {
        self.fix.map_or("-", Safety::as_str)
    }
}

/// One finding in one file. `pointer` is an RFC 6901 JSON pointer into the glTF JSON
/// (empty for the whole file).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    pub code: &'static str,
    pub message: String,
    pub severity: Severity,
    pub pointer: String,
    /// Where in the JSON text the finding stands when no pointer can name it (a syntax error).
    #[serde(skip)]
    pub position: Option<Position>,
}

/// A place in a JSON text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Position {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// Byte offset in the JSON text.
    pub offset: usize,
}

impl Diagnostic {
    pub fn new(code: &Code, pointer: impl Into<String>, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            code: code.name,
            message: message.into(),
            severity: code.severity,
            pointer: pointer.into(),
            position: None,
        }
    }

    /// The same finding placed at `position` in the JSON text.
    pub fn at(self, position: Position) -> Diagnostic {
        Diagnostic {
            position: Some(position),
            ..self
        }
    }
}
