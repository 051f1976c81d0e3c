//! Validation rules. Each rule is one unit in its own file: the codes it emits (name, default
//! severity, doc line), what it checks and why, and a test with a fixture that triggers it and a
//! twin that does not. [`REGISTRY`] is the one place rules are listed; `velvet codes`, the
//! table in docs/codes.md and report rule lists are generated from it.
//!
//! Rules read the asset and push diagnostics; they never change anything.

pub mod accessor_bounds;
pub mod accessor_declared_bounds;
pub mod accessor_usage;
pub mod accessors;
pub mod animation_data;
pub mod animations;
pub mod asset_version;
pub mod attributes;
pub mod buffer_views;
pub mod cameras;
pub mod clearcoat;
pub mod core;
pub mod data;
pub mod declaration;
pub mod disabled_layer;
pub mod exclusions;
pub mod extension_names;
pub mod extensions;
pub mod fallback;
pub mod fuzz_roughness_default;
pub mod fuzz_roughness_mapping;
pub mod image_size;
pub mod legacy_sheen;
pub mod lights;
pub mod materials;
pub mod node_tree;
pub mod nodes;
pub mod primitives;
pub mod references;
pub mod resources;
pub mod roughness_alpha;
pub mod schema;
pub mod skin_data;
pub mod skins;
pub mod sparse_data;
pub mod tangent_space;
pub mod texcoord;
pub mod texture_sources;
pub mod unexpected_property;
pub mod variants;
pub mod vertex_data;

use crate::asset::tape::Node;
use crate::asset::Asset;
use crate::diagnostics::{Code, Diagnostic};
use crate::layers::{self, FuzzView, SheenView};

/// What a rule sees: the asset and the schemas compiled for this run.
pub struct Context<'a> {
    pub asset: &'a Asset,
    pub schemas: &'a schema::Schemas,
    /// The sheen and fuzz objects, found and read once for every rule.
    layers: std::sync::OnceLock<Vec<Layer<'a>>>,
    /// The textures each material reads, found once for every rule.
    material_textures: std::sync::OnceLock<Vec<Vec<extensions::MaterialTexture>>>,
    /// The buffers, each read on the first rule that needs its data.
    buffers: std::sync::OnceLock<data::Buffers<'a>>,
    /// Whether the rules that read accessor data run (`--no-data` turns them off).
    read_data: bool,
}

