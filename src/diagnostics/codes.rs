//! Codes owned by the loader (reading .gltf/.glb files and their resources) and by the schema
//! check. Names follow the Khronos glTF-Validator where the meaning is the same.

use super::{Code, Severity::*};

pub const IO_ERROR: Code = Code::new(
    "IO_ERROR",
    Error,
    "A file or an external resource could not be read.",
);
pub const INVALID_JSON: Code = Code::new(
    "INVALID_JSON",
    Error,
    "The glTF JSON is not valid UTF-8 JSON (the message gives line and column).",
);
pub const BOM_PRESENT: Code = Code::new(
    "BOM_PRESENT",
    Error,
    "The JSON starts with a UTF-8 byte-order mark, which glTF forbids; the rest was checked.",
)
.fixable(super::Safety::Safe);
pub const GLB_INVALID_MAGIC: Code = Code::new(
    "GLB_INVALID_MAGIC",
    Error,
    "A .glb file does not start with the magic 'glTF'.",
);
pub const GLB_INVALID_VERSION: Code = Code::new(
    "GLB_INVALID_VERSION",
    Error,
    "A .glb header declares a container version other than 2.",
);
pub const GLB_LENGTH_MISMATCH: Code = Code::new(
    "GLB_LENGTH_MISMATCH",
    Error,
    "The length in the GLB header differs from the file's length.",
)
.fixable(super::Safety::Unsafe);
pub const GLB_UNEXPECTED_END_OF_HEADER: Code = Code::new(
    "GLB_UNEXPECTED_END_OF_HEADER",
    Error,
    "A .glb file ends inside its 12-byte header.",
);
pub const GLB_UNEXPECTED_END_OF_CHUNK_HEADER: Code = Code::new(
    "GLB_UNEXPECTED_END_OF_CHUNK_HEADER",
    Error,
    "A .glb file ends inside a chunk's header.",
);
pub const GLB_UNEXPECTED_END_OF_CHUNK_DATA: Code = Code::new(
    "GLB_UNEXPECTED_END_OF_CHUNK_DATA",
    Error,
    "A .glb file ends inside a chunk's data (a truncated file).",
);
pub const GLB_LENGTH_TOO_SMALL: Code = Code::new(
    "GLB_LENGTH_TOO_SMALL",
    Error,
    "The length in the GLB header leaves no room for a chunk.",
);
pub const GLB_CHUNK_TOO_BIG: Code = Code::new(
    "GLB_CHUNK_TOO_BIG",
    Error,
    "A GLB chunk runs past the length the GLB header declares.",
);
pub const GLB_EMPTY_CHUNK: Code = Code::new("GLB_EMPTY_CHUNK", Error, "A GLB JSON chunk is empty.");
pub const GLB_DUPLICATE_CHUNK: Code = Code::new(
    "GLB_DUPLICATE_CHUNK",
    Error,
    "A second JSON or BIN chunk; loaders ignore it.",
);
pub const GLB_UNEXPECTED_BIN_CHUNK: Code = Code::new(
    "GLB_UNEXPECTED_BIN_CHUNK",
    Error,
    "The BIN chunk follows a chunk of unknown type; it must come right after the JSON chunk.",
);
pub const GLB_CHUNK_LENGTH_UNALIGNED: Code = Code::new(
    "GLB_CHUNK_LENGTH_UNALIGNED",
    Error,
    "A GLB chunk's length is not a multiple of 4.",
)
.fixable(super::Safety::Safe);
pub const GLB_UNEXPECTED_FIRST_CHUNK: Code = Code::new(
    "GLB_UNEXPECTED_FIRST_CHUNK",
    Error,
    "The first GLB chunk is not the JSON chunk.",
);
pub const GLB_UNKNOWN_CHUNK_TYPE: Code = Code::new(
    "GLB_UNKNOWN_CHUNK_TYPE",
    Warning,
    "A GLB chunk of unknown type; loaders skip it.",
);
pub const GLB_INVALID_PADDING: Code = Code::new(
    "GLB_INVALID_PADDING",
    Warning,
    "A GLB chunk's trailing padding is not spaces (JSON) or zeros (BIN).",
)
.fixable(super::Safety::Safe);
pub const URI_NOT_FOLLOWED: Code = Code::new(
    "URI_NOT_FOLLOWED",
    Error,
    "A resource URI that velvet does not follow: another scheme than data:, an absolute path, \
     or a path that climbs out of the asset's folder.",
);
pub const INVALID_URI: Code = Code::new(
    "INVALID_URI",
    Error,
    "A resource URI that cannot be decoded (malformed data: URI, base64 or percent-encoding), or an image data: URI whose bytes are not of the media type it says.",
);
pub const BUFFER_VIEW_OUT_OF_RANGE: Code = Code::new(
    "BUFFER_VIEW_OUT_OF_RANGE",
    Error,
    "An image's bufferView lies outside the data of its buffer.",
);
/// A warning, as in the Khronos validator: the document is valid, and a loader may know the
/// format. A damaged header of a format velvet knows is IMAGE_DATA_INVALID.
pub const IMAGE_UNRECOGNIZED_FORMAT: Code = Code::new(
    "IMAGE_UNRECOGNIZED_FORMAT",
    Warning,
    "An image's bytes are not PNG, JPEG, WebP or KTX2; loaders that know only those cannot read it.",
);
pub const IMAGE_UNEXPECTED_EOS: Code = Code::new(
    "IMAGE_UNEXPECTED_EOS",
    Error,
    "An image of a known format ends inside its header (a truncated file).",
);
pub const IMAGE_DATA_INVALID: Code = Code::new(
    "IMAGE_DATA_INVALID",
    Error,
    "An image starts as a PNG, JPEG, WebP or KTX2 but its header is damaged or cut short.",
);

