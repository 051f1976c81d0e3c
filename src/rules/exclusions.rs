//! Exclusions: both specs say the layer "must not be used on a material that also uses
//! KHR_materials_pbrSpecularGlossiness" or "KHR_materials_unlit". The Khronos validator only
//! warns (MULTIPLE_EXTENSIONS); a loader may drop the layer or the material's look, so velvet
//! reports an error.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const SHEEN_EXCLUDED: Code = Code::new(
    "KHR_MATERIALS_SHEEN_EXCLUDED_COMBINATION",
    Severity::Error,
    "KHR_materials_sheen on a material that also uses KHR_materials_pbrSpecularGlossiness or KHR_materials_unlit.",
);
pub const FUZZ_EXCLUDED: Code = Code::new(
    "KHR_MATERIALS_FUZZ_EXCLUDED_COMBINATION",
    Severity::Error,
    "KHR_materials_fuzz on a material that also uses KHR_materials_pbrSpecularGlossiness or KHR_materials_unlit.",
);

pub struct Exclusions;

impl Rule for Exclusions {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&SHEEN_EXCLUDED, &FUZZ_EXCLUDED]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for layer in cx.layer_objects() {
            for excluded in [layers::SPEC_GLOSS, layers::UNLIT] {
                if layer.extensions.get(excluded).is_some() {
                    let code = if layer.extension == layers::SHEEN {
                        &SHEEN_EXCLUDED
                    } else {
                        &FUZZ_EXCLUDED
                    };
                    out.push(Diagnostic::new(
                        code,
                        layer.pointer(),
                        format!(
                            "{} must not be used together with {excluded} on one material",
                            layer.extension
                        ),
                    ));
                }
            }
        }
    }
}
