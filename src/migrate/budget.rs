//! The texture plan of mapped roughness textures, chosen within an error budget.
//!
//! A roughness texture read through the fitted mapping holds, per texel t, the target α(f·t)
//! for the material's factor f (see [`roughness`]); the layer reads
//! factor × texel. Three plans can give it, from cheapest to dearest:
//!
//! - [`TexturePlan::Shared`]: one mapped texture per source texture, g(t) = α(t), read by every
//!   material with that texture, each carrying its difference by its factor: f'·g(t) ≈ α(f·t)
//!   (a separable fit; f' is the minimax factor over the codes present).
//! - [`TexturePlan::Grouped`]: one texture α(f₀·t) shared by the materials whose factors f give
//!   curves within the budget of it with their own factor f' (greedy over sorted factors).
//! - [`TexturePlan::Exact`]: one bake per material, α(f·t) itself (factor 1), exact to the
//!   nearest code.
//!
//! The error of a plan is the worst case over the codes present in the source channel (every
//! texel's value occurs among them) of |f' · code'/max − α(f · code/max)|, where code' is the
//! code the bake writes (the mapped value rounded to the nearest code, as the bake engine
//! rounds it) and f' the factor written (rounded as velvet writes roughness). So the error
//! reported is the error a reader of the output measures from its decoded texels. The cheapest
//! plan within the budget is taken; a material no plan brings within it gets the exact bake,
//! reported with how far over it is. [`Budget::Exact`] takes the exact bake for every material.
//!
//! Planning decodes the source images of mapped roughness textures (the codes present per
//! channel), only when some material maps one; each texture's materials are planned in
//! parallel with the others'.

use super::material::MaterialPlan;
use super::note::Note;
use super::roughness;
use super::textures::Contents;
use crate::asset::Asset;
use crate::bake::{codec, srgb, Channel, Curve, Pixels};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The default budget: the largest roughness difference a plan may leave, in roughness units.
/// 0.01 is 2.5 codes of an 8-bit roughness texture. Measured by appearance, moving the fuzz
/// roughness 0.01 from the mapping's α(r) adds at most 0.0023 to the cosine-weighted rms
/// reflectance difference the mapping itself leaves (never below 0.0091), a quarter of it;
/// 0.03 would add up to 0.013 (docs/shading.md, "The roughness budget").
pub const DEFAULT_BUDGET: f64 = 0.01;

/// How far a planned texture may be from the exact target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Budget {
    /// The cheapest plan whose worst-case roughness difference is at most this.
    Within(f64),
    /// An exact bake per material (to the nearest code).
    Exact,
}

impl Default for Budget {
    fn default() -> Self {
        Budget::Within(DEFAULT_BUDGET)
    }
}

impl Budget {
    /// The budget as a number (`None` for the exact setting).
    pub fn limit(self) -> Option<f64> {
        match self {
            Budget::Within(b) => Some(b),
            Budget::Exact => None,
        }
    }
}

impl std::str::FromStr for Budget {
    type Err = String;

    /// `exact`, or a roughness difference in [0, 1].
    fn from_str(s: &str) -> Result<Budget, String> {
        if s.eq_ignore_ascii_case("exact") {
            return Ok(Budget::Exact);
        }
        match s.parse::<f64>() {
            Ok(b) if (0.0..=1.0).contains(&b) => Ok(Budget::Within(b)),
            _ => Err(format!(
                "'{s}' is not a roughness difference in [0, 1] or 'exact'"
            )),
        }
    }
}

pub use super::note::TexturePlan;

/// The codes one channel of an image holds, each once, and its largest code.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Codes {
    pub max: u32,
    pub present: Vec<u32>,
}

impl Codes {
    /// The codes of `channel` over every texel of `pixels` (alpha of an image without alpha
    /// reads as opaque, as the bake engine reads it).
    pub fn of(pixels: &Pixels, channel: Channel) -> Codes {
        let max = pixels.depth().max_code();
        let mut seen = vec![false; max as usize + 1];
        for y in 0..pixels.height() {
            for x in 0..pixels.width() {
                seen[pixels.code(x, y, channel) as usize] = true;
            }
        }
        let present = (0..=max).filter(|&c| seen[c as usize]).collect();
        Codes { max, present }
    }

    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        let max = f64::from(self.max);
        self.present.iter().map(move |&c| f64::from(c) / max)
    }
}

