//! The speed-against-error report of the albedo methods: time per evaluation measured in the run,
//! and the max and mean absolute error against quadrature over a dense grid, split into the
//! ordinary region (μ ≥ 0.1, r ≥ 0.25) and the hard region (the rest); and the per-point CSV
//! that lets anyone check velvet's numbers against their own.
//!
//! The same for the fuzz reflectance R(μ, α) (its table against quadrature) and for the
//! roughness mapping (the shipped tables against the reference optimum).
//!
//! The reference values are computed once per run (in parallel) and shared by every method's
//! error; the quadrature's time per evaluation is the mean of those same evaluations, each timed
//! on its own thread. The other methods are timed single-threaded over the grid, repeated until
//! the measurement lasts long enough to be stable; the tables' generation is timed separately.

use crate::shading::albedo::{
    albedo_quadrature, is_ordinary, AlbedoMethod, QUADRATURE_BOUND, QUADRATURE_TOL,
};
use crate::shading::charlie::Visibility;
use crate::shading::fuzz::{
    fuzz_reflectance, reflectance_quadrature, ReflectanceMethod, Scattering, REFLECTANCE_BOUND,
    REFLECTANCE_TOL, TABLE_BOUND_CORNER, TABLE_BOUND_HARD, TABLE_BOUND_ORDINARY,
};
use crate::shading::layering::{FuzzParams, SheenParams};
use crate::shading::mapping::{
    self, layer_match, LayerMatch, FUZZ_FOR_SHEEN_DEVIATION, MAPPING_RMS_LOSS, POOR_MATCH_BELOW,
    SHEEN_FOR_FUZZ_DEVIATION,
};
use crate::shading::{sheen_albedo, table};
use rayon::prelude::*;
use std::fmt;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Points per axis of the report's grid: μ and r = 0, 1/64, …, 1 (0 and 1 exactly included).
pub const REPORT_GRID: usize = 65;

/// The shortest time one timing round of a fast method runs.
const MIN_TIMING: Duration = Duration::from_millis(1);

/// Timing rounds per fast method; the fastest counts. Short rounds, many of them: on a busy
/// machine some round runs without being preempted, and the minimum finds it.
const TIMING_ROUNDS: usize = 50;

/// Grid points at which quadrature is timed (every k-th point of the grid, about this many).
const QUADRATURE_TIMING_POINTS: usize = 256;

/// Timings per quadrature point; the fastest counts, for the same reason.
const QUADRATURE_TIMING_REPEATS: usize = 3;

/// Absolute errors over one region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Largest absolute error.
    pub max: f64,
    /// Mean absolute error.
    pub mean: f64,
    /// Where the largest error is, (μ, r).
    pub worst_at: (f64, f64),
    /// Number of grid points in the region.
    pub points: usize,
}

/// One method's line of the report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodResult {
    /// The method.
    pub method: AlbedoMethod,
    /// Mean time per evaluation, in nanoseconds.
    pub nanos_per_eval: f64,
    /// One-time cost before the first evaluation (generating a table), if any.
    pub setup: Option<Duration>,
    /// Errors against quadrature in the ordinary region (None for quadrature, the reference).
    pub ordinary: Option<ErrorStats>,
    /// Errors against quadrature in the hard region (None for quadrature, the reference).
    pub hard: Option<ErrorStats>,
}

/// The whole report.
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyReport {
    /// Points per axis of the grid.
    pub grid: usize,
    /// Threads that computed the reference grid and the tables.
    pub threads: usize,
    /// The largest error estimate the integrator reported over the grid.
    pub quadrature_max_estimate: f64,
    /// Grid points where the integrator did not reach its tolerance.
    pub quadrature_not_converged: usize,
    /// One line per method, in [`AlbedoMethod::ALL`] order.
    pub methods: Vec<MethodResult>,
}

/// The grid coordinates 0, 1/(n−1), …, 1.
fn axis(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 / (n - 1) as f64).collect()
}

