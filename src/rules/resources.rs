//! Resources: every buffer and image a document names is checked on every run, whether or not
//! a sheen or fuzz rule needs its bytes, because a missing or broken resource breaks the asset
//! for every loader.
//!
//! For each URI: its syntax (percent-encoding, a `data:` URI's base64 and media type), its
//! scheme (remote URLs are valid glTF but not checked), whether it leaves the asset's folder
//! (judged on the resolved path, so a symbolic link inside the folder that points outside
//! leaves it too), and whether the file exists — a `stat`, not a read. A small file that is a
//! Git LFS pointer (a clone without `git lfs pull`) is named as such. A buffer file shorter than
//! its byteLength is found from its size. For every image the header is read (never the
//! pixels): its format must match `mimeType`, and what it holds that glTF does not support
//! (colour information other than sRGB's, non-square pixels, animation) is named. Images stored in a bufferView are checked when
//! the buffer is already in memory (the GLB BIN chunk or a `data:` URI); an external .bin is not
//! opened for them.

use super::{Context, Rule};
use crate::asset::resource::{self, ImageFormat, Location};
use crate::asset::tape::Node;
use crate::diagnostics::{codes, Code, Diagnostic, Severity};

pub const FILE_NOT_FOUND: Code = Code::new(
    "FILE_NOT_FOUND",
    Severity::Error,
    "A buffer or image URI names a file that does not exist.",
);
pub const GIT_LFS_POINTER: Code = Code::new(
    "GIT_LFS_POINTER",
    Severity::Error,
    "A buffer or image file is a Git LFS pointer, not its content (fetch it with `git lfs pull`).",
);
pub const IMAGE_MIME_TYPE_INVALID: Code = Code::new(
    "IMAGE_MIME_TYPE_INVALID",
    Severity::Error,
    "An image's data is in another format than its mimeType (or data: media type) declares.",
);
pub const IMAGE_NON_ENABLED_MIME_TYPE: Code = Code::new(
    "IMAGE_NON_ENABLED_MIME_TYPE",
    Severity::Error,
    "An image is WebP or KTX2 but the extension that lets textures use it is not in extensionsUsed.",
);
pub const URI_GLB: Code = Code::new(
    "URI_GLB",
    Severity::Info,
    "A .glb's buffer or image has a URI: its data is not all in the file.",
);
pub const IMAGE_NPOT_DIMENSIONS: Code = Code::new(
    "IMAGE_NPOT_DIMENSIONS",
    Severity::Info,
    "An image's width or height is not a power of two; some loaders and texture formats need one.",
);
/// A warning, as the Khronos validator has it: loaders ignore what glTF does not support, so the
/// image may look other than its author saw it.
pub const IMAGE_FEATURES_UNSUPPORTED: Code = Code::new(
    "IMAGE_FEATURES_UNSUPPORTED",
    Severity::Warning,
    "An image's header holds what glTF does not support: colour information other than sRGB's (an ICC profile, a gamma, primaries), non-square pixels, or animation.",
);
pub const DATA_URI_GLB: Code = Code::new(
    "DATA_URI_GLB",
    Severity::Warning,
    "A .glb's buffer or image uses a data: URI; the BIN chunk holds binary data without base64's third more bytes.",
);
pub const BUFFER_DATA_URI_MIME_TYPE_INVALID: Code = Code::new(
    "BUFFER_DATA_URI_MIME_TYPE_INVALID",
    Severity::Error,
    "A buffer's data: URI has a media type other than application/octet-stream or application/gltf-buffer.",
);
pub const NON_RELATIVE_URI: Code = Code::new(
    "NON_RELATIVE_URI",
    Severity::Warning,
    "A resource URI with a URL scheme (https:, …): valid glTF, but not portable, and not checked.",
);

/// A warning, not an error: the spec's "MAY use base64" does not forbid RFC 2397's
/// percent-encoded form, and the Khronos validator decodes it.
pub const DATA_URI_NOT_BASE64: Code = Code::new(
    "DATA_URI_NOT_BASE64",
    Severity::Warning,
    "A data: URI is percent-encoded rather than base64: valid, but some loaders decode only base64.",
);

pub struct Resources;

