//! The GLB container: splitting a .glb into its JSON and BIN chunks, and joining them again.
//!
//! Writing uses `gltf::binary::Glb`, which pads the chunks as the spec asks. Reading walks the
//! chunks here because `gltf::binary::Glb::from_slice` stops at the first fault without saying
//! which byte is wrong, accepts unaligned chunk lengths and a header length that disagrees with
//! the file, and underflows on a header length below 12; velvet must report every such fault
//! as a diagnostic with its byte offset and carry on where it can.

use crate::diagnostics::{codes, Diagnostic};
use std::borrow::Cow;

const MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;
pub const HEADER_LEN: usize = 12;
pub const CHUNK_HEADER_LEN: usize = 8;

/// The chunks of a GLB that velvet uses.
#[derive(Debug)]
pub struct GlbParts<'a> {
    /// The JSON chunk's data, with any trailing padding.
    pub json: &'a [u8],
    /// Byte offset of the JSON chunk's data in the file.
    pub json_offset: usize,
    pub bin: Option<&'a [u8]>,
    /// Whole chunks of types the spec does not define (header and data, as they stand in the
    /// file), in file order: extensions may define them, and a rewrite keeps them.
    pub other: Vec<&'a [u8]>,
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Splits a GLB file, pushing a diagnostic for every fault. Returns `None` when no JSON chunk
/// can be had.
pub fn split<'a>(bytes: &'a [u8], out: &mut Vec<Diagnostic>) -> Option<GlbParts<'a>> {
    if bytes.len() < HEADER_LEN {
        out.push(Diagnostic::new(
            &codes::GLB_UNEXPECTED_END,
            "",
            format!(
                "the file is {} bytes long; a GLB header needs 12",
                bytes.len()
            ),
        ));
        return None;
    }
    if &bytes[0..4] != MAGIC {
        out.push(Diagnostic::new(
            &codes::GLB_INVALID_MAGIC,
            "",
            format!(
                "the file starts with {:?}, not the GLB magic \"glTF\"",
                String::from_utf8_lossy(&bytes[0..4])
            ),
        ));
        return None;
    }
    let version = u32_at(bytes, 4);
    if version != 2 {
        out.push(Diagnostic::new(
            &codes::GLB_INVALID_VERSION,
            "",
            format!("the GLB header declares version {version}; only version 2 is defined"),
        ));
        return None;
    }
    let declared = u32_at(bytes, 8) as usize;
    // Bytes after the declared length are not part of the GLB: loaders stop at the length.
    let end = if declared > bytes.len() || declared < HEADER_LEN {
        out.push(Diagnostic::new(
            &codes::GLB_LENGTH_MISMATCH,
            "",
            format!(
                "the GLB header declares {declared} bytes but the file has {}",
                bytes.len()
            ),
        ));
        bytes.len()
    } else {
        if declared < bytes.len() {
            out.push(Diagnostic::new(
                &codes::GLB_TRAILING_DATA,
                "",
                format!(
                    "the file has {} bytes after the {declared} its GLB header declares; they are ignored",
                    bytes.len() - declared
                ),
            ));
        }
        declared
    };
    let mut at = HEADER_LEN;
    let mut json: Option<(usize, usize)> = None;
    let mut bin: Option<(usize, usize)> = None;
    let mut index = 0usize;
    let mut after_unknown = false;
    let mut other = Vec::new();
    while at < end {
        if end - at < CHUNK_HEADER_LEN {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_END,
                "",
                format!("the file ends inside the header of chunk {index} at byte {at}"),
            ));
            break;
        }
        let length = u32_at(bytes, at) as usize;
        let kind = u32_at(bytes, at + 4);
        let data = at + CHUNK_HEADER_LEN;
        if !length.is_multiple_of(4) {
            out.push(Diagnostic::new(
                &codes::GLB_CHUNK_LENGTH_UNALIGNED,
                "",
                format!("chunk {index} at byte {at} has length {length}, not a multiple of 4"),
            ));
        }
        let available = end - data;
        let (data_end, truncated) = if length > available {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_END,
                "",
                format!(
                    "chunk {index} at byte {at} declares {length} bytes but only {available} remain in the file"
                ),
            ));
            (end, true)
        } else {
            (data + length, false)
        };
        match kind {
            CHUNK_JSON if index == 0 => json = Some((data, data_end)),
            CHUNK_BIN if index == 1 && !after_unknown && bin.is_none() => {
                bin = Some((data, data_end))
            }
            _ if index == 0 => {
                out.push(Diagnostic::new(
                    &codes::GLB_UNEXPECTED_FIRST_CHUNK,
                    "",
                    format!("the first chunk has type 0x{kind:08X}; it must be JSON (0x4E4F534A)"),
                ));
                return None;
            }
            CHUNK_JSON | CHUNK_BIN => out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_CHUNK,
                "",
                format!(
                    "chunk {index} at byte {at} is a {} chunk where none may stand; it is ignored",
                    if kind == CHUNK_JSON { "JSON" } else { "BIN" }
                ),
            )),
            _ => {
                after_unknown = true;
                if !truncated {
                    other.push(&bytes[at..data_end]);
                }
                out.push(Diagnostic::new(
                    &codes::GLB_UNKNOWN_CHUNK_TYPE,
                    "",
                    format!(
                        "chunk {index} at byte {at} has unknown type 0x{kind:08X}; it is skipped"
                    ),
                ));
            }
        }
        if truncated {
            break;
        }
        at = data_end;
        index += 1;
    }
    let Some((json_start, json_end)) = json else {
        if end == HEADER_LEN {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_END,
                "",
                "the GLB ends after its header: it has no JSON chunk",
            ));
        }
        return None;
    };
    let json_bytes = &bytes[json_start..json_end];
    // Padding must be spaces; NULs (a common exporter mistake) would also break JSON parsers.
    if json_bytes.ends_with(&[0]) {
        out.push(Diagnostic::new(
            &codes::GLB_INVALID_PADDING,
            "",
            "the JSON chunk is padded with NUL bytes; the GLB container requires spaces (0x20)",
        ));
    }
    Some(GlbParts {
        json: json_bytes,
        json_offset: json_start,
        bin: bin.map(|(s, e)| &bytes[s..e]),
        other,
    })
}

