//! The sheen BRDF's directional albedo E(μ, r) = ∫ D·V·NdotL dω_l by adaptive quadrature (the
//! reference for every other method).
//!
//! With v = (sv, 0, μ) and l = (sl cosφ, sl sinφ, μl), the visibility does not depend on φ, and
//! NdotL cancels against the visibility's 1/NdotL:
//!
//!   E(μ) = ∫₀¹ dμl · 2∫₀^π dφ · D(h) / (4 μ (1 + λ(μ) + λ(μl)))            (Charlie)
//!   E(μ) = ∫₀¹ dμl · 2∫₀^π dφ · D(h) · μl / (4 (μl + μ − μl μ))           (Ashikhmin)
//!
//! sin²θh is formed from the unnormalised half vector v + l as |horizontal|² / |v + l|², which
//! lies in [0, 1] by construction (no 1 − NdotH² to go negative).
//!
//! Limits: μ is floored at [`MU_MIN`](super::charlie::MU_MIN). Below it the Charlie albedo grows without bound, because the
//! fitted λ stays finite at cosθ = 0 (λ(0) = exp(a + e)) while a masking term that balanced the
//! 1/(4μ) would have to grow like 1/μ: E(μ) ~ 1/(4 μ λ(μ)) → ∞. Renderers floor NdotV for the
//! same reason. For r → 0 and μ ≥ [`MU_MIN`](super::charlie::MU_MIN), NdotH ≥ μ/2 keeps the half vector off the horizon, so
//! E → 0; the lobe only reaches the view directions near grazing, where for small r the albedo
//! exceeds 1 (the fitted visibility is not energy conserving there). That excess is why the base
//! attenuation 1 − max3(sheenColor)·E needs a clamp (see `layering.rs`).

use super::charlie::{
    alpha_from_roughness, clamp01, floor_cos, LambdaCoefficients, Lobe, Visibility,
};
use super::quadrature::{integrate_2d, Estimate, Separable};
use std::f64::consts::PI;

/// The default absolute tolerance of [`albedo_quadrature`] (the integrator's own error estimate
/// is below it).
pub const QUADRATURE_TOL: f64 = 1e-7;

/// The absolute error bound velvet states for E by quadrature at [`QUADRATURE_TOL`].
pub const QUADRATURE_BOUND: f64 = 1e-6;

/// A BRDF times NdotL over the light hemisphere, in the separable form the cubature wants:
/// x = NdotL, y = the azimuth φ between l and v, taken over [0, π] (the integrand is even in φ).
pub(crate) trait CosWeightedBrdf {
    /// What depends on NdotL alone.
    type PerL: Copy + Default;
    /// The NdotL part.
    fn per_l(&self, mu_l: f64) -> Self::PerL;
    /// f·NdotL at (NdotL, φ), given cos²(φ/2).
    fn eval(&self, per_l: &Self::PerL, cos2_half_phi: f64) -> f64;
    /// NdotL values where the integrand has a kink (break lines for the cubature), in (0, 1).
    fn kinks(&self) -> Vec<f64>;
}

/// The power of the end-flattening substitution of NdotL (see [`to_mu_l`]).
const FLATTEN: i32 = 6;

/// NdotL = g(u) for u ∈ [0, 1], with g(u) = ½(2u)^p on [0, ½] and 1 − ½(2 − 2u)^p on [½, 1],
/// and g'(u). The fitted λ has (NdotL)^c kinks at NdotL = 0 and (1 − NdotL)^c at NdotL = 1 (c ≈ 1/6),
/// and sinθl = √(1 − NdotL²) one at NdotL = 1; with p = 6 these become (nearly) smooth powers of u,
/// so the cubature needs few cells at either end.
fn to_mu_l(u: f64) -> (f64, f64) {
    let p = FLATTEN;
    if u <= 0.5 {
        let t = 2.0 * u;
        (0.5 * t.powi(p), f64::from(p) * t.powi(p - 1))
    } else {
        let t = 2.0 - 2.0 * u;
        (1.0 - 0.5 * t.powi(p), f64::from(p) * t.powi(p - 1))
    }
}

/// The inverse of [`to_mu_l`]'s g.
fn from_mu_l(mu_l: f64) -> f64 {
    let p = f64::from(FLATTEN);
    if mu_l <= 0.5 {
        0.5 * (2.0 * mu_l).powf(1.0 / p)
    } else {
        1.0 - 0.5 * (2.0 - 2.0 * mu_l).powf(1.0 / p)
    }
}

