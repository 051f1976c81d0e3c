//! The `velvet` command line: parses the arguments into the library's requests, runs the
//! command ([`velvet::command`]) and makes its status the exit code (0 clean, 1 issues at or
//! above --fail-on or a file failed, 2 usage or configuration error, 130 / 143 stopped).

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use velvet::asset::discover::{self, Shard};
use velvet::cli_docs::{self, EXIT_STATUS, EXIT_STATUS_ALL};
use velvet::command::{self, ReportFormat, Status};
use velvet::config;
use velvet::diagnostics::FailOn;
use velvet::migrate;
use velvet::output::paths::Destination;
use velvet::output::summary::Detail;
use velvet::report::{self, ColorChoice, Format};

/// On Linux with glibc, the process allocates from mimalloc: validating makes and drops many
/// small values, and glibc's malloc and free were a sixth of the processor time of a
/// validation with fixes (500 small files: 49.6 → 42.8 ms, 89.5 → 76.7 ms of processor time;
/// docs/performance.md).
/// Elsewhere the system's allocator, where it was not measured.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// mimalloc's `mi_option_arena_eager_commit` (include/mimalloc.h of the pinned
/// libmimalloc-sys, whose Rust bindings do not name it): whether the memory mimalloc reserves
/// from the system is committed whole at once.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MI_OPTION_ARENA_EAGER_COMMIT: libmimalloc_sys::mi_option_t = 4;

/// mimalloc commits the memory it reserves as it is used, not all at once: committed at once
/// (its default on Linux), each run peaked 13–85 MiB higher than with glibc's allocator (the
/// 500 small files 31–33 MiB instead of 18, the library 87–103 instead of 57–58), for no
/// speed on the small files and the data library and some 10 % less processor time on the
/// library. Returning freed memory at once instead (`purge_delay` 0) kept the library's speed
/// and half the extra memory, but the data rules, which free and take again each accessor's
/// bytes, went from 37 to 58 ms.
///
/// The option is read when mimalloc first reserves memory, which the Rust runtime's start
/// already asks for, before `main`: it is set by a constructor of the executable, which the
/// loader runs before the runtime starts.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
extern "C" fn tune_allocator() {
    // SAFETY: mi_option_set stores an option's value, read by mimalloc when it next reserves
    // memory from the system; it touches no allocation.
    unsafe {
        libmimalloc_sys::mi_option_set(MI_OPTION_ARENA_EAGER_COMMIT, 0);
    }
}

/// [`tune_allocator`] as a constructor of the executable (`.init_array`, which the loader runs
/// before the Rust runtime starts): std has no hook before its runtime's first allocation.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[used]
#[link_section = ".init_array"]
static TUNE_ALLOCATOR: extern "C" fn() = tune_allocator;