/// Runs the report over an n×n grid (n ≥ 2); [`REPORT_GRID`] is the default.
pub fn accuracy_report(n: usize) -> AccuracyReport {
    assert!(n >= 2, "the grid needs at least 2 points per axis");
    let ax = axis(n);
    let points: Vec<(f64, f64)> = ax
        .iter()
        .flat_map(|&r| ax.iter().map(move |&mu| (mu, r)))
        .collect();

    // Reference values, computed once and shared by every method's errors.
    let reference: Vec<(f64, f64, bool)> = points
        .par_iter()
        .map(|&(mu, r)| {
            let est = albedo_quadrature(mu, r, Visibility::Charlie, QUADRATURE_TOL);
            (est.value, est.error, est.converged)
        })
        .collect();
    let mut methods = vec![MethodResult {
        method: AlbedoMethod::Quadrature,
        nanos_per_eval: quadrature_time_per_eval(&points),
        setup: None,
        ordinary: None,
        hard: None,
    }];

    for method in [AlbedoMethod::Lut16, AlbedoMethod::Lut32, AlbedoMethod::Fit] {
        let t = Instant::now();
        match method {
            AlbedoMethod::Lut16 => drop(table::lut16()),
            AlbedoMethod::Lut32 => drop(table::lut32()),
            _ => {}
        }
        let setup =
            matches!(method, AlbedoMethod::Lut16 | AlbedoMethod::Lut32).then(|| t.elapsed());
        let values: Vec<f64> = points
            .iter()
            .map(|&(mu, r)| sheen_albedo(mu, r, method))
            .collect();
        let errors: Vec<f64> = values
            .iter()
            .zip(&reference)
            .map(|(v, q)| (v - q.0).abs())
            .collect();
        methods.push(MethodResult {
            method,
            nanos_per_eval: time_per_eval(method, &points),
            setup,
            ordinary: Some(stats(&points, &errors, true)),
            hard: Some(stats(&points, &errors, false)),
        });
    }

    AccuracyReport {
        grid: n,
        threads: rayon::current_num_threads(),
        quadrature_max_estimate: reference.iter().map(|x| x.1).fold(0.0, f64::max),
        quadrature_not_converged: reference.iter().filter(|x| !x.2).count(),
        methods,
    }
}

/// Nanoseconds per quadrature, single-threaded: the mean over every k-th grid point (about
/// [`QUADRATURE_TIMING_POINTS`] of them) of the fastest of [`QUADRATURE_TIMING_REPEATS`] timings.
/// The cost varies across the grid (the hard region needs more cells), so the sample spans it.
fn quadrature_time_per_eval(points: &[(f64, f64)]) -> f64 {
    slow_time_per_eval(points, |mu, r| {
        albedo_quadrature(mu, r, Visibility::Charlie, QUADRATURE_TOL).value
    })
}

