//! Asset I/O: turning a .gltf or .glb file into an [`Asset`] (the JSON text, which is the
//! source of truth, with its index from [`tape`], plus the GLB BIN chunk; a
//! `serde_json::Value` of the document only when an editor asks), lazy access to buffers and
//! images, JSON pointers and source positions, and the atomic writer.
//!
//! Nothing external is opened while loading: buffers and images are read when a rule or a
//! conversion asks, and for images only the header when that is enough.

pub mod discover;
pub mod glb;
pub mod image_features;
pub mod json_text;
mod key_table;
pub mod limits;
pub mod pages;
pub mod pointer;
pub mod position;
pub mod resource;
pub mod source;
pub mod tape;
pub mod tape_schema;

use crate::diagnostics::{codes, Diagnostic};
pub use limits::LoadOptions;
use resource::{ImageHeader, Location};
use serde_json::Value;
pub use source::{FileBytes, Snapshot, SourceText};
use std::borrow::Cow;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// The file format an asset came in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Container {
    Gltf,
    Glb,
}

impl Container {
    pub fn mime_type(self) -> &'static str {
        match self {
            Container::Gltf => "model/gltf+json",
            Container::Glb => "model/gltf-binary",
        }
    }
}

/// A loaded asset. `json_text` is the JSON as it was in the file and `tape` its index, which
/// validation reads; [`Asset::json`] is the document as a `serde_json::Value`, built on first
/// use, which the editors read and change.
#[derive(Debug)]
pub struct Asset {
    pub path: PathBuf,
    pub container: Container,
    json: OnceLock<Value>,
    pub json_text: SourceText,
    /// The index of `json_text` that the rules read.
    pub tape: tape::Tape,
    /// Byte offset of `json_text` in the file (20 in a GLB, 3 after a byte-order mark).
    pub json_offset: usize,
    /// Whether a byte-order mark precedes `json_text` in its file or JSON chunk (its 3 bytes
    /// are in `json_offset`).
    pub byte_order_mark: bool,
    /// The GLB BIN chunk, if any.
    pub bin: Option<Vec<u8>>,
    /// A GLB's chunks of unknown types, whole, in file order: written back after BIN.
    pub other_chunks: Vec<Vec<u8>>,
    /// The limits and URI policy it was loaded with; resources are read under them too.
    pub options: LoadOptions,
    image_headers: Mutex<HashMap<usize, Result<ImageHeader, Diagnostic>>>,
    /// Whether each image asked about decodes, and why not (see [`Asset::image_decodes`]).
    image_decodes: Mutex<HashMap<usize, Result<(), String>>>,
    /// What the file system said of its resources ([`ResourceLookups`]), shared with the
    /// fixed texts tried for it.
    lookups: std::sync::Arc<ResourceLookups>,
}

/// What the file system said of a document's resource files, asked once per file: every
/// report of a file with fixable findings validates the fixed text too ([`crate::fix`]), whose
/// resources are the file's, and on small files the second round of path checks, stats and
/// header reads was a tenth of the run. Shared only by assets of one folder, loaded under one
/// policy, within one run ([`Asset::share_lookups`], [`Asset::share_folder_lookups`]): every
/// key is a path resolved from the folder, or a URI with the pointer that holds it.
#[derive(Debug, Default)]
struct ResourceLookups {
    /// The folder with its links resolved, found once on the first resource read.
    real_base: OnceLock<Option<PathBuf>>,
    /// Where each URI that is not a `data:` URI led (a file, or why not), by URI and pointer.
    resolved: Mutex<HashMap<(String, String), Result<PathBuf, Diagnostic>>>,
    /// What each resource file is, by path.
    files: Mutex<HashMap<PathBuf, Result<FileFacts, StatError>>>,
    /// The headers of images read from files, by image index and URI.
    headers: Mutex<HashMap<(usize, String), Result<ImageHeader, Diagnostic>>>,
    /// The bytes of each regular file short enough to be a Git LFS pointer, by path: read
    /// whole when its facts were asked (whether it is a pointer needs its first bytes), and
    /// read from here by whatever reads the file afterwards.
    short_files: Mutex<HashMap<PathBuf, std::sync::Arc<[u8]>>>,
}

/// The resource lookups of the documents of each folder, for one run under one set of load
/// options ([`Asset::share_folder_lookups`]): a library's documents in one folder share their
/// textures and buffers, and each document asked the file system about them again (500
/// small files sharing an image and a buffer made 6,500 system calls; now 4,472).
#[derive(Debug, Default)]
pub struct FolderLookups(Mutex<HashMap<PathBuf, (LoadOptions, std::sync::Arc<ResourceLookups>)>>);

/// A resource file as [`Asset::open_resource`] gives it: its bytes, when it is short and they
/// were read with its facts, or the file opened.
enum Opened {
    Read(std::sync::Arc<[u8]>),
    File(std::fs::File),
}

/// Why a resource file could not be stat'ed: the error's kind and its words.
pub type StatError = (std::io::ErrorKind, String);

/// What a resource file is: a regular file or not, its length, and whether it is a Git LFS
/// pointer file (for a file short enough to be one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileFacts {
    pub is_file: bool,
    pub len: u64,
    pub lfs_pointer: bool,
}

/// `mutex`'s value, whatever a thread that panicked while holding it left there (a cache: at
/// worst an entry is asked again).
fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}