impl Rule for Resources {
    fn reads(&self) -> super::Reads {
        super::Reads::Properties {
            properties: &["buffers", "bufferViews", "images", "extensionsUsed"],
            except: &[("bufferViews", "target")],
        }
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &FILE_NOT_FOUND,
            &GIT_LFS_POINTER,
            &IMAGE_MIME_TYPE_INVALID,
            &BUFFER_DATA_URI_MIME_TYPE_INVALID,
            &NON_RELATIVE_URI,
            &DATA_URI_NOT_BASE64,
            &codes::URI_NOT_FOLLOWED,
            &codes::INVALID_URI,
            &codes::IO_ERROR,
            &codes::IMAGE_UNRECOGNIZED_FORMAT,
            &codes::IMAGE_DATA_INVALID,
            &codes::IMAGE_UNEXPECTED_EOS,
            &codes::BUFFER_BYTE_LENGTH_MISMATCH,
            &IMAGE_NON_ENABLED_MIME_TYPE,
            &IMAGE_NPOT_DIMENSIONS,
            &IMAGE_FEATURES_UNSUPPORTED,
            &URI_GLB,
            &DATA_URI_GLB,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let glb = cx.asset.container == crate::asset::Container::Glb;
        for (key, check) in [
            (
                "buffers",
                check_buffer as fn(&Context, usize, Node, &mut Vec<Diagnostic>),
            ),
            ("images", check_image),
        ] {
            for (index, object) in array(json, key) {
                if glb && object.get("uri").is_some_and(|u| u.is_string()) {
                    out.push(Diagnostic::new(
                        &URI_GLB,
                        format!("/{key}/{index}/uri"),
                        "a URI in a .glb: the file does not hold all its data",
                    ));
                }
                // A data: URI without its payload is INVALID_URI alone.
                let data_uri = object
                    .get("uri")
                    .and_then(|u| u.as_str())
                    .is_some_and(|u| u.starts_with("data:") && u.contains(','));
                if glb && data_uri {
                    out.push(Diagnostic::new(
                        &DATA_URI_GLB,
                        format!("/{key}/{index}/uri"),
                        "a data: URI in a .glb: the BIN chunk holds the same bytes without base64",
                    ));
                }
                check(cx, index, object, out);
            }
        }
    }
}

/// The distinct URIs of the buffers and images of `json` that name files: not data: URIs, not
/// URLs.
pub fn file_uris(json: Node) -> std::collections::BTreeSet<String> {
    ["buffers", "images"]
        .into_iter()
        .flat_map(|key| array(json, key))
        .filter_map(|(_, resource)| resource.get("uri")?.as_str())
        .filter(|uri| !uri.starts_with("data:") && !resource::is_remote(uri))
        .map(std::borrow::Cow::into_owned)
        .collect()
}

fn array<'a>(json: Node<'a>, key: &str) -> impl Iterator<Item = (usize, Node<'a>)> {
    super::elements(json.get(key))
        .enumerate()
        .filter(|(_, v)| v.is_object())
}

fn byte_length(buffer: Node) -> Option<u64> {
    buffer.get("byteLength").and_then(super::as_index)
}

fn short_buffer(index: usize, declared: u64, actual: u64, what: &str) -> Diagnostic {
    Diagnostic::new(
        // At the buffer, as the Khronos validator places it.
        &codes::BUFFER_BYTE_LENGTH_MISMATCH,
        format!("/buffers/{index}"),
        format!("buffer {index} declares {declared} bytes but {what} holds {actual}"),
    )
}

fn check_buffer(cx: &Context, index: usize, buffer: Node, out: &mut Vec<Diagnostic>) {
    let declared = byte_length(buffer);
    // A buffer without uri is valid glTF: in a GLB the first one takes its bytes from the BIN
    // chunk (the loader reports BUFFER_MISSING_GLB_DATA when the chunk is absent); any other
    // is filled by an extension (EXT_meshopt_compression's fallback) or read by nothing.
    let Some(uri) = buffer.get("uri") else {
        return;
    };
    let Some(uri) = uri.as_str() else { return }; // TYPE_MISMATCH from the schema
    let pointer = format!("/buffers/{index}/uri");
    match locate(cx, &uri, &pointer, out) {
        Some(Located::Data {
            media_type, len, ..
        }) => {
            // In lower case, without parameters, as `resolve` gives it.
            if !matches!(
                media_type.as_str(),
                "application/octet-stream" | "application/gltf-buffer"
            ) {
                out.push(Diagnostic::new(
                    &BUFFER_DATA_URI_MIME_TYPE_INVALID,
                    &pointer,
                    format!(
                        "the data: URI's media type is '{media_type}'; a buffer's must be application/octet-stream or application/gltf-buffer"
                    ),
                ));
            }
            if let Some(declared) = declared.filter(|d| *d > len) {
                out.push(short_buffer(index, declared, len, "its data: URI"));
            }
        }
        Some(Located::File { len }) => {
            if let Some(declared) = declared.filter(|d| *d > len) {
                out.push(short_buffer(index, declared, len, &format!("'{uri}'")));
            }
        }
        None => {}
    }
}