#[derive(Parser)]
#[command(
    name = "velvet",
    // The package version, and the commit it was built from when built from a checkout
    // (build.rs).
    version = env!("VELVET_VERSION"),
    about = "Validate, migrate and bake glTF assets that use KHR_materials_sheen and KHR_materials_fuzz"
)]
#[command(after_help = EXIT_STATUS_ALL)]
struct Cli {
    /// When to colour output: auto colours on a terminal unless NO_COLOR is set.
    #[arg(long, value_enum, global = true, default_value_t = ColorChoice::Auto, value_name = "WHEN")]
    color: ColorChoice,
    /// Less output, no summary line and no progress bar: validate prints its findings only,
    /// migrate and bake only the files that failed, preview nothing (errors still go to
    /// standard error; JSON output is always complete).
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
    /// Add KHR_materials_fuzz to sheen materials (keeping the sheen as the fallback), a fallback
    /// sheen to fuzz materials, and upgrade the pre-ratification sheen draft.
    Migrate(MigrateArgs),
    /// Render contact sheets (PNG) of each sheen or fuzz material: as authored, as migrated
    /// and as a loader without fuzz sees it, with the report's figures, plus an index.html.
    Preview(PreviewArgs),
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
    /// Bake sheen and fuzz texture × factor into new textures, once per distinct combination.
    Bake(BakeArgs),
    /// List every code velvet reports, with its severity and description.
    Codes {
        /// Output format.
        #[arg(long, value_enum, default_value_t = CodesFormat::Text)]
        format: CodesFormat,
    },
    /// Print a shell completion script.
    ///
    /// For example `velvet completions bash > ~/.local/share/bash-completion/completions/velvet`.
    Completions { shell: clap_complete::Shell },
    /// Print the man page (roff), or write one page per command into DIR.
    Man {
        /// Write velvet.1 and a page per command (velvet-validate.1, …) into DIR instead of
        /// printing velvet.1.
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
    /// Numeric reports for developers: what velvet's shading methods cost and how far they are
    /// off (docs/shading.md). Not part of the user interface: built with `--features bench`.
    #[cfg(feature = "bench")]
    #[command(subcommand, hide = true)]
    Bench(velvet::bench::BenchCommand),
}

/// Settings shared by `validate` and `config`; each flag given beats velvet.toml.
#[derive(clap::Args)]
struct SettingsArgs {
    /// Use FILE for every input instead of the velvet.toml found above each one.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// List at most N issues per file, the most severe first (the report says how many it left
    /// out; the exit status and counts still come from every finding); 0: no limit.
    #[arg(long, value_name = "N")]
    max_issues: Option<usize>,
    /// Leave out issues with this code (repeatable); adds to the codes velvet.toml ignores.
    #[arg(long, value_name = "CODE", conflicts_with = "only")]
    ignore: Vec<String>,
    /// Report only issues with this code (repeatable); replaces velvet.toml's ignore/only.
    #[arg(long, value_name = "CODE")]
    only: Vec<String>,
    /// Give CODE another severity: error, warning, info, hint or 0-3 (repeatable).
    #[arg(long = "override", value_name = "CODE=SEVERITY")]
    overrides: Vec<String>,
    /// The lowest severity that makes the exit status 1 [default: error].
    #[arg(long, value_enum)]
    fail_on: Option<FailOnArg>,
    /// Check the JSON, the GLB container and image headers only: do not read accessor data
    /// (bounds, indices, keyframes, weights, …) nor image bytes beyond their headers.
    #[arg(long)]
    no_data: bool,
}

/// Limits for reading assets nobody checked; each refusal names the flag that raises it.
#[derive(clap::Args)]
struct LoadArgs {
    /// Refuse a JSON document (a .gltf, or a .glb's JSON chunk) larger than this (K, M, G
    /// suffixes: binary units).
    #[arg(long, value_name = "BYTES", default_value_t = velvet::asset::limits::DEFAULT_MAX_DOCUMENT_BYTES,
          value_parser = parse_bytes)]
    max_document_bytes: u64,
    /// Refuse JSON that nests arrays and objects deeper than this (at most 127).
    #[arg(long, value_name = "N", default_value_t = velvet::asset::limits::DEFAULT_MAX_JSON_DEPTH as u16,
          value_parser = clap::value_parser!(u16).range(1..=velvet::asset::limits::JSON_DEPTH_CEILING as i64))]
    max_json_depth: u16,
    /// Refuse to decode an image whose header declares more pixels (width × height) than this.
    #[arg(long, value_name = "PIXELS", default_value_t = velvet::asset::limits::DEFAULT_MAX_IMAGE_PIXELS)]
    max_image_pixels: u64,
    /// The memory budget in bytes (K, M, G suffixes: binary units); default a quarter of the
    /// machine's memory. A file or image that would need more to read or decode is refused.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    max_memory: Option<u64>,
    /// Read resources whose URI leaves the asset's folder (../, absolute paths, file:).
    /// Outputs never follow such URIs.
    #[arg(long)]
    allow_outside_uris: bool,
}

impl LoadArgs {
    fn options(&self) -> velvet::asset::LoadOptions {
        velvet::asset::LoadOptions {
            max_document_bytes: self.max_document_bytes,
            max_json_depth: usize::from(self.max_json_depth),
            max_image_pixels: self.max_image_pixels,
            max_memory: self
                .max_memory
                .unwrap_or_else(velvet::asset::limits::default_max_memory),
            allow_outside_uris: self.allow_outside_uris,
        }
    }
}

