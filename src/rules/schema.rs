//! The schema check: every KHR_materials_sheen and KHR_materials_fuzz object is validated
//! against our JSON schemas in `schema/` (compiled into the binary, or read from
//! `--schema-dir`), built once per run. Each schema error becomes a code with a pointer into the
//! document. The published schemas do not forbid unknown properties, so those are found here by
//! comparing keys with the properties the schemas define, and reported as warnings.

use super::{Context, LayerObject, Rule};
use crate::asset::pointer;
use crate::asset::tape::Node;
use crate::asset::tape_schema::TapeJson;
use crate::diagnostics::{codes, Code, Diagnostic};
use crate::layers;
use jsonschema::error::ValidationErrorKind;
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// Our schema files, by file name, as compiled into the binary.
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "material.KHR_materials_sheen.schema.json",
        include_str!("../../schema/material.KHR_materials_sheen.schema.json"),
    ),
    (
        "material.KHR_materials_fuzz.schema.json",
        include_str!("../../schema/material.KHR_materials_fuzz.schema.json"),
    ),
    (
        "textureInfo.schema.json",
        include_str!("../../schema/textureInfo.schema.json"),
    ),
    (
        "glTFProperty.schema.json",
        include_str!("../../schema/glTFProperty.schema.json"),
    ),
    (
        "glTFid.schema.json",
        include_str!("../../schema/glTFid.schema.json"),
    ),
    (
        "extension.schema.json",
        include_str!("../../schema/extension.schema.json"),
    ),
    (
        "extras.schema.json",
        include_str!("../../schema/extras.schema.json"),
    ),
];

#[derive(Debug, thiserror::Error)]
pub enum SchemaError {
    #[error("cannot read schema {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("schema {name} is not valid JSON: {source}")]
    Json {
        name: String,
        source: serde_json::Error,
    },
    #[error("schema {name} does not compile: {message}")]
    Compile { name: String, message: String },
}

/// Known property names of an object schema, and the same for properties that are objects
/// with their own known properties (textureInfo). Lists, searched in order: a layer's schema
/// names a handful, and every member of every layer object is looked up (with std's map, its
/// SipHash took a percent of validating the library).
#[derive(Debug, Default)]
struct PropertyTree {
    known: Vec<String>,
    children: Vec<(String, PropertyTree)>,
}

impl PropertyTree {
    fn knows(&self, key: &str) -> bool {
        self.known.iter().any(|known| known == key)
    }

    fn child(&self, key: &str) -> Option<&PropertyTree> {
        self.children
            .iter()
            .find_map(|(name, child)| (name == key).then_some(child))
    }
}

struct LayerSchema {
    validator: jsonschema::Validator<TapeJson>,
    properties: PropertyTree,
}

/// The compiled schemas for one run.
pub struct Schemas {
    sheen: LayerSchema,
    fuzz: LayerSchema,
    /// The official glTF 2.0 schemas (always the built-in files), compiled on first use
    /// ([`Schemas::core`]) or by a job of the run ([`Schemas::with_core`]).
    core: Arc<OnceLock<super::core::CoreSchema>>,
    /// The published extension schemas (always the built-in files), compiled on first use.
    pub extensions: super::extensions::ExtensionSchemas,
}

/// Serves `$ref`s from in-memory schema files, by the reference's last path segment: its own
/// files first, then the core schema files, shared rather than copied into each retriever.
pub(crate) struct FileRetriever {
    files: Arc<HashMap<String, Value>>,
    core: Option<Arc<HashMap<String, Value>>>,
}

impl FileRetriever {
    /// Serves `files` alone.
    pub(crate) fn new(files: Arc<HashMap<String, Value>>) -> FileRetriever {
        FileRetriever { files, core: None }
    }

    /// Serves `files`, and the core schema files that `files` does not name.
    pub(crate) fn over_core(files: HashMap<String, Value>) -> FileRetriever {
        FileRetriever {
            files: Arc::new(files),
            core: Some(Arc::clone(&super::core::CORE_FILES)),
        }
    }

    /// The file named `name`.
    pub(crate) fn file(&self, name: &str) -> Option<&Value> {
        self.files
            .get(name)
            .or_else(|| self.core.as_ref()?.get(name))
    }
}

