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
use crate::asset::tape::Node;
use crate::diagnostics::{codes, Code, Diagnostic};

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
    /// what it holds: the file's findings hold when it had none in the edited elements and the
    /// fixed elements have no key their kinds do not define.
    fn holds_inside(
        &self,
        cx: &Context,
        elements: &[super::ElementPlace],
        found_inside: &dyn Fn(&super::ElementPlace) -> bool,
    ) -> bool {
        let shapes = shapes();
        elements.iter().all(|element| {
            let kind = shapes
                .children(shapes.root())
                .iter()
                .find(|(name, _, array)| *array && *name == element.property);
            let (Some((_, kind, _)), Some(value), false) =
                (kind, element.in_document(cx.json()), found_inside(element))
            else {
                return false;
            };
            let mut path = vec![
                Step::Key(element.property.as_str().into()),
                Step::Index(element.index),
            ];
            let mut found = Vec::new();
            walk(shapes, value, *kind, &mut path, &mut found);
            found.is_empty()
        })
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let shapes = shapes();
        let mut path = Vec::new();
        walk(shapes, cx.json(), shapes.root(), &mut path, out);
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

fn walk<'a>(
    shapes: &Shapes,
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
    for (key, member) in object.iter() {
        if !shapes.defines(shape, &key) {
            let mut at = pointer_of(path);
            at.push('/');
            pointer::push_escaped(&mut at, &key);
            out.push(Diagnostic::new(
                &codes::UNEXPECTED_PROPERTY,
                at,
                format!("unexpected property '{key}'"),
            ));
        } else if key == "extensions" {
            path.push(Step::Key(key));
            for (name, extension) in member.as_object().into_iter().flat_map(|o| o.iter()) {
                if let Some(kind) = shapes.extension_object(&name, shape) {
                    path.push(Step::Key(name));
                    walk(shapes, extension, kind, path, out);
                    path.pop();
                }
            }
            path.pop();
        } else if let Some((_, child, array)) = shapes
            .children(shape)
            .iter()
            .find(|(name, _, _)| *name == key)
        {
            path.push(Step::Key(key));
            if *array {
                for (i, element) in super::elements(Some(member)).enumerate() {
                    path.push(Step::Index(i));
                    walk(shapes, element, *child, path, out);
                    path.pop();
                }
            } else {
                walk(shapes, member, *child, path, out);
            }
            path.pop();
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
