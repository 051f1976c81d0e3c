//! Renderers for validation reports: human text, the Khronos glTF-Validator JSON shape (one
//! report, an array, or JSON lines), SARIF 2.1.0 for code-scanning services, and GitHub
//! Actions workflow commands. Renderers only format; they decide nothing. This module also
//! owns the choices that shape output on a terminal: the format, colour, and the progress bar.

pub mod escape;
pub mod fold;
pub mod github;
pub mod json;
pub mod pretty;
pub mod sarif;
pub mod text;

use crate::validate::{FileReport, Finding, MissingResources};
use std::io::IsTerminal;

pub use crate::asset::discover::display_path;

/// What a report says of the findings a `--max-issues` cap left out of its listing.
pub fn omitted_note(omitted: usize) -> String {
    format!(
        "{omitted} more issue{} not shown (--max-issues)",
        if omitted == 1 { "" } else { "s" }
    )
}

/// A file's findings as the text, GitHub and SARIF reports list them: its FILE_NOT_FOUND
/// findings as one entry, after the others. A checkout without its binaries (Git LFS not
/// fetched, generated files not generated) has one such finding per buffer and image, and
/// listed one by one they bury the file's other findings (GitHub shows a step's first ten
/// error annotations). The JSON reports, in the Khronos validator's shape, keep one message per
/// missing file with its pointer, as that validator does; the counts and the exit status come
/// from every finding in every format.
pub struct Listing<'a> {
    /// The other findings, in the report's order.
    pub others: Vec<&'a Finding>,
    /// The entry for the missing files, when any FILE_NOT_FOUND finding is listed.
    pub missing: Option<Finding>,
}

/// How many missing files the entry names before it ends in `…`.
pub const MISSING_NAMED: usize = 5;

/// `report`'s findings, its FILE_NOT_FOUND findings gathered into one.
pub fn listing(report: &FileReport) -> Listing<'_> {
    let code = crate::rules::resources::FILE_NOT_FOUND.name;
    let first = report.findings.iter().find(|f| f.diagnostic.code == code);
    let Some(first) = first.filter(|_| !report.missing.uris.is_empty()) else {
        return Listing {
            others: report.findings.iter().collect(),
            missing: None,
        };
    };
    let mut diagnostic = first.diagnostic.clone();
    diagnostic.message = missing_message(&report.missing);
    // The entry speaks of every missing file: it stands where the first is named, but names
    // no one value.
    diagnostic.pointer = String::new();
    Listing {
        others: report
            .findings
            .iter()
            .filter(|f| f.diagnostic.code != code)
            .collect(),
        missing: Some(Finding {
            diagnostic,
            position: first.position,
        }),
    }
}

/// "9 of 12 resources are missing: Chair.bin, … — a checkout without Git LFS? …"
fn missing_message(missing: &MissingResources) -> String {
    let count = missing.uris.len();
    let named = missing.named.max(count);
    let mut names = missing
        .uris
        .iter()
        .take(MISSING_NAMED)
        .map(String::as_str)
        .collect::<Vec<_>>()
        .join(", ");
    if count > MISSING_NAMED {
        names += &format!(", … ({} more)", count - MISSING_NAMED);
    }
    format!(
        "{count} of {named} resource{} {} missing: {names} — a checkout without Git LFS? fetch {}, or `--ignore FILE_NOT_FOUND`",
        if named == 1 { "" } else { "s" },
        if count == 1 { "is" } else { "are" },
        if count == 1 { "it" } else { "them" },
    )
}

/// The output formats of `velvet validate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Human-readable lines, coloured on a terminal.
    Text,
    /// The Khronos glTF-Validator report shape (an array for several files).
    Json,
    /// One Khronos-shaped report per line.
    Jsonl,
    /// SARIF 2.1.0, for GitHub code scanning and other SARIF consumers.
    Sarif,
    /// GitHub Actions workflow commands (annotations on the pull request).
    Github,
}

impl Format {
    /// Whether reports in this format show where in the file each finding stands (line and
    /// column). The Khronos-shaped JSON reports name values by pointer only.
    pub fn shows_positions(self) -> bool {
        !matches!(self, Format::Json | Format::Jsonl)
    }
}

/// When to colour text output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum ColorChoice {
    /// Colour when standard output is a terminal and NO_COLOR is not set.
    #[default]
    Auto,
    /// Colour even into a pipe or file (CI logs that render ANSI).
    Always,
    /// No colour.
    Never,
}

