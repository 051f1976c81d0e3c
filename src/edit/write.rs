//! Writing assets: serialising an edited document in the input's own JSON style, packing GLBs,
//! and the atomic write (a temporary file in the target folder, renamed into place) that every
//! output of velvet goes through, resource copies included ([`copy_atomic`]).
//!
//! The atomic write carries a fault-injection seam for the tests of the "nothing lost"
//! guarantee, set by the environment variable `VELVET_TEST_WRITE_FAULT` (read once per
//! process): `error:N` makes every write after the first N fail halfway through its temporary
//! file with an I/O error, `abort:N` aborts the process there instead, as a kill or a power cut
//! would. Unset (always, outside those tests), it costs one cached lookup per write.

use crate::asset::{glb, Asset, Container};
use serde::Serialize;
use serde_json::Value;
use std::io::{self, Write};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

/// A fault the test seam injects into writes after the first `after`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fault {
    Error { after: usize },
    Abort { after: usize },
}

fn injected_fault() -> Option<Fault> {
    static FAULT: OnceLock<Option<Fault>> = OnceLock::new();
    *FAULT.get_or_init(|| {
        let value = std::env::var("VELVET_TEST_WRITE_FAULT").ok()?;
        let (kind, after) = value.split_once(':')?;
        let after = after.parse().ok()?;
        match kind {
            "error" => Some(Fault::Error { after }),
            "abort" => Some(Fault::Abort { after }),
            _ => None,
        }
    })
}

/// Writes `output` into a temporary file, or half of it and then the injected fault.
fn write_temporary(file: &mut impl Write, output: &Output) -> io::Result<()> {
    static WRITES: AtomicUsize = AtomicUsize::new(0);
    // The writes before the first `after` are whole.
    let fault = injected_fault().filter(|fault| {
        let (Fault::Error { after } | Fault::Abort { after }) = *fault;
        WRITES.fetch_add(1, Ordering::SeqCst) >= after
    });
    let Some(fault) = fault else {
        return write_pieces(file, output.pieces());
    };
    let mut half = output.len() / 2;
    for piece in output.pieces() {
        let take = piece.len().min(half);
        file.write_all(&piece[..take])?;
        half -= take;
        if half == 0 {
            break;
        }
    }
    file.flush()?;
    match fault {
        Fault::Abort { .. } => std::process::abort(),
        Fault::Error { .. } => Err(io::Error::other("injected write fault")),
    }
}

/// A file being written whose bytes are handed on to the disk every few megabytes, as they
/// are written: on Linux, `sync_file_range` starts writing them back and does not wait. The
/// `fsync` that makes the file durable then waits for the last few megabytes rather than for
/// all of them. Measured on the 15 MB output of `velvet migrate --fast` on the
/// 20,000-material library: the writing itself took 7–9 ms either way, the `fsync` after it
/// 6–10 ms before and 2–4 ms after. Elsewhere the bytes are written as they are.
struct HandedOn<'f> {
    file: &'f std::fs::File,
    written: u64,
    handed_on: u64,
}

impl<'f> HandedOn<'f> {
    /// How many bytes are written between two hand-ons.
    const EVERY: u64 = 2 << 20;

    fn new(file: &'f std::fs::File) -> HandedOn<'f> {
        HandedOn {
            file,
            written: 0,
            handed_on: 0,
        }
    }

    fn wrote(&mut self, n: usize) {
        self.written += n as u64;
        if self.written - self.handed_on < Self::EVERY {
            return;
        }
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            let (from, len) = (
                self.handed_on as libc::off64_t,
                self.written - self.handed_on,
            );
            // SAFETY: the call takes a descriptor this file holds open and a range of it; it
            // reads and writes no memory of this process. It only starts the writeback: an
            // error here is one the `fsync` after the writing reports.
            unsafe {
                libc::sync_file_range(
                    self.file.as_raw_fd(),
                    from,
                    len as libc::off64_t,
                    libc::SYNC_FILE_RANGE_WRITE,
                );
            }
        }
        self.handed_on = self.written;
    }
}

