//! What velvet is willing to read from an asset nobody checked: the size of the JSON document,
//! how deep its values nest, how many pixels an image may declare before it is decoded, and
//! whether resource URIs may lead out of the asset's folder. Each limit has a default that
//! real assets stay far below and a command-line flag to raise it; every refusal names the
//! limit and its flag, so that a user who meets one knows what to change.
//!
//! The limits exist so that a hostile or broken file costs a clear error, not a crash, a stack
//! overflow or an out-of-memory kill: the document's index takes about its text again and a
//! parsed JSON value (which the editors build) about eight times its text in memory, nesting is
//! walked recursively (schema checks, rules, parsing values, dropping them), and a decoded
//! image takes up to eight bytes per pixel however small its file is.

use super::source::FileBytes;
use std::io::Read;
use std::path::Path;

/// The signal that asked the run to stop (SIGINT, SIGTERM), 0 while none has: set by the
/// command's handler (`output::interrupt`), read by the long work below the commands (an
/// image's decoding, a bake's texels, an encoding), which gives up within a fraction of a
/// second rather than finish what will be thrown away. It lives here, with the other limits
/// of a run, because that work cannot see the commands.
pub static STOP_SIGNAL: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);

/// Whether the run was asked to stop (see [`STOP_SIGNAL`]).
pub fn stop_requested() -> bool {
    STOP_SIGNAL.load(std::sync::atomic::Ordering::Relaxed) != 0
}

/// The message of work given up because the run was asked to stop.
pub const STOPPED: &str = "stopped: the run was asked to stop";

/// A reader of bytes in memory that fails once the run is asked to stop: a decoder reading
/// through it gives up at its next read, within a fraction of a second, instead of decoding a
/// 16384² image to the end.
pub struct StoppableReader<'a>(pub std::io::Cursor<&'a [u8]>);

impl StoppableReader<'_> {
    fn check() -> std::io::Result<()> {
        // Not ErrorKind::Interrupted: readers and writers retry a read or write that was
        // interrupted, and would spin on this one forever.
        if stop_requested() {
            return Err(std::io::Error::other(STOPPED));
        }
        Ok(())
    }
}

impl Read for StoppableReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        Self::check()?;
        // At most 64 KiB a read, so that a decoder asking for everything at once still reads
        // in steps that look at the flag.
        let n = buf.len().min(1 << 16);
        self.0.read(&mut buf[..n])
    }
}

impl std::io::BufRead for StoppableReader<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        Self::check()?;
        let buf = self.0.fill_buf()?;
        Ok(&buf[..buf.len().min(1 << 16)])
    }
    fn consume(&mut self, amount: usize) {
        self.0.consume(amount)
    }
}

impl std::io::Seek for StoppableReader<'_> {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        self.0.seek(to)
    }
}

/// A writer into memory that fails once the run is asked to stop (an encoder writing a large
/// image gives up at its next write).
pub struct StoppableWriter<'a>(pub &'a mut Vec<u8>);

impl std::io::Write for StoppableWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        StoppableReader::check()?;
        self.0.extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The deepest nesting serde_json parses (its recursion limit of 128 counts the root);
/// `--max-json-depth` cannot go beyond it.
pub const JSON_DEPTH_CEILING: usize = 127;

/// Limits and URI policy for loading one asset. [`Default`] is what the command line uses
/// when no flag is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LoadOptions {
    /// Largest JSON document, in bytes: a .gltf file, or a .glb's JSON chunk.
    pub max_document_bytes: u64,
    /// Deepest nesting of arrays and objects (the root object is depth 1).
    pub max_json_depth: usize,
    /// Most pixels (width × height) an image may declare and still be decoded.
    pub max_image_pixels: u64,
    /// The memory budget, in bytes: a file or an image whose reading or decoding would need
    /// more is refused, naming `--max-memory`, before the memory is asked for.
    pub max_memory: u64,
    /// Read resources whose URI leads out of the asset's folder: `../` past its root, absolute
    /// paths and `file:` URIs. Writing never follows such URIs, whatever this says.
    pub allow_outside_uris: bool,
}

