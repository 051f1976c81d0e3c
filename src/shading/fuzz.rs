//! The fuzz layer's directional reflectance R(μ, α): what a KHR_materials_fuzz layer reflects at
//! view cosine μ for fuzzRoughness α, and so what it takes from the layers below (w·R).
//!
//! The model is the one the fuzz draft recommends (Zeltner, Burley and Chiang 2022): a slab of
//! density 1 and thickness 1 of fibres standing along the normal, scattering by the SGGX
//! microflake phase function (Heitz et al. 2015) with S = diag(1, 1, σ²), σ = α²; single
//! scattering exactly, multiple scattering by the talk's empirical fit. With ωi the view direction
//! (cosθi = μ) and ωo the light direction (cosθo = c):
//!
//!   s(ω) = sqrt(sin²θ + σ² cos²θ)                          projected area
//!   D(m) = σ³ / (π (σ² (mx² + my²) + mz²)²)                 microflake distribution
//!   f_ss·c = D(h) · (1 − exp(−L)) / (4 μ L),   L = s(ωi)/μ + s(ωo)/c
//!   f_ms·c = exp(b(σ) − m(σ)·sqrt(c² + μ²)) · F(σ, c) · F(σ, μ) · c
//!   R(μ, α) = ∫ (f_ss + f_ms)·c dωo over the light hemisphere
//!
//! R is integrated by the same adaptive cubature as the sheen albedo (see `albedo.rs`), over the
//! light cosine (with its end-flattening substitution) and the azimuth, to an absolute tolerance.
//!
//! The limits, each pinned by a test in this file:
//! - λ = s/cos grows without bound at grazing angles, and the talk's code returns 0 where it
//!   overflows. velvet never forms λ alone: with N = s(ωi)·c + μ·s(ωo) (never negative),
//!   f_ss·c = D(h) · (1 − exp(−L)) · c / (4 N) and L = N / (μ c), where L = +∞ gives
//!   1 − exp(−∞) = 1 and 1 − exp(−L) is computed as −expm1(−L) so that L → 0 keeps its digits.
//!   At c = 0 (light on the horizon, μ > 0) this is 0: the stated 0 is also the limit there.
//!   Where N = 0 (μ = c = 0, or σ → 0 at μ = c = 1, where D(h) vanishes anyway) it is 0 too.
//! - μ → 0 (view on the horizon): the integrand tends to D(h) / (4 s(ωi)), the phase function,
//!   so R tends to a finite limit, and velvet takes it at μ = 0 instead of returning the talk's
//!   0 there (which would make R jump at the horizon). By the z → −z symmetry of D, horizontally
//!   lit flakes send exactly half of the light upwards: the single-scattering part of R(0, α)
//!   is ½ for every α > 0. No floor on μ is needed (unlike the sheen albedo, R stays bounded).
//! - α → 0: σ = α² is floored at [`SIGMA_MIN`] (α = 1e-6), which keeps 1/σ finite. For μ > 0
//!   the single scattering vanishes with σ (D(h) ≤ 16σ³/(πμ⁴) since the half vector has
//!   cosθh ≥ μ/2, so the single-scattering part is below 8σ³/μ⁵): R(μ, 0) is the multiple-scattering
//!   fit at σ = 0 alone, which is not 0 near grazing (the fit gives R(0.1, 0) ≈ 0.196). At μ = 0
//!   the single scattering stays ½ for every σ > 0, so the two limits do not commute at
//!   (μ, α) = (0, 0); velvet takes μ → 0 first, R(0, α) = ½ + R_ms(0, α) for every α, and the
//!   transition lies at μ ≲ σ = α² (below μ = 1e-3 for α ≤ 0.03).
//! - α = 1: σ = 1 makes S the identity (isotropic flakes, D = 1/π, s = 1), and the single
//!   scattering is the classic slab of optical depth 1 with an isotropic phase function:
//!   R_ss(μ, 1) = ½ ∫₀¹ c/(μ + c) · (1 − exp(−1/μ − 1/c)) dc.
//! - Roughness outside [0, 1] and NaN are clamped into [0, 1] (NaN as 0), as for the sheen.

