//! Extension objects: where each may stand, and whether it is what its published schema says.
//!
//! The schemas the Khronos Group publishes for its extensions and the EXT ones
//! (`schema/extensions/<EXTENSION>/`, compiled in) name the kind of object each extends:
//! `material.KHR_materials_ior.schema.json` extends a material. [`PLACEMENTS`] is the one table
//! of where every extension with a schema may stand and the file that judges it there. An
//! extension object on any other kind of object is UNEXPECTED_EXTENSION_OBJECT (an error, as
//! in the Khronos validator, which lists it among its link errors); one where it belongs is judged by its
//! schema, with the codes and pointers of the core schema check.
//!
//! The kinds of objects come from the schemas too: the walk starts at the root with
//! `glTF.schema.json` and follows each property whose schema refers to another object's schema
//! (`materials` → `material.schema.json` → `normalTexture` → `material.normalTextureInfo…`,
//! which extends `textureInfo.schema.json`), and into the extension objects it finds (so that a
//! KHR_texture_transform on a clearcoat texture is found and judged). `extras` and extensions
//! without a schema are not walked into: their contents are free.
//!
//! Sheen and fuzz stand in the table with velvet's own schemas, for their placement only: the
//! layer schema check (`rules/schema.rs`) judges their contents. An extension velvet has no
//! schema for is left to the declaration rule, as any unknown extension.
//!
//! Each extension's schema compiles on first use, so a run pays only for the extensions its
//! documents use; an object's findings depend on its text alone, so each distinct text is
//! judged once per document.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{KeyId, Node};
use crate::asset::tape_schema::TapeJson;
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use serde_json::Value;
use std::collections::HashMap;
use std::sync::{LazyLock, OnceLock};

macro_rules! ext_file {
    ($dir:literal, $name:literal) => {
        (
            $name,
            include_str!(concat!("../../schema/extensions/", $dir, "/", $name)),
        )
    };
}

