//! External resources: resolving a buffer's or image's URI (relative path, percent-decoded, or
//! `data:` base64) and reading image headers without decoding pixels.
//!
//! URIs are refused unless they are `data:` or a relative path that stays inside the asset's
//! folder: velvet runs unattended over assets nobody checked, and must not read `/etc/passwd`
//! because a glTF names it. `--allow-outside-uris` lifts this for reading (paths that climb
//! out, absolute paths, `file:` URIs); writing always resolves with [`resolve`], which never
//! leaves the folder. Only regular files are read: a URI naming a device or a pipe (through a
//! link) could otherwise stream without end.

use super::image_features::{self, ImageFeatures};
use crate::diagnostics::{codes, Diagnostic};
use base64::Engine;
use std::path::{Component, Path, PathBuf};

/// Where a URI leads.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// The decoded bytes of a `data:` URI, with its media type (without its parameters, such
    /// as `;charset=…`, and in lower case: media types are case-insensitive, RFC 2045) and
    /// whether it was base64 (or else percent-encoded).
    Data {
        media_type: String,
        bytes: Vec<u8>,
        base64: bool,
    },
    /// A file next to the asset.
    File(PathBuf),
}

/// Resolves `uri` against `base_dir`, inside the folder only. `pointer` names the URI in the
/// document, for diagnostics.
pub fn resolve(uri: &str, base_dir: &Path, pointer: &str) -> Result<Location, Diagnostic> {
    resolve_with(uri, base_dir, pointer, false)
}

/// Resolves `uri` against `base_dir`; with `allow_outside`, paths that climb out of the
/// folder, absolute paths and `file:` URIs are followed too.
pub fn resolve_with(
    uri: &str,
    base_dir: &Path,
    pointer: &str,
    allow_outside: bool,
) -> Result<Location, Diagnostic> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').ok_or_else(|| {
            Diagnostic::new(
                &codes::INVALID_URI,
                pointer,
                "the data: URI has no ',' before its payload",
            )
        })?;
        // RFC 2397: `;base64` marks base64; without it the payload is percent-encoded
        // bytes. glTF's "MAY use base64" does not forbid the second form, which the Khronos
        // validator decodes too (the resources rule warns that some loaders do not).
        let (media_type, base64) = match header.strip_suffix(";base64") {
            Some(media_type) => (media_type, true),
            None => (header, false),
        };
        // RFC 2397: after the type, each parameter is `attribute=value`.
        if media_type
            .split(';')
            .skip(1)
            .any(|parameter| parameter.split_once('=').is_none_or(|(a, _)| a.is_empty()))
        {
            return Err(Diagnostic::new(
                &codes::INVALID_URI,
                pointer,
                format!("the data: URI's media type '{media_type}' has a parameter that is not attribute=value"),
            ));
        }
        let bytes = if base64 {
            base64::engine::general_purpose::STANDARD
                .decode(payload.trim_end())
                .map_err(|e| {
                    Diagnostic::new(
                        &codes::INVALID_URI,
                        pointer,
                        format!("the data: URI's base64 is invalid: {e}"),
                    )
                })?
        } else {
            percent_decode_strict(payload).ok_or_else(|| {
                Diagnostic::new(
                    &codes::INVALID_URI,
                    pointer,
                    "the data: URI's payload has a '%' not followed by two hexadecimal digits",
                )
            })?
        };
        return Ok(Location::Data {
            media_type: media_type
                .split(';')
                .next()
                .unwrap_or_default()
                .trim()
                .to_ascii_lowercase(),
            bytes,
            base64,
        });
    }
    let mut path_part = uri;
    // A relative reference's first segment cannot hold ':' (RFC 3986, 4.2); before a ':' there,
    // a URI has its scheme, which is not empty and starts with a letter.
    let first_segment = uri.split(['/', '?', '#']).next().unwrap_or_default();
    if first_segment.contains(':') && !has_scheme(uri) {
        return Err(Diagnostic::new(
            &codes::INVALID_URI,
            pointer,
            format!("'{uri}' is not a URI: the part before its ':' is no scheme"),
        ));
    }
    if has_scheme(uri) {
        match file_uri_path(uri) {
            Some(path) if allow_outside => path_part = path,
            Some(_) => {
                return Err(Diagnostic::new(
                    &codes::URI_NOT_FOLLOWED,
                    pointer,
                    format!("'{uri}' is a file: URI; only relative paths inside the asset's folder are read (--allow-outside-uris reads it)"),
                ))
            }
            None => {
                return Err(Diagnostic::new(
                    &codes::URI_NOT_FOLLOWED,
                    pointer,
                    format!("'{uri}' has a URL scheme; only data: URIs and file paths are read"),
                ))
            }
        }
    }
    let decoded = percent_encoding::percent_decode_str(path_part)
        .decode_utf8()
        .map_err(|_| {
            Diagnostic::new(
                &codes::INVALID_URI,
                pointer,
                format!("'{uri}' does not percent-decode to UTF-8"),
            )
        })?;
    let relative = Path::new(decoded.as_ref());
    if allow_outside {
        // Absolute paths replace the base in `join`; relative ones climb as they say.
        return Ok(Location::File(base_dir.join(relative)));
    }
    let mut depth: i64 = 0;
    for component in relative.components() {
        match component {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    return Err(Diagnostic::new(
                        &codes::URI_NOT_FOLLOWED,
                        pointer,
                        format!("'{uri}' climbs out of the asset's folder (--allow-outside-uris reads it)"),
                    ));
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(Diagnostic::new(
                    &codes::URI_NOT_FOLLOWED,
                    pointer,
                    format!("'{uri}' is an absolute path; only relative paths are read (--allow-outside-uris reads it)"),
                ))
            }
        }
    }
    Ok(Location::File(base_dir.join(relative)))
}

