//! velvet.toml: the project configuration for validation, where it is found, and how it
//! combines with the command line.
//!
//! A run looks for `velvet.toml` in each input file's folder and then in every folder above it
//! (the nearest one wins; `--config FILE` names one for every input instead). The keys have the
//! meanings of the Khronos glTF-Validator's config file where the two overlap (`max-issues`
//! with 0 for no limit, `ignore`, `only`, `override` with severities 0–3 or their names); velvet
//! adds `fail-on` and `exclude`, and `fail-on-visible` for `velvet migrate --check` (a file
//! fails the check when a material it holds would migrate visibly). An unknown key, an unknown code or a bad value is an error that
//! names it: a typo in a CI configuration must not silently switch a check off.
//!
//! Precedence is per key: a command-line flag over the file, the file over the built-in
//! default. `ignore` and `only` are one choice (which codes to report), and one layer may not
//! set both: a command-line `--ignore` adds its codes to the file's choice (so a pre-commit
//! `args: [--ignore X]` keeps what velvet.toml ignores), a command-line `--only` replaces it.
//! Severity overrides merge per code. Exclude globs come from the file only and are relative
//! to its folder.

use crate::diagnostics::{FailOn, Settings, Severity};
use crate::report::escape::terminal;
use globset::{Glob, GlobBuilder, GlobSet, GlobSetBuilder};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The name of the configuration file.
pub const FILE_NAME: &str = "velvet.toml";

/// A configuration that cannot be used. Each names the file and the key or value at fault.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {}: {source}", .path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}", .path.display())]
    Invalid { path: PathBuf, message: String },
    #[error("{0}")]
    CommandLine(String),
    /// Every file found was excluded: a run that checks nothing fails rather than pass as
    /// "0 files checked".
    #[error("no asset left to check: {found} found, all excluded by {by}; a run that checks nothing fails")]
    AllExcluded { found: usize, by: String },
}

/// Which codes a run reports.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Selection {
    /// Every code.
    #[default]
    All,
    /// Every code but these.
    Ignore(BTreeSet<String>),
    /// Only these codes.
    Only(BTreeSet<String>),
}

/// Where a value in force came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    Default,
    File,
    CommandLine,
    /// The file's list with the command line's codes added (`ignore`).
    FileAndCommandLine,
}

impl Source {
    fn describe(self) -> &'static str {
        match self {
            Source::Default => "default",
            Source::File => FILE_NAME,
            Source::CommandLine => "command line",
            Source::FileAndCommandLine => "velvet.toml and command line",
        }
    }
}

/// What one layer (a config file or the command line) sets; `None` and empty leave the key to
/// the layer below.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layer {
    /// 0 means no limit (as in the Khronos validator).
    pub max_issues: Option<usize>,
    pub selection: Option<Selection>,
    pub overrides: BTreeMap<String, Severity>,
    pub fail_on: Option<FailOn>,
    pub exclude: Vec<String>,
    /// `data = false`, `--no-data`: leave out the checks that read accessor data.
    pub data: Option<bool>,
    /// `fail-on-visible = true`, `migrate --check --fail-on-visible`: a material whose
    /// migration the plan's verdict calls "visible" fails the check.
    pub fail_on_visible: Option<bool>,
}

/// The keys of velvet.toml as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawFile {
    #[serde(default, deserialize_with = "whole_number")]
    max_issues: Option<i64>,
    ignore: Option<Vec<String>>,
    only: Option<Vec<String>>,
    #[serde(rename = "override")]
    overrides: Option<BTreeMap<String, RawSeverity>>,
    fail_on: Option<String>,
    exclude: Option<Vec<String>>,
    data: Option<bool>,
    fail_on_visible: Option<bool>,
}

/// An integer, with an error message that says so in the file's terms.
fn whole_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<i64>, D::Error> {
    struct Whole;
    impl serde::de::Visitor<'_> for Whole {
        type Value = i64;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a whole number (0: no limit)")
        }
        fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<i64, E> {
            Ok(v)
        }
        fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<i64, E> {
            i64::try_from(v).map_err(|_| E::custom(format!("{v} is too large")))
        }
    }
    d.deserialize_i64(Whole).map(Some)
}

/// A severity as the Khronos validator writes it (0 error … 3 hint) or by name.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum RawSeverity {
    Number(i64),
    Name(String),
}

/// Checks that `code` is one velvet emits.
fn known_code(code: &str, key: &str) -> Result<String, String> {
    match crate::rules::find_code(code) {
        Some(c) => Ok(c.name.to_string()),
        None => match crate::diagnostics::codes::renamed(code) {
            Some(now) => Err(format!(
                "{key}: {code} is no longer a code: it is now {}, as the Khronos glTF-Validator names it",
                now.join(", ")
            )),
            None => Err(format!(
                "{key}: no such code {code} (`velvet codes` lists them)"
            )),
        },
    }
}

/// Parses a severity name or Khronos number.
pub fn parse_severity(text: &str) -> Option<Severity> {
    Severity::parse(text).or(match text {
        "0" => Some(Severity::Error),
        "1" => Some(Severity::Warning),
        "2" => Some(Severity::Info),
        "3" => Some(Severity::Hint),
        _ => None,
    })
}