/// 64 MiB: a 20,000-material document is about 11 MB; its index takes about as much again, a
/// parsed value (built by the editors) ~8× the text.
pub const DEFAULT_MAX_DOCUMENT_BYTES: u64 = 64 << 20;
/// glTF documents nest about 8 deep; `extras` may go further.
pub const DEFAULT_MAX_JSON_DEPTH: usize = 64;
/// 16384 × 16384: the largest textures in use; decoded as 16-bit RGBA, 2 GiB.
pub const DEFAULT_MAX_IMAGE_PIXELS: u64 = 16384 * 16384;

/// The default memory budget: a quarter of the machine's physical memory (4 GiB where that
/// cannot be told), so that a run shares the machine with what else runs on it.
pub fn default_max_memory() -> u64 {
    static QUARTER: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *QUARTER.get_or_init(|| physical_memory().map_or(4 << 30, |bytes| bytes / 4))
}

fn physical_memory() -> Option<u64> {
    #[cfg(unix)]
    {
        // SAFETY: sysconf reads system values; it has no preconditions.
        let (pages, page) = unsafe {
            (
                libc::sysconf(libc::_SC_PHYS_PAGES),
                libc::sysconf(libc::_SC_PAGESIZE),
            )
        };
        if pages > 0 && page > 0 {
            return Some((pages as u64).saturating_mul(page as u64));
        }
    }
    None
}

/// A byte count as people read it: GiB, MiB or KiB with one decimal, or bytes.
pub fn bytes_text(bytes: u64) -> String {
    const UNITS: [(u64, &str); 3] = [(1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (size, unit) in UNITS {
        if bytes >= size {
            return format!("{:.1} {unit}", bytes as f64 / size as f64);
        }
    }
    format!("{bytes} bytes")
}

/// The message for work that needs `needed` bytes (`what` says of what) over the budget
/// `budget`, or `None` when it fits.
pub fn over_memory_budget(what: &str, needed: u64, budget: u64) -> Option<String> {
    (needed > budget).then(|| {
        format!(
            "{what} needs about {}, over the memory budget of {} (raise it with --max-memory)",
            bytes_text(needed),
            bytes_text(budget)
        )
    })
}

/// The memory that the decodes running now have reserved, summed over every thread of the
/// process: each decode reserves what it needs before it starts and gives it back when it
/// ends, so that images decoded side by side stay within the budget together, not each alone.
static RESERVED: std::sync::Mutex<u64> = std::sync::Mutex::new(0);
static RELEASED: std::sync::Condvar = std::sync::Condvar::new();

/// Memory reserved by [`reserve`], given back when dropped.
#[must_use = "the memory is given back when the reservation is dropped"]
pub struct Reservation(u64);

/// Reserves `needed` bytes of the memory budget `budget` for `what`: refused (the message
/// names `--max-memory`) when `needed` alone is over the budget; otherwise waits until the
/// decodes running beside it leave room, then holds it. A holder never waits for more while it
/// holds (a decode reserves once), so waiting always ends.
pub fn reserve(what: &str, needed: u64, budget: u64) -> Result<Reservation, String> {
    if let Some(message) = over_memory_budget(what, needed, budget) {
        return Err(message);
    }
    let mut reserved = RESERVED.lock().unwrap_or_else(|e| e.into_inner());
    while reserved.saturating_add(needed) > budget && *reserved > 0 {
        reserved = RELEASED.wait(reserved).unwrap_or_else(|e| e.into_inner());
    }
    *reserved += needed;
    Ok(Reservation(needed))
}

/// The memory reserved now by decodes running in this process.
pub fn reserved() -> u64 {
    *RESERVED.lock().unwrap_or_else(|e| e.into_inner())
}

impl Drop for Reservation {
    fn drop(&mut self) {
        let mut reserved = RESERVED.lock().unwrap_or_else(|e| e.into_inner());
        *reserved -= self.0;
        RELEASED.notify_all();
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            max_document_bytes: DEFAULT_MAX_DOCUMENT_BYTES,
            max_json_depth: DEFAULT_MAX_JSON_DEPTH,
            max_image_pixels: DEFAULT_MAX_IMAGE_PIXELS,
            max_memory: default_max_memory(),
            allow_outside_uris: false,
        }
    }
}

impl LoadOptions {
    /// The message for a document over the size limit.
    pub fn document_too_large(&self, size: u64) -> String {
        format!(
            "the JSON document is {size} bytes, over the limit of {} (raise it with --max-document-bytes)",
            self.max_document_bytes
        )
    }

    /// The message for an image over the pixel limit, or `None` when it is within it.
    pub fn image_too_large(&self, width: u32, height: u32) -> Option<String> {
        image_too_large(width, height, self.max_image_pixels)
    }

    /// The most bytes a decoder may allocate for an image within the pixel limit.
    pub fn max_decode_bytes(&self) -> u64 {
        max_decode_bytes(self.max_image_pixels)
    }
}

/// The message for an image of `width` × `height` over `max_pixels`, or `None` when within.
pub fn image_too_large(width: u32, height: u32, max_pixels: u64) -> Option<String> {
    let pixels = u64::from(width) * u64::from(height);
    (pixels > max_pixels).then(|| {
        format!(
            "the image declares {width} × {height} = {pixels} pixels, over the limit of \
             {max_pixels} (raise it with --max-image-pixels); it was not decoded"
        )
    })
}

/// The most bytes a decoder may allocate for an image of at most `max_pixels`: 16-bit RGBA
/// (8 bytes a pixel) plus room for the decoder's own buffers.
pub fn max_decode_bytes(max_pixels: u64) -> u64 {
    max_pixels.saturating_mul(8).saturating_add(64 << 20)
}

/// Where a JSON text first nests deeper than a limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TooDeep {
    /// Byte offset of the bracket that goes one level too deep.
    pub offset: usize,
    pub line: usize,
    /// 1-based, in characters.
    pub column: usize,
}