impl jsonschema::Retrieve for FileRetriever {
    fn retrieve(
        &self,
        uri: &jsonschema::Uri<String>,
    ) -> Result<Value, Box<dyn std::error::Error + Send + Sync>> {
        let name = uri.path().as_str().rsplit('/').next().unwrap_or_default();
        self.file(name)
            .cloned()
            .ok_or_else(|| format!("no schema file named '{name}'").into())
    }
}

impl Schemas {
    /// The schemas compiled into velvet.
    pub fn builtin() -> Schemas {
        Schemas::with_core(Arc::new(OnceLock::new()))
    }

    /// The schemas compiled into velvet, the core schema taken from `core` once something
    /// compiles it there: a run compiles it on one worker while another compiles the rest
    /// (the core schema is three quarters of the work, some 3 ms).
    pub fn with_core(core: Arc<OnceLock<super::core::CoreSchema>>) -> Schemas {
        if core.get().is_none() {
            // While the core schema's job parses its files, the validator of their
            // meta-schema, which jsonschema builds once per process before it compiles them,
            // is built here (1.3 of the core schema's 3.3 ms).
            super::core::prepare_meta_schema();
        }
        let files = BUILTIN
            .iter()
            .map(|(name, text)| {
                (
                    name.to_string(),
                    serde_json::from_str(text).expect("built-in schemas are valid JSON"),
                )
            })
            .collect();
        Schemas::compile(files, core).expect("built-in schemas compile")
    }

    /// The built-in schemas with every file present in `dir` (same file names) replacing its
    /// built-in twin.
    pub fn with_overrides(dir: &Path) -> Result<Schemas, SchemaError> {
        let mut files = HashMap::new();
        std::fs::read_dir(dir).map_err(|source| SchemaError::Read {
            path: dir.display().to_string(),
            source,
        })?;
        for (name, text) in BUILTIN {
            let path = dir.join(name);
            let (text, name) = if path.is_file() {
                let text = std::fs::read_to_string(&path).map_err(|source| SchemaError::Read {
                    path: path.display().to_string(),
                    source,
                })?;
                (text, path.display().to_string())
            } else {
                (text.to_string(), name.to_string())
            };
            let value = serde_json::from_str(&text).map_err(|source| SchemaError::Json {
                name: name.clone(),
                source,
            })?;
            files.insert(
                path.file_name().unwrap().to_string_lossy().into_owned(),
                value,
            );
        }
        Schemas::compile(files, Arc::new(OnceLock::new()))
    }

    /// The core schema, compiled here if nothing has compiled it yet.
    pub fn core(&self) -> &super::core::CoreSchema {
        self.core.get_or_init(super::core::CoreSchema::builtin)
    }

    fn compile(
        files: HashMap<String, Value>,
        core: Arc<OnceLock<super::core::CoreSchema>>,
    ) -> Result<Schemas, SchemaError> {
        let files = Arc::new(files);
        let layer = |name: &str| -> Result<LayerSchema, SchemaError> {
            let schema = &files[name];
            let validator = jsonschema::options_for::<TapeJson>()
                .with_draft(jsonschema::Draft::Draft4)
                .with_retriever(FileRetriever::new(files.clone()))
                .build(schema)
                .map_err(|e| SchemaError::Compile {
                    name: name.to_string(),
                    message: e.to_string(),
                })?;
            Ok(LayerSchema {
                validator,
                properties: property_tree(schema, &files, 0),
            })
        };
        Ok(Schemas {
            sheen: layer("material.KHR_materials_sheen.schema.json")?,
            fuzz: layer("material.KHR_materials_fuzz.schema.json")?,
            core,
            extensions: super::extensions::ExtensionSchemas::default(),
        })
    }
}

/// Collects the properties a schema defines, through `allOf` and `$ref`.
fn collect(
    schema: &Value,
    files: &HashMap<String, Value>,
    depth: usize,
    out: &mut Vec<(String, Value)>,
) {
    if depth > 16 {
        return;
    }
    if let Some(target) = schema.get("$ref").and_then(Value::as_str) {
        let name = target.rsplit('/').next().unwrap_or(target);
        if let Some(referenced) = files.get(name) {
            collect(referenced, files, depth + 1, out);
        }
    }
    for part in schema
        .get("allOf")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        collect(part, files, depth + 1, out);
    }
    if let Some(props) = schema.get("properties").and_then(Value::as_object) {
        out.extend(props.iter().map(|(k, v)| (k.clone(), v.clone())));
    }
}

