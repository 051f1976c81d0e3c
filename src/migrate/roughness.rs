//! The roughness choice between the sheen and fuzz lobes, in one place.
//!
//! Sheen ("Charlie" distribution, α = r²) and fuzz (an SGGX fibre volume) read roughness on
//! different scales: the same number does not give the same look. [`RoughnessMapping::Fitted`],
//! the default, carries a roughness by appearance: sheen → fuzz writes α(r), the fuzz roughness
//! whose reflectance is closest to the sheen's albedo over the view angle, and fuzz → sheen
//! writes r(α), the other way round (`shading::mapping` defines both, ships them as tables and
//! states their distance from the optimum). [`RoughnessMapping::Identity`] copies the value.
//!
//! A roughness texture cannot carry a non-linear mapping through its factor exactly (the layer
//! reads factor × texel): [`curve`] gives the mapping as a sampled curve for the bake engine to
//! apply to factor × texel, texel by texel, and [`budget`](super::budget) chooses how many such
//! textures a document needs.
//!
//! Every roughness velvet computes is written through [`written`]: rounded to four decimals
//! ([`ROUGHNESS_STEP`]; the tables deviate from the optimum by up to 1e-3, so further digits
//! carry no information, only float noise) and not below [`ROUGHNESS_FLOOR`].

use crate::bake::recipe::Curve;
use crate::shading::mapping;

/// The lowest roughness factor velvet writes. Renderers clamp small sheen roughness values
/// differently before use (some near 1e-6, others up to 0.06), so a lobe below that renders
/// differently in each; at or above 0.07 they all read the value as written. A material whose
/// best match lies below the floor gets the floor, reported with the difference.
pub const ROUGHNESS_FLOOR: f64 = 0.07;

/// The step roughness factors are written in (four decimals).
pub const ROUGHNESS_STEP: f64 = 1e-4;

/// A roughness as velvet writes it: rounded to [`ROUGHNESS_STEP`], within
/// [[`ROUGHNESS_FLOOR`], 1] (NaN reads as 0, so as the floor).
pub fn written(roughness: f64) -> f64 {
    let r = if roughness.is_nan() { 0.0 } else { roughness };
    let rounded = (r.clamp(0.0, 1.0) * 1e4).round() / 1e4;
    rounded.max(ROUGHNESS_FLOOR)
}

/// Which way a roughness value is carried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// sheenRoughnessFactor → fuzzRoughnessFactor.
    SheenToFuzz,
    /// fuzzRoughnessFactor → sheenRoughnessFactor (the fallback sheen).
    FuzzToSheen,
}

/// How a roughness value is carried between the layers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum RoughnessMapping {
    /// By appearance: α(r) one way, r(α) the other (see the module comment).
    #[default]
    Fitted,
    /// The same number on both layers.
    Identity,
}

impl RoughnessMapping {
    /// The mapping's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            RoughnessMapping::Fitted => "fitted",
            RoughnessMapping::Identity => "identity",
        }
    }
}

/// The roughness of the other layer that stands for `roughness` of this one. The fitted mapping
/// reads roughness clamped into [0, 1] (NaN as 0) and returns a value in [0, 1]; the identity
/// returns its input.
pub fn map(roughness: f64, direction: Direction, mapping: RoughnessMapping) -> f64 {
    match (mapping, direction) {
        (RoughnessMapping::Identity, _) => roughness,
        (RoughnessMapping::Fitted, Direction::SheenToFuzz) => {
            mapping::fuzz_roughness_for_sheen(roughness)
        }
        (RoughnessMapping::Fitted, Direction::FuzzToSheen) => {
            mapping::sheen_roughness_for_fuzz(roughness)
        }
    }
}

