//! Globally adaptive Gauss–Kronrod cubature over a rectangle, to an absolute tolerance.
//!
//! Each cell is integrated with the 15-point Kronrod rule in both directions (225 points); the
//! 7-point Gauss rule on the same points, in one direction at a time, gives one error estimate per
//! direction. The cell with the largest estimate is bisected across the direction that estimate
//! blames, until the estimates add up to less than the tolerance (QUADPACK's QAG, one dimension
//! up).
//!
//! Written here rather than taken from a crate because the albedo integral needs what the Rust
//! quadrature crates do not combine: an absolute (not relative) tolerance, since E(μ, r) tends to 0
//! as r → 0; one error budget over both variables (a nested 1-D integrator must meet its tolerance
//! in every inner integral, which costs several times more here); initial break lines at the
//! integrand's kinks; and a separable integrand f(X(x), Y(y)), so that what depends on one
//! variable only (the visibility of the light direction, the azimuth's cosine) is computed 15
//! times per cell instead of 225.

/// Kronrod nodes on [−1, 1] (non-negative half; the rule is symmetric). Odd indices are the
/// 7-point Gauss nodes; the last is the centre.
#[allow(clippy::excessive_precision)] // QUADPACK's published digits, kept as published.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];

/// Kronrod weights for the nodes of [`XGK`].
#[allow(clippy::excessive_precision)] // QUADPACK's published digits, kept as published.
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];

/// Gauss weights for the nodes `XGK[1]`, `XGK[3]`, `XGK[5]`, `XGK[7]`.
#[allow(clippy::excessive_precision)] // QUADPACK's published digits, kept as published.
const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// The 15 nodes on [−1, 1] in ascending order, their Kronrod weights and their Gauss weights
/// (0 where the node is not a Gauss node).
fn rule() -> ([f64; 15], [f64; 15], [f64; 15]) {
    let mut x = [0.0; 15];
    let mut wk = [0.0; 15];
    let mut wg = [0.0; 15];
    for j in 0..7 {
        x[j] = -XGK[j];
        x[14 - j] = XGK[j];
        wk[j] = WGK[j];
        wk[14 - j] = WGK[j];
        if j % 2 == 1 {
            wg[j] = WG[j / 2];
            wg[14 - j] = WG[j / 2];
        }
    }
    x[7] = 0.0;
    wk[7] = WGK[7];
    wg[7] = WG[3];
    (x, wk, wg)
}

/// The 15-point Kronrod rule on [a, b]: (node, weight) pairs in ascending order of node. Exact
/// for polynomials up to degree 22; used where a fixed 1-D rule is wanted (the roughness
/// mapping's integral over μ).
pub fn kronrod_15(a: f64, b: f64) -> [(f64, f64); 15] {
    let (x, wk, _) = rule();
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    std::array::from_fn(|i| (c + h * x[i], h * wk[i]))
}

/// A function of two variables written as f(X(x), Y(y)), so that X and Y are computed once per
/// node line rather than once per node.
pub trait Separable {
    /// What depends on x alone.
    type X: Copy + Default;
    /// What depends on y alone.
    type Y: Copy + Default;
    /// The x part.
    fn x(&self, x: f64) -> Self::X;
    /// The y part.
    fn y(&self, y: f64) -> Self::Y;
    /// The integrand.
    fn f(&self, x: &Self::X, y: &Self::Y) -> f64;
}

/// The outcome of one adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The integral.
    pub value: f64,
    /// The sum over cells of their error estimates, an estimate of the absolute error.
    pub error: f64,
    /// Integrand evaluations made.
    pub evaluations: u64,
    /// Whether `error` reached the tolerance within the cell limit.
    pub converged: bool,
}

#[derive(Clone, Copy, Debug)]
struct Cell {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    value: f64,
    err_x: f64,
    err_y: f64,
}

impl Cell {
    fn error(&self) -> f64 {
        self.err_x + self.err_y
    }
}

/// The most cells one integration may create before it gives up (and says so).
pub const MAX_CELLS: usize = 4000;

