//! The plan's verdict, measured: for each material a sheet shows, the material as authored
//! (column 0) against the material as written (column 1) at each swatch, the textures reduced
//! as the sheets reduce them ([`super::material`]), rendered as small spheres ([`SPHERE`]
//! pixels across, at the sheets' viewing angle: ꟻLIP's pixels per degree scaled with the size)
//! in the white furnace and under the directional light, with the sheets' own shading
//! ([`super::shade`] at [`Quality::Verdict`]) and ꟻLIP pooled as the sheets pool it (the 99th
//! percentile over the sphere, the largest over the swatches). The furnace's value decides the
//! label by the thresholds of [`crate::migrate::verdict`], as the sheets' did.
//!
//! This module owns that measurement and writes it into migrate's plan ([`judge`]): the
//! preview lies above migrate (it draws from migrate's plan), so the plan's verdict is measured
//! here, right after planning, by every command that plans (migrate, preview). Each distinct
//! set of material values is measured once per document; each measurement depends on its
//! values alone, so the verdicts do not depend on the thread count. A "visible" material that
//! a migration changes is planned again, alone, with the flags that could bring it closer
//! (`--exact`, `--roughness-budget exact`, both), and the best verdict one reaches is its
//! remedy. The default takes a remedy that brings the material to "close" or "same" while the
//! new textures it bakes fit the run's [`crate::migrate::verdict::CloserBudget`] (per file, in
//! material order): the material's plan becomes that plan, with a note saying so; otherwise
//! the material keeps its plan and gets a warning naming the remedy and, when the budget was
//! what stopped it, the size. This choice is made here, not in migrate's planner, because only
//! the renderer can tell which plan looks closer.

use super::material::{self, columns, Material};
use super::shade::{render_sphere, Light, Look, Quality, Shaded};
use super::sheet;
use crate::asset::Asset;
use crate::migrate::budget::Budget;
use crate::migrate::verdict::{BeyondBudget, Label, Remedy, Verdict};
use crate::migrate::{DocumentPlan, MaterialPlan, Note, Options};
use rayon::prelude::*;
use std::collections::HashMap;

/// The verdict's sphere, in pixels across: a quarter of a sheet's, at a sixteenth of the
/// pixels.
pub const SPHERE: usize = 24;

/// The step every value of a look is rounded to before it is measured (colours and weights
/// linear, roughness): materials whose values differ by less share one measurement. A step
/// (0.0039) is about one 8-bit code of mid-grey linear light and 0.4 of migrate's default
/// roughness budget (0.01, itself a difference chosen as one no one sees, docs/migrate.md),
/// and a library whose every factor differs by a little is measured in a fraction of the time:
/// the 20,000-material library's verdicts take 2.3 s of processor time (6.3 s at a step of
/// 1/512, about four times that at 1/1024). The verdict is the rounded look's, so it is still
/// a function of the material's own values.
pub const VALUE_STEP: f64 = 1.0 / 256.0;

/// `look` with every value rounded to [`VALUE_STEP`].
pub fn rounded(look: Look) -> Look {
    use super::shade::Layer;
    let r = |v: f64| (v / VALUE_STEP).round() * VALUE_STEP;
    Look {
        base: look.base.map(r),
        base_metallic: r(look.base_metallic),
        base_roughness: r(look.base_roughness),
        layer: match look.layer {
            Layer::None => Layer::None,
            Layer::Sheen { color, roughness } => Layer::Sheen {
                color: color.map(r),
                roughness: r(roughness),
            },
            Layer::Fuzz {
                color,
                weight,
                roughness,
            } => Layer::Fuzz {
                color: color.map(r),
                weight: r(weight),
                roughness: r(roughness),
            },
        },
    }
}

/// The pairs of looks as a key: every value's bits, each layer behind its kind. Two keys are
/// equal exactly when the looks are (the values are rounded already, see [`rounded`]).
fn key_of(pairs: &[(Look, Look)]) -> Vec<u64> {
    use super::shade::Layer;
    let mut key = Vec::with_capacity(pairs.len() * 2 * 10);
    for look in pairs.iter().flat_map(|(a, b)| [a, b]) {
        key.extend(look.base.map(f64::to_bits));
        key.extend([look.base_metallic.to_bits(), look.base_roughness.to_bits()]);
        match look.layer {
            Layer::None => key.push(0),
            Layer::Sheen { color, roughness } => {
                key.push(1);
                key.extend(color.map(f64::to_bits));
                key.push(roughness.to_bits());
            }
            Layer::Fuzz {
                color,
                weight,
                roughness,
            } => {
                key.push(2);
                key.extend(color.map(f64::to_bits));
                key.extend([weight.to_bits(), roughness.to_bits()]);
            }
        }
    }
    key
}

