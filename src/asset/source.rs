//! A file's bytes as velvet holds them, and the JSON text made of them: read into memory, or,
//! for a large regular file, mapped from the system's file cache.
//!
//! Why map: on the virtual machines velvet is measured on, the first touch of fresh memory a
//! few seconds after other programs freed it is slow, as where the host takes back the memory
//! its guest frees (a balloon driver's free-page reporting) and faults it in again page by
//! page: reading a 10.7 MB document into a new buffer took 43–55 ms there, where mapping the
//! file, whose pages the file cache holds already, took 3 ms (and 3–4 ms against 1.5 when the
//! memory was warm). The bytes are the same either way.
//!
//! A mapping reads the file as it is on disk while velvet runs. Another program that shortens
//! the file meanwhile makes a read past its new end fault (SIGBUS); [`enable_mapping`]
//! installs a handler that names the file, says what happened and ends the process with status
//! 1, where the default would be a crash. Files are mapped only once that handler is in place,
//! and only where it can name them (up to [`MAPPED_AT_ONCE`] at once; the rest are read).
//! velvet's own writes never change a file it maps: every output is a new file renamed into
//! place.

use std::fmt;
use std::fs::File;
use std::ops::Deref;
use std::path::Path;

/// Regular files from this size (bytes) are mapped once [`enable_mapping`] was called; smaller
/// ones are read (a mapping costs two system calls more than a read, and a small file little
/// fresh memory).
pub const MAPPED_FROM: u64 = 1 << 20;

/// How many files can be mapped at the same time; a file beyond that is read.
pub const MAPPED_AT_ONCE: usize = 64;

/// A file's bytes: read into memory, or mapped.
pub struct FileBytes(Held);

enum Held {
    Read(Vec<u8>),
    Mapped(Mapped),
}

impl FileBytes {
    /// Bytes already in memory.
    pub fn from_vec(bytes: Vec<u8>) -> FileBytes {
        FileBytes(Held::Read(bytes))
    }

    /// Whether the bytes are a mapping of the file (see the module comment).
    pub fn is_mapped(&self) -> bool {
        matches!(self.0, Held::Mapped(_))
    }

    /// Maps `file`, a regular file that `path` names and whose length is `size`, when mapping
    /// is enabled, `size` is at least [`MAPPED_FROM`] and a slot is free to name the file
    /// should it shrink; `None` otherwise (the caller reads it).
    pub fn map(file: &File, path: &Path, size: u64) -> Option<FileBytes> {
        if size < MAPPED_FROM || !mapping::enabled() {
            return None;
        }
        mapping::map(file, path).map(|m| FileBytes(Held::Mapped(m)))
    }
}

impl Deref for FileBytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match &self.0 {
            Held::Read(bytes) => bytes,
            Held::Mapped(mapped) => mapped.bytes(),
        }
    }
}

impl fmt::Debug for FileBytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let how = if self.is_mapped() { "mapped" } else { "read" };
        write!(f, "FileBytes({} bytes, {how})", self.len())
    }
}

