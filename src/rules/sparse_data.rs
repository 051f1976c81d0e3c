//! Sparse accessors' indices, read from the data (the spec: they "MUST strictly increase" and
//! name elements of the accessor), with the Khronos glTF-Validator's codes, at the accessor's
//! `sparse` object:
//!
//! - ACCESSOR_SPARSE_INDICES_NON_INCREASING (error): an index not greater than the one before.
//! - ACCESSOR_SPARSE_INDEX_OOB (error): an index at or past the accessor's count.
//!
//! Each kind is reported at most [`MAX_REPORTED`] times an accessor.

use super::accessor_bounds::MAX_REPORTED;
use super::data::{accessor_count, sparse_indices};
use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_SPARSE_INDICES_NON_INCREASING: Code = Code::new(
    "ACCESSOR_SPARSE_INDICES_NON_INCREASING",
    Severity::Error,
    "A sparse accessor's indices do not strictly increase.",
);
pub const ACCESSOR_SPARSE_INDEX_OOB: Code = Code::new(
    "ACCESSOR_SPARSE_INDEX_OOB",
    Severity::Error,
    "A sparse accessor's index names no element of the accessor.",
);

pub struct SparseData;

impl Rule for SparseData {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ACCESSOR_SPARSE_INDICES_NON_INCREASING,
            &ACCESSOR_SPARSE_INDEX_OOB,
        ]
    }

    fn reads(&self) -> super::Reads {
        super::data::DATA_READS
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        if !cx.reads_data() || cx.json().members_named("sparse").next().is_none() {
            return;
        }
        for a in 0..accessor_count(cx) {
            let Some((indices, count)) = sparse_indices(cx, a) else {
                continue;
            };
            let at = format!("/accessors/{a}/sparse");
            let (mut unordered, mut outside) = (0, 0);
            for (k, &index) in indices.iter().enumerate() {
                if let Some(&before) = k.checked_sub(1).and_then(|p| indices.get(p)) {
                    if index <= before && unordered < MAX_REPORTED {
                        unordered += 1;
                        out.push(Diagnostic::new(
                            &ACCESSOR_SPARSE_INDICES_NON_INCREASING,
                            at.clone(),
                            format!("sparse index {k} is not greater than the one before: {index} <= {before}"),
                        ));
                    }
                }
                if index >= count && outside < MAX_REPORTED {
                    outside += 1;
                    out.push(Diagnostic::new(
                        &ACCESSOR_SPARSE_INDEX_OOB,
                        at.clone(),
                        format!(
                            "sparse index {k} is {index}, not below the accessor's count {count}"
                        ),
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    #[test]
    fn sparse_indices_out_of_order_or_out_of_range_are_found() {
        let mut bytes = Vec::new();
        for i in [2u16, 1, 5, 0] {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
        bytes.extend_from_slice(&[0; 16]);
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":24,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":8}},{{"buffer":0,"byteOffset":8,"byteLength":16}}],
            "accessors":[{{"componentType":5126,"count":3,"type":"SCALAR","sparse":{{"count":4,
                "indices":{{"bufferView":0,"componentType":5123}},"values":{{"bufferView":1}}}}}}]}}"#
        );
        assert_eq!(
            crate::rules::findings_of(&SparseData, &text),
            [
                "ACCESSOR_SPARSE_INDICES_NON_INCREASING /accessors/0/sparse",
                "ACCESSOR_SPARSE_INDEX_OOB /accessors/0/sparse",
                "ACCESSOR_SPARSE_INDICES_NON_INCREASING /accessors/0/sparse",
            ]
        );
    }
}