/// True for a URI with a URL scheme that names no local file (`https:`, `s3:`, …): valid in
/// glTF, never fetched by velvet. `data:` and `file:` URIs and Windows drive letters are not
/// remote.
pub fn is_remote(uri: &str) -> bool {
    has_scheme(uri)
        && !uri.starts_with("data:")
        && file_uri_path(uri).is_none()
        && uri.find(':').is_some_and(|colon| colon > 1)
}

/// Refuses a path that lies in `base_dir` by its text but leads out of it through a symbolic
/// link. A path that does not exist (yet) is left to whoever opens it. `real_base` gives
/// `base_dir` with every link resolved (see [`real_folder`]), asked only when the path is not
/// plainly inside.
///
/// A path below the folder whose every component is a plain name and none a link is inside
/// without resolving anything: one `lstat` per component, where resolving the whole path
/// would read every directory above the folder too. Anything else is resolved in full.
///
/// What the walk saw of the file itself, when it saw it: its last component's `lstat`, which
/// for a path without links is its `stat`, or that a component is not there. The file's facts
/// are then taken from it instead of being asked again.
pub fn check_inside(
    path: &Path,
    base_dir: &Path,
    real_base: impl FnOnce() -> Option<PathBuf>,
    uri: &str,
    pointer: &str,
) -> Result<Option<std::io::Result<std::fs::Metadata>>, Diagnostic> {
    if let Ok(below) = path.strip_prefix(base_dir) {
        if below
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
        {
            let mut at = base_dir.to_path_buf();
            let mut last = None;
            for part in below.components() {
                at.push(part);
                match std::fs::symlink_metadata(&at) {
                    Ok(meta) if meta.file_type().is_symlink() => {
                        last = None;
                        break;
                    }
                    Ok(meta) => last = Some(Ok(meta)),
                    // Not there (yet): left to whoever opens it, and so is any other error.
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Some(Err(e))),
                    Err(_) => return Ok(None),
                }
            }
            if last.is_some() {
                return Ok(last);
            }
        }
    }
    let Ok(real) = std::fs::canonicalize(path) else {
        return Ok(None);
    };
    match real_base() {
        Some(base) if real.starts_with(&base) => Ok(None),
        _ => Err(Diagnostic::new(
            &codes::URI_NOT_FOLLOWED,
            pointer,
            format!(
                "'{uri}' leads out of the asset's folder through a symbolic link (to {}); --allow-outside-uris reads it",
                real.display()
            ),
        )),
    }
}