impl<'a> Context<'a> {
    pub fn new(asset: &'a Asset, schemas: &'a schema::Schemas) -> Context<'a> {
        Context {
            asset,
            schemas,
            layers: std::sync::OnceLock::new(),
            material_textures: std::sync::OnceLock::new(),
            buffers: std::sync::OnceLock::new(),
            read_data: true,
        }
    }

    /// The same context, with the rules that read accessor data on or off.
    pub fn reading_data(mut self, on: bool) -> Context<'a> {
        self.read_data = on;
        self
    }

    /// Whether the rules that read accessor data run.
    pub fn reads_data(&self) -> bool {
        self.read_data
    }

    /// Buffer `index`, opened on first use and kept for every rule that reads data (each reads
    /// the parts it needs); `None` when it cannot be read (the resource rules report why).
    pub fn buffer(&self, index: usize) -> Option<&crate::asset::BufferData<'a>> {
        self.buffers
            .get_or_init(|| data::Buffers::new(elements(self.json().get("buffers")).count()))
            .get(self.asset, index)
    }

    /// The textures each material reads (core and extensions, see
    /// [`extensions::material_textures`]), by material index: found on first use, then shared.
    /// Only a material that holds an `index` key can read one, and only those are walked.
    pub fn material_textures(&self) -> &[Vec<extensions::MaterialTexture>] {
        self.material_textures.get_or_init(|| {
            let json = self.json();
            let indices: Vec<usize> = json
                .members_named("index")
                .map(|n| n.span().start)
                .collect();
            let keys = extensions::WalkKeys::of(json);
            materials(json)
                .map(|material| {
                    let span = material.span();
                    let first = indices.partition_point(|start| *start < span.start);
                    if indices.get(first).is_some_and(|start| *start < span.end) {
                        extensions::material_textures(material, &keys)
                    } else {
                        Vec::new()
                    }
                })
                .collect()
        })
    }

    /// Every mesh primitive drawn with a material that exists, with what its material reads:
    /// (mesh index, primitive index, the primitive, the material's index, its textures). A
    /// dangling material index is the references rule's finding, not these rules'.
    pub fn primitives_with_textures(
        &self,
    ) -> impl Iterator<Item = (usize, usize, Node<'a>, u64, &[extensions::MaterialTexture])> + '_
    {
        let textures = self.material_textures();
        elements(self.json().get("meshes"))
            .enumerate()
            .flat_map(|(m, mesh)| {
                elements(mesh.get("primitives"))
                    .enumerate()
                    .map(move |(p, primitive)| (m, p, primitive))
            })
            .filter_map(move |(m, p, primitive)| {
                let material = primitive.get("material").and_then(|v| v.as_u64())?;
                let reads = usize::try_from(material)
                    .ok()
                    .and_then(|i| textures.get(i))?;
                Some((m, p, primitive, material, reads.as_slice()))
            })
    }

    /// The document, read through the asset's index.
    pub fn json(&self) -> Node<'a> {
        self.asset.root()
    }

    /// Every sheen and fuzz object with its values, in material order (a material's sheen
    /// before its fuzz): found and read on first use, then shared by the rules, which read the
    /// same objects many times over.
    pub fn layers(&self) -> &[Layer<'a>] {
        self.layers.get_or_init(|| {
            // Counted first, so that the list is allocated once at its size (on a large
            // document, megabytes: backed by huge pages where the system has them).
            let mut layers = Vec::with_capacity(layer_objects(self.json()).count());
            crate::asset::pages::advise_huge(&mut layers);
            layers.extend(layer_objects(self.json()).map(|object| Layer {
                view: match object.extension {
                    layers::SHEEN => SheenView::read(object.value).map(View::Sheen),
                    _ => FuzzView::read(object.value).map(View::Fuzz),
                },
                object,
            }));
            layers
        })
    }

    /// How many layer objects the document has: from [`Context::layers`] once they are read,
    /// else counted without reading their values (a fix's trial may run no rule that reads
    /// them).
    pub fn layer_object_count(&self) -> usize {
        match self.layers.get() {
            Some(layers) => layers.len(),
            None => layer_objects(self.json()).count(),
        }
    }

    /// Which of the two layers (sheen, fuzz) the document's materials hold, read as
    /// [`Context::layer_object_count`] counts them.
    pub fn layer_extensions_present(&self) -> [bool; 2] {
        let mut present = [false, false];
        let mut note = |extension: &str| present[usize::from(extension == layers::FUZZ)] = true;
        match self.layers.get() {
            Some(read) => read.iter().for_each(|l| note(l.object.extension)),
            None => layer_objects(self.json()).for_each(|l| note(l.extension)),
        }
        present
    }

    /// [`layer_objects`] of the document, from [`Context::layers`].
    pub fn layer_objects(&self) -> impl Iterator<Item = LayerObject<Node<'a>>> + '_ {
        self.layers().iter().map(|l| l.object)
    }

    /// Each material that has a sheen or fuzz object, with the two read (`None` when absent or
    /// not an object).
    pub fn material_layers(&self) -> impl Iterator<Item = MaterialLayers<'_>> + '_ {
        let layers = self.layers();
        let mut at = 0;
        std::iter::from_fn(move || {
            let first = layers.get(at)?;
            let mut pair = MaterialLayers {
                material: first.object.material,
                sheen: None,
                fuzz: None,
            };
            while let Some(layer) = layers
                .get(at)
                .filter(|l| l.object.material == pair.material)
            {
                pair.sheen = pair.sheen.or(layer.sheen());
                pair.fuzz = pair.fuzz.or(layer.fuzz());
                at += 1;
            }
            Some(pair)
        })
    }
}

/// One sheen or fuzz object and its values (defaults applied); `None` for a value that is not
/// an object.
pub struct Layer<'a> {
    pub object: LayerObject<Node<'a>>,
    view: Option<View>,
}

/// A layer object's values: one of the two, kept in one place (a large document has tens of
/// thousands).
enum View {
    Sheen(SheenView),
    Fuzz(FuzzView),
}

