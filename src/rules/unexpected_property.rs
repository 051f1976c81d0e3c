//! Properties no schema defines: UNEXPECTED_PROPERTY (a warning, as in the Khronos
//! glTF-Validator) at each key of a core object or of an extension object with a published
//! schema that its schemas, its bases' included, do not name.
//!
//! The glTF 2.0 schemas do not close their objects (`additionalProperties` is absent), so the
//! schema check passes a misspelt `"nmae"`; the Khronos validator reports it, and so does this
//! rule. The kinds of objects and the properties each defines come from the same schema walk
//! as the extension placements (`rules/extensions.rs`); `extras`, extensions without a schema
//! and schemas that admit any property are open and not judged. Sheen and fuzz objects are the
//! layer schema check's (`rules/schema.rs`).
//!
//! Example: `{"nodes": [{"nmae": "a"}]}` → UNEXPECTED_PROPERTY at `/nodes/0/nmae`.

use super::extensions::{shapes, Shapes};
use super::{Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{KeyId, Node};
use crate::diagnostics::{codes, Code, Diagnostic};
use std::collections::HashMap;

pub struct UnexpectedProperty;

/// Objects are never this deep in a real asset (a step is a key or an index); a hostile one
/// stops here.
const MAX_DEPTH: usize = 128;

impl Rule for UnexpectedProperty {
    fn codes(&self) -> &'static [&'static Code] {
        &[&codes::UNEXPECTED_PROPERTY]
    }

    /// A walk of every object of the document, as the core schema check's.
    fn cost(&self) -> u32 {
        2
    }

    /// An element of one of the root's arrays is walked by itself, and nothing else depends on
    /// what it holds.
    fn passes_alone(&self, _: &Context, element: &super::ElementPlace, value: Node) -> bool {
        let shapes = shapes();
        let Some((_, kind, _)) = shapes
            .children(shapes.root())
            .iter()
            .find(|(name, _, array)| *array && *name == element.property)
        else {
            return false;
        };
        let mut path = vec![
            Step::Key(element.property.as_str().into()),
            Step::Index(element.index),
        ];
        let mut found = Vec::new();
        Walk::new(shapes).walk(value, *kind, &mut path, &mut found);
        found.is_empty()
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let shapes = shapes();
        let mut path = Vec::new();
        Walk::new(shapes).walk(cx.json(), shapes.root(), &mut path, out);
    }
}

/// One step of the path to a value: a key or an array index. The pointer is written only for
/// a finding, not for each of the document's keys.
enum Step<'a> {
    Key(std::borrow::Cow<'a, str>),
    Index(usize),
}

fn pointer_of(path: &[Step]) -> String {
    let mut at = String::new();
    for step in path {
        at.push('/');
        match step {
            Step::Key(key) => pointer::push_escaped(&mut at, key),
            Step::Index(i) => at.push_str(&i.to_string()),
        }
    }
    at
}

/// What the walk does with a key on an object of one kind.
#[derive(Clone, Copy)]
enum Decision {
    /// The kind's schemas do not define it: a finding.
    Unexpected,
    /// The object's extensions, each judged by its own kind where it has a schema.
    Extensions,
    /// An object (or an array of them, `array`) of kind `kind`.
    Child { kind: usize, array: bool },
    /// A value with no properties of its own to judge.
    Leaf,
}

/// The walk of one document: each (kind, key) is decided once, by the key's number in the
/// document, and not by comparing its name with the kind's property names at every object (a
/// library's 20,000 materials ask the same few questions 20,000 times).
struct Walk<'s> {
    shapes: &'s Shapes,
    decided: HashMap<(usize, KeyId), Decision, foldhash::quality::RandomState>,
}