/// The published extension schemas, by extension, each file by name, as compiled in.
pub const EXTENSION_FILES: &[(&str, &[(&str, &str)])] = &[
    (
        "EXT_lights_ies",
        &[
            ext_file!("EXT_lights_ies", "glTF.EXT_lights_ies.schema.json"),
            ext_file!("EXT_lights_ies", "lightProfile.schema.json"),
            ext_file!("EXT_lights_ies", "node.EXT_lights_ies.schema.json"),
        ],
    ),
    (
        "EXT_lights_image_based",
        &[
            ext_file!(
                "EXT_lights_image_based",
                "glTF.EXT_lights_image_based.schema.json"
            ),
            ext_file!("EXT_lights_image_based", "light.schema.json"),
            ext_file!(
                "EXT_lights_image_based",
                "scene.EXT_lights_image_based.schema.json"
            ),
        ],
    ),
    (
        "EXT_mesh_gpu_instancing",
        &[ext_file!(
            "EXT_mesh_gpu_instancing",
            "glTF.EXT_mesh_gpu_instancing.schema.json"
        )],
    ),
    (
        "EXT_mesh_manifold",
        &[ext_file!(
            "EXT_mesh_manifold",
            "mesh.EXT_mesh_manifold.schema.json"
        )],
    ),
    (
        "EXT_mesh_primitive_edge_visibility",
        &[
            ext_file!(
                "EXT_mesh_primitive_edge_visibility",
                "lineString.schema.json"
            ),
            ext_file!(
                "EXT_mesh_primitive_edge_visibility",
                "primitive.EXT_mesh_primitive_edge_visibility.schema.json"
            ),
        ],
    ),
    (
        "EXT_mesh_primitive_restart",
        &[
            ext_file!(
                "EXT_mesh_primitive_restart",
                "EXT_mesh_primitive_restart.schema.json"
            ),
            ext_file!("EXT_mesh_primitive_restart", "primitiveGroup.schema.json"),
        ],
    ),
    (
        "EXT_meshopt_compression",
        &[
            ext_file!(
                "EXT_meshopt_compression",
                "buffer.EXT_meshopt_compression.schema.json"
            ),
            ext_file!(
                "EXT_meshopt_compression",
                "bufferView.EXT_meshopt_compression.schema.json"
            ),
        ],
    ),
    (
        "EXT_texture_astc",
        &[ext_file!(
            "EXT_texture_astc",
            "texture.EXT_texture_astc.schema.json"
        )],
    ),
    (
        "EXT_texture_webp",
        &[ext_file!(
            "EXT_texture_webp",
            "glTF.EXT_texture_webp.schema.json"
        )],
    ),
    (
        "KHR_animation_pointer",
        &[ext_file!(
            "KHR_animation_pointer",
            "animation.channel.target.KHR_animation_pointer.schema.json"
        )],
    ),
    (
        "KHR_draco_mesh_compression",
        &[ext_file!(
            "KHR_draco_mesh_compression",
            "mesh.primitive.KHR_draco_mesh_compression.schema.json"
        )],
    ),
    (
        "KHR_gaussian_splatting",
        &[ext_file!(
            "KHR_gaussian_splatting",
            "mesh.primitive.KHR_gaussian_splatting.schema.json"
        )],
    ),
    (
        "KHR_lights_punctual",
        &[
            ext_file!(
                "KHR_lights_punctual",
                "glTF.KHR_lights_punctual.schema.json"
            ),
            ext_file!("KHR_lights_punctual", "light.schema.json"),
            ext_file!("KHR_lights_punctual", "light.spot.schema.json"),
            ext_file!(
                "KHR_lights_punctual",
                "node.KHR_lights_punctual.schema.json"
            ),
        ],
    ),
    (
        "KHR_materials_anisotropy",
        &[ext_file!(
            "KHR_materials_anisotropy",
            "material.KHR_materials_anisotropy.schema.json"
        )],
    ),
    (
        "KHR_materials_clearcoat",
        &[ext_file!(
            "KHR_materials_clearcoat",
            "material.KHR_materials_clearcoat.schema.json"
        )],
    ),
    (
        "KHR_materials_diffuse_transmission",
        &[ext_file!(
            "KHR_materials_diffuse_transmission",
            "material.KHR_materials_diffuse_transmission.schema.json"
        )],
    ),
    (
        "KHR_materials_dispersion",
        &[ext_file!(
            "KHR_materials_dispersion",
            "material.KHR_materials_dispersion.schema.json"
        )],
    ),
    (
        "KHR_materials_emissive_strength",
        &[ext_file!(
            "KHR_materials_emissive_strength",
            "material.KHR_materials_emissive_strength.schema.json"
        )],
    ),
    (
        "KHR_materials_ior",
        &[ext_file!(
            "KHR_materials_ior",
            "material.KHR_materials_ior.schema.json"
        )],
    ),
    (
        "KHR_materials_iridescence",
        &[ext_file!(
            "KHR_materials_iridescence",
            "material.KHR_materials_iridescence.schema.json"
        )],
    ),
    // Archived, and not among the published schemas: velvet's own file, written from the
    // archived spec's property table (schema/extensions/README.md).
    (
        "KHR_materials_pbrSpecularGlossiness",
        &[ext_file!(
            "KHR_materials_pbrSpecularGlossiness",
            "material.KHR_materials_pbrSpecularGlossiness.schema.json"
        )],
    ),
    (
        "KHR_materials_specular",
        &[ext_file!(
            "KHR_materials_specular",
            "material.KHR_materials_specular.schema.json"
        )],
    ),
    (
        "KHR_materials_transmission",
        &[ext_file!(
            "KHR_materials_transmission",
            "material.KHR_materials_transmission.schema.json"
        )],
    ),
    (
        "KHR_materials_unlit",
        &[ext_file!(
            "KHR_materials_unlit",
            "material.KHR_materials_unlit.schema.json"
        )],
    ),
    (
        "KHR_materials_variants",
        &[
            ext_file!(
                "KHR_materials_variants",
                "glTF.KHR_materials_variants.schema.json"
            ),
            ext_file!(
                "KHR_materials_variants",
                "mesh.primitive.KHR_materials_variants.schema.json"
            ),
        ],
    ),
    (
        "KHR_materials_volume",
        &[ext_file!(
            "KHR_materials_volume",
            "material.KHR_materials_volume.schema.json"
        )],
    ),
    (
        "KHR_meshopt_compression",
        &[
            ext_file!(
                "KHR_meshopt_compression",
                "buffer.KHR_meshopt_compression.schema.json"
            ),
            ext_file!(
                "KHR_meshopt_compression",
                "bufferView.KHR_meshopt_compression.schema.json"
            ),
        ],
    ),
    (
        "KHR_node_hoverability",
        &[ext_file!(
            "KHR_node_hoverability",
            "node.KHR_node_hoverability.schema.json"
        )],
    ),
    (
        "KHR_node_selectability",
        &[ext_file!(
            "KHR_node_selectability",
            "node.KHR_node_selectability.schema.json"
        )],
    ),
    (
        "KHR_node_visibility",
        &[ext_file!(
            "KHR_node_visibility",
            "node.KHR_node_visibility.schema.json"
        )],
    ),
    (
        "KHR_texture_basisu",
        &[ext_file!(
            "KHR_texture_basisu",
            "texture.KHR_texture_basisu.schema.json"
        )],
    ),
    (
        "KHR_texture_transform",
        &[ext_file!(
            "KHR_texture_transform",
            "textureInfo.KHR_texture_transform.schema.json"
        )],
    ),
    (
        "KHR_xmp_json_ld",
        &[
            ext_file!("KHR_xmp_json_ld", "KHR_xmp_json_ld.schema.json"),
            ext_file!("KHR_xmp_json_ld", "glTF.KHR_xmp_json_ld.schema.json"),
        ],
    ),
];

/// Where objects of one extension may stand, and the schema file that judges them there.
pub struct Placement {
    pub extension: &'static str,
    /// The kinds of object it extends, by core schema name (`material` for
    /// `material.schema.json`); a kind that extends another (`material.normalTextureInfo`
    /// extends `textureInfo`) counts as both.
    pub on: &'static [&'static str],
    /// The schema file, in the extension's folder (velvet's own `schema/` for sheen and fuzz).
    pub schema: &'static str,
}

const fn place(
    extension: &'static str,
    on: &'static [&'static str],
    schema: &'static str,
) -> Placement {
    Placement {
        extension,
        on,
        schema,
    }
}

/// The objects KHR_xmp_json_ld may annotate: the asset and the top-level arrays its spec
/// names (the root holds the packets, under its own schema).
const XMP_ANNOTATED: &[&str] = &[
    "asset",
    "scene",
    "node",
    "mesh",
    "material",
    "image",
    "animation",
];