/// ꟻLIP's pixels per degree for the verdict's spheres: the default (a sheet's) scaled with the
/// sphere, so that a small sphere subtends the angle a sheet's does and the metric's filters
/// cover the same part of it.
pub fn pixels_per_degree() -> f32 {
    nv_flip::DEFAULT_PIXELS_PER_DEGREE * SPHERE as f32 / sheet::SPHERE as f32
}

/// The looks a verdict compares at each swatch: the material as authored and as written, each
/// [`rounded`].
pub fn pairs(material: &Material) -> Vec<(Look, Look)> {
    material
        .swatches
        .iter()
        .filter_map(|s| {
            let cols = columns(material, s);
            Some((rounded(cols.first()?.look), rounded(cols.get(1)?.look)))
        })
        .collect()
}

/// The verdict on the pairs of looks of one material.
pub fn measure_pairs(pairs: &[(Look, Look)]) -> Verdict {
    let mut flips = [0.0f64; 2];
    for (authored, written) in pairs {
        let (a, b) = (
            Shaded::with_quality(*authored, Quality::Verdict),
            Shaded::with_quality(*written, Quality::Verdict),
        );
        for (slot, light) in [Light::Furnace, Light::Directional].into_iter().enumerate() {
            let (sphere_a, sphere_b) = (
                render_sphere(&a, light, SPHERE),
                render_sphere(&b, light, SPHERE),
            );
            // The outline is the same for every look and light.
            let on_sphere: Vec<bool> = sphere_a.coverage.iter().map(|&c| c > 0.5).collect();
            let flip = sheet::flip_p99_at(
                &sheet::sphere_codes_clamped(&sphere_a),
                &sheet::sphere_codes_clamped(&sphere_b),
                &on_sphere,
                pixels_per_degree(),
            );
            flips[slot] = flips[slot].max(flip);
        }
    }
    Verdict::new(flips[0], flips[1])
}

/// A material's looks to compare (authored, written), and the key of their values' bits.
type KeyedPairs = (Vec<u64>, Vec<(Look, Look)>);

/// The verdict of each of `materials`, each distinct set of looks measured once (in parallel).
pub fn measure_all(materials: &[Material]) -> Vec<Verdict> {
    let keys: Vec<KeyedPairs> = materials
        .par_iter()
        .map(|m| {
            let pairs = pairs(m);
            (key_of(&pairs), pairs)
        })
        .collect();
    let mut first_of: HashMap<&[u64], usize> = HashMap::new();
    let mut distinct: Vec<usize> = Vec::new();
    let slot: Vec<usize> = keys
        .iter()
        .enumerate()
        .map(|(i, (key, _))| {
            *first_of.entry(key.as_slice()).or_insert_with(|| {
                distinct.push(i);
                distinct.len() - 1
            })
        })
        .collect();
    // A stop (SIGINT, SIGTERM) ends the measuring at once: what is left reads 0, and every
    // caller checks for the stop before it uses a verdict (see [`judge`]).
    crate::progress::stage("judging appearance", distinct.len());
    let verdicts: Vec<Verdict> = distinct
        .par_iter()
        .inspect(|_| crate::progress::advance(1))
        .map(|&i| match crate::output::interrupt::requested() {
            Some(_) => Verdict::new(0.0, 0.0),
            None => measure_pairs(&keys[i].1),
        })
        .collect();
    slot.into_iter().map(|s| verdicts[s]).collect()
}

/// The flags that could bring a material closer, beyond `options`, with the options they give.
fn remedies(options: &Options) -> Vec<(&'static str, Options)> {
    let mut out = Vec::new();
    if !options.exact {
        out.push((
            "--exact",
            Options {
                exact: true,
                ..options.clone()
            },
        ));
    }
    if options.budget != Budget::Exact {
        out.push((
            "--roughness-budget exact",
            Options {
                budget: Budget::Exact,
                ..options.clone()
            },
        ));
    }
    if out.len() == 2 {
        out.push((
            "--exact --roughness-budget exact",
            Options {
                exact: true,
                budget: Budget::Exact,
                ..options.clone()
            },
        ));
    }
    out
}