/// The outcome of loading one file: the asset when its JSON could be read, and every fault
/// found on the way.
#[derive(Debug)]
pub struct Loaded {
    pub asset: Option<Asset>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Reads and parses one file under the default limits. Never fails: faults become
/// diagnostics.
pub fn load(path: &Path) -> Loaded {
    load_with(path, &LoadOptions::default())
}

/// Reads and parses one file under `options`. Never fails: faults become diagnostics.
pub fn load_with(path: &Path, options: &LoadOptions) -> Loaded {
    crate::progress::stage("reading", 0);
    // The bytes are the asset's alone: a GLB's BIN chunk is carved out of them in place.
    match read_held(path, options, 1) {
        Ok(bytes) => load_owned(path, bytes, options),
        Err(d) => Loaded {
            asset: None,
            diagnostics: vec![d],
        },
    }
}

/// Reads the bytes of an asset file (see [`limits::read_asset_file`]). A .gltf larger than
/// the document limit is refused from its size alone, without being read.
pub fn read(path: &Path, options: &LoadOptions) -> Result<FileBytes, Diagnostic> {
    read_held(path, options, 2)
}

/// [`read`], a GLB asked of the memory budget `copies` times its size: 2 where the caller keeps
/// the file's bytes while its BIN chunk is copied out of them, 1 where the chunk is carved out
/// of them ([`load_with`]).
fn read_held(path: &Path, options: &LoadOptions, copies: u64) -> Result<FileBytes, Diagnostic> {
    let io_error = |e: std::io::Error| {
        Diagnostic::new(
            &codes::IO_ERROR,
            "",
            format!("cannot read {}: {e}", path.display()),
        )
    };
    // Opened once, and asked its metadata once: the checks and the reading share them.
    let mut file = std::fs::File::open(path).map_err(io_error)?;
    let meta = file.metadata().map_err(io_error)?;
    // The document limit applies to the JSON, which is the whole file unless it is a GLB
    // (whose BIN chunk may be large) or starts with a byte-order mark.
    if meta.is_file() && meta.len() > options.max_document_bytes.saturating_add(3) {
        let mut magic = [0u8; 4];
        let is_glb = std::io::Read::read_exact(&mut file, &mut magic).is_ok() && &magic == b"glTF";
        std::io::Seek::rewind(&mut file).map_err(io_error)?;
        if !is_glb {
            return Err(Diagnostic::new(
                &codes::DOCUMENT_TOO_LARGE,
                "",
                options.document_too_large(meta.len()),
            ));
        }
        // Asked for before it is read (see `copies`). (A .gltf over the document limit is
        // refused above; one within it is far below any budget.)
        let what = format!("reading {} (a GLB of {} bytes)", path.display(), meta.len());
        let needed = meta.len().saturating_mul(copies);
        if let Some(message) = limits::over_memory_budget(&what, needed, options.max_memory) {
            return Err(Diagnostic::new(&codes::IO_ERROR, "", message));
        }
    }
    limits::read_opened_asset(file, &meta, options).map_err(io_error)
}

/// Reads an asset file as [`read`] does, for a command that will write something for it: with
/// the [`Snapshot`] of the file to compare before writing. A file that changed while it was
/// read (its snapshot before and after differ) is refused, naming it.
pub fn read_for_writing(
    path: &Path,
    options: &LoadOptions,
) -> Result<(FileBytes, Snapshot), String> {
    let cannot = |e: std::io::Error| format!("cannot read {}: {e}", path.display());
    let before = Snapshot::before_reading(path).map_err(cannot)?;
    let bytes = read(path, options).map_err(|d| format!("{} ({})", d.message, d.code))?;
    match Snapshot::taken(path, before, &bytes).map_err(cannot)? {
        Some(snapshot) => Ok((bytes, snapshot)),
        None => Err(format!(
            "{} changed while velvet read it (another program wrote it); nothing was written \
             for it",
            path.display()
        )),
    }
}

/// Parses the bytes of a file that lives (or would live) at `path` under the default limits.
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Loaded {
    load_bytes_with(path, bytes, &LoadOptions::default())
}

/// Parses bytes read from `path`, keeping them as the JSON text without a copy when the file is
/// a .gltf in plain UTF-8 (a copy of a large document costs as much as indexing it).
fn load_owned(path: &Path, bytes: FileBytes, options: &LoadOptions) -> Loaded {
    if is_glb(path, &bytes) {
        // The BIN chunk is made of the file's own bytes, moved to the front of their
        // allocation, rather than copied out of them: the file is held once, not twice.
        return load_from(path, Bytes::Owned(bytes.into_vec()), options);
    }
    load_read(path, bytes, options).0
}

/// Whether bytes read from `path` are to be read as a GLB: they begin as one, or the file is
/// named as one.
fn is_glb(path: &Path, bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

/// A file's bytes for [`load_from`]: borrowed (the caller keeps them), or given (a GLB's BIN
/// chunk is then carved out of them in place).
enum Bytes<'a> {
    Borrowed(&'a [u8]),
    Owned(Vec<u8>),
}

impl std::ops::Deref for Bytes<'_> {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            Bytes::Borrowed(bytes) => bytes,
            Bytes::Owned(bytes) => bytes,
        }
    }
}

/// Parses bytes read from `path`, as [`load_with`] does, keeping them as the JSON text without
/// a copy where it can; gives them back when the asset did not take them as its text (a GLB, a
/// byte-order mark, a document over the limit, text that is not UTF-8). When it took them,
/// [`Asset::file_bytes`] reads them.
pub fn load_read(
    path: &Path,
    bytes: FileBytes,
    options: &LoadOptions,
) -> (Loaded, Option<FileBytes>) {
    crate::progress::stage("indexing", 0);
    load_given(path, bytes, options)
}

/// [`load_read`] without a word to the progress display: bytes a caller made and gives away
/// (a fix's trial of the fixed text).
pub fn load_given(
    path: &Path,
    bytes: FileBytes,
    options: &LoadOptions,
) -> (Loaded, Option<FileBytes>) {
    load_given_after(path, bytes, options, None)
}

/// [`load_given`] of a text velvet joined itself (UTF-8 as made, so not checked again): the
/// text of an earlier asset with edits spliced in, whose index takes what `resumption` copied
/// of the earlier one ([`tape::Tape::resumption`]) and is built only from the first edit on.
pub fn load_joined_resuming(
    path: &Path,
    text: String,
    options: &LoadOptions,
    resumption: Option<tape::Resumption>,
) -> (Loaded, Option<FileBytes>) {
    if !is_plain_text(path, text.as_bytes(), options) {
        return load_given_after(
            path,
            FileBytes::from_vec(text.into_bytes()),
            options,
            resumption,
        );
    }
    let loaded = load_text(
        path,
        SourceText::from(text),
        Container::Gltf,
        0,
        None,
        Vec::new(),
        options,
        resumption,
    );
    (loaded, None)
}

/// Whether `bytes`, of a file at `path`, are read as a plain glTF JSON text: not a GLB (by
/// their magic or the path's extension), no byte-order mark, within the document size limit.
fn is_plain_text(path: &Path, bytes: &[u8], options: &LoadOptions) -> bool {
    !bytes.starts_with(b"glTF")
        && !bytes.starts_with(b"\xEF\xBB\xBF")
        && !path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        && bytes.len() as u64 <= options.max_document_bytes
}

