//! Planning: for each material with sheen or fuzz, which conversion applies (or why none does),
//! as edits and notes; then the declarations the document needs. Nothing here writes: the plan
//! is a value that `apply` executes and `render` prints.

use super::note::{Conversion, Note, Skip};
use super::textures::{self, TextureBake};
use super::{fallback, legacy, sheen_to_fuzz, Options};
use crate::asset::tape::Node;
use crate::asset::Asset;
use crate::edit::{Edit, SetValue};
use crate::layers;
use serde::Serialize;
use serde_json::Value;
use std::collections::HashMap;

/// What happens to one material.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaterialPlan {
    pub index: usize,
    pub name: Option<String>,
    /// The conversions applied, in order (a draft sheen is upgraded before it becomes fuzz).
    pub conversions: Vec<Conversion>,
    /// Why nothing was done, when nothing was.
    pub skipped: Option<Skip>,
    pub edits: Vec<Edit>,
    /// Textures baked for this material (their textureInfos are among the edits).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bakes: Vec<TextureBake>,
    #[serde(serialize_with = "notes_json")]
    pub notes: Vec<Note>,
}

pub(crate) fn notes_json<S: serde::Serializer>(notes: &[Note], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(notes.len()))?;
    for note in notes {
        seq.serialize_element(&note.to_json())?;
    }
    seq.end()
}

impl MaterialPlan {
    fn new(index: usize, material: Node) -> MaterialPlan {
        MaterialPlan {
            index,
            name: material
                .get("name")
                .and_then(|name| name.as_str())
                .map(|name| name.into_owned()),
            // A conversion makes one edit, most often: made at that size, the lists are not
            // grown to four and cut back (`shrink_to_fit`) by the twenty thousand.
            conversions: Vec::with_capacity(1),
            skipped: None,
            edits: Vec::with_capacity(1),
            bakes: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Ends the plan with nothing done and why.
    pub(crate) fn skip(&mut self, why: Skip, note: Note) {
        if self.conversions.is_empty() {
            self.skipped = Some(why);
        }
        self.notes.push(note);
    }

    /// Cuts the plan's lists to their length. A plan is kept to the end of the run, for its
    /// report; grown by doubling, the lists of a large library's plans held a third more.
    fn shrink_to_fit(&mut self) {
        self.edits.shrink_to_fit();
        self.notes.shrink_to_fit();
        self.bakes.shrink_to_fit();
        self.conversions.shrink_to_fit();
    }

    /// Writes into the edit that sets each baked slot's layer object the factor the bake
    /// leaves in the file (see [`TextureBake::factor_in_file`]), once the budget has chosen
    /// it: the plan's edits, and so a dry run and `--check`, then show the value the file
    /// gets, not the factor before the bake.
    fn settle_baked_factors(&mut self) {
        for bake in &self.bakes {
            let factor_pointer = format!("{}/{}", bake.layer_pointer, bake.factor_key);
            for edit in &mut self.edits {
                let Edit::Set { pointer, value } = edit else {
                    continue;
                };
                if *pointer == factor_pointer {
                    *value = SetValue::Value(crate::edit::splice::written(bake.factor_in_file()));
                    continue;
                }
                if *pointer != bake.layer_pointer {
                    continue;
                }
                let mut layer = value.to_value().into_owned();
                let Some(members) = layer.as_object_mut() else {
                    continue;
                };
                members.insert(bake.factor_key.to_string(), bake.factor_in_file());
                *value = match value {
                    SetValue::Text(_) => {
                        let mut text = String::new();
                        crate::edit::splice::write_compact(&layer, &mut text);
                        SetValue::Text(text.into_boxed_str())
                    }
                    SetValue::Value(_) => SetValue::Value(crate::edit::splice::written(layer)),
                };
            }
        }
    }

    pub fn migrated(&self) -> bool {
        !self.conversions.is_empty()
    }
}

/// What a conversion sees of one material.
pub struct MaterialCx<'a> {
    pub asset: &'a Asset,
    pub index: usize,
    /// The material as loaded, through the index: only the layers a conversion reads are read
    /// into values.
    pub material: Node<'a>,
    pub options: &'a Options,
    /// The document's primitives by material, shared by every material's plan.
    pub primitives: &'a Primitives<'a>,
}

/// The mesh primitives drawn with each material: (mesh, primitive, the TEXCOORD_n attributes
/// it has; `None` when `attributes` is not an object). Found in one walk of the meshes, on
/// first use, for every material that asks: a search of all meshes per material would cost
/// materials × primitives.
pub struct Primitives<'a> {
    json: Node<'a>,
    by_material: std::sync::OnceLock<HashMap<u64, Vec<PrimitiveSets>>>,
}

type PrimitiveSets = (usize, usize, Option<Vec<String>>);

impl<'a> Primitives<'a> {
    pub fn new(json: Node<'a>) -> Primitives<'a> {
        Primitives {
            json,
            by_material: std::sync::OnceLock::new(),
        }
    }

    /// The primitives drawn with `material`, in document order.
    fn of(&self, material: usize) -> &[PrimitiveSets] {
        let by_material = self.by_material.get_or_init(|| {
            let mut by_material: HashMap<u64, Vec<_>> = HashMap::new();
            for (m, mesh) in crate::document::elements(self.json.get("meshes")).enumerate() {
                for (p, primitive) in crate::document::elements(mesh.get("primitives")).enumerate()
                {
                    if let Some(material) = primitive.get("material").and_then(|v| v.as_u64()) {
                        let sets =
                            primitive
                                .get("attributes")
                                .and_then(|a| a.as_object())
                                .map(|a| {
                                    a.keys()
                                        .filter(|k| k.starts_with("TEXCOORD_"))
                                        .map(|k| k.into_owned())
                                        .collect()
                                });
                        by_material.entry(material).or_default().push((m, p, sets));
                    }
                }
            }
            by_material
        });
        by_material
            .get(&(material as u64))
            .map_or(&[], Vec::as_slice)
    }
}

impl<'a> MaterialCx<'a> {
    /// The document as loaded, through its index.
    pub fn json(&self) -> Node<'a> {
        self.asset.root()
    }