/// ∫∫ f over `[xb[0], xb[last]] × [yb[0], yb[last]]` to absolute tolerance `tol`, starting from the
/// cells between consecutive break values (put them at the integrand's kinks).
pub fn integrate_2d<S: Separable>(f: &S, xb: &[f64], yb: &[f64], tol: f64) -> Estimate {
    assert!(
        xb.len() >= 2 && yb.len() >= 2,
        "need at least two break values per axis"
    );
    let rule = rule();
    let mut cells: Vec<Cell> = Vec::with_capacity(64);
    let mut evaluations = 0u64;
    for wx in xb.windows(2) {
        for wy in yb.windows(2) {
            cells.push(cell(f, &rule, wx[0], wx[1], wy[0], wy[1]));
            evaluations += 225;
        }
    }
    let converged = loop {
        let mut total = 0.0;
        let mut worst = 0;
        for (i, c) in cells.iter().enumerate() {
            total += c.error();
            if c.error() > cells[worst].error() {
                worst = i;
            }
        }
        if total <= tol {
            break true;
        }
        if cells.len() >= MAX_CELLS {
            break false;
        }
        let c = cells[worst];
        let (a, b) = if c.err_x >= c.err_y {
            let mid = 0.5 * (c.x0 + c.x1);
            if mid <= c.x0 || mid >= c.x1 {
                break false;
            }
            (
                cell(f, &rule, c.x0, mid, c.y0, c.y1),
                cell(f, &rule, mid, c.x1, c.y0, c.y1),
            )
        } else {
            let mid = 0.5 * (c.y0 + c.y1);
            if mid <= c.y0 || mid >= c.y1 {
                break false;
            }
            (
                cell(f, &rule, c.x0, c.x1, c.y0, mid),
                cell(f, &rule, c.x0, c.x1, mid, c.y1),
            )
        };
        evaluations += 450;
        cells[worst] = a;
        cells.push(b);
    };
    Estimate {
        value: cells.iter().map(|c| c.value).sum(),
        error: cells.iter().map(|c| c.error()).sum(),
        evaluations,
        converged,
    }
}