/// The mapping as a sampled curve on [0, 1], for the bake engine to apply per texel. The fitted
/// curves hold the mapping's own table nodes (j/256), and both interpolate linearly between
/// nodes, so the curve gives [`map`]'s values exactly (the test measures 0 difference); the
/// identity is the line through (0, 0) and (1, 1). Recipes compare curves by their samples as
/// well as their names, so recipes with different tables never compare equal.
pub fn curve(direction: Direction, mapping: RoughnessMapping) -> Curve {
    let built = match (mapping, direction) {
        (RoughnessMapping::Identity, _) => Curve::sampled("identity roughness", &[0.0, 1.0]),
        (RoughnessMapping::Fitted, Direction::SheenToFuzz) => Curve::sampled(
            "fitted sheen→fuzz roughness",
            mapping::fuzz_for_sheen_nodes(),
        ),
        (RoughnessMapping::Fitted, Direction::FuzzToSheen) => Curve::sampled(
            "fitted fuzz→sheen roughness",
            mapping::sheen_for_fuzz_nodes(),
        ),
    };
    built.expect("the mapping tables hold at least two finite samples")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_values_are_rounded_and_floored() {
        assert_eq!(written(0.555_812_345), 0.5558);
        assert_eq!(written(7.6e-8), ROUGHNESS_FLOOR);
        assert_eq!(written(0.0), ROUGHNESS_FLOOR);
        assert_eq!(written(f64::NAN), ROUGHNESS_FLOOR);
        assert_eq!(written(1.5), 1.0);
        assert_eq!(written(0.3).to_string(), "0.3");
        assert_eq!(written(0.1 + 0.2).to_string(), "0.3", "no float noise");
    }

    #[test]
    fn identity_copies_the_value() {
        for r in [0.0, 0.3, 0.5, 1.0] {
            assert_eq!(
                map(r, Direction::SheenToFuzz, RoughnessMapping::Identity),
                r
            );
            assert_eq!(
                map(r, Direction::FuzzToSheen, RoughnessMapping::Identity),
                r
            );
        }
    }

    #[test]
    fn fitted_is_the_default_and_reads_the_shading_tables() {
        assert_eq!(RoughnessMapping::default(), RoughnessMapping::Fitted);
        let fitted = RoughnessMapping::Fitted;
        assert_eq!(
            map(0.5, Direction::SheenToFuzz, fitted),
            mapping::fuzz_roughness_for_sheen(0.5)
        );
        assert_eq!(
            map(0.5, Direction::FuzzToSheen, fitted),
            mapping::sheen_roughness_for_fuzz(0.5)
        );
        // Sheen 0.5 reads as a rougher fuzz (≈ 0.556), fuzz 0.5 as a smoother sheen (≈ 0.418).
        assert!((map(0.5, Direction::SheenToFuzz, fitted) - 0.5558).abs() < 1e-3);
        assert!((map(0.5, Direction::FuzzToSheen, fitted) - 0.4179).abs() < 1e-3);
        for r in [-1.0, f64::NAN, 0.0, 0.25, 1.0, 3.0] {
            for d in [Direction::SheenToFuzz, Direction::FuzzToSheen] {
                let v = map(r, d, fitted);
                assert!((0.0..=1.0).contains(&v), "{r} {d:?}: {v}");
            }
        }
    }

    #[test]
    fn curves_give_the_mapping_exactly() {
        // Sampling error of the curves against map(): 0 over 10001 points, ends included.
        for d in [Direction::SheenToFuzz, Direction::FuzzToSheen] {
            for m in [RoughnessMapping::Fitted, RoughnessMapping::Identity] {
                let c = curve(d, m);
                let worst = (0..=10_000)
                    .map(|i| {
                        let x = i as f64 / 10_000.0;
                        (c.eval(x) - map(x, d, m)).abs()
                    })
                    .fold(0.0, f64::max);
                assert_eq!(worst, 0.0, "{d:?} {m:?}");
            }
        }
        assert_eq!(
            curve(Direction::SheenToFuzz, RoughnessMapping::Fitted).len(),
            257
        );
        assert_ne!(
            curve(Direction::SheenToFuzz, RoughnessMapping::Fitted),
            curve(Direction::FuzzToSheen, RoughnessMapping::Fitted)
        );
        assert_eq!(
            curve(Direction::SheenToFuzz, RoughnessMapping::Identity),
            curve(Direction::FuzzToSheen, RoughnessMapping::Identity)
        );
    }
}
