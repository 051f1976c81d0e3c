//! Accessors laid over their buffer views, as the JSON says they are (the Khronos
//! glTF-Validator's accessor link checks, with its codes and pointers); the data itself is not
//! read here.
//!
//! - ACCESSOR_NORMALIZED_INVALID (error): `normalized` on a float or unsigned-int accessor.
//! - ACCESSOR_MATRIX_ALIGNMENT (error): a matrix accessor's byteOffset not a multiple of 4.
//! - ACCESSOR_SMALL_BYTESTRIDE (error): its buffer view's byteStride is shorter than one element.
//! - ACCESSOR_OFFSET_ALIGNMENT (error): byteOffset not a multiple of the component's size.
//! - ACCESSOR_TOTAL_OFFSET_ALIGNMENT (error): the view's byteOffset plus the accessor's is not.
//! - ACCESSOR_TOO_LONG (error): the accessor's elements run past its buffer view's byteLength
//!   (at `byteOffset` when the offset alone is past it).
//! - ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE (error): a sparse count above the accessor's count.
//! - BUFFER_VIEW_INVALID_BYTE_STRIDE (error), for the buffer views of sparse indices and values,
//!   which are tightly packed: at their `bufferView`.
//!
//! Values of the wrong type and indices that name nothing are other rules' findings.

use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_NORMALIZED_INVALID: Code = Code::new(
    "ACCESSOR_NORMALIZED_INVALID",
    Severity::Error,
    "Only (unsigned) byte and short accessors can be normalized.",
);
pub const ACCESSOR_MATRIX_ALIGNMENT: Code = Code::new(
    "ACCESSOR_MATRIX_ALIGNMENT",
    Severity::Error,
    "A matrix accessor's byteOffset is not a multiple of 4.",
);
pub const ACCESSOR_SMALL_BYTESTRIDE: Code = Code::new(
    "ACCESSOR_SMALL_BYTESTRIDE",
    Severity::Error,
    "An accessor's buffer view has a byteStride shorter than one of its elements.",
);
pub const ACCESSOR_OFFSET_ALIGNMENT: Code = Code::new(
    "ACCESSOR_OFFSET_ALIGNMENT",
    Severity::Error,
    "An accessor's byteOffset is not a multiple of its component type's size.",
);
pub const ACCESSOR_TOTAL_OFFSET_ALIGNMENT: Code = Code::new(
    "ACCESSOR_TOTAL_OFFSET_ALIGNMENT",
    Severity::Error,
    "An accessor's byteOffset plus its buffer view's is not a multiple of its component type's size.",
);
pub const ACCESSOR_TOO_LONG: Code = Code::new(
    "ACCESSOR_TOO_LONG",
    Severity::Error,
    "An accessor's elements run past the end of its buffer view.",
);
pub const ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE: Code = Code::new(
    "ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE",
    Severity::Error,
    "A sparse accessor overrides more elements than the accessor has.",
);
pub const BUFFER_VIEW_INVALID_BYTE_STRIDE: Code = Code::new(
    "BUFFER_VIEW_INVALID_BYTE_STRIDE",
    Severity::Error,
    "A buffer view with byteStride holds data other than vertex attributes (indices, sparse data).",
);