/// Reported by the references rule for every index, and by the loader when a resource it is
/// asked for names no object.
pub const UNRESOLVED_REFERENCE: Code = Code::new(
    "UNRESOLVED_REFERENCE",
    Error,
    "An index names no object: a texture, an image, an accessor, a buffer, …",
);
pub const BUFFER_MISSING_GLB_DATA: Code = Code::new(
    "BUFFER_MISSING_GLB_DATA",
    Error,
    "A GLB's first buffer has no uri, and the GLB has no BIN chunk to hold its data.",
);
pub const BUFFER_GLB_CHUNK_TOO_BIG: Code = Code::new(
    "BUFFER_GLB_CHUNK_TOO_BIG",
    Warning,
    "A GLB's BIN chunk is longer than its buffer's byteLength padded to 4 bytes.",
);
pub const GLB_EXTRA_DATA: Code = Code::new(
    "GLB_EXTRA_DATA",
    Warning,
    "A .glb file has bytes after the length its header declares; loaders ignore them.",
)
.fixable(super::Safety::Safe);

pub const DOCUMENT_TOO_LARGE: Code = Code::new(
    "DOCUMENT_TOO_LARGE",
    Error,
    "The JSON document is larger than --max-document-bytes allows; it was not parsed.",
);
pub const JSON_TOO_DEEP: Code = Code::new(
    "JSON_TOO_DEEP",
    Error,
    "The JSON nests arrays and objects deeper than --max-json-depth allows; it was not parsed.",
);
pub const BUFFER_BYTE_LENGTH_MISMATCH: Code = Code::new(
    "BUFFER_BYTE_LENGTH_MISMATCH",
    Error,
    "A buffer's data (GLB BIN chunk, data: URI or file) is shorter than its byteLength.",
);
/// Reported by the image-size rule from headers, and by the decoders that refuse such images.
pub const IMAGE_TOO_LARGE: Code = Code::new(
    "IMAGE_TOO_LARGE",
    Error,
    "An image's header declares more pixels than --max-image-pixels allows; it was not decoded.",
);

/// Not a finding about an asset: the run could not start. The JSON reports of such a run hold
/// it as their one message, so that a report redirected into a file is never empty.
pub const USAGE_ERROR: Code = Code::new(
    "USAGE_ERROR",
    Error,
    "The run could not start (a path that does not exist, a bad flag value, an invalid velvet.toml); the JSON reports record it, and the exit status is 2.",
);

/// Codes velvet once emitted under its own names, with the Khronos glTF-Validator's codes that
/// replace them: a velvet.toml or `--ignore` that still names one is told what to write.
const RENAMED: &[(&str, &[&str])] = &[
    (
        "GLB_UNEXPECTED_END",
        &[
            "GLB_UNEXPECTED_END_OF_HEADER",
            "GLB_UNEXPECTED_END_OF_CHUNK_HEADER",
            "GLB_UNEXPECTED_END_OF_CHUNK_DATA",
        ],
    ),
    (
        "GLB_UNEXPECTED_CHUNK",
        &["GLB_DUPLICATE_CHUNK", "GLB_UNEXPECTED_BIN_CHUNK"],
    ),
    ("GLB_TRAILING_DATA", &["GLB_EXTRA_DATA"]),
    ("INVALID_JSON_ROOT_OBJECT", &["TYPE_MISMATCH"]),
];

