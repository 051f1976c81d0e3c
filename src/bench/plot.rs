//! The reports drawn as SVG: the accuracy report (max absolute error against time per
//! evaluation, both on log axes, one point per method and region) and the roughness mapping
//! (the sheen albedo E(μ, r) against the fuzz reflectance R(μ, α(r)) for a few r, and the
//! mapping α(r) and its reverse r(α)). Drawn with plotters' SVG backend only (no system fonts:
//! the SVG names a font family and the viewer renders the text).

use super::accuracy::AccuracyReport;
use crate::shading::albedo::{AlbedoMethod, QUADRATURE_BOUND};
use crate::shading::fuzz::{fuzz_reflectance, ReflectanceMethod};
use crate::shading::mapping;
use crate::shading::{sheen_albedo, AlbedoMethod as Method};
use plotters::prelude::*;
use rayon::prelude::*;

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

/// E(μ, r) and R(μ, α(r)) for one sheen roughness.
#[derive(Clone, Debug, PartialEq)]
pub struct LobePair {
    /// The sheen roughness r.
    pub r: f64,
    /// α(r), the fitted fuzz roughness.
    pub alpha: f64,
    /// E(μ_i, r).
    pub sheen: Vec<f64>,
    /// R(μ_i, α(r)).
    pub fuzz: Vec<f64>,
}

/// What the mapping plot draws: E against R(α(r)) on a μ grid for a few r, and both mappings
/// at their table nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct MappingCurves {
    /// The view cosines μ_i = i/(n − 1).
    pub mu: Vec<f64>,
    /// One pair of curves per sheen roughness.
    pub lobes: Vec<LobePair>,
    /// The table nodes j/256.
    pub roughness: Vec<f64>,
    /// α(r) at the nodes.
    pub fuzz_for_sheen: Vec<f64>,
    /// r(α) at the nodes.
    pub sheen_for_fuzz: Vec<f64>,
}

impl MappingCurves {
    /// E and R by quadrature at `samples` view cosines (0 and 1 included) for each r in `rs`.
    pub fn compute(rs: &[f64], samples: usize) -> Self {
        assert!(samples >= 2);
        let mu: Vec<f64> = (0..samples)
            .map(|i| i as f64 / (samples - 1) as f64)
            .collect();
        let lobes = rs
            .iter()
            .map(|&r| {
                let alpha = mapping::fuzz_roughness_for_sheen(r);
                let pairs: Vec<(f64, f64)> = mu
                    .par_iter()
                    .map(|&m| {
                        (
                            sheen_albedo(m, r, Method::Quadrature),
                            fuzz_reflectance(m, alpha, ReflectanceMethod::Quadrature),
                        )
                    })
                    .collect();
                LobePair {
                    r,
                    alpha,
                    sheen: pairs.iter().map(|p| p.0).collect(),
                    fuzz: pairs.iter().map(|p| p.1).collect(),
                }
            })
            .collect();
        MappingCurves {
            mu,
            lobes,
            roughness: (0..mapping::NODES).map(mapping::node).collect(),
            fuzz_for_sheen: mapping::fuzz_for_sheen_nodes().to_vec(),
            sheen_for_fuzz: mapping::sheen_for_fuzz_nodes().to_vec(),
        }
    }
}