use super::albedo::{hemisphere_albedo, CosWeightedBrdf};
use super::charlie::clamp01;
use super::fuzz_table;
use super::quadrature::Estimate;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Smallest σ = α² used (α = 1e-6): keeps the microflake distribution finite (its peak, on the
/// horizon, is 1/(πσ)). Below it R no longer changes for μ ≥ 1e-3 (the single scattering there
/// is under 8σ³/μ⁵ < 1e-20).
pub const SIGMA_MIN: f64 = 1e-12;

/// The control values of m(σ), the decay rate of the multiple-scattering fit, at
/// σ = −0.1, 0, 0.1, …, 1.0, 1.1 (the first and last set the slopes at the ends).
const M_CONTROL: [f64; 13] = [
    29.8, 20.0, 10.2, 6.14, 4.30, 3.30, 2.55, 2.02, 1.63, 1.33, 1.1, 0.95, 0.8,
];

/// The control values of b(σ), the log-scale of the multiple-scattering fit, at the same σ.
const B_CONTROL: [f64; 13] = [
    5.17, 3.7, 2.23, 1.06, 0.293, -0.212, -0.641, -0.952, -1.2, -1.4, -1.55, -1.65, -1.75,
];

/// The default absolute tolerance of [`reflectance_quadrature`].
pub const REFLECTANCE_TOL: f64 = 1e-7;

/// The absolute error bound velvet states for R by quadrature at [`REFLECTANCE_TOL`] (the
/// tests check it against closed forms and by convergence).
pub const REFLECTANCE_BOUND: f64 = 1e-6;

/// Which part of the scattering to integrate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scattering {
    /// Light that scatters once in the fibre layer (exact for the slab).
    Single,
    /// Light that scatters more than once (the talk's empirical fit).
    Multiple,
    /// Both: R itself.
    Total,
}

/// σ = α², floored at [`SIGMA_MIN`]; α outside [0, 1] is clamped into it.
pub fn sigma_from_roughness(alpha: f64) -> f64 {
    let a = clamp01(alpha);
    (a * a).max(SIGMA_MIN)
}

/// The SGGX projected area s(ω) = sqrt(sin²θ + σ² cos²θ) for cosθ = `cos_theta` (its absolute
/// value, clamped to 1).
pub fn projected_area(cos_theta: f64, sigma: f64) -> f64 {
    let c = clamp01(cos_theta.abs());
    ((1.0 - c) * (1.0 + c) + sigma * sigma * c * c).sqrt()
}

/// The fibre-like SGGX distribution D(m) = σ³ / (π (σ² (mx² + my²) + mz²)²) of a unit normal,
/// given as its horizontal part squared and its z part squared (an unnormalised m is normalised:
/// D depends on the direction only). 0 for the zero vector.
pub fn microflake_d(horizontal2: f64, z2: f64, sigma: f64) -> f64 {
    let total = horizontal2 + z2;
    if total <= 0.0 {
        return 0.0;
    }
    // q ≤ 1/σ² because σ ≤ 1, so D ≤ 1/(πσ): finite for σ ≥ SIGMA_MIN.
    let q = total / (sigma * sigma * horizontal2 + z2);
    sigma * sigma * sigma / PI * q * q
}

/// The spec's cubic through the 13 control values: with u = 10σ, i = min(⌊u⌋, 9), y = u − i,
/// ½ Σ Bk(y)·values[i + k]. It interpolates the control values at σ = 0, 0.1, …, 1 and has a
/// continuous slope (it is a Catmull–Rom spline).
fn spline(values: &[f64; 13], sigma: f64) -> f64 {
    let u = 10.0 * clamp01(sigma);
    let i = (u.floor() as usize).min(9);
    let w = catmull_rom_weights(u - i as f64);
    (0..4).map(|k| w[k] * values[i + k]).sum()
}

/// The Catmull–Rom weights ½(B0, B1, B2, B3) of four consecutive samples for the fraction y ∈
/// [0, 1] between the middle two. At y = 0 they are exactly (0, 1, 0, 0).
pub(crate) fn catmull_rom_weights(y: f64) -> [f64; 4] {
    let (y2, y3) = (y * y, y * y * y);
    [
        0.5 * (-y + 2.0 * y2 - y3),
        0.5 * (2.0 - 5.0 * y2 + 3.0 * y3),
        0.5 * (y + 4.0 * y2 - 3.0 * y3),
        0.5 * (-y2 + y3),
    ]
}

/// Catmull–Rom interpolation at x of n ≥ 2 samples taken at x_k = k/(n − 1) on [0, 1]. x is
/// clamped into [0, 1]; the samples are extended linearly past both ends (the sample beyond
/// the first is 2·s₀ − s₁), so a linear function is reproduced exactly everywhere.
pub(crate) fn catmull_rom(n: usize, sample: impl Fn(usize) -> f64, x: f64) -> f64 {
    debug_assert!(n >= 2);
    let p = clamp01(x) * (n - 1) as f64;
    // p ≥ 0, so truncation is the floor (without a call to libm's floor).
    let i = (p as usize).min(n - 2);
    let w = catmull_rom_weights(p - i as f64);
    let before = if i == 0 {
        2.0 * sample(0) - sample(1)
    } else {
        sample(i - 1)
    };
    let after = if i + 2 >= n {
        2.0 * sample(n - 1) - sample(n - 2)
    } else {
        sample(i + 2)
    };
    w[0] * before + w[1] * sample(i) + w[2] * sample(i + 1) + w[3] * after
}

/// m(σ), the decay rate of the multiple-scattering fit.
pub fn ms_decay(sigma: f64) -> f64 {
    spline(&M_CONTROL, sigma)
}

/// b(σ), the log-scale of the multiple-scattering fit.
pub fn ms_log_scale(sigma: f64) -> f64 {
    spline(&B_CONTROL, sigma)
}