/// Every extension with a schema: where it may stand, and what judges it there. The kind is
/// the first part of the schema file's name, except where a comment says otherwise.
pub const PLACEMENTS: &[Placement] = &[
    place(
        "EXT_lights_ies",
        &["glTF"],
        "glTF.EXT_lights_ies.schema.json",
    ),
    place(
        "EXT_lights_ies",
        &["node"],
        "node.EXT_lights_ies.schema.json",
    ),
    place(
        "EXT_lights_image_based",
        &["glTF"],
        "glTF.EXT_lights_image_based.schema.json",
    ),
    place(
        "EXT_lights_image_based",
        &["scene"],
        "scene.EXT_lights_image_based.schema.json",
    ),
    // The published file is named `glTF.…`, but the extension (its spec, and the schema's
    // description) gives instance attributes to a node.
    place(
        "EXT_mesh_gpu_instancing",
        &["node"],
        "glTF.EXT_mesh_gpu_instancing.schema.json",
    ),
    place(
        "EXT_mesh_manifold",
        &["mesh"],
        "mesh.EXT_mesh_manifold.schema.json",
    ),
    // `primitive.…`: the mesh primitive.
    place(
        "EXT_mesh_primitive_edge_visibility",
        &["mesh.primitive"],
        "primitive.EXT_mesh_primitive_edge_visibility.schema.json",
    ),
    // The file name names no kind; the extension groups a mesh's primitives, on the mesh.
    place(
        "EXT_mesh_primitive_restart",
        &["mesh"],
        "EXT_mesh_primitive_restart.schema.json",
    ),
    place(
        "EXT_meshopt_compression",
        &["buffer"],
        "buffer.EXT_meshopt_compression.schema.json",
    ),
    place(
        "EXT_meshopt_compression",
        &["bufferView"],
        "bufferView.EXT_meshopt_compression.schema.json",
    ),
    place(
        "EXT_texture_astc",
        &["texture"],
        "texture.EXT_texture_astc.schema.json",
    ),
    // The published file is named `glTF.…`; the extension gives a texture its WebP source.
    place(
        "EXT_texture_webp",
        &["texture"],
        "glTF.EXT_texture_webp.schema.json",
    ),
    place(
        "KHR_animation_pointer",
        &["animation.channel.target"],
        "animation.channel.target.KHR_animation_pointer.schema.json",
    ),
    place(
        "KHR_draco_mesh_compression",
        &["mesh.primitive"],
        "mesh.primitive.KHR_draco_mesh_compression.schema.json",
    ),
    place(
        "KHR_gaussian_splatting",
        &["mesh.primitive"],
        "mesh.primitive.KHR_gaussian_splatting.schema.json",
    ),
    place(
        "KHR_lights_punctual",
        &["glTF"],
        "glTF.KHR_lights_punctual.schema.json",
    ),
    place(
        "KHR_lights_punctual",
        &["node"],
        "node.KHR_lights_punctual.schema.json",
    ),
    place(
        "KHR_materials_anisotropy",
        &["material"],
        "material.KHR_materials_anisotropy.schema.json",
    ),
    place(
        "KHR_materials_clearcoat",
        &["material"],
        "material.KHR_materials_clearcoat.schema.json",
    ),
    place(
        "KHR_materials_diffuse_transmission",
        &["material"],
        "material.KHR_materials_diffuse_transmission.schema.json",
    ),
    place(
        "KHR_materials_dispersion",
        &["material"],
        "material.KHR_materials_dispersion.schema.json",
    ),
    place(
        "KHR_materials_emissive_strength",
        &["material"],
        "material.KHR_materials_emissive_strength.schema.json",
    ),
    place(
        "KHR_materials_fuzz",
        &["material"],
        "material.KHR_materials_fuzz.schema.json",
    ),
    place(
        "KHR_materials_ior",
        &["material"],
        "material.KHR_materials_ior.schema.json",
    ),
    place(
        "KHR_materials_iridescence",
        &["material"],
        "material.KHR_materials_iridescence.schema.json",
    ),
    place(
        "KHR_materials_sheen",
        &["material"],
        "material.KHR_materials_sheen.schema.json",
    ),
    place(
        "KHR_materials_pbrSpecularGlossiness",
        &["material"],
        "material.KHR_materials_pbrSpecularGlossiness.schema.json",
    ),
    place(
        "KHR_materials_specular",
        &["material"],
        "material.KHR_materials_specular.schema.json",
    ),
    place(
        "KHR_materials_transmission",
        &["material"],
        "material.KHR_materials_transmission.schema.json",
    ),
    place(
        "KHR_materials_unlit",
        &["material"],
        "material.KHR_materials_unlit.schema.json",
    ),
    place(
        "KHR_materials_variants",
        &["glTF"],
        "glTF.KHR_materials_variants.schema.json",
    ),
    place(
        "KHR_materials_variants",
        &["mesh.primitive"],
        "mesh.primitive.KHR_materials_variants.schema.json",
    ),
    place(
        "KHR_materials_volume",
        &["material"],
        "material.KHR_materials_volume.schema.json",
    ),
    place(
        "KHR_meshopt_compression",
        &["buffer"],
        "buffer.KHR_meshopt_compression.schema.json",
    ),
    place(
        "KHR_meshopt_compression",
        &["bufferView"],
        "bufferView.KHR_meshopt_compression.schema.json",
    ),
    place(
        "KHR_node_hoverability",
        &["node"],
        "node.KHR_node_hoverability.schema.json",
    ),
    place(
        "KHR_node_selectability",
        &["node"],
        "node.KHR_node_selectability.schema.json",
    ),
    place(
        "KHR_node_visibility",
        &["node"],
        "node.KHR_node_visibility.schema.json",
    ),
    place(
        "KHR_texture_basisu",
        &["texture"],
        "texture.KHR_texture_basisu.schema.json",
    ),
    place(
        "KHR_texture_transform",
        &["textureInfo"],
        "textureInfo.KHR_texture_transform.schema.json",
    ),
    place(
        "KHR_xmp_json_ld",
        &["glTF"],
        "glTF.KHR_xmp_json_ld.schema.json",
    ),
    // The file name names no kind: an object's packet reference, on the objects its spec lists.
    place(
        "KHR_xmp_json_ld",
        XMP_ANNOTATED,
        "KHR_xmp_json_ld.schema.json",
    ),
];