/// A byte count: digits, then K, M, G or T (binary units, an optional "iB" or "B").
fn parse_bytes(text: &str) -> Result<u64, String> {
    let upper = text.trim().to_ascii_uppercase();
    let number = upper.trim_end_matches('B').trim_end_matches('I');
    let (digits, shift) = match number.char_indices().last() {
        Some((at, 'K')) => (&number[..at], 10),
        Some((at, 'M')) => (&number[..at], 20),
        Some((at, 'G')) => (&number[..at], 30),
        Some((at, 'T')) => (&number[..at], 40),
        _ => (number, 0),
    };
    digits
        .trim()
        .parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(1 << shift))
        .ok_or_else(|| format!("{text:?} is not a byte count (e.g. 2147483648, 512M, 4G)"))
}

/// The files a command works on, shared by `validate`, `migrate` and `bake`.
#[derive(clap::Args)]
struct InputArgs {
    /// Files and folders (folders are searched for *.gltf and *.glb, in any letter case).
    #[arg(required_unless_present = "files_from")]
    paths: Vec<PathBuf>,
    /// Also take the paths listed in FILE ('-': standard input), one per line or NUL-separated
    /// (as `git diff --name-only -z` prints them). Entries other than folders and .gltf/.glb
    /// files are skipped.
    #[arg(long, value_name = "FILE")]
    files_from: Option<PathBuf>,
    /// Work on part K of N of the files found (e.g. 2/4): N jobs given the same inputs each
    /// take a different part, every file in exactly one, parts of similar size in bytes.
    #[arg(long, value_name = "K/N")]
    shard: Option<Shard>,
}

impl InputArgs {
    /// The paths named on the command line and in the list, checked: a path that does not
    /// exist, or a folder without any asset, is a usage error.
    fn resolve(&self) -> Result<Vec<PathBuf>, discover::InputError> {
        discover::resolve(&self.paths, self.files_from.as_deref())
    }
}

/// Where a file command writes, the same for migrate and bake.
#[derive(clap::Args)]
struct DestinationArgs {
    /// Write the one input's output here (same container as the input).
    #[arg(short = 'o', long = "output", value_name = "FILE", conflicts_with_all = ["out_dir", "in_place"])]
    output: Option<PathBuf>,
    /// Write outputs under DIR, mirroring each input folder's tree.
    #[arg(long, value_name = "DIR", conflicts_with = "in_place")]
    out_dir: Option<PathBuf>,
    /// Overwrite the inputs (a file with nothing to change is not written).
    #[arg(long)]
    in_place: bool,
}

impl DestinationArgs {
    fn destination(self) -> Destination {
        Destination::from_flags(self.output, self.out_dir, self.in_place)
    }
}

#[derive(clap::Args)]
struct ValidateArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Text output: print every finding (each missing resource too), instead of one per code,
    /// message and file with a count and the first positions of the others.
    #[arg(long)]
    no_fold: bool,
    /// Show everything: every finding on its own line, as --no-fold (the flag migrate and bake
    /// also take).
    #[arg(long, short)]
    verbose: bool,
    #[command(flatten)]
    settings: SettingsArgs,
    /// Read schema files from DIR instead of the built-in ones (files absent there stay built-in).
    #[arg(long, value_name = "DIR")]
    schema_dir: Option<PathBuf>,
    #[command(flatten)]
    load: LoadArgs,
    /// Repair the findings a safe fix can repair, in place, and report what remains (the exit
    /// status follows the findings left).
    #[arg(long)]
    fix: bool,
    /// With --fix or --diff: apply unsafe fixes too (they change the asset's meaning as their
    /// findings imply; each is named in the output).
    #[arg(long)]
    unsafe_fixes: bool,
    /// Print the fixes as a unified diff; write nothing (exit status 1 when there is one).
    #[arg(long, conflicts_with = "fix")]
    diff: bool,
    /// With --fix: exit with status 1 when a file was changed (for pre-commit hooks).
    #[arg(long, requires = "fix")]
    exit_non_zero_on_fix: bool,
    /// --fix, printing only the findings left unfixed (not the fixes applied): for hooks.
    #[arg(long, conflicts_with = "diff")]
    fix_only: bool,
}