impl<'s> Walk<'s> {
    fn new(shapes: &'s Shapes) -> Walk<'s> {
        Walk {
            shapes,
            decided: HashMap::default(),
        }
    }

    fn decide(&mut self, shape: usize, id: KeyId, key: &str) -> Decision {
        let shapes = self.shapes;
        *self.decided.entry((shape, id)).or_insert_with(|| {
            if !shapes.defines(shape, key) {
                Decision::Unexpected
            } else if key == "extensions" {
                Decision::Extensions
            } else if let Some((_, child, array)) = shapes
                .children(shape)
                .iter()
                .find(|(name, _, _)| *name == key)
            {
                Decision::Child {
                    kind: *child,
                    array: *array,
                }
            } else {
                Decision::Leaf
            }
        })
    }

    fn walk<'a>(
        &mut self,
        value: Node<'a>,
        shape: usize,
        path: &mut Vec<Step<'a>>,
        out: &mut Vec<Diagnostic>,
    ) {
        let Some(object) = value.as_object() else {
            return;
        };
        if path.len() > MAX_DEPTH {
            return;
        }
        for (id, key, member) in object.iter_keyed() {
            match self.decide(shape, id, &key) {
                Decision::Unexpected => {
                    let mut at = pointer_of(path);
                    at.push('/');
                    pointer::push_escaped(&mut at, &key);
                    out.push(Diagnostic::new(
                        &codes::UNEXPECTED_PROPERTY,
                        at,
                        format!("unexpected property '{key}'"),
                    ));
                }
                Decision::Extensions => {
                    path.push(Step::Key(key));
                    for (name, extension) in member.as_object().into_iter().flat_map(|o| o.iter()) {
                        if let Some(kind) = self.shapes.extension_object(&name, shape) {
                            path.push(Step::Key(name));
                            self.walk(extension, kind, path, out);
                            path.pop();
                        }
                    }
                    path.pop();
                }
                Decision::Child { kind, array } => {
                    path.push(Step::Key(key));
                    if array {
                        for (i, element) in super::elements(Some(member)).enumerate() {
                            path.push(Step::Index(i));
                            self.walk(element, kind, path, out);
                            path.pop();
                        }
                    } else {
                        self.walk(member, kind, path, out);
                    }
                    path.pop();
                }
                Decision::Leaf => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&UnexpectedProperty, text)
    }

    #[test]
    fn keys_no_schema_defines_are_found_in_core_and_extension_objects() {
        let text = r#"{"asset":{"version":"2.0","bogus":1},"nmae":"x",
            "nodes":[{"name":"n","extras":{"free":1},"extensions":{"KHR_node_visibility":{"visible":false,"odd":2},"EXT_unknown":{"any":1}}}],
            "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"scale":2}},
                "extensions":{"KHR_materials_sheen":{"whatever":1},
                              "KHR_texture_transform":{"nope":1}}}],
            "accessors":[{"componentType":5126,"count":1,"type":"SCALAR","sparse":{"count":1,"indices":{"bufferView":0,"componentType":5123,"x":0},"values":{"bufferView":0}}}],
            "a/b":1}"#;
        assert_eq!(
            found(text),
            [
                "UNEXPECTED_PROPERTY /asset/bogus",
                "UNEXPECTED_PROPERTY /nmae",
                "UNEXPECTED_PROPERTY /nodes/0/extensions/KHR_node_visibility/odd",
                "UNEXPECTED_PROPERTY /materials/0/pbrMetallicRoughness/baseColorTexture/scale",
                "UNEXPECTED_PROPERTY /accessors/0/sparse/indices/x",
                "UNEXPECTED_PROPERTY /a~1b",
            ]
        );
    }

    #[test]
    fn a_document_of_defined_properties_has_none() {
        let text = r#"{"asset":{"version":"2.0","generator":"g","copyright":"c","extras":{}},
            "scene":0,"scenes":[{"nodes":[0],"name":"s"}],
            "nodes":[{"mesh":0,"translation":[0,0,0],"extensions":{"KHR_lights_punctual":{"light":0}}}],
            "extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","spot":{"innerConeAngle":0.1}}]}},
            "materials":[{"normalTexture":{"index":0,"scale":1,"texCoord":0},"occlusionTexture":{"index":0,"strength":1}}]}"#;
        assert_eq!(found(text), Vec::<String>::new());
    }
}
