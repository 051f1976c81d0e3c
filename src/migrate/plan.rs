//! Planning: for each material with sheen or fuzz, which conversion applies (or why none does),
//! as edits and notes; then the declarations the document needs. Nothing here writes: the plan
//! is a value that `apply` executes and `render` prints.

pub use super::material::{DocumentPlan, MaterialCx, MaterialPlan, Primitives};
use super::note::{Conversion, Note, Skip};
use super::{fallback, legacy, sheen_to_fuzz, Options};
use crate::asset::Asset;
use crate::edit::Edit;
use crate::layers;

/// Plans the migration of every material of `asset`.
pub fn plan_document(asset: &Asset, options: &Options) -> DocumentPlan {
    let count = asset
        .root()
        .get("materials")
        .and_then(|m| m.as_array())
        .map_or(0, |m| m.len());
    // On the speed paths (--fast, and --roughness identity without --exact: nothing baked to
    // map roughness) materials are planned side by side on the thread pool (the 20,000 of the
    // library in 52 ms instead of 85). Otherwise one after another: planned on both workers,
    // the plans came from both workers' heaps, and the bakes that follow a default migration
    // found less of the memory freed in one heap free in the other (the library's default
    // migration peaked at 108 MiB instead of 101, measured with glibc's allocator).
    let primitives = Primitives::new(asset.root());
    crate::progress::stage("planning materials", count);
    let plan = |i: usize| {
        // A run asked to stop plans no more: what it planned is thrown away (nothing is
        // written once a stop is asked for), so the stop comes within one material.
        if crate::asset::limits::stop_requested() {
            return None;
        }
        crate::progress::advance(1);
        plan_material(asset, i, options, &primitives).map(|mut plan| {
            plan.shrink_to_fit();
            plan
        })
    };
    let side_by_side = options.fast
        || (options.roughness == super::roughness::RoughnessMapping::Identity && !options.exact);
    let mut materials: Vec<MaterialPlan> = if side_by_side {
        use rayon::prelude::*;
        // Collected by index, each plan written into its place: a filtered parallel collect
        // gathers lists per worker and copies them together.
        // The list is then filtered where it lies: `filter_map` on a vector's own iterator
        // collects into its allocation, where `flatten` makes a second list, grown by doubling.
        let planned: Vec<Option<MaterialPlan>> = (0..count).into_par_iter().map(plan).collect();
        #[allow(clippy::filter_map_identity)]
        planned.into_iter().filter_map(|plan| plan).collect()
    } else {
        (0..count).filter_map(plan).collect()
    };
    super::budget::plan(asset, &mut materials, options.budget);
    materials.iter_mut().for_each(|m| {
        m.settle_baked_factors();
        m.shrink_to_fit();
    });
    let declared: Vec<std::borrow::Cow<str>> =
        crate::document::elements(asset.root().get("extensionsUsed"))
            .filter_map(|e| e.as_str())
            .collect();
    let any = |wanted: &[Conversion]| {
        materials
            .iter()
            .any(|m| m.conversions.iter().any(|c| wanted.contains(c)))
    };
    let mut declarations = Vec::new();
    // extensionsRequired is never touched: fuzz is optional, sheen is its fallback.
    let declares = |name: &str| declared.iter().any(|d| d == name);
    if any(&[Conversion::SheenToFuzz]) && !declares(layers::FUZZ) {
        declarations.push(Edit::declare_used(layers::FUZZ));
    }
    if any(&[
        Conversion::FallbackSheen,
        Conversion::RefreshedFallback,
        Conversion::LegacyUpgrade,
    ]) && !declares(layers::SHEEN)
    {
        declarations.push(Edit::declare_used(layers::SHEEN));
    }
    DocumentPlan {
        materials,
        declarations,
    }
}

/// The plan of the materials at `indices` alone, each as [`plan_document`] plans it (roughness
/// textures shared among these materials only), without declarations: what another set of
/// options would do to them, for the verdict's remedies.
pub fn plan_materials(asset: &Asset, indices: &[usize], options: &Options) -> DocumentPlan {
    let primitives = Primitives::new(asset.root());
    let mut materials: Vec<MaterialPlan> = indices
        .iter()
        .filter_map(|&i| plan_material(asset, i, options, &primitives))
        .collect();
    super::budget::plan(asset, &mut materials, options.budget);
    materials.iter_mut().for_each(|m| {
        m.settle_baked_factors();
        m.shrink_to_fit();
    });
    DocumentPlan {
        materials,
        declarations: Vec::new(),
    }
}