fn load_given_after(
    path: &Path,
    bytes: FileBytes,
    options: &LoadOptions,
    resumption: Option<tape::Resumption>,
) -> (Loaded, Option<FileBytes>) {
    if !is_plain_text(path, &bytes, options) {
        return (load_bytes_with(path, &bytes, options), Some(bytes));
    }
    match SourceText::from_bytes(bytes) {
        Ok(text) => (
            load_text(
                path,
                text,
                Container::Gltf,
                0,
                None,
                Vec::new(),
                options,
                resumption,
            ),
            None,
        ),
        Err((bytes, _)) => (load_bytes_with(path, &bytes, options), Some(bytes)),
    }
}

/// Parses the bytes of a file that lives (or would live) at `path`; `path` is used for the
/// container kind (when the bytes do not tell) and to resolve relative URIs.
pub fn load_bytes_with(path: &Path, bytes: &[u8], options: &LoadOptions) -> Loaded {
    load_from(path, Bytes::Borrowed(bytes), options)
}

fn load_from(path: &Path, file: Bytes<'_>, options: &LoadOptions) -> Loaded {
    let bytes: &[u8] = &file;
    let mut diagnostics = Vec::new();
    let mut other_chunks = Vec::new();
    // Where the BIN chunk's data lies in the file.
    let (container, json_bytes, json_offset, bin_range) = if is_glb(path, bytes) {
        match glb::split(bytes, &mut diagnostics) {
            Some(parts) => {
                other_chunks = parts.other.iter().map(|c| c.to_vec()).collect();
                let bin_range = parts.bin.map(|bin| {
                    let start = bin.as_ptr() as usize - bytes.as_ptr() as usize;
                    start..start + bin.len()
                });
                (Container::Glb, parts.json, parts.json_offset, bin_range)
            }
            None => {
                return Loaded {
                    asset: None,
                    diagnostics,
                }
            }
        }
    } else {
        (Container::Gltf, bytes, 0, None)
    };
    let json_len = json_bytes
        .strip_prefix(b"\xEF\xBB\xBF")
        .unwrap_or(json_bytes)
        .len() as u64;
    if json_len > options.max_document_bytes {
        diagnostics.push(Diagnostic::new(
            &codes::DOCUMENT_TOO_LARGE,
            "",
            options.document_too_large(json_len),
        ));
        return Loaded {
            asset: None,
            diagnostics,
        };
    }
    let byte_order_mark = json_bytes.starts_with(b"\xEF\xBB\xBF");
    let (json_bytes, json_offset) = match json_bytes.strip_prefix(b"\xEF\xBB\xBF") {
        Some(rest) => {
            diagnostics.push(Diagnostic::new(
                &codes::BOM_PRESENT,
                "",
                "the JSON starts with a UTF-8 byte-order mark; glTF requires UTF-8 without one",
            ));
            (rest, json_offset + 3)
        }
        None => (json_bytes, json_offset),
    };
    let json_text = match std::str::from_utf8(json_bytes) {
        Ok(text) => SourceText::from(text.to_string()),
        Err(e) => {
            let at = e.valid_up_to();
            let line = json_bytes[..at].iter().filter(|b| **b == b'\n').count() + 1;
            let line_start = json_bytes[..at]
                .iter()
                .rposition(|b| *b == b'\n')
                .map_or(0, |p| p + 1);
            let column = String::from_utf8_lossy(&json_bytes[line_start..at])
                .chars()
                .count()
                + 1;
            diagnostics.push(
                Diagnostic::new(
                    &codes::INVALID_JSON,
                    "",
                    format!(
                        "invalid UTF-8 at line {line}, column {column} (byte {})",
                        json_offset + at
                    ),
                )
                .at(crate::diagnostics::Position {
                    line,
                    column,
                    offset: at,
                }),
            );
            return Loaded {
                asset: None,
                diagnostics,
            };
        }
    };
    let bin = bin_range.map(|range| match file {
        Bytes::Borrowed(bytes) => bytes[range].to_vec(),
        Bytes::Owned(mut bytes) => {
            bytes.truncate(range.end);
            bytes.drain(..range.start);
            bytes
        }
    });
    let mut loaded = load_text(
        path,
        json_text,
        container,
        json_offset,
        bin,
        diagnostics,
        options,
        None,
    );
    if let Some(asset) = &mut loaded.asset {
        asset.other_chunks = other_chunks;
        asset.byte_order_mark = byte_order_mark;
    }
    loaded
}

/// Indexes a document's JSON text and makes the asset.
#[allow(clippy::too_many_arguments)]
fn load_text(
    path: &Path,
    json_text: SourceText,
    container: Container,
    json_offset: usize,
    bin: Option<Vec<u8>>,
    mut diagnostics: Vec<Diagnostic>,
    options: &LoadOptions,
    resumption: Option<tape::Resumption>,
) -> Loaded {
    // A GLB's JSON chunk may carry NUL padding (reported by glb::split); parse past it.
    let parse_text = json_text.trim_end_matches(['\0', ' ']);
    let max_depth = options.max_json_depth.min(limits::JSON_DEPTH_CEILING);
    // With what an earlier index holds of the text (a fixed text's), the rest is indexed.
    let built = match resumption {
        Some(resumption) => resumption.build(parse_text, max_depth),
        None => tape::Tape::build_within(parse_text, max_depth),
    };
    // A text that nests too deep is refused for its depth, whatever else is wrong with it.
    let too_deep = match &built {
        Ok(_) => None,
        Err(_) => limits::find_too_deep(parse_text, max_depth),
    };
    if let Some(at) = too_deep {
        diagnostics.push(
            Diagnostic::new(
                &codes::JSON_TOO_DEEP,
                "",
                format!(
                "line {}, column {}: the JSON nests deeper than {max_depth} arrays and objects \
                 (raise the limit with --max-json-depth, at most {})",
                at.line,
                at.column,
                limits::JSON_DEPTH_CEILING
            ),
            )
            .at(crate::diagnostics::Position {
                line: at.line,
                column: at.column,
                offset: position::offset_of(parse_text, at.line, at.column),
            }),
        );
        return Loaded {
            asset: None,
            diagnostics,
        };
    }
    let index = match built {
        Ok(index) => index,
        Err(refused) => {
            let (at, message) = refusal(parse_text, refused);
            diagnostics.push(
                Diagnostic::new(
                    &codes::INVALID_JSON,
                    "",
                    format!("line {}, column {}: {message}", at.line, at.column),
                )
                .at(at),
            );
            return Loaded {
                asset: None,
                diagnostics,
            };
        }
    };
    if !index.root(parse_text).is_object() {
        diagnostics.push(Diagnostic::new(
            // The Khronos validator's code for a root that is no object.
            &codes::TYPE_MISMATCH,
            "",
            "the JSON root is not an object",
        ));
        return Loaded {
            asset: None,
            diagnostics,
        };
    }
    if container == Container::Glb {
        check_bin_length(index.root(parse_text), bin.as_deref(), &mut diagnostics);
    }
    Loaded {
        asset: Some(Asset {
            path: path.to_path_buf(),
            container,
            json: OnceLock::new(),
            tape: index,
            json_text,
            json_offset,
            byte_order_mark: false,
            bin,
            other_chunks: Vec::new(),
            options: *options,
            image_headers: Mutex::new(HashMap::new()),
            image_decodes: Mutex::new(HashMap::new()),
            lookups: Default::default(),
        }),
        diagnostics,
    }
}