/// Parses a `fail-on` value.
pub fn parse_fail_on(text: &str) -> Option<FailOn> {
    match text {
        "error" => Some(FailOn::Error),
        "warning" => Some(FailOn::Warning),
        "info" => Some(FailOn::Info),
        "hint" => Some(FailOn::Hint),
        _ => None,
    }
}

fn fail_on_name(f: FailOn) -> &'static str {
    match f {
        FailOn::Error => "error",
        FailOn::Warning => "warning",
        FailOn::Info => "info",
        FailOn::Hint => "hint",
    }
}

/// Builds the selection a layer asks for; setting both `ignore` and `only` is an error (as in
/// the Khronos validator).
pub fn selection(
    ignore: Option<Vec<String>>,
    only: Option<Vec<String>>,
    what: &str,
) -> Result<Option<Selection>, String> {
    let codes = |list: Vec<String>, key: &str| {
        list.iter()
            .map(|c| known_code(c, key))
            .collect::<Result<BTreeSet<_>, _>>()
    };
    match (ignore, only) {
        (Some(_), Some(_)) => Err(format!("{what} sets both ignore and only; use one")),
        (Some(list), None) => Ok(Some(Selection::Ignore(codes(list, "ignore")?))),
        (None, Some(list)) => Ok(Some(Selection::Only(codes(list, "only")?))),
        (None, None) => Ok(None),
    }
}

/// The codes reported under the command line's choice over the file's. A command-line
/// `--ignore` adds to what the file leaves out: to its `ignore` list, or it takes codes off its
/// `only` list. A command-line `--only` replaces the file's choice.
fn combine_selection(cli: &Option<Selection>, file: &Option<Selection>) -> (Selection, Source) {
    match (cli, file) {
        (Some(Selection::Ignore(more)), Some(Selection::Ignore(listed))) => (
            Selection::Ignore(listed.union(more).cloned().collect()),
            Source::FileAndCommandLine,
        ),
        (Some(Selection::Ignore(more)), Some(Selection::Only(listed))) => (
            Selection::Only(listed.difference(more).cloned().collect()),
            Source::FileAndCommandLine,
        ),
        (Some(cli), _) => (cli.clone(), Source::CommandLine),
        (None, Some(file)) => (file.clone(), Source::File),
        (None, None) => (Selection::All, Source::Default),
    }
}

/// Line and column (1-based, columns in characters) of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line, column)
}

impl Layer {
    /// Parses the text of a velvet.toml.
    pub fn parse(text: &str) -> Result<Layer, String> {
        let raw: RawFile = toml::from_str(text).map_err(|e| {
            let message = e
                .message()
                .trim_end()
                .replace("unknown field", "unknown key");
            match e.span() {
                Some(span) => {
                    let (line, column) = line_column(text, span.start);
                    // Name the key of a bad value (the span covers the value only).
                    let line_text = text.lines().nth(line - 1).unwrap_or("");
                    match line_text.split_once('=') {
                        Some((key, _)) if !message.starts_with("unknown key") => {
                            format!("line {line}, column {column}: {}: {message}", key.trim())
                        }
                        _ => format!("line {line}, column {column}: {message}"),
                    }
                }
                None => message,
            }
        })?;
        let max_issues = match raw.max_issues {
            Some(n) if n < 0 => {
                return Err(format!("max-issues: {n} is negative (0 means no limit)"))
            }
            Some(n) => Some(n as usize),
            None => None,
        };
        let selection = selection(raw.ignore, raw.only, "the file")?;
        let mut overrides = BTreeMap::new();
        for (code, severity) in raw.overrides.unwrap_or_default() {
            let code = known_code(&code, "override")?;
            let parsed = match &severity {
                RawSeverity::Number(n) => parse_severity(&n.to_string()),
                RawSeverity::Name(name) => parse_severity(name),
            };
            let Some(parsed) = parsed else {
                let shown = match severity {
                    RawSeverity::Number(n) => n.to_string(),
                    RawSeverity::Name(name) => format!("\"{name}\""),
                };
                return Err(format!(
                    "override.{code}: {shown} is not a severity (0 or \"error\", 1 or \"warning\", 2 or \"info\", 3 or \"hint\")"
                ));
            };
            overrides.insert(code, parsed);
        }
        let fail_on = match raw.fail_on {
            Some(text) => Some(parse_fail_on(&text).ok_or_else(|| {
                format!(
                    "fail-on: \"{text}\" is not one of \"error\", \"warning\", \"info\", \"hint\""
                )
            })?),
            None => None,
        };
        let exclude = raw.exclude.unwrap_or_default();
        if exclude.len() > MAX_EXCLUDE_PATTERNS {
            return Err(format!(
                "exclude: {} patterns, more than the {MAX_EXCLUDE_PATTERNS} velvet takes (each \
                 file found is matched against every one); a folder's pattern (\"dir/**\") \
                 excludes all below it",
                exclude.len()
            ));
        }
        for pattern in &exclude {
            glob(pattern).map_err(|e| format!("exclude: {e}"))?;
        }
        Ok(Layer {
            max_issues,
            selection,
            overrides,
            fail_on,
            exclude,
            data: raw.data,
            fail_on_visible: raw.fail_on_visible,
        })
    }