    /// Pointer to `extension` on this material.
    pub fn extension_pointer(&self, extension: &str) -> String {
        use std::fmt::Write;
        // Made at its length (a plan keeps it to the end of the run, by the twenty thousand);
        // `format!` cost more than the rest of the pointer.
        const PARTS: usize = "/materials//extensions/".len();
        let digits = self.index.checked_ilog10().unwrap_or(0) as usize + 1;
        let mut pointer = String::with_capacity(PARTS + digits + extension.len());
        // Writing to a String cannot fail.
        let _ = write!(pointer, "/materials/{}/extensions/", self.index);
        crate::asset::pointer::push_escaped(&mut pointer, extension);
        pointer
    }

    pub fn has_extension(&self, extension: &str) -> bool {
        self.material
            .get("extensions")
            .and_then(|e| e.as_object())
            .is_some_and(|e| e.get(extension).is_some())
    }

    /// A bake of the texture `texture_info` names into slot `texture_key` of `extension` on
    /// this material, or why it cannot be made (no such texture, an image that cannot be read
    /// or is KTX2).
    #[allow(clippy::too_many_arguments)]
    pub fn texture_bake(
        &self,
        extension: &'static str,
        texture_key: &'static str,
        factor_key: &'static str,
        factor: Vec<f64>,
        texture_info: &Value,
        contents: textures::Contents,
    ) -> Result<TextureBake, String> {
        let texture = textures::texture_index(texture_info)
            .ok_or_else(|| "its textureInfo has no valid index".to_string())?;
        let sources = textures::sources(self.asset, texture)?;
        Ok(TextureBake {
            written_factor: None,
            material: self.index,
            extension,
            layer_pointer: self.extension_pointer(extension),
            texture_key,
            factor_key,
            factor,
            texture,
            sources,
            contents,
        })
    }
}

/// The plan of one document: the materials' plans and the declarations they need.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct DocumentPlan {
    pub materials: Vec<MaterialPlan>,
    /// `extensionsUsed` additions.
    pub declarations: Vec<Edit>,
}

impl DocumentPlan {
    /// Every edit, materials first, in the order they are applied.
    pub fn edits(&self) -> impl Iterator<Item = &Edit> {
        self.materials
            .iter()
            .flat_map(|m| m.edits.iter())
            .chain(&self.declarations)
    }

    pub fn is_empty(&self) -> bool {
        self.edits().next().is_none()
    }
}

/// Plans the migration of every material of `asset`.
pub fn plan_document(asset: &Asset, options: &Options) -> DocumentPlan {
    let count = asset
        .root()
        .get("materials")
        .and_then(|m| m.as_array())
        .map_or(0, |m| m.len());
    // With --fast, materials are planned side by side on the thread pool (the 20,000 of the
    // library in 52 ms instead of 85). Otherwise one after another: the plans then come from
    // the workers' own allocator arenas, and the bakes that follow a default migration found
    // less of the memory freed in one arena free in the other (the library's default migration
    // peaked at 108 MiB instead of 101). One arena for the whole process made the workers wait
    // on each other's allocations instead (see `asset::pages::limit_heaps`).
    let primitives = Primitives::new(asset.root());
    let plan = |i: usize| {
        plan_material(asset, i, options, &primitives).map(|mut plan| {
            plan.shrink_to_fit();
            plan
        })
    };
    let mut materials: Vec<MaterialPlan> = if options.fast {
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

/// A number for the output: `original` itself (its text kept) when it already has this value,
/// else the value written anew.
pub(crate) fn number_like(original: Option<&Value>, value: f64) -> Value {
    match original {
        Some(v) if v.as_f64() == Some(value) => v.clone(),
        _ => Value::from(value),
    }
}

/// The texCoord set a textureInfo reads, and the first primitive drawn with `material` that
/// lacks it, if any (carrying such a texture into a slot velvet checks would add an error).
pub(crate) fn primitive_lacking_tex_coord(
    primitives: &Primitives,
    material: usize,
    texture_info: &Value,
) -> Option<String> {
    let set = crate::document::effective_tex_coord(texture_info);
    let attribute = format!("TEXCOORD_{set}");
    primitives
        .of(material)
        .iter()
        .find(|(_, _, sets)| !sets.as_ref().is_some_and(|s| s.contains(&attribute)))
        .map(|(m, p, _)| format!("mesh {m} primitive {p} has no {attribute}"))
}

/// Why a textureInfo cannot be carried into a checked slot, if it cannot: its index names no
/// texture, or a primitive lacks its texCoord set.
pub(crate) fn texture_unusable(cx: &MaterialCx, texture_info: &Value) -> Option<String> {
    let textures = cx
        .json()
        .get("textures")
        .and_then(|t| t.as_array())
        .map_or(0, |t| t.len());
    match texture_info.get("index").and_then(Value::as_u64) {
        Some(i) if (i as usize) < textures => {
            primitive_lacking_tex_coord(cx.primitives, cx.index, texture_info)
        }
        Some(i) => Some(format!(
            "its index {i} names no texture (the asset has {textures})"
        )),
        None => Some("it has no valid index".to_string()),
    }
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
