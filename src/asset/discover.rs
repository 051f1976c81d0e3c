//! Finding the assets to work on, for `validate`, `migrate` and `bake` alike.
//!
//! - Files named on the command line are taken as they are; folders are walked recursively for
//!   `*.gltf` and `*.glb` (case-insensitive), in sorted order, without following links to
//!   folders (so a link loop cannot hang a run). A link named like an asset whose target is
//!   missing is kept, so that the loader reports it rather than the run skipping it in silence;
//!   so is a file that vanishes between the walk and its loading.
//! - [`check_inputs`] refuses, before anything is read, a path that does not exist and a folder
//!   with no asset in it or below: a typo or an emptied folder in a CI command must not pass as
//!   "0 files checked".
//! - [`absolute`] and [`display_path`]: how velvet names a file for matching (absolute, without
//!   resolving links) and in reports (relative to the working folder, forward slashes).
//! - [`read_list`] reads `--files-from`: paths one per line or NUL-separated (told apart by the
//!   presence of a NUL byte), so that `git diff --name-only -z` output can be fed as it is.
//! - [`Shard`] splits the files found into N parts for N independent CI jobs. The split is a
//!   function of the files alone (each file's path relative to the argument it was found under,
//!   and its size), never of the machine, the working directory or the order of discovery, so
//!   N jobs over one checkout together see every file exactly once. It balances bytes: files
//!   are taken largest first and each goes to the shard with the least work so far (the
//!   longest-processing-time rule), so no shard carries more than the lightest one plus the
//!   largest file.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::fmt;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};
use std::str::FromStr;

/// True for a path whose extension is .gltf or .glb.
pub fn is_asset_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// A folder that could not be walked, with its error.
pub type WalkError = (PathBuf, io::Error);

/// A file found, with the index of the input (command-line argument) it was found under.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found {
    pub path: PathBuf,
    pub input: usize,
}

/// The asset files under `inputs`. Folders that cannot be read are returned with their error.
pub fn collect(inputs: &[PathBuf]) -> (Vec<PathBuf>, Vec<WalkError>) {
    let (found, errors) = find(inputs, None);
    (found.into_iter().map(|f| f.path).collect(), errors)
}

/// The asset files under `inputs`, each with the input it was found under, in input order;
/// with a shard, only that shard's files (still in input order). Folders that cannot be read
/// are returned with their error; with a shard, only shard 1 returns them, so that N shards
/// report each such folder once between them.
pub fn find(inputs: &[PathBuf], shard: Option<Shard>) -> (Vec<Found>, Vec<WalkError>) {
    let mut files = Vec::new();
    let mut errors = Vec::new();
    for (index, input) in inputs.iter().enumerate() {
        if input.is_dir() {
            let mut paths = Vec::new();
            walk(input, &mut paths, &mut errors);
            files.extend(paths.into_iter().map(|path| Found { path, input: index }));
        } else {
            // A named file is taken whatever its name; a missing one is reported by the loader.
            files.push(Found {
                path: input.clone(),
                input: index,
            });
        }
    }
    match shard {
        None => (files, errors),
        Some(shard) => {
            let keep = shard.select(inputs, &files);
            let files = files
                .into_iter()
                .zip(keep)
                .filter_map(|(f, k)| k.then_some(f))
                .collect();
            if shard.index != 1 {
                errors.clear();
            }
            (files, errors)
        }
    }
}

fn walk(dir: &Path, files: &mut Vec<PathBuf>, errors: &mut Vec<WalkError>) {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) => {
            errors.push((dir.to_path_buf(), e));
            return;
        }
    };
    // Each entry with its type as the listing gives it (no look at the entry itself where the
    // file system says: a folder of 500 assets took 500 more system calls).
    let mut paths: Vec<(PathBuf, Option<std::fs::FileType>)> = entries
        .filter_map(|e| e.ok().map(|e| (e.path(), e.file_type().ok())))
        .collect();
    paths.sort_by(|a, b| a.0.cmp(&b.0));
    for (path, listed) in paths {
        let kind = match listed {
            Some(kind) => kind,
            None => match std::fs::symlink_metadata(&path) {
                Ok(meta) => meta.file_type(),
                // Gone between the listing and now: nothing to report.
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                // An entry that cannot be looked at (a path longer than the system allows, a
                // permission): reported, never skipped in silence.
                Err(e) => {
                    errors.push((path, e));
                    continue;
                }
            },
        };
        if kind.is_dir() {
            walk(&path, files, errors);
        } else if is_asset(&path, kind) {
            files.push(path);
        }
    }
}