fn check_image(cx: &Context, index: usize, image: Node, out: &mut Vec<Diagnostic>) {
    let mut declared = image
        .get("mimeType")
        .and_then(|m| m.as_str())
        .map(|m| (m.to_string(), format!("/images/{index}/mimeType")));
    if let Some(uri) = image.get("uri") {
        let Some(uri) = uri.as_str() else { return };
        let pointer = format!("/images/{index}/uri");
        match locate(cx, &uri, &pointer, out) {
            Some(Located::Data {
                media_type,
                holds,
                len,
            }) => {
                // The Khronos validator holds an image's data: URI to its own media type: bytes
                // of another format, or bytes of no format it knows under a type it knows, make
                // the URI invalid, and the image is not judged further. A type velvet does not
                // read (DDS, AVIF, from their extensions) over bytes it does not recognize is
                // valid glTF, left alone as a `mimeType` of that type is.
                let known = KNOWN_MIME_TYPES.contains(&media_type.as_str());
                let held = holds.map(mime_of);
                if held != Some(media_type.as_str()) {
                    if !known && held.is_none() {
                        return;
                    }
                    let bytes = match held {
                        Some(held) => format!("its bytes are {held}"),
                        None if len == 0 => "it holds no bytes".to_string(),
                        None => "its bytes are no image format velvet recognizes".to_string(),
                    };
                    out.push(Diagnostic::new(
                        &codes::INVALID_URI,
                        &pointer,
                        format!("image {index}'s data: URI says {media_type}, but {bytes}"),
                    ));
                    return;
                }
                if declared.is_none() {
                    declared = Some((media_type, pointer));
                }
            }
            Some(Located::File { .. }) => {}
            None => return,
        }
    } else if !view_in_memory(cx, image) {
        return;
    }
    // An image in a format velvet does not read (DDS, AVIF, … from their extensions) is
    // valid glTF; its header is not velvet's to judge.
    if declared
        .as_ref()
        .is_some_and(|(mime, _)| !KNOWN_MIME_TYPES.contains(&mime.as_str()))
        || image
            .get("uri")
            .and_then(|u| u.as_str())
            .is_some_and(|uri| !uri.starts_with("data:") && other_format_extension(&uri))
    {
        return;
    }
    match cx.asset.image_header(index) {
        Ok(header) => {
            // WebP and KTX2 are formats only an extension lets a texture use.
            let enabling: &[&str] = match header.format {
                ImageFormat::Webp => &["EXT_texture_webp"],
                ImageFormat::Ktx2 => &["KHR_texture_basisu", "EXT_texture_astc"],
                _ => &[],
            };
            let declared_extension = |name: &&str| super::declares(cx.json(), name);
            if !header.width.is_power_of_two() || !header.height.is_power_of_two() {
                out.push(Diagnostic::new(
                    &IMAGE_NPOT_DIMENSIONS,
                    format!("/images/{index}"),
                    format!(
                        "image {index} is {} × {}, not a power of two in each dimension",
                        header.width, header.height
                    ),
                ));
            }
            if header.features.any() {
                out.push(Diagnostic::new(
                    &IMAGE_FEATURES_UNSUPPORTED,
                    format!("/images/{index}"),
                    format!(
                        "image {index} holds what glTF does not support: {}",
                        header.features.describe().join(", ")
                    ),
                ));
            }
            if !enabling.is_empty() && !enabling.iter().any(declared_extension) {
                out.push(Diagnostic::new(
                    &IMAGE_NON_ENABLED_MIME_TYPE,
                    format!("/images/{index}"),
                    format!(
                        "image {index} is {}, which needs {} in extensionsUsed",
                        mime_of(header.format),
                        enabling.join(" or ")
                    ),
                ));
            }
            let Some((mime, pointer)) = declared else {
                return;
            };
            let actual = mime_of(header.format);
            if mime != actual {
                // The Khronos validator places the mismatch at the image's data: its uri.
                let pointer = if image.get("uri").is_some() {
                    format!("/images/{index}/uri")
                } else {
                    pointer
                };
                out.push(Diagnostic::new(
                    &IMAGE_MIME_TYPE_INVALID,
                    pointer,
                    format!("image {index} is {actual} but declares '{mime}'"),
                ));
            }
        }
        Err(d) => out.push(d),
    }
}