fn property_tree(schema: &Value, files: &HashMap<String, Value>, depth: usize) -> PropertyTree {
    let mut props = Vec::new();
    collect(schema, files, depth, &mut props);
    let mut tree = PropertyTree::default();
    for (name, sub) in props {
        if !tree.knows(&name) {
            tree.known.push(name.clone());
        }
        if depth < 4 {
            let child = property_tree(&sub, files, depth + 1);
            // Only objects with a closed set of known properties are checked (not extensions
            // or extras, whose keys are open). A name defined again (through `allOf`) takes
            // its last definition.
            if !child.known.is_empty() {
                tree.children.retain(|(known, _)| *known != name);
                tree.children.push((name, child));
            }
        }
    }
    tree
}

fn unexpected(value: Node, tree: &PropertyTree, at: &str, out: &mut Vec<Diagnostic>) {
    let Some(obj) = value.as_object() else { return };
    for (key, child) in obj.iter() {
        let key = key.as_ref();
        if !tree.knows(key) {
            out.push(Diagnostic::new(
                &codes::UNEXPECTED_PROPERTY,
                pointer::join(at, key),
                format!("unexpected property '{key}'"),
            ));
        } else if let Some(sub) = tree.child(key) {
            unexpected(child, sub, &pointer::join(at, key), out);
        }
    }
}

fn code_for(kind: &ValidationErrorKind) -> &'static Code {
    match kind {
        ValidationErrorKind::Type { .. } => &codes::TYPE_MISMATCH,
        ValidationErrorKind::Minimum { .. }
        | ValidationErrorKind::Maximum { .. }
        | ValidationErrorKind::ExclusiveMinimum { .. }
        | ValidationErrorKind::ExclusiveMaximum { .. } => &codes::VALUE_NOT_IN_RANGE,
        ValidationErrorKind::MinItems { .. } | ValidationErrorKind::MaxItems { .. } => {
            &codes::ARRAY_LENGTH_NOT_IN_LIST
        }
        ValidationErrorKind::Required { .. } => &codes::UNDEFINED_PROPERTY,
        ValidationErrorKind::Enum { .. } | ValidationErrorKind::Constant { .. } => {
            &codes::VALUE_NOT_IN_LIST
        }
        ValidationErrorKind::AdditionalProperties { .. } => &codes::UNEXPECTED_PROPERTY,
        _ => &codes::SCHEMA_MISMATCH,
    }
}

pub struct SchemaCheck;

impl Rule for SchemaCheck {
    /// The layer objects, all in materials.
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    /// Among the dearest rules on a large document: every layer object against its schema.
    fn cost(&self) -> u32 {
        10
    }

    fn codes(&self) -> &'static [&'static Code] {
        codes::SCHEMA
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        // The findings on one object depend on its text alone, and libraries repeat the same
        // layer object on many materials: each distinct text is checked once, its findings kept
        // with pointers relative to the object. The texts are hashed with foldhash, seeded at
        // random for each map: with SipHash the map's lookups took a fifth of this rule's
        // instructions on a document of 20,000 materials (29 million; 9 with foldhash), and a
        // random seed keeps a crafted document from choosing collisions.
        // Sized for every object distinct: growing it rehashed each entry again and again.
        let mut checked: HashMap<(&str, &str), Vec<Diagnostic>, foldhash::quality::RandomState> =
            HashMap::with_capacity_and_hasher(cx.layers().len(), Default::default());
        for layer in cx.layer_objects() {
            let found = checked
                .entry((layer.extension, layer.value.raw()))
                .or_insert_with(|| check_layer(cx.schemas, &layer));
            if found.is_empty() {
                continue;
            }
            let at = layer.pointer();
            // Each field but the pointer copied: a clone of the whole finding would copy its
            // relative pointer only to drop it.
            out.extend(found.iter().map(|d| Diagnostic {
                code: d.code,
                message: d.message.clone(),
                severity: d.severity,
                pointer: [at.as_str(), d.pointer.as_str()].concat(),
                position: d.position,
            }));
        }
    }
}