    /// The layer the command line sets: `--max-issues`, `--ignore` or `--only` (repeatable),
    /// `--override CODE=SEVERITY` (repeatable), `--fail-on` and `--no-data` (`data` false).
    /// Empty lists leave the key to the file.
    pub fn command_line(
        max_issues: Option<usize>,
        ignore: &[String],
        only: &[String],
        overrides: &[String],
        fail_on: Option<FailOn>,
        data: Option<bool>,
    ) -> Result<Layer, ConfigError> {
        let nonempty = |l: &[String]| (!l.is_empty()).then(|| l.to_vec());
        let flag = |m: String| ConfigError::CommandLine(format!("--{m}"));
        if !ignore.is_empty() && !only.is_empty() {
            return Err(ConfigError::CommandLine(
                "--ignore and --only cannot be used together".into(),
            ));
        }
        let selection =
            selection(nonempty(ignore), nonempty(only), "the command line").map_err(flag)?;
        let mut map = BTreeMap::new();
        for item in overrides {
            let Some((code, severity)) = item.split_once('=') else {
                return Err(flag(format!("override {item}: expected CODE=SEVERITY")));
            };
            let code = known_code(code.trim(), "override").map_err(flag)?;
            let Some(severity) = parse_severity(severity.trim()) else {
                return Err(flag(format!("override {item}: {severity} is not a severity (error, warning, info, hint or 0-3)")));
            };
            map.insert(code, severity);
        }
        Ok(Layer {
            max_issues,
            selection,
            overrides: map,
            fail_on,
            exclude: Vec::new(),
            data,
            fail_on_visible: None,
        })
    }