/// Published extensions that define no extension object at all (KHR_mesh_quantization only
/// widens the accessor types attributes may use): an object under their name stands nowhere.
const OBJECTLESS: &[&str] = &["KHR_mesh_quantization"];

pub const UNEXPECTED_EXTENSION_OBJECT: Code = Code::new(
    "UNEXPECTED_EXTENSION_OBJECT",
    Severity::Error,
    "An extension object stands on a kind of object its extension does not extend (KHR_materials_ior on a node, KHR_texture_transform on a material).",
);

/// Whether velvet's layer schema check, not this rule, judges the extension's contents.
fn judged_as_layer(extension: &str) -> bool {
    extension == layers::SHEEN || extension == layers::FUZZ
}

/// The files an extension's schemas may refer to: its own folder (velvet's `schema/` for sheen
/// and fuzz).
fn folder_of(extension: &str) -> &'static [(&'static str, &'static str)] {
    if judged_as_layer(extension) {
        return super::schema::BUILTIN;
    }
    EXTENSION_FILES
        .iter()
        .find(|(name, _)| *name == extension)
        .map_or(&[], |(_, files)| files)
}

/// The text of schema file `name` as an extension's schemas see it: from its folder first,
/// then the core.
fn schema_text(folder: &[(&'static str, &'static str)], name: &str) -> Option<&'static str> {
    folder
        .iter()
        .chain(super::core::CORE_SCHEMAS)
        .find(|(file, _)| *file == name)
        .map(|(_, text)| *text)
}

/// A kind of object, as its schema describes it.
struct Shape {
    /// The schema files it is: its own and, through `allOf`, those it extends.
    is: Vec<String>,
    /// Its properties that hold objects of a known kind: name, kind, whether an array of them.
    children: Vec<(String, usize, bool)>,
    /// Every property its schemas define (its own and its bases'), sorted; `None` when the
    /// schema admits any other (`additionalProperties` other than `false`).
    known: Option<Vec<String>>,
}

/// The kinds of objects of a glTF document and of its extension objects, from the schemas.
pub(crate) struct Shapes {
    shapes: Vec<Shape>,
    /// Per kind: whether it is a textureInfo, and a normal texture's, read once here rather
    /// than by comparing file names at every object of every material.
    texture_info: Vec<bool>,
    normal_texture_info: Vec<bool>,
    /// Per kind, per placement: whether the placement may stand on it ([`Shapes::fits`]).
    fit: Vec<Vec<bool>>,
    root: usize,
    /// The kind of a material.
    material: usize,
    /// The kind of each placement's object, by index into [`PLACEMENTS`].
    placed: Vec<usize>,
    /// The placements of each extension, by name.
    by_extension: HashMap<&'static str, Vec<usize>>,
}

/// The schema files that describe no object to walk into: an index, and the open `extensions`
/// and `extras` (whose members are walked as extension objects, or not at all).
fn is_leaf(name: &str) -> bool {
    matches!(
        name,
        "glTFid.schema.json" | "extension.schema.json" | "extras.schema.json"
    )
}

/// The schema file a property refers to for its objects, and whether it holds an array of them.
fn object_ref(property: &Value) -> Option<(&str, bool)> {
    // An object described in place, with properties of its own beside the schema it extends
    // (KHR_materials_variants' mappings), is not that schema's kind.
    if property.get("properties").is_some() {
        return None;
    }
    if let Some(target) = property.get("$ref").and_then(Value::as_str) {
        return Some((target, false));
    }
    if let Some([one]) = property
        .get("allOf")
        .and_then(Value::as_array)
        .map(Vec::as_slice)
    {
        if let Some(target) = one.get("$ref").and_then(Value::as_str) {
            return Some((target, false));
        }
    }
    let (target, _) = object_ref(property.get("items")?)?;
    Some((target, true))
}

struct ShapeBuilder {
    shapes: Vec<Shape>,
    known: HashMap<(usize, String), usize>,
}

/// An object a property describes in place (`properties` of its own, as KHR_materials_variants'
/// variants and mappings), and whether the property holds an array of them.
fn object_in_place(property: &Value) -> Option<(&Value, bool)> {
    if property.get("properties").is_some() {
        return Some((property, false));
    }
    let items = property.get("items")?;
    items.get("properties").is_some().then_some((items, true))
}

impl ShapeBuilder {
    /// The kind that file `name` describes, as seen from `folder`; `None` for a file that
    /// describes no object or is not there.
    fn shape(
        &mut self,
        folder: &'static [(&'static str, &'static str)],
        name: &str,
    ) -> Option<usize> {
        if is_leaf(name) {
            return None;
        }
        let text = schema_text(folder, name)?;
        // Files are told apart by their text's address: two extensions' `light.schema.json`
        // are different files.
        let key = (text.as_ptr() as usize, name.to_string());
        if let Some(&at) = self.known.get(&key) {
            return Some(at);
        }
        let schema: Value = serde_json::from_str(text).expect("compiled-in schemas are valid JSON");
        Some(self.shape_of(folder, key, name.to_string(), &schema))
    }