/// A walked entry that is an asset: named like one, and a file or a link to one (or to nothing).
fn is_asset(path: &Path, kind: std::fs::FileType) -> bool {
    is_asset_path(path)
        && (kind.is_file()
            || (kind.is_symlink() && std::fs::metadata(path).map_or(true, |m| m.is_file())))
}

/// True when `dir` holds an asset or a folder that cannot be read (whose error a run
/// reports); stops at the first one.
fn has_asset(dir: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return true;
    };
    let mut folders = Vec::new();
    for entry in entries.filter_map(Result::ok) {
        let path = entry.path();
        let meta = match std::fs::symlink_metadata(&path) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
            // Reported by the walk (see `walk`).
            Err(_) => return true,
        };
        if meta.is_dir() {
            folders.push(path);
        } else if is_asset(&path, meta.file_type()) {
            return true;
        }
    }
    folders.iter().any(|f| has_asset(f))
}

/// An input that makes the request unusable (exit status 2): nothing was read or written.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    #[error("{}: no such file or folder", .0.display())]
    Missing(PathBuf),
    #[error("{}: no .gltf or .glb file in this folder or below", .0.display())]
    NoAssets(PathBuf),
    #[error("{}: not a regular file or folder ({kind}); velvet reads assets from files", .path.display())]
    NotAFile { path: PathBuf, kind: &'static str },
    #[error("--files-from {}: {source}", .list.display())]
    ListUnreadable { list: PathBuf, source: io::Error },
    #[error("--files-from {}: {path} (entry {entry}) does not exist", .list.display())]
    ListedMissing {
        list: PathBuf,
        path: String,
        entry: usize,
    },
    #[error("--files-from {}: entry {entry} is not a valid path on this system", .list.display())]
    ListedNotAPath { list: PathBuf, entry: usize },
    #[error("--files-from {}: the list is longer than {} bytes; velvet reads no further (split it, or name folders)", .list.display(), MAX_LIST_BYTES)]
    ListTooLong { list: PathBuf },
    #[error("--files-from {}: a FIFO no program is writing into; velvet does not wait for one (write the list to a file, or pipe it to --files-from -)", .list.display())]
    ListWithoutWriter { list: PathBuf },
}

/// The paths named on the command line and in a `--files-from` list (`-`: standard input),
/// checked: a path that does not exist, or a folder without any asset, is an error.
pub fn resolve(paths: &[PathBuf], files_from: Option<&Path>) -> Result<Vec<PathBuf>, InputError> {
    let mut paths = paths.to_vec();
    if let Some(list) = files_from {
        paths.extend(read_list(list)?);
    }
    check_inputs(&paths)?;
    Ok(paths)
}

/// Refuses a path that does not exist, one that is neither a regular file nor a folder (a FIFO
/// would block the run until something writes to it, a device would be read without end), and
/// a folder with no asset in it or below. A link named on the command line is taken even when
/// it dangles: the loader reports that file.
pub fn check_inputs(inputs: &[PathBuf]) -> Result<(), InputError> {
    for input in inputs {
        match std::fs::symlink_metadata(input) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(InputError::Missing(input.clone()))
            }
            _ => {}
        }
        if let Ok(meta) = std::fs::metadata(input) {
            if !meta.is_file() && !meta.is_dir() {
                return Err(InputError::NotAFile {
                    path: input.clone(),
                    kind: file_kind(&meta),
                });
            }
        }
        if input.is_dir() && !has_asset(input) {
            return Err(InputError::NoAssets(input.clone()));
        }
    }
    Ok(())
}

/// Opens `path` for reading without waiting: opening a FIFO blocks until a program opens it for
/// writing, which may be never, so it is opened non-blocking (a regular file or a device reads
/// as before; a FIFO is left non-blocking for [`read_stream_start`]).
pub fn open_without_waiting(path: &Path) -> io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if !file.metadata()?.file_type().is_fifo() {
            set_blocking(&file)?;
        }
    }
    Ok(file)
}

#[cfg(unix)]
fn set_blocking(file: &std::fs::File) -> io::Result<()> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: F_GETFL and F_SETFL on a descriptor this function's caller owns.
    unsafe {
        let flags = libc::fcntl(file.as_raw_fd(), libc::F_GETFL);
        if flags < 0 || libc::fcntl(file.as_raw_fd(), libc::F_SETFL, flags & !libc::O_NONBLOCK) < 0
        {
            return Err(io::Error::last_os_error());
        }
    }
    Ok(())
}