impl Layer<'_> {
    /// The values of a KHR_materials_sheen object.
    pub fn sheen(&self) -> Option<&SheenView> {
        match &self.view {
            Some(View::Sheen(view)) => Some(view),
            _ => None,
        }
    }

    /// The values of a KHR_materials_fuzz object.
    pub fn fuzz(&self) -> Option<&FuzzView> {
        match &self.view {
            Some(View::Fuzz(view)) => Some(view),
            _ => None,
        }
    }
}

/// A material's sheen and fuzz, read.
pub struct MaterialLayers<'l> {
    pub material: usize,
    pub sheen: Option<&'l SheenView>,
    pub fuzz: Option<&'l FuzzView>,
}
/// The parts of a document a rule's findings depend on. A fix's trial validates the fixed
/// text again: a rule that reads nothing the fixes' edits touch gives the findings it gave the
/// file, and the trial takes them from the file's report instead of reading the data again.
#[derive(Debug, Clone, Copy)]
pub enum Reads {
    /// Anything in the document: the rule runs again after any edit.
    Document,
    /// Only the values of these top-level properties, less the `except` members of their
    /// elements (`("bufferViews", "target")`: no data check reads a view's target).
    Properties {
        properties: &'static [&'static str],
        except: &'static [(&'static str, &'static str)],
    },
    /// Only the values at the pointers `values` match, and which elements the arrays
    /// `elements` match hold (their number, not what is in them). In a pattern `*` stands for
    /// any key or array index and `*Suffix` for any key that ends so, as in the references
    /// rule's table (`/nodes/*/mesh`; `/animations/*/samplers`).
    Places {
        values: &'static [&'static str],
        elements: &'static [&'static str],
    },
    /// Only the extension objects (where each stands and what it holds) and the names
    /// `extensionsUsed` and `extensionsRequired` list. An edit touches them when it is at the
    /// root, at or inside one of those lists or an `extensions` object, or brings, takes away
    /// or moves an extension object ([`EditPath::keeping_extensions`] says it does none of
    /// these): a fix of a buffer view's target leaves a library's 20,000 extension objects as
    /// they were, and the rules that judge them give the file's findings again.
    Extensions,
}

impl Reads {
    /// Every value of these top-level properties.
    pub const fn properties(properties: &'static [&'static str]) -> Reads {
        Reads::Properties {
            properties,
            except: &[],
        }
    }

    /// Whether an edit at JSON pointer `pointer` may change what the rule reads; an edit of an
    /// excepted member counts only where `element_exists` says the element it is in (the
    /// pointer's first two tokens) is already there, since a set creates what it misses.
    pub fn touched_by(&self, pointer: &str, element_exists: impl Fn(&str) -> bool) -> bool {
        self.touched_by_path(&EditPath::of(pointer), element_exists)
    }

    /// [`Reads::touched_by`] of an edit whose path is split already: a fix's trial asks it of
    /// every rule for each edit.
    pub fn touched_by_path(&self, edit: &EditPath, element_exists: impl Fn(&str) -> bool) -> bool {
        let (properties, except) = match self {
            Reads::Document => return true,
            Reads::Places { values, elements } => {
                return places_touched_by(values, elements, &edit.tokens);
            }
            Reads::Extensions => {
                let lists = ["extensionsUsed", "extensionsRequired"];
                return !edit.keeps_extensions
                    || edit
                        .tokens
                        .first()
                        .is_none_or(|p| lists.contains(&p.as_ref()))
                    || edit.tokens.iter().any(|token| token == "extensions");
            }
            Reads::Properties { properties, except } => (properties, except),
        };
        let Some(property) = edit.tokens.first() else {
            // The whole document.
            return true;
        };
        if !properties.contains(&property.as_ref()) {
            return false;
        }
        match (edit.tokens.get(2), edit.element_end) {
            (Some(member), Some(end)) if except.contains(&(property.as_ref(), member.as_ref())) => {
                // The element's pointer is where the edit's begins: `/{property}/{index}`.
                !element_exists(&edit.pointer[..end])
            }
            _ => true,
        }
    }
}