    /// The kind `schema` describes, known by `key` (its file's, or for an object described in
    /// place its file's and its place there) and called `name`: a file's name, or for an
    /// object described in place its holder's kind and the property (`glTF.KHR_materials_
    /// variants.variants`).
    fn shape_of(
        &mut self,
        folder: &'static [(&'static str, &'static str)],
        key: (usize, String),
        name: String,
        schema: &Value,
    ) -> usize {
        let at = self.shapes.len();
        self.shapes.push(Shape {
            is: vec![name.clone()],
            children: Vec::new(),
            known: None,
        });
        self.known.insert(key.clone(), at);
        let mut is = vec![name.clone()];
        let mut children = Vec::new();
        let mut known: Option<Vec<String>> = match schema.get("additionalProperties") {
            None | Some(Value::Bool(false)) => Some(Vec::new()),
            Some(_) => None,
        };
        for base in schema
            .get("allOf")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|part| part.get("$ref").and_then(Value::as_str))
        {
            if let Some(base) = self.shape(folder, base) {
                is.extend(self.shapes[base].is.iter().cloned());
                children.extend(self.shapes[base].children.iter().cloned());
                match (&mut known, &self.shapes[base].known) {
                    (Some(own), Some(inherited)) => own.extend(inherited.iter().cloned()),
                    _ => known = None,
                }
            }
        }
        for (property, sub) in schema
            .get("properties")
            .and_then(Value::as_object)
            .into_iter()
            .flatten()
        {
            if let Some(own) = &mut known {
                own.push(property.clone());
            }
            let child = if let Some((target, array)) = object_ref(sub) {
                self.shape(folder, target).map(|child| (child, array))
            } else if let Some((object, array)) = object_in_place(sub) {
                let holder = name.strip_suffix(".schema.json").unwrap_or(&name);
                let place = (key.0, format!("{}#/properties/{property}", key.1));
                let child = match self.known.get(&place) {
                    Some(&child) => child,
                    None => self.shape_of(folder, place, format!("{holder}.{property}"), object),
                };
                Some((child, array))
            } else {
                None
            };
            if let Some((child, array)) = child {
                children.retain(|(name, _, _)| name != property);
                children.push((property.clone(), child, array));
            }
        }
        if let Some(own) = &mut known {
            own.sort();
            own.dedup();
        }
        self.shapes[at] = Shape {
            is,
            children,
            known,
        };
        at
    }
}

static SHAPES: LazyLock<Shapes> = LazyLock::new(|| {
    let mut builder = ShapeBuilder {
        shapes: Vec::new(),
        known: HashMap::new(),
    };
    let root = builder
        .shape(&[], "glTF.schema.json")
        .expect("the core schemas describe the root");
    let material = builder
        .shape(&[], "material.schema.json")
        .expect("the core schemas describe a material");
    let mut by_extension: HashMap<&'static str, Vec<usize>> = HashMap::new();
    let placed = PLACEMENTS
        .iter()
        .enumerate()
        .map(|(i, p)| {
            by_extension.entry(p.extension).or_default().push(i);
            builder
                .shape(folder_of(p.extension), p.schema)
                .unwrap_or_else(|| panic!("{} has no schema file {}", p.extension, p.schema))
        })
        .collect();
    let shapes = builder.shapes;
    let is = |shape: &Shape, file: &str| shape.is.iter().any(|f| f == file);
    let fit = shapes
        .iter()
        .map(|shape| {
            PLACEMENTS
                .iter()
                .map(|p| {
                    p.on.iter().any(|kind| {
                        shape
                            .is
                            .iter()
                            .any(|file| file.strip_suffix(".schema.json") == Some(*kind))
                    })
                })
                .collect()
        })
        .collect();
    Shapes {
        texture_info: shapes
            .iter()
            .map(|s| is(s, "textureInfo.schema.json"))
            .collect(),
        normal_texture_info: shapes
            .iter()
            .map(|s| is(s, "material.normalTextureInfo.schema.json"))
            .collect(),
        fit,
        shapes,
        root,
        material,
        placed,
        by_extension,
    }
});

/// Reads the kinds of objects from the schemas now, if no document has needed them yet.
pub fn prepare() {
    LazyLock::force(&SHAPES);
}

/// The kinds of objects, read from the schemas on first use.
pub(crate) fn shapes() -> &'static Shapes {
    &SHAPES
}

impl Shapes {
    /// The kind of the document's root.
    pub(crate) fn root(&self) -> usize {
        self.root
    }

    /// The properties of kind `shape` that hold objects of a known kind: name, kind, whether
    /// an array of them.
    pub(crate) fn children(&self, shape: usize) -> &[(String, usize, bool)] {
        &self.shapes[shape].children
    }

    /// Whether kind `shape`'s schemas define property `key`; true for every key of a kind
    /// whose schema admits any.
    pub(crate) fn defines(&self, shape: usize, key: &str) -> bool {
        self.shapes[shape]
            .known
            .as_ref()
            .is_none_or(|known| known.binary_search_by(|k| k.as_str().cmp(key)).is_ok())
    }

    /// The kind of extension `name`'s object where it stands on an object of kind `on`, for
    /// an extension judged by a published schema there (not sheen and fuzz, which the layer
    /// schema check judges, nor one misplaced or without a schema).
    pub(crate) fn extension_object(&self, name: &str, on: usize) -> Option<usize> {
        if judged_as_layer(name) {
            return None;
        }
        let placements = self.by_extension.get(name)?;
        let placement = placements.iter().find(|p| self.fits(**p, on))?;
        Some(self.placed[*placement])
    }

    /// Whether placement `placement` may stand on an object of kind `shape`.
    fn fits(&self, placement: usize, shape: usize) -> bool {
        self.fit[shape][placement]
    }

    /// A kind's name as messages give it: its schema file's name without `.schema.json`.
    fn name(&self, shape: usize) -> &str {
        let file = &self.shapes[shape].is[0];
        file.strip_suffix(".schema.json").unwrap_or(file)
    }
}

/// The extension schemas of one run, each compiled when a document first uses it.
pub struct ExtensionSchemas {
    validators: Vec<OnceLock<jsonschema::Validator<TapeJson>>>,
}