/// Nanoseconds per call of a costly `f(μ, r)`, as [`quadrature_time_per_eval`] measures it.
fn slow_time_per_eval(points: &[(f64, f64)], f: impl Fn(f64, f64) -> f64) -> f64 {
    let step = points.len().div_ceil(QUADRATURE_TIMING_POINTS).max(1);
    let sample: Vec<(f64, f64)> = points.iter().copied().step_by(step).collect();
    let total: f64 = sample
        .iter()
        .map(|&(mu, r)| {
            (0..QUADRATURE_TIMING_REPEATS)
                .map(|_| {
                    let t = Instant::now();
                    black_box(f(black_box(mu), black_box(r)));
                    t.elapsed().as_nanos() as f64
                })
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    total / sample.len() as f64
}

/// Nanoseconds per call of `sheen_albedo(μ, r, method)` over the grid, single-threaded: the
/// fastest of [`TIMING_ROUNDS`] rounds of at least [`MIN_TIMING`] each, so that other work on the
/// machine inflates the figure as little as possible.
fn time_per_eval(method: AlbedoMethod, points: &[(f64, f64)]) -> f64 {
    fast_time_per_eval(points, |mu, r| sheen_albedo(mu, r, method))
}

/// Nanoseconds per call of a cheap `f(x, y)` over the points, as [`time_per_eval`] measures it.
fn fast_time_per_eval(points: &[(f64, f64)], f: impl Fn(f64, f64) -> f64) -> f64 {
    (0..TIMING_ROUNDS)
        .map(|_| {
            let mut calls = 0u64;
            let t = Instant::now();
            while t.elapsed() < MIN_TIMING {
                for &(x, y) in points {
                    black_box(f(black_box(x), black_box(y)));
                }
                calls += points.len() as u64;
            }
            t.elapsed().as_nanos() as f64 / calls as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn stats(points: &[(f64, f64)], errors: &[f64], ordinary: bool) -> ErrorStats {
    let mut s = ErrorStats {
        max: 0.0,
        mean: 0.0,
        worst_at: (f64::NAN, f64::NAN),
        points: 0,
    };
    let mut sum = 0.0;
    for (&(mu, r), &e) in points.iter().zip(errors) {
        if is_ordinary(mu, r) != ordinary {
            continue;
        }
        s.points += 1;
        sum += e;
        if e > s.max || s.worst_at.0.is_nan() {
            s.max = e;
            s.worst_at = (mu, r);
        }
    }
    if s.points > 0 {
        s.mean = sum / s.points as f64;
    }
    s
}

/// A duration per evaluation in the unit that keeps three or four digits.
fn format_nanos(ns: f64) -> String {
    if ns < 1e3 {
        format!("{ns:.1} ns")
    } else if ns < 1e6 {
        format!("{:.1} µs", ns / 1e3)
    } else {
        format!("{:.1} ms", ns / 1e6)
    }
}

impl fmt::Display for AccuracyReport {
    /// The report as a Markdown table with a short preamble and footnote.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.grid;
        let (ord, hard) = self
            .methods
            .get(1)
            .and_then(|m| Some((m.ordinary?.points, m.hard?.points)))
            .unwrap_or((0, 0));
        writeln!(
            f,
            "Sheen albedo E(μ, r), Charlie visibility: each method against adaptive quadrature."
        )?;
        writeln!(
            f,
            "Grid {n}×{n} (μ, r = 0, 1/{}, …, 1); ordinary region μ ≥ 0.1 and r ≥ 0.25 ({ord} points), hard region the rest ({hard} points).",
            n - 1
        )?;
        writeln!(f)?;
        let header = [
            "method",
            "time/eval",
            "setup",
            "ordinary max",
            "ordinary mean",
            "hard max",
            "hard mean",
            "stated bound (ordinary)",
        ];
        let mut rows: Vec<Vec<String>> = Vec::new();
        for m in &self.methods {
            let cell = |s: Option<ErrorStats>, max: bool| match s {
                Some(s) => format!("{:.2e}", if max { s.max } else { s.mean }),
                None => "reference".to_string(),
            };
            rows.push(vec![
                m.method.name().to_string(),
                format_nanos(m.nanos_per_eval),
                m.setup
                    .map_or("–".to_string(), |d| format!("{:.2} s", d.as_secs_f64())),
                cell(m.ordinary, true),
                cell(m.ordinary, false),
                cell(m.hard, true),
                cell(m.hard, false),
                format!("{:e}", m.method.ordinary_bound()),
            ]);
        }
        markdown_table(f, &header, &rows)?;
        writeln!(f)?;
        writeln!(
            f,
            "Quadrature: tolerance {QUADRATURE_TOL:.0e}, stated bound {QUADRATURE_BOUND:.0e}; its own error estimate is at most {:.1e} over the grid ({} points short of the tolerance).",
            self.quadrature_max_estimate, self.quadrature_not_converged
        )?;
        writeln!(
            f,
            "Times measured in this run, single-threaded, the fastest of repeated timings: quadrature at every k-th grid point (about {QUADRATURE_TIMING_POINTS}), the others over the whole grid; setup = generating the table (on {} threads).",
            self.threads
        )?;
        for m in &self.methods {
            if let (Some(o), Some(h)) = (m.ordinary, m.hard) {
                writeln!(
                    f,
                    "{}: worst ordinary point (μ, r) = ({}, {}), worst hard point ({}, {}).",
                    m.method.name(),
                    o.worst_at.0,
                    o.worst_at.1,
                    h.worst_at.0,
                    h.worst_at.1
                )?;
            }
        }
        Ok(())
    }
}

/// Writes a Markdown table, columns padded to their widest cell.
fn markdown_table(
    f: &mut fmt::Formatter<'_>,
    header: &[&str],
    rows: &[Vec<String>],
) -> fmt::Result {
    let widths: Vec<usize> = (0..header.len())
        .map(|c| {
            rows.iter()
                .map(|r| r[c].chars().count())
                .chain([header[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |f: &mut fmt::Formatter<'_>, cells: &[String]| -> fmt::Result {
        write!(f, "|")?;
        for (c, s) in cells.iter().enumerate() {
            write!(f, " {s:<w$} |", w = widths[c])?;
        }
        writeln!(f)
    };
    line(f, &header.iter().map(|h| h.to_string()).collect::<Vec<_>>())?;
    line(
        f,
        &widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>(),
    )?;
    for r in rows {
        line(f, r)?;
    }
    Ok(())
}

/// The fuzz reflectance's lines of the report: the table against quadrature over the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzAccuracy {
    /// Points per axis of the grid (μ, α = 0, 1/(n − 1), …, 1).
    pub grid: usize,
    /// Nanoseconds per quadrature.
    pub quadrature_nanos: f64,
    /// Nanoseconds per table lookup.
    pub table_nanos: f64,
    /// The table's errors where μ ≥ 0.1 and α ≥ 0.25.
    pub ordinary: ErrorStats,
    /// The table's errors over the rest of the grid.
    pub hard: ErrorStats,
    /// The largest error estimate the integrator reported over the grid.
    pub quadrature_max_estimate: f64,
    /// Grid points where the integrator did not reach its tolerance.
    pub quadrature_not_converged: usize,
}

/// Runs the fuzz reflectance's report over an n×n grid of (μ, α) (n ≥ 2).
pub fn fuzz_accuracy(n: usize) -> FuzzAccuracy {
    assert!(n >= 2, "the grid needs at least 2 points per axis");
    let ax = axis(n);
    let points: Vec<(f64, f64)> = ax
        .iter()
        .flat_map(|&a| ax.iter().map(move |&mu| (mu, a)))
        .collect();
    let reference: Vec<(f64, f64, bool)> = points
        .par_iter()
        .map(|&(mu, a)| {
            let est = reflectance_quadrature(mu, a, Scattering::Total, REFLECTANCE_TOL);
            (est.value, est.error, est.converged)
        })
        .collect();
    let errors: Vec<f64> = points
        .iter()
        .zip(&reference)
        .map(|(&(mu, a), q)| (fuzz_reflectance(mu, a, ReflectanceMethod::Table) - q.0).abs())
        .collect();
    FuzzAccuracy {
        grid: n,
        quadrature_nanos: slow_time_per_eval(&points, |mu, a| {
            fuzz_reflectance(mu, a, ReflectanceMethod::Quadrature)
        }),
        table_nanos: fast_time_per_eval(&points, |mu, a| {
            fuzz_reflectance(mu, a, ReflectanceMethod::Table)
        }),
        ordinary: stats(&points, &errors, true),
        hard: stats(&points, &errors, false),
        quadrature_max_estimate: reference.iter().map(|x| x.1).fold(0.0, f64::max),
        quadrature_not_converged: reference.iter().filter(|x| !x.2).count(),
    }
}

impl fmt::Display for FuzzAccuracy {
    /// The fuzz reflectance's lines as a Markdown table with a preamble and footnote.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.grid;
        writeln!(
            f,
            "Fuzz reflectance R(μ, α): the 33×33 table (bicubic in √μ and α) against adaptive quadrature."
        )?;
        writeln!(
            f,
            "Grid {n}×{n} (μ, α = 0, 1/{}, …, 1); ordinary region μ ≥ 0.1 and α ≥ 0.25 ({} points), hard region the rest ({} points).",
            n - 1,
            self.ordinary.points,
            self.hard.points
        )?;
        writeln!(f)?;
        let header = [
            "method",
            "time/eval",
            "ordinary max",
            "ordinary mean",
            "hard max",
            "hard mean",
            "stated bound (ordinary / hard)",
        ];
        let e = |v: f64| format!("{v:.2e}");
        let rows = vec![
            vec![
                ReflectanceMethod::Quadrature.name().to_string(),
                format_nanos(self.quadrature_nanos),
                "reference".into(),
                "reference".into(),
                "reference".into(),
                "reference".into(),
                format!("{REFLECTANCE_BOUND:e}"),
            ],
            vec![
                ReflectanceMethod::Table.name().to_string(),
                format_nanos(self.table_nanos),
                e(self.ordinary.max),
                e(self.ordinary.mean),
                e(self.hard.max),
                e(self.hard.mean),
                format!("{TABLE_BOUND_ORDINARY:e} / {TABLE_BOUND_HARD:e}"),
            ],
        ];
        markdown_table(f, &header, &rows)?;
        writeln!(f)?;
        writeln!(
            f,
            "Quadrature: tolerance {REFLECTANCE_TOL:.0e}, stated bound {REFLECTANCE_BOUND:.0e}; its own error estimate is at most {:.1e} over the grid ({} points short of the tolerance).",
            self.quadrature_max_estimate, self.quadrature_not_converged
        )?;
        writeln!(
            f,
            "table: worst ordinary point (μ, α) = ({}, {}), worst hard point ({}, {}). Between μ = 0 and 0.01 (not on this grid) the table can miss the single-scattering step of small α by up to {TABLE_BOUND_CORNER}.",
            self.ordinary.worst_at.0,
            self.ordinary.worst_at.1,
            self.hard.worst_at.0,
            self.hard.worst_at.1
        )
    }
}

/// One direction of the roughness mapping against its reference optimum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MappingAccuracy {
    /// Which way.
    pub direction: Direction,
    /// Nanoseconds per table lookup.
    pub table_nanos: f64,
    /// Nanoseconds per reference optimum (E and R by quadrature at every step).
    pub optimum_nanos: f64,
    /// Where a sheen lobe matches: the deviation of the table from the optimum in roughness,
    /// max and mean, where the max is, and the points.
    pub matched: Deviation,
    /// The rest: sheen roughness below [`POOR_MATCH_BELOW`] (sheen → fuzz), or a best sheen below
    /// it on either side of a table cell, which includes the cell of r(α)'s jump (fuzz → sheen).
    pub poor: Deviation,
}

/// How far the shipped table is from the optimum over a set of roughness values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deviation {
    /// Largest |table − optimum| in roughness.
    pub max: f64,
    /// Mean of it.
    pub mean: f64,
    /// The input roughness where the largest is.
    pub worst_at: f64,
    /// Largest rms(table) − rms(optimum): what the deviation costs in the matched quantity.
    pub max_rms_loss: f64,
    /// Roughness values measured.
    pub points: usize,
}

/// Which way a mapping goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    /// α(r).
    SheenToFuzz,
    /// r(α).
    FuzzToSheen,
}

impl Direction {
    /// The mapping's name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Direction::SheenToFuzz => "α(r), sheen → fuzz",
            Direction::FuzzToSheen => "r(α), fuzz → sheen",
        }
    }

    /// The stated bound on the deviation in roughness where the match is good.
    pub fn stated_deviation(self) -> f64 {
        match self {
            Direction::SheenToFuzz => FUZZ_FOR_SHEEN_DEVIATION,
            Direction::FuzzToSheen => SHEEN_FOR_FUZZ_DEVIATION,
        }
    }
}

/// `n` roughness values in the middle of table cells (where linear interpolation is furthest
/// from the nodes), spread over [0, 1].
pub fn mapping_points(n: usize) -> Vec<f64> {
    assert!(n >= 2);
    let cells = mapping::NODES - 1;
    (0..n)
        .map(|i| ((i * (cells - 1) / (n - 1)) as f64 + 0.5) / cells as f64)
        .collect()
}

/// Both directions of the mapping against the reference optimum at `n` roughness values
/// ([`mapping_points`]), the optima computed in parallel.
pub fn mapping_accuracy(n: usize) -> [MappingAccuracy; 2] {
    let xs = mapping_points(n);
    let timed: Vec<(f64, f64)> = xs.iter().map(|&x| (x, 0.0)).collect();
    [Direction::SheenToFuzz, Direction::FuzzToSheen].map(|direction| {
        let table = |x: f64| match direction {
            Direction::SheenToFuzz => mapping::fuzz_roughness_for_sheen(x),
            Direction::FuzzToSheen => mapping::sheen_roughness_for_fuzz(x),
        };
        let results: Vec<(f64, f64, f64, f64, bool)> = xs
            .par_iter()
            .map(|&x| {
                let t = Instant::now();
                let best = match direction {
                    Direction::SheenToFuzz => mapping::optimal_fuzz_roughness(x),
                    Direction::FuzzToSheen => mapping::optimal_sheen_roughness(x),
                };
                let nanos = t.elapsed().as_nanos() as f64;
                let v = table(x);
                let rms = match direction {
                    Direction::SheenToFuzz => mapping::mapping_rms(x, v),
                    Direction::FuzzToSheen => mapping::mapping_rms(v, x),
                };
                let matched = match direction {
                    Direction::SheenToFuzz => x >= POOR_MATCH_BELOW,
                    Direction::FuzzToSheen => {
                        let nodes = mapping::sheen_for_fuzz_nodes();
                        let cell = ((x * (mapping::NODES - 1) as f64).floor() as usize)
                            .min(mapping::NODES - 2);
                        nodes[cell] >= POOR_MATCH_BELOW && nodes[cell + 1] >= POOR_MATCH_BELOW
                    }
                };
                (
                    x,
                    (v - best.roughness).abs(),
                    rms - best.rms,
                    nanos,
                    matched,
                )
            })
            .collect();
        let deviation = |matched: bool| {
            let set: Vec<_> = results.iter().filter(|r| r.4 == matched).collect();
            let worst =
                set.iter().fold(
                    (f64::NAN, 0.0f64),
                    |w, r| if r.1 >= w.1 { (r.0, r.1) } else { w },
                );
            Deviation {
                max: worst.1,
                mean: set.iter().map(|r| r.1).sum::<f64>() / set.len().max(1) as f64,
                worst_at: worst.0,
                max_rms_loss: set.iter().map(|r| r.2).fold(0.0, f64::max),
                points: set.len(),
            }
        };
        MappingAccuracy {
            direction,
            table_nanos: fast_time_per_eval(&timed, |x, _| table(x)),
            optimum_nanos: results.iter().map(|r| r.3).sum::<f64>() / results.len() as f64,
            matched: deviation(true),
            poor: deviation(false),
        }
    })
}

/// The mapping's lines of the report, as a Markdown table.
pub struct MappingReport<'a>(pub &'a [MappingAccuracy]);

