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

/// Splits a GLB file, pushing a diagnostic for every fault, with the Khronos glTF-Validator's
/// codes: the header's length is the length of the GLB, chunks are read in order until it is
/// reached or the file ends, and the first chunk must be JSON. Returns `None` when no JSON
/// chunk can be had.
pub fn split<'a>(bytes: &'a [u8], out: &mut Vec<Diagnostic>) -> Option<GlbParts<'a>> {
    let size = bytes.len();
    if size < HEADER_LEN {
        out.push(Diagnostic::new(
            &codes::GLB_UNEXPECTED_END_OF_HEADER,
            "",
            format!("the file is {size} bytes long; a GLB header needs 12"),
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
    if declared <= HEADER_LEN {
        out.push(Diagnostic::new(
            &codes::GLB_LENGTH_TOO_SMALL,
            "",
            format!("the GLB header declares {declared} bytes, leaving no room for a chunk"),
        ));
    }
    let mut at = HEADER_LEN;
    let mut json: Option<(usize, usize)> = None;
    let mut bin: Option<(usize, usize)> = None;
    let mut index = 0usize;
    let mut after_unknown = false;
    let mut other = Vec::new();
    // Whether the file ended inside a chunk: its length is then not judged again.
    let mut cut_short = false;
    while at < declared && at < size {
        if size - at < CHUNK_HEADER_LEN {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_END_OF_CHUNK_HEADER,
                "",
                format!("the file ends inside the header of chunk {index} at byte {at}"),
            ));
            cut_short = true;
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
        if data.saturating_add(length) > declared {
            out.push(Diagnostic::new(
                &codes::GLB_CHUNK_TOO_BIG,
                "",
                format!(
                    "chunk {index} at byte {at} declares {length} bytes, past the {declared} the GLB header declares"
                ),
            ));
        }
        let available = size - data;
        let (data_end, truncated) = if length > available {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_END_OF_CHUNK_DATA,
                "",
                format!(
                    "chunk {index} at byte {at} declares {length} bytes but only {available} remain in the file"
                ),
            ));
            cut_short = true;
            (size, true)
        } else {
            (data + length, false)
        };
        if kind == CHUNK_JSON && length == 0 {
            out.push(Diagnostic::new(
                &codes::GLB_EMPTY_CHUNK,
                "",
                format!("chunk {index} at byte {at} is an empty JSON chunk"),
            ));
        }
        if index == 0 && kind != CHUNK_JSON {
            out.push(Diagnostic::new(
                &codes::GLB_UNEXPECTED_FIRST_CHUNK,
                "",
                format!("the first chunk has type 0x{kind:08X}; it must be JSON (0x4E4F534A)"),
            ));
        }
        match kind {
            CHUNK_JSON if json.is_none() && index == 0 => json = Some((data, data_end)),
            CHUNK_BIN if bin.is_none() => {
                // A BIN chunk after an unknown one is out of place, but it is still the BIN
                // chunk: loaders that find it use it.
                if after_unknown {
                    out.push(Diagnostic::new(
                        &codes::GLB_UNEXPECTED_BIN_CHUNK,
                        "",
                        format!("the BIN chunk at byte {at} follows a chunk of unknown type; it must come right after the JSON chunk"),
                    ));
                }
                bin = Some((data, data_end));
            }
            CHUNK_JSON | CHUNK_BIN => out.push(Diagnostic::new(
                &codes::GLB_DUPLICATE_CHUNK,
                "",
                format!(
                    "chunk {index} at byte {at} is a second {} chunk; it is ignored",
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
    if !cut_short {
        if at == declared && size > declared {
            // Bytes after the declared length are not part of the GLB: loaders stop there.
            out.push(Diagnostic::new(
                &codes::GLB_EXTRA_DATA,
                "",
                format!(
                    "the file has {} bytes after the {declared} its GLB header declares; they are ignored",
                    size - declared
                ),
            ));
        } else if at != declared {
            out.push(Diagnostic::new(
                &codes::GLB_LENGTH_MISMATCH,
                "",
                format!("the GLB header declares {declared} bytes but the file has {size}"),
            ));
        }
    }
    // An empty JSON chunk is that finding alone: there is no document to read.
    let (json_start, json_end) = json.filter(|(start, end)| end > start)?;
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
        assert_eq!(codes_of(&out), vec!["GLB_UNEXPECTED_END_OF_CHUNK_DATA"]);
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
                "GLB_UNEXPECTED_END_OF_HEADER",
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

    /// A GLB of the given chunks (type, data), its header's length `declared` or the real one.
    fn glb_of(chunks: &[(&[u8; 4], &[u8])], declared: Option<u32>) -> Vec<u8> {
        let mut bytes = b"glTF\x02\0\0\0\0\0\0\0".to_vec();
        for (kind, data) in chunks {
            bytes.extend_from_slice(&(data.len() as u32).to_le_bytes());
            bytes.extend_from_slice(*kind);
            bytes.extend_from_slice(data);
        }
        let len = declared.unwrap_or(bytes.len() as u32);
        bytes[8..12].copy_from_slice(&len.to_le_bytes());
        bytes
    }

    fn split_codes(bytes: &[u8]) -> Vec<&'static str> {
        let mut out = Vec::new();
        split(bytes, &mut out);
        out.iter().map(|d| d.code).collect()
    }

    #[test]
    fn container_faults_get_the_reference_validators_codes() {
        let json: &[u8] = b"{\"asset\":{\"version\":\"2.0\"}} ";
        assert_eq!(
            split_codes(&glb_of(&[], Some(12))),
            ["GLB_LENGTH_TOO_SMALL"]
        );
        assert_eq!(
            split_codes(&glb_of(&[], Some(0))),
            ["GLB_LENGTH_TOO_SMALL", "GLB_LENGTH_MISMATCH"]
        );
        assert_eq!(
            split_codes(&glb_of(&[(b"JSON", json)], Some(13))),
            ["GLB_CHUNK_TOO_BIG", "GLB_LENGTH_MISMATCH"]
        );
        let whole = glb_of(&[(b"JSON", json)], None);
        let mut extra = whole.clone();
        extra.push(0);
        assert_eq!(split_codes(&extra), ["GLB_EXTRA_DATA"]);
        let mut longer = whole.clone();
        longer[8] += 1;
        assert_eq!(split_codes(&longer), ["GLB_LENGTH_MISMATCH"]);
        assert_eq!(
            split_codes(&whole[..13]),
            ["GLB_UNEXPECTED_END_OF_CHUNK_HEADER"]
        );
        assert_eq!(
            split_codes(&glb_of(&[(b"JSON", b""), (b"JSON", b"")], None)),
            ["GLB_EMPTY_CHUNK", "GLB_EMPTY_CHUNK", "GLB_DUPLICATE_CHUNK"]
        );
        assert_eq!(
            split_codes(&glb_of(
                &[(b"JSON", json), (b"BIN\0", b"abcd"), (b"BIN\0", b"abcd")],
                None
            )),
            ["GLB_DUPLICATE_CHUNK"]
        );
        let mut out = Vec::new();
        let misplaced = glb_of(
            &[(b"JSON", json), (b"UNK\0", b"abcd"), (b"BIN\0", b"efgh")],
            None,
        );
        let parts = split(&misplaced, &mut out).expect("the JSON chunk is read");
        assert_eq!(
            codes_of(&out),
            ["GLB_UNKNOWN_CHUNK_TYPE", "GLB_UNEXPECTED_BIN_CHUNK"]
        );
        assert_eq!(parts.bin, Some(&b"efgh"[..]));
        assert_eq!(
            split_codes(&glb_of(&[(b"UNK\0", b"abcd")], None)),
            ["GLB_UNEXPECTED_FIRST_CHUNK", "GLB_UNKNOWN_CHUNK_TYPE"]
        );
        assert_eq!(
            split_codes(&glb_of(&[(b"BIN\0", b"abcd"), (b"BIN\0", b"abcd")], None)),
            ["GLB_UNEXPECTED_FIRST_CHUNK", "GLB_DUPLICATE_CHUNK"]
        );
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
