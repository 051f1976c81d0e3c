//! The core schema check: the whole document is validated against the official glTF 2.0 JSON
//! schemas (`schema/core/`, the files Khronos publishes, compiled into the binary and built
//! once per run) through jsonschema. The schemas, not a typed model, are the judge: an
//! accessor without bufferView, a texture whose image comes from an extension, a channel
//! target without node or an integer written `1.0` are all valid glTF and pass here.
//!
//! Each schema error becomes a code named as in the Khronos glTF-Validator, with a pointer to
//! the value at fault (for a missing property, its parent object). Rules the schemas cannot
//! express (indices in range, asset version, declarations, resources) are separate rules.

use super::{Context, Rule};
use crate::asset::tape::Node;
use crate::asset::tape_schema::TapeJson;
use crate::diagnostics::{codes, Code, Diagnostic, Severity};
use jsonschema::error::ValidationErrorKind;
use serde_json::Value;
use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

macro_rules! core_schema {
    ($name:literal) => {
        ($name, include_str!(concat!("../../schema/core/", $name)))
    };
}

/// The official glTF 2.0 schema files, by file name, as compiled into the binary.
pub const CORE_SCHEMAS: &[(&str, &str)] = &[
    core_schema!("accessor.schema.json"),
    core_schema!("accessor.sparse.indices.schema.json"),
    core_schema!("accessor.sparse.schema.json"),
    core_schema!("accessor.sparse.values.schema.json"),
    core_schema!("animation.channel.schema.json"),
    core_schema!("animation.channel.target.schema.json"),
    core_schema!("animation.sampler.schema.json"),
    core_schema!("animation.schema.json"),
    core_schema!("asset.schema.json"),
    core_schema!("buffer.schema.json"),
    core_schema!("bufferView.schema.json"),
    core_schema!("camera.orthographic.schema.json"),
    core_schema!("camera.perspective.schema.json"),
    core_schema!("camera.schema.json"),
    core_schema!("extension.schema.json"),
    core_schema!("extras.schema.json"),
    core_schema!("glTF.schema.json"),
    core_schema!("glTFChildOfRootProperty.schema.json"),
    core_schema!("glTFProperty.schema.json"),
    core_schema!("glTFid.schema.json"),
    core_schema!("image.schema.json"),
    core_schema!("material.normalTextureInfo.schema.json"),
    core_schema!("material.occlusionTextureInfo.schema.json"),
    core_schema!("material.pbrMetallicRoughness.schema.json"),
    core_schema!("material.schema.json"),
    core_schema!("mesh.primitive.schema.json"),
    core_schema!("mesh.schema.json"),
    core_schema!("node.schema.json"),
    core_schema!("sampler.schema.json"),
    core_schema!("scene.schema.json"),
    core_schema!("skin.schema.json"),
    core_schema!("texture.schema.json"),
    core_schema!("textureInfo.schema.json"),
];