impl Default for ExtensionSchemas {
    fn default() -> Self {
        ExtensionSchemas {
            validators: PLACEMENTS.iter().map(|_| OnceLock::new()).collect(),
        }
    }
}

impl ExtensionSchemas {
    /// The validator of placement `placement`, compiled on first use.
    fn validator(&self, placement: usize) -> &jsonschema::Validator<TapeJson> {
        self.validators[placement].get_or_init(|| compile(&PLACEMENTS[placement]))
    }
}

fn compile(placement: &Placement) -> jsonschema::Validator<TapeJson> {
    let mut files = HashMap::new();
    for (name, text) in folder_of(placement.extension) {
        let mut schema = serde_json::from_str(text).expect("compiled-in schemas are valid JSON");
        super::core::close_open_enums(&mut schema);
        files.insert(name.to_string(), schema);
    }
    let files = super::schema::FileRetriever::over_core(files);
    let root = files
        .file(placement.schema)
        .expect("every placement names a compiled-in schema")
        .clone();
    // Each file declares its draft (draft 4 or 2020-12), and is read as it declares.
    jsonschema::options_for::<TapeJson>()
        .with_retriever(files)
        // A JSON pointer (KHR_animation_pointer) is judged by its format; URIs are the
        // resources rule's to judge, which knows what a glTF URI may be.
        .should_validate_formats(true)
        .with_format("iri-reference", |_: &str| true)
        .with_format("uri-reference", |_: &str| true)
        .with_format("uri", |_: &str| true)
        .with_format("iri", |_: &str| true)
        .build(&root)
        .unwrap_or_else(|e| panic!("{} does not compile: {e}", placement.schema))
}

pub struct ExtensionObjects;

impl Rule for ExtensionObjects {
    fn cost(&self) -> u32 {
        2
    }

    /// Where each extension object stands and what it holds: the kinds of the objects that
    /// hold them come from the paths to them.
    fn reads(&self) -> super::Reads {
        super::Reads::Extensions
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&UNEXPECTED_EXTENSION_OBJECT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        // Every `extensions` object, found by one scan of the index; the walk enters only
        // values that hold one.
        let found: Vec<Node> = json.members_named("extensions").collect();
        if found.is_empty() {
            return;
        }
        // When the only extensions with a schema are sheen and fuzz, each on a material (the
        // layers found them there), nothing is out of place and nothing is left to judge.
        let shapes = &*SHAPES;
        let mut layer_keys = 0;
        let mut others = false;
        for extensions in &found {
            for (name, _) in extensions.as_object().into_iter().flat_map(|o| o.iter()) {
                if judged_as_layer(&name) {
                    layer_keys += 1;
                } else if shapes.by_extension.contains_key(name.as_ref())
                    || OBJECTLESS.contains(&name.as_ref())
                {
                    others = true;
                }
            }
        }
        if !others && layer_keys == cx.layer_object_count() {
            return;
        }
        let holders = found.iter().map(|e| e.span().start).collect();
        let mut walk = Walk {
            shapes,
            schemas: &cx.schemas.extensions,
            holders,
            path: String::new(),
            judged: HashMap::default(),
            out,
        };
        walk.object(json, shapes.root, 0);
    }
}

struct Walk<'r, 'a> {
    shapes: &'r Shapes,
    schemas: &'r ExtensionSchemas,
    holders: Vec<usize>,
    path: String,
    /// The findings on each distinct (placement, object text), pointers relative to the object.
    judged: HashMap<(usize, &'a str), Vec<Diagnostic>, foldhash::quality::RandomState>,
    out: &'r mut Vec<Diagnostic>,
}

/// Extension objects are never this deep in a real asset; a hostile one stops here.
const MAX_DEPTH: usize = 64;

impl<'a> Walk<'_, 'a> {
    /// Whether `value` holds an `extensions` object (its own or a descendant's).
    fn holds_extensions(&self, value: Node) -> bool {
        let span = value.span();
        let first = self.holders.partition_point(|start| *start < span.start);
        self.holders
            .get(first)
            .is_some_and(|start| *start < span.end)
    }

    fn object(&mut self, value: Node<'a>, shape: usize, depth: usize) {
        if depth > MAX_DEPTH || !self.holds_extensions(value) {
            return;
        }
        let Some(object) = value.as_object() else {
            return;
        };
        if let Some(extensions) = object.get("extensions").and_then(|e| e.as_object()) {
            for (name, extension) in extensions.iter() {
                let Some(placements) = self.shapes.by_extension.get(name.as_ref()) else {
                    if OBJECTLESS.contains(&name.as_ref()) {
                        self.out.push(Diagnostic::new(
                            &UNEXPECTED_EXTENSION_OBJECT,
                            format!("{}/extensions/{}", self.path, pointer::escape(&name)),
                            format!("{name} defines no extension object; it is only declared"),
                        ));
                    }
                    continue;
                };
                let len = self.path.len();
                self.path.push_str("/extensions/");
                self.path.push_str(&pointer::escape(&name));
                match placements.iter().find(|p| self.shapes.fits(**p, shape)) {
                    Some(&placement) => {
                        // One that is no object is the core schema's TYPE_MISMATCH.
                        if !judged_as_layer(&name) && extension.is_object() {
                            self.judge(placement, extension);
                        }
                        self.object(extension, self.shapes.placed[placement], depth + 1);
                    }
                    None => self.out.push(Diagnostic::new(
                        &UNEXPECTED_EXTENSION_OBJECT,
                        self.path.as_str(),
                        format!(
                            "{name} extends {}, not {}: loaders ignore it here",
                            kinds(placements),
                            self.shapes.name(shape)
                        ),
                    )),
                }
                self.path.truncate(len);
            }
        }
        let shapes = self.shapes;
        for (property, child, array) in &shapes.shapes[shape].children {
            let Some(member) = object.get(property) else {
                continue;
            };
            let len = self.path.len();
            self.path.push('/');
            self.path.push_str(&pointer::escape(property));
            if *array {
                for (i, element) in super::elements(Some(member)).enumerate() {
                    let len = self.path.len();
                    self.path.push('/');
                    self.path.push_str(&i.to_string());
                    self.object(element, *child, depth + 1);
                    self.path.truncate(len);
                }
            } else {
                self.object(member, *child, depth + 1);
            }
            self.path.truncate(len);
        }
    }