impl Write for HandedOn<'_> {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        let n = (&mut &*self.file).write(bytes)?;
        self.wrote(n);
        Ok(n)
    }

    fn write_vectored(&mut self, bytes: &[io::IoSlice<'_>]) -> io::Result<usize> {
        let n = (&mut &*self.file).write_vectored(bytes)?;
        self.wrote(n);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        (&mut &*self.file).flush()
    }
}

/// The most pieces one write hands the kernel (Linux's `IOV_MAX`).
const PIECES_PER_WRITE: usize = 1024;

/// Writes `pieces` in order, many to a call (`writev`): a spliced output is a run of the
/// source and a splice per edit, and a migration of every material of a large document has
/// tens of thousands of them, which one write each would spend most of the writing on calls.
fn write_pieces<'p>(
    file: &mut impl Write,
    pieces: impl Iterator<Item = &'p [u8]>,
) -> io::Result<()> {
    let mut pieces = pieces.filter(|p| !p.is_empty()).peekable();
    let mut pending: Vec<&[u8]> = Vec::with_capacity(PIECES_PER_WRITE);
    let mut slices: Vec<io::IoSlice> = Vec::with_capacity(PIECES_PER_WRITE);
    while pieces.peek().is_some() {
        pending.clear();
        pending.extend(pieces.by_ref().take(PIECES_PER_WRITE));
        let mut first = 0;
        while first < pending.len() {
            slices.clear();
            slices.extend(pending[first..].iter().map(|p| io::IoSlice::new(p)));
            match file.write_vectored(&slices) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(mut written) => {
                    // A short write: the pieces it took whole are done, the next one is
                    // taken from where it stopped.
                    while first < pending.len() && written >= pending[first].len() {
                        written -= pending[first].len();
                        first += 1;
                    }
                    if written > 0 {
                        pending[first] = &pending[first][written..];
                    }
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
    }
    Ok(())
}

/// How the input's JSON was laid out, so that an edited file keeps its look.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JsonStyle {
    /// The indentation unit, or `None` for minified JSON.
    pub indent: Option<String>,
    pub trailing_newline: bool,
}

impl JsonStyle {
    /// Reads the style off a JSON text: the first indented line gives the unit.
    pub fn detect(text: &str) -> JsonStyle {
        let trimmed = text.trim_end_matches(['\0', ' ']);
        let indent = trimmed.lines().skip(1).find_map(|line| {
            let unit: String = line
                .chars()
                .take_while(|c| *c == ' ' || *c == '\t')
                .collect();
            (!unit.is_empty()).then_some(unit)
        });
        JsonStyle {
            indent,
            trailing_newline: trimmed.ends_with('\n'),
        }
    }

    pub fn render(&self, json: &Value) -> Vec<u8> {
        let mut out = Vec::new();
        match &self.indent {
            Some(unit) => {
                let formatter = serde_json::ser::PrettyFormatter::with_indent(unit.as_bytes());
                let mut ser = serde_json::Serializer::with_formatter(&mut out, formatter);
                json.serialize(&mut ser)
                    .expect("serialising a Value into memory cannot fail");
            }
            None => serde_json::to_writer(&mut out, json)
                .expect("serialising a Value into memory cannot fail"),
        }
        if self.trailing_newline {
            out.push(b'\n');
        }
        out
    }
}

/// The bytes of `asset` with `json` as its document and `bin` as its GLB BIN chunk. When
/// `json` equals the loaded document and the BIN chunk is the loaded one, this is not called:
/// see [`unchanged`].
///
/// The JSON is written as splices into the loaded text (see [`crate::edit::splice`]): every
/// byte of the input that the edit did not change is kept. The document as loaded is read off
/// that text as the comparison goes (callers apply their edits to `asset.json` itself), and the
/// result is read once more to check it, neither time building a second document. A GLB's
/// chunk padding belongs to the container and is set anew.
pub fn to_bytes(asset: &Asset, json: &Value, bin: Option<&[u8]>) -> Vec<u8> {
    let spliced = crate::edit::splice::rewrite(source(asset), asset.root(), json)
        // The spliced text must read back as the document meant, numbers as velvet writes
        // them; if it ever did not, the document is written afresh rather than corrupted.
        .filter(|text| crate::edit::splice::reads_as_written(text, json));
    let text = match spliced {
        Some(text) => text.into_bytes(),
        None => JsonStyle::detect(&asset.json_text).render(json),
    };
    in_container(asset, text, bin)
}

/// The loaded text splices are made into: a GLB chunk's padding belongs to the container.
pub fn source(asset: &Asset) -> &str {
    match asset.container {
        Container::Gltf => asset.json_text.as_str(),
        Container::Glb => asset.json_text.trim_end_matches(['\0', ' ']),
    }
}

/// The file's bytes for JSON `text`: the text itself, or a GLB with `bin`.
fn in_container(asset: &Asset, text: Vec<u8>, bin: Option<&[u8]>) -> Vec<u8> {
    match asset.container {
        Container::Gltf => text,
        Container::Glb => glb::join_with(&text, bin, &asset.other_chunks),
    }
}

/// The bytes of `asset` with `edits` applied as splices into its loaded text (see
/// [`crate::edit::splice::splice_edits`]), and whether they changed anything; `Ok(None)` for a
/// plan the splicer does not take or a text that does not read back as meant, which the caller
/// then applies to the whole document.
pub fn spliced_bytes<'a, 'e>(
    asset: &'a Asset,
    edits: impl IntoIterator<Item = &'e crate::edit::Edit>,
) -> Result<Option<(Output<'a>, bool)>, crate::edit::EditError> {
    let Some((spliced, changed)) =
        crate::edit::splice::splice_edits(source(asset), asset.root(), edits)?
    else {
        return Ok(None);
    };
    let output = match asset.container {
        Container::Gltf => Output::Spliced(spliced),
        Container::Glb => Output::Bytes(
            glb::join_with(
                spliced.to_text().as_bytes(),
                asset.bin.as_deref(),
                &asset.other_chunks,
            )
            .into(),
        ),
    };
    Ok(Some((output, changed)))
}

/// True when an edit left the document as loaded, so the input's bytes can stand as they are.
pub fn unchanged(asset: &Asset, json: &Value, bin: Option<&[u8]>) -> bool {
    asset.json() == json && asset.bin.as_deref() == bin
}

/// An output file's bytes: whole, or the text of a .gltf written as splices into its loaded
/// text, written piece by piece (see [`crate::edit::splice::Spliced`]).
#[derive(Debug)]
pub enum Output<'t> {
    Bytes(std::borrow::Cow<'t, [u8]>),
    Spliced(crate::edit::splice::Spliced<'t>),
}

impl Output<'_> {
    /// The bytes in order, a run at a time.
    fn pieces(&self) -> Box<dyn Iterator<Item = &[u8]> + '_> {
        match self {
            Output::Bytes(bytes) => Box::new(std::iter::once(bytes.as_ref())),
            Output::Spliced(spliced) => Box::new(spliced.pieces()),
        }
    }

    pub fn len(&self) -> usize {
        match self {
            Output::Bytes(bytes) => bytes.len(),
            Output::Spliced(spliced) => spliced.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Writes `bytes` to `path` atomically: into a temporary file in the same folder, flushed to
/// disk, then renamed over `path`. On any failure the temporary file is removed and `path` is
/// as it was.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_output_atomic(path, &Output::Bytes(bytes.into()))
}

/// Writes `output` to `path` atomically, as [`write_atomic`] writes bytes.
pub fn write_output_atomic(path: &Path, output: &Output) -> io::Result<()> {
    stage_output(path, output)?.put_in_place()
}

/// A complete file written under a temporary name in its target's folder, flushed to disk,
/// waiting to be renamed into place ([`Staged::put_in_place`]). Dropped without that, it is
/// removed. Its name, `.velvet-PID-*.tmp`, carries the writing process's id, so that the next
/// run into the folder removes it when that process is gone ([`remove_leftovers`]): a kill
/// or a power cut leaves nothing that lasts.
#[derive(Debug)]
pub struct Staged {
    tmp: tempfile::NamedTempFile,
    to: std::path::PathBuf,
}

impl Staged {
    /// Where the file goes.
    pub fn target(&self) -> &Path {
        &self.to
    }

    /// Renames the file into place, over whatever was there.
    pub fn put_in_place(self) -> io::Result<()> {
        self.tmp.persist(&self.to).map_err(|e| e.error)?;
        Ok(())
    }
}

/// An error when a file at `path` is read-only (no write permission for anyone): renaming
/// over it would succeed where the folder is writable, and overwrite what its owner protected.
fn refuse_read_only(path: &Path) -> io::Result<()> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() && meta.permissions().readonly() => Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only; velvet does not replace it (make it writable to let it)",
        )),
        _ => Ok(()),
    }
}