/// A GLB's buffer 0 without a URI is its BIN chunk: the chunk must hold the declared
/// byteLength (it may be up to 3 bytes longer, for padding).
fn check_bin_length(json: tape::Node, bin: Option<&[u8]>, out: &mut Vec<Diagnostic>) {
    let Some(buffer) = json.pointer("/buffers/0") else {
        return;
    };
    if buffer.get("uri").is_some() {
        return;
    }
    let Some(declared) = buffer.get("byteLength").and_then(|v| v.as_u64()) else {
        return;
    };
    match bin {
        None => out.push(Diagnostic::new(
            &codes::BUFFER_MISSING_GLB_DATA,
            "/buffers/0",
            format!(
                "buffer 0 has no uri and declares {declared} bytes, but the GLB has no BIN chunk"
            ),
        )),
        Some(bin) if (bin.len() as u64) < declared => out.push(Diagnostic::new(
            &codes::BUFFER_BYTE_LENGTH_MISMATCH,
            "/buffers/0",
            format!(
                "buffer 0 declares {declared} bytes but the GLB's BIN chunk holds {}",
                bin.len()
            ),
        )),
        // The chunk pads the buffer to 4 bytes; more than that is bytes no buffer holds.
        Some(bin) if (bin.len() as u64) > declared.next_multiple_of(4) => out.push(Diagnostic::new(
            &codes::BUFFER_GLB_CHUNK_TOO_BIG,
            "/buffers/0",
            format!(
                "the GLB's BIN chunk holds {} bytes, {} more than buffer 0's byteLength of {declared} padded to 4",
                bin.len(),
                bin.len() as u64 - declared.next_multiple_of(4)
            ),
        )),
        Some(_) => {}
    }
}

/// Checks that a buffer's data holds its declared byteLength.
/// A buffer's bytes, for reading a part at a time: those already in memory (the GLB BIN
/// chunk, a decoded `data:` URI), or its file, of which each part is read when it is asked
/// for. The data rules read one accessor's bytes at a time, so that a document's buffers are
/// never held whole: validating the 67 MB of the data library's buffer peaked at 80 MiB when
/// it was read whole (docs/performance.md).
pub enum BufferData<'a> {
    Memory(Cow<'a, [u8]>),
    /// The file and its length when it was opened. Reads are positional (no shared cursor):
    /// the data checks read one buffer from several threads at once.
    File {
        file: std::fs::File,
        len: usize,
    },
}

impl BufferData<'_> {
    /// The buffer's length in bytes (a file's, when it was opened).
    pub fn len(&self) -> usize {
        match self {
            BufferData::Memory(bytes) => bytes.len(),
            BufferData::File { len, .. } => *len,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The bytes of `range`; `None` when the range goes past the buffer's end, or its file
    /// no longer holds them (another program cut it short since it was opened).
    pub fn read(&self, range: std::ops::Range<usize>) -> Option<Cow<'_, [u8]>> {
        match self {
            BufferData::Memory(bytes) => bytes.get(range).map(Cow::Borrowed),
            BufferData::File { file, len } => {
                if range.start > range.end || range.end > *len {
                    return None;
                }
                let mut bytes = vec![0u8; range.len()];
                read_exact_at(file, &mut bytes, range.start as u64).ok()?;
                Some(Cow::Owned(bytes))
            }
        }
    }
}

/// Fills `buf` from `file` at `offset`, leaving the file's cursor to no one: an error when the
/// file ends first.
fn read_exact_at(file: &std::fs::File, buf: &mut [u8], offset: u64) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
    }
    #[cfg(windows)]
    {
        let mut done = 0;
        while done < buf.len() {
            match std::os::windows::fs::FileExt::seek_read(
                file,
                &mut buf[done..],
                offset + done as u64,
            )? {
                0 => return Err(std::io::ErrorKind::UnexpectedEof.into()),
                n => done += n,
            }
        }
        Ok(())
    }
}

fn check_buffer_length(
    buffer: tape::Node,
    index: usize,
    actual: usize,
    pointer: &str,
) -> Result<(), Diagnostic> {
    match buffer.get("byteLength").and_then(|v| v.as_u64()) {
        Some(declared) if (actual as u64) < declared => Err(Diagnostic::new(
            &codes::BUFFER_BYTE_LENGTH_MISMATCH,
            pointer.to_string(),
            format!("buffer {index} declares {declared} bytes but its data holds {actual}"),
        )),
        _ => Ok(()),
    }
}

/// serde_json appends " at line L column C"; velvet states the position itself, first.
/// Where and why a JSON text the index refused is wrong. serde_json words the fault and
/// refuses what the index refuses (tested), with two exceptions: a text too large to index, and
/// a string whose escapes do not make a string (a lone surrogate), which serde_json skips
/// without decoding when it reads the whole text and refuses when it reads that string as one.
fn refusal(text: &str, refused: tape::TapeError) -> (crate::diagnostics::Position, String) {
    let found = |e: &serde_json::Error| {
        let offset = position::offset_of(text, e.line(), e.column());
        (
            position::position_of(text, offset),
            strip_position(&e.to_string()).to_owned(),
        )
    };
    if let Err(e) = serde_json::from_str::<serde::de::IgnoredAny>(text) {
        return found(&e);
    }
    match refused {
        tape::TapeError::Syntax(start) => {
            let mut string = serde_json::Deserializer::from_str(&text[start..]);
            match <String as serde::Deserialize>::deserialize(&mut string) {
                // The string starts a line of its own text: its fault lies `column` characters
                // into it, on the line it starts on (a JSON string holds no raw line break).
                Err(e) if e.line() == 1 => {
                    let within = position::offset_of(&text[start..], 1, e.column());
                    (
                        position::position_of(text, start + within),
                        // serde_json calls a lone trailing surrogate a "lone leading" one.
                        "a \\u escape of this string is half of a UTF-16 surrogate pair \
                         without its other half, which is no character"
                            .to_owned(),
                    )
                }
                _ => (
                    position::position_of(text, start),
                    "the JSON text could not be indexed".to_owned(),
                ),
            }
        }
        tape::TapeError::TooDeep(start) => (
            position::position_of(text, start),
            "the JSON text could not be indexed".to_owned(),
        ),
        tape::TapeError::TooLarge => (
            position::position_of(text, 0),
            "the JSON text is too large to index".to_owned(),
        ),
    }
}

