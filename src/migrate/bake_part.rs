//! The part of a document that a migration's bakes are applied to, so that a library of
//! thousands of materials is not built as one value to add a few textures to it.
//!
//! A bake adds images and textures, points textureInfos at them and sets factors. Of the
//! document it reads and changes only the top-level members other than the scene's geometry,
//! and in the materials its slots name, the layer objects it bakes. [`BakePart`] holds those
//! as values: the top-level members whole, and of each baked material only its places (the
//! layer objects the bake's slots name and the values the migration's edits set, with the
//! objects on the way to them; every other material is `null`). It takes the migration's
//! edits of those places, and after the bake gives back the edits that write the result into
//! the source text as splices: each place and each member that changed, replaced whole
//! ([`Edit::Replace`]: the numbers the bake left keep their spelling). The migration's edits of
//! every other material are spliced as they are.
//!
//! Dropping what a bake left unreferenced needs the whole document (a texture may be named by
//! a material outside the part, and dropping renumbers every reference), so the caller does
//! not use a part whose bake dropped anything. A migration drops nothing in practice: the
//! sheen it keeps still names the textures its bakes read.

use std::collections::{BTreeMap, BTreeSet};

use serde_json::{Map, Value};

use crate::asset::tape::Node;
use crate::asset::{pointer, Asset};
use crate::bake::plan::BakePlan;
use crate::edit::Edit;
use crate::migrate::plan::DocumentPlan;

/// Top-level members no bake reads or changes: the bulk of a large scene.
const LEFT_OUT: [&str; 7] = [
    "meshes",
    "nodes",
    "accessors",
    "animations",
    "skins",
    "scenes",
    "cameras",
];

/// The member of the part that names, for the bake's pruning, the replaced textures that
/// something outside the part names; not a glTF key (the colon), never written.
const STAND_IN: &str = "velvet:named-elsewhere";

/// The part of a document a bake plan applies to.
#[derive(Debug)]
pub struct BakePart {
    /// The document's top level without the geometry (meshes, nodes, accessors, …); of
    /// `materials`, only the places below, with the objects on the way to them; the other
    /// materials are `null`.
    pub json: Value,
    /// Per material in the part, the places it holds (pointers from the root; none lies inside
    /// another).
    places: BTreeMap<usize, Vec<String>>,
}

