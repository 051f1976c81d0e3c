//! A file's bytes as velvet holds them, and the JSON text made of them: always read into
//! velvet's own memory, a snapshot of the file as it was read.
//!
//! Why read and not map: velvet once mapped files of 1 MiB or more from the file cache, which
//! saved the first touch of fresh memory (on the 20,000-material library, validate 61.8 →
//! 56.1 ms and `migrate --fast` 68.7 → 67.6 ms, medians back to back; more where fresh memory
//! is slow to fault in, see docs/performance.md). But a mapping shares its pages with every
//! program that writes the file: another program rewriting the file while velvet ran changed
//! the text under the parser, so a text checked to be UTF-8 once stopped being UTF-8 (a panic,
//! and strictly undefined behaviour), and `--in-place` wrote back a mix of the two versions
//! with exit status 0. No check made after the fact (size, time, a checksum before writing)
//! makes the reads in between sound, so the bytes are read: UTF-8 is checked once, when the
//! text is made, and nothing another program does later reaches them. What another program
//! does to the file meanwhile is caught before anything is written for it
//! ([`super::Snapshot`]).

use std::fmt;
use std::ops::Deref;
use std::path::Path;

/// A file's bytes, read into memory.
pub struct FileBytes(Vec<u8>);

impl FileBytes {
    /// Bytes already in memory.
    pub fn from_vec(bytes: Vec<u8>) -> FileBytes {
        FileBytes(bytes)
    }

    /// The bytes, given back.
    pub fn into_vec(self) -> Vec<u8> {
        self.0
    }
}

impl Deref for FileBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        &self.0
    }
}

impl fmt::Debug for FileBytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "FileBytes({} bytes)", self.len())
    }
}

/// A document's JSON text: UTF-8, held as a `String` or as the bytes read from its file.
pub struct SourceText(FileBytes);

impl SourceText {
    /// The bytes as text when they are UTF-8; otherwise the bytes back, and where they stop
    /// being UTF-8.
    pub fn from_bytes(bytes: FileBytes) -> Result<SourceText, (FileBytes, std::str::Utf8Error)> {
        match std::str::from_utf8(&bytes) {
            Ok(_) => Ok(SourceText(bytes)),
            Err(e) => Err((bytes, e)),
        }
    }

    pub fn as_str(&self) -> &str {
        // SAFETY: every SourceText was checked to be UTF-8 when it was made (from_bytes, or a
        // String), and its bytes are velvet's own memory, which nothing changes after that
        // (see the module comment).
        unsafe { std::str::from_utf8_unchecked(&self.0) }
    }
}

impl From<String> for SourceText {
    fn from(text: String) -> SourceText {
        SourceText(FileBytes::from_vec(text.into_bytes()))
    }
}

impl Deref for SourceText {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl fmt::Debug for SourceText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

/// What a file was when velvet read it: its identity, size, modification and change times,
/// and, for a file written shortly before it was read, a digest of its bytes. Taken before the
/// file is read and compared after reading and again before anything is written for it, so
/// that an input another program writes meanwhile (an editor saving, a sync client, a second
/// run) fails with a message naming it rather than being overwritten by an output made from
/// older bytes.
///
/// The times alone are exact for a file last written well before it was read: any later write
/// moves them. A filesystem's clock advances in ticks (a few milliseconds on Linux, up to two
/// seconds elsewhere), so a file written within [`RECENT`] of being read may be written again
/// within the same tick and keep its times; only such a file pays for a digest of its bytes,
/// and for reading them again before the write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Snapshot {
    len: u64,
    /// Only a regular file's bytes are read again: a stream would not give the same ones.
    regular: bool,
    modified: Option<std::time::SystemTime>,
    #[cfg(unix)]
    identity: (u64, u64, i64, i64),
    digest: Option<u64>,
}

/// How long after its last write a file's times may still not tell a later write.
pub const RECENT: std::time::Duration = std::time::Duration::from_secs(3);

/// The block the digest hashes at a time; the same blocks whether the bytes are in memory or
/// read again from the file.
const DIGEST_BLOCK: usize = 1 << 16;

/// A digest of bytes taken [`DIGEST_BLOCK`] at a time, each block hashed with the digest so
/// far (foldhash's fast hash with a fixed seed: it guards against another program's write, not
/// against an adversary, who could as well set the times back).
#[derive(Default)]
struct Digest(u64);

impl Digest {
    fn add(&mut self, block: &[u8]) {
        use std::hash::BuildHasher;
        self.0 = foldhash::fast::FixedState::with_seed(0x5afe).hash_one((self.0, block));
    }