/// For a FIFO opened by [`open_without_waiting`]: whether a program writes into it, its first
/// bytes read into `bytes`, the file then blocking so that the rest is read as it comes. A FIFO
/// no program has open for writing reads as ended at once (false): a list or a configuration
/// that is not there, which velvet refuses rather than take for an empty one. Anything else:
/// true, nothing read.
pub fn read_stream_start(file: &std::fs::File, bytes: &mut Vec<u8>) -> io::Result<bool> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file.metadata()?.file_type().is_fifo() {
            let mut first = [0u8; 4096];
            let start = loop {
                match (&*file).read(&mut first) {
                    Ok(0) => return Ok(false),
                    Ok(n) => break n,
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => break 0,
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                    Err(e) => return Err(e),
                }
            };
            bytes.extend_from_slice(&first[..start]);
            set_blocking(file)?;
        }
    }
    let _ = (file, bytes);
    Ok(true)
}

/// What a file that is neither a regular file nor a folder is, for messages.
pub fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    let _ = meta;
    "a special file"
}

/// The entries of a `--files-from` list: NUL-separated when the bytes hold a NUL, else one per
/// line (a line's trailing `\r` removed). Empty entries are skipped. Each entry comes with its
/// number (1-based) for error messages; `None` is an entry that is not a path on this system.
pub fn parse_list(bytes: &[u8]) -> Vec<(usize, Option<PathBuf>)> {
    let separator = if bytes.contains(&0) { 0 } else { b'\n' };
    bytes
        .split(|b| *b == separator)
        .map(|entry| match separator {
            b'\n' => entry.strip_suffix(b"\r").unwrap_or(entry),
            _ => entry,
        })
        .filter(|entry| !entry.is_empty())
        .enumerate()
        .map(|(i, entry)| (i + 1, path_from_bytes(entry)))
        .collect()
}

#[cfg(unix)]
fn path_from_bytes(bytes: &[u8]) -> Option<PathBuf> {
    use std::os::unix::ffi::OsStrExt;
    Some(PathBuf::from(std::ffi::OsStr::from_bytes(bytes)))
}

#[cfg(not(unix))]
fn path_from_bytes(bytes: &[u8]) -> Option<PathBuf> {
    std::str::from_utf8(bytes).ok().map(PathBuf::from)
}

/// The longest `--files-from` list velvet reads: 64 MiB, some 500,000 paths of 130 bytes.
pub const MAX_LIST_BYTES: u64 = 64 << 20;

/// Reads a `--files-from` list (`-`: standard input) and returns the inputs it names: folders
/// (walked as on the command line) and `.gltf`/`.glb` files. Other entries are skipped, so the
/// output of `git diff --name-only` or `find` can be fed as it is; a listed folder or asset
/// that does not exist is an error naming it.
pub fn read_list(list: &Path) -> Result<Vec<PathBuf>, InputError> {
    let unreadable = |source| InputError::ListUnreadable {
        list: list.to_path_buf(),
        source,
    };
    // Read no further than the limit: `--files-from /dev/zero` costs an error, not memory.
    let mut bytes = Vec::new();
    if list == Path::new("-") {
        io::stdin()
            .lock()
            .take(MAX_LIST_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(unreadable)?;
    } else {
        let file = open_without_waiting(list).map_err(unreadable)?;
        if !read_stream_start(&file, &mut bytes).map_err(unreadable)? {
            return Err(InputError::ListWithoutWriter {
                list: list.to_path_buf(),
            });
        }
        file.take(MAX_LIST_BYTES + 1 - bytes.len() as u64)
            .read_to_end(&mut bytes)
            .map_err(unreadable)?;
    }
    if bytes.len() as u64 > MAX_LIST_BYTES {
        return Err(InputError::ListTooLong {
            list: list.to_path_buf(),
        });
    }
    let mut inputs = Vec::new();
    for (entry, path) in parse_list(&bytes) {
        let Some(path) = path else {
            return Err(InputError::ListedNotAPath {
                list: list.to_path_buf(),
                entry,
            });
        };
        let exists = std::fs::symlink_metadata(&path).is_ok();
        if path.is_dir() {
            inputs.push(path);
        } else if is_asset_path(&path) {
            if !exists {
                return Err(InputError::ListedMissing {
                    list: list.to_path_buf(),
                    path: path.display().to_string(),
                    entry,
                });
            }
            inputs.push(path);
        }
    }
    Ok(inputs)
}

/// Shard K of N (K from 1), as `--shard K/N` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// K, from 1 to `count`.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(text: &str) -> Result<Shard, String> {
        let usage = || format!("{text}: expected K/N with 1 <= K <= N, e.g. 2/4");
        let (k, n) = text.split_once('/').ok_or_else(usage)?;
        let index: usize = k.trim().parse().map_err(|_| usage())?;
        let count: usize = n.trim().parse().map_err(|_| usage())?;
        if count == 0 || index == 0 || index > count {
            return Err(usage());
        }
        Ok(Shard { index, count })
    }
}

