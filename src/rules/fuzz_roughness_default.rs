//! The fuzz roughness default is ambiguous: the draft's parameter table says 0.5, its JSON
//! schema 0.0. A material that leaves fuzzRoughnessFactor out while the layer is on looks
//! different in loaders that follow one or the other.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS: Code = Code::new(
    "KHR_MATERIALS_FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS",
    Severity::Hint,
    "fuzzRoughnessFactor omitted on an active fuzz layer: the draft's table says 0.5, its schema 0.0; write it explicitly.",
)
.fixable(crate::diagnostics::Safety::Safe);

pub struct FuzzRoughnessDefault;

impl Rule for FuzzRoughnessDefault {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        // One text for every finding, written once.
        let message = format!(
            "fuzzRoughnessFactor is omitted: the draft's table gives {} and its schema {}; loaders may differ, so write it explicitly (velvet assumes {})",
            layers::FUZZ_ROUGHNESS_DEFAULT_TABLE,
            layers::FUZZ_ROUGHNESS_DEFAULT_SCHEMA,
            layers::FUZZ_ROUGHNESS_DEFAULT_TABLE
        );
        for read in cx.layers() {
            let (layer, Some(fuzz)) = (read.object, read.fuzz()) else {
                continue;
            };
            if fuzz.is_on() && layer.value.get("fuzzRoughnessFactor").is_none() {
                out.push(Diagnostic::new(
                    &FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS,
                    layer.pointer(),
                    message.clone(),
                ));
            }
        }
    }
}