/// An edit's JSON pointer with its tokens unescaped, split once for all the rules asked
/// whether it touches what they read.
pub struct EditPath<'p> {
    pointer: &'p str,
    tokens: Vec<std::borrow::Cow<'p, str>>,
    /// Where `/{property}/{index}` ends in the pointer, when the edit lies below it.
    element_end: Option<usize>,
    /// Whether the edit is known to leave every extension object where it was.
    keeps_extensions: bool,
}

impl<'p> EditPath<'p> {
    pub fn of(pointer: &'p str) -> EditPath<'p> {
        let raw: Vec<&str> = pointer.split('/').skip(1).collect();
        EditPath {
            pointer,
            tokens: raw
                .iter()
                .map(|token| crate::asset::pointer::unescape(token))
                .collect(),
            element_end: (raw.len() >= 3).then(|| raw[0].len() + raw[1].len() + 2),
            keeps_extensions: false,
        }
    }

    /// The path of an edit that, as its caller knows, brings no extension object, takes none
    /// away and moves none (no element of an array before one shifts): what it sets and what
    /// it replaces or removes hold no `extensions` member at any depth, and it removes no
    /// array element. A path made by [`EditPath::of`] is not known to.
    pub fn keeping_extensions(mut self, keeps: bool) -> EditPath<'p> {
        self.keeps_extensions = keeps;
        self
    }
}

/// Whether an edit at the path `tokens` may change a value at a place `values` match (the
/// edit is at or above such a place, which it may create, remove or replace, or inside one)
/// or the elements an array `elements` matches holds (the edit is at or above one of its
/// elements).
fn places_touched_by(values: &[&str], elements: &[&str], tokens: &[std::borrow::Cow<str>]) -> bool {
    // Whether the edit's path and the pattern's agree as far as both go. A pattern is split
    // on bytes: its segments are a few bytes long, shorter than a search for '/' is worth.
    let agrees = |pattern: &str| {
        pattern
            .as_bytes()
            .split(|b| *b == b'/')
            .skip(1)
            .zip(tokens)
            .all(|(segment, token)| match segment.strip_prefix(b"*") {
                Some(b"") => true,
                Some(suffix) => token.as_bytes().ends_with(suffix),
                None => segment == token.as_bytes(),
            })
    };
    values.iter().any(|pattern| agrees(pattern))
        || elements.iter().any(|array| {
            // At or above the array's elements: no deeper than one token past the array.
            tokens.len() <= array.bytes().filter(|b| *b == b'/').count() + 1 && agrees(array)
        })
}

/// A validation rule.
pub trait Rule: Sync {
    /// The codes this rule may emit.
    fn codes(&self) -> &'static [&'static Code];
    /// Checks the asset, pushing what it finds.
    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>);
    /// How long the rule takes on a large document, relative to the others (1: a walk of the
    /// layers, or less), as timed one rule at a time on the 20,000-material benchmark document.
    /// Rules run side by side start with the dearest, so that the cores finish together, and
    /// so that the rules that read the layers do not wait while the first of them reads them
    /// (see [`Context::layers`]): the layer schema check reads them first, and the core
    /// schema check, which does not read them, starts beside it.
    fn cost(&self) -> u32 {
        1
    }
    /// What the rule's findings depend on (see [`Reads`]); a rule that says nothing depends on
    /// the whole document.
    fn reads(&self) -> Reads {
        Reads::Document
    }
    /// For a rule that judges each element of the root's arrays by that element alone, and
    /// whose findings elsewhere do not depend on it: whether the element `value` at `element`
    /// of the document `cx` gives no finding, judged by itself. A rule that cannot judge an
    /// element alone says no (the default), and runs again whenever its reads are touched.
    fn passes_alone(&self, cx: &Context, element: &ElementPlace, value: Node) -> bool {
        let _ = (cx, element, value);
        false
    }
}

/// For a rule whose reads a fix's edits touched, all inside the elements `elements` that the
/// file has of the root's arrays: whether its findings on the file are its findings on the
/// fixed document `cx`. They are when the file's findings of the rule held none at or inside
/// those elements (`found_inside`) and each fixed element passes alone
/// ([`Rule::passes_alone`]).
pub fn findings_hold_inside(
    rule: &dyn Rule,
    cx: &Context,
    elements: &[ElementPlace],
    found_inside: &dyn Fn(&ElementPlace) -> bool,
) -> bool {
    elements.iter().all(|element| {
        !found_inside(element)
            && element
                .in_document(cx.json())
                .is_some_and(|value| rule.passes_alone(cx, element, value))
    })
}