    /// Judges an extension object by its placement's schema.
    fn judge(&mut self, placement: usize, value: Node<'a>) {
        let schemas = self.schemas;
        let found = self
            .judged
            .entry((placement, value.raw()))
            .or_insert_with(|| {
                let validator = schemas.validator(placement);
                let mut found = Vec::new();
                if !validator.is_valid(value) {
                    super::core::diagnostics(validator, value, &mut found);
                }
                found
            });
        let at = self.path.as_str();
        self.out.extend(found.iter().map(|d| Diagnostic {
            code: d.code,
            message: d.message.clone(),
            severity: d.severity,
            pointer: [at, d.pointer.as_str()].concat(),
            position: d.position,
        }));
    }
}

/// A texture a material reads: a textureInfo of the core or of one of the material's
/// extensions that has a schema (sheen and fuzz included).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MaterialTexture {
    /// Its pointer below the material (`/normalTexture`,
    /// `/extensions/KHR_materials_clearcoat/clearcoatNormalTexture`).
    pub pointer: String,
    /// The TEXCOORD set it reads (KHR_texture_transform's `texCoord` overrides its own).
    pub set: u64,
    /// Whether it is a normal texture (a `material.normalTextureInfo`), which needs a tangent
    /// space.
    pub normal: bool,
}

/// The keys a walk of the kinds asks objects for, numbered once for one document: a lookup by
/// number compares numbers, where a lookup by name hashes the name (for every property of
/// every material, most of the cost of finding a library's textures). `None` for a key the
/// document does not have, which no object holds.
pub struct WalkKeys {
    children: Vec<Vec<Option<KeyId>>>,
    extensions: Option<KeyId>,
}

impl WalkKeys {
    /// The keys of the document `node` belongs to.
    pub fn of(node: Node) -> WalkKeys {
        WalkKeys {
            children: SHAPES
                .shapes
                .iter()
                .map(|s| s.children.iter().map(|(p, _, _)| node.key_id(p)).collect())
                .collect(),
            extensions: node.key_id("extensions"),
        }
    }
}

/// Every texture `material` reads, in the order its schemas walk them: the core's properties,
/// then its extensions'. `keys` are its document's ([`WalkKeys::of`]).
pub fn material_textures(material: Node, keys: &WalkKeys) -> Vec<MaterialTexture> {
    let shapes = &*SHAPES;
    let mut out = Vec::new();
    let mut path = String::new();
    textures_in(
        shapes,
        keys,
        material,
        shapes.material,
        &mut path,
        0,
        &mut out,
    );
    out
}

fn textures_in(
    shapes: &Shapes,
    keys: &WalkKeys,
    value: Node,
    shape: usize,
    path: &mut String,
    depth: usize,
    out: &mut Vec<MaterialTexture>,
) {
    let Some(object) = value.as_object() else {
        return;
    };
    if depth > MAX_DEPTH {
        return;
    }
    if shapes.texture_info[shape] {
        out.push(MaterialTexture {
            pointer: path.clone(),
            set: super::effective_tex_coord(value),
            normal: shapes.normal_texture_info[shape],
        });
    }
    for ((property, child, array), key) in shapes.shapes[shape]
        .children
        .iter()
        .zip(&keys.children[shape])
    {
        let Some(member) = key.and_then(|key| object.get_id(key)) else {
            continue;
        };
        let len = path.len();
        path.push('/');
        path.push_str(&pointer::escape(property));
        if *array {
            for (i, element) in member
                .as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .enumerate()
            {
                let len = path.len();
                path.push('/');
                path.push_str(&i.to_string());
                textures_in(shapes, keys, element, *child, path, depth + 1, out);
                path.truncate(len);
            }
        } else {
            textures_in(shapes, keys, member, *child, path, depth + 1, out);
        }
        path.truncate(len);
    }
    let extensions = keys.extensions.and_then(|key| object.get_id(key));
    if let Some(extensions) = extensions.and_then(|e| e.as_object()) {
        for (name, extension) in extensions.iter() {
            let Some(placement) = shapes
                .by_extension
                .get(name.as_ref())
                .and_then(|ps| ps.iter().find(|p| shapes.fits(**p, shape)))
            else {
                continue;
            };
            let len = path.len();
            path.push_str("/extensions/");
            path.push_str(&pointer::escape(&name));
            textures_in(
                shapes,
                keys,
                extension,
                shapes.placed[*placement],
                path,
                depth + 1,
                out,
            );
            path.truncate(len);
        }
    }
}