/// E = ∫ f·NdotL dω over the hemisphere, to absolute tolerance `tol`.
pub(crate) fn hemisphere_albedo<B: CosWeightedBrdf>(brdf: &B, tol: f64) -> Estimate {
    struct Integrand<'a, B>(&'a B);
    impl<B: CosWeightedBrdf> Separable for Integrand<'_, B> {
        type X = (B::PerL, f64);
        type Y = f64;
        fn x(&self, u: f64) -> (B::PerL, f64) {
            let (mu_l, jacobian) = to_mu_l(u);
            (self.0.per_l(mu_l), jacobian)
        }
        fn y(&self, phi: f64) -> f64 {
            let c = (0.5 * phi).cos();
            c * c
        }
        fn f(&self, x: &(B::PerL, f64), c2: &f64) -> f64 {
            // The integrand is even in φ: ∫ over [0, 2π] is twice ∫ over [0, π].
            2.0 * x.1 * self.0.eval(&x.0, *c2)
        }
    }
    let mut xb = vec![0.0, 0.5];
    xb.extend(
        brdf.kinks()
            .into_iter()
            .filter(|k| *k > 0.0 && *k < 1.0)
            .map(from_mu_l),
    );
    xb.push(1.0);
    xb.sort_by(f64::total_cmp);
    xb.dedup();
    integrate_2d(&Integrand(brdf), &xb, &[0.0, PI], tol)
}

/// The sheen BRDF (D·V·NdotL, NdotL cancelled) for one view direction and roughness.
struct SheenCos {
    vis: Visibility,
    mu_v: f64,
    sv: f64,
    lobe: Lobe,
    lambda: LambdaCoefficients,
    lambda_v: f64,
}

/// Per light direction: the weight V·NdotL/ D and the pieces of |v + l|².
#[derive(Clone, Copy, Default)]
struct SheenPerL {
    weight: f64,
    /// (sv − sl)²
    ds2: f64,
    /// 4·sv·sl
    four_svsl: f64,
    /// (NdotV + NdotL)²
    hz2: f64,
}

impl CosWeightedBrdf for SheenCos {
    type PerL = SheenPerL;

    fn per_l(&self, mu_l: f64) -> SheenPerL {
        let sl = ((1.0 - mu_l) * (1.0 + mu_l)).sqrt();
        let mu_v = self.mu_v;
        let weight = match self.vis {
            Visibility::Charlie => {
                1.0 / (4.0 * mu_v * (1.0 + self.lambda_v + self.lambda.lambda(mu_l)))
            }
            Visibility::Ashikhmin => mu_l / (4.0 * (mu_l + mu_v - mu_l * mu_v)),
        };
        let hz = mu_v + mu_l;
        let ds = self.sv - sl;
        SheenPerL {
            weight,
            ds2: ds * ds,
            four_svsl: 4.0 * self.sv * sl,
            hz2: hz * hz,
        }
    }

    #[inline]
    fn eval(&self, p: &SheenPerL, c2: f64) -> f64 {
        // |horizontal(v + l)|² = (sv − sl)² + 4 sv sl cos²(φ/2): no cancellation, never negative.
        let horiz2 = p.ds2 + p.four_svsl * c2;
        let total = horiz2 + p.hz2;
        if total == 0.0 {
            return 0.0;
        }
        let cos2h = p.hz2 / total;
        let ln_sin2h = if cos2h < 0.5 {
            (-cos2h).ln_1p()
        } else {
            (horiz2 / total).ln()
        };
        p.weight * self.lobe.d(ln_sin2h)
    }

    fn kinks(&self) -> Vec<f64> {
        // λ switches branch at 0.5; at NdotL = NdotV (with φ = π) the half vector is the normal,
        // where D is not smooth for most α.
        vec![0.5, self.mu_v]
    }
}

/// E(μ, r) by adaptive quadrature to absolute tolerance `tol`, with the integrator's estimate
/// and the number of BRDF evaluations. μ is floored at [`MU_MIN`](super::charlie::MU_MIN); μ and
/// r are clamped into [0, 1].
pub fn albedo_quadrature(mu: f64, r: f64, vis: Visibility, tol: f64) -> Estimate {
    let mu_v = floor_cos(mu);
    let alpha = alpha_from_roughness(clamp01(r));
    let lambda = LambdaCoefficients::new(alpha);
    let brdf = SheenCos {
        vis,
        mu_v,
        sv: ((1.0 - mu_v) * (1.0 + mu_v)).sqrt(),
        lobe: Lobe::new(alpha),
        lambda,
        lambda_v: lambda.lambda(mu_v),
    };
    hemisphere_albedo(&brdf, tol)
}