/// The folder a file at `path` is written in.
fn folder(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Writes `output` to a temporary file next to `path`, flushed to disk, with the mode of the
/// file it will replace (or the umask's), to be put in place later.
pub fn stage_output(path: &Path, output: &Output) -> io::Result<Staged> {
    refuse_read_only(path)?;
    let tmp = temporary_in(folder(path))?;
    write_temporary(&mut HandedOn::new(tmp.as_file()), output)?;
    tmp.as_file().sync_all()?;
    if let Ok(meta) = std::fs::metadata(path) {
        // Keep the permissions of a file being replaced.
        let _ = std::fs::set_permissions(tmp.path(), meta.permissions());
    }
    Ok(Staged {
        tmp,
        to: path.to_path_buf(),
    })
}

/// How [`copy_atomic`] placed a file. Either way the output is a file of its own (another
/// inode): a tool that edits an output in place never edits the input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placed {
    /// A copy-on-write clone of the source (a reflink, where the filesystem has them: Btrfs,
    /// XFS, bcachefs…): no bytes copied, and a write to either file leaves the other as it was.
    Cloned,
    /// A copy of the bytes.
    Copied,
}

/// Places a regular file holding `from`'s bytes at `to`, atomically: see [`stage_copy`].
pub fn copy_atomic(from: &Path, to: &Path) -> io::Result<Placed> {
    let (staged, placed) = stage_copy(from, to)?;
    staged.put_in_place()?;
    Ok(placed)
}

