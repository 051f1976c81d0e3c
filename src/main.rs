//! The velvet command line: parses arguments, calls the library, maps outcomes to exit codes.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "velvet", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Numeric reports: what velvet's shading methods cost and how far they are off.
    #[command(subcommand)]
    Bench(velvet::shading::bench::BenchCommand),
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Bench(cmd) => {
            match velvet::shading::bench::run(&cmd, &mut std::io::stdout().lock()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("velvet: {e}");
                    ExitCode::from(2)
                }
            }
        }
    }
}