/// The ways velvet computes E(μ, r) of the Charlie sheen BRDF, all behind
/// [`sheen_albedo`](super::sheen_albedo).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AlbedoMethod {
    /// Adaptive quadrature at [`QUADRATURE_TOL`]: the reference, error at most [`QUADRATURE_BOUND`].
    Quadrature,
    /// The 16×16 table with bilinear interpolation (nodes at texel centres).
    Lut16,
    /// The 32×32 table with bilinear interpolation (nodes at texel centres).
    Lut32,
    /// velvet's closed-form fit exp(P(μ, r)).
    Fit,
}

impl AlbedoMethod {
    /// Every method, in the order the accuracy report lists them.
    pub const ALL: [AlbedoMethod; 4] = [
        AlbedoMethod::Quadrature,
        AlbedoMethod::Lut16,
        AlbedoMethod::Lut32,
        AlbedoMethod::Fit,
    ];

    /// The method's name in reports and CSV headers.
    pub fn name(self) -> &'static str {
        match self {
            AlbedoMethod::Quadrature => "quadrature",
            AlbedoMethod::Lut16 => "lut16",
            AlbedoMethod::Lut32 => "lut32",
            AlbedoMethod::Fit => "fit",
        }
    }

    /// The absolute error bound velvet states for the method on the ordinary region
    /// (μ ≥ 0.1, r ≥ 0.25), against quadrature. The tests hold the method to it.
    pub fn ordinary_bound(self) -> f64 {
        match self {
            AlbedoMethod::Quadrature => QUADRATURE_BOUND,
            AlbedoMethod::Lut16 => LUT16_BOUND_ORDINARY,
            AlbedoMethod::Lut32 => LUT32_BOUND_ORDINARY,
            AlbedoMethod::Fit => FIT_BOUND_ORDINARY,
        }
    }
}

/// Stated bound on |lut16 − quadrature| over the ordinary region (measured: 9.7e-3 on a 129×129
/// grid, at μ = 1 where the lookup clamps to the last texel centre, 31/32).
pub const LUT16_BOUND_ORDINARY: f64 = 1.2e-2;
/// Stated bound on |lut32 − quadrature| over the ordinary region (measured: 4.8e-3 on a 129×129
/// grid, again at μ = 1).
pub const LUT32_BOUND_ORDINARY: f64 = 6e-3;
/// Stated bound on |fit − quadrature| over the ordinary region (measured: 3.6e-3 on a 129×129
/// grid).
pub const FIT_BOUND_ORDINARY: f64 = 5e-3;

/// Whether (μ, r) lies in the ordinary region μ ≥ 0.1, r ≥ 0.25 (the rest is the hard region:
/// grazing views and small roughness, where E changes fastest and exceeds 1).
pub fn is_ordinary(mu: f64, r: f64) -> bool {
    mu >= 0.1 && r >= 0.25
}

#[cfg(test)]
mod tests {
    use super::super::charlie::{ALPHA_MIN, MU_MIN};
    use super::*;

    fn e(mu: f64, r: f64) -> f64 {
        albedo_quadrature(mu, r, Visibility::Charlie, QUADRATURE_TOL).value
    }

    /// f·NdotL = c·NdotL: a constant BRDF, whose albedo is π·c.
    struct Constant(f64);

    impl CosWeightedBrdf for Constant {
        type PerL = f64;
        fn per_l(&self, mu_l: f64) -> f64 {
            self.0 * mu_l
        }
        fn eval(&self, p: &f64, _c2: f64) -> f64 {
            *p
        }
        fn kinks(&self) -> Vec<f64> {
            Vec::new()
        }
    }

    /// A normalised Phong lobe about the normal, (n + 2)/(2π)·NdotL^n, with albedo 1, times an
    /// azimuthal factor 2cos²(φ/2) whose mean over φ is 1: checks both axes of the integrator.
    struct Lobe(i32);

    impl CosWeightedBrdf for Lobe {
        type PerL = f64;
        fn per_l(&self, mu_l: f64) -> f64 {
            f64::from(self.0 + 2) / (2.0 * PI) * mu_l.powi(self.0) * mu_l
        }
        fn eval(&self, p: &f64, c2: f64) -> f64 {
            p * 2.0 * c2
        }
        fn kinks(&self) -> Vec<f64> {
            vec![0.3]
        }
    }