/// An element of a top-level array (`/bufferViews/1`) that a fix edits inside.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ElementPlace {
    pub property: String,
    pub index: usize,
}

impl ElementPlace {
    /// The element an edit at `pointer` lies inside, when `pointer` goes below an element the
    /// document `json` has of a top-level array (`/bufferViews/1/target`; not `/bufferViews/1`
    /// itself, whose removal or replacement moves or reshapes the array).
    pub fn of_edit(json: Node, pointer: &str) -> Option<ElementPlace> {
        let mut tokens = pointer.split('/').skip(1);
        let property = crate::asset::pointer::unescape(tokens.next()?);
        // An array index as a pointer writes it (no sign, no leading zero).
        let index = crate::asset::pointer::array_index(tokens.next()?)?;
        tokens.next()?;
        (index < json.get(property.as_ref())?.as_array()?.len()).then(|| ElementPlace {
            property: property.into_owned(),
            index,
        })
    }

    /// Whether `diagnostic` stands at this element or inside it.
    pub fn holds(&self, diagnostic: &Diagnostic) -> bool {
        let at = &diagnostic.pointer;
        at.strip_prefix('/')
            .and_then(|rest| rest.strip_prefix(&crate::asset::pointer::escape(&self.property)[..]))
            .and_then(|rest| rest.strip_prefix('/'))
            .and_then(|rest| rest.strip_prefix(&self.index.to_string()[..]))
            .is_some_and(|rest| rest.is_empty() || rest.starts_with('/'))
    }

    /// The element in the document `json`.
    pub fn in_document<'a>(&self, json: Node<'a>) -> Option<Node<'a>> {
        json.get(&self.property)?.as_array()?.get(self.index)
    }
}

/// Every rule, in the order their findings are reported.
pub static REGISTRY: &[&dyn Rule] = &[
    &core::CoreStructure,
    &schema::SchemaCheck,
    &asset_version::AssetVersion,
    &declaration::Declaration,
    &extensions::ExtensionObjects,
    &unexpected_property::UnexpectedProperty,
    &extension_names::ExtensionNames,
    &lights::Lights,
    &exclusions::Exclusions,
    &references::References,
    &attributes::Attributes,
    &accessors::Accessors,
    &accessor_declared_bounds::AccessorDeclaredBounds,
    &accessor_usage::AccessorUsage,
    &accessor_bounds::AccessorBounds,
    &vertex_data::VertexData,
    &animation_data::AnimationData,
    &skin_data::SkinData,
    &sparse_data::SparseData,
    &buffer_views::BufferViews,
    &node_tree::NodeTree,
    &nodes::Nodes,
    &primitives::Primitives,
    &animations::Animations,
    &cameras::Cameras,
    &materials::Materials,
    &variants::Variants,
    &resources::Resources,
    &texture_sources::TextureSources,
    &texcoord::TexCoords,
    &tangent_space::TangentSpace,
    &skins::Skins,
    &disabled_layer::DisabledLayer,
    &roughness_alpha::RoughnessAlpha,
    &image_size::ImageSize,
    &fallback::Fallback,
    &fuzz_roughness_mapping::FuzzRoughnessMapping,
    &fuzz_roughness_default::FuzzRoughnessDefault,
    &legacy_sheen::LegacySheen,
    &clearcoat::Clearcoat,
];

/// Every code velvet can emit, loader and schema codes first, then the rules' codes in
/// registry order. Each name appears once.
pub fn all_codes() -> Vec<&'static Code> {
    let mut out: Vec<&'static Code> = Vec::new();
    for code in crate::diagnostics::codes::LOADER
        .iter()
        .chain(crate::diagnostics::codes::SCHEMA)
        .chain(crate::diagnostics::codes::RUN)
        .copied()
        .chain(REGISTRY.iter().flat_map(|r| r.codes().iter().copied()))
    {
        if !out.iter().any(|c| c.name == code.name) {
            out.push(code);
        }
    }
    out
}

/// Looks a code up by name.
pub fn find_code(name: &str) -> Option<&'static Code> {
    all_codes().into_iter().find(|c| c.name == name)
}