    /// Reads and parses a velvet.toml, refusing one over [`MAX_CONFIG_BYTES`] (read no
    /// further than that: a configuration that is a stream or a huge file costs an error, not
    /// memory).
    pub fn read(path: &Path) -> Result<Layer, ConfigError> {
        use std::io::Read;
        let unreadable = |source| ConfigError::Read {
            path: path.to_path_buf(),
            source,
        };
        let mut bytes = Vec::new();
        // A configuration is a file: a FIFO would block the run until a program writes into it,
        // a device could never end. Opened without waiting, and refused by what was opened.
        let file = crate::asset::discover::open_without_waiting(path).map_err(unreadable)?;
        let meta = file.metadata().map_err(unreadable)?;
        if !meta.is_file() {
            return Err(ConfigError::Invalid {
                path: path.to_path_buf(),
                message: format!(
                    "not a regular file ({}); velvet reads a configuration from a file",
                    crate::asset::discover::file_kind(&meta)
                ),
            });
        }
        file.take(MAX_CONFIG_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(unreadable)?;
        if bytes.len() as u64 > MAX_CONFIG_BYTES {
            return Err(ConfigError::Invalid {
                path: path.to_path_buf(),
                message: format!(
                    "the file is larger than {MAX_CONFIG_BYTES} bytes, more than a configuration \
                     needs; velvet reads no further"
                ),
            });
        }
        let text = String::from_utf8(bytes)
            .map_err(|e| unreadable(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))?;
        Layer::parse(&text).map_err(|message| ConfigError::Invalid {
            path: path.to_path_buf(),
            message,
        })
    }
}

/// The largest velvet.toml velvet reads: 1 MiB, thousands of times a real one.
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The most exclude patterns a velvet.toml may list: every file found is matched against
/// them all, and 40,000 cost seconds a run.
pub const MAX_EXCLUDE_PATTERNS: usize = 1000;

/// An exclude pattern: `*` and `?` stay inside one path component, `**` crosses them.
fn glob(pattern: &str) -> Result<Glob, globset::Error> {
    GlobBuilder::new(pattern.trim_start_matches('/'))
        .literal_separator(true)
        .build()
}

/// The configuration in force for a set of files: the layers combined, with where each value
/// came from.
#[derive(Debug, Clone)]
pub struct Config {
    /// The velvet.toml in force, if any.
    pub file: Option<PathBuf>,
    pub max_issues: (usize, Source),
    pub selection: (Selection, Source),
    pub overrides: BTreeMap<String, (Severity, Source)>,
    pub fail_on: (FailOn, Source),
    pub exclude: Vec<String>,
    /// Whether the checks that read accessor data run.
    pub data: (bool, Source),
    /// Whether `migrate --check` fails a file with a material that would migrate visibly.
    pub fail_on_visible: (bool, Source),
    /// Patterns with a `/`, matched against the path below the file's folder.
    anchored: GlobSet,
    /// Patterns without a `/`, matched against every component of that path.
    component: GlobSet,
    settings: Settings,
    /// The error codes the selection would have left out had it not left out every one
    /// (see [`Config::warning`]); empty for a selection that lets an error code through.
    kept_errors: Vec<String>,
}

impl Config {
    /// Combines the command line over a file (given as its path and parsed layer) over the
    /// defaults.
    pub fn combine(file: Option<(PathBuf, Layer)>, cli: &Layer) -> Config {
        let (path, file_layer) = match file {
            Some((p, l)) => (Some(p), l),
            None => (None, Layer::default()),
        };
        fn pick<T: Clone>(cli: &Option<T>, file: &Option<T>, default: T) -> (T, Source) {
            match (cli, file) {
                (Some(v), _) => (v.clone(), Source::CommandLine),
                (None, Some(v)) => (v.clone(), Source::File),
                (None, None) => (default, Source::Default),
            }
        }
        let max_issues = pick(&cli.max_issues, &file_layer.max_issues, 0);
        let selection = combine_selection(&cli.selection, &file_layer.selection);
        let fail_on = pick(&cli.fail_on, &file_layer.fail_on, FailOn::Error);
        let data = pick(&cli.data, &file_layer.data, true);
        let fail_on_visible = pick(&cli.fail_on_visible, &file_layer.fail_on_visible, false);
        let mut overrides: BTreeMap<String, (Severity, Source)> = file_layer
            .overrides
            .iter()
            .map(|(c, s)| (c.clone(), (*s, Source::File)))
            .collect();
        for (c, s) in &cli.overrides {
            overrides.insert(c.clone(), (*s, Source::CommandLine));
        }
        let mut anchored = GlobSetBuilder::new();
        let mut component = GlobSetBuilder::new();
        for pattern in &file_layer.exclude {
            // Validated when the layer was parsed.
            if let Ok(g) = glob(pattern) {
                if pattern.trim_start_matches('/').contains('/') {
                    anchored.add(g);
                } else {
                    component.add(g);
                }
            }
        }
        let ignore = match &selection.0 {
            Selection::All => BTreeSet::new(),
            Selection::Ignore(codes) => codes.clone(),
            Selection::Only(codes) => crate::rules::all_codes()
                .into_iter()
                .map(|c| c.name.to_string())
                .filter(|n| !codes.contains(n))
                .collect(),
        };
        // A selection may leave out error codes one at a time, but not every one of them: a
        // gate that filters out all its errors passes any file, and says nothing. Such a
        // selection keeps its error codes reported and counted (`--fail-on` judges them), and
        // `kept_errors` names them for the run's warning.
        let mut ignore = ignore;
        let error_codes: Vec<&str> = crate::rules::all_codes()
            .into_iter()
            .filter(|c| overrides.get(c.name).map_or(c.severity, |(s, _)| *s) == Severity::Error)
            .map(|c| c.name)
            .collect();
        let kept_errors: Vec<String> =
            if !error_codes.is_empty() && error_codes.iter().all(|c| ignore.contains(*c)) {
                for code in &error_codes {
                    ignore.remove(*code);
                }
                error_codes.iter().map(|c| c.to_string()).collect()
            } else {
                Vec::new()
            };
        let settings = Settings {
            ignore,
            severity_overrides: overrides
                .iter()
                .map(|(c, (s, _))| (c.clone(), *s))
                .collect(),
            max_issues: (max_issues.0 > 0).then_some(max_issues.0),
            fail_on: fail_on.0,
            skip_data: !data.0,
        };
        Config {
            file: path,
            max_issues,
            selection,
            overrides,
            fail_on,
            data,
            fail_on_visible,
            exclude: file_layer.exclude,
            anchored: anchored.build().unwrap_or_else(|_| GlobSet::empty()),
            component: component.build().unwrap_or_else(|_| GlobSet::empty()),
            settings,
            kept_errors,
        }
    }

    /// The warning a run prints when this configuration's `ignore` or `only` would leave out
    /// every error code, naming the codes it keeps reporting anyway.
    pub fn warning(&self) -> Option<String> {
        if self.kept_errors.is_empty() {
            return None;
        }
        let (key, source) = match &self.selection {
            (Selection::Only(_), source) => ("only", *source),
            (_, source) => ("ignore", *source),
        };
        let by = match (source, &self.file) {
            (Source::CommandLine, _) | (_, None) => format!("--{key}"),
            (Source::File, Some(file)) => format!("{} ({key})", file.display()),
            (_, Some(file)) => format!("{} and the command line ({key})", file.display()),
        };
        Some(format!(
            "warning: {by} leaves out every error code; a configuration cannot silence every \
             error, so these {} codes are still reported and fail the run: {}",
            self.kept_errors.len(),
            self.kept_errors.join(", ")
        ))
    }

    /// The settings a validator applies under this configuration.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// True when `path` (absolute, as the resolver sees it) matches an exclude pattern. Paths
    /// outside the config file's folder are matched by their components only.
    pub fn excludes(&self, path: &Path) -> bool {
        if self.exclude.is_empty() {
            return false;
        }
        let dir = self
            .file
            .as_deref()
            .and_then(Path::parent)
            .unwrap_or(Path::new(""));
        let relative = path.strip_prefix(dir).ok();
        if let Some(rel) = relative {
            // A pattern that names a folder excludes everything below it.
            let mut prefix = PathBuf::new();
            for c in rel.components() {
                prefix.push(c);
                if self.anchored.is_match(&prefix) {
                    return true;
                }
            }
        }
        let components = relative.unwrap_or(path).components();
        components
            .into_iter()
            .any(|c| self.component.is_match(Path::new(c.as_os_str())))
    }