impl fmt::Display for MappingReport<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let points = self
            .0
            .first()
            .map_or(0, |m| m.matched.points + m.poor.points);
        writeln!(
            f,
            "Roughness mapping: the shipped 257-node tables against the reference optimum (E and R by quadrature at every step), at {points} roughness values between table nodes."
        )?;
        writeln!(f)?;
        let header = [
            "mapping",
            "time/eval",
            "optimum time",
            "max deviation (matched)",
            "mean",
            "max rms loss",
            "max deviation (poor match)",
            "stated bounds (deviation, rms loss)",
        ];
        let rows: Vec<Vec<String>> = self
            .0
            .iter()
            .map(|m| {
                vec![
                    m.direction.name().to_string(),
                    format_nanos(m.table_nanos),
                    format_nanos(m.optimum_nanos),
                    format!("{:.2e} ({} points)", m.matched.max, m.matched.points),
                    format!("{:.2e}", m.matched.mean),
                    format!("{:.2e}", m.matched.max_rms_loss.max(m.poor.max_rms_loss)),
                    format!("{:.2e} ({} points)", m.poor.max, m.poor.points),
                    format!("{:e}, {MAPPING_RMS_LOSS:e}", m.direction.stated_deviation()),
                ]
            })
            .collect();
        markdown_table(f, &header, &rows)?;
        writeln!(f)?;
        writeln!(
            f,
            "Deviation in roughness; rms loss = the cosine-weighted rms of E − R with the table's roughness minus that with the optimum's. Matched: r ≥ {POOR_MATCH_BELOW} for α(r); for r(α), cells whose best sheen is r ≥ {POOR_MATCH_BELOW} at both ends (below α = 0.25 the best sheen is none, and the next cell holds the jump)."
        )?;
        writeln!(
            f,
            "Optimum time: wall time of one reference minimisation (Brent on the table's value ± 0.05, each step 30 quadratures of R, or of E for r(α)), mean over the points, which run in parallel on all threads. The points miss the cell of r(α)'s jump, α ∈ (0.25, 0.2539), where the table blends the two branches."
        )?;
        for m in self.0 {
            writeln!(
                f,
                "{}: worst matched point {}, worst poor point {}.",
                m.direction.name(),
                m.matched.worst_at,
                m.poor.worst_at
            )?;
        }
        Ok(())
    }
}

