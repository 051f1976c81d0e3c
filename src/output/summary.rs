//! The wording `velvet migrate` and `velvet bake` share in their text reports: how much a
//! report says ([`Detail`]), counts with their nouns, byte sizes, what a file or run added, and
//! the summary's first line. Both commands word these alike, so they are written once here.

/// How much the text says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Detail {
    /// Failed files only.
    Quiet,
    /// One line per file, then the summary.
    Normal,
    /// Also what each file has to say: migrate's materials and notes, bake's slots, outputs and
    /// notes.
    Verbose,
}

/// `n` with the singular or plural noun.
pub fn plural(n: usize, one: &str, many: &str) -> String {
    if n == 1 {
        format!("{n} {one}")
    } else {
        format!("{n} {many}")
    }
}

/// A byte count for people: bytes, KiB or MiB, to three significant digits.
pub fn bytes(n: usize) -> String {
    let n = n as f64;
    if n < 1024.0 {
        format!("{n} bytes")
    } else if n < 1024.0 * 1024.0 {
        format!("{:.1} KiB", n / 1024.0)
    } else {
        format!("{:.1} MiB", n / (1024.0 * 1024.0))
    }
}

/// "N textures added (B)", or "no texture added": what a file or run added.
pub fn added(textures: usize, size: usize, dry_run: bool) -> String {
    match (textures, dry_run) {
        (0, true) => "no texture to add".to_string(),
        (0, false) => "no texture added".to_string(),
        (n, true) => format!("{} to add", plural(n, "texture", "textures")),
        (n, false) => format!(
            "{} added ({})",
            plural(n, "texture", "textures"),
            bytes(size)
        ),
    }
}

/// The summary's first line, alike for migrate and bake: "N files: X `<done>`, Y unchanged,
/// Z failed".
pub fn files_line(
    files: usize,
    done: usize,
    done_word: &str,
    unchanged: usize,
    failed: usize,
) -> String {
    format!(
        "{}: {done} {done_word}, {unchanged} unchanged, {failed} failed",
        plural(files, "file", "files")
    )
}
