//! KHR_materials_variants, beyond its schema: a variant names one material of a primitive, so
//! a variant listed by two mappings of one primitive is KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT
//! (an error, as in the Khronos glTF-Validator), at its second listing.

use super::{elements, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT: Code = Code::new(
    "KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT",
    Severity::Error,
    "A material variant is listed by two mappings of one primitive.",
);

pub struct Variants;

impl Rule for Variants {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["meshes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        if json
            .members_named("KHR_materials_variants")
            .next()
            .is_none()
        {
            return;
        }
        for (m, mesh) in elements(json.get("meshes")).enumerate() {
            for (p, primitive) in elements(mesh.get("primitives")).enumerate() {
                let Some(variants) = primitive
                    .get("extensions")
                    .and_then(|e| e.get("KHR_materials_variants"))
                else {
                    continue;
                };
                let mut seen: Vec<u64> = Vec::new();
                for (k, mapping) in elements(variants.get("mappings")).enumerate() {
                    for (v, variant) in elements(mapping.get("variants")).enumerate() {
                        let Some(index) = variant.as_u64() else {
                            continue;
                        };
                        if seen.contains(&index) {
                            out.push(Diagnostic::new(
                                &KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT,
                                format!("/meshes/{m}/primitives/{p}/extensions/KHR_materials_variants/mappings/{k}/variants/{v}"),
                                format!("variant {index} is already mapped to a material of this primitive"),
                            ));
                        } else {
                            seen.push(index);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_variant_mapped_twice_in_one_primitive_is_found_at_its_second_listing() {
        let text = r#"{"asset":{"version":"2.0"},"materials":[{},{}],
            "extensions":{"KHR_materials_variants":{"variants":[{"name":"a"},{"name":"b"}]}},
            "meshes":[{"primitives":[{"attributes":{"POSITION":0},"extensions":{"KHR_materials_variants":
                {"mappings":[{"material":0,"variants":[1,0]},{"material":1,"variants":[0]}]}}},
                {"attributes":{"POSITION":0},"extensions":{"KHR_materials_variants":
                {"mappings":[{"material":0,"variants":[0]},{"material":1,"variants":[1]}]}}}]}]}"#;
        let found = crate::rules::findings_of(&Variants, text);
        assert_eq!(
            found,
            ["KHR_MATERIALS_VARIANTS_NON_UNIQUE_VARIANT /meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/1/variants/0"]
        );
    }
}