/// A document's JSON text: UTF-8, held as a `String` or as the bytes of its file.
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
        // String). A mapped file's bytes could change after the check only if another program
        // rewrote the file while velvet ran (see the module comment).
        unsafe { std::str::from_utf8_unchecked(&self.0) }
    }

    /// Whether the text is a mapping of its file.
    pub fn is_mapped(&self) -> bool {
        self.0.is_mapped()
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

/// Allows large input files to be mapped (see the module comment), installing the handler that
/// reports a mapped file shortened while it is read. The command-line tool calls it first
/// thing; a program that uses the library and has its own SIGBUS handling need not. Does
/// nothing where there is no SIGBUS (not Unix).
pub fn enable_mapping() {
    mapping::enable();
}

#[cfg(unix)]
mod mapping {
    //! The mappings and the SIGBUS handler. The handler may run on any thread at any moment,
    //! so what it reads is a fixed table of atomics (no lock, no allocation): each slot holds
    //! a mapping's address range and a pointer to its file's name, which the mapping owns.

    use std::fs::File;
    use std::path::Path;
    use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
    use std::sync::Once;

    static ENABLED: AtomicBool = AtomicBool::new(false);
    static INSTALL: Once = Once::new();

    struct Slot {
        taken: AtomicBool,
        /// The mapping's first address, 0 while the slot names none.
        start: AtomicUsize,
        len: AtomicUsize,
        name: AtomicPtr<u8>,
        name_len: AtomicUsize,
    }

    #[allow(clippy::declare_interior_mutable_const)]
    const FREE: Slot = Slot {
        taken: AtomicBool::new(false),
        start: AtomicUsize::new(0),
        len: AtomicUsize::new(0),
        name: AtomicPtr::new(std::ptr::null_mut()),
        name_len: AtomicUsize::new(0),
    };

    static SLOTS: [Slot; super::MAPPED_AT_ONCE] = [FREE; super::MAPPED_AT_ONCE];

    pub fn enabled() -> bool {
        ENABLED.load(Ordering::Acquire)
    }

    /// The SIGBUS handler there was before velvet's (the Rust runtime's, which reports a
    /// stack overflow where a system signals one with SIGBUS), and its flags: a fault outside
    /// the mapped files is passed on to it.
    static PREVIOUS_HANDLER: AtomicUsize = AtomicUsize::new(libc::SIG_DFL);
    static PREVIOUS_FLAGS: AtomicUsize = AtomicUsize::new(0);

    pub fn enable() {
        INSTALL.call_once(|| {
            // SAFETY: sigaction with a zeroed struct, an empty mask and a handler of the
            // SA_SIGINFO shape; the handler reads atomics, writes to stderr and exits, or
            // passes the fault on. The previous action is written to a zeroed struct.
            let installed = unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                let mut previous: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_sigbus as *const () as libc::sighandler_t;
                action.sa_flags = libc::SA_SIGINFO;
                libc::sigemptyset(&mut action.sa_mask);
                let installed = libc::sigaction(libc::SIGBUS, &action, &mut previous) == 0;
                if installed {
                    PREVIOUS_HANDLER.store(previous.sa_sigaction, Ordering::Release);
                    PREVIOUS_FLAGS.store(previous.sa_flags as usize, Ordering::Release);
                }
                installed
            };
            ENABLED.store(installed, Ordering::Release);
        });
    }

    /// A mapped file, named in its slot until it is dropped.
    pub struct Mapped {
        map: memmap2::Mmap,
        slot: usize,
        // Pointed to by the slot; kept here so that it lives as long as the mapping.
        _name: Box<[u8]>,
    }

    impl Mapped {
        pub fn bytes(&self) -> &[u8] {
            &self.map
        }
    }

    pub fn map(file: &File, path: &Path) -> Option<Mapped> {
        let slot = SLOTS.iter().position(|s| {
            s.taken
                .compare_exchange(false, true, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
        })?;
        // SAFETY: a read-only private mapping of a file velvet does not write. Another program
        // changing the file while it is mapped is the risk the module comment describes: its
        // bytes may change under velvet, and a read past a new, shorter end faults, which the
        // handler reports.
        let map = match unsafe { memmap2::MmapOptions::new().populate().map(file) } {
            Ok(map) => map,
            Err(_) => {
                SLOTS[slot].taken.store(false, Ordering::Release);
                return None;
            }
        };
        let mut name: Box<[u8]> = path.display().to_string().into_bytes().into_boxed_slice();
        let s = &SLOTS[slot];
        s.name.store(name.as_mut_ptr(), Ordering::Relaxed);
        s.name_len.store(name.len(), Ordering::Relaxed);
        s.len.store(map.len(), Ordering::Relaxed);
        s.start.store(map.as_ptr() as usize, Ordering::Release);
        Some(Mapped {
            map,
            slot,
            _name: name,
        })
    }

    impl Drop for Mapped {
        fn drop(&mut self) {
            let s = &SLOTS[self.slot];
            s.start.store(0, Ordering::Release);
            s.taken.store(false, Ordering::Release);
        }
    }

    fn write_stderr(bytes: &[u8]) {
        // SAFETY: write(2) is async-signal-safe; the bytes are valid for their length.
        unsafe {
            libc::write(2, bytes.as_ptr().cast(), bytes.len());
        }
    }

    extern "C" fn on_sigbus(
        signal: libc::c_int,
        info: *mut libc::siginfo_t,
        context: *mut libc::c_void,
    ) {
        // SAFETY: the kernel passes a valid siginfo_t to an SA_SIGINFO handler.
        let address = unsafe { (*info).si_addr() } as usize;
        for s in &SLOTS {
            let start = s.start.load(Ordering::Acquire);
            if start == 0 || address < start || address >= start + s.len.load(Ordering::Relaxed) {
                continue;
            }
            let name = s.name.load(Ordering::Relaxed);
            let name_len = s.name_len.load(Ordering::Relaxed);
            write_stderr(b"velvet: ");
            // SAFETY: the slot's mapping is alive (this thread was reading it), and with it
            // the name it points to.
            write_stderr(unsafe { std::slice::from_raw_parts(name, name_len) });
            write_stderr(
                b": the file became shorter while velvet read it (another program changed it); \
                  velvet stopped\n",
            );
            // SAFETY: _exit ends the process without running anything else; it is
            // async-signal-safe.
            unsafe { libc::_exit(1) };
        }
        // Not a mapped file: the fault goes to the handler there was before, or, where there
        // was none, takes its default course (the instruction runs again and the process ends
        // on the signal).
        let previous = PREVIOUS_HANDLER.load(Ordering::Acquire);
        if previous != libc::SIG_DFL && previous != libc::SIG_IGN {
            // SAFETY: `previous` is the handler sigaction reported, of the shape its flags
            // say; it is called as the kernel would have called it.
            unsafe {
                if PREVIOUS_FLAGS.load(Ordering::Acquire) & libc::SA_SIGINFO as usize != 0 {
                    let handler: extern "C" fn(
                        libc::c_int,
                        *mut libc::siginfo_t,
                        *mut libc::c_void,
                    ) = std::mem::transmute(previous);
                    handler(signal, info, context);
                } else {
                    let handler: extern "C" fn(libc::c_int) = std::mem::transmute(previous);
                    handler(signal);
                }
            }
            return;
        }
        // SAFETY: signal(2) with SIG_DFL is async-signal-safe.
        unsafe {
            libc::signal(libc::SIGBUS, libc::SIG_DFL);
        }
    }
}

#[cfg(not(unix))]
mod mapping {
    use std::fs::File;
    use std::path::Path;

    pub struct Mapped(std::convert::Infallible);

    impl Mapped {
        pub fn bytes(&self) -> &[u8] {
            match self.0 {}
        }
    }

    pub fn enabled() -> bool {
        false
    }

    pub fn enable() {}

    pub fn map(_: &File, _: &Path) -> Option<Mapped> {
        None
    }
}

use mapping::Mapped;

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the test named `test` again in a child process with `var` set to `value`: how a
    /// test checks what ends the process. The child's exit status and standard error.
    #[cfg(unix)]
    fn run_as_child(test: &str, var: &str, value: &std::ffi::OsStr) -> (Option<i32>, String) {
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                &format!("asset::source::tests::{test}"),
                "--nocapture",
                "--test-threads=1",
            ])
            .env(var, value)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }

    #[test]
    fn small_files_are_read_not_mapped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("small.gltf");
        std::fs::write(&path, b"{}").unwrap();
        let file = File::open(&path).unwrap();
        enable_mapping();
        assert!(FileBytes::map(&file, &path, 2).is_none());
    }

    #[cfg(unix)]
    #[test]
    fn a_large_file_is_mapped_with_its_bytes_and_frees_its_slot() {
        enable_mapping();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("large.gltf");
        let mut text = String::from("{\"asset\":{\"version\":\"2.0\"},\"extras\":\"");
        text.push_str(&"é".repeat(MAPPED_FROM as usize));
        text.push_str("\"}");
        std::fs::write(&path, &text).unwrap();
        let file = File::open(&path).unwrap();
        let size = file.metadata().unwrap().len();
        let bytes = FileBytes::map(&file, &path, size).expect("mapped");
        assert!(bytes.is_mapped());
        assert_eq!(&bytes[..], text.as_bytes());
        let source = SourceText::from_bytes(bytes).unwrap();
        assert!(source.is_mapped());
        assert_eq!(source.as_str(), text);
        drop(source);
        // Slots are given back: more mappings than there are slots, one after another.
        for _ in 0..MAPPED_AT_ONCE + 4 {
            assert!(FileBytes::map(&file, &path, size).is_some());
        }
    }

    /// A mapped file that another program shortens while velvet reads it ends the process
    /// with status 1 and a message naming the file, not a crash. The test runs itself again
    /// as a child process that maps, shortens and reads the file.
    #[cfg(unix)]
    #[test]
    fn a_mapped_file_shortened_while_read_is_reported_by_name() {
        const CHILD: &str = "VELVET_SHORTENED_FILE";
        if let Some(path) = std::env::var_os(CHILD) {
            let path = std::path::PathBuf::from(path);
            enable_mapping();
            let file = File::open(&path).unwrap();
            let size = file.metadata().unwrap().len();
            let bytes = FileBytes::map(&file, &path, size).expect("mapped");
            std::fs::OpenOptions::new()
                .write(true)
                .open(&path)
                .unwrap()
                .set_len(0)
                .unwrap();
            let sum: u64 = bytes.iter().map(|&b| u64::from(b)).sum();
            panic!("read {sum} past the end without a fault");
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("shrinks.gltf");
        std::fs::write(&path, vec![b' '; 2 * MAPPED_FROM as usize]).unwrap();
        let (status, stderr) = run_as_child(
            "a_mapped_file_shortened_while_read_is_reported_by_name",
            CHILD,
            path.as_os_str(),
        );
        assert_eq!(status, Some(1), "{stderr}");
        assert!(
            stderr.contains(&format!(
                "velvet: {}: the file became shorter while velvet read it (another program \
                 changed it); velvet stopped\n",
                path.display()
            )),
            "{stderr}"
        );
    }

    /// A SIGBUS outside the mapped files goes to the handler there was before velvet's. The
    /// test runs itself again as a child process that installs a handler, enables mapping and
    /// raises the signal.
    #[cfg(unix)]
    #[test]
    fn a_fault_outside_the_mapped_files_goes_to_the_handler_there_was_before() {
        const CHILD: &str = "VELVET_PREVIOUS_HANDLER";
        extern "C" fn previous(_: libc::c_int) {
            let text = b"the previous handler ran\n";
            // SAFETY: write(2) and _exit(2) are async-signal-safe.
            unsafe {
                libc::write(2, text.as_ptr().cast(), text.len());
                libc::_exit(3);
            }
        }
        if std::env::var_os(CHILD).is_some() {
            let installed = |handler: &mut libc::sigaction| {
                // SAFETY: reads the current action into a zeroed struct.
                unsafe { libc::sigaction(libc::SIGBUS, std::ptr::null(), handler) };
                handler.sa_sigaction
            };
            // SAFETY: a zeroed sigaction is a valid struct to read an action into; the handler
            // installed writes and exits.
            let mut action: libc::sigaction = unsafe { std::mem::zeroed() };
            unsafe { libc::signal(libc::SIGBUS, previous as *const () as libc::sighandler_t) };
            let before = installed(&mut action);
            enable_mapping();
            assert_ne!(
                installed(&mut action),
                before,
                "velvet's handler is installed"
            );
            // SAFETY: raises the signal, which the handlers end the process on.
            unsafe { libc::raise(libc::SIGBUS) };
            panic!("the signal came back");
        }
        let (status, stderr) = run_as_child(
            "a_fault_outside_the_mapped_files_goes_to_the_handler_there_was_before",
            CHILD,
            "1".as_ref(),
        );
        assert_eq!(status, Some(3), "{stderr}");
        assert!(stderr.contains("the previous handler ran\n"), "{stderr}");
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
