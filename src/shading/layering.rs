//! How a sheen or fuzz layer sits on its base, and how far the base attenuation moves when a sheen
//! layer becomes a fuzz layer.
//!
//! - Sheen (KHR_materials_sheen, albedo scaling):
//!   sheen = sheenColor·f_sheen + base·(1 − max3(sheenColor)·E(μ, r)).
//! - Fuzz (KHR_materials_fuzz): fuzz = fuzzColor·R·w + base·(1 − w·R), R the fuzz layer's
//!   directional reflectance and w the fuzz intensity.
//!
//! The base attenuation must lie in [0, 1], but the Charlie albedo E exceeds 1 for small r at
//! grazing μ (its fitted visibility is not energy conserving there), so 1 − max3·E can go negative.
//! Every attenuation here is clamped into [0, 1] and says whether the clamp acted; [`ClampCount`]
//! adds them up so reports can say how often it happened.
//!
//! The fuzz layer's reflectance R(μ, α) is velvet's model of the fuzz draft's fibre layer
//! ([`FuzzReflectance`], see `fuzz.rs`). The comparison functions take the reflectances as
//! [`LayerReflectance`] trait objects, so either layer's reflectance can be swapped for another
//! method (a table, a stand-in in tests) without changing them.

use super::albedo::AlbedoMethod;
use super::charlie::clamp01;
use super::fuzz::{fuzz_reflectance, ReflectanceMethod};
use super::sheen_albedo;

/// A base attenuation factor, clamped into [0, 1], with the value before the clamp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attenuation {
    /// The factor the base is multiplied by, in [0, 1].
    pub factor: f64,
    /// The formula's value before clamping (negative where the layer's reflectance exceeds 1).
    pub unclamped: f64,
}

impl Attenuation {
    fn new(unclamped: f64) -> Self {
        Attenuation {
            factor: clamp01(unclamped),
            unclamped,
        }
    }

    /// Whether the clamp changed the value.
    pub fn was_clamped(&self) -> bool {
        self.factor != self.unclamped
    }
}

/// How many attenuations were computed and how many of them were clamped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClampCount {
    /// Attenuations recorded.
    pub evaluated: u64,
    /// Of those, how many the clamp changed.
    pub clamped: u64,
}

impl ClampCount {
    /// Records one attenuation and returns its clamped factor.
    pub fn record(&mut self, a: Attenuation) -> f64 {
        self.evaluated += 1;
        self.clamped += u64::from(a.was_clamped());
        a.factor
    }
}

/// The largest of three channels (the spec's max3).
pub fn max3(c: [f64; 3]) -> f64 {
    c[0].max(c[1]).max(c[2])
}

/// The sheen layer's base attenuation 1 − max3(sheenColor)·E, clamped into [0, 1]. `color_max3`
/// is clamped into [0, 1]; `albedo` is E(μ, r), which may exceed 1.
pub fn sheen_base_attenuation(color_max3: f64, albedo: f64) -> Attenuation {
    Attenuation::new(1.0 - clamp01(color_max3) * albedo.max(0.0))
}

/// The fuzz layer's base attenuation 1 − w·R (= mix(1, 1 − R, w)), clamped into [0, 1]. `weight`
/// is clamped into [0, 1]; `reflectance` is R(μ, α).
pub fn fuzz_base_attenuation(weight: f64, reflectance: f64) -> Attenuation {
    Attenuation::new(1.0 - clamp01(weight) * reflectance.max(0.0))
}

/// One channel set of the sheen layering: sheenColor·f_sheen + base·attenuation.
pub fn sheen_layer(
    sheen_color: [f64; 3],
    sheen_brdf: f64,
    base: [f64; 3],
    albedo: f64,
) -> ([f64; 3], Attenuation) {
    let a = sheen_base_attenuation(max3(sheen_color), albedo);
    (
        std::array::from_fn(|k| sheen_color[k] * sheen_brdf + base[k] * a.factor),
        a,
    )
}

/// One channel set of the fuzz layering: fuzzColor·R·w + base·attenuation.
pub fn fuzz_layer(
    fuzz_color: [f64; 3],
    weight: f64,
    reflectance: f64,
    base: [f64; 3],
) -> ([f64; 3], Attenuation) {
    let a = fuzz_base_attenuation(weight, reflectance);
    let w = clamp01(weight);
    (
        std::array::from_fn(|k| fuzz_color[k] * reflectance * w + base[k] * a.factor),
        a,
    )
}