fn strip_position(message: &str) -> &str {
    message.rsplit_once(" at line ").map_or(message, |(m, _)| m)
}

impl Asset {
    /// The file's bytes, where its JSON text is the whole file (a .gltf without a byte-order
    /// mark); a GLB's are not kept.
    pub fn file_bytes(&self) -> Option<&[u8]> {
        (self.container == Container::Gltf && self.json_offset == 0)
            .then_some(self.json_text.as_bytes())
    }

    /// The document as read from the file, through its index.
    pub fn root(&self) -> tape::Node<'_> {
        self.tape.root(&self.json_text)
    }

    /// The document as a `serde_json::Value`, parsed from the text on first use.
    pub fn json(&self) -> &Value {
        self.json.get_or_init(|| {
            // The index accepted this text, and serde_json accepts what the index accepts
            // (tested), so the fallback is never taken.
            serde_json::from_str(self.json_text.trim_end_matches(['\0', ' '])).unwrap_or_default()
        })
    }

    /// The document for editing.
    pub fn json_mut(&mut self) -> &mut Value {
        self.json();
        self.json.get_mut().expect("set just above")
    }

    /// Takes the document out, leaving an empty one; [`Asset::set_json`] puts one back.
    pub fn take_json(&mut self) -> Value {
        std::mem::take(self.json_mut())
    }

    pub fn set_json(&mut self, json: Value) {
        *self.json_mut() = json;
    }

    /// The folder relative URIs are resolved against.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }

    /// The bytes of buffer `index`, whole: the GLB BIN chunk, a `data:` URI or a file.
    pub fn buffer_bytes(&self, index: usize) -> Result<Cow<'_, [u8]>, Diagnostic> {
        match self.buffer_data(index)? {
            BufferData::Memory(bytes) => Ok(bytes),
            file @ BufferData::File { .. } => file
                .read(0..file.len())
                .map(|bytes| Cow::Owned(bytes.into_owned()))
                .ok_or_else(|| {
                    Diagnostic::new(
                        &codes::IO_ERROR,
                        format!("/buffers/{index}/uri"),
                        format!(
                            "buffer {index}: its file no longer holds the bytes it had when opened"
                        ),
                    )
                }),
        }
    }

    /// Buffer `index`, for reading a part at a time ([`BufferData`]): the GLB BIN chunk, a
    /// `data:` URI or a file. Refused when it does not exist, cannot be opened, or is shorter
    /// than its byteLength.
    pub fn buffer_data(&self, index: usize) -> Result<BufferData<'_>, Diagnostic> {
        let pointer = format!("/buffers/{index}");
        let buffer = self.root().pointer(&pointer).ok_or_else(|| {
            Diagnostic::new(
                &codes::UNRESOLVED_REFERENCE,
                &pointer,
                format!("buffer {index} does not exist"),
            )
        })?;
        let uri_pointer = format!("{pointer}/uri");
        let data = match buffer.get("uri").and_then(|u| u.as_str()) {
            Some(uri) => match self.resolve(&uri, &uri_pointer)? {
                Location::File(path) => match self.open_resource(&path, &uri, &uri_pointer)? {
                    Opened::Read(bytes) => BufferData::Memory(Cow::Owned(bytes.to_vec())),
                    Opened::File(file) => {
                        let len = file
                            .metadata()
                            .map(|m| usize::try_from(m.len()).unwrap_or(usize::MAX))
                            .map_err(|e| {
                                Diagnostic::new(
                                    &codes::IO_ERROR,
                                    &uri_pointer,
                                    format!("cannot read '{uri}' ({}): {e}", path.display()),
                                )
                            })?;
                        BufferData::File { file, len }
                    }
                },
                Location::Data { bytes, .. } => BufferData::Memory(Cow::Owned(bytes)),
            },
            None => match (&self.bin, index) {
                (Some(bin), 0) => BufferData::Memory(Cow::Borrowed(bin.as_slice())),
                _ => {
                    return Err(Diagnostic::new(
                        &codes::IO_ERROR,
                        &pointer,
                        format!("buffer {index} has no uri and is not the GLB's BIN chunk"),
                    ))
                }
            },
        };
        check_buffer_length(buffer, index, data.len(), &pointer)?;
        Ok(data)
    }

    /// The encoded bytes of image `index`, from its URI or its bufferView.
    pub fn image_bytes(&self, index: usize) -> Result<Cow<'_, [u8]>, Diagnostic> {
        let pointer = format!("/images/{index}");
        let image = self.root().pointer(&pointer).ok_or_else(|| {
            Diagnostic::new(
                &codes::UNRESOLVED_REFERENCE,
                &pointer,
                format!("image {index} does not exist"),
            )
        })?;
        if let Some(uri) = image.get("uri").and_then(|u| u.as_str()) {
            return self
                .read_uri(&uri, &format!("{pointer}/uri"))
                .map(Cow::Owned);
        }
        let view_index = image
            .get("bufferView")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| {
                Diagnostic::new(
                    &codes::IO_ERROR,
                    &pointer,
                    format!("image {index} has neither a uri nor a bufferView"),
                )
            })?;
        self.buffer_view_bytes(view_index as usize, &format!("{pointer}/bufferView"))
    }

    fn buffer_view_bytes(
        &self,
        view_index: usize,
        pointer: &str,
    ) -> Result<Cow<'_, [u8]>, Diagnostic> {
        let view = self
            .root()
            .pointer(&format!("/bufferViews/{view_index}"))
            .ok_or_else(|| {
                Diagnostic::new(
                    &codes::UNRESOLVED_REFERENCE,
                    pointer,
                    format!("bufferView {view_index} does not exist"),
                )
            })?;
        let buffer = view
            .get("buffer")
            .and_then(|v| v.as_u64())
            .unwrap_or(u64::MAX) as usize;
        let offset = view.get("byteOffset").and_then(|v| v.as_u64()).unwrap_or(0) as usize;
        let length = view.get("byteLength").and_then(|v| v.as_u64()).unwrap_or(0) as usize;
        let data = self.buffer_data(buffer)?;
        let out_of_range = || {
            Diagnostic::new(
                &codes::BUFFER_VIEW_OUT_OF_RANGE,
                pointer,
                format!(
                    "bufferView {view_index} spans bytes {offset}..{} of buffer {buffer}, which has {}",
                    offset.saturating_add(length),
                    data.len()
                ),
            )
        };
        let end = offset
            .checked_add(length)
            .filter(|end| *end <= data.len())
            .ok_or_else(out_of_range)?;
        match data {
            BufferData::Memory(Cow::Borrowed(bin)) => Ok(Cow::Borrowed(&bin[offset..end])),
            BufferData::Memory(Cow::Owned(mut bytes)) => {
                bytes.truncate(end);
                bytes.drain(..offset);
                Ok(Cow::Owned(bytes))
            }
            file @ BufferData::File { .. } => file
                .read(offset..end)
                .map(|bytes| Cow::Owned(bytes.into_owned()))
                .ok_or_else(|| {
                    Diagnostic::new(
                        &codes::IO_ERROR,
                        pointer,
                        format!(
                            "bufferView {view_index}: the file of buffer {buffer} no longer holds bytes {offset}..{end}"
                        ),
                    )
                }),
        }
    }

    /// Where a resource URI leads under this asset's URI policy.
    /// Unless outside URIs are allowed, a path that stays in the folder by its text but leads
    /// out of it through a symbolic link is refused too.
    pub fn resolve(&self, uri: &str, pointer: &str) -> Result<Location, Diagnostic> {
        // A data: URI is decoded from the text each time (nothing to ask the file system).
        if uri.starts_with("data:") {
            return self.resolve_asking(uri, pointer);
        }
        let key = (uri.to_string(), pointer.to_string());
        if let Some(known) = lock(&self.lookups.resolved).get(&key) {
            return known.clone().map(Location::File);
        }
        let location = self.resolve_asking(uri, pointer);
        let known = match &location {
            Ok(Location::File(path)) => Ok(path.clone()),
            Ok(Location::Data { .. }) => return location,
            Err(d) => Err(d.clone()),
        };
        lock(&self.lookups.resolved).insert(key, known);
        location
    }

    /// Gives this asset the resource lookups of `other`, an asset of the same file loaded
    /// under the same policy (the fixed text of a file, tried for its report): what the file
    /// system said of their resources holds for both. Nothing is shared otherwise.
    pub fn share_lookups(&mut self, other: &Asset) {
        if self.path == other.path && self.options == other.options {
            self.lookups = other.lookups.clone();
        }
    }

    /// Gives this asset, fresh from loading, the resource lookups of the documents of its
    /// folder that `folders` holds, loaded under the same options (or makes its own theirs):
    /// a resource path is resolved from the folder, and what the file system said of it holds
    /// for every document there within one run.
    pub fn share_folder_lookups(&mut self, folders: &FolderLookups) {
        let mut folders = lock(&folders.0);
        match folders.get(self.base_dir()) {
            Some((options, lookups)) if *options == self.options => {
                self.lookups = lookups.clone();
            }
            Some(_) => {}
            None => {
                folders.insert(
                    self.base_dir().to_path_buf(),
                    (self.options, self.lookups.clone()),
                );
            }
        }
    }

    /// What the resource file `path` is ([`FileFacts`]), asked once per file; the error of its
    /// stat otherwise.
    pub fn file_facts(&self, path: &Path) -> Result<FileFacts, StatError> {
        if let Some(known) = lock(&self.lookups.files).get(path) {
            return known.clone();
        }
        self.file_facts_from(path, std::fs::metadata(path))
    }

    /// [`Asset::file_facts`] of `path` from its `stat`, kept for every later question (unless
    /// some were kept already).
    fn file_facts_from(
        &self,
        path: &Path,
        stat: std::io::Result<std::fs::Metadata>,
    ) -> Result<FileFacts, StatError> {
        if let Some(known) = lock(&self.lookups.files).get(path) {
            return known.clone();
        }
        let facts = stat
            .map(|meta| {
                let short = (meta.is_file() && meta.len() <= resource::LFS_POINTER_MAX_LEN)
                    .then(|| resource::read_short(path, meta.len()))
                    .flatten();
                let lfs_pointer = short
                    .as_ref()
                    .is_some_and(|bytes| bytes.starts_with(resource::LFS_POINTER_PREFIX));
                if let Some(bytes) = short {
                    lock(&self.lookups.short_files).insert(path.to_path_buf(), bytes.into());
                }
                FileFacts {
                    is_file: meta.is_file(),
                    len: meta.len(),
                    lfs_pointer,
                }
            })
            .map_err(|e| (e.kind(), e.to_string()));
        lock(&self.lookups.files).insert(path.to_path_buf(), facts.clone());
        facts
    }

    /// Opens the resource file `path` that `uri` (at `pointer`) led to
    /// ([`resource::open_file`]), from the file's facts as the run first asked them
    /// ([`Asset::file_facts`]): one stat of a file for every question of a run.
    /// A short file's bytes come from its facts, read once.
    fn open_resource(&self, path: &Path, uri: &str, pointer: &str) -> Result<Opened, Diagnostic> {
        let is_file = self
            .file_facts(path)
            .map(|facts| facts.is_file)
            .map_err(|(_, why)| why);
        if let Some(bytes) = lock(&self.lookups.short_files).get(path) {
            return Ok(Opened::Read(bytes.clone()));
        }
        resource::open_file(path, uri, pointer, is_file).map(Opened::File)
    }

    fn resolve_asking(&self, uri: &str, pointer: &str) -> Result<Location, Diagnostic> {
        let location = resource::resolve_with(
            uri,
            self.base_dir(),
            pointer,
            self.options.allow_outside_uris,
        )?;
        if let Location::File(path) = &location {
            if !self.options.allow_outside_uris {
                // The folder's real path is resolved only for a path that is not plainly
                // inside it (a link on the way, `..`): resolving it reads every folder above.
                let real_base = || {
                    self.lookups
                        .real_base
                        .get_or_init(|| resource::real_folder(self.base_dir()))
                        .clone()
                };
                let seen = resource::check_inside(path, self.base_dir(), real_base, uri, pointer)?;
                if let Some(stat) = seen {
                    let _ = self.file_facts_from(path, stat);
                }
            }
        }
        Ok(location)
    }

    fn read_uri(&self, uri: &str, pointer: &str) -> Result<Vec<u8>, Diagnostic> {
        match self.resolve(uri, pointer)? {
            Location::Data { bytes, .. } => Ok(bytes),
            Location::File(path) => match self.open_resource(&path, uri, pointer)? {
                Opened::Read(bytes) => Ok(bytes.to_vec()),
                Opened::File(file) => resource::read_whole(file, &path, uri, pointer),
            },
        }
    }

    /// The pixels of image `index`, decoded, the budget reserved for them alone (see
    /// [`Asset::decode_image_with`], for a caller that converts them).
    pub fn decode_image(&self, index: usize) -> Result<image::DynamicImage, Diagnostic> {
        self.decode_image_with(index, 1, 0, |pixels| pixels)
    }

    /// The pixels of image `index`, decoded (PNG, JPEG or WebP), handed to `use_pixels`, whose
    /// result is returned. Decoding is costly: only the steps that need texel values call this.
    ///
    /// The memory budget (`--max-memory`) is reserved for all that is held while `use_pixels`
    /// runs, before anything is decoded: `copies` of the decoded image (1: the pixels alone; a
    /// check for a bake that will hold more asks for as many as the bake will) and
    /// `extra_bytes_per_pixel` for what `use_pixels` converts them into (4 for `to_rgba8`, 12
    /// for `to_rgb32f`). Reserving the decoded copy alone let a conversion after it take twice
    /// the budget and more.
    pub fn decode_image_with<T>(
        &self,
        index: usize,
        copies: u64,
        extra_bytes_per_pixel: u64,
        use_pixels: impl FnOnce(image::DynamicImage) -> T,
    ) -> Result<T, Diagnostic> {
        let bytes = self.image_bytes(index)?;
        let pointer = format!("/images/{index}");
        let unreadable = |detail: String| {
            Diagnostic::new(
                &codes::IMAGE_DATA_INVALID,
                &pointer,
                format!("image {index}: {detail}"),
            )
        };
        let header = resource::read_header(
            Cursor::new(bytes.as_ref()),
            &pointer,
            &format!("image {index}"),
        )?;
        if let Some(message) = self.options.image_too_large(header.width, header.height) {
            return Err(Diagnostic::new(
                &codes::IMAGE_TOO_LARGE,
                &pointer,
                format!("image {index}: {message}"),
            ));
        }
        let format = match resource::ImageFormat::sniff(&bytes) {
            Some(resource::ImageFormat::Png) => image::ImageFormat::Png,
            Some(resource::ImageFormat::Jpeg) => image::ImageFormat::Jpeg,
            Some(resource::ImageFormat::Webp) => image::ImageFormat::WebP,
            Some(resource::ImageFormat::Ktx2) => {
                return Err(Diagnostic::new(
                    &codes::IMAGE_UNRECOGNIZED_FORMAT,
                    &pointer,
                    format!("image {index}: velvet does not decode KTX2 images"),
                ))
            }
            // read_header has refused it already.
            None => {
                return Err(Diagnostic::new(
                    &codes::IMAGE_UNRECOGNIZED_FORMAT,
                    &pointer,
                    format!("image {index}: not a PNG, JPEG, WebP or KTX2 image"),
                ))
            }
        };
        let reader = image::ImageReader::with_format(
            limits::StoppableReader(Cursor::new(bytes.as_ref())),
            format,
        );
        let mut decoder = reader
            .into_decoder()
            .map_err(|e| unreadable(e.to_string()))?;
        // The pixels returned, one copy; held against the budget with every other decode of
        // the run while this one lasts.
        let needed = u64::from(header.width)
            .saturating_mul(u64::from(header.height))
            .saturating_mul(
                u64::from(image::ImageDecoder::color_type(&decoder).bytes_per_pixel())
                    .saturating_mul(copies.max(1))
                    .saturating_add(extra_bytes_per_pixel),
            );
        let what = format!(
            "decoding the {} × {} image ({} bytes a pixel)",
            header.width,
            header.height,
            image::ImageDecoder::color_type(&decoder).bytes_per_pixel()
        );
        let _reserved = limits::reserve(&what, needed, self.options.max_memory).map_err(|m| {
            Diagnostic::new(
                &codes::IMAGE_TOO_LARGE,
                &pointer,
                format!("image {index}: {m}; it was not decoded"),
            )
        })?;
        let mut decode_limits = image::Limits::default();
        decode_limits.max_alloc = Some(self.options.max_decode_bytes());
        image::ImageDecoder::set_limits(&mut decoder, decode_limits)
            .map_err(|e| unreadable(e.to_string()))?;
        let pixels =
            image::DynamicImage::from_decoder(decoder).map_err(|e| unreadable(e.to_string()))?;
        Ok(use_pixels(pixels))
    }

    /// Whether the data of image `index` is whole, found once per asset by decoding it (the
    /// pixels are dropped): `Err` says how it is damaged. A plan that bakes an image asks this
    /// first: a header can be whole while the data after it is cut short or damaged, and only a
    /// decode tells, so that the plan, not the bake after it, finds an image that cannot be
    /// baked and takes the way round it. An image velvet will not decode under the run's limits
    /// (pixels, memory) or cannot read is no damage: the bake then fails naming the limit, so
    /// that what a file becomes never depends on a limit.
    pub fn image_decodes(&self, index: usize) -> Result<(), String> {
        if let Some(known) = self
            .image_decodes
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&index)
        {
            return known.clone();
        }
        // Decoded outside the lock: other images are checked meanwhile.
        // Reserved as the bake that follows will hold the image (the decoder's buffer, the
        // pixels and an output: bake::codec::DECODE_COPIES), so that a check is refused where
        // its bake would be, before anything is decoded, rather than decode what cannot be
        // baked.
        let found = match self.decode_image_with(index, 3, 0, drop) {
            Err(d)
                if d.code == codes::IMAGE_DATA_INVALID.name
                    || d.code == codes::IMAGE_UNEXPECTED_EOS.name =>
            {
                Err(d.message)
            }
            _ => Ok(()),
        };
        self.image_decodes
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(index, found.clone());
        found
    }

    /// The header of image `index`, read once per asset. A file is opened and only its header
    /// read; embedded images are read from their bytes.
    pub fn image_header(&self, index: usize) -> Result<ImageHeader, Diagnostic> {
        let mut cache = self.image_headers.lock().unwrap_or_else(|e| e.into_inner());
        cache
            .entry(index)
            .or_insert_with(|| self.read_image_header(index))
            .clone()
    }

    fn read_image_header(&self, index: usize) -> Result<ImageHeader, Diagnostic> {
        let what = format!("image {index}");
        let pointer = format!("/images/{index}");
        let uri = self
            .root()
            .pointer(&format!("{pointer}/uri"))
            .and_then(|u| u.as_str());
        if let Some(uri) = uri {
            let uri_pointer = format!("{pointer}/uri");
            if let Location::File(path) = self.resolve(&uri, &uri_pointer)? {
                let key = (index, uri.into_owned());
                if let Some(known) = lock(&self.lookups.headers).get(&key) {
                    return known.clone();
                }
                let header = self
                    .open_resource(&path, &key.1, &uri_pointer)
                    .and_then(|opened| match opened {
                        Opened::Read(bytes) => {
                            resource::read_header(Cursor::new(&bytes[..]), &pointer, &what)
                        }
                        Opened::File(file) => {
                            resource::read_header(resource::Rewinding::new(file), &pointer, &what)
                        }
                    });
                lock(&self.lookups.headers).insert(key, header.clone());
                return header;
            }
        }
        let bytes = self.image_bytes(index)?;
        resource::read_header(Cursor::new(bytes.as_ref()), &pointer, &what)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_glb_given_to_the_loader_has_its_bin_chunk_carved_out_in_place_as_a_copy_would_be() {
        let json = br#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":5}]}"#;
        let bin = [1u8, 2, 3, 4, 5];
        let mut file = glb::join(json, Some(&bin));
        file.extend_from_slice(b"trailing bytes");
        let path = Path::new("t.glb");
        let options = LoadOptions::default();
        let copied = load_bytes_with(path, &file, &options);
        let carved = load_owned(path, FileBytes::from_vec(file), &options);
        let (copied_asset, carved_asset) = (copied.asset.unwrap(), carved.asset.unwrap());
        // The chunk padded to 4 bytes, as the container holds it.
        assert_eq!(
            carved_asset.bin.as_deref(),
            Some(&[1u8, 2, 3, 4, 5, 0, 0, 0][..])
        );
        assert_eq!(carved_asset.bin, copied_asset.bin);
        assert_eq!(
            carved_asset.json_text.as_str(),
            copied_asset.json_text.as_str()
        );
        assert_eq!(carved.diagnostics, copied.diagnostics);
        assert!(carved
            .diagnostics
            .iter()
            .any(|d| d.code == codes::GLB_EXTRA_DATA.name));
    }

    #[test]
    fn what_the_file_system_said_is_shared_only_by_assets_of_one_file_and_policy() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let image = dir.path().join("a.png");
        std::fs::write(&image, b"not yet a picture").expect("written");
        let text = br#"{"asset":{"version":"2.0"}}"#;
        let load = |name: &str, options: &LoadOptions| {
            load_bytes_with(&dir.path().join(name), text, options)
                .asset
                .expect("the document parses")
        };
        let options = LoadOptions::default();
        let file = load("a.gltf", &options);
        let facts = file.file_facts(&image).expect("a file");
        assert_eq!(
            (facts.is_file, facts.len, facts.lfs_pointer),
            (true, 17, false)
        );
        std::fs::remove_file(&image).expect("removed");
        // The fixed text of the same file shares the answer; the file itself keeps it.
        let mut fixed = load("a.gltf", &options);
        fixed.share_lookups(&file);
        assert_eq!(fixed.file_facts(&image), Ok(facts));
        // Another file, or the same one under another policy, asks again.
        for (name, options) in [
            ("b.gltf", options),
            (
                "a.gltf",
                LoadOptions {
                    allow_outside_uris: !options.allow_outside_uris,
                    ..options
                },
            ),
        ] {
            let mut other = load(name, &options);
            other.share_lookups(&file);
            let asked = other.file_facts(&image);
            assert_eq!(asked.map_err(|e| e.0), Err(std::io::ErrorKind::NotFound));
        }
    }

    #[test]
    fn a_short_resource_is_read_once_with_its_facts_and_then_from_memory() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let mut png = Vec::new();
        image::RgbaImage::new(2, 3)
            .write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("encoded");
        assert!(png.len() as u64 <= resource::LFS_POINTER_MAX_LEN);
        std::fs::write(dir.path().join("a.png"), &png).expect("written");
        std::fs::write(dir.path().join("b.bin"), [7u8; 8]).expect("written");
        let text = br#"{"asset":{"version":"2.0"},"images":[{"uri":"a.png"}],
            "buffers":[{"uri":"b.bin","byteLength":8}]}"#;
        let asset = load_bytes_with(&dir.path().join("a.gltf"), text, &LoadOptions::default())
            .asset
            .expect("the document parses");
        let facts = asset.file_facts(&dir.path().join("a.png")).expect("a file");
        assert_eq!((facts.len, facts.lfs_pointer), (png.len() as u64, false));
        // Gone from the disk: what is read of them afterwards is what their facts read.
        std::fs::remove_file(dir.path().join("a.png")).expect("removed");
        let header = asset.image_header(0).expect("the header of the bytes kept");
        assert_eq!((header.width, header.height), (2, 3));
        // The buffer's facts are asked when it is resolved.
        let _ = asset.resolve("b.bin", "/buffers/0/uri");
        std::fs::remove_file(dir.path().join("b.bin")).expect("removed");
        let data = asset.buffer_data(0).expect("the bytes kept");
        assert_eq!(data.len(), 8);
        // A short file that begins as a Git LFS pointer is one.
        let pointer = [resource::LFS_POINTER_PREFIX, b"v1\noid sha256:0\nsize 9\n"].concat();
        std::fs::write(dir.path().join("c.png"), pointer).expect("written");
        let facts = asset.file_facts(&dir.path().join("c.png")).expect("a file");
        assert!(facts.lfs_pointer);
    }
}