/// The codes that replace a code velvet no longer emits.
pub fn renamed(code: &str) -> Option<&'static [&'static str]> {
    RENAMED
        .iter()
        .find(|(old, _)| *old == code)
        .map(|(_, now)| *now)
}

/// The codes about a run rather than a file (no asset triggers them).
pub const RUN: &[&Code] = &[&USAGE_ERROR];

pub const LOADER: &[&Code] = &[
    &IO_ERROR,
    &DOCUMENT_TOO_LARGE,
    &JSON_TOO_DEEP,
    &INVALID_JSON,
    &BOM_PRESENT,
    &GLB_INVALID_MAGIC,
    &GLB_INVALID_VERSION,
    &GLB_LENGTH_MISMATCH,
    &GLB_LENGTH_TOO_SMALL,
    &GLB_EXTRA_DATA,
    &GLB_UNEXPECTED_END_OF_HEADER,
    &GLB_UNEXPECTED_END_OF_CHUNK_HEADER,
    &GLB_UNEXPECTED_END_OF_CHUNK_DATA,
    &GLB_CHUNK_TOO_BIG,
    &GLB_EMPTY_CHUNK,
    &GLB_CHUNK_LENGTH_UNALIGNED,
    &GLB_UNEXPECTED_FIRST_CHUNK,
    &GLB_DUPLICATE_CHUNK,
    &GLB_UNEXPECTED_BIN_CHUNK,
    &GLB_UNKNOWN_CHUNK_TYPE,
    &GLB_INVALID_PADDING,
    &URI_NOT_FOLLOWED,
    &INVALID_URI,
    &BUFFER_VIEW_OUT_OF_RANGE,
    &BUFFER_BYTE_LENGTH_MISMATCH,
    &BUFFER_GLB_CHUNK_TOO_BIG,
    &IMAGE_UNRECOGNIZED_FORMAT,
    &IMAGE_DATA_INVALID,
    &IMAGE_UNEXPECTED_EOS,
    &UNRESOLVED_REFERENCE,
    &BUFFER_MISSING_GLB_DATA,
];

pub const TYPE_MISMATCH: Code = Code::new(
    "TYPE_MISMATCH",
    Error,
    "A property's value has the wrong JSON type.",
);
pub const VALUE_NOT_IN_RANGE: Code = Code::new(
    "VALUE_NOT_IN_RANGE",
    Error,
    "A number lies outside the range the schema allows.",
)
.fixable(super::Safety::Unsafe);
pub const ARRAY_LENGTH_NOT_IN_LIST: Code = Code::new(
    "ARRAY_LENGTH_NOT_IN_LIST",
    Error,
    "An array has a length the schema does not allow.",
);
pub const UNDEFINED_PROPERTY: Code = Code::new(
    "UNDEFINED_PROPERTY",
    Error,
    "A required property is missing.",
);
pub const UNEXPECTED_PROPERTY: Code = Code::new(
    "UNEXPECTED_PROPERTY",
    Warning,
    "A property the schema does not define (loaders ignore it).",
);
pub const VALUE_NOT_IN_LIST: Code = Code::new(
    "VALUE_NOT_IN_LIST",
    // A warning in the Khronos validator: an unknown enum value (a filter, an alphaMode) is
    // one a newer loader may know.
    Warning,
    "A value is not one of those the schema allows.",
);
pub const SCHEMA_MISMATCH: Code = Code::new(
    "SCHEMA_MISMATCH",
    Error,
    "A schema constraint without a more specific code failed (the message names it).",
);

pub const SCHEMA: &[&Code] = &[
    &TYPE_MISMATCH,
    &VALUE_NOT_IN_RANGE,
    &ARRAY_LENGTH_NOT_IN_LIST,
    &UNDEFINED_PROPERTY,
    &UNEXPECTED_PROPERTY,
    &VALUE_NOT_IN_LIST,
    &SCHEMA_MISMATCH,
];