/// Builds a GLB file from a JSON text and an optional BIN chunk; both are padded to 4 bytes.
pub fn join(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    join_with(json, bin, &[])
}

/// Builds a GLB file as [`join`] does, then appends `other` chunks (whole, header and data) as
/// they were read: the chunks of unknown types a rewrite keeps.
pub fn join_with(json: &[u8], bin: Option<&[u8]>, other: &[Vec<u8>]) -> Vec<u8> {
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *MAGIC,
            version: 2,
            // to_vec computes the real length itself.
            length: 0,
        },
        json: Cow::Borrowed(json),
        bin: bin.map(Cow::Borrowed),
    };
    let mut bytes = glb.to_vec().expect("writing a GLB into memory cannot fail");
    if !other.is_empty() {
        for chunk in other {
            bytes.extend_from_slice(chunk);
        }
        // The header's length covers the chunks after BIN too; a length beyond 4 GiB is not
        // a GLB (the loader refuses such a file before this).
        let length = u32::try_from(bytes.len()).unwrap_or(u32::MAX);
        bytes[8..12].copy_from_slice(&length.to_le_bytes());
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn codes_of(out: &[Diagnostic]) -> Vec<&str> {
        out.iter().map(|d| d.code).collect()
    }

    #[test]
    fn join_then_split_round_trips_with_padding() {
        let bytes = join(b"{\"a\":1}", Some(&[1, 2, 3]));
        assert_eq!(bytes.len(), 12 + 8 + 8 + 8 + 4);
        assert_eq!(u32_at(&bytes, 8) as usize, bytes.len());
        let mut out = Vec::new();
        let parts = split(&bytes, &mut out).unwrap();
        assert!(out.is_empty(), "{out:?}");
        assert_eq!(parts.json, b"{\"a\":1} ");
        assert_eq!(parts.json_offset, 20);
        assert_eq!(parts.bin, Some(&[1u8, 2, 3, 0][..]));
    }

    #[test]
    fn truncated_file_reports_unexpected_end_and_length_mismatch() {
        let bytes = join(b"{\"a\":1}", Some(&[0; 16]));
        let cut = &bytes[..bytes.len() - 6];
        let mut out = Vec::new();
        let parts = split(cut, &mut out).unwrap();
        assert_eq!(
            codes_of(&out),
            vec!["GLB_LENGTH_MISMATCH", "GLB_UNEXPECTED_END"]
        );
        assert_eq!(parts.bin.map(<[u8]>::len), Some(10));
    }

    #[test]
    fn short_header_bad_magic_and_version_stop_loading() {
        let mut out = Vec::new();
        assert!(split(b"glTF", &mut out).is_none());
        assert!(split(b"GLTF\x02\0\0\0\x0c\0\0\0", &mut out).is_none());
        assert!(split(b"glTF\x01\0\0\0\x0c\0\0\0", &mut out).is_none());
        assert_eq!(
            codes_of(&out),
            vec![
                "GLB_UNEXPECTED_END",
                "GLB_INVALID_MAGIC",
                "GLB_INVALID_VERSION"
            ]
        );
    }

    #[test]
    fn unaligned_chunk_and_unknown_chunk_are_reported() {
        let mut bytes = b"glTF\x02\0\0\0\0\0\0\0".to_vec();
        bytes.extend_from_slice(&7u32.to_le_bytes());
        bytes.extend_from_slice(b"JSON{\"a\":1}");
        bytes.extend_from_slice(&4u32.to_le_bytes());
        bytes.extend_from_slice(b"XYZW\0\0\0\0");
        let len = bytes.len() as u32;
        bytes[8..12].copy_from_slice(&len.to_le_bytes());
        let mut out = Vec::new();
        let parts = split(&bytes, &mut out).unwrap();
        assert_eq!(
            codes_of(&out),
            vec!["GLB_CHUNK_LENGTH_UNALIGNED", "GLB_UNKNOWN_CHUNK_TYPE"]
        );
        assert_eq!(parts.json, b"{\"a\":1}");
        assert!(parts.bin.is_none());
    }

    #[test]
    fn bin_first_is_rejected() {
        let mut bytes = b"glTF\x02\0\0\0\x18\0\0\0".to_vec();
        bytes.extend_from_slice(&4u32.to_le_bytes());
        bytes.extend_from_slice(b"BIN\0\0\0\0\0");
        let mut out = Vec::new();
        assert!(split(&bytes, &mut out).is_none());
        assert_eq!(codes_of(&out), vec!["GLB_UNEXPECTED_FIRST_CHUNK"]);
    }
}