/// `base_dir` with every link resolved (`.` for the empty path); `None` when it cannot be.
pub fn real_folder(base_dir: &Path) -> Option<PathBuf> {
    let base = if base_dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base_dir
    };
    std::fs::canonicalize(base).ok()
}

/// The path of a local `file:` URI (`file:///p`, `file://localhost/p` or `file:/p`), still
/// percent-encoded; `None` for any other URI.
fn file_uri_path(uri: &str) -> Option<&str> {
    let rest = uri
        .get(..5)
        .filter(|s| s.eq_ignore_ascii_case("file:"))
        .map(|_| &uri[5..])?;
    match rest.strip_prefix("//") {
        Some(authority_and_path) => {
            let slash = authority_and_path.find('/')?;
            let host = &authority_and_path[..slash];
            (host.is_empty() || host.eq_ignore_ascii_case("localhost"))
                .then_some(&authority_and_path[slash..])
        }
        None => rest.starts_with('/').then_some(rest),
    }
}

/// How a Git LFS pointer file begins (a clone without Git LFS has these in place of content).
pub const LFS_POINTER_PREFIX: &[u8] = b"version https://git-lfs.github.com/spec/";
/// Git LFS pointer files are about 130 bytes; anything larger is real content.
pub const LFS_POINTER_MAX_LEN: u64 = 1024;

/// The bytes of the short file at `path`, whose stat said `len`; `None` when it cannot be
/// read. Read through `take`: `std::fs::read` and a `File`'s own `read_to_end` ask the file's
/// length and position again (a stat and a seek), which a run over hundreds of files would pay
/// for each.
pub fn read_short(path: &Path, len: u64) -> Option<Vec<u8>> {
    use std::io::Read;
    let mut file = std::fs::File::open(path).ok()?;
    // One byte more than the stat said, to see that the file ends there.
    let mut bytes = Vec::with_capacity(usize::try_from(len).ok()?.saturating_add(1));
    (&mut file).take(u64::MAX).read_to_end(&mut bytes).ok()?;
    Some(bytes)
}

/// Opens a resource file that a URI led to, refusing anything but a regular file. `is_file`
/// is what the file system said of `path` when asked (whether it is a regular file, or why it
/// could not say): asked before opening, since opening a pipe waits for a writer.
pub fn open_file(
    path: &Path,
    uri: &str,
    pointer: &str,
    is_file: Result<bool, String>,
) -> Result<std::fs::File, Diagnostic> {
    let fail = |detail: &str| {
        Diagnostic::new(
            &codes::IO_ERROR,
            pointer,
            format!("cannot read '{uri}' ({}): {detail}", path.display()),
        )
    };
    match is_file {
        Err(why) => Err(fail(&why)),
        Ok(false) => Err(fail("not a regular file")),
        Ok(true) => std::fs::File::open(path).map_err(|e| fail(&e.to_string())),
    }
}

/// The whole of a resource file opened with [`open_file`].
pub fn read_whole(
    mut file: std::fs::File,
    path: &Path,
    uri: &str,
    pointer: &str,
) -> Result<Vec<u8>, Diagnostic> {
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut file, &mut bytes).map_err(|e| {
        Diagnostic::new(
            &codes::IO_ERROR,
            pointer,
            format!("cannot read '{uri}' ({}): {e}", path.display()),
        )
    })?;
    Ok(bytes)
}

/// Percent-decodes `text` into bytes; `None` when a '%' is not followed by two hexadecimal
/// digits (which `percent_encoding` would pass through as they stand).
fn percent_decode_strict(text: &str) -> Option<Vec<u8>> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut at = 0;
    while at < bytes.len() {
        if bytes[at] == b'%' {
            let hex = bytes.get(at + 1..at + 3)?;
            let digits = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(digits, 16).ok()?);
            at += 3;
        } else {
            out.push(bytes[at]);
            at += 1;
        }
    }
    Some(out)
}

/// RFC 3986 scheme: a letter, then letters, digits, '+', '-' or '.', then ':'. A Windows drive
/// letter ("C:") counts too, which is what we want: it is not a relative path either.
fn has_scheme(uri: &str) -> bool {
    match uri.split_once(':') {
        Some((scheme, _)) => {
            let mut chars = scheme.chars();
            chars.next().is_some_and(|c| c.is_ascii_alphabetic())
                && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
        }
        None => false,
    }
}