/// Copying the roughness against the fitted mapping, for one roughness value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComparisonRow {
    /// The roughness mapped from (r for sheen → fuzz, α for fuzz → sheen).
    pub from: f64,
    /// The fitted roughness it maps to.
    pub fitted: f64,
    /// |E − R| with the roughness copied.
    pub identity: LayerMatch,
    /// |E − R| with the fitted roughness.
    pub fitted_match: LayerMatch,
}

/// The mapping command's report: copying against fitting, both ways, at a few roughness values.
#[derive(Clone, Debug, PartialEq)]
pub struct MappingComparison {
    /// Sheen r → fuzz α(r).
    pub sheen_to_fuzz: Vec<ComparisonRow>,
    /// Fuzz α → sheen r(α).
    pub fuzz_to_sheen: Vec<ComparisonRow>,
}

/// Compares copying and fitting at each roughness in `values`, with colour and weight 1 (the
/// differences scale with them), E and R by quadrature.
pub fn mapping_comparison(values: &[f64]) -> MappingComparison {
    let full = |r: f64, alpha: f64| {
        layer_match(
            SheenParams {
                color_max3: 1.0,
                roughness: r,
            },
            FuzzParams {
                weight: 1.0,
                roughness: alpha,
            },
        )
    };
    MappingComparison {
        sheen_to_fuzz: values
            .iter()
            .map(|&r| {
                let alpha = mapping::fuzz_roughness_for_sheen(r);
                ComparisonRow {
                    from: r,
                    fitted: alpha,
                    identity: full(r, r),
                    fitted_match: full(r, alpha),
                }
            })
            .collect(),
        fuzz_to_sheen: values
            .iter()
            .map(|&alpha| {
                let r = mapping::sheen_roughness_for_fuzz(alpha);
                ComparisonRow {
                    from: alpha,
                    fitted: r,
                    identity: full(alpha, alpha),
                    fitted_match: full(r, alpha),
                }
            })
            .collect(),
    }
}