/// Colours of the lobe pairs, in order.
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// The mapping plot as SVG text, two panels side by side. Left: for each r, E(μ, r) as a solid
/// line and R(μ, α(r)) dashed in the same colour (the y axis reaches the largest value, so
/// nothing is clipped). Right: α(r) solid, r(α) dashed, and the identity dotted.
pub fn mapping_svg(curves: &MappingCurves) -> Result<String, String> {
    if curves.lobes.is_empty() || curves.mu.len() < 2 || curves.roughness.len() < 2 {
        return Err("nothing to plot".into());
    }
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let top = curves
        .lobes
        .iter()
        .flat_map(|l| l.sheen.iter().chain(&l.fuzz))
        .fold(0.0f64, |a, &b| a.max(b));
    let top = (top * 10.0).ceil() / 10.0;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1200, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let panels = root.split_evenly((1, 2));

        let mut left = ChartBuilder::on(&panels[0])
            .caption(
                "Sheen E(μ, r) solid, fuzz R(μ, α(r)) dashed",
                ("sans-serif", 18),
            )
            .margin(16)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..1.0, 0.0..top)
            .map_err(|e| err(&e))?;
        left.configure_mesh()
            .x_desc("μ = cos θ (view)")
            .y_desc("directional reflectance")
            .draw()
            .map_err(|e| err(&e))?;
        for (k, lobe) in curves.lobes.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let style = colour.stroke_width(2);
            left.draw_series(LineSeries::new(
                curves.mu.iter().copied().zip(lobe.sheen.iter().copied()),
                style,
            ))
            .map_err(|e| err(&e))?
            .label(format!("r = {}, α(r) = {:.3}", lobe.r, lobe.alpha))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            left.draw_series(DashedLineSeries::new(
                curves.mu.iter().copied().zip(lobe.fuzz.iter().copied()),
                6,
                4,
                style,
            ))
            .map_err(|e| err(&e))?;
        }
        left.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(|e| err(&e))?;

        let mut right = ChartBuilder::on(&panels[1])
            .caption(
                "The fitted mapping: α(r) solid, r(α) dashed",
                ("sans-serif", 18),
            )
            .margin(16)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..1.0, 0.0..1.0)
            .map_err(|e| err(&e))?;
        right
            .configure_mesh()
            .x_desc("roughness of the layer mapped from")
            .y_desc("roughness of the layer mapped to")
            .draw()
            .map_err(|e| err(&e))?;
        let forward = PALETTE[0].stroke_width(2);
        let reverse = PALETTE[3].stroke_width(2);
        let identity = RGBColor(150, 150, 150).stroke_width(1);
        right
            .draw_series(LineSeries::new(
                curves
                    .roughness
                    .iter()
                    .copied()
                    .zip(curves.fuzz_for_sheen.iter().copied()),
                forward,
            ))
            .map_err(|e| err(&e))?
            .label("α(r): sheen r → fuzz α")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], forward));
        right
            .draw_series(DashedLineSeries::new(
                curves
                    .roughness
                    .iter()
                    .copied()
                    .zip(curves.sheen_for_fuzz.iter().copied()),
                6,
                4,
                reverse,
            ))
            .map_err(|e| err(&e))?
            .label("r(α): fuzz α → fallback sheen r")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], reverse));
        right
            .draw_series(DashedLineSeries::new(
                [(0.0, 0.0), (1.0, 1.0)],
                2,
                4,
                identity,
            ))
            .map_err(|e| err(&e))?
            .label("identity (copy the number)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], identity));
        right
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
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
    fn mapping_svg_draws_both_panels_and_names_every_r() {
        let curves = MappingCurves {
            mu: vec![0.0, 0.5, 1.0],
            lobes: vec![
                LobePair {
                    r: 0.2,
                    alpha: 0.36,
                    sheen: vec![1.3, 0.2, 0.01],
                    fuzz: vec![0.7, 0.1, 0.0],
                },
                LobePair {
                    r: 1.0,
                    alpha: 0.79,
                    sheen: vec![0.8, 0.35, 0.16],
                    fuzz: vec![0.78, 0.3, 0.2],
                },
            ],
            roughness: vec![0.0, 0.5, 1.0],
            fuzz_for_sheen: vec![0.0, 0.56, 0.79],
            sheen_for_fuzz: vec![0.0, 0.42, 1.0],
        };
        let svg = mapping_svg(&curves).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for text in [
            "r = 0.2, α(r) = 0.360",
            "r = 1, α(r) = 0.790",
            "α(r): sheen r → fuzz α",
            "r(α): fuzz α → fallback sheen r",
            "identity (copy the number)",
        ] {
            assert!(svg.contains(text), "missing {text}");
        }
        assert!(!svg.contains("NaN"));
        let empty = MappingCurves {
            lobes: vec![],
            ..curves
        };
        assert!(mapping_svg(&empty).is_err());
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