/// F(σ, c) = β + (1 − β)(1 − (1 − c)¹²), β = max(0.55, 0.44 + 0.42σ).
pub fn ms_angular(sigma: f64, cos_theta: f64) -> f64 {
    let beta = (0.44 + 0.42 * clamp01(sigma)).max(0.55);
    let c = clamp01(cos_theta);
    beta + (1.0 - beta) * (1.0 - (1.0 - c).powi(12))
}

/// The cosine-weighted fuzz BRDF for one view cosine and σ, split into what depends on the
/// light cosine alone and the rest.
struct FuzzCos {
    parts: Scattering,
    sigma: f64,
    /// View cosine μ and sine.
    mu: f64,
    sin_v: f64,
    /// s(ωi).
    area_v: f64,
    /// exp(b(σ))·F(σ, μ), m(σ).
    ms_scale: f64,
    ms_decay: f64,
}

/// Per light cosine c: the single-scattering weight (1 − e^−L)·c/(4N), the pieces of the half
/// vector and the multiple-scattering value.
#[derive(Clone, Copy, Default)]
struct FuzzPerLight {
    weight: f64,
    /// (sinθi − sinθo)²
    ds2: f64,
    /// 4·sinθi·sinθo
    four_ss: f64,
    /// (μ + c)²
    hz2: f64,
    ms: f64,
}

impl FuzzCos {
    fn new(mu: f64, alpha: f64, parts: Scattering) -> Self {
        let mu = clamp01(mu);
        let sigma = sigma_from_roughness(alpha);
        FuzzCos {
            parts,
            sigma,
            mu,
            sin_v: ((1.0 - mu) * (1.0 + mu)).sqrt(),
            area_v: projected_area(mu, sigma),
            ms_scale: ms_log_scale(sigma).exp() * ms_angular(sigma, mu),
            ms_decay: ms_decay(sigma),
        }
    }

    /// (1 − exp(−L))·c / (4N) with N = s(ωi)·c + μ·s(ωo), L = N/(μc): the single-scattering
    /// integrand divided by D(h).
    fn single_weight(&self, c: f64, area_l: f64) -> f64 {
        let n = self.area_v * c + self.mu * area_l;
        if n <= 0.0 {
            return 0.0; // μ = c = 0, or σ → 0 at μ = c = 1 (where D(h) = 0 too)
        }
        // μc = 0 gives L = +∞ and −expm1(−∞) = 1: the λ → ∞ limit, taken exactly.
        let l = n / (self.mu * c);
        -(-l).exp_m1() * c / (4.0 * n)
    }

    fn multiple(&self, c: f64) -> f64 {
        self.ms_scale * (-self.ms_decay * c.hypot(self.mu)).exp() * ms_angular(self.sigma, c) * c
    }

    /// The integrand at light cosine c and cos²(φ/2), φ the azimuth between the two directions.
    fn at(&self, c: f64, cos2_half_phi: f64) -> f64 {
        let p = self.per_l(c);
        self.eval(&p, cos2_half_phi)
    }
}

impl CosWeightedBrdf for FuzzCos {
    type PerL = FuzzPerLight;

    fn per_l(&self, c: f64) -> FuzzPerLight {
        let c = clamp01(c);
        let sin_l = ((1.0 - c) * (1.0 + c)).sqrt();
        let single = self.parts != Scattering::Multiple;
        let multiple = self.parts != Scattering::Single;
        let ds = self.sin_v - sin_l;
        let hz = self.mu + c;
        FuzzPerLight {
            weight: if single {
                self.single_weight(c, projected_area(c, self.sigma))
            } else {
                0.0
            },
            ds2: ds * ds,
            four_ss: 4.0 * self.sin_v * sin_l,
            hz2: hz * hz,
            ms: if multiple { self.multiple(c) } else { 0.0 },
        }
    }

    #[inline]
    fn eval(&self, p: &FuzzPerLight, cos2_half_phi: f64) -> f64 {
        let single = if p.weight > 0.0 {
            // |horizontal(ωi + ωo)|² = (sinθi − sinθo)² + 4 sinθi sinθo cos²(φ/2): no
            // cancellation, never negative.
            let horizontal2 = p.ds2 + p.four_ss * cos2_half_phi;
            p.weight * microflake_d(horizontal2, p.hz2, self.sigma)
        } else {
            0.0
        };
        single + p.ms
    }

    fn kinks(&self) -> Vec<f64> {
        // Not kinks but scales: the single-scattering weight rises from 0 over c ~ μ, and for
        // small σ the distribution's peak (half vectors near the horizon) is a band c ≲ σ.
        vec![self.mu, self.sigma]
    }
}

/// The cosine-weighted single-scattering BRDF f_ss·cosθo at view cosine `mu`, light cosine
/// `mu_l` and azimuth `phi` between them (0 = light on the viewer's side).
pub fn single_scattering_cos(mu: f64, mu_l: f64, phi: f64, alpha: f64) -> f64 {
    let f = FuzzCos::new(mu, alpha, Scattering::Single);
    let half = 0.5 * phi;
    f.at(mu_l, half.cos() * half.cos())
}

