//! The accuracy report drawn as an SVG: max absolute error against time per evaluation, both on
//! log axes, one point per method and region. Drawn with plotters' SVG backend only (no system
//! fonts: the SVG names a font family and the viewer renders the text).

use super::accuracy::AccuracyReport;
use super::albedo::{AlbedoMethod, QUADRATURE_BOUND};
use plotters::prelude::*;

/// Width and height of the plot in pixels.
const SIZE: (u32, u32) = (900, 560);

/// Errors below this are drawn at it (a log axis has no 0).
const ERROR_FLOOR: f64 = 1e-12;

const ORDINARY: RGBColor = RGBColor(31, 119, 180);
const HARD: RGBColor = RGBColor(214, 39, 40);

/// The report's plot as SVG text. Colour tells the region (blue ordinary, red hard), the marker
/// tells the method (circle lut16, square lut32, triangle fit); quadrature, the reference, is a
/// cross at its stated bound. The table methods run at similar speeds, so a legend names them
/// rather than labels that would overlap.
pub fn accuracy_svg(report: &AccuracyReport) -> Result<String, String> {
    // (method, time per evaluation in ns, ordinary max, hard max); quadrature has no errors.
    let mut rows = Vec::new();
    let mut quadrature = None;
    for m in &report.methods {
        let t = m.nanos_per_eval.max(1e-3);
        match (m.ordinary, m.hard) {
            (Some(o), Some(h)) => {
                rows.push((m.method, t, o.max.max(ERROR_FLOOR), h.max.max(ERROR_FLOOR)))
            }
            _ => quadrature = Some(t),
        }
    }
    let times = rows.iter().map(|r| r.1).chain(quadrature);
    let errors = rows
        .iter()
        .flat_map(|r| [r.2, r.3])
        .chain(quadrature.map(|_| QUADRATURE_BOUND));
    let (t_min, t_max) = times.fold((f64::INFINITY, 0.0f64), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    let (e_min, e_max) = errors.fold((f64::INFINITY, 0.0f64), |(lo, hi), e| {
        (lo.min(e), hi.max(e))
    });
    if !(t_min <= t_max && e_min <= e_max) {
        return Err("the report has no methods to plot".into());
    }
    let err = |e: &dyn std::fmt::Display| e.to_string();

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
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
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("time per evaluation (ns)")
            .y_desc("max |E − E quadrature|")
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(|e| err(&e))?;

        for (method, t, ordinary, hard) in rows {
            let points = [(t, ordinary, ORDINARY), (t, hard, HARD)];
            let name = method.name();
            match method {
                AlbedoMethod::Lut16 => {
                    chart
                        .draw_series(
                            points
                                .iter()
                                .map(|&(t, e, c)| Circle::new((t, e), 5, c.filled())),
                        )
                        .map_err(|e| err(&e))?
                        .label(name)
                        .legend(|(x, y)| Circle::new((x, y), 5, BLACK.filled()));
                }
                AlbedoMethod::Lut32 => {
                    chart
                        .draw_series(points.iter().map(|&(t, e, c)| {
                            EmptyElement::at((t, e))
                                + Rectangle::new([(-4, -4), (4, 4)], c.filled())
                        }))
                        .map_err(|e| err(&e))?
                        .label(name)
                        .legend(|(x, y)| {
                            Rectangle::new([(x - 4, y - 4), (x + 4, y + 4)], BLACK.filled())
                        });
                }
                _ => {
                    chart
                        .draw_series(
                            points
                                .iter()
                                .map(|&(t, e, c)| TriangleMarker::new((t, e), 6, c.filled())),
                        )
                        .map_err(|e| err(&e))?
                        .label(name)
                        .legend(|(x, y)| TriangleMarker::new((x, y), 6, BLACK.filled()));
                }
            }
        }
        if let Some(t) = quadrature {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at((t, QUADRATURE_BOUND))
                        + Cross::new((0, 0), 6, BLACK.stroke_width(2))
                        + Text::new(
                            "quadrature (stated bound)",
                            (-150, -20),
                            ("sans-serif", 13).into_font(),
                        ),
                ))
                .map_err(|e| err(&e))?
                .label("quadrature, the reference, at its stated bound")
                .legend(|(x, y)| Cross::new((x, y), 5, BLACK.stroke_width(2)));
        }
        for (colour, label) in [
            (ORDINARY, "ordinary region (μ ≥ 0.1, r ≥ 0.25)"),
            (HARD, "hard region (the rest)"),
        ] {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(|e| err(&e))?
                .label(label)
                .legend(move |(x, y)| {
                    Rectangle::new([(x - 6, y - 3), (x + 6, y + 3)], colour.filled())
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::super::accuracy::{ErrorStats, MethodResult};
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