/// The schema findings on one layer object, with pointers relative to it.
fn check_layer(schemas: &Schemas, layer: &LayerObject<Node>) -> Vec<Diagnostic> {
    let schema = if layer.extension == layers::SHEEN {
        &schemas.sheen
    } else {
        &schemas.fuzz
    };
    let mut out = Vec::new();
    // Most objects are valid, and the yes-or-no check is the cheaper walk.
    let errors = (!schema.validator.is_valid(layer.value))
        .then(|| schema.validator.iter_errors(layer.value));
    // The pointers of the values found out of range, each reported once (a set: a hostile
    // object may have many).
    let mut out_of_range = std::collections::HashSet::new();
    for error in errors.into_iter().flatten() {
        let code = match error.kind() {
            // A number past f64's range fails its type: it is out of range, reported once.
            ValidationErrorKind::Type { .. } if super::core::is_non_finite(error.instance()) => {
                &codes::VALUE_NOT_IN_RANGE
            }
            kind => code_for(kind),
        };
        let at = error.instance_path().as_str();
        if code.name == codes::VALUE_NOT_IN_RANGE.name && !out_of_range.insert(at.to_string()) {
            continue;
        }
        out.push(Diagnostic::new(code, at, error.to_string()));
    }
    let before = out.len();
    unexpected(layer.value, &schema.properties, "", &mut out);
    if layer.extension == layers::SHEEN && out.len() > before {
        // A property of the sheen draft is one fault, reported by the legacy rule under its
        // more specific code, not here as well.
        let legacy: Vec<String> = super::legacy_sheen::LEGACY_PROPERTIES
            .iter()
            .map(|name| pointer::join("", name))
            .collect();
        let found = out.split_off(before);
        out.extend(
            found.into_iter().filter(|d| {
                d.code != codes::UNEXPECTED_PROPERTY.name || !legacy.contains(&d.pointer)
            }),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::{load_bytes_with, LoadOptions};

    #[test]
    fn the_core_schema_compiles_once_into_the_slot_the_schemas_share() {
        let core = Arc::new(OnceLock::new());
        let schemas = Schemas::with_core(Arc::clone(&core));
        // Compiled on first use, not with the layers' schemas.
        assert!(core.get().is_none());
        let compiled: *const super::super::core::CoreSchema = schemas.core();
        assert!(std::ptr::eq(compiled, core.get().unwrap()));
        // A second set of schemas sharing the slot takes the same compiled schema.
        let again = Schemas::with_core(Arc::clone(&core));
        assert!(std::ptr::eq(again.core(), compiled));
    }

    fn schema_findings(text: &str) -> Vec<(String, String, String)> {
        let loaded = load_bytes_with(
            Path::new("memo.gltf"),
            text.as_bytes(),
            &LoadOptions::default(),
        );
        let asset = loaded.asset.expect("the document parses");
        let schemas = Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let mut out = Vec::new();
        SchemaCheck.check(&cx, &mut out);
        out.into_iter()
            .map(|d| (d.code.to_string(), d.pointer, d.message))
            .collect()
    }

    #[test]
    fn a_layer_object_repeated_on_several_materials_is_reported_at_each_of_them() {
        let bad =
            r#"{"KHR_materials_sheen":{"sheenRoughnessFactor":2,"sheenColor":[1,1,1],"x":{}}}"#;
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"materials":[{{"extensions":{bad}}},{{}},{{"extensions":{bad}}}]}}"#
        );
        let at =
            |m: usize, rest: &str| format!("/materials/{m}/extensions/KHR_materials_sheen{rest}");
        let expected: Vec<(String, String, String)> = [0, 2]
            .into_iter()
            .flat_map(|m| {
                [
                    (
                        "VALUE_NOT_IN_RANGE".to_string(),
                        at(m, "/sheenRoughnessFactor"),
                        "2 is greater than the maximum of 1.0".to_string(),
                    ),
                    (
                        "UNEXPECTED_PROPERTY".to_string(),
                        at(m, "/x"),
                        "unexpected property 'x'".to_string(),
                    ),
                ]
            })
            .collect();
        assert_eq!(schema_findings(&text), expected);
    }
}