    /// The configuration as velvet.toml text, each value followed by a comment saying where it
    /// came from. Feeding the text back as a velvet.toml gives the same configuration.
    pub fn to_toml(&self) -> String {
        let mut out = String::new();
        let quoted = |s: &str| toml::Value::String(s.to_string()).to_string();
        let list = |items: &mut dyn Iterator<Item = &String>| {
            format!(
                "[{}]",
                items.map(|s| quoted(s)).collect::<Vec<_>>().join(", ")
            )
        };
        match &self.file {
            Some(p) => {
                // A folder's name is shown, not obeyed: ESC or a newline in it would act on the
                // terminal or end the comment.
                let _ = writeln!(
                    out,
                    "# {FILE_NAME} in force: {}",
                    terminal(&crate::asset::discover::display_path(p))
                );
            }
            None => {
                out.push_str("# no velvet.toml in force: built-in defaults and the command line\n")
            }
        }
        let (max, source) = self.max_issues;
        let _ = writeln!(
            out,
            "max-issues = {max}  # {}{}",
            source.describe(),
            if max == 0 { " (0: no limit)" } else { "" }
        );
        let (sel, source) = &self.selection;
        let _ = match sel {
            Selection::All => writeln!(out, "ignore = []  # {}", source.describe()),
            Selection::Ignore(codes) => writeln!(
                out,
                "ignore = {}  # {}",
                list(&mut codes.iter()),
                source.describe()
            ),
            Selection::Only(codes) => writeln!(
                out,
                "only = {}  # {}",
                list(&mut codes.iter()),
                source.describe()
            ),
        };
        let (fail_on, source) = self.fail_on;
        let _ = writeln!(
            out,
            "fail-on = {}  # {}",
            quoted(fail_on_name(fail_on)),
            source.describe()
        );
        let source = if self.exclude.is_empty() {
            Source::Default
        } else {
            Source::File
        };
        let _ = writeln!(
            out,
            "exclude = {}  # {}",
            list(&mut self.exclude.iter()),
            source.describe()
        );
        let (data, source) = self.data;
        let _ = writeln!(
            out,
            "data = {data}  # {}{}",
            source.describe(),
            if data {
                ""
            } else {
                " (accessor data and image bytes not read)"
            }
        );
        let (fail_on_visible, source) = self.fail_on_visible;
        let _ = writeln!(
            out,
            "fail-on-visible = {fail_on_visible}  # {} (migrate --check)",
            source.describe()
        );
        out.push_str("\n[override]\n");
        for (code, (severity, source)) in &self.overrides {
            let _ = writeln!(
                out,
                "{code} = {}  # {}",
                quoted(severity.as_str()),
                source.describe()
            );
        }
        out
    }
}

/// The settings a command line gives (`--config`, `--max-issues`, `--ignore`, `--only`,
/// `--override`, `--fail-on`), read as `validate` and `config` read them: each beats
/// velvet.toml, key by key.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Flags {
    /// `--config FILE`: one configuration for every input instead of the velvet.toml found.
    pub config: Option<PathBuf>,
    pub max_issues: Option<usize>,
    pub ignore: Vec<String>,
    pub only: Vec<String>,
    /// `CODE=SEVERITY`, as given.
    pub overrides: Vec<String>,
    pub fail_on: Option<FailOn>,
    /// `--no-data`: the checks that read accessor data are left out.
    pub no_data: bool,
}

impl Flags {
    /// The resolver of every input's configuration under these flags.
    pub fn resolver(&self) -> Result<Resolver, ConfigError> {
        let layer = Layer::command_line(
            self.max_issues,
            &self.ignore,
            &self.only,
            &self.overrides,
            self.fail_on,
            self.no_data.then_some(false),
        )?;
        Resolver::new(self.config.as_deref(), layer)
    }

    /// velvet.toml text of the configuration in force for `path`, with where each value
    /// comes from (`velvet config`), and whether it excludes `path`.
    pub fn show(&self, path: &Path) -> Result<String, ConfigError> {
        let config = self.resolver()?.for_path(path)?;
        let mut text = String::new();
        if config.excludes(&absolute(path)) {
            text += &format!(
                "# {} is excluded by this configuration\n",
                terminal(&crate::asset::discover::display_path(path))
            );
        }
        if let Some(warning) = config.warning() {
            text += &format!("# {}\n", terminal(&warning));
        }
        text += &config.to_toml();
        Ok(text)
    }
}