impl BakePart {
    /// The part of `asset`'s document that `bake` and the edits of `document` apply to;
    /// `None` when a slot lies outside the material it names, or the document is not an
    /// object that writes each key once.
    pub fn new(asset: &Asset, bake: &BakePlan, document: &DocumentPlan) -> Option<BakePart> {
        let mut layers: BTreeMap<usize, Vec<&str>> = BTreeMap::new();
        for slot in &bake.slots {
            let prefix = format!("/materials/{}/", slot.material);
            if !slot.layer_pointer.starts_with(&prefix) {
                return None;
            }
            layers
                .entry(slot.material)
                .or_default()
                .push(&slot.layer_pointer);
        }
        // The places the edits set first, in their order (new keys go into an object in the
        // order the edits add them), then the layers baked.
        let mut places: BTreeMap<usize, Vec<String>> = BTreeMap::new();
        for (&material, baked) in &layers {
            let prefix = format!("/materials/{material}/");
            let edits = document
                .materials
                .binary_search_by_key(&material, |m| m.index)
                .map_or(&[][..], |at| &document.materials[at].edits[..]);
            let list = edits
                .iter()
                .map(|edit| match edit {
                    Edit::Set { pointer, .. }
                    | Edit::Replace { pointer, .. }
                    | Edit::Remove { pointer }
                        if pointer.starts_with(&prefix) =>
                    {
                        pointer.clone()
                    }
                    // Anything else: the whole material.
                    _ => format!("/materials/{material}"),
                })
                .chain(baked.iter().map(|p| p.to_string()))
                .collect();
            places.insert(material, list);
        }
        for list in places.values_mut() {
            let all = list.clone();
            let mut seen = std::collections::HashSet::new();
            // Each place once, and none inside another (it is held by the outer one).
            list.retain(|p| seen.insert(p.clone()) && !all.iter().any(|q| inside(p, q)));
        }
        // A texture a bake replaces that a textureInfo outside the places names (another
        // material, another layer of the same one, a mesh's extension) is named in the part by
        // a stand-in, so that the bake, seeing it named, keeps the texture as it would on the
        // whole document. The stand-in is never written.
        let replaced: BTreeSet<usize> = bake.slots.iter().map(|s| s.texture).collect();
        let root = asset.root();
        let object = root.as_object().filter(|o| !o.has_duplicate_keys())?;
        let mut named_elsewhere = BTreeSet::new();
        for (index, texture) in crate::bake::prune::texture_refs(root) {
            if !replaced.contains(&texture) {
                continue;
            }
            let material = match pointer::tokens(&index).as_slice() {
                [member, i, ..] if member == "materials" => i.parse::<usize>().ok(),
                _ => None,
            };
            let held = material
                .and_then(|m| places.get(&m))
                .is_some_and(|list| list.iter().any(|p| inside(&index, p)));
            if !held {
                named_elsewhere.insert(texture);
            }
        }
        let mut part = Map::new();
        for (key, node) in object.iter() {
            if LEFT_OUT.contains(&key.as_ref()) {
                continue;
            }
            let value = if key == "materials" {
                let items = node.as_array()?;
                let mut materials = Vec::with_capacity(items.len());
                for (i, material) in items.iter().enumerate() {
                    materials.push(match places.get(&i) {
                        Some(list) => sparse(material, &format!("/materials/{i}"), list)?,
                        None => Value::Null,
                    });
                }
                Value::Array(materials)
            } else {
                node.to_value()
            };
            part.insert(key.into_owned(), value);
        }
        if !named_elsewhere.is_empty() {
            let stand_ins = named_elsewhere
                .iter()
                .map(|t| serde_json::json!({ "namedElsewhereTexture": { "index": t } }))
                .collect();
            part.insert(STAND_IN.to_string(), Value::Array(stand_ins));
        }
        Some(BakePart {
            json: Value::Object(part),
            places,
        })
    }

    /// Whether what `edit` changes lies in the part.
    pub fn holds(&self, edit: &Edit) -> bool {
        let pointer = match edit {
            Edit::DeclareUsed { .. } => return true,
            Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer } => pointer,
        };
        let tokens = pointer::tokens(pointer);
        match tokens.as_slice() {
            [] => false,
            [member] if member == "materials" => false,
            [member, index, ..] if member == "materials" => index
                .parse::<usize>()
                .ok()
                .filter(|i| i.to_string() == *index)
                .and_then(|i| self.places.get(&i))
                .is_some_and(|list| list.iter().any(|p| p == pointer || inside(pointer, p))),
            [member, ..] => !LEFT_OUT.contains(&member.as_str()),
        }
    }

    /// The edits that write `json` (this part after the bake) into `asset`'s text: each place
    /// of a material and each member that differs from the document as loaded, replaced whole
    /// (removed when the part no longer holds it).
    pub fn into_edits(self, asset: &Asset, mut json: Value) -> Vec<Edit> {
        let root = asset.root();
        let mut edits = Vec::new();
        for list in self.places.values() {
            for place in list {
                match json.pointer_mut(place).map(std::mem::take) {
                    Some(value) => edits.push(Edit::replace(place.clone(), value)),
                    None if root.pointer(place).is_some() => {
                        edits.push(Edit::remove(place.clone()))
                    }
                    None => {}
                }
            }
        }
        let Value::Object(part) = json else {
            return edits;
        };
        for key in root.as_object().into_iter().flat_map(|o| o.keys()) {
            if !LEFT_OUT.contains(&key.as_ref()) && !part.contains_key(key.as_ref()) {
                edits.push(Edit::remove(pointer::join("", key)));
            }
        }
        for (key, value) in part {
            if key == "materials" || key == STAND_IN {
                continue;
            }
            if root
                .get(&key)
                .is_some_and(|loaded| loaded.to_value() == value)
            {
                continue;
            }
            edits.push(Edit::replace(pointer::join("", &key), value));
        }
        edits
    }
}