/// An image's container format, from its first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Jpeg,
    Webp,
    Ktx2,
}

impl ImageFormat {
    /// The format's name as messages give it.
    pub fn name(self) -> &'static str {
        match self {
            ImageFormat::Png => "PNG",
            ImageFormat::Jpeg => "JPEG",
            ImageFormat::Webp => "WebP",
            ImageFormat::Ktx2 => "KTX2",
        }
    }

    pub fn sniff(bytes: &[u8]) -> Option<ImageFormat> {
        if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(ImageFormat::Png)
        } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
            Some(ImageFormat::Jpeg)
        } else if bytes.len() >= 12 && &bytes[0..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
            Some(ImageFormat::Webp)
        } else if bytes.starts_with(b"\xABKTX 20\xBB\r\n\x1A\n") {
            Some(ImageFormat::Ktx2)
        } else {
            None
        }
    }
}

/// What an image's header says, read without decoding pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageHeader {
    pub format: ImageFormat,
    pub width: u32,
    pub height: u32,
    /// Channels after the decoder's expansion (a PNG palette or tRNS chunk counts as its
    /// expanded form). `None` where the header does not tell (KTX2).
    pub channels: Option<u8>,
    pub has_alpha: Option<bool>,
    /// Bits per channel, where known.
    pub bits: Option<u8>,
    /// What the header holds that glTF does not support (IMAGE_FEATURES_UNSUPPORTED).
    pub features: ImageFeatures,
}

/// Reads the header of an image whose first bytes `reader` yields. Only the header is read
/// from the reader (for PNG, up to the first image-data chunk, walked twice: once for the
/// chunks [`image_features::png`] reads, once by the decoder).
pub fn read_header<R: std::io::BufRead + std::io::Seek>(
    mut reader: R,
    pointer: &str,
    what: &str,
) -> Result<ImageHeader, Diagnostic> {
    use image::ImageDecoder;
    // Past its first bytes, an image of a known format whose header cannot be read is damaged.
    let unrecognized = |detail: String| {
        Diagnostic::new(
            &codes::IMAGE_DATA_INVALID,
            pointer,
            format!("{what}: {detail}"),
        )
    };
    // Every format's signature, and a WebP's first chunk header and VP8X flags.
    let mut magic = [0u8; 21];
    let read = read_up_to(&mut reader, &mut magic).map_err(|e| unrecognized(e.to_string()))?;
    reader
        .seek(std::io::SeekFrom::Start(0))
        .map_err(|e| unrecognized(e.to_string()))?;
    let format = ImageFormat::sniff(&magic[..read]).ok_or_else(|| {
        Diagnostic::new(
            &codes::IMAGE_UNRECOGNIZED_FORMAT,
            pointer,
            format!("{what}: not a PNG, JPEG, WebP or KTX2 image"),
        )
    })?;
    let features = match format {
        ImageFormat::Png => {
            let found = image_features::png(&mut reader);
            reader
                .seek(std::io::SeekFrom::Start(0))
                .map_err(|e| unrecognized(e.to_string()))?;
            found
        }
        ImageFormat::Webp => image_features::webp(&magic[..read]),
        ImageFormat::Jpeg | ImageFormat::Ktx2 => ImageFeatures::default(),
    };
    if format == ImageFormat::Ktx2 {
        let mut head = [0u8; 28];
        let n = read_up_to(&mut reader, &mut head).map_err(|e| unrecognized(e.to_string()))?;
        if n < 28 {
            return Err(Diagnostic::new(
                &codes::IMAGE_UNEXPECTED_EOS,
                pointer,
                format!("{what}: the image ends inside its KTX2 header"),
            ));
        }
        let width = u32::from_le_bytes([head[20], head[21], head[22], head[23]]);
        let height = u32::from_le_bytes([head[24], head[25], head[26], head[27]]);
        return Ok(ImageHeader {
            format,
            width,
            height,
            channels: None,
            has_alpha: None,
            bits: None,
            features,
        });
    }
    // A header cut short is IMAGE_UNEXPECTED_EOS, as the Khronos validator names it; any other
    // damage IMAGE_DATA_INVALID.
    let damaged = |e: image::ImageError| match &e {
        image::ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            Diagnostic::new(
                &codes::IMAGE_UNEXPECTED_EOS,
                pointer,
                format!("{what}: the image ends inside its header"),
            )
        }
        _ => unrecognized(e.to_string()),
    };
    let decoder: Box<dyn ImageDecoder> = match format {
        ImageFormat::Png => Box::new(image::codecs::png::PngDecoder::new(reader).map_err(damaged)?),
        ImageFormat::Jpeg => {
            Box::new(image::codecs::jpeg::JpegDecoder::new(reader).map_err(damaged)?)
        }
        ImageFormat::Webp => {
            Box::new(image::codecs::webp::WebPDecoder::new(reader).map_err(damaged)?)
        }
        ImageFormat::Ktx2 => unreachable!("handled above"),
    };
    let (width, height) = decoder.dimensions();
    let color = decoder.color_type();
    let channels = color.channel_count();
    Ok(ImageHeader {
        format,
        width,
        height,
        channels: Some(channels),
        has_alpha: Some(color.has_alpha()),
        bits: Some((color.bits_per_pixel() / u16::from(channels)) as u8),
        features,
    })
}