/// Finds the configuration for each path of a run, reading every velvet.toml once.
pub struct Resolver {
    cli: Layer,
    /// `--config FILE`: the one configuration for every path.
    fixed: Option<Arc<Config>>,
    /// Folder → the configuration found from it.
    by_folder: HashMap<PathBuf, Arc<Config>>,
    /// velvet.toml path → its configuration.
    by_file: HashMap<PathBuf, Arc<Config>>,
    /// The distinct warnings of the configurations found so far ([`Config::warning`]).
    warnings: Vec<String>,
}

pub use crate::asset::discover::absolute;

impl Resolver {
    /// A resolver that layers `cli` over the discovered files, or over `config_file` for every
    /// path when one is given.
    pub fn new(config_file: Option<&Path>, cli: Layer) -> Result<Resolver, ConfigError> {
        let fixed = match config_file {
            Some(path) => {
                let layer = Layer::read(path)?;
                Some(Arc::new(Config::combine(
                    Some((absolute(path), layer)),
                    &cli,
                )))
            }
            None => None,
        };
        let mut resolver = Resolver {
            cli,
            fixed: None,
            by_folder: HashMap::new(),
            by_file: HashMap::new(),
            warnings: Vec::new(),
        };
        if let Some(fixed) = &fixed {
            resolver.warn(fixed);
        }
        resolver.fixed = fixed;
        Ok(resolver)
    }

