//! A material's plan and the document's, as every conversion fills them and every view reads
//! them ([`MaterialPlan`], [`DocumentPlan`]), and what a conversion sees of one material
//! ([`MaterialCx`]). The conversions depend on these types; the planner (`plan.rs`) runs the
//! conversions; nothing here calls either.

use super::note::{Conversion, Note, Skip};
use super::textures::{self, TextureBake};
use super::Options;
use crate::asset::tape::{JsonView, Node};
use crate::asset::Asset;
use crate::bake::Channel;
use crate::edit::splice::{write_compact, write_compact_node};
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
    /// How the material as written looks beside the material as authored, measured right
    /// after planning (see [`super::verdict`]); `None` when it was not measured (`--fast`,
    /// `--roughness identity`, a material no sheet shows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<super::verdict::Verdict>,
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
    pub(super) fn new(index: usize, material: Node) -> MaterialPlan {
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
            verdict: None,
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
    pub(super) fn shrink_to_fit(&mut self) {
        self.edits.shrink_to_fit();
        self.notes.shrink_to_fit();
        self.bakes.shrink_to_fit();
        self.conversions.shrink_to_fit();
    }

    /// Writes into the edit that sets each baked slot's layer object the factor the bake
    /// leaves in the file (see [`TextureBake::factor_in_file`]), once the budget has chosen
    /// it: the plan's edits, and so a dry run and `--check`, then show the value the file
    /// gets, not the factor before the bake.
    pub(super) fn settle_baked_factors(&mut self) {
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

/// A ratified sheen as the conversion needs it: numbers with the JSON text they came in (so
/// that unchanged numbers keep it), and the textureInfo objects as they are. Read through the
/// document's index, those stay places in its text ([`Read::Node`]) until a conversion needs a
/// value (a bake, a measurement); the fuzz object is written from them as they are.
#[derive(Debug, Clone, PartialEq)]
pub struct Sheen<'a> {
    pub color: [f64; 3],
    /// The colour as written: each reads as its component of `color`.
    pub color_values: [Read<'a>; 3],
    pub roughness: f64,
    /// The roughness as written: it reads as `roughness`.
    pub roughness_value: Read<'a>,
    pub color_texture: Option<Read<'a>>,
    pub roughness_texture: Option<Read<'a>>,
    /// The channel the roughness texture holds roughness in: alpha for a ratified sheen, green
    /// for a draft sheen that followed the material's metallicRoughnessTexture (baked into
    /// alpha on the way).
    pub roughness_channel: Channel,
}

/// A member of a sheen as read: a value, or its place in the document's index.
#[derive(Debug, Clone)]
pub enum Read<'a> {
    Value(Value),
    Node(Node<'a>),
}

impl Read<'_> {
    /// The value (read from the document's text for a place in it).
    pub fn to_value(&self) -> std::borrow::Cow<'_, Value> {
        match self {
            Read::Value(value) => std::borrow::Cow::Borrowed(value),
            Read::Node(node) => std::borrow::Cow::Owned(node.to_value()),
        }
    }

    /// Writes it as [`write_compact`] writes its value.
    pub fn write_compact(&self, out: &mut String) {
        match self {
            Read::Value(value) => write_compact(value, out),
            Read::Node(node) => write_compact_node(*node, out),
        }
    }
}

impl PartialEq for Read<'_> {
    fn eq(&self, other: &Read<'_>) -> bool {
        self.to_value() == other.to_value()
    }
}

impl<'a> Sheen<'a> {
    /// Reads a ratified KHR_materials_sheen object, with the spec's defaults (a malformed
    /// value reads as its default: the schema check reports it).
    pub fn read(ext: impl SheenSource<'a>) -> Sheen<'a> {
        // Each member is looked up once (a layer read through the index pays for every
        // lookup), with what `layers::SheenView::read` would read from it. A value that is not
        // an object has no members: every one reads as its default.
        let raw = ext.member("sheenColorFactor");
        let parsed = raw.and_then(layers::rgb_of);
        let color = parsed.unwrap_or(layers::SHEEN_COLOR_DEFAULT);
        let roughness_raw = ext.member("sheenRoughnessFactor");
        let roughness_parsed = roughness_raw.and_then(JsonView::number);
        let roughness = roughness_parsed.unwrap_or(layers::SHEEN_ROUGHNESS_DEFAULT);
        // A number just read as its component is kept as it is, without reading it again.
        let color_values = std::array::from_fn(|i| {
            let element = raw.and_then(|a| a.element(i));
            match (parsed, element) {
                (Some(_), Some(element)) => element.read(),
                _ => number_read(element, color[i]),
            }
        });
        let roughness_value = match (roughness_parsed, roughness_raw) {
            (Some(_), Some(raw)) => raw.read(),
            _ => number_read(roughness_raw, roughness),
        };
        let texture = |key| {
            ext.member(key)
                .filter(|v| v.object())
                .map(SheenSource::read)
        };
        Sheen {
            color,
            color_values,
            roughness,
            roughness_value,
            color_texture: texture("sheenColorTexture"),
            roughness_texture: texture("sheenRoughnessTexture"),
            roughness_channel: Channel::A,
        }
    }
}

/// The number `original` as read, when it reads as `value`; else `value` as a value.
fn number_read<'a, S: SheenSource<'a>>(original: Option<S>, value: f64) -> Read<'a> {
    match original {
        Some(v) if v.number() == Some(value) => v.read(),
        _ => Read::Value(Value::from(value)),
    }
}

/// What a sheen is read from: a value, or the document's index (the members the conversion
/// keeps, numbers and textureInfos, then stay places in the text).
pub trait SheenSource<'a>: JsonView<'a> {
    fn read(self) -> Read<'a>;
}

impl<'a> SheenSource<'a> for &'a Value {
    fn read(self) -> Read<'a> {
        Read::Value(self.clone())
    }
}

impl<'a> SheenSource<'a> for Node<'a> {
    fn read(self) -> Read<'a> {
        Read::Node(self)
    }
}