/// One cell by the 15×15 Kronrod product rule, with an error estimate per direction.
///
/// The estimate for x is |KK − GK| (Gauss in x, Kronrod in y), scaled as QUADPACK scales its 1-D
/// estimate: by min(1, (200·|KK − GK| / I₁)^1.5) times I₁ = ∫∫ |f − mean f|. Once a cell
/// resolves the integrand, |KK − GK| measures the error of the 7-point rule, far larger than that
/// of the 15-point value returned; the scaling makes the estimate track the latter. Neither
/// estimate goes below 50 ε ∫∫|f|.
fn cell<S: Separable>(
    f: &S,
    rule: &([f64; 15], [f64; 15], [f64; 15]),
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
) -> Cell {
    let (nodes, wk, wg) = rule;
    let (cx, hx) = (0.5 * (x0 + x1), 0.5 * (x1 - x0));
    let (cy, hy) = (0.5 * (y0 + y1), 0.5 * (y1 - y0));
    let mut xs = [S::X::default(); 15];
    let mut ys = [S::Y::default(); 15];
    for i in 0..15 {
        xs[i] = f.x(cx + hx * nodes[i]);
        ys[i] = f.y(cy + hy * nodes[i]);
    }
    let mut values = [[0.0f64; 15]; 15];
    let (mut kk, mut gk, mut kg, mut abs) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..15 {
        let (mut row_k, mut row_g, mut row_abs) = (0.0, 0.0, 0.0);
        for j in 0..15 {
            let v = f.f(&xs[i], &ys[j]);
            values[i][j] = v;
            row_k += wk[j] * v;
            row_g += wg[j] * v;
            row_abs += wk[j] * v.abs();
        }
        kk += wk[i] * row_k;
        gk += wg[i] * row_k;
        kg += wk[i] * row_g;
        abs += wk[i] * row_abs;
    }
    let mean = kk / 4.0;
    let mut asc = 0.0;
    for i in 0..15 {
        let mut row = 0.0;
        for j in 0..15 {
            row += wk[j] * (values[i][j] - mean).abs();
        }
        asc += wk[i] * row;
    }
    let area = hx * hy;
    let scale = |raw: f64| {
        let raw = (raw * area).abs();
        let asc = asc * area.abs();
        let mut e = raw;
        if asc != 0.0 && raw != 0.0 {
            e = asc * (200.0 * raw / asc).powf(1.5).min(1.0);
        }
        e.max(50.0 * f64::EPSILON * abs * area.abs())
    };
    Cell {
        x0,
        x1,
        y0,
        y1,
        value: kk * area,
        err_x: scale(kk - gk),
        err_y: scale(kk - kg),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x, y) = g(x, y) for tests that do not need the separable split.
    struct Plain<G: Fn(f64, f64) -> f64>(G);

    impl<G: Fn(f64, f64) -> f64> Separable for Plain<G> {
        type X = f64;
        type Y = f64;
        fn x(&self, x: f64) -> f64 {
            x
        }
        fn y(&self, y: f64) -> f64 {
            y
        }
        fn f(&self, x: &f64, y: &f64) -> f64 {
            (self.0)(*x, *y)
        }
    }

    #[test]
    fn the_1d_rule_integrates_polynomials_to_degree_22_on_any_interval() {
        for (a, b, p) in [(0.0, 1.0, 22), (0.1, 1.0, 7), (-2.0, 3.0, 0)] {
            let sum: f64 = kronrod_15(a, b).iter().map(|(x, w)| w * x.powi(p)).sum();
            let exact = (b.powi(p + 1) - a.powi(p + 1)) / f64::from(p + 1);
            assert!(
                (sum - exact).abs() < 1e-13 * exact.abs().max(1.0),
                "{a} {b} {p}"
            );
        }
        let r = kronrod_15(0.0, 0.1);
        assert!(r.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(r[0].0 > 0.0 && r[14].0 < 0.1);
    }

    #[test]
    fn weights_sum_to_the_interval_length() {
        let (_, wk, wg) = rule();
        assert!((wk.iter().sum::<f64>() - 2.0).abs() < 1e-15);
        assert!((wg.iter().sum::<f64>() - 2.0).abs() < 1e-15);
    }

    #[test]
    fn one_cell_is_exact_for_polynomials_to_degree_22_in_each_variable() {
        for (p, q) in [(0, 0), (1, 22), (22, 3), (13, 13)] {
            let f = Plain(|x: f64, y: f64| x.powi(p) * y.powi(q));
            let est = integrate_2d(&f, &[0.0, 1.0], &[0.0, 1.0], 1.0);
            let exact = 1.0 / ((p as f64 + 1.0) * (q as f64 + 1.0));
            assert!(
                (est.value - exact).abs() < 1e-14,
                "x^{p} y^{q}: {}",
                est.value
            );
            assert_eq!(est.evaluations, 225);
        }
    }

    #[test]
    fn meets_the_tolerance_on_a_sharp_peak_in_a_corner() {
        // ∫∫ over [0,1]² of 1/((x² + ε²)(y² + ε²)) = (atan(1/ε)/ε)².
        let eps: f64 = 1e-3;
        let one = (1.0 / eps).atan() / eps;
        let f = Plain(|x: f64, y: f64| 1.0 / ((x * x + eps * eps) * (y * y + eps * eps)));
        let est = integrate_2d(&f, &[0.0, 1.0], &[0.0, 1.0], 1e-3);
        assert!(est.converged);
        assert!(
            (est.value - one * one).abs() <= 1e-3,
            "{} vs {}",
            est.value,
            one * one
        );
    }

    #[test]
    fn meets_the_tolerance_on_an_endpoint_singularity_of_the_derivative() {
        // ∫∫ x^0.2 y^0.2 = 1/1.44: the kind of kink λ's fit has at cosθ = 0.
        let f = Plain(|x: f64, y: f64| (x * y).powf(0.2));
        let est = integrate_2d(&f, &[0.0, 1.0], &[0.0, 1.0], 1e-9);
        assert!(est.converged);
        assert!((est.value - 1.0 / 1.44).abs() <= 1e-9, "{}", est.value);
    }

    #[test]
    fn break_values_are_honoured() {
        // |x − 0.3|·|y − 0.6| has kinks on the break lines, so no bisection is needed.
        let f = Plain(|x: f64, y: f64| (x - 0.3).abs() * (y - 0.6).abs());
        let est = integrate_2d(&f, &[0.0, 0.3, 1.0], &[0.0, 0.6, 1.0], 1e-12);
        let exact = (0.045 + 0.245) * (0.18 + 0.08);
        assert!((est.value - exact).abs() < 1e-14);
        assert_eq!(est.evaluations, 4 * 225);
    }

    #[test]
    fn a_cell_limit_reports_no_convergence_with_a_finite_value() {
        let f = Plain(|x: f64, _y: f64| if x < 1.0 / 3.0 { 0.0 } else { 1.0 });
        let est = integrate_2d(&f, &[0.0, 1.0], &[0.0, 1.0], 0.0);
        assert!(!est.converged);
        assert!((est.value - 2.0 / 3.0).abs() < 1e-6);
    }
}