    fn of(bytes: &[u8]) -> u64 {
        let mut digest = Digest::default();
        bytes
            .chunks(DIGEST_BLOCK)
            .for_each(|block| digest.add(block));
        digest.0
    }
}

/// Fills `block` from `file` as far as the file goes: the number of bytes read, short only at
/// the end.
fn read_block(file: &mut std::fs::File, block: &mut [u8]) -> std::io::Result<usize> {
    use std::io::Read;
    let mut filled = 0;
    while filled < block.len() {
        match file.read(&mut block[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

impl Snapshot {
    /// The file at `path` as it is now (without a digest).
    fn stat(path: &Path) -> std::io::Result<Snapshot> {
        let meta = std::fs::metadata(path)?;
        Ok(Snapshot {
            len: meta.len(),
            regular: meta.is_file(),
            modified: meta.modified().ok(),
            #[cfg(unix)]
            identity: {
                use std::os::unix::fs::MetadataExt;
                (meta.dev(), meta.ino(), meta.ctime(), meta.ctime_nsec())
            },
            digest: None,
        })
    }

    /// The snapshot of a file whose bytes were read as `bytes` between `before` and now; `None`
    /// when the file changed while it was read.
    pub fn taken(path: &Path, before: Snapshot, bytes: &[u8]) -> std::io::Result<Option<Snapshot>> {
        let after = Snapshot::stat(path)?;
        if after != before {
            return Ok(None);
        }
        let recent = before.regular
            && before.modified.is_none_or(|m| {
                std::time::SystemTime::now()
                    .duration_since(m)
                    .map_or(true, |age| age < RECENT)
            });
        Ok(Some(Snapshot {
            digest: recent.then(|| Digest::of(bytes)),
            ..before
        }))
    }

    /// The file at `path` as it is now, before it is read (see [`Snapshot::taken`]).
    pub fn before_reading(path: &Path) -> std::io::Result<Snapshot> {
        Snapshot::stat(path)
    }

    /// `Ok` when the file at `path` still holds what this snapshot describes; otherwise the
    /// message saying so, naming the file.
    pub fn unchanged(&self, path: &Path) -> Result<(), String> {
        let changed = || {
            format!(
                "{} changed while velvet worked on it (another program wrote it); nothing was \
                 written for it",
                path.display()
            )
        };
        let cannot = |e: std::io::Error| {
            format!(
                "{} cannot be read again before writing ({e}); nothing was written for it",
                path.display()
            )
        };
        let now = Snapshot::stat(path).map_err(cannot)?;
        if now
            != (Snapshot {
                digest: None,
                ..*self
            })
        {
            return Err(changed());
        }
        let Some(digest) = self.digest else {
            return Ok(());
        };
        let mut file = std::fs::File::open(path).map_err(cannot)?;
        let mut block = vec![0u8; DIGEST_BLOCK];
        let mut read = 0u64;
        let mut acc = Digest::default();
        loop {
            let n = read_block(&mut file, &mut block).map_err(cannot)?;
            if n == 0 {
                break;
            }
            acc.add(&block[..n]);
            read += n as u64;
            if read > self.len {
                break;
            }
        }
        if read != self.len || acc.0 != digest {
            return Err(changed());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Seek, SeekFrom, Write};

    /// A large document's text stays what was read when another program then rewrites the
    /// file in place with bytes that are not UTF-8: the text is a snapshot, still UTF-8.
    #[test]
    fn a_large_text_stays_as_read_when_its_file_is_rewritten_in_place() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("large.gltf");
        let mut text = String::from("{\"asset\":{\"version\":\"2.0\"},\"extras\":\"");
        text.push_str(&"é".repeat(1 << 20));
        text.push_str("\"}");
        std::fs::write(&path, &text).unwrap();
        let bytes =
            crate::asset::limits::read_asset_file(&path, &crate::asset::LoadOptions::default())
                .unwrap();
        let source = SourceText::from_bytes(bytes).unwrap();
        let mut file = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
        file.seek(SeekFrom::Start(40)).unwrap();
        file.write_all(&[0xff; 4096]).unwrap();
        file.sync_all().unwrap();
        assert_eq!(source.as_str(), text);
    }

    #[test]
    fn bytes_that_are_not_utf8_come_back_with_where_they_stop() {
        let (bytes, e) = SourceText::from_bytes(FileBytes::from_vec(b"{\"a\":\"\xff\"}".to_vec()))
            .err()
            .unwrap();
        assert_eq!(&bytes[..], b"{\"a\":\"\xff\"}");
        assert_eq!(e.valid_up_to(), 6);
    }
}