/// The cosine-weighted multiple-scattering fit f_ms·cosθo (independent of the azimuth).
pub fn multiple_scattering_cos(mu: f64, mu_l: f64, alpha: f64) -> f64 {
    FuzzCos::new(mu, alpha, Scattering::Multiple).multiple(clamp01(mu_l))
}

/// R(μ, α) (or one of its parts) by adaptive quadrature to absolute tolerance `tol`, with the
/// integrator's estimate and the number of integrand evaluations. μ and α are clamped into
/// [0, 1].
pub fn reflectance_quadrature(mu: f64, alpha: f64, parts: Scattering, tol: f64) -> Estimate {
    hemisphere_albedo(&FuzzCos::new(mu, alpha, parts), tol)
}

/// The ways velvet computes R(μ, α), both behind [`fuzz_reflectance`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReflectanceMethod {
    /// Adaptive quadrature at [`REFLECTANCE_TOL`]: the reference, error at most
    /// [`REFLECTANCE_BOUND`].
    Quadrature,
    /// velvet's checked-in 33×33 table with bicubic interpolation (see [`table_lookup`]).
    Table,
}

impl ReflectanceMethod {
    /// Both methods, in the order the accuracy report lists them.
    pub const ALL: [ReflectanceMethod; 2] =
        [ReflectanceMethod::Quadrature, ReflectanceMethod::Table];

    /// The method's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            ReflectanceMethod::Quadrature => "quadrature",
            ReflectanceMethod::Table => "table",
        }
    }
}

/// R(μ, α) of the fuzz layer: the fraction of light at view cosine μ that a fuzz layer of
/// roughness α reflects (and takes from the base, times the fuzz weight). μ and α are clamped
/// into [0, 1].
pub fn fuzz_reflectance(mu: f64, alpha: f64, method: ReflectanceMethod) -> f64 {
    match method {
        ReflectanceMethod::Quadrature => {
            reflectance_quadrature(mu, alpha, Scattering::Total, REFLECTANCE_TOL).value
        }
        ReflectanceMethod::Table => table_lookup(&fuzz_table::VALUES, mu, alpha),
    }
}

/// Nodes per axis of the reflectance table.
pub const TABLE_SIZE: usize = fuzz_table::SIZE;

/// Stated bound on |table − quadrature| where μ ≥ 0.1 and α ≥ 0.25 (measured by `velvet bench
/// accuracy`: 5.8e-4 over its 65×65 grid, at μ ≈ 0.156, α ≈ 0.453; 5.4e-4 on a 97×97 grid).
pub const TABLE_BOUND_ORDINARY: f64 = 1e-3;

/// Stated bound on |table − quadrature| outside that region for μ = 0 or μ ≥ 0.01 (measured:
/// 7.3e-4 over the 65×65 grid, 1.5e-3 on a 97×97 grid at μ ≈ 0.0104, α ≈ 0.06).
pub const TABLE_BOUND_HARD: f64 = 3e-3;

/// Stated bound on |table − quadrature| in the corner 0 < μ < 0.01: for small α the single
/// scattering falls from ½ at μ = 0 to nearly 0 within μ ≲ α², a step the table's first cell
/// (μ from 0 to 1/1024) cannot follow, so there the table can miss most of the step (measured
/// by the tests: 0.48; the interpolant is monotone in that cell and stays between the step's
/// two levels).
pub const TABLE_BOUND_CORNER: f64 = 0.5;

/// The table's node coordinate along either axis: k/(TABLE_SIZE − 1). Along μ the nodes sit at
/// the squares of these (μ_i = (i/32)²): R changes like √μ near μ = 0, so the table's μ axis is
/// √μ, where R is close to linear.
pub fn table_node(k: usize) -> f64 {
    k as f64 / (TABLE_SIZE - 1) as f64
}

/// R at (μ, α) from table values laid out as `fuzz_table::VALUES` (R at μ_i = (i/32)²,
/// α_j = j/32 in values[j·33 + i]): Catmull–Rom in √μ and in α, with the samples extended
/// linearly past the edges, and negative results (an overshoot where R ≈ 0) raised to 0. μ and
/// α are clamped into [0, 1]; at the nodes the lookup returns the stored value exactly.
pub fn table_lookup(values: &[f64], mu: f64, alpha: f64) -> f64 {
    let n = TABLE_SIZE;
    assert_eq!(values.len(), n * n, "a {n}×{n} table");
    let u = clamp01(mu).sqrt();
    let row = |j: usize| catmull_rom(n, |i| values[j * n + i], u);
    catmull_rom(n, row, alpha).max(0.0)
}

/// The table's values by quadrature (at [`REFLECTANCE_TOL`]), in parallel: what
/// `fuzz_table.rs` holds.
pub fn generate_table() -> Vec<f64> {
    let n = TABLE_SIZE;
    (0..n * n)
        .into_par_iter()
        .map(|k| {
            let u = table_node(k % n);
            fuzz_reflectance(u * u, table_node(k / n), ReflectanceMethod::Quadrature)
        })
        .collect()
}