impl fmt::Display for MappingComparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let table = |f: &mut fmt::Formatter<'_>, rows: &[ComparisonRow], names: [&str; 2]| {
            let header = [
                names[0],
                names[1],
                "max μ≥0.1, copied",
                "max μ≥0.1, fitted",
                "rms, copied",
                "rms, fitted",
                "note",
            ];
            let body: Vec<Vec<String>> = rows
                .iter()
                .map(|row| {
                    let poor = if names[0] == "r" {
                        row.fitted_match.poor_match
                    } else {
                        row.fitted < POOR_MATCH_BELOW
                    };
                    vec![
                        format!("{}", row.from),
                        format!("{:.3}", row.fitted),
                        format!("{:.3}", row.identity.max_ordinary),
                        format!("{:.3}", row.fitted_match.max_ordinary),
                        format!("{:.3}", row.identity.rms),
                        format!("{:.3}", row.fitted_match.rms),
                        if poor {
                            format!("r < {POOR_MATCH_BELOW}: no good match")
                        } else {
                            String::new()
                        },
                    ]
                })
                .collect();
            markdown_table(f, &header, &body)
        };
        writeln!(
            f,
            "Sheen → fuzz: |E(μ, r) − R(μ, α)| with α = r copied and with α = α(r) fitted (colour and weight 1; the differences scale with them)."
        )?;
        writeln!(f)?;
        table(f, &self.sheen_to_fuzz, ["r", "α(r)"])?;
        writeln!(f)?;
        writeln!(
            f,
            "Fuzz → fallback sheen: |E(μ, r) − R(μ, α)| with r = α copied and with r = r(α) fitted."
        )?;
        writeln!(f)?;
        table(f, &self.fuzz_to_sheen, ["α", "r(α)"])?;
        writeln!(f)?;
        writeln!(
            f,
            "max μ≥0.1: the largest difference over view cosines μ ≥ 0.1; rms: cosine-weighted over μ ∈ [0, 1]. E and R by quadrature."
        )
    }
}