/// Work a file adds besides its bytes (opening it, setting up its report), in bytes: it keeps
/// shards of many small files balanced by count.
const FILE_COST: u64 = 4096;

/// The name a file is sharded by: its path relative to the folder argument it was found under
/// (a named file: its path as given), with `.` components dropped and `/` between components.
/// It is the same on every machine and from every working directory that names the same
/// folders.
pub fn shard_key(input: &Path, file: &Path) -> String {
    let relative = match file.strip_prefix(input) {
        Ok(r) if !r.as_os_str().is_empty() => r,
        _ => file,
    };
    let mut parts: Vec<String> = Vec::new();
    for c in relative.components() {
        match c {
            Component::CurDir => {}
            Component::RootDir => parts.push(String::new()),
            other => parts.push(other.as_os_str().to_string_lossy().into_owned()),
        }
    }
    parts.join("/")
}

impl Shard {
    /// Which of `files` (found under `inputs`) belong to this shard, one flag per file.
    pub fn select(&self, inputs: &[PathBuf], files: &[Found]) -> Vec<bool> {
        let items: Vec<(String, usize, u64)> = files
            .iter()
            .map(|f| {
                let input = inputs
                    .get(f.input)
                    .map(PathBuf::as_path)
                    .unwrap_or(Path::new(""));
                let size = std::fs::metadata(&f.path).map_or(0, |m| m.len());
                (shard_key(input, &f.path), f.input, size + FILE_COST)
            })
            .collect();
        assign(&items, self.count)
            .into_iter()
            .map(|s| s + 1 == self.index)
            .collect()
    }
}

/// Assigns each item (key, input index, weight) to one of `count` shards (0-based), by the
/// longest-processing-time rule: heaviest first (ties by key, then input index), each to the
/// shard with the least weight so far (ties to the lowest shard). The result depends on the
/// items' values only, not on their order.
pub fn assign(items: &[(String, usize, u64)], count: usize) -> Vec<usize> {
    let count = count.max(1);
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by(|&a, &b| {
        let (ka, ia, wa) = &items[a];
        let (kb, ib, wb) = &items[b];
        wb.cmp(wa).then_with(|| ka.cmp(kb)).then_with(|| ia.cmp(ib))
    });
    let mut loads: BinaryHeap<Reverse<(u64, usize)>> =
        (0..count).map(|s| Reverse((0, s))).collect();
    let mut shard_of = vec![0; items.len()];
    for i in order {
        let Some(Reverse((load, shard))) = loads.pop() else {
            break;
        };
        shard_of[i] = shard;
        loads.push(Reverse((load + items[i].2, shard)));
    }
    shard_of
}

/// `path` made absolute without touching the file system (links are not resolved, so the
/// folders walked are those the user sees).
pub fn absolute(path: &Path) -> PathBuf {
    let path = if path.as_os_str().is_empty() {
        Path::new(".")
    } else {
        path
    };
    let abs = if cfg!(unix) && path.is_relative() {
        // The working folder asked once per run, not once per path: velvet never changes it.
        match working_folder() {
            Some(cwd) => cwd.join(path),
            None => path.to_path_buf(),
        }
    } else {
        std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
    };
    // Drop `.` components and fold `..` where it is lexically safe.
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                if !out.pop() {
                    out.push(c);
                }
            }
            other => out.push(other),
        }
    }
    out
}

/// The working folder, asked of the system once per run (velvet never changes it).
pub fn working_folder() -> Option<&'static Path> {
    static FOLDER: std::sync::OnceLock<Option<PathBuf>> = std::sync::OnceLock::new();
    FOLDER
        .get_or_init(|| std::env::current_dir().ok())
        .as_deref()
}