impl ColorChoice {
    /// Whether text written to standard output gets colour. `auto` follows the conventions
    /// anstream implements: NO_COLOR (non-empty) turns colour off, CLICOLOR_FORCE turns it on,
    /// otherwise colour only on a terminal that is not TERM=dumb.
    pub fn for_stdout(self) -> bool {
        match self {
            ColorChoice::Always => true,
            ColorChoice::Never => false,
            ColorChoice::Auto => {
                anstream::AutoStream::choice(&std::io::stdout()) != anstream::ColorChoice::Never
            }
        }
    }
}

/// How to render, beyond the format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Options {
    /// ANSI colour in text output.
    pub color: bool,
    /// Findings only: no summary line (text output; machine formats are always complete).
    pub quiet: bool,
    /// Text output: every finding on its own, instead of one entry per code, message and file.
    pub no_fold: bool,
    /// Text output: each file's fixes as a unified diff, instead of its findings (`--diff`).
    pub diff: bool,
    /// Text output: no line for each fix applied, only the findings left (`--fix-only`).
    pub fix_only: bool,
}

/// The table of every code that `velvet codes` prints: name, default severity, how it is
/// fixed (`safe`, `unsafe` or `-`) and its one line of documentation; as Markdown, the table
/// of docs/codes.md.
pub fn codes_table(markdown: bool) -> String {
    let codes = crate::rules::all_codes();
    if markdown {
        let mut out = String::from("| code | severity | fix | meaning |\n|---|---|---|---|\n");
        for c in codes {
            out += &format!(
                "| `{}` | {} | {} | {} |\n",
                c.name,
                c.severity,
                c.fix_label(),
                c.doc.replace('|', "\\|")
            );
        }
        return out;
    }
    let width = codes.iter().map(|c| c.name.len()).max().unwrap_or(0);
    // A header naming the columns, as the Markdown table has; the severity column is as wide
    // as its header ("severity" is longer than any severity).
    let line = |name: &str, severity: &str, fix: &str, doc: &str| {
        format!("{name:width$}  {severity:8}  {fix:6}  {doc}\n")
    };
    let mut out = line("code", "severity", "fix", "meaning");
    for c in codes {
        out += &line(c.name, c.severity.as_str(), c.fix_label(), c.doc);
    }
    out
}

/// Renders `reports` in `format`.
pub fn render(format: Format, reports: &[FileReport], options: &Options) -> String {
    match format {
        Format::Text => text::render_with(reports, options),
        Format::Json => json::render(reports),
        Format::Jsonl => json::render_lines(reports),
        Format::Sarif => sarif::render(reports),
        Format::Github => github::render(reports),
    }
}

/// What a run that could not start writes to standard output in `format`, besides its
/// message on standard error: a document that records the failure, so that output redirected
/// into the file a CI step uploads (`if: always()`) is never empty or cut short. SARIF: a log
/// whose invocation has `executionSuccessful: false`, exit code 2 and the message, and no
/// results. JSON and JSON lines: a report in the Khronos shape whose one message is
/// USAGE_ERROR (an array of it, as a run over anything but one file gives, for `json_array`).
/// GitHub: an error annotation. Text: nothing.
pub fn failed_run(format: Format, message: &str, json_array: bool) -> String {
    let report = || FileReport {
        path: std::path::PathBuf::new(),
        container: None,
        json_offset: 0,
        findings: vec![Finding {
            diagnostic: crate::diagnostics::Diagnostic::new(
                &crate::diagnostics::codes::USAGE_ERROR,
                "",
                message,
            ),
            position: None,
        }],
        counts: crate::validate::Counts {
            errors: 1,
            ..Default::default()
        },
        omitted: 0,
        info: None,
        missing: MissingResources::default(),
        fixes: Default::default(),
        rule_spans: Vec::new(),
    };
    match format {
        Format::Text => String::new(),
        Format::Github => format!(
            "::error title=velvet::{}\n",
            github::escape_data(&escape::terminal(message))
        ),
        // As the stream writes an array of one report.
        Format::Json if json_array => json::render_array(&[report()]),
        Format::Json => json::render(&[report()]),
        Format::Jsonl => json::render_lines(&[report()]),
        Format::Sarif => sarif::render_failed(message),
    }
}

