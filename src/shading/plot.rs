//! The accuracy report drawn as an SVG: max absolute error against time per evaluation, both on
//! log axes, one point per method and region. Drawn with plotters' SVG backend only (no system
//! fonts: the SVG names a font family and the viewer renders the text).

use super::accuracy::AccuracyReport;
use super::albedo::QUADRATURE_BOUND;
use plotters::prelude::*;

/// Width and height of the plot in pixels.
const SIZE: (u32, u32) = (900, 560);

/// (time per evaluation in ns, max error, method name).
type Point<'a> = (f64, f64, &'a str);

/// Errors below this are drawn at it (a log axis has no 0).
const ERROR_FLOOR: f64 = 1e-12;

/// The report's plot as SVG text.
pub fn accuracy_svg(report: &AccuracyReport) -> Result<String, String> {
    let mut ordinary = Vec::new();
    let mut hard = Vec::new();
    let mut quadrature = None;
    for m in &report.methods {
        let t = m.nanos_per_eval.max(1e-3);
        match (m.ordinary, m.hard) {
            (Some(o), Some(h)) => {
                ordinary.push((t, o.max.max(ERROR_FLOOR), m.method.name()));
                hard.push((t, h.max.max(ERROR_FLOOR), m.method.name()));
            }
            _ => quadrature = Some((t, QUADRATURE_BOUND, m.method.name())),
        }
    }
    let all: Vec<&Point> = ordinary
        .iter()
        .chain(&hard)
        .chain(quadrature.iter())
        .collect();
    if all.is_empty() {
        return Err("the report has no methods to plot".into());
    }
    let (t_min, t_max) = all.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    });
    let (e_min, e_max) = all.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Sheen albedo E(μ, r): max error against time per evaluation",
                ("sans-serif", 20),
            )
            .margin(16)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(
                (t_min / 3.0..t_max * 3.0).log_scale(),
                (e_min / 10.0..e_max * 10.0).log_scale(),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("time per evaluation (ns)")
            .y_desc("max |E − E quadrature|")
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;

        let font = ("sans-serif", 13).into_font();
        let series: [(&[Point], RGBColor, &str); 2] = [
            (
                &ordinary,
                RGBColor(31, 119, 180),
                "ordinary region (μ ≥ 0.1, r ≥ 0.25)",
            ),
            (&hard, RGBColor(214, 39, 40), "hard region (the rest)"),
        ];
        for (points, colour, label) in series {
            let mut line: Vec<(f64, f64)> = points.iter().map(|p| (p.0, p.1)).collect();
            line.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(line, colour.stroke_width(1)))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(points.iter().map(|&(t, e, name)| {
                    EmptyElement::at((t, e))
                        + Circle::new((0, 0), 5, colour.filled())
                        + Text::new(name.to_string(), label_offset(name), font.clone())
                }))
                .map_err(|e| e.to_string())?
                .label(label)
                .legend(move |(x, y)| Circle::new((x, y), 5, colour.filled()));
        }
        if let Some((t, e, name)) = quadrature {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((t, e))
                        + TriangleMarker::new((0, 0), 7, BLACK.filled())
                        + Text::new(format!("{name} (stated bound)"), (-150, -18), font.clone()),
                ))
                .map_err(|e| e.to_string())?
                .label("quadrature (the reference), at its stated bound")
                .legend(|(x, y)| TriangleMarker::new((x, y), 6, BLACK.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// Where a method's label sits relative to its point: the table methods run at similar speeds,
/// so their labels are spread vertically and the fit's goes to the left.
fn label_offset(name: &str) -> (i32, i32) {
    match name {
        "lut16" => (9, -18),
        "lut32" => (9, -2),
        "fit" => (-26, -6),
        _ => (9, -10),
    }
}

#[cfg(test)]
mod tests {
    use super::super::accuracy::{ErrorStats, MethodResult};
    use super::super::AlbedoMethod;
    use super::*;

    fn stats(max: f64) -> Option<ErrorStats> {
        Some(ErrorStats {
            max,
            mean: max / 2.0,
            worst_at: (0.0, 0.0),
            points: 1,
        })
    }

    #[test]
    fn svg_names_every_method_and_both_regions() {
        let report = AccuracyReport {
            grid: 2,
            threads: 1,
            quadrature_max_estimate: 1e-8,
            quadrature_not_converged: 0,
            methods: vec![
                MethodResult {
                    method: AlbedoMethod::Quadrature,
                    nanos_per_eval: 5e5,
                    setup: None,
                    ordinary: None,
                    hard: None,
                },
                MethodResult {
                    method: AlbedoMethod::Lut16,
                    nanos_per_eval: 10.0,
                    setup: None,
                    ordinary: stats(1e-3),
                    hard: stats(2.0),
                },
                MethodResult {
                    method: AlbedoMethod::Lut32,
                    nanos_per_eval: 11.0,
                    setup: None,
                    ordinary: stats(3e-4),
                    hard: stats(1.0),
                },
                MethodResult {
                    method: AlbedoMethod::Fit,
                    nanos_per_eval: 0.0,
                    setup: None,
                    ordinary: stats(0.0),
                    hard: stats(5.0),
                },
            ],
        };
        let svg = accuracy_svg(&report).unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(svg.trim_end().ends_with("</svg>"));
        for name in [
            "quadrature (stated bound)",
            "\nlut16\n",
            "\nlut32\n",
            "\nfit\n",
            "ordinary region",
            "hard region",
        ] {
            assert!(svg.contains(name), "missing {name}");
        }
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}