    #[test]
    fn integrator_gives_pi_c_for_a_constant_brdf() {
        for c in [1.0, 0.25, 1.0 / PI] {
            let est = hemisphere_albedo(&Constant(c), QUADRATURE_TOL);
            assert!(est.converged);
            assert!(
                (est.value - PI * c).abs() <= QUADRATURE_TOL,
                "{} vs {}",
                est.value,
                PI * c
            );
        }
    }

    #[test]
    fn integrator_gives_rho_for_a_lambertian_brdf() {
        for rho in [0.0, 0.18, 0.8, 1.0] {
            let est = hemisphere_albedo(&Constant(rho / PI), QUADRATURE_TOL);
            assert!((est.value - rho).abs() <= QUADRATURE_TOL, "{}", est.value);
        }
    }

    #[test]
    fn integrator_gives_one_for_a_normalised_lobe() {
        for n in [0, 1, 10, 100] {
            let est = hemisphere_albedo(&Lobe(n), QUADRATURE_TOL);
            assert!(
                (est.value - 1.0).abs() <= QUADRATURE_TOL,
                "n={n}: {}",
                est.value
            );
        }
    }

    #[test]
    fn ashikhmin_albedo_at_normal_view_matches_its_closed_form() {
        // At μ = 1 the Ashikhmin visibility is 1/4 and θh = θl/2, so
        // E = (2 + k)/2 ∫₀^½ s^(k/2) (1 − 2s) ds = 2^(−m)/(m + 1), k = 1/α, m = k/2 + 1.
        // This exercises the whole sheen integrand: D, the half vector and both axes.
        for r in [0.25f64, 0.3, 0.5, 0.7, 0.9, 1.0] {
            let m = 0.5 / (r * r) + 1.0;
            let exact = 2f64.powf(-m) / (m + 1.0);
            let est = albedo_quadrature(1.0, r, Visibility::Ashikhmin, QUADRATURE_TOL);
            assert!(est.converged);
            assert!(
                (est.value - exact).abs() <= QUADRATURE_TOL,
                "r={r}: {} vs {exact}",
                est.value
            );
        }
    }

    #[test]
    fn halving_the_tolerance_changes_e_by_less_than_the_tolerance() {
        let points = [
            (0.5, 0.5),
            (0.05, 0.1),
            (0.0, 0.19),
            (1.0, 1.0),
            (0.9, 0.25),
            (0.01, 0.03),
            (0.2, 0.8),
        ];
        for (mu, r) in points {
            for vis in [Visibility::Charlie, Visibility::Ashikhmin] {
                let a = albedo_quadrature(mu, r, vis, QUADRATURE_TOL);
                let b = albedo_quadrature(mu, r, vis, QUADRATURE_TOL / 2.0);
                assert!(a.converged && b.converged);
                assert!(a.error <= QUADRATURE_TOL && b.error <= QUADRATURE_TOL / 2.0);
                assert!(
                    (a.value - b.value).abs() < QUADRATURE_TOL,
                    "({mu}, {r}, {vis:?}): {} vs {}",
                    a.value,
                    b.value
                );
            }
        }
    }

    #[test]
    fn r_zero_exactly_gives_zero_albedo_the_limit() {
        for mu in [0.0, MU_MIN, 0.01, 0.5, 1.0] {
            assert_eq!(e(mu, 0.0), 0.0, "mu={mu}");
        }
    }

    #[test]
    fn r_to_zero_tends_to_zero_at_fixed_mu() {
        // At μ = 0.05 the lobe must reach NdotH ≈ μ/2; once α ≪ μ²/8 it cannot.
        let seq: Vec<f64> = [0.03, 0.01, 1e-3, 1e-6]
            .iter()
            .map(|&r| e(0.05, r))
            .collect();
        assert!(seq[0] > 0.5 && seq[1] > 1e-3, "{seq:?}");
        assert!(seq[2] < 1e-12 && seq[3] == 0.0, "{seq:?}");
        // Below r = sqrt(ALPHA_MIN) the floor makes E exactly the r = 0 value.
        assert_eq!(e(MU_MIN, ALPHA_MIN.sqrt() / 2.0), e(MU_MIN, 0.0));
    }

    #[test]
    fn mu_zero_and_mu_to_zero_use_the_floor_and_stay_finite() {
        for r in [0.05, 0.25, 1.0] {
            let at_floor = e(MU_MIN, r);
            assert!(at_floor.is_finite() && at_floor > 0.0);
            assert_eq!(e(0.0, r), at_floor);
            assert_eq!(e(1e-300, r), at_floor);
            // Continuous into the floor from above.
            let above = e(MU_MIN * (1.0 + 1e-6), r);
            assert!(
                (above - at_floor).abs() < 1e-5 * at_floor.max(1.0),
                "r={r}: {above} vs {at_floor}"
            );
        }
    }

