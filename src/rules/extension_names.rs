//! The names in `extensionsUsed`, beyond their schema (the Khronos glTF-Validator's checks):
//!
//! - INVALID_EXTENSION_NAME_FORMAT (warning): a name that is not `PREFIX_name`, an upper-case
//!   vendor prefix, an underscore and a name (the spec's "Extensions": "all extension names MUST
//!   have a prefix followed by an underscore").
//! - NON_REQUIRED_EXTENSION (error): an extension whose spec says it must also be in
//!   `extensionsRequired` (KHR_mesh_quantization: loaders without it misread the attributes), but
//!   is not.

use super::{elements, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const INVALID_EXTENSION_NAME_FORMAT: Code = Code::new(
    "INVALID_EXTENSION_NAME_FORMAT",
    Severity::Warning,
    "An extension name is not a vendor prefix in capitals, an underscore and a name.",
);
pub const NON_REQUIRED_EXTENSION: Code = Code::new(
    "NON_REQUIRED_EXTENSION",
    Severity::Error,
    "An extension that must be required (KHR_mesh_quantization) is used but not in extensionsRequired.",
);

/// Extensions whose specs say they must be required wherever they are used.
const ALWAYS_REQUIRED: &[&str] = &["KHR_mesh_quantization"];

/// Whether `name` is `PREFIX_name`: capitals or digits, an underscore, then letters, digits or
/// underscores.
pub fn is_extension_name(name: &str) -> bool {
    let Some((prefix, rest)) = name.split_once('_') else {
        return false;
    };
    !prefix.is_empty()
        && prefix
            .bytes()
            .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit())
        && !rest.is_empty()
        && rest.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
}

pub struct ExtensionNames;

impl Rule for ExtensionNames {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["extensionsUsed", "extensionsRequired"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&INVALID_EXTENSION_NAME_FORMAT, &NON_REQUIRED_EXTENSION]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let required: Vec<String> = elements(json.get("extensionsRequired"))
            .filter_map(|e| e.as_str().map(|s| s.into_owned()))
            .collect();
        for (i, name) in elements(json.get("extensionsUsed")).enumerate() {
            let Some(name) = name.as_str() else {
                continue;
            };
            if !is_extension_name(&name) {
                out.push(Diagnostic::new(
                    &INVALID_EXTENSION_NAME_FORMAT,
                    format!("/extensionsUsed/{i}"),
                    format!("'{name}' is not an extension name: a capital prefix, '_' and a name"),
                ));
            }
            if ALWAYS_REQUIRED.contains(&name.as_ref()) && !required.iter().any(|r| *r == name) {
                out.push(Diagnostic::new(
                    &NON_REQUIRED_EXTENSION,
                    format!("/extensionsUsed/{i}"),
                    format!("{name} must also be in extensionsRequired"),
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extension_names_have_a_capital_prefix_and_a_name() {
        for ok in [
            "KHR_materials_sheen",
            "EXT_texture_webp",
            "ADOBE_materials_thin_transparency",
            "MSFT_lod",
            "A1_x",
        ] {
            assert!(is_extension_name(ok), "{ok}");
        }
        for bad in [
            "_extension",
            "khr_materials_sheen",
            "KHR",
            "KHR_",
            "KHR_a-b",
            "",
        ] {
            assert!(!is_extension_name(bad), "{bad}");
        }
    }
}