/// A layer's directional reflectance as a function of the view cosine μ and the layer's
/// roughness: what the layer takes away from the base.
pub trait LayerReflectance {
    /// A short name for reports ("sheen E (quadrature)", …).
    fn name(&self) -> String;
    /// The reflectance at view cosine `mu` for the layer's `roughness`.
    fn reflectance(&self, mu: f64, roughness: f64) -> f64;
}

/// The sheen layer's reflectance: the Charlie albedo E(μ, r) by one of velvet's methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SheenAlbedo(pub AlbedoMethod);

impl LayerReflectance for SheenAlbedo {
    fn name(&self) -> String {
        format!("sheen E ({})", self.0.name())
    }
    fn reflectance(&self, mu: f64, roughness: f64) -> f64 {
        sheen_albedo(mu, roughness, self.0)
    }
}

/// The fuzz layer's reflectance R(μ, α) (velvet's model of the fibre layer the fuzz draft
/// recommends) by one of velvet's methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FuzzReflectance(pub ReflectanceMethod);

impl LayerReflectance for FuzzReflectance {
    fn name(&self) -> String {
        format!("fuzz R ({})", self.0.name())
    }
    fn reflectance(&self, mu: f64, roughness: f64) -> f64 {
        fuzz_reflectance(mu, roughness, self.0)
    }
}

/// A sheen layer as the comparison needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheenParams {
    /// max3(sheenColor).
    pub color_max3: f64,
    /// sheenRoughness r.
    pub roughness: f64,
}

/// A fuzz layer as the comparison needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzParams {
    /// The fuzz intensity w (fuzzFactor).
    pub weight: f64,
    /// fuzzRoughness.
    pub roughness: f64,
}

/// The view cosines the comparison samples: μ_k = k / (COMPARISON_SAMPLES − 1).
pub const COMPARISON_SAMPLES: usize = 65;

/// Both layers at one view cosine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// View cosine μ.
    pub mu: f64,
    /// The sheen layer's reflectance E(μ, r).
    pub sheen_reflectance: f64,
    /// The fuzz layer's reflectance R(μ, α).
    pub fuzz_reflectance: f64,
    /// 1 − max3·E, clamped.
    pub sheen_attenuation: Attenuation,
    /// 1 − w·R, clamped.
    pub fuzz_attenuation: Attenuation,
}

impl CurvePoint {
    /// |sheen attenuation − fuzz attenuation| (clamped factors).
    pub fn difference(&self) -> f64 {
        (self.sheen_attenuation.factor - self.fuzz_attenuation.factor).abs()
    }
}

/// How far a sheen layer's base attenuation is from that of the fuzz layer it became.
#[derive(Clone, Debug, PartialEq)]
pub struct AttenuationComparison {
    /// Name of the sheen reflectance used.
    pub sheen_reflectance: String,
    /// Name of the fuzz reflectance used.
    pub fuzz_reflectance: String,
    /// The curves at every sampled μ (for reports that show E against R).
    pub curve: Vec<CurvePoint>,
    /// The largest difference over the samples.
    pub max_difference: f64,
    /// The μ where it occurs (the first, if several tie).
    pub at_mu: f64,
    /// Clamps applied over both curves.
    pub clamps: ClampCount,
}

/// Compares the base attenuation of one sheen layer and of the fuzz layer it became, at the
/// [`COMPARISON_SAMPLES`] view cosines μ_k = k/64 in [0, 1]. E and R are evaluated only at the
/// two roughness values given, never over a whole table (with [`AlbedoMethod::Quadrature`],
/// 2 × 65 quadratures).
pub fn compare_base_attenuation(
    sheen: SheenParams,
    fuzz: FuzzParams,
    sheen_reflectance: &dyn LayerReflectance,
    fuzz_reflectance: &dyn LayerReflectance,
) -> AttenuationComparison {
    let mut clamps = ClampCount::default();
    let n = COMPARISON_SAMPLES;
    let curve: Vec<CurvePoint> = (0..n)
        .map(|k| {
            let mu = k as f64 / (n - 1) as f64;
            let e = sheen_reflectance.reflectance(mu, sheen.roughness);
            let r = fuzz_reflectance.reflectance(mu, fuzz.roughness);
            let sa = sheen_base_attenuation(sheen.color_max3, e);
            let fa = fuzz_base_attenuation(fuzz.weight, r);
            clamps.record(sa);
            clamps.record(fa);
            CurvePoint {
                mu,
                sheen_reflectance: e,
                fuzz_reflectance: r,
                sheen_attenuation: sa,
                fuzz_attenuation: fa,
            }
        })
        .collect();
    let worst = curve.iter().fold(&curve[0], |w, p| {
        if p.difference() > w.difference() {
            p
        } else {
            w
        }
    });
    AttenuationComparison {
        sheen_reflectance: sheen_reflectance.name(),
        fuzz_reflectance: fuzz_reflectance.name(),
        max_difference: worst.difference(),
        at_mu: worst.mu,
        curve,
        clamps,
    }
}

