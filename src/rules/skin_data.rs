//! Inverse bind matrices, read from the data: each is an affine transform, so its last row is
//! 0, 0, 0, 1 (column-major components 3, 7, 11 and 15). Any other value there is
//! ACCESSOR_INVALID_IBM (an error, as in the Khronos glTF-Validator), at the skin's
//! `inverseBindMatrices`, one finding a value, at most [`MAX_REPORTED`] a skin.

use super::accessor_bounds::MAX_REPORTED;
use super::data::{index_of, Elements};
use super::{elements, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_INVALID_IBM: Code = Code::new(
    "ACCESSOR_INVALID_IBM",
    Severity::Error,
    "An inverse bind matrix is not affine: its last row is not 0, 0, 0, 1.",
);

/// The last row of a column-major 4×4 matrix: (component, the value it must hold).
const LAST_ROW: [(usize, f64); 4] = [(3, 0.0), (7, 0.0), (11, 0.0), (15, 1.0)];

pub struct SkinData;

impl Rule for SkinData {
    fn codes(&self) -> &'static [&'static Code] {
        &[&ACCESSOR_INVALID_IBM]
    }

    fn reads(&self) -> super::Reads {
        super::data::DATA_READS
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        if !cx.reads_data() {
            return;
        }
        for (s, skin) in elements(cx.json().get("skins")).enumerate() {
            let Some(matrices) = index_of(skin.get("inverseBindMatrices"))
                .and_then(|i| Elements::of(cx, i))
                .filter(|m| m.components == 16)
            else {
                continue;
            };
            let mut reported = 0;
            matrices.for_each(|i, m| {
                for (c, expected) in LAST_ROW {
                    let value = matrices.normalize(m[c]);
                    if value != expected && reported < MAX_REPORTED {
                        reported += 1;
                        out.push(Diagnostic::new(
                            &ACCESSOR_INVALID_IBM,
                            format!("/skins/{s}/inverseBindMatrices"),
                            format!(
                                "matrix {i}'s component {c} (value index {}) is {value}; the last row of an inverse bind matrix is 0, 0, 0, 1",
                                i * 16 + c
                            ),
                        ));
                    }
                }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    #[test]
    fn a_matrix_whose_last_row_is_not_0_0_0_1_is_found_once_a_value() {
        let mut bytes = Vec::new();
        let identity = [
            1.0f32, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
        ];
        let mut bad = identity;
        bad[3] = 1.0;
        bad[15] = 2.0;
        for v in identity.iter().chain(bad.iter()) {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"nodes":[{{}},{{}}],"skins":[{{"joints":[0,1],"inverseBindMatrices":0}}],
            "buffers":[{{"byteLength":128,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":128}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":2,"type":"MAT4"}}]}}"#
        );
        assert_eq!(
            crate::rules::findings_of(&SkinData, &text),
            [
                "ACCESSOR_INVALID_IBM /skins/0/inverseBindMatrices",
                "ACCESSOR_INVALID_IBM /skins/0/inverseBindMatrices"
            ]
        );
    }
}