/// A copy of `from` staged for `to`: a temporary file in `to`'s folder gets a copy-on-write
/// clone of `from` where the filesystem can make one, else an ordinary copy, and is flushed to
/// disk. Never a hard link: an output's resource sharing the input's inode would let an edit
/// of the output change the input.
pub fn stage_copy(from: &Path, to: &Path) -> io::Result<(Staged, Placed)> {
    refuse_read_only(to)?;
    let mut source = std::fs::File::open(from)?;
    if injected_fault().is_some() {
        // The fault seam covers the bytes' write, as it does every other output's.
        let mut bytes = Vec::new();
        io::Read::read_to_end(&mut source, &mut bytes)?;
        let staged = stage_output(to, &Output::Bytes(bytes.into()))?;
        return Ok((staged, Placed::Copied));
    }
    let tmp = temporary_in(folder(to))?;
    let placed = if clone_file(&source, tmp.as_file()) {
        Placed::Cloned
    } else {
        // std's copy between files uses copy_file_range(2) on Linux, in the kernel.
        io::copy(&mut source, &mut tmp.as_file())?;
        Placed::Copied
    };
    tmp.as_file().sync_all()?;
    Ok((
        Staged {
            tmp,
            to: to.to_path_buf(),
        },
        placed,
    ))
}

/// The name prefix of this process's temporary files: `.velvet-PID-`.
fn temporary_prefix() -> String {
    format!(".velvet-{}-", std::process::id())
}

/// Removes from `dir` the temporary files (`.velvet-PID-*.tmp`) of velvet processes that are
/// no longer running: what a killed run, a crash or a power cut left. A file of a process
/// still running (another run into the same folder) is left alone. Returns how many were
/// removed.
pub fn remove_leftovers(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.filter_map(Result::ok) {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(leftover_pid) else {
            continue;
        };
        if pid != std::process::id() && !process_running(pid) {
            removed += usize::from(std::fs::remove_file(entry.path()).is_ok());
        }
    }
    removed
}

/// The process id in a temporary file's name `.velvet-PID-*.tmp`.
fn leftover_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(".velvet-")?.strip_suffix(".tmp")?;
    let (pid, _) = rest.split_once('-')?;
    pid.parse().ok()
}