pub const EMPTY_ENTITY: Code = Code::new(
    "EMPTY_ENTITY",
    Severity::Error,
    "An array or object that glTF requires to be non-empty is empty (\"nodes\": [], \"attributes\": {}).",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const UNSATISFIED_DEPENDENCY: Code = Code::new(
    "UNSATISFIED_DEPENDENCY",
    Severity::Error,
    "A property that requires another is present without it (an image's bufferView without mimeType, a scene without scenes, …).",
);
pub const PATTERN_MISMATCH: Code = Code::new(
    "PATTERN_MISMATCH",
    Severity::Error,
    "A string does not match the pattern its schema gives (asset.version must read MAJOR.MINOR).",
);
pub const ONE_OF_MISMATCH: Code = Code::new(
    "ONE_OF_MISMATCH",
    Severity::Error,
    "Exactly one of a set of properties must be defined and is not (an image's uri or bufferView; a camera's perspective or orthographic).",
);
pub const DUPLICATE_ELEMENTS: Code = Code::new(
    "DUPLICATE_ELEMENTS",
    Severity::Error,
    "An array whose elements must be unique holds one twice (extensionsUsed, a scene's or node's node list).",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const INVALID_INDEX: Code = Code::new(
    "INVALID_INDEX",
    Severity::Error,
    "An index is negative (`\"mesh\": -1`); indices are non-negative integers.",
);
pub const VALUE_MULTIPLE_OF: Code = Code::new(
    "VALUE_MULTIPLE_OF",
    Severity::Error,
    "A number is not a multiple of the step its schema gives (a bufferView's byteStride of 4).",
);
pub const ARRAY_TYPE_MISMATCH: Code = Code::new(
    "ARRAY_TYPE_MISMATCH",
    Severity::Error,
    "An element of a nested array has the wrong JSON type (a primitive that is no object).",
);
pub const NODE_MATRIX_TRS: Code = Code::new(
    "NODE_MATRIX_TRS",
    Severity::Error,
    "A node has both a matrix and translation, rotation or scale.",
);

/// Makes the schemas' open enumerations judge their values, as the Khronos validator does.
///
/// The glTF schemas write an enumeration as `anyOf` of its values and a bare `{"type": T}`,
/// so that a newer value still passes (`"type": "VEC5"`, a light of type "ambient"). The
/// Khronos validator reports such a value as VALUE_NOT_IN_LIST, a warning: a loader that
/// knows only the listed values cannot use it. Here the bare branch becomes `{"not": {"type":
/// T}}` and `T` the property's type: a value of another type is TYPE_MISMATCH, one of type `T`
/// outside the list fails the `anyOf` (VALUE_NOT_IN_LIST). Both are draft-4 keywords, so every
/// file keeps its draft.
pub(crate) fn close_open_enums(schema: &mut Value) {
    match schema {
        Value::Object(map) => {
            let open = map
                .get("anyOf")
                .and_then(Value::as_array)
                .and_then(|branches| {
                    let listed = branches
                        .iter()
                        .filter(|b| b.get("const").is_some() || b.get("enum").is_some())
                        .count();
                    let bare: Vec<&Value> = branches
                        .iter()
                        .filter_map(|b| {
                            let b = b.as_object()?;
                            let only_type = b.keys().all(|k| k == "type" || k == "description");
                            only_type.then(|| b.get("type")).flatten()
                        })
                        .collect();
                    (listed > 0 && listed + 1 == branches.len() && bare.len() == 1)
                        .then(|| bare[0].clone())
                });
            if let Some(kind) = open {
                if let Some(Value::Array(branches)) = map.get_mut("anyOf") {
                    for branch in branches.iter_mut() {
                        if branch.get("const").is_none() && branch.get("enum").is_none() {
                            *branch = serde_json::json!({"not": {"type": kind.clone()}});
                        }
                    }
                }
                map.entry("type").or_insert(kind);
            }
            map.values_mut().for_each(close_open_enums);
        }
        Value::Array(items) => items.iter_mut().for_each(close_open_enums),
        _ => {}
    }
}

/// The core schema files parsed, their open enums closed: read once, and shared by the core
/// schema, the element schemas and every extension schema that compiles.
pub(crate) static CORE_FILES: std::sync::LazyLock<Arc<HashMap<String, Value>>> =
    std::sync::LazyLock::new(|| {
        Arc::new(
            CORE_SCHEMAS
                .iter()
                .map(|(name, text)| {
                    let mut schema =
                        serde_json::from_str(text).expect("core schemas are valid JSON");
                    close_open_enums(&mut schema);
                    (name.to_string(), schema)
                })
                .collect(),
        )
    });

/// Builds jsonschema's validator of the core schemas' meta-schema (draft 2020-12), which it
/// builds once per process, the first time a schema of that draft compiles.
pub(crate) fn prepare_meta_schema() {
    let schema = serde_json::json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "type": "object"
    });
    let valid = jsonschema::meta::is_valid(&schema);
    debug_assert!(valid);
}

/// The core schema compiled for one run.
pub struct CoreSchema {
    validator: jsonschema::Validator<TapeJson>,
    /// The schema of each of [`ELEMENT_ARRAYS`]' elements, compiled once a run has judged
    /// [`COMPILE_AFTER`] of them alone (a fix's trial judges the elements it edits).
    elements: [OnceLock<jsonschema::Validator<TapeJson>>; ELEMENT_ARRAYS.len()],
    /// How many elements of each array were judged alone before its schema was compiled.
    judged: [std::sync::atomic::AtomicUsize; ELEMENT_ARRAYS.len()],
}

/// How many elements of an array are judged in a minimal document of their own before their
/// schema is compiled by itself. A compile costs some 1.2 million instructions, as much as a
/// hundred such documents: a run over one file judges a few, a run over a library thousands.
const COMPILE_AFTER: usize = 64;

/// The core schemas' compile options: draft 2020-12, the files compiled in.
fn core_options() -> jsonschema::ValidationOptions<'static, Arc<dyn jsonschema::Retrieve>, TapeJson>
{
    jsonschema::options_for::<TapeJson>()
        .with_draft(jsonschema::Draft::Draft202012)
        // URIs are judged by the resources rule, which knows what a glTF URI may be.
        .should_validate_formats(false)
        .with_retriever(super::schema::FileRetriever::new(Arc::clone(&CORE_FILES)))
}