pub use crate::document::{
    declares, effective_tex_coord, element_at, elements, materials, texture_sources,
};
pub use crate::layers::{as_index, layer_objects, slot_pointer, slot_uses, LayerObject, SlotUse};

/// The findings of `rule` alone on the document `text`, as "CODE pointer" lines: the rules'
/// unit tests read them.
#[cfg(test)]
pub(crate) fn findings_of(rule: &dyn Rule, text: &str) -> Vec<String> {
    diagnostics_of(rule, text)
        .into_iter()
        .map(|d| format!("{} {}", d.code, d.pointer))
        .collect()
}

/// The fixture documents of every code's folder (`fixtures/validate/<CODE>/`) whose file name
/// ends in one of `extensions`, in path order: the tests that hold a mechanism to every
/// fixture walk them.
#[cfg(test)]
pub(crate) fn fixture_documents(extensions: &[&str]) -> Vec<std::path::PathBuf> {
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/validate");
    let mut documents: Vec<std::path::PathBuf> = std::fs::read_dir(&fixtures)
        .expect("the fixtures are there")
        .flat_map(|folder| std::fs::read_dir(folder.expect("a fixture folder").path()))
        .flatten()
        .map(|e| e.expect("a fixture").path())
        .filter(|p| {
            p.extension()
                .is_some_and(|e| extensions.iter().any(|x| e == *x))
        })
        .collect();
    documents.sort();
    documents
}

/// [`findings_of`] with each finding's message: "CODE pointer message".
#[cfg(test)]
pub(crate) fn findings_with_messages_of(rule: &dyn Rule, text: &str) -> Vec<String> {
    diagnostics_of(rule, text)
        .into_iter()
        .map(|d| format!("{} {} {}", d.code, d.pointer, d.message))
        .collect()
}

/// What `rule` finds in the document `text` (read as `t.gltf`).
#[cfg(test)]
fn diagnostics_of(rule: &dyn Rule, text: &str) -> Vec<Diagnostic> {
    let loaded = crate::asset::load_bytes_with(
        std::path::Path::new("t.gltf"),
        text.as_bytes(),
        &crate::asset::LoadOptions::default(),
    );
    let asset = loaded.asset.expect("the document parses");
    let schemas = schema::Schemas::builtin();
    let cx = Context::new(&asset, &schemas);
    let mut out = Vec::new();
    rule.check(&cx, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::{load_bytes_with, LoadOptions};

    #[test]
    fn material_layers_pair_each_materials_sheen_and_fuzz_as_read() {
        let text = r#"{"asset":{"version":"2.0"},"materials":[
            {"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":0.25}}},
            {},
            {"extensions":{"KHR_materials_fuzz":{"fuzzFactor":1},"KHR_materials_sheen":{"sheenColorFactor":[1,1,1]}}},
            {"extensions":{"KHR_materials_fuzz":7}},
            {"extensions":{"KHR_materials_fuzz":{"fuzzRoughnessFactor":0.5}}}
        ]}"#;
        let loaded = load_bytes_with(
            std::path::Path::new("pairs.gltf"),
            text.as_bytes(),
            &LoadOptions::default(),
        );
        let asset = loaded.asset.expect("the document parses");
        let schemas = schema::Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let pairs: Vec<(usize, Option<f64>, Option<f64>)> = cx
            .material_layers()
            .map(|p| {
                (
                    p.material,
                    p.sheen.map(|s| s.roughness_factor + s.color_factor[0]),
                    p.fuzz
                        .map(|f| f.factor + f.roughness_factor.unwrap_or(-1.0)),
                )
            })
            .collect();
        assert_eq!(
            pairs,
            [
                (0, Some(0.25), None),
                (2, Some(1.0), Some(0.0)),
                (3, None, None),
                (4, None, Some(0.5)),
            ]
        );
        let objects: Vec<(usize, &str)> = cx
            .layer_objects()
            .map(|l| (l.material, l.extension))
            .collect();
        assert_eq!(
            objects,
            [
                (0, layers::SHEEN),
                (2, layers::SHEEN),
                (2, layers::FUZZ),
                (3, layers::FUZZ),
                (4, layers::FUZZ)
            ]
        );
    }
}