#[derive(clap::Args)]
#[command(
    after_help = "Exit status: 0 done, 1 a file failed (the others are still baked), 2 usage error (nothing written), 130 / 143 stopped by SIGINT / SIGTERM (finished files complete, nothing left of the others)."
)]
struct BakeArgs {
    #[command(flatten)]
    input: InputArgs,
    #[command(flatten)]
    destination: DestinationArgs,
    /// Print what would be baked; write nothing.
    #[arg(long)]
    dry_run: bool,
    /// .gltf: store new images as data: URIs instead of files next to the output.
    #[arg(long)]
    embed: bool,
    /// Bake factors outside [0, 1] (clamped; the clamping is counted).
    #[arg(long)]
    allow_out_of_range: bool,
    /// Turn a texture whose texels are all equal after baking into a factor.
    #[arg(long)]
    collapse_uniform: bool,
    /// Keep JPEG textures as JPEG (lossy) instead of lossless PNG.
    #[arg(long)]
    keep_format: bool,
    /// Measure and print each output's largest error in codes (and show every slot and
    /// output, as --verbose).
    #[arg(long)]
    report: bool,
    /// Show every slot baked and every output written under its file's line.
    #[arg(long, short)]
    verbose: bool,
    /// PNG compression effort for new images.
    #[arg(long, value_enum, default_value_t = Compression::Fast)]
    compression: Compression,
    /// An output in another folder refers back to the input's resources (URIs rewritten to
    /// lead there) instead of getting its own copies beside it (the default).
    #[arg(long)]
    rewrite_uris: bool,
    /// Copy resources beside outputs in another folder (never hard links): the default, kept so
    /// that existing scripts run.
    #[arg(long, hide = true, conflicts_with = "rewrite_uris")]
    copy_resources: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = ReportFormat::Text)]
    format: ReportFormat,
    #[command(flatten)]
    load: LoadArgs,
}

#[derive(clap::Args)]
#[command(
    after_help = "Exit status: 0 done, 1 a file could not be previewed or an output not written (the other sheets are still written), 2 usage error (nothing written), 130 / 143 stopped by SIGINT / SIGTERM (the sheets written are complete and listed in index.json)."
)]
struct PreviewArgs {
    /// Files and folders (folders are searched for *.gltf and *.glb, in any letter case).
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// The folder the sheets and index pages are written into.
    #[arg(short, long, value_name = "DIR", default_value = "velvet-preview")]
    output: PathBuf,
    /// Draw only the N sheets the plan's verdict ranks worst (its ꟻLIP in the furnace, known
    /// before anything is drawn); the index lists the others.
    #[arg(long, value_name = "N")]
    worst: Option<usize>,
    #[command(flatten)]
    load: LoadArgs,
}

#[derive(Clone, Copy, ValueEnum)]
enum Compression {
    Fast,
    Balanced,
    Best,
}

#[derive(Clone, Copy, ValueEnum)]
enum CodesFormat {
    /// A header line, then one line per code: name, severity, fix, description.
    Text,
    /// A Markdown table (docs/codes.md is this output).
    Markdown,
}

#[derive(Clone, Copy, ValueEnum)]
enum FailOnArg {
    Error,
    Warning,
    Info,
    Hint,
}

/// Runs `job` on a worker of the thread pool, the calling thread asleep until it is done. On the
/// calling thread it would be a thread beside the pool's workers (one per core), and the
/// workers that wait for work between its parallel steps yield in a loop for a while before
/// they sleep, taking turns on the cores with it.
fn in_pool<T: Send>(job: impl FnOnce() -> T + Send) -> T {
    rayon::scope(|_| job())
}

fn main() -> ExitCode {
    velvet::output::interrupt::ignore_file_size_signal();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(mut e) => {
            // A validate run refused for its arguments (a mistyped flag or value) still writes
            // the report its --format asks for, as every other run that cannot start does.
            if e.use_stderr() {
                if let Some(format) = validate_format_asked(std::env::args_os().skip(1)) {
                    // clap's own wording, its first line: "unexpected argument '--formt' found".
                    let rendered = e.render().to_string();
                    let first = rendered.lines().next().unwrap_or_default();
                    let message = first.strip_prefix("error: ").unwrap_or(first);
                    command::emit(report::failed_run(format, message, true).as_bytes());
                }
            } else {
                // --help and --version: their text is the output, and a failure to write it
                // fails the run as any other output's would.
                command::stdout_written(e.print());
                return ExitCode::from(command::finish(Status::Done).code());
            }
            without_dash_dash_tip(&mut e);
            e.exit()
        }
    };
    let status = match cli.command {
        Command::Validate(args) => in_pool(|| validate(args, cli.color, cli.quiet)),
        Command::Migrate(args) => in_pool(|| migrate(args, cli.quiet)),
        Command::Config { path, settings } => config(path, settings),
        Command::Bake(args) => bake(args, cli.quiet),
        Command::Preview(args) => command::preview::command(&command::preview::Request {
            inputs: args.paths,
            output: args.output,
            worst: args.worst,
            load: args.load.options(),
            quiet: cli.quiet,
        }),
        Command::Codes { format } => {
            command::emit(codes_table(format).as_bytes());
            Status::Done
        }
        Command::Completions { shell } => {
            let mut out = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "velvet", &mut out);
            command::emit(&out);
            Status::Done
        }
        Command::Man { dir } => man(dir),
        #[cfg(feature = "bench")]
        Command::Bench(cmd) => match velvet::bench::run(&cmd, &mut std::io::stdout().lock()) {
            Ok(()) => Status::Done,
            Err(e) => command::usage_error(e),
        },
    };
    ExitCode::from(command::finish(status).code())
}

