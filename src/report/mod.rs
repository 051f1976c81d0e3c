//! Renderers for validation reports: human text, the Khronos glTF-Validator JSON shape (one
//! report, an array, or JSON lines), SARIF 2.1.0 for code-scanning services, and GitHub
//! Actions workflow commands. Renderers only format; they decide nothing. This module also
//! owns the choices that shape output on a terminal: the format, colour, and the progress bar.

pub mod github;
pub mod json;
pub mod sarif;
pub mod text;

use crate::validate::FileReport;
use std::io::IsTerminal;
use std::path::Path;

/// A path as reports show it: relative to the working directory when it lies below it, with
/// forward slashes.
pub fn display_path(path: &Path) -> String {
    let shown = std::env::current_dir()
        .ok()
        .and_then(|cwd| path.strip_prefix(&cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf());
    shown.to_string_lossy().replace('\\', "/")
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

/// Writes a run's reports as they come. Text, JSON Lines and GitHub commands are written one
/// file at a time and only the totals are kept, so a run over many files holds one file's
/// report at a time, not all of them; the JSON report (an object for one file, an array for
/// several) and SARIF (one log for the run) are documents of the whole run, written at the end.
/// Write errors (a closed pipe) are ignored: the run's outcome is its exit status.
pub struct Stream<W: std::io::Write> {
    format: Format,
    options: Options,
    out: W,
    kept: Vec<FileReport>,
    files: usize,
    totals: [usize; 4],
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
        }
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
        let one = std::slice::from_ref(&report);
        let text = match self.format {
            Format::Text => text::render_with(
                one,
                &Options {
                    quiet: true,
                    ..self.options
                },
            ),
            Format::Jsonl => json::render_lines(one),
            Format::Github => github::render(one),
            Format::Json | Format::Sarif => {
                self.kept.push(report);
                return;
            }
        };
        let _ = self.out.write_all(text.as_bytes());
    }

    /// Writes out what is buffered.
    pub fn flush(&mut self) {
        let _ = self.out.flush();
    }

    /// Writes what ends the output: the summary line, or the whole-run document.
    pub fn finish(mut self) {
        let text = match self.format {
            Format::Text if !self.options.quiet => text::summary(self.files, self.totals),
            Format::Json | Format::Sarif => render(self.format, &self.kept, &self.options),
            _ => String::new(),
        };
        let _ = self.out.write_all(text.as_bytes());
        let _ = self.out.flush();
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