/// The source text of `fuzz_table.rs` for the given values.
#[cfg(test)]
fn table_source(values: &[f64]) -> String {
    super::square_table_source(
        "//! R(μ, α) at the nodes of velvet's fuzz reflectance table (see `fuzz.rs`), computed by\n\
         //! velvet's quadrature. Generated: `VELVET_UPDATE_GOLDEN=1 cargo test --lib\n\
         //! shading::fuzz` rewrites this file, and that test fails when the quadrature no longer\n\
         //! gives these values. Do not edit by hand.\n",
        TABLE_SIZE,
        "R at μ_i = (i/32)², α_j = j/32, in VALUES[j·SIZE + i].",
        values,
    )
}

#[cfg(test)]
mod tests {
    use super::super::quadrature::{integrate_2d, kronrod_15, Separable};
    use super::*;

    fn r(mu: f64, alpha: f64, parts: Scattering) -> f64 {
        reflectance_quadrature(mu, alpha, parts, REFLECTANCE_TOL).value
    }

    /// ∫₀¹ f by the 15-point Kronrod rule on `pieces` equal intervals (an independent 1-D check).
    fn integral_1d(f: impl Fn(f64) -> f64, pieces: usize) -> f64 {
        (0..pieces)
            .flat_map(|k| kronrod_15(k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64))
            .map(|(x, w)| w * f(x))
            .sum()
    }

    /// A function of (cosθ, φ) over the whole sphere: x = cosθ ∈ [−1, 1], y = φ ∈ [0, 2π].
    struct Sphere<G: Fn([f64; 3]) -> f64>(G);

    impl<G: Fn([f64; 3]) -> f64> Separable for Sphere<G> {
        type X = (f64, f64);
        type Y = (f64, f64);
        fn x(&self, z: f64) -> (f64, f64) {
            (z, ((1.0 - z) * (1.0 + z)).max(0.0).sqrt())
        }
        fn y(&self, phi: f64) -> (f64, f64) {
            (phi.cos(), phi.sin())
        }
        fn f(&self, x: &(f64, f64), y: &(f64, f64)) -> f64 {
            (self.0)([x.1 * y.0, x.1 * y.1, x.0])
        }
    }

    /// ∫ over the sphere of g, with break lines at the equator and at φ = kπ/2, where the
    /// tests' integrands have their kinks when ω lies in the xz-plane at cosθ = 0 or 1. Returns
    /// the value and whether the integrator met the tolerance.
    fn over_sphere(g: impl Fn([f64; 3]) -> f64, tol: f64) -> (f64, bool) {
        let phis = [0.0, 0.5 * PI, PI, 1.5 * PI, 2.0 * PI];
        let est = integrate_2d(&Sphere(g), &[-1.0, 0.0, 1.0], &phis, tol);
        (est.value, est.converged)
    }