/// The output format a `velvet validate` command line asks for, read from the raw arguments
/// of a command line clap refused: the last `--format F` or `--format=F` with a known F, if the
/// command is validate.
fn validate_format_asked(args: impl Iterator<Item = std::ffi::OsString>) -> Option<Format> {
    let args: Vec<String> = args.map(|a| a.to_string_lossy().into_owned()).collect();
    // The subcommand is the first argument that is not an option or its value (--color WHEN).
    let mut i = 0;
    while i < args.len() && args[i].starts_with('-') {
        i += if args[i] == "--color" { 2 } else { 1 };
    }
    if args.get(i).map(String::as_str) != Some("validate") {
        return None;
    }
    let mut format = None;
    let mut rest = args[i + 1..].iter();
    while let Some(a) = rest.next() {
        let value = match a.strip_prefix("--format") {
            Some("") => rest.next().map(String::as_str),
            Some(v) => v.strip_prefix('='),
            None => None,
        };
        if let Some(f) = value.and_then(|v| Format::from_str(v, false).ok()) {
            format = Some(f);
        }
    }
    format
}

fn config(path: Option<PathBuf>, settings: SettingsArgs) -> Status {
    let path = path.unwrap_or_else(|| PathBuf::from("."));
    // A path that does not exist would show the defaults of wherever it would be (a typo
    // passing for a folder without velvet.toml): refused, as validate refuses it. Only its
    // existence is checked: a folder without assets has a configuration too.
    if std::fs::symlink_metadata(&path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
        return command::usage_error(discover::InputError::Missing(path));
    }
    match settings.flags().show(&path) {
        Ok(text) => {
            command::emit(text.as_bytes());
            Status::Done
        }
        Err(e) => command::usage_error(e),
    }
}

fn man(dir: Option<PathBuf>) -> Status {
    match dir {
        Some(dir) => match cli_docs::write_man_pages(Cli::command(), &dir) {
            Ok(()) => Status::Done,
            Err(e) => command::usage_error(format!(
                "cannot write man pages into {}: {e}",
                dir.display()
            )),
        },
        // The page lists the pages --dir writes: no velvet-help(1), which it does not.
        None => match cli_docs::man_page(Cli::command().disable_help_subcommand(true)) {
            Ok(page) => {
                command::emit(&page);
                Status::Done
            }
            Err(e) => command::usage_error(e),
        },
    }
}

fn codes_table(format: CodesFormat) -> String {
    report::codes_table(matches!(format, CodesFormat::Markdown))
}