/// The plan of material `index`, or `None` when it has neither sheen nor fuzz.
pub fn plan_material(
    asset: &Asset,
    index: usize,
    options: &Options,
    primitives: &Primitives,
) -> Option<MaterialPlan> {
    // The material is read through the index: the document is never built as a value, and a
    // layer object becomes one only where a conversion needs it so (a ratified sheen on its
    // way to fuzz, by far the most common, is read from the index alone).
    let node = asset.root().get("materials")?.get(index)?;
    let layer_nodes = node.get("extensions")?.as_object()?;
    let (sheen, fuzz) = (
        layer_nodes.get(layers::SHEEN),
        layer_nodes.get(layers::FUZZ),
    );
    if sheen.is_none() && fuzz.is_none() {
        return None;
    }
    let mut plan = MaterialPlan::new(index, node);
    for (extension, why) in [
        (layers::UNLIT, Skip::Unlit),
        (layers::SPEC_GLOSS, Skip::SpecularGlossiness),
    ] {
        if layer_nodes.get(extension).is_some() {
            plan.skip(
                why,
                Note::Excluded {
                    extension: extension.to_string(),
                },
            );
            return Some(plan);
        }
    }
    for (name, layer) in [(layers::SHEEN, sheen), (layers::FUZZ, fuzz)] {
        if layer.is_some_and(|v| v.kind() != crate::asset::tape::Kind::Object) {
            plan.skip(
                Skip::Malformed,
                Note::Malformed {
                    extension: name.to_string(),
                },
            );
            return Some(plan);
        }
    }
    let cx = MaterialCx {
        asset,
        index,
        material: node,
        options,
        primitives,
    };
    match (sheen, fuzz) {
        (Some(sheen), None) => {
            // An empty list is made without allocating: the draft is looked for in the index.
            let upgraded = match legacy::legacy_properties(sheen).is_empty() {
                true => None,
                false => legacy::upgrade(&cx, &sheen.to_value(), &mut plan),
            };
            let sheen = upgraded.unwrap_or_else(|| sheen_to_fuzz::Sheen::read(sheen));
            sheen_to_fuzz::convert(&cx, &sheen, &mut plan);
        }
        (None, Some(fuzz)) => fallback::add(&cx, &fuzz.to_value(), &mut plan),
        (Some(sheen), Some(fuzz)) if options.refresh_fallback => {
            fallback::refresh(&cx, &sheen.to_value(), &fuzz.to_value(), &mut plan)
        }
        (Some(_), Some(_)) => plan.skip(Skip::BothPresent, Note::BothPresent),
        (None, None) => unreachable!("checked above"),
    }
    Some(plan)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn materials_planned_side_by_side_come_in_material_order_as_planned_one_by_one() {
        // No roughness textures, so --fast changes nothing but how the plans are made.
        let materials: Vec<serde_json::Value> = (0..500)
            .map(|i| match i % 4 {
                0 => serde_json::json!({"extensions": {"KHR_materials_sheen": {
                    "sheenColorFactor": [0.1 + i as f64 / 1000.0, 0.5, 0.25],
                    "sheenRoughnessFactor": i as f64 / 500.0}}}),
                1 => serde_json::json!({"extensions": {"KHR_materials_fuzz": {"fuzzFactor": 0.5}}}),
                2 => serde_json::json!({"name": "plain"}),
                _ => serde_json::json!({"extensions": {"KHR_materials_sheen": {
                    "sheenFactor": 1.0, "sheenColor": [0.2, 0.3, 0.4]}}}),
            })
            .collect();
        let text = serde_json::json!({"asset": {"version": "2.0"}, "materials": materials});
        let loaded = crate::asset::load_bytes(
            std::path::Path::new("many.gltf"),
            text.to_string().as_bytes(),
        );
        let asset = loaded.asset.expect("a document");
        let one_by_one = plan_document(&asset, &Options::default());
        let side_by_side = plan_document(
            &asset,
            &Options {
                fast: true,
                ..Options::default()
            },
        );
        assert_eq!(one_by_one.materials.len(), 375);
        assert_eq!(side_by_side, one_by_one);
    }
}