/// The size in bytes of a component type, for the six glTF allows.
pub fn component_size(component_type: u64) -> Option<u64> {
    match component_type {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

/// The number of components of an accessor type.
pub fn components(kind: &str) -> Option<u64> {
    Some(match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

/// The bytes one element takes and the stride between elements when packed tightly: matrix
/// columns start on 4-byte boundaries (the spec's data alignment), so a byte MAT2 takes 6
/// bytes and a stride of 8, a byte MAT3 11 and 12, a short MAT3 22 and 24.
pub fn element_layout(size: u64, kind: &str) -> Option<(u64, u64)> {
    let n = components(kind)?;
    Some(match (size, kind) {
        (1, "MAT2") => (6, 8),
        (1, "MAT3") => (11, 12),
        (2, "MAT3") => (22, 24),
        _ => (size * n, size * n),
    })
}

pub struct Accessors;

impl Rule for Accessors {
    fn reads(&self) -> super::Reads {
        super::Reads::Properties {
            properties: &["accessors", "bufferViews"],
            except: &[("bufferViews", "target")],
        }
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ACCESSOR_NORMALIZED_INVALID,
            &ACCESSOR_MATRIX_ALIGNMENT,
            &ACCESSOR_SMALL_BYTESTRIDE,
            &ACCESSOR_OFFSET_ALIGNMENT,
            &ACCESSOR_TOTAL_OFFSET_ALIGNMENT,
            &ACCESSOR_TOO_LONG,
            &ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE,
            &BUFFER_VIEW_INVALID_BYTE_STRIDE,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let views = json.get("bufferViews");
        let view = |index| super::element_at(views, index);
        for (i, accessor) in elements(json.get("accessors")).enumerate() {
            let at = format!("/accessors/{i}");
            let component_type = accessor.get("componentType").and_then(|c| c.as_u64());
            let size = component_type.and_then(component_size);
            let kind = accessor.get("type").and_then(|t| t.as_str());
            let count = accessor
                .get("count")
                .and_then(|c| c.as_u64())
                .filter(|c| *c >= 1);
            let byte_offset = match accessor.get("byteOffset") {
                None => Some(0),
                Some(offset) => offset.as_u64(),
            };
            if accessor.get("normalized").and_then(|n| n.as_bool()) == Some(true)
                && matches!(component_type, Some(5125 | 5126))
            {
                out.push(Diagnostic::new(
                    &ACCESSOR_NORMALIZED_INVALID,
                    format!("{at}/normalized"),
                    "only (unsigned) byte and short accessors can be normalized",
                ));
            }
            if kind.as_deref().is_some_and(|k| k.starts_with("MAT"))
                && byte_offset.is_some_and(|o| o % 4 != 0)
            {
                out.push(Diagnostic::new(
                    &ACCESSOR_MATRIX_ALIGNMENT,
                    format!("{at}/byteOffset"),
                    "a matrix accessor's byteOffset must be a multiple of 4",
                ));
            }
            let (Some(size), Some(kind), Some(count), Some(byte_offset)) =
                (size, kind, count, byte_offset)
            else {
                continue;
            };
            let Some((element, packed)) = element_layout(size, &kind) else {
                continue;
            };
            if let Some(bv) = view(accessor.get("bufferView")) {
                let stride = bv.get("byteStride").and_then(|s| s.as_u64());
                if stride.is_some_and(|s| s < element) {
                    out.push(Diagnostic::new(
                        &ACCESSOR_SMALL_BYTESTRIDE,
                        at.clone(),
                        format!(
                            "the buffer view's byteStride ({}) is shorter than one element ({element} bytes)",
                            stride.unwrap_or_default()
                        ),
                    ));
                }
                let length = stride
                    .unwrap_or(packed)
                    .saturating_mul(count - 1)
                    .saturating_add(element);
                laid_over(bv, byte_offset, size, length, &at, true, out);
            }
            let Some(sparse) = accessor.get("sparse").filter(|s| s.is_object()) else {
                continue;
            };
            let Some(sparse_count) = sparse.get("count").and_then(|c| c.as_u64()) else {
                continue;
            };
            if sparse_count > count {
                out.push(Diagnostic::new(
                    &ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE,
                    format!("{at}/sparse/count"),
                    format!("the sparse accessor overrides {sparse_count} elements of {count}"),
                ));
            }
            for part in ["indices", "values"] {
                let Some(held) = sparse.get(part).filter(|p| p.is_object()) else {
                    continue;
                };
                let Some(bv) = view(held.get("bufferView")) else {
                    continue;
                };
                let part_at = format!("{at}/sparse/{part}");
                if bv.get("byteStride").is_some() {
                    out.push(Diagnostic::new(
                        &BUFFER_VIEW_INVALID_BYTE_STRIDE,
                        format!("{part_at}/bufferView"),
                        format!("sparse {part} are tightly packed: their buffer view must have no byteStride"),
                    ));
                }
                let part_size = if part == "indices" {
                    match held
                        .get("componentType")
                        .and_then(|c| c.as_u64())
                        .and_then(component_size)
                    {
                        Some(s) => s,
                        None => continue,
                    }
                } else {
                    size
                };
                let per_element = if part == "indices" {
                    part_size
                } else {
                    size * components(&kind).unwrap_or(1)
                };
                let offset = match held.get("byteOffset") {
                    None => 0,
                    Some(o) => match o.as_u64() {
                        Some(o) => o,
                        None => continue,
                    },
                };
                laid_over(
                    bv,
                    offset,
                    part_size,
                    per_element.saturating_mul(sparse_count),
                    &part_at,
                    false,
                    out,
                );
            }
        }
    }
}

/// Checks `length` bytes at `offset` in buffer view `bv` for a component of `size` bytes,
/// reporting at `at` (its `byteOffset` where the finding is the offset's). An accessor's own
/// total offset is reported at the accessor; a sparse part's at its `byteOffset`.
fn laid_over(
    bv: Node,
    offset: u64,
    size: u64,
    length: u64,
    at: &str,
    accessor: bool,
    out: &mut Vec<Diagnostic>,
) {
    if !offset.is_multiple_of(size) {
        out.push(Diagnostic::new(
            &ACCESSOR_OFFSET_ALIGNMENT,
            format!("{at}/byteOffset"),
            format!("byteOffset {offset} is not a multiple of the component size {size}"),
        ));
    }
    let view_offset = match bv.get("byteOffset") {
        None => Some(0),
        Some(o) => o.as_u64(),
    };
    if let Some(view_offset) = view_offset {
        let total = view_offset.saturating_add(offset);
        if total % size != 0 {
            out.push(Diagnostic::new(
                &ACCESSOR_TOTAL_OFFSET_ALIGNMENT,
                if accessor {
                    at.to_string()
                } else {
                    format!("{at}/byteOffset")
                },
                format!("the total offset {total} is not a multiple of the component size {size}"),
            ));
        }
    }
    let Some(view_length) = bv.get("byteLength").and_then(|l| l.as_u64()) else {
        return;
    };
    if offset > view_length {
        out.push(Diagnostic::new(
            &ACCESSOR_TOO_LONG,
            format!("{at}/byteOffset"),
            format!("byteOffset {offset} is past the buffer view's byteLength {view_length}"),
        ));
    } else if offset.saturating_add(length) > view_length {
        out.push(Diagnostic::new(
            &ACCESSOR_TOO_LONG,
            at,
            format!(
                "{length} bytes at offset {offset} run past the buffer view's byteLength {view_length}"
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Accessors, text)
    }

    #[test]
    fn accessors_laid_badly_over_their_views_are_found() {
        let text = r#"{"asset":{"version":"2.0"},
            "buffers":[{"byteLength":1000}],
            "bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":2,"byteLength":100,"byteStride":8}],
            "accessors":[
              {"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},
              {"bufferView":0,"componentType":5126,"count":5,"type":"VEC3"},
              {"bufferView":0,"byteOffset":52,"componentType":5126,"count":1,"type":"SCALAR"},
              {"bufferView":1,"byteOffset":1,"componentType":5126,"count":1,"type":"VEC3","normalized":true},
              {"bufferView":0,"byteOffset":2,"componentType":5123,"count":1,"type":"MAT2"},
              {"componentType":5126,"count":2,"type":"SCALAR","sparse":{"count":3,
                 "indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":0}}}]}"#;
        assert_eq!(
            found(text),
            [
                "ACCESSOR_TOO_LONG /accessors/1",
                "ACCESSOR_TOO_LONG /accessors/2/byteOffset",
                "ACCESSOR_NORMALIZED_INVALID /accessors/3/normalized",
                "ACCESSOR_SMALL_BYTESTRIDE /accessors/3",
                "ACCESSOR_OFFSET_ALIGNMENT /accessors/3/byteOffset",
                "ACCESSOR_TOTAL_OFFSET_ALIGNMENT /accessors/3",
                "ACCESSOR_MATRIX_ALIGNMENT /accessors/4/byteOffset",
                "ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE /accessors/5/sparse/count",
                "BUFFER_VIEW_INVALID_BYTE_STRIDE /accessors/5/sparse/indices/bufferView",
            ]
        );
    }

    #[test]
    fn byte_matrices_take_padded_columns() {
        assert_eq!(element_layout(1, "MAT2"), Some((6, 8)));
        assert_eq!(element_layout(1, "MAT3"), Some((11, 12)));
        assert_eq!(element_layout(2, "MAT3"), Some((22, 24)));
        assert_eq!(element_layout(4, "MAT4"), Some((64, 64)));
        assert_eq!(element_layout(2, "VEC3"), Some((6, 6)));
    }
}