/// A path as reports show it: relative to the working directory when it lies below it, with
/// forward slashes.
pub fn display_path(path: &Path) -> String {
    let shown = working_folder()
        .and_then(|cwd| path.strip_prefix(cwd).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| path.to_path_buf());
    shown.to_string_lossy().replace('\\', "/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_parses_k_of_n_and_refuses_the_rest() {
        assert_eq!("2/4".parse(), Ok(Shard { index: 2, count: 4 }));
        assert_eq!("1/1".parse(), Ok(Shard { index: 1, count: 1 }));
        for bad in ["0/4", "5/4", "1/0", "4", "a/b", "-1/4", ""] {
            assert_eq!(
                bad.parse::<Shard>(),
                Err(format!("{bad}: expected K/N with 1 <= K <= N, e.g. 2/4")),
                "{bad}"
            );
        }
    }

    #[test]
    fn shard_keys_are_relative_to_the_argument_and_use_slashes() {
        assert_eq!(
            shard_key(Path::new("assets"), Path::new("assets/a/b.gltf")),
            "a/b.gltf"
        );
        assert_eq!(
            shard_key(
                Path::new("/ci/x/assets"),
                Path::new("/ci/x/assets/a/b.gltf")
            ),
            "a/b.gltf"
        );
        assert_eq!(
            shard_key(Path::new("./assets"), Path::new("./assets/b.glb")),
            "b.glb"
        );
        assert_eq!(
            shard_key(Path::new("./a/b.gltf"), Path::new("./a/b.gltf")),
            "a/b.gltf"
        );
        assert_eq!(
            shard_key(Path::new("/a/b.gltf"), Path::new("/a/b.gltf")),
            "/a/b.gltf"
        );
    }

    fn items(weights: &[u64]) -> Vec<(String, usize, u64)> {
        weights
            .iter()
            .enumerate()
            .map(|(i, w)| (format!("f{i:03}.gltf"), 0, *w))
            .collect()
    }

    #[test]
    fn assignment_balances_weight_and_ignores_item_order() {
        let weights = [900, 10, 10, 400, 500, 10, 10, 10, 300, 200, 100, 90];
        let all = items(&weights);
        let shards = assign(&all, 3);
        let mut loads = [0u64; 3];
        for (i, s) in shards.iter().enumerate() {
            loads[*s] += weights[i];
        }
        // Largest first: 900 | 500 | 400; 300 → the third (700), 200 → the second (700),
        // 100 → the second (800), 90 → the third (790), the five 10s two and three apiece.
        assert_eq!(loads, [900, 820, 820]);
        let (max, min) = (loads.iter().max().unwrap(), loads.iter().min().unwrap());
        assert!(max - min <= 900);
        // The same items in reverse order land in the same shards.
        let mut reversed = all.clone();
        reversed.reverse();
        let again = assign(&reversed, 3);
        for (i, s) in again.iter().enumerate() {
            assert_eq!(*s, shards[all.len() - 1 - i]);
        }
    }

    #[test]
    fn equal_files_go_round_the_shards_by_name() {
        let shards = assign(&items(&[5; 7]), 3);
        assert_eq!(shards, [0, 1, 2, 0, 1, 2, 0]);
        assert_eq!(assign(&items(&[5; 2]), 4), [0, 1]);
        assert_eq!(assign(&[], 4), Vec::<usize>::new());
    }

    #[test]
    fn lists_split_on_nul_when_there_is_one_else_on_lines() {
        let paths = |bytes: &[u8]| -> Vec<String> {
            parse_list(bytes)
                .into_iter()
                .map(|(_, p)| p.unwrap().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(
            paths(b"a.gltf\r\nb c.glb\n\nd.gltf"),
            ["a.gltf", "b c.glb", "d.gltf"]
        );
        assert_eq!(
            paths(b"a\nb.gltf\0c d.glb\0\0"),
            ["a\nb.gltf", "c d.glb"],
            "a NUL anywhere makes newlines part of names"
        );
        assert!(parse_list(b"").is_empty());
        assert_eq!(
            parse_list(b"\n\nx.gltf\n")
                .iter()
                .map(|e| e.0)
                .collect::<Vec<_>>(),
            [1],
            "entries are numbered without the empty ones"
        );
    }
}