/// A reader that keeps the first bytes it reads (up to [`Rewinding::KEEP`]), so that a seek
/// back lands in what it kept: an image header is read from the file once, though
/// [`read_header`] goes back to the start twice (after the signature, after the PNG chunks)
/// and the decoder reads it again from there. `std::io::BufReader` forgets its buffer on
/// every seek and reads the file again. Past what it keeps (a PNG whose chunks before its
/// pixels run over a mebibyte) it reads as a `BufReader` would, so a hostile file costs no
/// more memory than that. No well-kept crate offers this; it is a few lines.
pub struct Rewinding<R> {
    inner: R,
    /// The file's first bytes, as read.
    kept: Vec<u8>,
    /// Whether the file ended within what is kept.
    ended: bool,
    /// Bytes past what is kept, from `window_start` on.
    window: Vec<u8>,
    window_start: u64,
    /// Where the reader stands, and where `inner` does.
    at: u64,
    inner_at: u64,
}

impl<R: std::io::Read + std::io::Seek> Rewinding<R> {
    /// How much of the file's start is kept.
    pub const KEEP: usize = 1 << 20;
    /// How much is read from `inner` at a time.
    const CHUNK: usize = 8 << 10;

    pub fn new(inner: R) -> Rewinding<R> {
        Rewinding {
            inner,
            kept: Vec::new(),
            ended: false,
            window: Vec::new(),
            window_start: 0,
            at: 0,
            inner_at: 0,
        }
    }

    /// Reads from `inner` at `from` into `into`; how many bytes came.
    fn read_at(&mut self, from: u64, into: &mut [u8]) -> std::io::Result<usize> {
        if self.inner_at != from {
            self.inner.seek(std::io::SeekFrom::Start(from))?;
            self.inner_at = from;
        }
        let n = loop {
            match self.inner.read(into) {
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                other => break other?,
            }
        };
        self.inner_at += n as u64;
        Ok(n)
    }
}

impl<R: std::io::Read + std::io::Seek> std::io::Read for Rewinding<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = std::io::BufRead::fill_buf(self)?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.at += n as u64;
        Ok(n)
    }
}

impl<R: std::io::Read + std::io::Seek> std::io::BufRead for Rewinding<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        // What is kept grows, a chunk at a time, until it holds the place asked for (a seek
        // forward within the first mebibyte reads what it passes: the decoder reads it next).
        while self.at >= self.kept.len() as u64 && self.at < Self::KEEP as u64 && !self.ended {
            let start = self.kept.len();
            let take = Self::CHUNK.min(Self::KEEP - start);
            self.kept.resize(start + take, 0);
            let mut chunk = std::mem::take(&mut self.kept);
            let read = self.read_at(start as u64, &mut chunk[start..]);
            chunk.truncate(start + *read.as_ref().unwrap_or(&0));
            self.kept = chunk;
            self.ended = read? == 0;
        }
        if self.at < self.kept.len() as u64 {
            return Ok(&self.kept[self.at as usize..]);
        }
        if self.ended {
            return Ok(&[]);
        }
        let in_window =
            self.at >= self.window_start && self.at < self.window_start + self.window.len() as u64;
        if !in_window {
            let mut window = std::mem::take(&mut self.window);
            window.resize(Self::CHUNK, 0);
            let read = self.read_at(self.at, &mut window);
            window.truncate(*read.as_ref().unwrap_or(&0));
            self.window = window;
            self.window_start = self.at;
            read?;
        }
        Ok(&self.window[(self.at - self.window_start) as usize..])
    }

    fn consume(&mut self, amount: usize) {
        self.at += amount as u64;
    }
}

