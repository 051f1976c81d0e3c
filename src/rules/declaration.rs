//! Declared extensions: a sheen or fuzz object on a material whose extension is missing from
//! `extensionsUsed` is an error (loaders may ignore it); a declaration with no use is a warning.

use super::{layer_objects, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use serde_json::Value;

pub const UNDECLARED_EXTENSION: Code = Code::new(
    "UNDECLARED_EXTENSION",
    Severity::Error,
    "A sheen or fuzz object is used but its extension is not in extensionsUsed.",
);
pub const SHEEN_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_SHEEN_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_sheen is in extensionsUsed but no material uses it.",
);
pub const FUZZ_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_FUZZ_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_fuzz is in extensionsUsed but no material uses it.",
);

pub struct Declaration;

impl Rule for Declaration {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &UNDECLARED_EXTENSION,
            &SHEEN_DECLARED_UNUSED,
            &FUZZ_DECLARED_UNUSED,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let declared: Vec<&str> = cx
            .json()
            .get("extensionsUsed")
            .and_then(Value::as_array)
            .map(|a| a.iter().filter_map(Value::as_str).collect())
            .unwrap_or_default();
        let mut used = [false, false];
        for layer in layer_objects(cx.json()) {
            used[usize::from(layer.extension == layers::FUZZ)] = true;
            if !declared.contains(&layer.extension) {
                out.push(Diagnostic::new(
                    &UNDECLARED_EXTENSION,
                    &layer.pointer,
                    format!(
                        "{} is used but not declared in extensionsUsed",
                        layer.extension
                    ),
                ));
            }
        }
        for (k, name) in declared.iter().enumerate() {
            let (is_used, code) = match *name {
                layers::SHEEN => (used[0], &SHEEN_DECLARED_UNUSED),
                layers::FUZZ => (used[1], &FUZZ_DECLARED_UNUSED),
                _ => continue,
            };
            if !is_used {
                out.push(Diagnostic::new(
                    code,
                    format!("/extensionsUsed/{k}"),
                    format!("{name} is declared in extensionsUsed but no material uses it"),
                ));
            }
        }
    }
}
