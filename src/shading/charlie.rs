//! The sheen BRDF of KHR_materials_sheen: the "Charlie" distribution of Conty and Kulla (2017),
//! its fitted visibility (the λ(cosθ) form with five interpolated coefficients), the cheaper
//! Ashikhmin visibility, and the BRDF D·V, written so that every input in [0, 1] gives a finite
//! number.
//!
//! The limits, each pinned by a test in this file:
//! - `r = 0` exactly: α = r² = 0 makes 1/α infinite. For NdotH > 0 the distribution tends to 0
//!   (a power of a number below 1 that grows without bound); at NdotH = 0 it tends to +∞ (the lobe
//!   collapses to a spike on the horizon). α is floored at [`ALPHA_MIN`], which keeps every value
//!   finite and moves no albedo by more than the quadrature tolerance (see `albedo.rs`).
//! - NdotH = 1 exactly: sin²θh = 0 raised to the power 1/(2α) is 0; computed in log space as
//!   exp(−∞) = 0, never 0·∞.
//! - 1 − NdotH² slightly negative from rounding (NdotH a hair above 1): sin²θh is clamped to 0, so
//!   the distribution is 0 there as at NdotH = 1.
//! - NdotV → 0 and NdotL → 0: the visibility's 1/(4·NdotV·NdotL) grows without bound. The BRDF
//!   times NdotL is computed with NdotL cancelled ([`sheen_brdf_cos`]), so it stays finite as
//!   NdotL → 0. NdotV (the direction the albedo is a function of) is floored at [`MU_MIN`], as
//!   renderers floor it; see `albedo.rs` for why the albedo needs the floor.
//! - λ's branch switch at cosθ = 0.5: both branches give exp(l(0.5)) there and have the same
//!   slope, so λ is continuous and smooth through the switch.

use std::f64::consts::PI;

/// Smallest α = r² used (r = 1e-6). Flooring α keeps 1/α finite for r = 0 exactly. It is small
/// enough that the floored lobe already behaves as the limit: for every view cosine μ ≥
/// [`MU_MIN`] the half vector has cos²θh ≥ μ²/4 ≥ 2.5e-9, where D ≤ (1/α)·exp(−cos²θh/(2α)) =
/// 1e12·e^−1250 underflows to 0, so E(μ, 0) = 0 exactly, the α → 0 limit.
pub const ALPHA_MIN: f64 = 1e-12;

/// Smallest cosine used where the BRDF divides by a cosine (NdotV for the albedo, NdotV and
/// NdotL for the bare BRDF). Renderers apply the same kind of floor to NdotV.
pub const MU_MIN: f64 = 1e-4;

/// The visibility term paired with the Charlie distribution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Visibility {
    /// The fitted Charlie visibility of Conty and Kulla (the one KHR_materials_sheen describes
    /// first, and the one the albedo tables are for).
    Charlie,
    /// The cheaper visibility of Ashikhmin and Premoze, 1 / (4 (NdotL + NdotV − NdotL·NdotV)).
    Ashikhmin,
}

/// α = r², floored at [`ALPHA_MIN`]. Roughness outside [0, 1] is clamped into it.
pub fn alpha_from_roughness(r: f64) -> f64 {
    let r = clamp01(r);
    (r * r).max(ALPHA_MIN)
}

/// The Charlie distribution D(NdotH; r) = (2 + 1/α) · (sin²θh)^(1/(2α)) / (2π), α = r².
///
/// Computed as exp(ln(2 + 1/α) − ln 2π + ln(sin²θh)/(2α)) so that neither the power nor the
/// factor can overflow, and 0 is returned where the power underflows.
pub fn charlie_d(n_dot_h: f64, r: f64) -> f64 {
    let c = n_dot_h.abs().min(1.0);
    let c2 = c * c;
    let ln_sin2h = if c >= 1.0 {
        f64::NEG_INFINITY
    } else if c2 < 0.5 {
        (-c2).ln_1p()
    } else {
        // (1 − c) is exact here, and ln(1 − c) + ln(1 + c) keeps the digits that 1 − c² loses.
        (1.0 - c).ln() + c.ln_1p()
    };
    Lobe::new(alpha_from_roughness(r)).d(ln_sin2h)
}