/// Whether `pointer` lies inside `outer` (below it, not at it).
fn inside(pointer: &str, outer: &str) -> bool {
    pointer.len() > outer.len()
        && pointer.starts_with(outer)
        && pointer.as_bytes()[outer.len()] == b'/'
}

/// Of `material` (at `at`), the values at `places` as loaded, with the objects on the way to
/// them and nothing else; `None` when a way passes through something other than an object
/// that writes each key once.
fn sparse(material: Node, at: &str, places: &[String]) -> Option<Value> {
    if places.iter().any(|p| p == at) {
        return Some(material.to_value());
    }
    let mut out = Map::new();
    for place in places {
        let tokens = pointer::tokens(place.strip_prefix(at)?);
        let (last, way) = tokens.split_last()?;
        let mut node = Some(material);
        let mut object = &mut out;
        for token in way {
            node = match node {
                Some(n) => {
                    let o = n.as_object().filter(|o| !o.has_duplicate_keys())?;
                    o.get(token)
                }
                None => None,
            };
            if node.is_some_and(|n| !n.is_object()) {
                return None;
            }
            object = object
                .entry(token.clone())
                .or_insert_with(|| Value::Object(Map::new()))
                .as_object_mut()?;
        }
        let here = match node {
            Some(n) => n.as_object().filter(|o| !o.has_duplicate_keys())?.get(last),
            None => None,
        };
        if let Some(value) = here {
            object.insert(last.clone(), value.to_value());
        }
    }
    Some(Value::Object(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::plan::SlotPlan;

    fn asset(text: &str) -> Asset {
        let loaded = crate::asset::load_bytes(std::path::Path::new("a.gltf"), text.as_bytes());
        loaded.asset.expect("a document")
    }

    fn no_edits() -> DocumentPlan {
        DocumentPlan {
            materials: Vec::new(),
            declarations: Vec::new(),
        }
    }

    fn slot(material: usize, layer: &str) -> SlotPlan {
        SlotPlan {
            material,
            extension: crate::layers::FUZZ,
            texture_key: "fuzzRoughnessTexture",
            factor_key: "fuzzRoughnessFactor",
            layer_pointer: format!("/materials/{material}/extensions/{layer}"),
            texture: 0,
            factor: vec![1.0],
            written_factor: None,
            sources: Vec::new(),
        }
    }

    fn plan_for(material: usize) -> BakePlan {
        BakePlan {
            slots: vec![
                slot(material, "KHR_materials_fuzz"),
                slot(material, "KHR_materials_sheen"),
            ],
            ..BakePlan::default()
        }
    }

    #[test]
    fn a_part_holds_the_layers_baked_and_the_members_a_bake_reads_and_nothing_else() {
        let text = r#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": []}],
            "materials": [{"name": "a"}, {"name": "b", "extensions": {"KHR_materials_sheen":
            {"sheenRoughnessFactor": 0.80000001192092896}}}],
            "textures": [{"source": 0}], "images": [{"uri": "a.png"}]}"#;
        let asset = asset(text);
        let fuzz = "/materials/1/extensions/KHR_materials_fuzz";
        let mut plan = crate::migrate::plan::plan_document(&asset, &Default::default());
        plan.materials.retain(|m| m.index == 1);
        plan.materials[0].edits = vec![Edit::set(fuzz, serde_json::json!({"fuzzFactor": 1}))];
        let part = BakePart::new(&asset, &plan_for(1), &plan).unwrap();
        let value = |text: &str| serde_json::from_str::<Value>(text).unwrap();
        // The sheen as loaded; the fuzz is not there until the edit sets it.
        assert_eq!(
            part.json,
            value(
                r#"{"asset": {"version": "2.0"},
                "materials": [null, {"extensions": {"KHR_materials_sheen":
                {"sheenRoughnessFactor": 0.80000001192092896}}}],
                "textures": [{"source": 0}], "images": [{"uri": "a.png"}]}"#
            )
        );
        for (edit, held) in [
            (Edit::set(fuzz, Value::Null), true),
            (Edit::set(format!("{fuzz}/fuzzFactor"), Value::Null), true),
            (Edit::set("/materials/1/name", Value::Null), false),
            (Edit::set("/materials/0/extensions/x", Value::Null), false),
            (
                Edit::set("/materials/01/extensions/KHR_materials_fuzz", Value::Null),
                false,
            ),
            (Edit::set("/images/0/uri", Value::Null), true),
            (Edit::set("/meshes/0/name", Value::Null), false),
            (Edit::declare_used("KHR_materials_fuzz"), true),
        ] {
            assert_eq!(part.holds(&edit), held, "{edit}");
        }
        // After the edit and the bake: each place and the members that changed are replaced
        // whole, with the numbers the bake left as they were written; what did not change is
        // left.
        let mut after = part.json.clone();
        crate::edit::apply(&mut after, &plan.materials[0].edits).unwrap();
        after.pointer_mut(fuzz).unwrap()["fuzzRoughnessTexture"] = serde_json::json!({"index": 1});
        after["textures"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"source": 1}));
        let edits = part.into_edits(&asset, after);
        assert_eq!(
            edits,
            vec![
                Edit::replace(
                    fuzz,
                    serde_json::json!({"fuzzFactor": 1, "fuzzRoughnessTexture": {"index": 1}})
                ),
                Edit::replace(
                    "/materials/1/extensions/KHR_materials_sheen",
                    value(r#"{"sheenRoughnessFactor": 0.80000001192092896}"#)
                ),
                Edit::replace(
                    "/textures",
                    serde_json::json!([{"source": 0}, {"source": 1}])
                ),
            ]
        );
    }

    #[test]
    fn a_replaced_texture_named_outside_the_places_is_named_in_the_part_by_a_stand_in() {
        // Material 0 is not baked but names texture 0, which the bake of material 1 replaces;
        // so does a mesh's extension. The part names texture 0 once by a stand-in (so the bake
        // keeps it), holds nothing of material 0, and the stand-in is never written.
        let text = r#"{"materials": [{"name": "a", "normalTexture": {"index": 0, "scale": 2}},
            {"extensions": {"KHR_materials_sheen": {"sheenRoughnessTexture": {"index": 0}}}}],
            "meshes": [{"extensions": {"x": {"occlusionTexture": {"index": 0}}}}],
            "textures": [{"source": 0}]}"#;
        let asset = asset(text);
        let mut plan = plan_for(1);
        plan.slots.truncate(1); // the fuzz layer alone: the sheen's textureInfo lies outside
        let part = BakePart::new(&asset, &plan, &no_edits()).unwrap();
        assert_eq!(
            part.json,
            serde_json::json!({
                "materials": [null, {"extensions": {}}],
                "textures": [{"source": 0}],
                STAND_IN: [{"namedElsewhereTexture": {"index": 0}}]
            })
        );
        let after = part.json.clone();
        assert_eq!(part.into_edits(&asset, after), Vec::<Edit>::new());
    }

    #[test]
    fn a_slot_outside_the_material_it_names_gives_no_part() {
        let asset = asset(r#"{"materials": [{}]}"#);
        let mut plan = plan_for(0);
        plan.slots[0].layer_pointer = "/extensions/x".to_string();
        assert!(BakePart::new(&asset, &plan, &no_edits()).is_none());
    }
}