    fn direction(cos_theta: f64) -> [f64; 3] {
        [
            ((1.0 - cos_theta) * (1.0 + cos_theta)).sqrt(),
            0.0,
            cos_theta,
        ]
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    #[test]
    fn distribution_projects_to_the_sggx_area() {
        // SGGX's normalisation: ∫ over the sphere of max(0, ω·m)·D(m) dm = s(ω).
        for sigma in [0.3, 0.7, 1.0] {
            // At cosθ = 0 and 1 the kink of max(0, ω·m) lies on break lines and the cubature
            // converges to 1e-8; at cosθ = 0.5 it is a curve across cells, so the tolerance is
            // looser there.
            for (c, tol) in [(0.0, 1e-8), (1.0, 1e-8), (0.5, 1e-6)] {
                let w = direction(c);
                let (got, converged) = over_sphere(
                    |m| {
                        dot(w, m).max(0.0)
                            * microflake_d(m[0] * m[0] + m[1] * m[1], m[2] * m[2], sigma)
                    },
                    tol,
                );
                let want = projected_area(c, sigma);
                assert!(converged || c == 0.5, "σ={sigma}, cosθ={c}");
                assert!(
                    (got - want).abs() < 1e-5,
                    "σ={sigma}, cosθ={c}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn phase_function_integrates_to_one_over_the_sphere() {
        // p(ωi → ωo) = D(h)/(4 s(ωi)) with h ∝ ωi + ωo is a probability density of ωo.
        for sigma in [0.4, 1.0] {
            for c in [0.2, 0.7, 1.0] {
                let wi = direction(c);
                let s = projected_area(c, sigma);
                let (got, converged) = over_sphere(
                    |wo| {
                        let h = [wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]];
                        microflake_d(h[0] * h[0] + h[1] * h[1], h[2] * h[2], sigma) / (4.0 * s)
                    },
                    1e-8,
                );
                assert!(converged);
                assert!((got - 1.0).abs() < 1e-6, "σ={sigma}, μ={c}: {got}");
            }
        }
    }

    #[test]
    fn the_fit_spline_passes_through_its_control_values_with_a_continuous_slope() {
        for k in 0..=10 {
            let sigma = k as f64 / 10.0;
            assert!(
                (ms_decay(sigma) - M_CONTROL[k + 1]).abs() < 1e-12,
                "m({sigma})"
            );
            assert!(
                (ms_log_scale(sigma) - B_CONTROL[k + 1]).abs() < 1e-12,
                "b({sigma})"
            );
        }
        let h = 1e-7;
        for k in 1..10 {
            let knot = k as f64 / 10.0;
            for f in [ms_decay as fn(f64) -> f64, ms_log_scale] {
                let left = (f(knot) - f(knot - h)) / h;
                let right = (f(knot + h) - f(knot)) / h;
                assert!(
                    (left - right).abs() < 1e-4 * left.abs().max(1.0),
                    "at {knot}"
                );
            }
        }
        // F(σ, c): β at c = 0, 1 at c = 1, β = max(0.55, 0.44 + 0.42σ).
        assert_eq!(ms_angular(0.0, 0.0), 0.55);
        assert!((ms_angular(1.0, 0.0) - 0.86).abs() < 1e-15);
        assert_eq!(ms_angular(0.5, 1.0), 1.0);
    }

    #[test]
    fn isotropic_single_scattering_is_the_classic_slab() {
        // α = 1: S = I, D = 1/π, s = 1, and f_ss·c = c·(1 − e^(−1/μ − 1/c)) / (4π (μ + c)).
        for mu in [0.05, 0.3, 0.7, 1.0] {
            let slab = 0.5
                * integral_1d(
                    |c| {
                        if c == 0.0 {
                            0.0
                        } else {
                            c / (mu + c) * -(-(1.0 / mu + 1.0 / c)).exp_m1()
                        }
                    },
                    64,
                );
            let got = r(mu, 1.0, Scattering::Single);
            assert!(
                (got - slab).abs() < REFLECTANCE_BOUND,
                "μ={mu}: {got} vs {slab}"
            );
        }
    }

    #[test]
    fn multiple_scattering_is_its_one_dimensional_integral() {
        // f_ms·c does not depend on the azimuth: R_ms = 2π ∫₀¹ f_ms·c dc.
        for &(mu, alpha) in &[(0.0, 0.0), (0.05, 0.1), (0.3, 0.5), (1.0, 1.0), (0.6, 0.8)] {
            let sigma = sigma_from_roughness(alpha);
            let (m, b) = (ms_decay(sigma), ms_log_scale(sigma));
            let direct = 2.0
                * PI
                * integral_1d(
                    |c| {
                        (b - m * (c * c + mu * mu).sqrt()).exp()
                            * ms_angular(sigma, c)
                            * ms_angular(sigma, mu)
                            * c
                    },
                    64,
                );
            let got = r(mu, alpha, Scattering::Multiple);
            assert!(
                (got - direct).abs() < REFLECTANCE_BOUND,
                "({mu}, {alpha}): {got} vs {direct}"
            );
            assert!(
                (multiple_scattering_cos(mu, 0.4, alpha)
                    - (b - m * (0.16 + mu * mu).sqrt()).exp()
                        * ms_angular(sigma, 0.4)
                        * ms_angular(sigma, mu)
                        * 0.4)
                    .abs()
                    < 1e-15
            );
        }
    }

    #[test]
    fn single_scattering_at_mu_zero_is_one_half_for_every_alpha() {
        // Limit μ → 0: horizontally lit flakes send half of the light up (D is even in z).
        for alpha in [1e-3, 0.01, 0.1, 0.5, 1.0] {
            let ss = r(0.0, alpha, Scattering::Single);
            assert!((ss - 0.5).abs() < REFLECTANCE_BOUND, "α={alpha}: {ss}");
            let total = r(0.0, alpha, Scattering::Total);
            let ms = r(0.0, alpha, Scattering::Multiple);
            assert!((total - (0.5 + ms)).abs() < 2.0 * REFLECTANCE_BOUND);
        }
        // And R is continuous into μ = 0 where σ is not tiny.
        for alpha in [0.3, 0.6, 1.0] {
            let at = r(0.0, alpha, Scattering::Total);
            let near = r(1e-12, alpha, Scattering::Total);
            assert!((at - near).abs() < 1e-5, "α={alpha}: {at} vs {near}");
        }
    }

    #[test]
    fn single_scattering_vanishes_as_alpha_goes_to_zero_when_mu_is_above_zero() {
        // Limit α → 0 at μ > 0: the half vector keeps cosθh ≥ μ/2, so R_ss ≤ 8σ³/μ⁵.
        for &(mu, alpha) in &[(0.1f64, 0.01f64), (0.5, 0.05), (1.0, 0.1), (0.01, 0.003)] {
            let sigma = alpha * alpha;
            let ss = r(mu, alpha, Scattering::Single);
            assert!(
                ss >= 0.0 && ss <= 8.0 * sigma.powi(3) / mu.powi(5),
                "({mu}, {alpha}): {ss}"
            );
        }
        // α = 0 exactly is the floor σ = SIGMA_MIN, and below the floor nothing changes.
        for mu in [0.0, 1e-3, 0.1, 0.5, 1.0] {
            assert_eq!(
                r(mu, 0.0, Scattering::Total),
                r(mu, 1e-7, Scattering::Total)
            );
        }
        // At the floor R is the multiple-scattering fit alone once μ ≥ 1e-3 …
        for mu in [1e-3, 0.1, 0.5, 1.0] {
            let ss = r(mu, 0.0, Scattering::Single);
            assert!(ss < 1e-20, "μ={mu}: {ss}");
        }
        // … which is not 0 near grazing (R(0.1, 0) ≈ 0.196) and is at normal view (2.6e-8).
        assert!((r(0.1, 0.0, Scattering::Total) - 0.1957).abs() < 1e-3);
        assert!(r(1.0, 0.0, Scattering::Total) < 1e-7);
    }

    #[test]
    fn the_integrand_takes_its_limits_without_nan() {
        let (alpha, phi) = (0.5, 1.0f64);
        // c = 0 (λo → ∞): the stated 0, which is also the limit.
        for mu in [0.0, 1e-300, 0.3, 1.0] {
            assert_eq!(single_scattering_cos(mu, 0.0, phi, alpha), 0.0, "μ={mu}");
        }
        // μ = 0 (λi → ∞): D(h)/(4 s(ωi)), the phase function, for c > 0.
        let sigma = sigma_from_roughness(alpha);
        for c in [1e-3f64, 0.4, 1.0] {
            let sl = ((1.0 - c) * (1.0 + c)).sqrt();
            let h = [1.0 + sl * phi.cos(), sl * phi.sin(), c];
            let want = microflake_d(h[0] * h[0] + h[1] * h[1], h[2] * h[2], sigma) / 4.0;
            let got = single_scattering_cos(0.0, c, phi, alpha);
            assert!((got - want).abs() <= 1e-14 * want, "c={c}: {got} vs {want}");
            // μ just above 0 approaches it.
            let near = single_scattering_cos(1e-12, c, phi, alpha);
            assert!(
                (near - want).abs() <= 1e-6 * want,
                "c={c}: {near} vs {want}"
            );
        }
        // L → 0 (σ → 0 at normal view): −expm1 keeps the digits, no 0/0.
        let v = single_scattering_cos(1.0, 1.0, 0.0, 0.0);
        assert!(v.is_finite() && v >= 0.0);
        // Both on the horizon, facing each other: ωi + ωo = 0, N = 0.
        assert_eq!(single_scattering_cos(0.0, 0.0, PI, alpha), 0.0);
        let grid = [
            0.0,
            1e-300,
            1e-12,
            1e-6,
            0.01,
            0.3,
            0.5,
            0.99,
            1.0 - 1e-15,
            1.0,
        ];
        for &mu in &grid {
            for &c in &grid {
                for &a in &grid {
                    for phi in [0.0, 1.0, PI] {
                        let ss = single_scattering_cos(mu, c, phi, a);
                        let ms = multiple_scattering_cos(mu, c, a);
                        assert!(
                            ss.is_finite() && ss >= 0.0,
                            "ss({mu}, {c}, {phi}, {a}) = {ss}"
                        );
                        assert!(ms.is_finite() && ms >= 0.0, "ms({mu}, {c}, {a}) = {ms}");
                    }
                }
            }
        }
    }

    #[test]
    fn halving_the_tolerance_changes_r_by_less_than_the_tolerance() {
        let points = [
            (0.5, 0.5),
            (0.0, 0.0),
            (0.0, 0.3),
            (1e-4, 0.01),
            (0.01, 0.1),
            (1.0, 1.0),
            (0.9, 0.25),
            (0.2, 0.8),
        ];
        for (mu, alpha) in points {
            let a = reflectance_quadrature(mu, alpha, Scattering::Total, REFLECTANCE_TOL);
            let b = reflectance_quadrature(mu, alpha, Scattering::Total, REFLECTANCE_TOL / 2.0);
            assert!(a.converged && b.converged, "({mu}, {alpha})");
            assert!(a.error <= REFLECTANCE_TOL && b.error <= REFLECTANCE_TOL / 2.0);
            assert!(
                (a.value - b.value).abs() < REFLECTANCE_TOL,
                "({mu}, {alpha}): {} vs {}",
                a.value,
                b.value
            );
        }
    }

    #[test]
    fn reflectance_is_finite_bounded_and_converged_on_a_grid_with_extremes() {
        let mut values: Vec<f64> = (0..=8).map(|i| i as f64 / 8.0).collect();
        values.extend([
            1e-300,
            1e-12,
            1e-4,
            0.5 - 1e-15,
            1.0 - 1e-15,
            f64::NAN,
            -1.0,
            2.0,
        ]);
        for &mu in &values {
            for &alpha in &values {
                let est = reflectance_quadrature(mu, alpha, Scattering::Total, REFLECTANCE_TOL);
                let ss = r(mu, alpha, Scattering::Single);
                assert!(est.converged, "({mu}, {alpha})");
                assert!(
                    est.value.is_finite() && est.value >= 0.0 && est.value < 0.8,
                    "R({mu}, {alpha}) = {}",
                    est.value
                );
                assert!(ss <= 0.5 + REFLECTANCE_BOUND, "R_ss({mu}, {alpha}) = {ss}");
            }
        }
    }

    #[test]
    fn committed_table_is_what_the_quadrature_gives() {
        let fresh = generate_table();
        if std::env::var_os("VELVET_UPDATE_GOLDEN").is_some() {
            let path =
                std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/shading/fuzz_table.rs");
            std::fs::write(&path, table_source(&fresh)).unwrap();
            return;
        }
        // Within the quadrature's tolerance: another platform's libm may bisect differently.
        for (k, (a, b)) in fuzz_table::VALUES.iter().zip(&fresh).enumerate() {
            assert!(
                (a - b).abs() <= REFLECTANCE_TOL,
                "node {k}: committed {a}, quadrature {b}; regenerate with VELVET_UPDATE_GOLDEN=1"
            );
        }
    }

    #[test]
    fn table_returns_its_nodes_and_clamps_its_inputs() {
        let n = TABLE_SIZE;
        for (i, j) in [(0, 0), (5, 9), (32, 32), (32, 0), (0, 32)] {
            let u = table_node(i);
            let want = fuzz_table::VALUES[j * n + i];
            assert_eq!(
                fuzz_reflectance(u * u, table_node(j), ReflectanceMethod::Table),
                want
            );
        }
        let t = |mu, a| fuzz_reflectance(mu, a, ReflectanceMethod::Table);
        assert_eq!(t(-1.0, f64::NAN), t(0.0, 0.0));
        assert_eq!(t(2.0, 7.0), t(1.0, 1.0));
        for i in 0..=200 {
            for j in 0..=200 {
                let v = t(i as f64 / 200.0, j as f64 / 200.0);
                assert!(v.is_finite() && (0.0..0.8).contains(&v), "({i}, {j}): {v}");
            }
        }
    }

    #[test]
    fn catmull_rom_reproduces_lines_and_nodes() {
        let line = |k: usize| 0.25 + 3.0 * k as f64 / 8.0;
        for x in [0.0, 0.01, 0.3, 0.5, 0.99, 1.0] {
            assert!(
                (catmull_rom(9, line, x) - (0.25 + 3.0 * x)).abs() < 1e-14,
                "{x}"
            );
        }
        let bumpy = |k: usize| ((k * 7919) % 13) as f64;
        for k in 0..=8 {
            assert_eq!(catmull_rom(9, bumpy, k as f64 / 8.0), bumpy(k));
        }
        assert_eq!(catmull_rom(2, |k| k as f64, 0.25), 0.25);
    }

    #[test]
    fn table_agrees_with_quadrature_within_the_stated_bounds() {
        // A grid that is not the table's: μ and α in steps of 1/40 (0 and 1 included) and the
        // corner's own points.
        let axis: Vec<f64> = (0..=40).map(|i| i as f64 / 40.0).collect();
        let mut points: Vec<(f64, f64)> = axis
            .iter()
            .flat_map(|&a| axis.iter().map(move |&mu| (mu, a)))
            .collect();
        for mu in [1e-6, 1e-4, 4e-4, 2e-3, 6e-3] {
            for a in [0.0, 0.01, 0.03, 0.1, 0.3, 1.0] {
                points.push((mu, a));
            }
        }
        // Just above the corner, where the single scattering of α ≈ 0.1 still changes fast.
        for mu in [0.01, 0.012, 0.015, 0.02, 0.03] {
            for a in [0.05, 0.08, 0.1, 0.12, 0.15, 0.2] {
                points.push((mu, a));
            }
        }
        let reference: Vec<f64> = points
            .par_iter()
            .map(|&(mu, a)| fuzz_reflectance(mu, a, ReflectanceMethod::Quadrature))
            .collect();
        let mut worst = [0.0f64; 3];
        for (&(mu, a), q) in points.iter().zip(&reference) {
            let e = (fuzz_reflectance(mu, a, ReflectanceMethod::Table) - q).abs();
            let region = if mu >= 0.1 && a >= 0.25 {
                0
            } else if mu >= 0.01 {
                1
            } else {
                2
            };
            worst[region] = worst[region].max(e);
        }
        assert!(worst[0] <= TABLE_BOUND_ORDINARY, "ordinary: {}", worst[0]);
        assert!(worst[1] <= TABLE_BOUND_HARD, "hard: {}", worst[1]);
        assert!(worst[2] <= TABLE_BOUND_CORNER, "corner: {}", worst[2]);
    }
}