/// The Charlie distribution for one α, with its normalisation hoisted out of the per-direction
/// evaluation (the albedo integrand evaluates it tens of thousands of times per call).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lobe {
    /// 1/(2α).
    half_inv_alpha: f64,
    /// ln((2 + 1/α) / (2π)).
    ln_norm: f64,
}

impl Lobe {
    /// The lobe for an already floored α.
    pub(crate) fn new(alpha: f64) -> Self {
        debug_assert!(alpha >= ALPHA_MIN);
        let inv_alpha = 1.0 / alpha;
        Lobe {
            half_inv_alpha: 0.5 * inv_alpha,
            ln_norm: (2.0 + inv_alpha).ln() - (2.0 * PI).ln(),
        }
    }

    /// D from ln(sin²θh); the albedo integrand calls this with a ln(sin²θh) it computed without
    /// forming NdotH. ln(sin²θh) = −∞ (NdotH = 1) gives exp(−∞) = 0.
    #[inline]
    pub(crate) fn d(&self, ln_sin2h: f64) -> f64 {
        (self.ln_norm + self.half_inv_alpha * ln_sin2h).exp()
    }
}

/// The five coefficients of the fitted l(x), interpolated in (1 − α)².
#[derive(Clone, Copy, Debug)]
pub(crate) struct LambdaCoefficients {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    e: f64,
    /// l(0.5), which the second branch of λ needs; computed once per α.
    l_half: f64,
}

impl LambdaCoefficients {
    pub(crate) fn new(alpha: f64) -> Self {
        let t = (1.0 - alpha) * (1.0 - alpha);
        let mix = |x: f64, y: f64| x + (y - x) * t;
        let mut k = LambdaCoefficients {
            a: mix(21.5473, 25.3245),
            b: mix(3.82987, 3.32435),
            c: mix(0.19823, 0.16801),
            d: mix(-1.97760, -1.27393),
            e: mix(-4.32054, -4.85967),
            l_half: 0.0,
        };
        k.l_half = k.l(0.5);
        k
    }

    fn l(&self, x: f64) -> f64 {
        self.a / (1.0 + self.b * x.powf(self.c)) + self.d * x + self.e
    }

    /// λ(cosθ). cosθ is taken as |cosθ| clamped to [0, 1], so a cosine a hair above 1 does not
    /// hand a negative number to powf.
    pub(crate) fn lambda(&self, cos_theta: f64) -> f64 {
        let x = cos_theta.abs().min(1.0);
        if x < 0.5 {
            self.l(x).exp()
        } else {
            (2.0 * self.l_half - self.l(1.0 - x)).exp()
        }
    }
}

/// λ(cosθ; r) of the Charlie visibility.
pub fn charlie_lambda(cos_theta: f64, r: f64) -> f64 {
    LambdaCoefficients::new(alpha_from_roughness(r)).lambda(cos_theta)
}

/// The Charlie visibility 1 / ((1 + λ(NdotV) + λ(NdotL)) · 4 · NdotV · NdotL), both cosines
/// floored at [`MU_MIN`].
pub fn charlie_visibility(n_dot_v: f64, n_dot_l: f64, r: f64) -> f64 {
    let (v, l) = (floor_cos(n_dot_v), floor_cos(n_dot_l));
    let k = LambdaCoefficients::new(alpha_from_roughness(r));
    1.0 / ((1.0 + k.lambda(v) + k.lambda(l)) * (4.0 * v * l))
}

/// The Ashikhmin visibility 1 / (4 (NdotL + NdotV − NdotL·NdotV)), both cosines floored at
/// [`MU_MIN`] (with both at 0 the denominator is 0).
pub fn ashikhmin_visibility(n_dot_v: f64, n_dot_l: f64) -> f64 {
    let (v, l) = (floor_cos(n_dot_v), floor_cos(n_dot_l));
    1.0 / (4.0 * (l + v - l * v))
}