/// Per code present: the value the baked texture holds (`texture` at baked × code, rounded to
/// a code as the bake engine rounds it, decoded) and the target (`mapping` at target × code).
fn texture_and_target(
    codes: &Codes,
    texture: &Curve,
    mapping: &Curve,
    baked: f64,
    target: f64,
) -> Vec<(f64, f64)> {
    let max = f64::from(codes.max);
    codes
        .values()
        .map(|x| {
            let code = srgb::quantise(texture.eval(baked * x), codes.max);
            (f64::from(code) / max, mapping.eval(target * x))
        })
        .collect()
}

/// The largest |written · texture − target| over `pairs`.
fn worst(pairs: &[(f64, f64)], written: f64) -> f64 {
    largest(pairs.len(), |i| (written * pairs[i].0 - pairs[i].1).abs())
}

/// The largest of `term(0..n)` and 0, NaN terms skipped: the value `fold(0.0, f64::max)`
/// gives. The minimax searches spend most of the planner's time here. `f64::max` is a
/// five-instruction NaN-aware sequence in one chain of dependent steps; a plain comparison
/// (false for NaN, so NaN is skipped alike) is one instruction, and four running maxima over
/// interleaved terms break the chain. The value is the same: the largest of a set does not
/// depend on the order it is taken in, and the terms are absolute values (no −0).
#[inline]
fn largest(n: usize, term: impl Fn(usize) -> f64) -> f64 {
    let mut lanes = [0.0f64; 4];
    let whole = n - n % 4;
    for i in (0..whole).step_by(4) {
        for (k, lane) in lanes.iter_mut().enumerate() {
            let d = term(i + k);
            if d > *lane {
                *lane = d;
            }
        }
    }
    for i in whole..n {
        let d = term(i);
        if d > lanes[0] {
            lanes[0] = d;
        }
    }
    lanes
        .into_iter()
        .fold(0.0, |m, d| if d > m { d } else { m })
}

/// The factor, as velvet writes it (rounded, not below the floor, at most 1), that minimises
/// the worst difference over `pairs`, with that difference.
fn best_factor(pairs: &[(f64, f64)]) -> (f64, f64) {
    let step = roughness::ROUGHNESS_STEP;
    let centre = roughness::written(minimax(|w| worst(pairs, w), 60));
    [centre - step, centre, centre + step]
        .into_iter()
        .map(roughness::written)
        .map(|w| (w, worst(pairs, w)))
        .fold(
            (1.0, f64::INFINITY),
            |best, c| if c.1 < best.1 { c } else { best },
        )
}