#[derive(clap::Args)]
#[command(
    after_help = "Exit status: 0 done, 1 a file failed (the others are still migrated) or, with --check, a file would change, 2 usage error (nothing written), 130 / 143 stopped by SIGINT / SIGTERM (finished files complete, nothing left of the others)."
)]
struct MigrateArgs {
    #[command(flatten)]
    input: InputArgs,
    #[command(flatten)]
    destination: DestinationArgs,
    /// Print what would change per material; write nothing.
    #[arg(long)]
    dry_run: bool,
    /// Write nothing; exit with status 1 when a file would change (for CI and pre-commit).
    #[arg(long, conflicts_with_all = ["output", "out_dir", "in_place"])]
    check: bool,
    /// With --check: judge appearance instead of change, and fail on a material that would
    /// migrate visibly (also `fail-on-visible = true` in velvet.toml).
    #[arg(long, requires = "check")]
    fail_on_visible: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = ReportFormat::Text)]
    format: ReportFormat,
    /// Decode sheen colour textures to measure what the fast conversion changes (and show
    /// every material's notes, as --verbose).
    #[arg(long)]
    report: bool,
    /// Show every material with something to say, and its notes, under its file's line.
    #[arg(long, short)]
    verbose: bool,
    /// Bake a fuzzTexture and a normalised fuzzColorTexture from each sheen colour texture so
    /// that the fuzz matches the sheen texel by texel (lobe and base attenuation).
    #[arg(long)]
    exact: bool,
    /// .gltf: store baked textures as data: URIs instead of files next to the output.
    #[arg(long)]
    embed: bool,
    /// How roughness is carried between sheen and fuzz: fitted (by appearance: α(r) for the
    /// fuzz, r(α) for a fallback sheen) or identity (the same number).
    #[arg(long, value_enum, default_value_t = RoughnessArg::Fitted, value_name = "MAPPING")]
    roughness: RoughnessArg,
    /// With a roughness texture, copy the roughness (identity) instead of baking a mapped
    /// texture, and say so.
    #[arg(long)]
    fast: bool,
    /// The largest roughness difference a shared mapped roughness texture may leave, per
    /// material, before a dearer plan is taken; `exact` bakes one texture per material.
    #[arg(long, value_name = "DIFFERENCE|exact", default_value = "0.01")]
    roughness_budget: migrate::budget::Budget,
    /// The most new textures (MiB, uncompressed, per file) the default may bake to bring a
    /// material whose migration would be visible to close, as --exact or an exact roughness
    /// bake would; 0 takes none.
    #[arg(long, value_name = "MIB", default_value_t = migrate::verdict::DEFAULT_CLOSER_BUDGET_MIB)]
    closer_budget: u64,
    /// Regenerate the sheen fallback of materials that already have fuzz and sheen.
    #[arg(long)]
    refresh_fallback: bool,
    /// An output in another folder refers back to the input's resources (URIs rewritten to
    /// lead there) instead of getting its own copies beside it (the default).
    #[arg(long)]
    rewrite_uris: bool,
    /// Copy resources beside outputs in another folder (never hard links): the default, kept so
    /// that existing scripts run.
    #[arg(long, hide = true, conflicts_with = "rewrite_uris")]
    copy_resources: bool,
    /// Also write contact sheets of the inputs' sheen and fuzz materials (as authored, as
    /// migrated, without fuzz) and an index.html into DIR, as `velvet preview` does.
    #[arg(long, value_name = "DIR")]
    preview: Option<PathBuf>,
    #[command(flatten)]
    load: LoadArgs,
}

#[derive(Clone, Copy, ValueEnum)]
enum RoughnessArg {
    Fitted,
    Identity,
}

impl SettingsArgs {
    fn flags(self) -> config::Flags {
        config::Flags {
            config: self.config,
            max_issues: self.max_issues,
            ignore: self.ignore,
            only: self.only,
            overrides: self.overrides,
            fail_on: self.fail_on.map(|f| match f {
                FailOnArg::Error => FailOn::Error,
                FailOnArg::Warning => FailOn::Warning,
                FailOnArg::Info => FailOn::Info,
                FailOnArg::Hint => FailOn::Hint,
            }),
            no_data: self.no_data,
        }
    }
}

/// Drops clap's tip for an unknown flag "to pass '--out-dir' as a value, use '-- --out-dir'":
/// what a user who typed an unknown flag meant is a flag (a path that starts with a dash is
/// rare, and `--` before it still works), so the tip misleads. clap keeps its tips as the
/// error's suggestions; a similar flag's name is kept apart from them and stays.
fn without_dash_dash_tip(e: &mut clap::Error) {
    use clap::error::{ContextKind, ContextValue};
    if let Some(ContextValue::StyledStrs(tips)) = e.remove(ContextKind::Suggested) {
        let kept: Vec<_> = tips
            .into_iter()
            .filter(|tip| !tip.to_string().contains("' as a value, use '-- "))
            .collect();
        if !kept.is_empty() {
            e.insert(ContextKind::Suggested, ContextValue::StyledStrs(kept));
        }
    }
}