/// The sheen BRDF D·V (without sheenColor). Both cosines are floored at [`MU_MIN`]: the bare BRDF
/// grows without bound as either goes to 0.
pub fn sheen_brdf(n_dot_v: f64, n_dot_l: f64, n_dot_h: f64, r: f64, vis: Visibility) -> f64 {
    let d = charlie_d(n_dot_h, r);
    let v = match vis {
        Visibility::Charlie => charlie_visibility(n_dot_v, n_dot_l, r),
        Visibility::Ashikhmin => ashikhmin_visibility(n_dot_v, n_dot_l),
    };
    d * v
}

/// The sheen BRDF times NdotL, D·V·NdotL, with NdotL cancelled analytically so that the product
/// stays finite as NdotL → 0 (it tends to D / (4·NdotV·(1 + λ(NdotV) + λ(0))) for Charlie, and to
/// 0 for Ashikhmin). NdotV is floored at [`MU_MIN`].
pub fn sheen_brdf_cos(n_dot_v: f64, n_dot_l: f64, n_dot_h: f64, r: f64, vis: Visibility) -> f64 {
    let alpha = alpha_from_roughness(r);
    let d = charlie_d(n_dot_h, r);
    let v = floor_cos(n_dot_v);
    let l = clamp01(n_dot_l);
    match vis {
        Visibility::Charlie => {
            let k = LambdaCoefficients::new(alpha);
            d / (4.0 * v * (1.0 + k.lambda(v) + k.lambda(l)))
        }
        Visibility::Ashikhmin => d * l / (4.0 * (l + v - l * v)),
    }
}

/// A cosine clamped to [MU_MIN, 1].
pub(crate) fn floor_cos(c: f64) -> f64 {
    clamp01(c).max(MU_MIN)
}