/// Writes a run's reports as they come, one file at a time, keeping only the totals: a run over
/// many files holds one file's report, not all of them. The JSON report's shape is chosen per
/// invocation, never per count: a run over one file argument gives the report object, any
/// other run an array (empty when no file was found), each element written as it is done. SARIF is one log for the whole run
/// and is written at the end. Write errors (a closed pipe) are ignored: the run's outcome is
/// its exit status.
pub struct Stream<W: std::io::Write> {
    format: Format,
    options: Options,
    out: W,
    kept: Vec<FileReport>,
    files: usize,
    totals: [usize; 4],
    json_array: bool,
    /// GitHub output: the missing-resource annotations, written after every other one.
    deferred: String,
    /// The run's fixes, counted for the text summary.
    fixes: text::FixTotals,
}

impl<W: std::io::Write> Stream<W> {
    pub fn new(format: Format, options: Options, out: W) -> Stream<W> {
        Stream {
            format,
            options,
            out,
            kept: Vec::new(),
            files: 0,
            totals: [0; 4],
            json_array: true,
            deferred: String::new(),
            fixes: Default::default(),
        }
    }

    /// Whether JSON output is an array of reports (the default) or the one report object of a
    /// run over a single file argument.
    pub fn json_array(self, json_array: bool) -> Stream<W> {
        Stream { json_array, ..self }
    }

    /// Takes the next file's report (in input order).
    pub fn push(&mut self, report: FileReport) {
        self.files += 1;
        let c = report.counts;
        for (t, n) in self
            .totals
            .iter_mut()
            .zip([c.errors, c.warnings, c.infos, c.hints])
        {
            *t += n;
        }
        self.fixes.add(&report.fixes);
        let one = std::slice::from_ref(&report);
        let text = match self.format {
            // --diff: the file's change, and nothing else, so that the output applies as a patch.
            Format::Text if self.options.diff => report.fixes.diff.clone().unwrap_or_default(),
            Format::Text => text::render_with(
                one,
                &Options {
                    quiet: true,
                    ..self.options
                },
            ),
            Format::Jsonl => json::render_lines(one),
            Format::Github => {
                let (text, missing) = github::render_file(&report);
                self.deferred += &missing;
                text
            }
            Format::Json if !self.json_array => {
                self.kept.push(report);
                return;
            }
            Format::Json => json::report_pretty_element(&report, self.files == 1),
            Format::Sarif => {
                self.kept.push(report);
                return;
            }
        };
        let _ = self.out.write_all(text.as_bytes());
        release(report);
    }

    /// Writes out what is buffered.
    pub fn flush(&mut self) {
        let _ = self.out.flush();
    }

    /// Writes what ends the output: the summary line, or the whole-run document.
    pub fn finish(mut self) {
        if let (Format::Json, false, [one]) = (self.format, self.json_array, self.kept.as_slice()) {
            let _ = json::write_pretty(&mut self.out, one);
            let _ = self.out.flush();
            self.kept.drain(..).for_each(release);
            return;
        }
        if self.format == Format::Sarif {
            let _ = sarif::write(&mut self.out, &self.kept);
            let _ = self.out.flush();
            self.kept.drain(..).for_each(release);
            return;
        }
        let text = match self.format {
            Format::Text if self.options.diff => String::new(),
            Format::Text if !self.options.quiet => {
                text::summary_with(self.files, self.totals, &self.fixes)
            }
            Format::Json if self.json_array && self.files == 0 => "[]\n".to_string(),
            Format::Json if self.json_array => "\n]\n".to_string(),
            Format::Json => render(self.format, &self.kept, &self.options),
            Format::Github => std::mem::take(&mut self.deferred),
            _ => String::new(),
        };
        let _ = self.out.write_all(text.as_bytes());
        let _ = self.out.flush();
        self.kept.drain(..).for_each(release);
    }
}

/// Reports from this many findings are freed on the thread pool.
const RELEASED_ELSEWHERE_FROM: usize = 4096;

/// Frees a report that has been written. A large one is freed on the thread pool, so that the
/// next report, or the end of the run, does not wait for its findings' tens of thousands of
/// frees (some 5 % of a 20,000-material document's run went to them).
fn release(report: FileReport) {
    if report.findings.len() >= RELEASED_ELSEWHERE_FROM {
        rayon::spawn(move || drop(report));
    }
}