/// A bad line in a points file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PointsError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for PointsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Parses CSV text with the header `mu,r` and one `mu,r` pair per line, both numbers in [0, 1].
/// Blank lines are skipped. The format has two numeric fields and no quoting, so splitting on
/// commas is the whole of it (no CSV crate needed).
pub fn parse_points(text: &str) -> Result<Vec<(f64, f64)>, PointsError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    match lines.next() {
        None => {
            return Err(PointsError {
                line: 1,
                message: "empty file: expected the header `mu,r`".into(),
            })
        }
        Some((n, header)) => {
            let names: Vec<&str> = header
                .trim_start_matches('\u{feff}')
                .split(',')
                .map(str::trim)
                .collect();
            if names != ["mu", "r"] {
                return Err(PointsError {
                    line: n,
                    message: format!("expected the header `mu,r`, found `{header}`"),
                });
            }
        }
    }
    lines
        .map(|(n, l)| {
            let fields: Vec<&str> = l.split(',').map(str::trim).collect();
            if fields.len() != 2 {
                return Err(PointsError {
                    line: n,
                    message: format!("expected 2 fields (mu,r), found {}", fields.len()),
                });
            }
            let value = |name: &str, s: &str| -> Result<f64, PointsError> {
                let v: f64 = s.parse().map_err(|_| PointsError {
                    line: n,
                    message: format!("{name} `{s}` is not a number"),
                })?;
                if !(0.0..=1.0).contains(&v) {
                    return Err(PointsError {
                        line: n,
                        message: format!("{name} {s} is outside [0, 1]"),
                    });
                }
                Ok(v)
            };
            Ok((value("mu", fields[0])?, value("r", fields[1])?))
        })
        .collect()
}

