//! The `velvet` command line: parses arguments, calls the library, maps outcomes to exit
//! codes (0 clean, 1 issues at or above --fail-on or a file failed, 2 usage or configuration
//! error).

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use velvet::cli_docs::{self, EXIT_STATUS};
use velvet::config::{self, Layer, Resolver};
use velvet::diagnostics::{self, FailOn, Settings};
use velvet::report::{self, ColorChoice, Format};
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

#[derive(Parser)]
#[command(
    name = "velvet",
    version,
    about = "Validate, migrate and bake glTF assets that use KHR_materials_sheen and KHR_materials_fuzz"
)]
#[command(after_help = EXIT_STATUS)]
struct Cli {
    /// When to colour output: auto colours on a terminal unless NO_COLOR is set.
    #[arg(long, value_enum, global = true, default_value_t = ColorChoice::Auto, value_name = "WHEN")]
    color: ColorChoice,
    /// Print findings only: no summary line and no progress bar.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check .gltf/.glb files (and folders, recursively) against the sheen and fuzz specs.
    #[command(after_help = EXIT_STATUS)]
    Validate(ValidateArgs),
    /// Print the configuration in force for a file or folder.
    ///
    /// The output is velvet.toml text with the source of each value (default, velvet.toml or
    /// command line); flags given here are layered as `validate` layers them.
    Config {
        /// The file or folder to look from [default: the current folder].
        path: Option<PathBuf>,
        #[command(flatten)]
        settings: SettingsArgs,
    },
    /// List every code velvet reports, with its severity and description.
    Codes {
        #[arg(long, value_enum, default_value_t = CodesFormat::Text)]
        format: CodesFormat,
    },
    /// Print a shell completion script.
    ///
    /// For example `velvet completions bash > ~/.local/share/bash-completion/completions/velvet`.
    Completions { shell: clap_complete::Shell },
    /// Print the man page (roff), or write one page per command into DIR.
    Man {
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
}

/// Settings shared by `validate` and `config`; each flag given beats velvet.toml.
#[derive(clap::Args)]
struct SettingsArgs {
    /// Use FILE for every input instead of the velvet.toml found above each one.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Report at most N issues per file (the report then says truncated); 0: no limit.
    #[arg(long, value_name = "N")]
    max_issues: Option<usize>,
    /// Leave out issues with this code (repeatable).
    #[arg(long, value_name = "CODE", conflicts_with = "only")]
    ignore: Vec<String>,
    /// Report only issues with this code (repeatable).
    #[arg(long, value_name = "CODE")]
    only: Vec<String>,
    /// Give CODE another severity: error, warning, info, hint or 0-3 (repeatable).
    #[arg(long = "override", value_name = "CODE=SEVERITY")]
    overrides: Vec<String>,
    /// The lowest severity that makes the exit status 1 [default: error].
    #[arg(long, value_enum)]
    fail_on: Option<FailOnArg>,
}

#[derive(clap::Args)]
struct ValidateArgs {
    /// Files and folders to check (folders are searched for *.gltf and *.glb).
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    #[command(flatten)]
    settings: SettingsArgs,
    /// Read schema files from DIR instead of the built-in ones (files absent there stay built-in).
    #[arg(long, value_name = "DIR")]
    schema_dir: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum CodesFormat {
    Text,
    Markdown,
}

#[derive(Clone, Copy, ValueEnum)]
enum FailOnArg {
    Error,
    Warning,
    Info,
}

fn usage_error(message: impl std::fmt::Display) -> ExitCode {
    eprintln!("velvet: {message}");
    ExitCode::from(2)
}

/// Writes to standard output; a closed pipe (`velvet … | head`) is not an error.
fn emit(text: &[u8]) {
    let _ = std::io::stdout().lock().write_all(text);
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Validate(args) => validate(args, cli.color, cli.quiet),
        Command::Config { path, settings } => show_config(path, settings),
        Command::Codes { format } => {
            emit(codes_table(format).as_bytes());
            ExitCode::SUCCESS
        }
        Command::Completions { shell } => {
            let mut out = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "velvet", &mut out);
            emit(&out);
            ExitCode::SUCCESS
        }
        Command::Man { dir } => man(dir),
    }
}

fn man(dir: Option<PathBuf>) -> ExitCode {
    match dir {
        Some(dir) => match cli_docs::write_man_pages(Cli::command(), &dir) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => usage_error(format!(
                "cannot write man pages into {}: {e}",
                dir.display()
            )),
        },
        None => match cli_docs::man_page(Cli::command()) {
            Ok(page) => {
                emit(&page);
                ExitCode::SUCCESS
            }
            Err(e) => usage_error(e),
        },
    }
}

fn codes_table(format: CodesFormat) -> String {
    let codes = diagnostics::all_codes();
    match format {
        CodesFormat::Text => {
            let width = codes.iter().map(|c| c.name.len()).max().unwrap_or(0);
            codes
                .iter()
                .map(|c| format!("{:width$}  {:7}  {}\n", c.name, c.severity.as_str(), c.doc))
                .collect()
        }
        CodesFormat::Markdown => {
            let mut out = String::from("| code | severity | meaning |\n|---|---|---|\n");
            for c in codes {
                out += &format!(
                    "| `{}` | {} | {} |\n",
                    c.name,
                    c.severity,
                    c.doc.replace('|', "\\|")
                );
            }
            out
        }
    }
}

fn resolver(args: &SettingsArgs) -> Result<Resolver, config::ConfigError> {
    let fail_on = args.fail_on.map(|f| match f {
        FailOnArg::Error => FailOn::Error,
        FailOnArg::Warning => FailOn::Warning,
        FailOnArg::Info => FailOn::Info,
    });
    let layer = Layer::command_line(
        args.max_issues,
        &args.ignore,
        &args.only,
        &args.overrides,
        fail_on,
    )?;
    Resolver::new(args.config.as_deref(), layer)
}

fn show_config(path: Option<PathBuf>, args: SettingsArgs) -> ExitCode {
    let path = path.unwrap_or_else(|| PathBuf::from("."));
    let config = match resolver(&args).and_then(|mut r| r.for_path(&path)) {
        Ok(c) => c,
        Err(e) => return usage_error(e),
    };
    let mut text = String::new();
    if config.excludes(&config::absolute(&path)) {
        text += &format!(
            "# {} is excluded by this configuration\n",
            report::display_path(&path)
        );
    }
    text += &config.to_toml();
    emit(text.as_bytes());
    ExitCode::SUCCESS
}

fn validate(args: ValidateArgs, color: ColorChoice, quiet: bool) -> ExitCode {
    let mut resolver = match resolver(&args.settings) {
        Ok(r) => r,
        Err(e) => return usage_error(e),
    };
    let schemas = match &args.schema_dir {
        Some(dir) => match Schemas::with_overrides(dir) {
            Ok(s) => s,
            Err(e) => return usage_error(e),
        },
        None => Schemas::builtin(),
    };
    let validator = Validator::new(schemas, Settings::default());
    let progress = report::progress_bar(quiet);
    let outcome =
        match velvet::run::validate(&validator, &args.paths, &mut resolver, progress.as_ref()) {
            Ok(o) => o,
            Err(e) => return usage_error(e),
        };
    let options = report::Options {
        color: args.format == Format::Text && color.for_stdout(),
        quiet,
    };
    emit(report::render(args.format, &outcome.reports, &options).as_bytes());
    if outcome.failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