impl<R: std::io::Read + std::io::Seek> std::io::Seek for Rewinding<R> {
    fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
        let target = match to {
            std::io::SeekFrom::Start(n) => Some(n),
            std::io::SeekFrom::Current(d) => self.at.checked_add_signed(d),
            std::io::SeekFrom::End(d) => {
                let end = self.inner.seek(std::io::SeekFrom::End(0))?;
                self.inner_at = end;
                end.checked_add_signed(d)
            }
        };
        self.at = target.ok_or_else(|| {
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "seek out of range")
        })?;
        Ok(self.at)
    }
}

fn read_up_to<R: std::io::Read>(reader: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..])? {
            0 => break,
            n => filled += n,
        }
    }
    Ok(filled)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> &'static Path {
        Path::new("/assets/chair")
    }

    #[test]
    fn relative_uris_are_percent_decoded_and_joined() {
        assert_eq!(
            resolve("tex/My%20Image.png", base(), "/images/0/uri").unwrap(),
            Location::File(PathBuf::from("/assets/chair/tex/My Image.png"))
        );
        assert_eq!(
            resolve("a/../b.png", base(), "").unwrap(),
            Location::File(PathBuf::from("/assets/chair/a/../b.png"))
        );
    }

    #[test]
    fn escaping_absolute_and_remote_uris_are_refused() {
        for uri in [
            "../x.png",
            "a/../../x.png",
            "/etc/passwd",
            "https://example.com/x.png",
            "C:/x.png",
            "file:///x",
        ] {
            let err = resolve(uri, base(), "/images/3/uri").unwrap_err();
            assert_eq!(
                (err.code, err.pointer.as_str()),
                ("URI_NOT_FOLLOWED", "/images/3/uri"),
                "{uri}"
            );
        }
    }

    #[test]
    fn outside_uris_are_followed_only_when_allowed() {
        for (uri, expected) in [
            ("../x.png", "/assets/chair/../x.png"),
            ("a/../../x%20y.png", "/assets/chair/a/../../x y.png"),
            ("/etc/hostname", "/etc/hostname"),
            ("file:///srv/tex/a%20b.png", "/srv/tex/a b.png"),
            ("file://localhost/srv/a.png", "/srv/a.png"),
            ("FILE:/srv/a.png", "/srv/a.png"),
        ] {
            assert_eq!(
                resolve_with(uri, base(), "", true).unwrap(),
                Location::File(PathBuf::from(expected)),
                "{uri}"
            );
            let refused = resolve_with(uri, base(), "", false).unwrap_err();
            assert_eq!(refused.code, "URI_NOT_FOLLOWED", "{uri}");
            assert!(
                refused.message.contains("--allow-outside-uris"),
                "{}",
                refused.message
            );
        }
        // Remote schemes and other hosts are never fetched.
        for uri in [
            "https://example.com/x.png",
            "file://server/share/x.png",
            "C:/x.png",
        ] {
            let refused = resolve_with(uri, base(), "", true).unwrap_err();
            assert_eq!(refused.code, "URI_NOT_FOLLOWED", "{uri}");
        }
    }

    #[test]
    fn only_regular_files_are_read() {
        let zero = Path::new("/dev/zero");
        let is_file = std::fs::metadata(zero)
            .map(|m| m.is_file())
            .map_err(|e| e.to_string());
        let err = open_file(zero, "zero.bin", "/buffers/0/uri", is_file).unwrap_err();
        assert_eq!(
            (err.code, err.pointer.as_str()),
            ("IO_ERROR", "/buffers/0/uri")
        );
        assert!(
            err.message.contains("not a regular file"),
            "{}",
            err.message
        );
    }

    #[test]
    fn percent_encoded_data_uris_decode_to_their_bytes() {
        assert_eq!(
            resolve("data:application/gltf-buffer,%00%01%FFa+b", base(), "").unwrap(),
            Location::Data {
                media_type: "application/gltf-buffer".into(),
                bytes: vec![0, 1, 255, b'a', b'+', b'b'],
                base64: false,
            }
        );
        assert_eq!(
            resolve("data:text/plain,hello", base(), "").unwrap(),
            Location::Data {
                media_type: "text/plain".into(),
                bytes: b"hello".to_vec(),
                base64: false,
            }
        );
    }

    #[test]
    fn data_uris_decode_base64_and_refuse_malformed_ones() {
        assert_eq!(
            resolve("data:application/octet-stream;base64,AAEC", base(), "").unwrap(),
            Location::Data {
                media_type: "application/octet-stream".into(),
                bytes: vec![0, 1, 2],
                base64: true,
            }
        );
        // The media type without its parameters, in lower case.
        assert_eq!(
            resolve(
                "data:Application/Octet-Stream;charset=x;base64,AAEC",
                base(),
                ""
            )
            .unwrap(),
            Location::Data {
                media_type: "application/octet-stream".into(),
                bytes: vec![0, 1, 2],
                base64: true,
            }
        );
        for uri in [
            "data:;base64,@@@",
            "data:nocomma",
            "data:,100%",
            "data:,%zz",
        ] {
            assert_eq!(
                resolve(uri, base(), "").unwrap_err().code,
                "INVALID_URI",
                "{uri}"
            );
        }
    }

    fn png(color: image::ExtendedColorType) -> Vec<u8> {
        let mut bytes = Vec::new();
        let channels = color.channel_count() as usize;
        let bytes_per = (color.bits_per_pixel() as usize / channels).div_ceil(8);
        let data = vec![0u8; 4 * channels * bytes_per];
        image::ImageEncoder::write_image(
            image::codecs::png::PngEncoder::new(&mut bytes),
            &data,
            2,
            2,
            color,
        )
        .unwrap();
        bytes
    }

    /// A reader that counts the bytes it hands out.
    struct Counted<'c> {
        bytes: std::io::Cursor<&'c [u8]>,
        handed: &'c std::cell::Cell<usize>,
    }

    impl std::io::Read for Counted<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let n = self.bytes.read(buf)?;
            self.handed.set(self.handed.get() + n);
            Ok(n)
        }
    }

    impl std::io::Seek for Counted<'_> {
        fn seek(&mut self, to: std::io::SeekFrom) -> std::io::Result<u64> {
            self.bytes.seek(to)
        }
    }

    #[test]
    fn a_header_read_through_a_rewinding_reader_reads_each_byte_once_and_says_the_same() {
        use image::ColorType;
        for color in [ColorType::Rgba8, ColorType::L16] {
            let bytes = png(color.into());
            let handed = std::cell::Cell::new(0);
            let rewinding = Rewinding::new(Counted {
                bytes: std::io::Cursor::new(&bytes),
                handed: &handed,
            });
            let header = read_header(rewinding, "", "image 0").unwrap();
            let expected = read_header(std::io::Cursor::new(&bytes), "", "image 0").unwrap();
            assert_eq!(header, expected);
            // The signature is read, then the chunks from the start, then the decoder reads
            // from the start again: the file gives each byte once, and no more than it holds.
            assert!(
                handed.get() <= bytes.len(),
                "{} of {}",
                handed.get(),
                bytes.len()
            );
        }
        // Seeks from the end and from where it is, and past the end.
        let mut r = Rewinding::new(std::io::Cursor::new(&b"0123456789"[..]));
        let mut two = [0u8; 2];
        use std::io::{Read, Seek, SeekFrom};
        assert_eq!(r.seek(SeekFrom::End(-3)).unwrap(), 7);
        r.read_exact(&mut two).unwrap();
        assert_eq!(&two, b"78");
        assert_eq!(r.seek(SeekFrom::Current(-9)).unwrap(), 0);
        r.read_exact(&mut two).unwrap();
        assert_eq!(&two, b"01");
        assert_eq!(r.seek(SeekFrom::Start(20)).unwrap(), 20);
        assert_eq!(r.read(&mut two).unwrap(), 0);
        assert!(r.seek(SeekFrom::Current(-30)).is_err());
    }

    #[test]
    fn a_png_whose_chunks_before_its_pixels_run_past_what_is_kept_reads_the_same() {
        // A 3 MiB tEXt chunk after the header: the reader keeps its first mebibyte and reads
        // on as a buffered reader does.
        let plain = png(image::ExtendedColorType::Rgba8);
        let chunk = crate::asset::image_features::png_chunk(b"tEXt", &vec![b'a'; 3 << 20]);
        // After the signature (8 bytes) and the IHDR chunk (25).
        let bytes = [&plain[..33], &chunk, &plain[33..]].concat();
        let mut rewinding = Rewinding::new(std::io::Cursor::new(&bytes[..]));
        let header = read_header(&mut rewinding, "", "image 0").unwrap();
        let expected = read_header(std::io::Cursor::new(&bytes), "", "image 0").unwrap();
        assert_eq!(header, expected);
        assert_eq!((header.width, header.height), (2, 2));
        assert_eq!(
            rewinding.kept.len(),
            Rewinding::<std::io::Cursor<&[u8]>>::KEEP
        );
    }

    #[test]
    fn every_cut_of_an_image_reads_through_a_rewinding_reader_as_from_memory() {
        // PNG, JPEG and WebP headers cut at every length, and bytes no format begins with:
        // the same header, or the same finding, whichever way the bytes come.
        let mut images = vec![png(image::ExtendedColorType::Rgba8)];
        for format in [image::ImageFormat::Jpeg, image::ImageFormat::WebP] {
            let mut bytes = Vec::new();
            image::DynamicImage::new_rgb8(3, 2)
                .write_to(&mut std::io::Cursor::new(&mut bytes), format)
                .unwrap();
            images.push(bytes);
        }
        images.push(b"GIF89a not an image velvet reads".to_vec());
        for image in &images {
            for cut in 0..=image.len() {
                let bytes = &image[..cut];
                let rewinding = read_header(
                    Rewinding::new(std::io::Cursor::new(bytes)),
                    "/images/0",
                    "image 0",
                );
                let memory = read_header(std::io::Cursor::new(bytes), "/images/0", "image 0");
                assert_eq!(rewinding, memory, "{cut} of {} bytes", image.len());
            }
        }
    }

    #[test]
    fn png_headers_tell_alpha_and_depth() {
        use image::ExtendedColorType::*;
        for (color, channels, alpha, bits) in [
            (L8, 1, false, 8),
            (La8, 2, true, 8),
            (Rgb8, 3, false, 8),
            (Rgba16, 4, true, 16),
        ] {
            let h = read_header(std::io::Cursor::new(png(color)), "", "image 0").unwrap();
            assert_eq!((h.format, h.width, h.height), (ImageFormat::Png, 2, 2));
            assert_eq!(
                (h.channels, h.has_alpha, h.bits),
                (Some(channels), Some(alpha), Some(bits)),
                "{color:?}"
            );
        }
    }

    #[test]
    fn garbage_is_an_unrecognized_image_a_cut_png_an_unexpected_end_and_a_bad_one_invalid() {
        let err = read_header(
            std::io::Cursor::new(b"hello world, not an image".to_vec()),
            "/images/1",
            "image 1",
        )
        .unwrap_err();
        assert_eq!(err.code, "IMAGE_UNRECOGNIZED_FORMAT");
        let err = read_header(
            std::io::Cursor::new(b"\x89PNG\r\n\x1a\n\0\0".to_vec()),
            "/images/1",
            "image 1",
        )
        .unwrap_err();
        assert_eq!(err.code, "IMAGE_UNEXPECTED_EOS");
        // A whole IHDR chunk whose colour type no PNG has is damage, not a cut.
        let mut bad = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x01\0\0\0\x01\x08\x09\0\0\0".to_vec();
        bad.extend_from_slice(&[0, 0, 0, 0]);
        let err = read_header(std::io::Cursor::new(bad), "/images/1", "image 1").unwrap_err();
        assert_eq!(err.code, "IMAGE_DATA_INVALID");
    }
}
