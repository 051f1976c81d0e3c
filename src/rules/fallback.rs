//! Sheen as the fuzz layer's fallback. The fuzz draft says that with both present, fuzz takes
//! precedence and sheen "only exists as a fallback for loaders that do not support the newer
//! extension". So: fuzz without sheen, when fuzz is not required, shows no layer at all in
//! loaders without fuzz (hint); both present is worth knowing (info); and a fallback that is on
//! while the fuzz is off, or off while the fuzz is on, contradicts it (warning).

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const FUZZ_WITHOUT_FALLBACK: Code = Code::new(
    "KHR_MATERIALS_FUZZ_WITHOUT_FALLBACK",
    Severity::Hint,
    "Fuzz without a KHR_materials_sheen fallback while fuzz is not required: loaders without fuzz show no layer (see `velvet migrate`).",
);
pub const FUZZ_WITH_SHEEN_FALLBACK: Code = Code::new(
    "KHR_MATERIALS_FUZZ_WITH_SHEEN_FALLBACK",
    Severity::Info,
    "Fuzz and sheen on one material: loaders with fuzz use it and ignore the sheen.",
);
pub const FUZZ_FALLBACK_CONTRADICTS: Code = Code::new(
    "KHR_MATERIALS_FUZZ_FALLBACK_CONTRADICTS",
    Severity::Warning,
    "The sheen fallback is switched on while the fuzz is off, or off while the fuzz is on.",
);

pub struct Fallback;

impl Rule for Fallback {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials", "extensionsRequired"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &FUZZ_WITHOUT_FALLBACK,
            &FUZZ_WITH_SHEEN_FALLBACK,
            &FUZZ_FALLBACK_CONTRADICTS,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let fuzz_required = json
            .get("extensionsRequired")
            .and_then(|r| r.as_array())
            .is_some_and(|a| a.iter().any(|e| e.is_str(layers::FUZZ)));
        for pair in cx.material_layers() {
            let i = pair.material;
            let Some(fuzz) = pair.fuzz else {
                continue;
            };
            match pair.sheen {
                None if !fuzz_required && fuzz.is_on() => out.push(Diagnostic::new(
                    &FUZZ_WITHOUT_FALLBACK,
                    format!("/materials/{i}/extensions/{}", layers::FUZZ),
                    "loaders without KHR_materials_fuzz show no layer here; `velvet migrate` adds a KHR_materials_sheen fallback",
                )),
                None => {}
                Some(sheen) => {
                    let sheen_pointer = format!("/materials/{i}/extensions/{}", layers::SHEEN);
                    let contradiction =
                        (sheen.is_on() != fuzz.is_on()).then(|| sheen_pointer.clone());
                    out.push(Diagnostic::new(
                        &FUZZ_WITH_SHEEN_FALLBACK,
                        sheen_pointer,
                        "KHR_materials_fuzz takes precedence; this sheen is the fallback for loaders without it",
                    ));
                    if let Some(sheen_pointer) = contradiction {
                        let (on, off) = if fuzz.is_on() { ("fuzz", "sheen fallback") } else { ("sheen fallback", "fuzz") };
                        out.push(Diagnostic::new(
                            &FUZZ_FALLBACK_CONTRADICTS,
                            sheen_pointer,
                            format!("the {on} is switched on but the {off} is off: loaders with and without fuzz disagree on whether this material has a layer"),
                        ));
                    }
                }
            }
        }
    }
}