/// The minimum on [0, 1] of a convex function, by ternary search.
fn minimax(f: impl Fn(f64) -> f64, iterations: usize) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..iterations {
        let a = lo + (hi - lo) / 3.0;
        let b = hi - (hi - lo) / 3.0;
        if f(a) <= f(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    (lo + hi) / 2.0
}

/// How many factors a joint fit follows at most.
const FIT_FACTORS: usize = 33;

/// The shared texture's curve g for a source texture read by materials with `factors`: a joint
/// minimax fit of f'·g(t) ≈ α(f·t) over the codes present, by alternation (each factor's
/// best f' for g, then each code's best g for those f'), started from g = α, over `factors`
/// (sorted). Sampled at every
/// code of the channel's depth (codes not present keep α), so the bake reads g exactly there.
fn fit_shared(codes: &Codes, mapping: &Curve, factors: &[f64]) -> Curve {
    // At most FIT_FACTORS factors, evenly spread over the sorted ones (the smallest and largest
    // included): the fit follows the extremes, and every material is checked afterwards.
    let n = factors.len();
    let factors: Vec<f64> = if n <= FIT_FACTORS {
        factors.to_vec()
    } else {
        (0..FIT_FACTORS)
            .map(|k| factors[k * (n - 1) / (FIT_FACTORS - 1)])
            .collect()
    };
    let max = f64::from(codes.max);
    let mut g: Vec<f64> = (0..=codes.max)
        .map(|j| mapping.eval(f64::from(j) / max))
        .collect();
    let targets: Vec<Vec<f64>> = factors
        .iter()
        .map(|&f| codes.values().map(|x| mapping.eval(f * x)).collect())
        .collect();
    // The targets by code (each code's across the factors) for the codes' own searches.
    let by_code: Vec<Vec<f64>> = (0..codes.present.len())
        .map(|k| targets.iter().map(|a| a[k]).collect())
        .collect();
    for _ in 0..3 {
        let stored: Vec<f64> = codes
            .present
            .iter()
            .map(|&c| f64::from(srgb::quantise(g[c as usize], codes.max)) / max)
            .collect();
        let scales: Vec<f64> = targets
            .iter()
            .map(|a| {
                minimax(
                    |w| largest(stored.len().min(a.len()), |i| (w * stored[i] - a[i]).abs()),
                    50,
                )
            })
            .collect();
        for (k, &c) in codes.present.iter().enumerate() {
            let column = &by_code[k];
            g[c as usize] = minimax(
                |v| largest(scales.len(), |f| (scales[f] * v - column[f]).abs()),
                50,
            );
        }
    }
    Curve::sampled(&format!("{} (shared fit)", mapping.name()), &g)
        .expect("every code's sample is finite")
}

/// A plan for one slot: the factor baked into the texels, the factor written (`None`: the
/// identity), and the worst-case difference.
#[derive(Debug, Clone, PartialEq)]
struct Choice {
    plan: TexturePlan,
    /// The curve the texture is baked through (`None`: the mapping itself).
    curve: Option<Curve>,
    baked: f64,
    written: Option<f64>,
    error: f64,
}

fn over_sources(
    sources: &[Codes],
    texture: &Curve,
    mapping: &Curve,
    baked: f64,
    target: f64,
) -> Vec<(f64, f64)> {
    sources
        .iter()
        .flat_map(|codes| texture_and_target(codes, texture, mapping, baked, target))
        .collect()
}

fn exact(sources: &[Codes], curve: &Curve, f: f64) -> Choice {
    let pairs = over_sources(sources, curve, curve, f, f);
    Choice {
        plan: TexturePlan::Exact,
        curve: None,
        baked: f,
        written: None,
        error: worst(&pairs, 1.0),
    }
}

/// The mapped roughness slot `bake` of material `material`.
struct Slot {
    material: usize,
    bake: usize,
    factor: f64,
}

/// Chooses the texture plan of every mapped roughness texture of a document's materials: sets
/// each such bake's baked factor and written factor, and adds a note with its error.
pub fn plan(asset: &Asset, materials: &mut [MaterialPlan], budget: Budget) {
    // Slots by (texture, channel, mapping): they can share a mapped texture.
    let mut groups: BTreeMap<(usize, u8, String), Vec<Slot>> = BTreeMap::new();
    for (m, material) in materials.iter().enumerate() {
        for (b, bake) in material.bakes.iter().enumerate() {
            if let Contents::Roughness {
                channel,
                factor,
                curve: Some(curve),
            } = &bake.contents
            {
                groups
                    .entry((bake.texture, *channel as u8, curve.name().to_string()))
                    .or_default()
                    .push(Slot {
                        material: m,
                        bake: b,
                        factor: *factor,
                    });
            }
        }
    }
    // Each group is planned on its own (in parallel): its images decoded for the codes present,
    // then its choices made. A group whose image cannot be decoded keeps its exact bakes; the
    // bake itself then fails on that image and says why.
    let groups: Vec<Vec<Slot>> = groups.into_values().collect();
    let planned: Vec<Option<Vec<Choice>>> = groups
        .par_iter()
        .map(|slots| {
            let first = &materials[slots[0].material].bakes[slots[0].bake];
            let Contents::Roughness {
                channel,
                curve: Some(curve),
                ..
            } = &first.contents
            else {
                return None;
            };
            let sources: Vec<Codes> = first
                .sources
                .iter()
                .map(|(_, image)| codes_of(asset, *image, *channel))
                .collect::<Result<_, _>>()
                .ok()?;
            choose(slots, &sources, curve, budget)
        })
        .collect();
    for (slots, choices) in groups.iter().zip(planned) {
        let Some(choices) = choices else { continue };
        for (slot, choice) in slots.iter().zip(choices) {
            let material = &mut materials[slot.material];
            let bake = &mut material.bakes[slot.bake];
            if let Contents::Roughness { factor, curve, .. } = &mut bake.contents {
                *factor = choice.baked;
                if let Some(fitted) = &choice.curve {
                    *curve = Some(fitted.clone());
                }
            }
            bake.written_factor = choice.written;
            let property = bake.texture_key.to_string();
            let factor_key = bake.factor_key.to_string();
            material.notes.push(Note::RoughnessPlan {
                property,
                plan: choice.plan,
                factor_key,
                factor: choice.written.unwrap_or(1.0),
                max_error: choice.error,
                budget: budget.limit(),
            });
        }
    }
}

fn codes_of(asset: &Asset, image: usize, channel: Channel) -> Result<Codes, String> {
    let bytes = asset.image_bytes(image).map_err(|d| d.message)?;
    let (pixels, _) = codec::decode_within(
        &bytes,
        asset.options.max_image_pixels,
        asset.options.max_memory,
    )
    .map_err(|e| e.to_string())?;
    Ok(Codes::of(&pixels, channel))
}

/// The choice for each slot of one (texture, channel, mapping) group, in the slots' order;
/// `None` once the run is asked to stop (the fitting of a library's groups takes most of a
/// second, and what it would choose is thrown away: nothing is written after a stop).
fn choose(slots: &[Slot], sources: &[Codes], curve: &Curve, budget: Budget) -> Option<Vec<Choice>> {
    let stopped = crate::asset::limits::stop_requested;
    let Budget::Within(limit) = budget else {
        return Some(
            slots
                .iter()
                .map(|s| exact(sources, curve, s.factor))
                .collect(),
        );
    };
    let mut out: Vec<Option<Choice>> = vec![None; slots.len()];
    // Shared: one texture for every factor, its curve fitted jointly to them (one source
    // depth only; otherwise the mapping itself at factor 1).
    let mut factors: Vec<f64> = slots.iter().map(|s| s.factor).collect();
    factors.sort_by(f64::total_cmp);
    factors.dedup();
    let shared = match sources {
        [codes] => fit_shared(codes, curve, &factors),
        _ => curve.clone(),
    };
    let mut pending = Vec::new();
    for (i, slot) in slots.iter().enumerate() {
        if stopped() {
            return None;
        }
        let pairs = over_sources(sources, &shared, curve, 1.0, slot.factor);
        let (written, error) = best_factor(&pairs);
        if error <= limit {
            out[i] = Some(Choice {
                plan: TexturePlan::Shared,
                curve: Some(shared.clone()),
                baked: 1.0,
                written: Some(written),
                error,
            });
        } else {
            pending.push(i);
        }
    }
    // Grouped: runs of sorted factors, each run as long as one fitted texture serves it
    // (found by doubling, then bisecting, the run's length).
    pending.sort_by(|&a, &b| {
        slots[a]
            .factor
            .total_cmp(&slots[b].factor)
            .then(slots[a].material.cmp(&slots[b].material))
    });
    let group = |run: &[usize]| -> Option<Vec<Choice>> {
        if stopped() {
            return None;
        }
        let mut factors: Vec<f64> = run.iter().map(|&i| slots[i].factor).collect();
        factors.dedup();
        let (texture, baked) = match sources {
            [codes] => (fit_shared(codes, curve, &factors), 1.0),
            _ => (curve.clone(), factors[0]),
        };
        run.iter()
            .map(|&i| {
                let pairs = over_sources(sources, &texture, curve, baked, slots[i].factor);
                let (written, error) = best_factor(&pairs);
                (error <= limit).then(|| Choice {
                    plan: TexturePlan::Grouped,
                    curve: (baked == 1.0).then(|| texture.clone()),
                    baked,
                    written: Some(written),
                    error,
                })
            })
            .collect()
    };
    let mut k = 0;
    while k < pending.len() {
        if stopped() {
            return None;
        }
        let rest = &pending[k..];
        let (mut good, mut good_choices) = (1, None);
        let mut bad = None;
        let mut len = 2;
        while len <= rest.len() {
            match group(&rest[..len]) {
                Some(c) => {
                    good = len;
                    good_choices = Some(c);
                    len *= 2;
                }
                None => {
                    bad = Some(len);
                    break;
                }
            }
        }
        if bad.is_none() && good < rest.len() {
            match group(rest) {
                Some(c) => {
                    good = rest.len();
                    good_choices = Some(c);
                }
                None => bad = Some(rest.len()),
            }
        }
        if let Some(mut hi) = bad {
            while hi - good > 1 {
                let mid = (good + hi) / 2;
                match group(&rest[..mid]) {
                    Some(c) => {
                        good = mid;
                        good_choices = Some(c);
                    }
                    None => hi = mid,
                }
            }
        }
        match good_choices {
            Some(choices) => {
                for (&i, choice) in rest[..good].iter().zip(choices) {
                    out[i] = Some(choice);
                }
                k += good;
            }
            None => {
                out[rest[0]] = Some(exact(sources, curve, slots[rest[0]].factor));
                k += 1;
            }
        }
    }
    Some(
        out.into_iter()
            .map(|c| c.expect("every slot gets a choice"))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::migrate::roughness::{Direction, RoughnessMapping};

    fn every_code() -> Vec<Codes> {
        vec![Codes {
            max: 255,
            present: (0..=255).collect(),
        }]
    }

    fn slots(factors: &[f64]) -> Vec<Slot> {
        factors
            .iter()
            .enumerate()
            .map(|(i, &f)| Slot {
                material: i,
                bake: 0,
                factor: f,
            })
            .collect()
    }

    #[test]
    fn budgets_parse_from_numbers_and_exact() {
        assert_eq!("exact".parse::<Budget>(), Ok(Budget::Exact));
        assert_eq!("0.02".parse::<Budget>(), Ok(Budget::Within(0.02)));
        assert!("-1".parse::<Budget>().is_err());
        assert!("lots".parse::<Budget>().is_err());
        assert_eq!(Budget::default(), Budget::Within(DEFAULT_BUDGET));
    }

    /// A fabric-like roughness texture: codes 192–255 (roughness 0.75–1).
    fn fabric_codes() -> Vec<Codes> {
        vec![Codes {
            max: 255,
            present: (192..=255).collect(),
        }]
    }

    #[test]
    fn nearby_factors_share_one_fitted_texture_within_the_default_budget() {
        let curve = roughness::curve(Direction::SheenToFuzz, RoughnessMapping::Fitted);
        let factors: Vec<f64> = (0..=30).map(|i| 0.3 + 0.01 * f64::from(i)).collect();
        let choices = choose(&slots(&factors), &fabric_codes(), &curve, Budget::default())
            .expect("no stop was asked for");
        for (f, c) in factors.iter().zip(&choices) {
            assert_eq!(c.plan, TexturePlan::Shared, "factor {f}: {c:?}");
            assert!(c.error <= DEFAULT_BUDGET, "{c:?}");
            assert_eq!(c.baked, 1.0);
            assert_eq!(c.curve, choices[0].curve, "one texture for all");
        }
        // The joint fit does better than the mapping itself at factor 1 for every factor.
        let worst_fitted = choices.iter().map(|c| c.error).fold(0.0, f64::max);
        let worst_plain = factors
            .iter()
            .map(|&f| best_factor(&over_sources(&fabric_codes(), &curve, &curve, 1.0, f)).1)
            .fold(0.0, f64::max);
        assert!(worst_fitted < worst_plain, "{worst_fitted} {worst_plain}");
    }

    #[test]
    fn factors_too_far_apart_for_one_texture_are_grouped_or_baked() {
        let curve = roughness::curve(Direction::SheenToFuzz, RoughnessMapping::Fitted);
        let factors: Vec<f64> = (0..=85).map(|i| 0.12 + 0.01 * f64::from(i)).collect();
        let choices = choose(&slots(&factors), &every_code(), &curve, Budget::default())
            .expect("no stop was asked for");
        assert!(
            choices.iter().all(|c| c.error <= DEFAULT_BUDGET),
            "{choices:?}"
        );
        assert!(choices.iter().any(|c| c.plan != TexturePlan::Shared));
        let mut textures: Vec<(Option<&Curve>, u64)> = choices
            .iter()
            .map(|c| (c.curve.as_ref(), c.baked.to_bits()))
            .collect();
        textures.sort();
        textures.dedup();
        assert!(
            textures.len() < factors.len() / 2,
            "{} textures",
            textures.len()
        );
    }

    #[test]
    fn the_exact_setting_bakes_each_factor_to_the_nearest_code() {
        let curve = roughness::curve(Direction::SheenToFuzz, RoughnessMapping::Fitted);
        let choices = choose(&slots(&[0.4, 0.9]), &every_code(), &curve, Budget::Exact)
            .expect("no stop was asked for");
        for (c, f) in choices.iter().zip([0.4, 0.9]) {
            assert_eq!((c.plan, c.baked, c.written), (TexturePlan::Exact, f, None));
            assert!(c.error <= 0.5 / 255.0 + 1e-12, "{c:?}");
        }
    }

    #[test]
    fn a_zero_budget_refuses_the_shared_texture() {
        let curve = roughness::curve(Direction::SheenToFuzz, RoughnessMapping::Fitted);
        let choices = choose(
            &slots(&[0.4, 0.7]),
            &every_code(),
            &curve,
            Budget::Within(0.0),
        )
        .expect("no stop was asked for");
        assert!(
            choices.iter().all(|c| c.plan == TexturePlan::Exact),
            "{choices:?}"
        );
    }
}