/// Clamp to [0, 1]; NaN becomes 0 so that no NaN enters the maths.
pub(crate) fn clamp01(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution_is_normalised_with_the_cosine() {
        // ∫ D(θh) cosθh dω = 1 in closed form: (2 + 1/α) ∫ sin^(1/α + 1) cos dθ = 1.
        for r in [0.3, 0.5, 1.0] {
            let n = 200_000;
            let mut sum = 0.0;
            for i in 0..n {
                let t = (i as f64 + 0.5) / n as f64 * (PI / 2.0);
                sum += charlie_d(t.cos(), r) * t.cos() * t.sin();
            }
            let integral = 2.0 * PI * sum * (PI / 2.0) / n as f64;
            assert!((integral - 1.0).abs() < 1e-6, "r={r}: {integral}");
        }
    }

    #[test]
    fn distribution_matches_the_spec_formula_where_that_is_finite() {
        for &(c, r) in &[(0.1f64, 0.5f64), (0.5, 0.3), (0.9, 1.0), (0.2, 0.8)] {
            let a: f64 = r * r;
            let inv = 1.0 / a;
            let spec = (2.0 + inv) * (1.0 - c * c).powf(inv * 0.5) / (2.0 * PI);
            let ours = charlie_d(c, r);
            assert!((ours - spec).abs() <= 1e-12 * spec.max(1.0), "{c} {r}");
        }
    }

    #[test]
    fn r_zero_exactly_gives_zero_off_the_horizon_and_a_finite_spike_on_it() {
        // Limit: D → 0 for NdotH > 0 as α → 0.
        for c in [1e-3, 0.1, 0.5, 0.999, 1.0] {
            assert_eq!(charlie_d(c, 0.0), 0.0, "NdotH={c}");
        }
        // Limit: D → +∞ at NdotH = 0; with α floored it is (2 + 1/ALPHA_MIN)/(2π).
        let spike = charlie_d(0.0, 0.0);
        assert!(spike.is_finite());
        let expected = (2.0 + 1.0 / ALPHA_MIN) / (2.0 * PI);
        assert!((spike - expected).abs() < 1e-9 * expected);
    }

    #[test]
    fn r_to_zero_is_continuous_into_r_zero() {
        // Below sqrt(ALPHA_MIN) the floor holds α constant, so D is exactly the r = 0 value.
        for c in [0.0, 1e-7, 1e-4, 1e-3] {
            assert_eq!(charlie_d(c, 1e-7), charlie_d(c, 0.0));
            assert_eq!(charlie_d(c, 1e-300), charlie_d(c, 0.0));
        }
        // Just above the floor the value is close to the floored one (NdotH = 1e-7 keeps D
        // away from both 0 and the spike).
        let a = charlie_d(1e-7, ALPHA_MIN.sqrt() * (1.0 + 1e-9));
        let b = charlie_d(1e-7, 0.0);
        assert!(b > 1e10 && (a - b).abs() <= 1e-6 * b, "{a} {b}");
    }

    #[test]
    fn n_dot_h_one_exactly_gives_zero() {
        for r in [0.0, 1e-3, 0.25, 0.5, 1.0] {
            assert_eq!(charlie_d(1.0, r), 0.0, "r={r}");
        }
    }

    #[test]
    fn n_dot_h_a_hair_above_one_gives_zero_not_nan() {
        // 1 − NdotH² < 0 here in floating point.
        let c = 1.0 + f64::EPSILON;
        assert!(1.0 - c * c < 0.0);
        for r in [0.0, 0.5, 1.0] {
            assert_eq!(charlie_d(c, r), 0.0);
            assert!(charlie_lambda(c, r).is_finite());
        }
        assert_eq!(charlie_lambda(c, 0.5), charlie_lambda(1.0, 0.5));
    }

    #[test]
    fn n_dot_h_just_below_one_keeps_its_digits() {
        // sin²θh = (1 − c)(1 + c) = 2e-12 − 1e-24 for c = 1 − 1e-12; with r = 1, D = 3 sinθh/(2π).
        let c = 1.0 - 1e-12;
        let d = charlie_d(c, 1.0);
        let sin_h = ((1.0 - c) * (1.0 + c)).sqrt();
        let expected = 3.0 * sin_h / (2.0 * PI);
        assert!((d - expected).abs() <= 1e-12 * expected, "{d} {expected}");
    }

    #[test]
    fn lambda_is_continuous_and_smooth_at_the_branch_switch() {
        for r in [0.0, 0.1, 0.5, 1.0] {
            let at = charlie_lambda(0.5, r);
            let k = LambdaCoefficients::new(alpha_from_roughness(r));
            // Both branches give exp(l(0.5)) at the switch.
            assert!((at - k.l(0.5).exp()).abs() <= 1e-14 * at);
            let eps = 1e-7;
            let below = charlie_lambda(0.5 - eps, r);
            let above = charlie_lambda(0.5 + eps, r);
            assert!((below - above).abs() <= 1e-5 * at, "r={r}");
            // One-sided slopes agree (C¹): l'(0.5) from both sides.
            let h = 1e-5;
            let left = (charlie_lambda(0.5, r) - charlie_lambda(0.5 - h, r)) / h;
            let right = (charlie_lambda(0.5 + h, r) - charlie_lambda(0.5, r)) / h;
            assert!(
                (left - right).abs() <= 1e-3 * left.abs().max(1.0),
                "{left} {right}"
            );
        }
    }

    #[test]
    fn lambda_at_zero_is_the_finite_fit_value() {
        // l(0) = a + e: the fit stays finite at grazing.
        let k = LambdaCoefficients::new(1.0);
        assert!((charlie_lambda(0.0, 1.0) - (21.5473f64 - 4.32054).exp()).abs() < 1e-6 * k.a);
        let k0 = LambdaCoefficients::new(ALPHA_MIN);
        let expected = (k0.a + k0.e).exp();
        assert!((charlie_lambda(0.0, 0.0) - expected).abs() <= 1e-12 * expected);
    }

    #[test]
    fn brdf_cos_stays_finite_and_tends_to_its_limit_as_n_dot_l_goes_to_zero() {
        let (v, h, r) = (0.5, 0.3, 0.5);
        let k = LambdaCoefficients::new(alpha_from_roughness(r));
        let limit = charlie_d(h, r) / (4.0 * v * (1.0 + k.lambda(v) + k.lambda(0.0)));
        assert_eq!(sheen_brdf_cos(v, 0.0, h, r, Visibility::Charlie), limit);
        // λ approaches λ(0) like NdotL^c (c ≈ 0.2), so slowly: at 1e-12 it is still far off, at
        // 1e-300 it is there; every value on the way is finite.
        for l in [1e-3, 1e-12, 1e-100] {
            let v = sheen_brdf_cos(v, l, h, r, Visibility::Charlie);
            assert!(v.is_finite() && v > 0.0);
        }
        let near = sheen_brdf_cos(v, 1e-300, h, r, Visibility::Charlie);
        assert!((near - limit).abs() <= 1e-9 * limit, "{near} {limit}");
        // Ashikhmin: D·NdotL/(4(NdotL + NdotV − NdotL·NdotV)) → 0.
        assert_eq!(sheen_brdf_cos(v, 0.0, h, r, Visibility::Ashikhmin), 0.0);
        // And equals D·V·NdotL away from the limit.
        let l = 0.7;
        let direct = sheen_brdf(v, l, h, r, Visibility::Charlie) * l;
        let cancelled = sheen_brdf_cos(v, l, h, r, Visibility::Charlie);
        assert!((direct - cancelled).abs() <= 1e-13 * direct);
    }

    #[test]
    fn n_dot_v_zero_uses_the_floor() {
        for vis in [Visibility::Charlie, Visibility::Ashikhmin] {
            assert_eq!(
                sheen_brdf_cos(0.0, 0.4, 0.3, 0.5, vis),
                sheen_brdf_cos(MU_MIN, 0.4, 0.3, 0.5, vis)
            );
            assert_eq!(
                sheen_brdf(0.0, 0.0, 0.0, 0.0, vis),
                sheen_brdf(MU_MIN, MU_MIN, 0.0, 0.0, vis)
            );
        }
        assert_eq!(
            ashikhmin_visibility(0.0, 0.0),
            1.0 / (4.0 * (2.0 * MU_MIN - MU_MIN * MU_MIN))
        );
    }

    #[test]
    fn nothing_is_nan_or_infinite_on_a_dense_grid_including_0_and_1() {
        let n = 64;
        let vals: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
        let extra = [0.0, 1e-300, 1e-12, 0.5 - 1e-15, 0.5, 1.0 - 1e-15, 1.0];
        let all: Vec<f64> = vals.iter().chain(extra.iter()).copied().collect();
        for &r in &all {
            for &c in &all {
                for vis in [Visibility::Charlie, Visibility::Ashikhmin] {
                    let d = charlie_d(c, r);
                    let lam = charlie_lambda(c, r);
                    assert!(d.is_finite() && d >= 0.0, "D({c},{r})={d}");
                    assert!(lam.is_finite() && lam > 0.0);
                    // NdotV, NdotL and NdotH all from the grid.
                    for &h in &[0.0, 0.5, 1.0] {
                        let f = sheen_brdf(c, r, h, r, vis);
                        let fc = sheen_brdf_cos(c, r, h, r, vis);
                        assert!(f.is_finite() && f >= 0.0, "f({c},{r},{h})={f}");
                        assert!(fc.is_finite() && fc >= 0.0, "fc({c},{r},{h})={fc}");
                    }
                }
            }
        }
    }

    #[test]
    fn nan_inputs_do_not_propagate() {
        assert!(charlie_d(f64::NAN, 0.5).is_finite());
        assert!(charlie_d(0.5, f64::NAN).is_finite());
        assert!(charlie_lambda(f64::NAN, 0.5).is_finite());
    }
}