/// Finds the first `[` or `{` in `text` that opens a container deeper than `max_depth`. A scan
/// of our own because serde_json's only depth limit is a fixed 128 whose error does not say
/// how deep the text went; this one runs in one pass over the bytes, skipping strings, and
/// stops at the first excess. Malformed JSON is left for the parser to report.
pub fn find_too_deep(text: &str, max_depth: usize) -> Option<TooDeep> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    let mut in_string = false;
    let mut escaped = false;
    for (i, &b) in bytes.iter().enumerate() {
        if in_string {
            if escaped {
                escaped = false;
            } else if b == b'\\' {
                escaped = true;
            } else if b == b'"' {
                in_string = false;
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                depth += 1;
                if depth > max_depth {
                    let before = &text[..i];
                    let line = before.matches('\n').count() + 1;
                    let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
                    return Some(TooDeep {
                        offset: i,
                        line,
                        column,
                    });
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

/// Reads a file that is to be parsed as an asset. A regular file is read whole into memory
/// (its size is what the user stored; [`super::source`] says why it is not mapped); anything
/// else — a pipe, a device — is read up to what the limits allow, so that `/dev/zero` named as an input costs an error, not all memory. A GLB stream
/// is read up to the length its header declares (at most 4 GiB), anything else up to the
/// document limit; one byte more is read so that a longer stream is seen to be longer.
pub fn read_asset_file(path: &Path, options: &LoadOptions) -> std::io::Result<FileBytes> {
    let file = std::fs::File::open(path)?;
    let metadata = file.metadata()?;
    read_opened_asset(file, &metadata, options)
}

/// [`read_asset_file`] of a file opened, whose metadata is `metadata`.
pub fn read_opened_asset(
    mut file: std::fs::File,
    metadata: &std::fs::Metadata,
    options: &LoadOptions,
) -> std::io::Result<FileBytes> {
    if metadata.is_file() {
        // Sized to the file (and one byte more, to see that it ends there) before it is read,
        // so that a large one can be advised huge pages (see super::pages).
        let size = usize::try_from(metadata.len()).unwrap_or(0);
        let mut bytes = Vec::new();
        if bytes.try_reserve_exact(size.saturating_add(1)).is_ok() {
            super::pages::advise_huge(&mut bytes);
        }
        // Through `take`: a `File`'s own `read_to_end` asks its length and position again
        // (a stat and a seek), which the metadata above already told.
        (&mut file).take(u64::MAX).read_to_end(&mut bytes)?;
        return Ok(FileBytes::from_vec(bytes));
    }
    let mut head = Vec::with_capacity(12);
    (&mut file).take(12).read_to_end(&mut head)?;
    let cap = if head.len() == 12 && head.starts_with(b"glTF") {
        u64::from(u32::from_le_bytes([head[8], head[9], head[10], head[11]]))
    } else {
        // A byte-order mark may precede the document.
        options.max_document_bytes.saturating_add(3)
    };
    let mut bytes = head;
    file.take(cap.saturating_sub(bytes.len() as u64).saturating_add(1))
        .read_to_end(&mut bytes)?;
    Ok(FileBytes::from_vec(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_counts_containers_and_skips_strings() {
        assert_eq!(find_too_deep(r#"{"a":[1,{"b":2}]}"#, 3), None);
        let deep = find_too_deep(r#"{"a":[1,{"b":[2]}]}"#, 3).unwrap();
        assert_eq!((deep.offset, deep.line, deep.column), (13, 1, 14));
        // Brackets inside strings, escaped quotes included, do not count.
        assert_eq!(find_too_deep(r#"{"a":"[[[{{\"[[["}"#, 1), None);
        let text = "{\n  \"é\": [\n    [[]]\n  ]\n}";
        let deep = find_too_deep(text, 3).unwrap();
        assert_eq!((deep.line, deep.column), (3, 6));
    }

    #[test]
    fn the_ceiling_is_what_serde_json_parses() {
        let nested = |depth: usize| "[".repeat(depth) + &"]".repeat(depth);
        assert!(serde_json::from_str::<serde_json::Value>(&nested(JSON_DEPTH_CEILING)).is_ok());
        assert!(
            serde_json::from_str::<serde_json::Value>(&nested(JSON_DEPTH_CEILING + 1)).is_err()
        );
    }

    #[test]
    fn pixel_limit_is_inclusive_and_named_with_its_flag() {
        let options = LoadOptions {
            max_image_pixels: 100,
            ..LoadOptions::default()
        };
        assert_eq!(options.image_too_large(10, 10), None);
        let message = options.image_too_large(100_000, 100_000).unwrap();
        assert!(message.contains("10000000000 pixels"), "{message}");
        assert!(message.contains("--max-image-pixels"), "{message}");
    }

    #[test]
    fn the_memory_budget_is_inclusive_and_named_with_its_flag() {
        assert_eq!(over_memory_budget("x", 1 << 30, 1 << 30), None);
        assert_eq!(
            over_memory_budget("decoding it", 6 << 30, 2 << 30).unwrap(),
            "decoding it needs about 6.0 GiB, over the memory budget of 2.0 GiB (raise it \
             with --max-memory)"
        );
        assert!(default_max_memory() >= 1 << 20);
    }

    #[test]
    fn streams_are_read_up_to_the_limit() {
        let options = LoadOptions {
            max_document_bytes: 1000,
            ..LoadOptions::default()
        };
        let bytes = read_asset_file(Path::new("/dev/zero"), &options).unwrap();
        assert_eq!(bytes.len(), 1000 + 3 + 1);
    }
}