    #[test]
    fn albedo_exceeds_one_for_small_r_at_grazing_mu_and_not_in_the_ordinary_region() {
        assert!(e(0.05, 0.0625) > 1.0);
        assert!(e(1e-3, 0.1) > 2.0);
        assert!(e(MU_MIN, 0.01) > 10.0);
        for i in 0..=9 {
            for j in 0..=6 {
                let (mu, r) = (0.1 + 0.1 * i as f64, 0.25 + 0.125 * j as f64);
                let v = e(mu, r);
                assert!(v > 0.0 && v < 1.0, "E({mu}, {r}) = {v}");
            }
        }
    }

    #[test]
    fn albedo_is_finite_on_a_grid_including_0_and_1_and_extreme_values() {
        let mut values: Vec<f64> = (0..=8).map(|i| i as f64 / 8.0).collect();
        values.extend([1e-300, 1e-12, MU_MIN, 0.5 - 1e-15, 0.5 + 1e-15, 1.0 - 1e-15]);
        for &mu in &values {
            for &r in &values {
                for vis in [Visibility::Charlie, Visibility::Ashikhmin] {
                    let est = albedo_quadrature(mu, r, vis, QUADRATURE_TOL);
                    assert!(
                        est.value.is_finite() && est.value >= 0.0,
                        "({mu}, {r}, {vis:?}) = {}",
                        est.value
                    );
                    assert!(est.converged, "({mu}, {r}, {vis:?}) did not converge");
                }
            }
        }
    }

    #[test]
    fn tables_and_fit_agree_with_quadrature_within_the_stated_bounds() {
        // A grid that is neither the tables' nodes nor the report's grid, edges included.
        let mus: Vec<f64> = (0..=15).map(|i| 0.1 + 0.06 * i as f64).collect();
        let rs: Vec<f64> = (0..=12).map(|j| 0.25 + 0.0625 * j as f64).collect();
        let points: Vec<(f64, f64)> = rs
            .iter()
            .flat_map(|&r| mus.iter().map(move |&mu| (mu, r)))
            .collect();
        let reference: Vec<f64> = {
            use rayon::prelude::*;
            points.par_iter().map(|&(mu, r)| e(mu, r)).collect()
        };
        for method in [AlbedoMethod::Lut16, AlbedoMethod::Lut32, AlbedoMethod::Fit] {
            let worst = points
                .iter()
                .zip(&reference)
                .map(|(&(mu, r), q)| (super::super::sheen_albedo(mu, r, method) - q).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= method.ordinary_bound(),
                "{}: {worst}",
                method.name()
            );
        }
        assert_eq!(AlbedoMethod::Quadrature.ordinary_bound(), QUADRATURE_BOUND);
    }

    #[test]
    fn every_method_is_finite_and_non_negative_on_a_dense_grid_including_0_and_1() {
        for method in [AlbedoMethod::Lut16, AlbedoMethod::Lut32, AlbedoMethod::Fit] {
            for i in 0..=200 {
                for j in 0..=200 {
                    let (mu, r) = (i as f64 / 200.0, j as f64 / 200.0);
                    let v = super::super::sheen_albedo(mu, r, method);
                    assert!(
                        v.is_finite() && v >= 0.0,
                        "{} at ({mu}, {r}): {v}",
                        method.name()
                    );
                }
            }
        }
    }

    #[test]
    fn substitution_maps_the_unit_interval_onto_itself_and_inverts() {
        assert_eq!(to_mu_l(0.0).0, 0.0);
        assert_eq!(to_mu_l(0.5).0, 0.5);
        assert_eq!(to_mu_l(1.0).0, 1.0);
        // g' is continuous at the junction u = ½ (both halves give p there; g'' jumps).
        assert_eq!(to_mu_l(0.5).1, f64::from(FLATTEN));
        assert!((to_mu_l(0.5 + 1e-12).1 - f64::from(FLATTEN)).abs() < 1e-9);
        for u in [0.1, 0.3, 0.7, 0.95] {
            assert!((from_mu_l(to_mu_l(u).0) - u).abs() < 1e-12);
            // g' against a central difference.
            let h = 1e-6;
            let fd = (to_mu_l(u + h).0 - to_mu_l(u - h).0) / (2.0 * h);
            assert!(
                (fd - to_mu_l(u).1).abs() < 1e-6 * fd.max(1.0),
                "u={u}: {fd} vs {}",
                to_mu_l(u).1
            );
        }
    }
}