impl CoreSchema {
    /// The official schemas compiled into velvet.
    pub fn builtin() -> CoreSchema {
        let root = CORE_FILES["glTF.schema.json"].clone();
        let validator = core_options().build(&root).expect("core schemas compile");
        CoreSchema {
            validator,
            elements: std::array::from_fn(|_| OnceLock::new()),
            judged: std::array::from_fn(|_| Default::default()),
        }
    }

    /// Whether `element`, an element of the root's array `property`, passes its schema: as the
    /// one element of that array in an otherwise minimal document, or by the schema the root's
    /// `items` names for that array, which judges the same (the root's other constraints hold
    /// in any document with that one element). False for an array whose elements are not
    /// judged one by one.
    pub fn element_passes(&self, property: &str, element: Node) -> bool {
        use std::sync::atomic::Ordering;
        let Some(at) = ELEMENT_ARRAYS.iter().position(|p| *p == property) else {
            return false;
        };
        if self.elements[at].get().is_none()
            && self.judged[at].fetch_add(1, Ordering::Relaxed) < COMPILE_AFTER
        {
            return self.passes_in_minimal_document(property, element);
        }
        self.element_schema(at).is_valid(element)
    }

    /// Whether `element` passes as the one element of `property` in a document that has only
    /// that array and `asset`.
    fn passes_in_minimal_document(&self, property: &str, element: Node) -> bool {
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"{property}":[{}]}}"#,
            element.raw()
        );
        crate::asset::tape::Tape::build(&text)
            .is_ok_and(|tape| self.validator.is_valid(tape.root(&text)))
    }

    /// The schema of an element of `ELEMENT_ARRAYS[at]`, compiled on first use.
    fn element_schema(&self, at: usize) -> &jsonschema::Validator<TapeJson> {
        self.elements[at].get_or_init(|| {
            let items = &CORE_FILES["glTF.schema.json"]["properties"][ELEMENT_ARRAYS[at]]["items"];
            let schema = serde_json::json!({
                "$schema": "https://json-schema.org/draft/2020-12/schema",
                "$id": "velvet.element.schema.json",
                "$ref": items["$ref"],
            });
            core_options().build(&schema).expect("core schemas compile")
        })
    }

    /// Validates `json`, pushing one diagnostic per schema error.
    pub fn check(&self, json: Node, out: &mut Vec<Diagnostic>) {
        // Most documents are valid, and the yes-or-no check is a quarter of the full walk.
        if self.validator.is_valid(json) {
            return;
        }
        let first = out.len();
        diagnostics(&self.validator, json, out);
        // The Khronos validator names the document's root "/".
        for found in &mut out[first..] {
            if found.pointer.is_empty() {
                found.pointer.push('/');
            }
        }
    }
}

