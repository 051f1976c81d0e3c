//! Layer order with a clear coat: sheen lies under KHR_materials_clearcoat, fuzz over it. The
//! same material converted from one to the other changes its look where the coat is strong.
//! A clear coat whose clearcoatFactor is 0 (the default) is switched off ("If `clearcoatFactor`
//! (in the extension) is zero, the whole clearcoat layer is disabled"): it lies over nothing.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const SHEEN_UNDER_CLEARCOAT: Code = Code::new(
    "KHR_MATERIALS_SHEEN_UNDER_CLEARCOAT",
    Severity::Info,
    "Sheen with KHR_materials_clearcoat: the coat lies over the sheen.",
);
pub const FUZZ_OVER_CLEARCOAT: Code = Code::new(
    "KHR_MATERIALS_FUZZ_OVER_CLEARCOAT",
    Severity::Info,
    "Fuzz with KHR_materials_clearcoat: the fuzz lies over the coat (sheen lay under it).",
);

pub struct Clearcoat;

impl Rule for Clearcoat {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&SHEEN_UNDER_CLEARCOAT, &FUZZ_OVER_CLEARCOAT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for layer in cx.layer_objects() {
            let coat_factor = layer
                .extensions
                .get(layers::CLEARCOAT)
                .and_then(|coat| coat.get("clearcoatFactor"))
                .and_then(|f| f.as_f64());
            if !coat_factor.is_some_and(|f| f > 0.0) {
                continue;
            }
            let (code, message) = if layer.extension == layers::SHEEN {
                (
                    &SHEEN_UNDER_CLEARCOAT,
                    "the clear coat lies over this sheen layer",
                )
            } else {
                (
                    &FUZZ_OVER_CLEARCOAT,
                    "this fuzz layer lies over the clear coat (a sheen layer would lie under it)",
                )
            };
            out.push(Diagnostic::new(code, layer.pointer(), message));
        }
    }
}