/// A progress bar on standard error, or `None` when standard error is not a terminal or the
/// run is quiet (so logs and pipes never see one). Built only when asked for.
pub fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar =
        indicatif::ProgressBar::with_draw_target(Some(0), indicatif::ProgressDrawTarget::stderr());
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{spinner} {pos}/{len} files checked {wide_bar} {elapsed}",
    ) {
        bar.set_style(style);
    }
    Some(bar)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostics::Settings;
    use crate::rules::schema::Schemas;
    use crate::validate::Validator;

    fn reports(n: usize) -> Vec<FileReport> {
        let validator = Validator::new(Schemas::builtin(), Settings::default());
        (0..n)
            .map(|i| {
                let path = std::path::PathBuf::from(format!("memory/{i}.gltf"));
                let text = format!(
                    r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_materials_fuzz"],"buffers":[{{"uri":"gone{i}.bin","byteLength":1}}],"extras":{{"n":{i},"s":"a\nb"}}}}"#
                );
                let loaded = crate::asset::load_bytes(&path, text.as_bytes());
                validator.validate_loaded(&path, loaded)
            })
            .collect()
    }

    #[test]
    fn streamed_output_is_the_rendered_output_in_every_format() {
        for format in [
            Format::Text,
            Format::Json,
            Format::Jsonl,
            Format::Sarif,
            Format::Github,
        ] {
            for quiet in [false, true] {
                let options = Options {
                    color: false,
                    quiet,
                    no_fold: false,
                    diff: false,
                    fix_only: false,
                };
                for n in 0..4 {
                    let all = reports(n);
                    let mut out = Vec::new();
                    // render() gives one report as an object, as a single-file run does.
                    let mut stream = Stream::new(format, options, &mut out).json_array(n != 1);
                    for r in all.clone() {
                        stream.push(r);
                    }
                    stream.finish();
                    assert_eq!(
                        String::from_utf8(out).unwrap(),
                        render(format, &all, &options),
                        "{format:?}, {n} reports, quiet {quiet}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_missing_resources_entry_names_the_first_five_and_counts_the_rest() {
        let missing = |uris: &[&str], named| MissingResources {
            named,
            uris: uris.iter().map(|u| u.to_string()).collect(),
        };
        assert_eq!(
            missing_message(&missing(&["a.bin", "b.png", "c.png", "d.png", "e.png", "f.png", "g.png"], 12)),
            "7 of 12 resources are missing: a.bin, b.png, c.png, d.png, e.png, … (2 more) — a checkout without Git LFS? fetch them, or `--ignore FILE_NOT_FOUND`"
        );
        assert_eq!(
            missing_message(&missing(&["a.bin"], 3)),
            "1 of 3 resources is missing: a.bin — a checkout without Git LFS? fetch it, or `--ignore FILE_NOT_FOUND`"
        );
    }

    #[test]
    fn streamed_github_output_lists_every_missing_resource_entry_after_the_other_findings() {
        let mut out = Vec::new();
        let mut stream = Stream::new(Format::Github, Options::default(), &mut out);
        for r in reports(3) {
            stream.push(r);
        }
        stream.finish();
        let codes: Vec<&str> = std::str::from_utf8(&out)
            .unwrap()
            .lines()
            .map(|l| {
                l.rsplit_once("title=")
                    .unwrap()
                    .1
                    .split("::")
                    .next()
                    .unwrap()
            })
            .collect();
        let missing = codes.iter().position(|c| *c == "FILE_NOT_FOUND").unwrap();
        assert_eq!(missing, codes.len() - 3, "{codes:?}");
        assert!(
            codes[missing..].iter().all(|c| *c == "FILE_NOT_FOUND"),
            "{codes:?}"
        );
        assert!(missing > 0, "{codes:?}");
    }

    #[test]
    fn json_of_a_run_over_a_folder_is_an_array_even_for_one_file() {
        let mut out = Vec::new();
        let mut stream = Stream::new(Format::Json, Options::default(), &mut out);
        stream.push(reports(1).remove(0));
        stream.finish();
        let value: serde_json::Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(value.as_array().map(Vec::len), Some(1));
        let mut out = Vec::new();
        Stream::new(Format::Json, Options::default(), &mut out).finish();
        assert_eq!(out, b"[]\n");
    }
}