/// How much a migrate or bake text report says: `-q`, the default, or `-v` (which `also`
/// implies: `--report`, and for bake `--dry-run`).
fn detail(quiet: bool, verbose: bool, also: bool) -> Detail {
    if quiet {
        Detail::Quiet
    } else if verbose || also {
        Detail::Verbose
    } else {
        Detail::Normal
    }
}

fn validate(args: ValidateArgs, color: ColorChoice, quiet: bool) -> Status {
    command::validate::command(&command::validate::Request {
        paths: args.input.paths,
        files_from: args.input.files_from,
        shard: args.input.shard,
        settings: args.settings.flags(),
        schema_dir: args.schema_dir,
        load: args.load.options(),
        format: args.format,
        color,
        quiet,
        no_fold: args.no_fold || args.verbose,
        fix: command::validate::FixFlags {
            fix: args.fix || args.fix_only,
            fix_only: args.fix_only,
            unsafe_fixes: args.unsafe_fixes,
            diff: args.diff,
            exit_non_zero_on_fix: args.exit_non_zero_on_fix,
        },
    })
}

fn migrate(args: MigrateArgs, quiet: bool) -> Status {
    let inputs = match args.input.resolve() {
        Ok(p) => p,
        Err(e) => return command::usage_error(e),
    };
    let request = command::migrate::Request {
        inputs,
        destination: args.destination.destination(),
        options: migrate::Options {
            refresh_fallback: args.refresh_fallback,
            report: args.report,
            exact: args.exact,
            embed: args.embed,
            roughness: match args.roughness {
                RoughnessArg::Fitted => migrate::roughness::RoughnessMapping::Fitted,
                RoughnessArg::Identity => migrate::roughness::RoughnessMapping::Identity,
            },
            fast: args.fast,
            budget: args.roughness_budget,
            rewrite_uris: args.rewrite_uris,
            // The speed paths leave the verdict out unless a view reads it.
            skip_verdict: (args.fast || matches!(args.roughness, RoughnessArg::Identity))
                && args.preview.is_none()
                && !args.check,
            closer_budget: migrate::verdict::CloserBudget(
                args.closer_budget.saturating_mul(1 << 20),
            ),
            load: args.load.options(),
        },
        dry_run: args.dry_run || args.check,
        progress: !quiet,
    };
    let view = command::migrate::View {
        format: args.format,
        detail: detail(quiet, args.verbose, args.report),
        check: args.check,
        fail_on_visible: args.fail_on_visible,
        preview: args.preview,
    };
    command::migrate::command(&request, args.input.shard, &view)
}

fn bake(args: BakeArgs, quiet: bool) -> Status {
    use velvet::command::bake::{Options, Request, View};
    let inputs = match args.input.resolve() {
        Ok(p) => p,
        Err(e) => return command::usage_error(e),
    };
    let request = Request {
        inputs,
        destination: args.destination.destination(),
        dry_run: args.dry_run,
        options: Options {
            plan: velvet::bake::plan::PlanOptions {
                allow_out_of_range: args.allow_out_of_range,
            },
            embed: args.embed,
            collapse_uniform: args.collapse_uniform,
            keep_format: args.keep_format,
            report: args.report,
            png: match args.compression {
                Compression::Fast => velvet::bake::PngCompression::Fast,
                Compression::Balanced => velvet::bake::PngCompression::Default,
                Compression::Best => velvet::bake::PngCompression::Best,
            },
            rewrite_uris: args.rewrite_uris,
            load: args.load.options(),
        },
        progress: !quiet,
    };
    let view = View {
        format: args.format,
        detail: detail(quiet, args.verbose, args.report || args.dry_run),
    };
    command::bake::command(&request, args.input.shard, view)
}

#[cfg(all(test, target_os = "linux", target_env = "gnu"))]
mod tests {
    use super::*;

    /// The option number main.rs sets is mimalloc's eager commit (two before the one the
    /// bindings name `mi_option_large_os_pages`, as in the pinned version's list), and the
    /// constructor has set it before the test harness started.
    #[test]
    fn reserved_memory_is_committed_as_it_is_used() {
        assert_eq!(
            libmimalloc_sys::mi_option_large_os_pages,
            MI_OPTION_ARENA_EAGER_COMMIT + 2
        );
        // SAFETY: mi_option_get reads an option's value.
        let eager = unsafe { libmimalloc_sys::mi_option_get(MI_OPTION_ARENA_EAGER_COMMIT) };
        assert_eq!(eager, 0);
    }
}