/// The image media types whose headers velvet reads.
const KNOWN_MIME_TYPES: [&str; 4] = ["image/png", "image/jpeg", "image/webp", "image/ktx2"];

/// True for a file name whose extension names an image format velvet does not read.
fn other_format_extension(uri: &str) -> bool {
    let name = uri.rsplit('/').next().unwrap_or(uri);
    match name.rsplit_once('.') {
        Some((_, ext)) => !matches!(
            ext.to_ascii_lowercase().as_str(),
            "png" | "jpg" | "jpeg" | "webp" | "ktx2"
        ),
        None => false,
    }
}

fn mime_of(format: ImageFormat) -> &'static str {
    match format {
        ImageFormat::Png => "image/png",
        ImageFormat::Jpeg => "image/jpeg",
        ImageFormat::Webp => "image/webp",
        ImageFormat::Ktx2 => "image/ktx2",
    }
}

/// True when an image's bufferView lies in a buffer already in memory.
fn view_in_memory(cx: &Context, image: Node) -> bool {
    let json = cx.json();
    let Some(buffer) = image
        .get("bufferView")
        .and_then(super::as_index)
        .and_then(|v| json.get("bufferViews")?.get(v as usize))
        .and_then(|view| view.get("buffer"))
        .and_then(super::as_index)
        .and_then(|b| json.get("buffers")?.get(b as usize))
    else {
        return false; // a dangling index is reported by the indices rule
    };
    match buffer.get("uri").and_then(|u| u.as_str()) {
        Some(uri) => uri.starts_with("data:"),
        None => cx.asset.bin.is_some(),
    }
}

/// What a URI that could be followed leads to.
enum Located {
    /// A `data:` URI: its media type (parameters left out, lower case), how many bytes it
    /// holds, and the image format those bytes begin as, if they begin as one.
    Data {
        media_type: String,
        len: u64,
        holds: Option<ImageFormat>,
    },
    File {
        len: u64,
    },
}

/// Resolves `uri` and checks what it leads to, pushing every fault; `None` when there is
/// nothing further to check.
fn locate(cx: &Context, uri: &str, pointer: &str, out: &mut Vec<Diagnostic>) -> Option<Located> {
    if resource::is_remote(uri) {
        out.push(Diagnostic::new(
            &NON_RELATIVE_URI,
            pointer,
            format!("'{uri}' is a URL; velvet does not fetch it, so it was not checked"),
        ));
        return None;
    }
    let path = match cx.asset.resolve(uri, pointer) {
        Ok(Location::Data {
            media_type,
            bytes,
            base64,
        }) => {
            if !base64 {
                out.push(Diagnostic::new(
                    &DATA_URI_NOT_BASE64,
                    pointer,
                    "the data: URI is percent-encoded, not base64; it is valid, but some loaders decode only base64",
                ));
            }
            return Some(Located::Data {
                media_type,
                len: bytes.len() as u64,
                holds: ImageFormat::sniff(&bytes),
            });
        }
        Ok(Location::File(path)) => path,
        Err(d) => {
            out.push(d);
            return None;
        }
    };
    let fault = |code: &Code, detail: String| Diagnostic::new(code, pointer, detail);
    // Asset::resolve has refused links that lead out of the folder. A stat, not a read (and
    // the first bytes of a file short enough to be a Git LFS pointer).
    let facts = match cx.asset.file_facts(&path) {
        Ok(facts) if facts.is_file => facts,
        Ok(_) => {
            out.push(fault(
                &codes::IO_ERROR,
                format!("'{uri}' ({}) is not a regular file", path.display()),
            ));
            return None;
        }
        Err((kind, e)) => {
            out.push(if kind == std::io::ErrorKind::NotFound {
                fault(
                    &FILE_NOT_FOUND,
                    format!("'{uri}' names {}, which does not exist", path.display()),
                )
            } else {
                fault(
                    &codes::IO_ERROR,
                    format!("cannot read '{uri}' ({}): {e}", path.display()),
                )
            });
            return None;
        }
    };
    if facts.lfs_pointer {
        out.push(fault(
            &GIT_LFS_POINTER,
            format!(
                "'{uri}' is a Git LFS pointer file, not its content: fetch it with `git lfs pull`"
            ),
        ));
        return None;
    }
    Some(Located::File { len: facts.len })
}