/// The CSV `mu,r,quadrature,lut16,lut32,fit` with one row per point, numbers in Rust's shortest
/// round-trip form.
pub fn points_csv(points: &[(f64, f64)]) -> String {
    let rows: Vec<String> = points
        .par_iter()
        .map(|&(mu, r)| {
            let v = AlbedoMethod::ALL.map(|m| sheen_albedo(mu, r, m));
            format!("{mu},{r},{},{},{},{}\n", v[0], v[1], v[2], v[3])
        })
        .collect();
    let mut out = String::from("mu,r,quadrature,lut16,lut32,fit\n");
    out.extend(rows);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_with_header_blank_lines_crlf_and_bom() {
        let text = "\u{feff}mu,r\r\n0.5,0.25\r\n\r\n 1 , 0 \n0,1\n";
        assert_eq!(
            parse_points(text).unwrap(),
            vec![(0.5, 0.25), (1.0, 0.0), (0.0, 1.0)]
        );
        assert_eq!(parse_points("mu,r\n").unwrap(), vec![]);
    }

    #[test]
    fn bad_points_name_the_line_and_the_problem() {
        let err = |t: &str| parse_points(t).unwrap_err();
        assert_eq!(
            err(""),
            PointsError {
                line: 1,
                message: "empty file: expected the header `mu,r`".into()
            }
        );
        assert_eq!(
            err("r,mu\n0,0\n").to_string(),
            "line 1: expected the header `mu,r`, found `r,mu`"
        );
        assert_eq!(err("0.5,0.5\n").line, 1, "a header is required");
        assert_eq!(
            err("mu,r\n0.5,0.5\n0.1\n").to_string(),
            "line 3: expected 2 fields (mu,r), found 1"
        );
        assert_eq!(
            err("mu,r\n0.5,0.5,1\n").to_string(),
            "line 2: expected 2 fields (mu,r), found 3"
        );
        assert_eq!(
            err("mu,r\nabc,0.5\n").to_string(),
            "line 2: mu `abc` is not a number"
        );
        assert_eq!(
            err("mu,r\n0.5,1.5\n").to_string(),
            "line 2: r 1.5 is outside [0, 1]"
        );
        assert_eq!(
            err("mu,r\n\n\nNaN,0.5\n").to_string(),
            "line 4: mu NaN is outside [0, 1]"
        );
        assert_eq!(
            err("mu,r\n-0.1,0.5\n").to_string(),
            "line 2: mu -0.1 is outside [0, 1]"
        );
    }

    #[test]
    fn points_csv_has_the_header_and_every_method_per_row() {
        let csv = points_csv(&[(0.5, 0.5), (1.0, 0.25)]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "mu,r,quadrature,lut16,lut32,fit");
        assert_eq!(lines.len(), 3);
        let row: Vec<f64> = lines[1].split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!(&row[..2], &[0.5, 0.5]);
        for (k, m) in AlbedoMethod::ALL.iter().enumerate() {
            assert_eq!(row[2 + k], sheen_albedo(0.5, 0.5, *m), "{}", m.name());
        }
    }

    #[test]
    fn fuzz_report_measures_the_table_within_its_bounds() {
        let report = fuzz_accuracy(9);
        assert_eq!(report.quadrature_not_converged, 0);
        assert!(report.quadrature_max_estimate <= REFLECTANCE_TOL);
        assert_eq!(report.ordinary.points, 8 * 7);
        assert_eq!(report.hard.points, 81 - 56);
        assert!(report.ordinary.max <= TABLE_BOUND_ORDINARY, "{report:?}");
        assert!(report.hard.max <= TABLE_BOUND_HARD, "{report:?}");
        assert!(report.table_nanos > 0.0 && report.quadrature_nanos > report.table_nanos);
        let text = report.to_string();
        assert!(
            text.contains("| quadrature ") && text.contains("| table "),
            "{text}"
        );
    }

    #[test]
    fn mapping_points_sit_between_table_nodes() {
        let xs = mapping_points(65);
        assert_eq!(xs.len(), 65);
        assert_eq!(xs[0], 0.5 / 256.0);
        assert_eq!(xs[64], 255.5 / 256.0);
        for x in xs {
            assert_eq!((x * 256.0).fract(), 0.5);
        }
    }

    #[test]
    fn mapping_report_holds_both_directions_within_the_stated_bound() {
        let report = mapping_accuracy(3);
        // Points 0.5/256, 127.5/256 and 255.5/256: the first is a poor match both ways.
        for m in &report {
            assert_eq!(m.matched.points + m.poor.points, 3);
            assert!(m.matched.max <= m.direction.stated_deviation(), "{m:?}");
            assert!(m.matched.max_rms_loss <= MAPPING_RMS_LOSS, "{m:?}");
            assert!(m.poor.max_rms_loss <= MAPPING_RMS_LOSS, "{m:?}");
            assert!(m.optimum_nanos > m.table_nanos);
        }
        assert_eq!(report[0].matched.points, 2);
        assert_eq!(report[1].matched.points, 2);
        let text = MappingReport(&report).to_string();
        assert!(text.contains("| α(r), sheen → fuzz ") && text.contains("| r(α), fuzz → sheen "));
    }

    #[test]
    fn small_report_has_every_method_and_splits_the_regions() {
        let report = accuracy_report(9);
        assert_eq!(report.methods.len(), 4);
        assert_eq!(report.quadrature_not_converged, 0);
        assert!(report.quadrature_max_estimate <= QUADRATURE_TOL);
        // Axis 0, 1/8, …, 1: μ ≥ 0.1 has 8 values, r ≥ 0.25 has 7.
        let lut = report.methods[1];
        assert_eq!(lut.ordinary.unwrap().points, 8 * 7);
        assert_eq!(lut.hard.unwrap().points, 81 - 56);
        for m in &report.methods {
            assert!(m.nanos_per_eval > 0.0);
            if let Some(o) = m.ordinary {
                assert!(
                    o.max <= m.method.ordinary_bound(),
                    "{}: {}",
                    m.method.name(),
                    o.max
                );
                assert!(o.mean <= o.max);
            }
        }
        let text = report.to_string();
        assert!(text.contains("| method "));
        for m in AlbedoMethod::ALL {
            assert!(text.contains(&format!("| {} ", m.name())), "{text}");
        }
    }
}
