//! The part of a document that a migration's bakes are applied to, so that a library of
//! thousands of materials is not built as one value to add a few textures to it.
//!
//! A bake adds images and textures, points textureInfos at them and sets factors. Of the
//! document it reads and changes only the top-level members other than the scene's geometry,
//! and the materials its slots name. [`BakePart`] holds those as values (every other material
//! as `null`), takes the migration's edits of them, and after the bake gives back the edits
//! that write the result into the source text as splices: each baked material and each
//! member that changed, replaced whole ([`Edit::Replace`]: the numbers the bake left keep their
//! spelling). The migration's edits of every other material are spliced as they are.
//!
//! Dropping what a bake left unreferenced needs the whole document (a texture may be named by
//! a material outside the part, and dropping renumbers every reference), so the caller does
//! not use a part whose bake dropped anything. A migration drops nothing in practice: the
//! sheen it keeps still names the textures its bakes read.

use std::collections::BTreeSet;

use serde_json::{Map, Value};

use crate::asset::{pointer, Asset};
use crate::bake::plan::BakePlan;
use crate::edit::Edit;

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

/// The part of a document a bake plan applies to.
#[derive(Debug)]
pub struct BakePart {
    /// The document's top level without the members in [`LEFT_OUT`]; of `materials`, only
    /// those in `materials` are read, the others are `null`.
    pub json: Value,
    /// The materials the plan's slots lie in.
    materials: BTreeSet<usize>,
}

impl BakePart {
    /// The part of `asset`'s document that `bake` applies to; `None` when a slot lies outside
    /// the material it names, or the document is not an object that writes each key once.
    pub fn new(asset: &Asset, bake: &BakePlan) -> Option<BakePart> {
        let mut materials = BTreeSet::new();
        for slot in &bake.slots {
            let prefix = format!("/materials/{}/", slot.material);
            if !slot.layer_pointer.starts_with(&prefix) {
                return None;
            }
            materials.insert(slot.material);
        }
        let object = asset
            .root()
            .as_object()
            .filter(|o| !o.has_duplicate_keys())?;
        let mut part = Map::new();
        for (key, node) in object.iter() {
            if LEFT_OUT.contains(&key.as_ref()) {
                continue;
            }
            let value = if key == "materials" {
                let items = node.as_array()?;
                Value::Array(
                    items
                        .iter()
                        .enumerate()
                        .map(|(i, material)| match materials.contains(&i) {
                            true => material.to_value(),
                            false => Value::Null,
                        })
                        .collect(),
                )
            } else {
                node.to_value()
            };
            part.insert(key.into_owned(), value);
        }
        Some(BakePart {
            json: Value::Object(part),
            materials,
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
                .parse()
                .is_ok_and(|i: usize| self.materials.contains(&i) && i.to_string() == *index),
            [member, ..] => !LEFT_OUT.contains(&member.as_str()),
        }
    }

    /// The edits that write `json` (this part after the bake) into `asset`'s text: each
    /// material of the part and each member that differs from the document as loaded,
    /// replaced whole; a member the bake removed, removed.
    pub fn into_edits(self, asset: &Asset, json: Value) -> Vec<Edit> {
        let root = asset.root();
        let Value::Object(part) = json else {
            return Vec::new();
        };
        let mut edits = Vec::new();
        for key in root.as_object().into_iter().flat_map(|o| o.keys()) {
            if !LEFT_OUT.contains(&key.as_ref()) && !part.contains_key(key.as_ref()) {
                edits.push(Edit::remove(pointer::join("", key)));
            }
        }
        for (key, value) in part {
            match (key.as_str(), value) {
                ("materials", Value::Array(mut items)) => {
                    for &i in &self.materials {
                        if let Some(material) = items.get_mut(i) {
                            let material = std::mem::take(material);
                            edits.push(Edit::replace(format!("/materials/{i}"), material));
                        }
                    }
                }
                (_, value) => {
                    if root
                        .get(&key)
                        .is_some_and(|loaded| loaded.to_value() == value)
                    {
                        continue;
                    }
                    edits.push(Edit::replace(pointer::join("", &key), value));
                }
            }
        }
        edits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::plan::SlotPlan;

    fn asset(text: &str) -> Asset {
        let loaded = crate::asset::load_bytes(std::path::Path::new("a.gltf"), text.as_bytes());
        loaded.asset.expect("a document")
    }

    fn plan_for(material: usize) -> BakePlan {
        BakePlan {
            slots: vec![SlotPlan {
                material,
                extension: crate::layers::FUZZ,
                texture_key: "fuzzRoughnessTexture",
                factor_key: "fuzzRoughnessFactor",
                layer_pointer: format!("/materials/{material}/extensions/KHR_materials_fuzz"),
                texture: 0,
                factor: vec![1.0],
                written_factor: None,
                sources: Vec::new(),
            }],
            ..BakePlan::default()
        }
    }

    #[test]
    fn a_part_holds_the_baked_materials_and_the_members_a_bake_reads_and_nothing_else() {
        let text = r#"{"asset": {"version": "2.0"}, "meshes": [{"primitives": []}],
            "materials": [{"name": "a"}, {"name": "b", "k": 0.80000001192092896}],
            "textures": [{"source": 0}], "images": [{"uri": "a.png"}]}"#;
        let asset = asset(text);
        let part = BakePart::new(&asset, &plan_for(1)).unwrap();
        let value = |text: &str| serde_json::from_str::<Value>(text).unwrap();
        assert_eq!(
            part.json,
            value(
                r#"{"asset": {"version": "2.0"},
                "materials": [null, {"name": "b", "k": 0.80000001192092896}],
                "textures": [{"source": 0}], "images": [{"uri": "a.png"}]}"#
            )
        );
        for (edit, held) in [
            (Edit::set("/materials/1/extensions/x", Value::Null), true),
            (Edit::set("/materials/0/extensions/x", Value::Null), false),
            (Edit::set("/materials/01/name", Value::Null), false),
            (Edit::set("/images/0/uri", Value::Null), true),
            (Edit::set("/meshes/0/name", Value::Null), false),
            (Edit::declare_used("KHR_materials_fuzz"), true),
        ] {
            assert_eq!(part.holds(&edit), held, "{edit}");
        }
        // After the bake: the baked material and the members that changed are replaced whole,
        // with the numbers the bake left as they were written; what did not change is left.
        let mut after = part.json.clone();
        after["materials"][1]["name"] = "b2".into();
        after["textures"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!({"source": 1}));
        let edits = part.into_edits(&asset, after);
        assert_eq!(
            edits,
            vec![
                Edit::replace(
                    "/materials/1",
                    value(r#"{"name": "b2", "k": 0.80000001192092896}"#)
                ),
                Edit::replace(
                    "/textures",
                    serde_json::json!([{"source": 0}, {"source": 1}])
                ),
            ]
        );
    }

    #[test]
    fn a_slot_outside_the_material_it_names_gives_no_part() {
        let asset = asset(r#"{"materials": [{}]}"#);
        let mut plan = plan_for(0);
        plan.slots[0].layer_pointer = "/extensions/x".to_string();
        assert!(BakePart::new(&asset, &plan).is_none());
    }
}