/// Measures the verdict of every material of `plan` a sheet shows, writes it into the plan
/// (and a warning on each "visible" material the migration changes, with the run that would
/// bring it closer when one would), and returns the materials as the sheets show them, in
/// document order, each with its verdict. A stop (SIGINT, SIGTERM) during the measuring ends it
/// within a measurement: the verdicts are then not to be used, and the callers, which check
/// for the stop right after, use none.
pub fn judge(asset: &Asset, plan: &mut DocumentPlan, options: &Options) -> Vec<Material> {
    let cache = material::ImageCache::default();
    let mut materials = material::materials_with(asset, plan, options.roughness, &cache);
    let verdicts = measure_all(&materials);
    let mut at: HashMap<usize, usize> = HashMap::new();
    for (k, m) in plan.materials.iter().enumerate() {
        at.entry(m.index).or_insert(k);
    }
    let mut visible: Vec<usize> = Vec::new();
    for (m, v) in materials.iter_mut().zip(verdicts) {
        m.verdict = Some(v);
        if let Some(&k) = at.get(&m.index) {
            plan.materials[k].verdict = Some(v);
            if v.label == Label::Visible && plan.materials[k].migrated() {
                visible.push(k);
            }
        }
    }
    if visible.is_empty() || crate::output::interrupt::requested().is_some() {
        return materials;
    }
    // Each visible material planned again, alone, with each remedy's flags; a remedy that
    // leaves its plan as it was is not one for it.
    let indices: Vec<usize> = visible.iter().map(|&k| plan.materials[k].index).collect();
    let mut tried: Vec<Vec<String>> = vec![Vec::new(); visible.len()];
    let mut best: Vec<Option<(Remedy, MaterialPlan, Material)>> = vec![None; visible.len()];
    for (flags, alternative) in remedies(options) {
        let other = crate::migrate::plan::plan_materials(asset, &indices, &alternative);
        let read = material::materials_with(asset, &other, alternative.roughness, &cache);
        let measured = measure_all(&read);
        for (j, &k) in visible.iter().enumerate() {
            let current = &plan.materials[k];
            let Some(changed) = other.materials.iter().find(|p| p.index == current.index) else {
                continue;
            };
            if changed.edits == current.edits && changed.bakes == current.bakes {
                continue;
            }
            tried[j].push(flags.to_string());
            let Some((shown, v)) = read
                .iter()
                .zip(&measured)
                .find(|(m, _)| m.index == current.index)
            else {
                continue;
            };
            let better = match &best[j] {
                Some((b, _, _)) => (v.label, v.flip) < (b.verdict.label, b.verdict.flip),
                None => v.label < Label::Visible,
            };
            if better {
                let mut shown = shown.clone();
                shown.verdict = Some(*v);
                best[j] = Some((
                    Remedy {
                        flags: flags.to_string(),
                        verdict: *v,
                    },
                    changed.clone(),
                    shown,
                ));
            }
        }
    }
    // The default takes each remedy, in material order, while the new textures fit the budget.
    let mut left = options.closer_budget.0;
    for ((k, tried), best) in visible.into_iter().zip(tried).zip(best) {
        let verdict = plan.materials[k].verdict.expect("measured above");
        let mut beyond_budget = None;
        if let Some((remedy, taken, shown)) = &best {
            match new_texture_bytes(asset, &plan.materials[k], taken) {
                Some(bytes) if bytes <= left => {
                    left -= bytes;
                    let mut taken = taken.clone();
                    taken.verdict = Some(remedy.verdict);
                    taken.notes.push(Note::CloserPlanTaken {
                        flags: remedy.flags.clone(),
                        before: verdict,
                        after: remedy.verdict,
                        bytes,
                    });
                    if let Some(m) = materials.iter_mut().find(|m| m.index == taken.index) {
                        *m = shown.clone();
                    }
                    plan.materials[k] = taken;
                    continue;
                }
                Some(bytes) => beyond_budget = Some(BeyondBudget { bytes, left }),
                None => {}
            }
        }
        plan.materials[k].notes.push(Note::VisibleDifference {
            verdict,
            remedy: best.map(|(r, _, _)| r),
            tried,
            beyond_budget,
        });
    }
    materials
}

/// The uncompressed size (width × height × 4 bytes) of the textures `taken` bakes that
/// `current` does not, from the source images' headers; `None` when a header cannot be read
/// (the size cannot be bounded, so the plan is not taken).
fn new_texture_bytes(asset: &Asset, current: &MaterialPlan, taken: &MaterialPlan) -> Option<u64> {
    let mut bytes = 0u64;
    for bake in taken.bakes.iter().filter(|b| !current.bakes.contains(b)) {
        let (_, image) = *bake.sources.first()?;
        let header = asset.image_header(image).ok()?;
        // Saturating: a header may claim any size up to 2³² a side.
        let texture = (u64::from(header.width) * u64::from(header.height)).saturating_mul(4);
        bytes = bytes.saturating_add(texture);
    }
    Some(bytes)
}