/// [`compare_base_attenuation`] with the sheen E and the fuzz R both by quadrature.
pub fn sheen_to_fuzz_attenuation_difference(
    sheen: SheenParams,
    fuzz: FuzzParams,
) -> AttenuationComparison {
    compare_base_attenuation(
        sheen,
        fuzz,
        &SheenAlbedo(AlbedoMethod::Quadrature),
        &FuzzReflectance(ReflectanceMethod::Quadrature),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    #[test]
    fn sheen_attenuation_is_one_minus_max3_times_e() {
        let a = sheen_base_attenuation(0.5, 0.4);
        assert_eq!(a.factor, 0.8);
        assert!(!a.was_clamped());
        assert_eq!(sheen_base_attenuation(0.0, 3.0).factor, 1.0);
    }

    #[test]
    fn albedo_above_one_is_clamped_and_counted() {
        // E > 1 happens for small r at grazing μ; with max3 = 1 the formula goes negative.
        let e = sheen_albedo(0.05, 0.0625, AlbedoMethod::Quadrature);
        assert!(e > 1.0, "E = {e}");
        let a = sheen_base_attenuation(1.0, e);
        assert_eq!(a.factor, 0.0);
        assert!((a.unclamped - (1.0 - e)).abs() < 1e-15);
        assert!(a.was_clamped());
        let mut count = ClampCount::default();
        assert_eq!(count.record(a), 0.0);
        assert_eq!(count.record(sheen_base_attenuation(0.5, 0.5)), 0.75);
        assert_eq!(
            count,
            ClampCount {
                evaluated: 2,
                clamped: 1
            }
        );
    }

    #[test]
    fn fuzz_attenuation_is_mix_of_one_and_one_minus_r() {
        for &(w, r) in &[(0.0, 0.7), (1.0, 0.7), (0.3, 0.2)] {
            let mix = 1.0 + ((1.0 - r) - 1.0) * w;
            assert!((fuzz_base_attenuation(w, r).factor - mix).abs() < 1e-15);
        }
        assert!(fuzz_base_attenuation(1.0, 1.5).was_clamped());
        assert_eq!(fuzz_base_attenuation(1.0, 1.5).factor, 0.0);
    }

    #[test]
    fn layers_combine_as_the_specs_write_them() {
        let (c, a) = sheen_layer([0.2, 0.6, 0.4], 0.5, [1.0, 0.5, 0.25], 0.5);
        assert_eq!(a.factor, 0.7);
        let expected = [0.2 * 0.5 + 0.7, 0.6 * 0.5 + 0.35, 0.4 * 0.5 + 0.175];
        for k in 0..3 {
            assert!((c[k] - expected[k]).abs() < 1e-15);
        }
        // Black fuzz at full weight darkens the base by R and adds nothing.
        let (c, a) = fuzz_layer([0.0; 3], 1.0, 0.25, [0.8, 0.4, 0.2]);
        assert_eq!(a.factor, 0.75);
        for (got, want) in c.iter().zip([0.6, 0.3, 0.15]) {
            assert!((got - want).abs() < 1e-15);
        }
    }

    #[test]
    fn nan_inputs_give_finite_attenuations() {
        assert!(sheen_base_attenuation(f64::NAN, 0.5).factor.is_finite());
        assert!(sheen_base_attenuation(0.5, f64::NAN).factor.is_finite());
        assert!(fuzz_base_attenuation(f64::NAN, f64::NAN).factor.is_finite());
    }

    /// A reflectance that records the roughness values it is asked about.
    struct Recording<'a>(&'a RefCell<Vec<f64>>, f64);

    impl LayerReflectance for Recording<'_> {
        fn name(&self) -> String {
            "recording".into()
        }
        fn reflectance(&self, _mu: f64, roughness: f64) -> f64 {
            self.0.borrow_mut().push(roughness);
            self.1
        }
    }

    #[test]
    fn comparison_asks_only_for_the_two_roughness_values() {
        let seen = RefCell::new(Vec::new());
        let cmp = compare_base_attenuation(
            SheenParams {
                color_max3: 1.0,
                roughness: 0.3,
            },
            FuzzParams {
                weight: 0.5,
                roughness: 0.7,
            },
            &Recording(&seen, 0.4),
            &Recording(&seen, 0.4),
        );
        let seen = seen.into_inner();
        assert_eq!(seen.len(), 2 * COMPARISON_SAMPLES);
        assert!(seen.iter().all(|&r| r == 0.3 || r == 0.7));
        // Constant reflectances: sheen 1 − 0.4 = 0.6, fuzz 1 − 0.2 = 0.8.
        assert!((cmp.max_difference - 0.2).abs() < 1e-15);
        assert_eq!(cmp.at_mu, 0.0);
        assert_eq!(
            cmp.clamps,
            ClampCount {
                evaluated: 2 * COMPARISON_SAMPLES as u64,
                clamped: 0
            }
        );
    }

    #[test]
    fn identical_reflectances_differ_by_nothing() {
        // The same reflectance on both sides with max3 = w: the layers agree exactly.
        let cmp = compare_base_attenuation(
            SheenParams {
                color_max3: 0.8,
                roughness: 0.5,
            },
            FuzzParams {
                weight: 0.8,
                roughness: 0.5,
            },
            &SheenAlbedo(AlbedoMethod::Fit),
            &SheenAlbedo(AlbedoMethod::Fit),
        );
        assert_eq!(cmp.max_difference, 0.0);
        assert_eq!(cmp.curve.len(), COMPARISON_SAMPLES);
        assert_eq!(cmp.fuzz_reflectance, "sheen E (fit)");
    }

    #[test]
    fn sheen_and_fuzz_at_one_roughness_differ_most_at_normal_view_for_r_one() {
        // r = α = 1, full colour and weight: E(1, 1) ≈ 0.164 and R(1, 1) ≈ 0.332 (velvet's
        // quadrature), so the base attenuations differ by R − E ≈ 0.168 at μ = 1, and the
        // comparison's curve carries both reflectances.
        let cmp = sheen_to_fuzz_attenuation_difference(
            SheenParams {
                color_max3: 1.0,
                roughness: 1.0,
            },
            FuzzParams {
                weight: 1.0,
                roughness: 1.0,
            },
        );
        let last = cmp.curve.last().unwrap();
        assert_eq!(last.mu, 1.0);
        assert!((last.fuzz_reflectance - 0.3324).abs() < 1e-3, "{last:?}");
        assert!((last.sheen_reflectance - 0.164).abs() < 1e-3, "{last:?}");
        assert!(
            (last.difference() - (last.fuzz_reflectance - last.sheen_reflectance)).abs() < 1e-15
        );
        assert!(cmp.max_difference >= last.difference());
        assert_eq!(cmp.fuzz_reflectance, "fuzz R (quadrature)");
    }

    #[test]
    fn a_weaker_layer_shows_the_gap_where_the_reflectance_is_largest() {
        // Same reflectance on both sides, w = 0.5·max3: the difference is 0.5·max3·E, largest
        // where E is.
        let cmp = compare_base_attenuation(
            SheenParams {
                color_max3: 1.0,
                roughness: 0.5,
            },
            FuzzParams {
                weight: 0.5,
                roughness: 0.5,
            },
            &SheenAlbedo(AlbedoMethod::Quadrature),
            &SheenAlbedo(AlbedoMethod::Quadrature),
        );
        let e_max = cmp
            .curve
            .iter()
            .map(|p| p.sheen_reflectance)
            .fold(0.0, f64::max);
        assert!((cmp.max_difference - 0.5 * e_max).abs() < 1e-12);
        assert_eq!(cmp.clamps.clamped, 0, "E < 1 everywhere at r = 0.5");
    }
}