/// Every error of `validator` on `json` as a diagnostic, its pointer relative to `json`: the
/// core schema check's, and the extension schemas' (`rules/extensions.rs`).
pub(crate) fn diagnostics(
    validator: &jsonschema::Validator<TapeJson>,
    json: Node,
    out: &mut Vec<Diagnostic>,
) {
    // The (code, pointer) of each finding so far: a document with many faults has many
    // findings, and comparing each with all the others would take quadratic time.
    let first = out.len();
    let mut seen: std::collections::HashSet<(&'static str, String, String)> =
        std::collections::HashSet::new();
    for error in validator.iter_errors(json) {
        let mut at = error.instance_path().as_str().to_string();
        let schema_path = error.schema_path().as_str().to_string();
        let dependent = match error.kind() {
            ValidationErrorKind::Required { property }
                if schema_path.ends_with("/dependencies") =>
            {
                json.pointer(&at).and_then(|object| {
                    dependent_property(object, &property_name(property), |key| {
                        !seen.contains(&(
                            UNSATISFIED_DEPENDENCY.name,
                            format!("{at}/{}", crate::asset::pointer::escape(key)),
                            String::new(),
                        ))
                    })
                })
            }
            _ => None,
        };
        if let Some(property) = &dependent {
            // The Khronos validator judges these two elsewhere: a default scene that names no
            // scene is UNRESOLVED_REFERENCE (the references rule), an alphaCutoff without
            // alphaMode is MATERIAL_ALPHA_CUTOFF_INVALID_MODE (a warning, the alpha rule).
            if (at.is_empty() && property == "scene")
                || (at.starts_with("/materials/") && property == "alphaCutoff")
            {
                continue;
            }
        }
        let (instance, len) = match json.pointer(&at) {
            Some(node) => sample(node),
            None => {
                let value = error.instance().clone().into_owned();
                let len = value
                    .as_array()
                    .map_or(value.as_object().map_or(0, |o| o.len()), Vec::len);
                (value, len)
            }
        };
        // A property's missing dependency is reported at the property that needs it, as the
        // Khronos validator does (`/accessors/0/byteOffset` needs `bufferView`).
        if let Some(property) = &dependent {
            at.push('/');
            crate::asset::pointer::push_escaped(&mut at, property);
        }
        // Each missing property is a finding of its own, as in the Khronos validator.
        let missing = match error.kind() {
            ValidationErrorKind::Required { property } if dependent.is_none() => {
                property_name(property)
            }
            _ => String::new(),
        };
        let mut found = diagnostic(error.kind(), &schema_path, &instance, len, at);
        if found.code == codes::SCHEMA_MISMATCH.name {
            // jsonschema's own words, which name the value and the constraint plainly.
            found.message = format!("{}: {error}", quote(&instance));
        }
        reshape(&mut found, json);
        // A fault is one finding, though the schema may say so twice: a number past f64's
        // range fails both its type and its maximum, a value its own `type` and its base's.
        if !seen.insert((found.code, found.pointer.clone(), missing)) {
            continue;
        }
        out.push(found);
    }
    // A value of the wrong type is that one finding: what else its schema says of it (no
    // `oneOf` alternative matches an array) follows from the type.
    let mistyped: std::collections::HashSet<String> = out[first..]
        .iter()
        .filter(|d| d.code == codes::TYPE_MISMATCH.name)
        .map(|d| d.pointer.clone())
        .collect();
    if !mistyped.is_empty() {
        let mut at = first;
        for i in first..out.len() {
            if out[i].code == codes::TYPE_MISMATCH.name || !mistyped.contains(&out[i].pointer) {
                out.swap(at, i);
                at += 1;
            }
        }
        out.truncate(at);
    }
}

/// Places a finding as the Khronos validator does, where its pointer or code differ from the
/// schema error's:
/// - a nested array's element of the wrong type is ARRAY_TYPE_MISMATCH at the array (the
///   top-level arrays' elements, `/materials/0`, stay TYPE_MISMATCH at the element);
/// - a duplicate is reported at its second occurrence, not at the array;
/// - a node's matrix beside translation, rotation or scale is reported at the matrix;
/// - a negative index is INVALID_INDEX.
fn reshape(found: &mut Diagnostic, json: Node) {
    if found.code == codes::VALUE_NOT_IN_RANGE.name
        && super::references::is_index(&found.pointer)
        && json
            .pointer(&found.pointer)
            .and_then(|v| v.as_f64())
            .is_some_and(|v| v < 0.0)
    {
        // An index below 0 names nothing: the Khronos validator's INVALID_INDEX.
        found.code = INVALID_INDEX.name;
        found.severity = INVALID_INDEX.severity;
        found.message = format!("{}: an index is a non-negative integer", found.message);
    } else if found.code == codes::TYPE_MISMATCH.name {
        if let Some((array, last)) = found.pointer.rsplit_once('/') {
            let nested = array.matches('/').count() >= 2;
            if nested
                && last.parse::<usize>().is_ok()
                && json.pointer(array).is_some_and(|a| a.is_array())
            {
                found.code = ARRAY_TYPE_MISMATCH.name;
                found.severity = ARRAY_TYPE_MISMATCH.severity;
                found.message = format!(
                    "an element of the array is not of the type its items must have ({})",
                    found.message
                );
                found.pointer = array.to_string();
            }
        }
    } else if found.code == DUPLICATE_ELEMENTS.name {
        if let Some(array) = json.pointer(&found.pointer).and_then(|a| a.as_array()) {
            // Elements compared by their text, in one pass (a hostile array holds millions).
            let mut seen = std::collections::HashSet::new();
            if let Some(second) = array.iter().position(|e| !seen.insert(e.raw())) {
                found.pointer = format!("{}/{second}", found.pointer);
            }
        }
    } else if found.code == NODE_MATRIX_TRS.name {
        found.pointer.push_str("/matrix");
    }
}

/// Every `dependencies` entry of the core and extension schemas: (the property present, a
/// property it needs). jsonschema places a failed dependency at the `dependencies` keyword,
/// not at the entry, so the property that needs the missing one is found from this list.
static DEPENDENCIES: std::sync::LazyLock<Vec<(String, String)>> = std::sync::LazyLock::new(|| {
    fn collect(value: &Value, out: &mut Vec<(String, String)>) {
        match value {
            Value::Object(map) => {
                if let Some(Value::Object(entries)) = map.get("dependencies") {
                    for (present, needs) in entries {
                        for need in needs.as_array().into_iter().flatten() {
                            if let Some(need) = need.as_str() {
                                out.push((present.clone(), need.to_string()));
                            }
                        }
                    }
                }
                map.values().for_each(|v| collect(v, out));
            }
            Value::Array(items) => items.iter().for_each(|v| collect(v, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    let texts = CORE_SCHEMAS.iter().chain(
        super::extensions::EXTENSION_FILES
            .iter()
            .flat_map(|(_, files)| files.iter()),
    );
    for (_, text) in texts {
        let schema: Value = serde_json::from_str(text).expect("compiled-in schemas are valid JSON");
        collect(&schema, &mut out);
    }
    out
});

/// The member of `object` whose dependency on `missing` failed: the first, in the object's
/// order, that needs it and that `unreported` accepts (a node with both `weights` and `skin`
/// and no `mesh` fails twice).
fn dependent_property(
    object: Node,
    missing: &str,
    unreported: impl Fn(&str) -> bool,
) -> Option<String> {
    object
        .as_object()?
        .iter()
        .map(|(key, _)| key.into_owned())
        .find(|key| {
            DEPENDENCIES
                .iter()
                .any(|(present, need)| present == key && need == missing)
                && unreported(key)
        })
}

/// The first elements (or members) a message can show of the value `node` is, with how many
/// it has. A message quotes at most 60 characters of a value ([`quote`]), which the first 64
/// elements always fill; reading the whole of a large array into a value for it cost some 240
/// bytes an element (a 62 MB list of node indices took 7 GB).
fn sample(node: Node) -> (Value, usize) {
    const SHOWN: usize = 64;
    if let Some(array) = node.as_array() {
        let len = array.len();
        if len > SHOWN {
            let first = array.iter().take(SHOWN).map(|e| e.to_value()).collect();
            return (Value::Array(first), len);
        }
        return (node.to_value(), len);
    }
    if let Some(object) = node.as_object() {
        let len = object.len();
        if len > SHOWN {
            let first = object
                .iter()
                .take(SHOWN)
                .map(|(k, v)| (k.into_owned(), v.to_value()))
                .collect();
            return (Value::Object(first), len);
        }
        return (node.to_value(), len);
    }
    (node.to_value(), 0)
}

/// Whether `value` is a number that reads as an infinity in f64 (`1e400`): the index keeps its
/// text, and schemas that ask for a number see none there (see `asset/tape_schema.rs`).
pub(crate) fn is_non_finite(value: &Value) -> bool {
    value
        .as_number()
        .is_some_and(|n| n.to_string().parse::<f64>().is_ok_and(|f| !f.is_finite()))
}

/// Whether a type error asked for a number (not only an integer).
fn asks_for_number(kind: &jsonschema::error::TypeKind) -> bool {
    use jsonschema::types::JsonType;
    match kind {
        jsonschema::error::TypeKind::Single(t) => *t == JsonType::Number,
        jsonschema::error::TypeKind::Multiple(ts) => ts.contains(JsonType::Number),
    }
}

/// Whether every alternative of a `oneOf` or `anyOf` failed on a bound alone: the value is out
/// of every range the schema allows (KHR_materials_ior's `ior`, 0 or at least 1).
fn only_bounds_failed(context: &[Vec<jsonschema::ValidationError<'static>>]) -> bool {
    use ValidationErrorKind as K;
    !context.is_empty()
        && context.iter().all(|branch| {
            !branch.is_empty()
                && branch.iter().all(|e| {
                    matches!(
                        e.kind(),
                        K::Minimum { .. }
                            | K::Maximum { .. }
                            | K::ExclusiveMinimum { .. }
                            | K::ExclusiveMaximum { .. }
                    )
                })
        })
}

/// A value as messages quote it: strings in single quotes, the rest as JSON, long values cut.
fn quote(value: &Value) -> String {
    let text = match value {
        Value::String(s) => format!("'{s}'"),
        other => other.to_string(),
    };
    if text.chars().count() > 60 {
        let cut: String = text.chars().take(57).collect();
        format!("{cut}…")
    } else {
        text
    }
}

fn property_name(value: &Value) -> String {
    value
        .as_str()
        .map_or_else(|| value.to_string(), str::to_string)
}

fn diagnostic(
    kind: &ValidationErrorKind,
    schema_path: &str,
    instance: &Value,
    len: usize,
    at: String,
) -> Diagnostic {
    use ValidationErrorKind as K;
    let (code, message): (&Code, String) = match kind {
        K::Type { kind } if asks_for_number(kind) && is_non_finite(instance) => (
            &codes::VALUE_NOT_IN_RANGE,
            format!(
                "{} is past the range of a 64-bit float: it reads as infinity",
                quote(instance)
            ),
        ),
        K::OneOfNotValid { context } | K::AnyOf { context }
            if instance.is_number() && only_bounds_failed(context) =>
        {
            (
                &codes::VALUE_NOT_IN_RANGE,
                format!(
                    "{} is outside every range the schema allows",
                    quote(instance)
                ),
            )
        }
        K::Format { format } => (
            &PATTERN_MISMATCH,
            format!("{} is not a valid {format}", quote(instance)),
        ),
        K::Type { kind } => (
            &codes::TYPE_MISMATCH,
            format!("{} is not of type {}", quote(instance), type_names(kind)),
        ),
        K::Minimum { limit } => (
            &codes::VALUE_NOT_IN_RANGE,
            format!("{} is below the minimum {limit}", quote(instance)),
        ),
        K::ExclusiveMinimum { limit } => (
            &codes::VALUE_NOT_IN_RANGE,
            format!(
                "{} is not above the exclusive minimum {limit}",
                quote(instance)
            ),
        ),
        K::Maximum { limit } => (
            &codes::VALUE_NOT_IN_RANGE,
            format!("{} is above the maximum {limit}", quote(instance)),
        ),
        K::ExclusiveMaximum { limit } => (
            &codes::VALUE_NOT_IN_RANGE,
            format!(
                "{} is not below the exclusive maximum {limit}",
                quote(instance)
            ),
        ),
        K::MinItems { .. } if instance.as_array().is_some_and(Vec::is_empty) => {
            (&EMPTY_ENTITY, "the array is empty".to_string())
        }
        K::MinProperties { .. } if instance.as_object().is_some_and(|o| o.is_empty()) => {
            (&EMPTY_ENTITY, "the object is empty".to_string())
        }
        K::MinItems { limit } | K::MaxItems { limit } => (
            &codes::ARRAY_LENGTH_NOT_IN_LIST,
            format!(
                "the array has {} elements; {} {limit} allowed",
                len,
                if matches!(kind, K::MinItems { .. }) {
                    "at least"
                } else {
                    "at most"
                }
            ),
        ),
        K::Required { property } if schema_path.contains("/dependencies") => (
            &UNSATISFIED_DEPENDENCY,
            format!(
                "'{}' must be defined here (a property present depends on it)",
                property_name(property)
            ),
        ),
        K::Required { property } => (
            &codes::UNDEFINED_PROPERTY,
            format!("property '{}' must be defined", property_name(property)),
        ),
        K::Enum { .. } | K::Constant { .. } | K::AnyOf { .. } => (
            &codes::VALUE_NOT_IN_LIST,
            format!("{} is not one of the values allowed here", quote(instance)),
        ),
        K::Pattern { pattern } => (
            &PATTERN_MISMATCH,
            format!("{} does not match the pattern '{pattern}'", quote(instance)),
        ),
        K::OneOfNotValid { context } if required_names(context).is_some() => (
            &ONE_OF_MISMATCH,
            format!(
                "exactly one of {} must be defined",
                required_names(context).unwrap_or_default()
            ),
        ),
        K::OneOfNotValid { .. } | K::OneOfMultipleValid { .. } => (
            &ONE_OF_MISMATCH,
            format!("exactly one of {} must be defined", one_of_names(&at)),
        ),
        K::MultipleOf { multiple_of } => (
            &VALUE_MULTIPLE_OF,
            format!("{} is not a multiple of {multiple_of}", quote(instance)),
        ),
        K::Not { .. } if at.starts_with("/nodes/") => (
            &NODE_MATRIX_TRS,
            "a node has either a matrix or translation/rotation/scale, not both".to_string(),
        ),
        K::Not { .. } if at.starts_with("/cameras/") => (
            &ONE_OF_MISMATCH,
            "exactly one of 'perspective' and 'orthographic' may be defined".to_string(),
        ),
        K::UniqueItems => (
            &DUPLICATE_ELEMENTS,
            "the array holds an element twice".to_string(),
        ),
        _ => (
            &codes::SCHEMA_MISMATCH,
            format!("{} does not match the glTF 2.0 schema", quote(instance)),
        ),
    };
    Diagnostic::new(code, at, message)
}

fn type_names(kind: &jsonschema::error::TypeKind) -> String {
    match kind {
        jsonschema::error::TypeKind::Single(t) => format!("'{t}'"),
        jsonschema::error::TypeKind::Multiple(ts) => {
            let names: Vec<String> = ts.iter().map(|t| format!("'{t}'")).collect();
            names.join(" or ")
        }
    }
}

/// The properties a `oneOf` of `required` alternatives names ("'uri' and 'bufferView'"), when
/// every alternative failed for want of one property.
fn required_names(context: &[Vec<jsonschema::ValidationError<'static>>]) -> Option<String> {
    let names: Option<Vec<String>> = context
        .iter()
        .map(|branch| match branch.as_slice() {
            [one] => match one.kind() {
                ValidationErrorKind::Required { property } => {
                    Some(format!("'{}'", property_name(property)))
                }
                _ => None,
            },
            _ => None,
        })
        .collect();
    names.filter(|n| n.len() > 1).map(|n| n.join(" and "))
}

/// The properties a `oneOf` of `required` names, from where it stands (only an image has one).
fn one_of_names(at: &str) -> &'static str {
    if at.starts_with("/images/") {
        "'uri' and 'bufferView'"
    } else {
        "the alternatives the schema lists"
    }
}

/// The root's arrays whose elements the core schemas judge one by one (`items` of an object
/// schema, no constraint across elements).
const ELEMENT_ARRAYS: &[&str] = &[
    "accessors",
    "animations",
    "buffers",
    "bufferViews",
    "cameras",
    "images",
    "materials",
    "meshes",
    "nodes",
    "samplers",
    "scenes",
    "skins",
    "textures",
];

pub struct CoreStructure;

impl Rule for CoreStructure {
    /// Among the dearest rules on a large document: the whole document against the official schemas.
    fn cost(&self) -> u32 {
        5
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &codes::TYPE_MISMATCH,
            &codes::VALUE_NOT_IN_RANGE,
            &codes::ARRAY_LENGTH_NOT_IN_LIST,
            &codes::UNDEFINED_PROPERTY,
            &codes::VALUE_NOT_IN_LIST,
            &codes::SCHEMA_MISMATCH,
            &EMPTY_ENTITY,
            &UNSATISFIED_DEPENDENCY,
            &PATTERN_MISMATCH,
            &ONE_OF_MISMATCH,
            &DUPLICATE_ELEMENTS,
            &NODE_MATRIX_TRS,
            &VALUE_MULTIPLE_OF,
            &ARRAY_TYPE_MISMATCH,
            &INVALID_INDEX,
        ]
    }

    /// The core schemas judge each element of the root's arrays of objects by itself (their
    /// only constraint across elements, `uniqueItems`, is on the lists of extension names).
    fn passes_alone(&self, cx: &Context, element: &super::ElementPlace, value: Node) -> bool {
        cx.schemas.core().element_passes(&element.property, value)
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let first = out.len();
        cx.schemas.core().check(json, out);
        // Values an extension adds to a core enumeration are in the list once the extension
        // is declared, as the Khronos validator reads them.
        let declared = |name: &str| super::declares(json, name);
        let mut kept = first;
        for at in first..out.len() {
            let d = &out[at];
            let added = d.code == codes::VALUE_NOT_IN_LIST.name
                && json.pointer(&d.pointer).is_some_and(|value| {
                    EXTENDED_VALUES
                        .iter()
                        .any(|(property, value_added, extension)| {
                            d.pointer.ends_with(property)
                                && value.is_str(value_added)
                                && declared(extension)
                        })
                });
            if !added {
                out.swap(kept, at);
                kept += 1;
            }
        }
        out.truncate(kept);
        // The Khronos validator reads extensionsRequired as depending on extensionsUsed,
        // though the published schema does not say so.
        if json.get("extensionsRequired").is_some() && json.get("extensionsUsed").is_none() {
            out.push(Diagnostic::new(
                &UNSATISFIED_DEPENDENCY,
                "/extensionsRequired",
                "'extensionsUsed' must be defined here (extensionsRequired depends on it)",
            ));
        }
    }
}

/// Values that extensions add to core enumerations: (the property's last pointer segment,
/// the value, the extension that adds it).
const EXTENDED_VALUES: &[(&str, &str, &str)] = &[
    ("/target/path", "pointer", "KHR_animation_pointer"),
    ("/mimeType", "image/webp", "EXT_texture_webp"),
    ("/mimeType", "image/ktx2", "KHR_texture_basisu"),
    ("/mimeType", "image/ktx2", "EXT_texture_astc"),
    ("/mimeType", "image/vnd-ms.dds", "MSFT_texture_dds"),
    ("/mimeType", "image/avif", "EXT_texture_avif"),
];

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn codes_and_pointers(json: Value) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        let text = json.to_string();
        let tape = crate::asset::tape::Tape::build(&text).unwrap();
        CoreSchema::builtin().check(tape.root(&text), &mut out);
        out.into_iter().map(|d| (d.code, d.pointer)).collect()
    }

    #[test]
    fn an_element_passes_its_schema_exactly_when_a_document_of_it_alone_passes() {
        // Every element of the root's arrays in every fixture document, and each of them with
        // a member given a value of the wrong type: judged by the element schema, as the one
        // element of its array in an otherwise minimal document.
        let core = CoreSchema::builtin();
        let (mut judged, mut failing) = (0, 0);
        let mut compare = |property: &str, element: &Value| {
            let text = element.to_string();
            let tape = crate::asset::tape::Tape::build(&text).unwrap();
            let at = ELEMENT_ARRAYS.iter().position(|p| *p == property).unwrap();
            let alone = core.element_schema(at).is_valid(tape.root(&text));
            let doc = json!({"asset": {"version": "2.0"}, property: [element]}).to_string();
            let tape = crate::asset::tape::Tape::build(&doc).unwrap();
            let in_document = core.validator.is_valid(tape.root(&doc));
            assert_eq!(alone, in_document, "{property}: {text}");
            let tape = crate::asset::tape::Tape::build(&text).unwrap();
            assert_eq!(core.element_passes(property, tape.root(&text)), in_document);
            judged += 1;
            failing += usize::from(!alone);
        };
        for path in crate::rules::fixture_documents(&["gltf"]) {
            let text = std::fs::read_to_string(&path).unwrap();
            let Ok(Value::Object(root)) = serde_json::from_str::<Value>(&text) else {
                continue;
            };
            for property in ELEMENT_ARRAYS {
                let Some(Value::Array(elements)) = root.get(*property) else {
                    continue;
                };
                for element in elements {
                    compare(property, element);
                    if let Value::Object(members) = element {
                        for key in members.keys() {
                            let mut wrong = members.clone();
                            wrong.insert(key.clone(), json!([[true]]));
                            compare(property, &Value::Object(wrong));
                        }
                    }
                }
            }
        }
        assert!(
            judged > 1000 && failing > 100,
            "{judged} elements, {failing} failing"
        );
        // An array whose elements are not judged one by one.
        let text = "\"KHR_materials_sheen\"";
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        assert!(!core.element_passes("extensionsUsed", tape.root(text)));
    }

    #[test]
    fn valid_gltf_that_a_typed_model_refused_passes() {
        let doc = json!({
            "asset": {"version": "2.0"},
            "scenes": [{}],
            "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3"}],
            "textures": [{"extensions": {"EXT_texture_webp": {"source": 0}}}],
            "animations": [{"channels": [{"sampler": 0, "target": {"path": "rotation"}}],
                            "samplers": [{"input": 0, "output": 1.0}]}],
            "meshes": [{"primitives": [{"attributes": {"NORMAL": 0}}]}]
        });
        assert_eq!(codes_and_pointers(doc), vec![]);
    }

    #[test]
    fn schema_errors_get_khronos_codes_and_pointers_at_the_value() {
        let doc = json!({
            "asset": {"version": "2"},
            "scene": 0,
            "nodes": [],
            "images": [{"uri": "a.png", "bufferView": 0, "mimeType": "image/png"}, {"bufferView": 0}],
            "accessors": [{"count": 0, "type": "VEC3"}],
            "extensionsUsed": ["A", "A"],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 1, "znear": 0.1},
                          "orthographic": {"xmag": 1, "ymag": 1, "zfar": 2, "znear": 1}}]
        });
        let mut found = codes_and_pointers(doc);
        found.sort();
        let mut expected = vec![
            ("PATTERN_MISMATCH", "/asset/version".to_string()),
            // `scene` without `scenes` is the references rule's UNRESOLVED_REFERENCE.
            ("EMPTY_ENTITY", "/nodes".to_string()),
            ("ONE_OF_MISMATCH", "/images/0".to_string()),
            ("UNSATISFIED_DEPENDENCY", "/images/1/bufferView".to_string()),
            ("UNDEFINED_PROPERTY", "/accessors/0".to_string()),
            ("VALUE_NOT_IN_RANGE", "/accessors/0/count".to_string()),
            ("DUPLICATE_ELEMENTS", "/extensionsUsed/1".to_string()),
            ("ONE_OF_MISMATCH", "/cameras/0".to_string()),
        ];
        expected.sort();
        assert_eq!(found, expected);
    }

    #[test]
    fn a_node_with_matrix_and_trs_is_node_matrix_trs() {
        let doc = json!({"asset": {"version": "2.0"},
            "nodes": [{"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "scale": [1, 1, 1]}]});
        assert_eq!(
            codes_and_pointers(doc),
            vec![("NODE_MATRIX_TRS", "/nodes/0/matrix".to_string())]
        );
    }
}
