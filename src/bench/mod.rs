//! `velvet bench`, developer tooling behind the `bench` feature (outside the default library and
//! binary): the speed-against-error report of the shading maths ([`accuracy`]), drawn as SVG
//! ([`plot`]), and the command that runs them, its arguments and what it runs. The binary only
//! parses and maps the outcome to an exit code; everything here is callable from tests.

pub mod accuracy;
pub mod plot;

use accuracy::{
    accuracy_report, fuzz_accuracy, mapping_accuracy, mapping_comparison, parse_points, points_csv,
    MappingReport, PointsError, REPORT_GRID,
};
use plot::{accuracy_svg, mapping_svg, MappingCurves};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// `velvet bench …`: numeric reports.
#[derive(Debug, Clone, PartialEq, Eq, clap::Subcommand)]
pub enum BenchCommand {
    /// Speed against error of the sheen albedo methods (quadrature, lut16, lut32, fit), of the
    /// fuzz reflectance table, and of the fitted roughness mapping.
    Accuracy(AccuracyArgs),
    /// The fitted sheen ↔ fuzz roughness mapping against copying the roughness.
    Mapping(MappingArgs),
}

/// Arguments of `velvet bench mapping`.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct MappingArgs {
    /// Also write an SVG plot of E(μ, r) against R(μ, α(r)) for r = 0.2, 0.4, …, 1, and of the
    /// mapping itself, to this file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// Roughness values of the mapping command's table.
const COMPARISON_VALUES: [f64; 11] = [0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];

/// Sheen roughness values of the mapping plot.
const PLOT_VALUES: [f64; 5] = [0.2, 0.4, 0.6, 0.8, 1.0];

/// View cosines per curve in the mapping plot.
const PLOT_SAMPLES: usize = 101;

/// Roughness values at which `bench accuracy` measures the mapping against its optimum.
const MAPPING_POINTS: usize = 65;

/// Arguments of `velvet bench accuracy`.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct AccuracyArgs {
    /// Evaluate every method at the points of this CSV file (header `mu,r`) and print CSV
    /// (`mu,r,quadrature,lut16,lut32,fit`) instead of the table.
    #[arg(long, value_name = "FILE", conflicts_with = "plot")]
    pub points: Option<PathBuf>,
    /// Also write an SVG plot of error against time per evaluation to this file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// Why a bench command failed. Each names the file involved.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The points file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: io::Error,
    },
    /// The points file has a bad line.
    #[error("{}: {error}", path.display())]
    Points {
        /// The file.
        path: PathBuf,
        /// The line and what is wrong with it.
        error: PointsError,
    },
    /// The plot could not be drawn or written.
    #[error("{}: cannot write the plot: {message}", path.display())]
    Plot {
        /// The file.
        path: PathBuf,
        /// The cause.
        message: String,
    },
    /// Standard output could not be written.
    #[error("<stdout>: {0}")]
    Output(io::Error),
}

/// Runs a bench command, writing its report to `out`.
pub fn run(command: &BenchCommand, out: &mut dyn Write) -> Result<(), BenchError> {
    match command {
        BenchCommand::Accuracy(args) => run_accuracy(args, out),
        BenchCommand::Mapping(args) => run_mapping(args, out),
    }
}

fn run_mapping(args: &MappingArgs, out: &mut dyn Write) -> Result<(), BenchError> {
    write!(out, "{}", mapping_comparison(&COMPARISON_VALUES)).map_err(BenchError::Output)?;
    if let Some(path) = &args.plot {
        let svg = mapping_svg(&MappingCurves::compute(&PLOT_VALUES, PLOT_SAMPLES));
        write_plot(path, svg)?;
    }
    Ok(())
}

/// Writes a drawn plot (or the reason it could not be drawn) to `path`, atomically.
fn write_plot(path: &Path, svg: Result<String, String>) -> Result<(), BenchError> {
    let plot_error = |message: String| BenchError::Plot {
        path: path.to_path_buf(),
        message,
    };
    let svg = svg.map_err(plot_error)?;
    write_atomically(path, svg.as_bytes()).map_err(|e| plot_error(e.to_string()))
}

fn run_accuracy(args: &AccuracyArgs, out: &mut dyn Write) -> Result<(), BenchError> {
    if let Some(path) = &args.points {
        let text = std::fs::read_to_string(path).map_err(|source| BenchError::Read {
            path: path.clone(),
            source,
        })?;
        let points = parse_points(&text).map_err(|error| BenchError::Points {
            path: path.clone(),
            error,
        })?;
        return out
            .write_all(points_csv(&points).as_bytes())
            .map_err(BenchError::Output);
    }
    let report = accuracy_report(REPORT_GRID);
    write!(out, "{report}").map_err(BenchError::Output)?;
    writeln!(out).map_err(BenchError::Output)?;
    write!(out, "{}", fuzz_accuracy(REPORT_GRID)).map_err(BenchError::Output)?;
    writeln!(out).map_err(BenchError::Output)?;
    let mapping = mapping_accuracy(MAPPING_POINTS);
    write!(out, "{}", MappingReport(&mapping)).map_err(BenchError::Output)?;
    if let Some(path) = &args.plot {
        write_plot(path, accuracy_svg(&report))?;
    }
    Ok(())
}

/// Writes `bytes` to a temporary file beside `path` and renames it into place.
fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_command_prints_csv_and_names_the_file_on_errors() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.csv");
        std::fs::write(&good, "mu,r\n0.5,0.5\n").unwrap();
        let mut out = Vec::new();
        let cmd = BenchCommand::Accuracy(AccuracyArgs {
            points: Some(good.clone()),
            plot: None,
        });
        run(&cmd, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("mu,r,quadrature,lut16,lut32,fit\n0.5,0.5,"));
        assert_eq!(
            std::fs::read_to_string(&good).unwrap(),
            "mu,r\n0.5,0.5\n",
            "input untouched"
        );

        let bad = dir.path().join("bad.csv");
        std::fs::write(&bad, "mu,r\n0.5,x\n").unwrap();
        let cmd = BenchCommand::Accuracy(AccuracyArgs {
            points: Some(bad.clone()),
            plot: None,
        });
        let err = run(&cmd, &mut Vec::new()).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("{}: line 2: r `x` is not a number", bad.display())
        );

        let missing = dir.path().join("missing.csv");
        let cmd = BenchCommand::Accuracy(AccuracyArgs {
            points: Some(missing.clone()),
            plot: None,
        });
        let err = run(&cmd, &mut Vec::new()).unwrap_err();
        assert!(
            err.to_string()
                .starts_with(&format!("{}: cannot read: ", missing.display())),
            "{err}"
        );
    }

    #[test]
    fn mapping_plot_into_a_missing_folder_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/mapping.svg");
        let err = write_plot(&path, Ok("<svg/>".into())).unwrap_err();
        assert!(
            err.to_string()
                .starts_with(&format!("{}: cannot write the plot: ", path.display())),
            "{err}"
        );
        let err = write_plot(&path, Err("nothing to plot".into())).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("{}: cannot write the plot: nothing to plot", path.display())
        );
    }

    #[test]
    fn atomic_write_replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("plot.svg");
        std::fs::write(&path, "old").unwrap();
        write_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let into_missing_dir = dir.path().join("no/such/dir/plot.svg");
        assert!(write_atomically(&into_missing_dir, b"x").is_err());
    }
}