/// Whether a process with id `pid` runs (or may: where that cannot be told, yes).
fn process_running(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(pid) = libc::pid_t::try_from(pid) else {
            return true;
        };
        // SAFETY: kill with signal 0 sends nothing; it only checks that the process exists.
        let alive = unsafe { libc::kill(pid, 0) } == 0;
        alive || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// A new temporary file in `dir`, named `.velvet-PID-*.tmp`, asking for mode 0666 (the umask trims
/// it, as it does any program's new file; tempfile's default is 0600).
fn temporary_in(dir: &Path) -> io::Result<tempfile::NamedTempFile> {
    let prefix = temporary_prefix();
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

/// Makes `to` a copy-on-write clone of `from` (FICLONE); false where the filesystem cannot.
#[cfg(target_os = "linux")]
fn clone_file(from: &std::fs::File, to: &std::fs::File) -> bool {
    use std::os::fd::AsRawFd;
    // SAFETY: FICLONE takes the source's descriptor as its argument; both are open files.
    unsafe { libc::ioctl(to.as_raw_fd(), libc::FICLONE, from.as_raw_fd()) == 0 }
}

#[cfg(not(target_os = "linux"))]
fn clone_file(_: &std::fs::File, _: &std::fs::File) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_handed_on_as_it_is_written_holds_every_byte_in_order() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.bin");
        let file = std::fs::File::create(&path).unwrap();
        let mut out = HandedOn::new(&file);
        // Past two hand-ons, in single writes and in vectored ones, pieces of every size.
        let pieces: Vec<Vec<u8>> = (0..6000u32)
            .map(|i| (0..(i % 1500)).map(|j| (i + j) as u8).collect())
            .collect();
        let (first, rest) = pieces.split_at(1000);
        for piece in first {
            out.write_all(piece).unwrap();
        }
        write_pieces(&mut out, rest.iter().map(Vec::as_slice)).unwrap();
        out.flush().unwrap();
        let expected: Vec<u8> = pieces.concat();
        assert!(expected.len() as u64 > 2 * HandedOn::EVERY);
        assert_eq!(out.written, expected.len() as u64);
        assert!(out.written - out.handed_on < HandedOn::EVERY);
        assert!(out.handed_on >= 2 * HandedOn::EVERY);
        file.sync_all().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), expected);
    }

    #[cfg(unix)]
    #[test]
    fn new_outputs_follow_the_umask_and_replaced_files_keep_their_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let new = dir.path().join("new.gltf");
        write_atomic(&new, b"{}").unwrap();
        // The umask is the process's; read it back through a file made the ordinary way.
        let plain = dir.path().join("plain");
        std::fs::write(&plain, b"").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&new), mode(&plain));
        let kept = dir.path().join("kept.gltf");
        std::fs::write(&kept, b"old").unwrap();
        std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&kept, b"new").unwrap();
        assert_eq!(mode(&kept), 0o640);
        assert_eq!(std::fs::read(&kept).unwrap(), b"new");
    }

    #[test]
    fn style_is_detected_and_reproduced() {
        let pretty = "{\n    \"a\": [\n        1.0\n    ]\n}\n";
        let style = JsonStyle::detect(pretty);
        assert_eq!(
            style,
            JsonStyle {
                indent: Some("    ".into()),
                trailing_newline: true
            }
        );
        let v: Value = serde_json::from_str(pretty).unwrap();
        assert_eq!(style.render(&v), pretty.as_bytes());
        let minified = r#"{"b":1e-5,"a":0.50}"#;
        let v: Value = serde_json::from_str(minified).unwrap();
        assert_eq!(
            JsonStyle::detect(minified).render(&v),
            minified.as_bytes(),
            "numbers and key order kept"
        );
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.gltf");
        write_atomic(&target, b"first").unwrap();
        write_atomic(&target, b"second").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out.gltf")]);
    }

    #[test]
    fn copies_are_regular_files_holding_the_source_and_replace_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let from = dir.path().join("from.bin");
        std::fs::write(&from, b"resource").unwrap();
        let to = dir.path().join("to.bin");
        std::fs::write(&to, b"old").unwrap();
        copy_atomic(&from, &to).unwrap();
        assert_eq!(std::fs::read(&to).unwrap(), b"resource");
        assert!(std::fs::symlink_metadata(&to)
            .unwrap()
            .file_type()
            .is_file());
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(names, ["from.bin", "to.bin"], "no temporary name is left");
        // Again, onto the copy made the first time: still no temporary name left.
        copy_atomic(&from, &to).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        // A copy is a file of its own: writing into it leaves the source as it was.
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let inode = |p: &Path| std::fs::metadata(p).unwrap().ino();
            assert_ne!(inode(&from), inode(&to));
        }
        std::fs::OpenOptions::new()
            .write(true)
            .open(&to)
            .and_then(|mut f| f.write_all(b"EDITED"))
            .unwrap();
        assert_eq!(std::fs::read(&from).unwrap(), b"resource");
    }

    #[test]
    fn leftovers_of_processes_gone_are_removed_and_others_kept() {
        let dir = tempfile::tempdir().unwrap();
        // A process id no process holds: above the kernel's largest (2^22).
        let gone = dir.path().join(".velvet-99999999-abc.tmp");
        let mine = dir
            .path()
            .join(format!(".velvet-{}-abc.tmp", std::process::id()));
        // The parent process (the test harness's caller) runs.
        #[cfg(unix)]
        let running = dir.path().join(format!(
            ".velvet-{}-abc.tmp",
            std::os::unix::process::parent_id()
        ));
        let other = dir.path().join("velvet-99999999-abc.tmp");
        for path in [&gone, &mine, &other] {
            std::fs::write(path, b"x").unwrap();
        }
        #[cfg(unix)]
        std::fs::write(&running, b"x").unwrap();
        assert_eq!(remove_leftovers(dir.path()), 1);
        assert!(!gone.exists());
        assert!(mine.exists() && other.exists());
        #[cfg(unix)]
        assert!(running.exists());
    }

    #[test]
    fn a_staged_file_dropped_before_it_is_put_in_place_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.png");
        let staged = stage_output(&target, &Output::Bytes(b"png".as_slice().into())).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        assert!(!target.exists());
        drop(staged);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let staged = stage_output(&target, &Output::Bytes(b"png".as_slice().into())).unwrap();
        staged.put_in_place().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"png");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn atomic_write_into_missing_folder_fails_without_output() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("missing").join("out.gltf");
        assert!(write_atomic(&target, b"x").is_err());
        assert!(!target.exists());
    }

    /// A writer that takes at most `bytes` bytes from at most `slices` slices a call, and
    /// counts its calls: the short writes a file or pipe may make.
    struct Trickle {
        got: Vec<u8>,
        bytes: usize,
        slices: usize,
        calls: usize,
    }

    impl Trickle {
        fn new(bytes: usize, slices: usize) -> Trickle {
            Trickle {
                got: Vec::new(),
                bytes,
                slices,
                calls: 0,
            }
        }
    }

    impl Write for Trickle {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            self.write_vectored(&[io::IoSlice::new(buf)])
        }

        fn write_vectored(&mut self, bufs: &[io::IoSlice<'_>]) -> io::Result<usize> {
            self.calls += 1;
            let mut taken = 0;
            for buf in bufs.iter().take(self.slices) {
                let n = buf.len().min(self.bytes - taken);
                self.got.extend_from_slice(&buf[..n]);
                taken += n;
                if n < buf.len() {
                    break;
                }
            }
            Ok(taken)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    /// 3,000 pieces (more than two batches of `PIECES_PER_WRITE`), every third one empty.
    fn pieces() -> Vec<Vec<u8>> {
        (0..3000u32)
            .map(|i| match i % 3 {
                0 => Vec::new(),
                _ => format!("{i},").into_bytes(),
            })
            .collect()
    }

    #[test]
    fn pieces_are_written_whole_and_in_order_through_short_writes() {
        let pieces = pieces();
        let mut short = Trickle::new(5, 2);
        write_pieces(&mut short, pieces.iter().map(Vec::as_slice)).unwrap();
        assert_eq!(short.got, pieces.concat());
    }

    #[test]
    fn pieces_go_out_a_batch_a_call() {
        let pieces = pieces();
        let mut file = Trickle::new(usize::MAX, usize::MAX);
        write_pieces(&mut file, pieces.iter().map(Vec::as_slice)).unwrap();
        assert_eq!(file.got, pieces.concat());
        // 2,000 non-empty pieces, 1,024 a call.
        assert_eq!(file.calls, 2);
    }
}