    /// The warnings of the configurations resolved so far, each once.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    fn warn(&mut self, config: &Config) {
        if let Some(w) = config.warning() {
            if !self.warnings.contains(&w) {
                self.warnings.push(w);
            }
        }
    }

    /// The configuration for a file (searched from its folder) or a folder (from itself).
    pub fn for_path(&mut self, path: &Path) -> Result<Arc<Config>, ConfigError> {
        if let Some(fixed) = &self.fixed {
            return Ok(fixed.clone());
        }
        let abs = absolute(path);
        let start = if abs.is_dir() {
            abs
        } else {
            abs.parent().map(Path::to_path_buf).unwrap_or(abs)
        };
        self.for_folder(start)
    }

    /// The configuration for the file at the absolute path `file`, known not to be a folder
    /// (a file a run found): searched from its folder, with no look at the file itself.
    pub fn for_file(&mut self, file: &Path) -> Result<Arc<Config>, ConfigError> {
        if let Some(fixed) = &self.fixed {
            return Ok(fixed.clone());
        }
        match file.parent() {
            Some(folder) => self.for_folder(folder.to_path_buf()),
            None => self.for_path(file),
        }
    }

    /// The configuration found from the absolute folder `start` upwards.
    fn for_folder(&mut self, start: PathBuf) -> Result<Arc<Config>, ConfigError> {
        let mut visited = Vec::new();
        let mut found = None;
        for dir in start.ancestors() {
            if let Some(config) = self.by_folder.get(dir) {
                found = Some(config.clone());
                break;
            }
            visited.push(dir.to_path_buf());
            let candidate = dir.join(FILE_NAME);
            if candidate.is_file() {
                let config = match self.by_file.get(&candidate) {
                    Some(c) => c.clone(),
                    None => {
                        let layer = Layer::read(&candidate)?;
                        let c =
                            Arc::new(Config::combine(Some((candidate.clone(), layer)), &self.cli));
                        self.warn(&c);
                        self.by_file.insert(candidate, c.clone());
                        c
                    }
                };
                found = Some(config);
                break;
            }
        }
        let config = match found {
            Some(config) => config,
            None => {
                let config = Arc::new(Config::combine(None, &self.cli));
                self.warn(&config);
                config
            }
        };
        for dir in visited {
            self.by_folder.insert(dir, config.clone());
        }
        Ok(config)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_key_with_khronos_severity_numbers_and_names() {
        let layer = Layer::parse(
            "max-issues = 5\nignore = [\"UNEXPECTED_PROPERTY\"]\nfail-on = \"warning\"\nexclude = [\"drafts/**\"]\n\
             [override]\nTYPE_MISMATCH = 1\nVALUE_NOT_IN_RANGE = \"hint\"\n",
        )
        .unwrap();
        assert_eq!(layer.max_issues, Some(5));
        assert_eq!(
            layer.selection,
            Some(Selection::Ignore(
                ["UNEXPECTED_PROPERTY".to_string()].into()
            ))
        );
        assert_eq!(layer.fail_on, Some(FailOn::Warning));
        assert_eq!(layer.exclude, vec!["drafts/**"]);
        assert_eq!(
            layer.overrides.get("TYPE_MISMATCH"),
            Some(&Severity::Warning)
        );
        assert_eq!(
            layer.overrides.get("VALUE_NOT_IN_RANGE"),
            Some(&Severity::Hint)
        );
    }

    #[test]
    fn unknown_key_is_an_error_naming_the_key_and_its_line() {
        let err = Layer::parse("max-issues = 3\nmax_issue = 4\n").unwrap_err();
        assert!(
            err.starts_with("line 2, column 1: unknown key `max_issue`"),
            "{err}"
        );
    }

    #[test]
    fn bad_values_name_the_key_and_value() {
        assert_eq!(
            Layer::parse("ignore = [\"NOT_A_CODE\"]").unwrap_err(),
            "ignore: no such code NOT_A_CODE (`velvet codes` lists them)"
        );
        assert_eq!(
            Layer::parse("ignore = [\"GLB_TRAILING_DATA\"]").unwrap_err(),
            "ignore: GLB_TRAILING_DATA is no longer a code: it is now GLB_EXTRA_DATA, as the Khronos glTF-Validator names it"
        );
        assert_eq!(
            Layer::parse("ignore = []\nonly = []").unwrap_err(),
            "the file sets both ignore and only; use one"
        );
        assert_eq!(
            Layer::parse("max-issues = -1").unwrap_err(),
            "max-issues: -1 is negative (0 means no limit)"
        );
        assert_eq!(
            Layer::parse("fail-on = \"hints\"").unwrap_err(),
            "fail-on: \"hints\" is not one of \"error\", \"warning\", \"info\", \"hint\""
        );
        assert_eq!(
            Layer::parse("fail-on = \"hint\"").unwrap().fail_on,
            Some(FailOn::Hint)
        );
        assert!(Layer::parse("[override]\nTYPE_MISMATCH = 4")
            .unwrap_err()
            .starts_with("override.TYPE_MISMATCH: 4 is not a severity"));
        assert!(Layer::parse("exclude = [\"a/[\"]")
            .unwrap_err()
            .starts_with("exclude: "));
        assert_eq!(
            Layer::parse("\nmax-issues = \"ten\"").unwrap_err(),
            "line 2, column 14: max-issues: invalid type: string \"ten\", \
             expected a whole number (0: no limit)"
        );
        assert_eq!(
            Layer::parse("fail-on = 1").unwrap_err(),
            "line 1, column 11: fail-on: invalid type: integer `1`, expected a string"
        );
    }

    #[test]
    fn fail_on_visible_is_a_boolean_key() {
        assert_eq!(
            Layer::parse("fail-on-visible = true\n")
                .unwrap()
                .fail_on_visible,
            Some(true)
        );
        assert_eq!(Layer::parse("").unwrap().fail_on_visible, None);
        let e = Layer::parse("fail-on-visible = \"yes\"\n").unwrap_err();
        assert!(e.starts_with("line 1, column 19: fail-on-visible: "), "{e}");
    }

    #[test]
    fn command_line_beats_file_beats_default_per_key() {
        let file = Layer {
            max_issues: Some(7),
            selection: Some(Selection::Ignore(["TYPE_MISMATCH".to_string()].into())),
            overrides: [
                ("TYPE_MISMATCH".to_string(), Severity::Info),
                ("VALUE_NOT_IN_RANGE".to_string(), Severity::Info),
            ]
            .into(),
            fail_on: None,
            exclude: vec![],
            data: Some(false),
            fail_on_visible: Some(true),
        };
        let cli = Layer {
            max_issues: Some(2),
            overrides: [("VALUE_NOT_IN_RANGE".to_string(), Severity::Hint)].into(),
            ..Layer::default()
        };
        let c = Config::combine(Some((PathBuf::from("/p/velvet.toml"), file)), &cli);
        assert_eq!(c.max_issues, (2, Source::CommandLine));
        assert_eq!(c.selection.1, Source::File);
        assert_eq!(c.fail_on_visible, (true, Source::File));
        assert_eq!(c.fail_on, (FailOn::Error, Source::Default));
        assert_eq!(c.overrides["TYPE_MISMATCH"], (Severity::Info, Source::File));
        assert_eq!(
            c.overrides["VALUE_NOT_IN_RANGE"],
            (Severity::Hint, Source::CommandLine)
        );
        assert_eq!(c.settings().max_issues, Some(2));
        assert!(c.settings().ignore.contains("TYPE_MISMATCH"));
        // `data = false` in the file leaves out the data checks; `--no-data` does the same
        // from the command line; by default they run.
        assert_eq!(c.data, (false, Source::File));
        assert!(c.settings().skip_data);
        let none = Config::combine(None, &Layer::default());
        assert_eq!(none.data, (true, Source::Default));
        assert!(!none.settings().skip_data);
        let flag = Layer::command_line(None, &[], &[], &[], None, Some(false)).unwrap();
        assert_eq!(
            Config::combine(None, &flag).data,
            (false, Source::CommandLine)
        );
        assert_eq!(Layer::parse("data = false").unwrap().data, Some(false));
    }

    fn codes(list: &[&str]) -> BTreeSet<String> {
        list.iter().map(|c| c.to_string()).collect()
    }

    #[test]
    fn command_line_ignore_adds_to_the_files_ignore_and_takes_codes_off_its_only() {
        let file_ignore = Layer::parse("ignore = [\"TYPE_MISMATCH\"]").unwrap();
        let file_only = Layer::parse("only = [\"TYPE_MISMATCH\", \"VALUE_NOT_IN_RANGE\"]").unwrap();
        let cli = Layer::command_line(None, &["UNEXPECTED_PROPERTY".into()], &[], &[], None, None)
            .unwrap();
        let file = PathBuf::from("/p/velvet.toml");
        let c = Config::combine(Some((file.clone(), file_ignore.clone())), &cli);
        assert_eq!(
            c.selection,
            (
                Selection::Ignore(codes(&["TYPE_MISMATCH", "UNEXPECTED_PROPERTY"])),
                Source::FileAndCommandLine
            )
        );
        assert_eq!(
            c.settings().ignore,
            codes(&["TYPE_MISMATCH", "UNEXPECTED_PROPERTY"])
        );
        assert!(c
            .to_toml()
            .contains("ignore = [\"TYPE_MISMATCH\", \"UNEXPECTED_PROPERTY\"]  # velvet.toml and command line\n"));
        let cli_only_off =
            Layer::command_line(None, &["VALUE_NOT_IN_RANGE".into()], &[], &[], None, None)
                .unwrap();
        let c = Config::combine(Some((file.clone(), file_only.clone())), &cli_only_off);
        assert_eq!(
            c.selection,
            (
                Selection::Only(codes(&["TYPE_MISMATCH"])),
                Source::FileAndCommandLine
            )
        );
        // Without a file the command line's list is the list; `--only` replaces the file's.
        let c = Config::combine(None, &cli);
        assert_eq!(
            c.selection,
            (
                Selection::Ignore(codes(&["UNEXPECTED_PROPERTY"])),
                Source::CommandLine
            )
        );
        let cli_only =
            Layer::command_line(None, &[], &["VALUE_NOT_IN_RANGE".into()], &[], None, None)
                .unwrap();
        let c = Config::combine(Some((file, file_ignore)), &cli_only);
        assert_eq!(
            c.selection,
            (
                Selection::Only(codes(&["VALUE_NOT_IN_RANGE"])),
                Source::CommandLine
            )
        );
    }

    #[test]
    fn only_becomes_ignore_of_every_other_code_and_zero_max_issues_means_no_limit() {
        let cli = Layer {
            selection: Some(Selection::Only(["TYPE_MISMATCH".to_string()].into())),
            max_issues: Some(0),
            ..Layer::default()
        };
        let c = Config::combine(None, &cli);
        let all = crate::rules::all_codes().len();
        assert_eq!(c.settings().ignore.len(), all - 1);
        assert!(!c.settings().ignore.contains("TYPE_MISMATCH"));
        assert_eq!(c.settings().max_issues, None);
    }

    #[test]
    fn exclude_patterns_anchor_with_a_slash_and_match_components_without() {
        let layer = Layer {
            exclude: vec![
                "drafts/**".into(),
                "*.wip.gltf".into(),
                "vendor".into(),
                "/top/a.glb".into(),
            ],
            ..Layer::default()
        };
        let c = Config::combine(
            Some((PathBuf::from("/p/velvet.toml"), layer)),
            &Layer::default(),
        );
        assert!(c.excludes(Path::new("/p/drafts/x.gltf")));
        assert!(c.excludes(Path::new("/p/drafts/deep/x.gltf")));
        assert!(!c.excludes(Path::new("/p/assets/drafts.gltf")));
        assert!(
            !c.excludes(Path::new("/p/assets/drafts/x.gltf")),
            "anchored patterns start at the config folder"
        );
        assert!(c.excludes(Path::new("/p/a/b/c.wip.gltf")));
        assert!(c.excludes(Path::new("/p/a/vendor/c.gltf")));
        assert!(c.excludes(Path::new("/p/top/a.glb")));
        assert!(!c.excludes(Path::new("/p/top/b.glb")));
        assert!(!c.excludes(Path::new("/p/a.gltf")));
        assert!(
            c.excludes(Path::new("/elsewhere/vendor/c.gltf")),
            "component patterns apply outside the folder too"
        );
    }

    #[test]
    fn printed_configuration_reads_back_as_the_same_configuration() {
        let file = Layer::parse("only = [\"TYPE_MISMATCH\", \"UNEXPECTED_PROPERTY\"]\nexclude = [\"a \\\"b\\\"/**\"]\n[override]\nTYPE_MISMATCH = 2\n").unwrap();
        let cli = Layer {
            fail_on: Some(FailOn::Warning),
            ..Layer::default()
        };
        let c = Config::combine(Some((PathBuf::from("/p/velvet.toml"), file)), &cli);
        let text = c.to_toml();
        let again = Config::combine(
            Some((
                PathBuf::from("/p/velvet.toml"),
                Layer::parse(&text).unwrap(),
            )),
            &Layer::default(),
        );
        assert_eq!(again.max_issues.0, c.max_issues.0);
        assert_eq!(again.selection.0, c.selection.0);
        assert_eq!(again.fail_on.0, c.fail_on.0);
        assert_eq!(again.exclude, c.exclude);
        assert_eq!(
            again.settings().severity_overrides,
            c.settings().severity_overrides
        );
    }

    #[test]
    fn absolute_folds_dots_lexically() {
        let cwd = std::env::current_dir().unwrap();
        assert_eq!(absolute(Path::new("a/./b/../c")), cwd.join("a/c"));
        assert_eq!(absolute(Path::new("")), cwd);
    }
}