/// The kinds an extension's placements name, for messages: "material", "glTF or node".
fn kinds(placements: &[usize]) -> String {
    let names: Vec<&str> = placements
        .iter()
        .flat_map(|p| PLACEMENTS[*p].on.iter().copied())
        .collect();
    names.join(" or ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The placements whose kind is not the first part of their schema file's name, each with
    /// the reason the table gives.
    const RENAMED: &[&str] = &[
        "glTF.EXT_mesh_gpu_instancing.schema.json",
        "primitive.EXT_mesh_primitive_edge_visibility.schema.json",
        "EXT_mesh_primitive_restart.schema.json",
        "glTF.EXT_texture_webp.schema.json",
        "KHR_xmp_json_ld.schema.json",
    ];

    #[test]
    fn the_table_places_every_extension_schema_file_where_its_name_says_but_the_named_exceptions() {
        for (extension, files) in EXTENSION_FILES {
            // Every file named `<kind>.<extension>.schema.json` is a placement.
            for (file, _) in files.iter() {
                if file.contains(&format!(".{extension}.")) || file.starts_with(extension) {
                    let placement = PLACEMENTS
                        .iter()
                        .find(|p| p.schema == *file)
                        .unwrap_or_else(|| panic!("{file} is in no placement"));
                    assert_eq!(placement.extension, *extension);
                    if !RENAMED.contains(file) {
                        let kind = file.strip_suffix(&format!(".{extension}.schema.json"));
                        assert_eq!(placement.on, [kind.unwrap()], "{file}");
                    }
                }
            }
        }
        for placement in PLACEMENTS {
            // Each kind named is a core object (the root included).
            for kind in placement.on {
                assert!(
                    super::super::core::CORE_SCHEMAS
                        .iter()
                        .any(|(file, _)| *file == format!("{kind}.schema.json")),
                    "{}: {kind}",
                    placement.extension
                );
            }
        }
    }

    #[test]
    fn every_placement_compiles_and_finds_its_kind() {
        let schemas = ExtensionSchemas::default();
        for (i, placement) in PLACEMENTS.iter().enumerate() {
            if !judged_as_layer(placement.extension) {
                schemas.validator(i);
            }
            assert!(
                SHAPES.fits(i, shape_named(placement.on[0])),
                "{}",
                placement.schema
            );
        }
    }

    /// The findings of judging `object` by placement `extension` on `kind`, as (code, pointer,
    /// message), pointers relative to the object.
    fn judged(extension: &str, kind: &str, object: &str) -> Vec<(&'static str, String, String)> {
        let placement = (0..PLACEMENTS.len())
            .find(|p| PLACEMENTS[*p].extension == extension && PLACEMENTS[*p].on.contains(&kind))
            .unwrap();
        let tape = crate::asset::tape::Tape::build(object).unwrap();
        let mut out = Vec::new();
        super::super::core::diagnostics(
            ExtensionSchemas::default().validator(placement),
            tape.root(object),
            &mut out,
        );
        out.into_iter()
            .map(|d| (d.code, d.pointer, d.message))
            .collect()
    }

    #[test]
    fn extension_schema_errors_get_the_core_codes_with_messages_that_name_the_fault() {
        let found = |code: &'static str, pointer: &str, message: &str| {
            (code, pointer.to_string(), message.to_string())
        };
        // IOR: 0, or at least 1; 0.5 is in neither range.
        assert_eq!(
            judged("KHR_materials_ior", "material", r#"{"ior":0.5}"#),
            [found(
                "VALUE_NOT_IN_RANGE",
                "/ior",
                "0.5 is outside every range the schema allows"
            )]
        );
        // An IES profile is read from a uri or a bufferView, exactly one.
        assert_eq!(
            judged("EXT_lights_ies", "glTF", r#"{"lights":[{"mimeType":"x"}]}"#),
            [found(
                "ONE_OF_MISMATCH",
                "/lights/0",
                "exactly one of 'uri' and 'bufferView' must be defined"
            )]
        );
        assert_eq!(
            judged("KHR_lights_punctual", "glTF", r#"{"lights":[]}"#),
            [found("EMPTY_ENTITY", "/lights", "the array is empty")]
        );
        assert_eq!(
            judged(
                "KHR_animation_pointer",
                "animation.channel.target",
                r#"{"pointer":"nodes/0"}"#
            ),
            [found(
                "PATTERN_MISMATCH",
                "/pointer",
                "'nodes/0' is not a valid json-pointer"
            )]
        );
        assert_eq!(
            judged("KHR_lights_punctual", "node", r#"{"light":1e400}"#),
            [found(
                "TYPE_MISMATCH",
                "/light",
                "1e+400 is not of type 'integer'"
            )]
        );
    }

    fn shape_named(kind: &str) -> usize {
        let file = format!("{kind}.schema.json");
        (0..SHAPES.shapes.len())
            .find(|s| SHAPES.shapes[*s].is[0] == file)
            .unwrap_or_else(|| panic!("no kind {kind}"))
    }

    #[test]
    fn a_material_reads_the_textures_of_the_core_and_of_its_extensions() {
        let text = r#"{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":1}},
            "normalTexture":{"index":1},
            "extensions":{
                "KHR_materials_clearcoat":{"clearcoatNormalTexture":{"index":2,
                    "extensions":{"KHR_texture_transform":{"texCoord":3}}}},
                "KHR_materials_sheen":{"sheenColorTexture":{"index":0}},
                "VENDOR_unknown":{"someTexture":{"index":0}}}}"#;
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let found: Vec<(String, u64, bool)> =
            material_textures(tape.root(text), &WalkKeys::of(tape.root(text)))
                .into_iter()
                .map(|t| (t.pointer, t.set, t.normal))
                .collect();
        let texture = |p: &str, set, normal| (p.to_string(), set, normal);
        assert_eq!(
            found,
            [
                texture("/pbrMetallicRoughness/baseColorTexture", 1, false),
                texture("/normalTexture", 0, true),
                texture(
                    "/extensions/KHR_materials_clearcoat/clearcoatNormalTexture",
                    3,
                    true
                ),
                texture(
                    "/extensions/KHR_materials_sheen/sheenColorTexture",
                    0,
                    false
                ),
            ]
        );
    }
}
