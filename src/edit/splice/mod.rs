//! Format-preserving output: an edited document is written as splices into its source text.
//!
//! Given the text a document was loaded from, the document as loaded and the document after a
//! plan was applied, [`rewrite`] compares the two values and changes only the spans that
//! differ: a changed value replaces its span, a new key goes after the last member of its
//! object, a new element after the last element of its array, a removed member takes its
//! separator with it. Every other byte — indentation, line endings, key order, number
//! spellings (`1E-1`, `1.0`), unicode escapes, a missing final newline — comes out as it went
//! in, so a migration's diff shows only what it changed (as toml_edit does for Cargo.toml).
//!
//! What velvet inserts follows the file's own layout: its indent unit (tabs or N spaces), its
//! line ending, its spacing after `:` and `,`; an object or array written on one line stays on
//! one line, a minified file stays minified, and arrays of numbers are inline when the file
//! writes them so.
//!
//! Numbers velvet writes are rounded to [`DECIMALS`] decimal places and written as the
//! shortest decimal that reads back as that value: an error of at most 5e-7, thirty times below
//! one step of a 16-bit texture channel (1.5e-5), and no float noise such as
//! `0.7499999999999999` in an output file. Numbers that already have at most that many
//! decimals (copied from the input, or integers) keep their spelling.
//!
//! [`splice_edits`] takes a plan's edits instead of a whole edited document: only the parts
//! they touch are read, each part's new text is checked alone (where the edits only add
//! members, by reading the inserted text; otherwise by reading the part's new text back), and
//! the result is a [`Spliced`] text, written to its file piece by piece rather than joined.
//! A value an edit holds as compact text ([`write_compact`], as a conversion writes its layer
//! object) is laid out from that text in one pass, and the inserted text is checked against it
//! token by token.
//!
//! The spans come from the document's index ([`crate::asset::tape`]), built when it was loaded:
//! the source is not read a second time. No maintained crate offers format-preserving edits of
//! JSON text (toml_edit's equivalent for JSON does not exist). The check a spliced text passes
//! before it is written reads that new text with a small streaming scanner, written here for the
//! same reason.
//!
//! The writer is split by concern, one file each. Each file imports only the files listed
//! before it, and the splices defined here:
//!
//! - `numbers.rs`: how velvet writes numbers ([`DECIMALS`], [`number_text`], [`written`],
//!   [`written_f64`]);
//! - `read_back.rs`: the read-back checks of a spliced text, with the streaming scanner
//!   ([`reads_as_written`], the check of inserted members and of laid-out compact text);
//! - `layout.rs`: the file's own layout, read once, and new values written in it;
//! - `compact.rs`: compact text ([`write_compact`], [`write_compact_node`],
//!   [`push_written_f64`]);
//! - `digest.rs`: the digest a part is checked by as it reads back;
//! - `diff.rs`: the document as loaded compared with the edited value, and the splices that
//!   make one the other;
//! - `edits.rs`: [`splice_edits`], a plan's edits spliced part by part;
//! - `mod.rs` (here): [`rewrite`], and [`Spliced`], the text the splices make.

mod compact;
mod diff;
mod digest;
mod edits;
mod layout;
mod numbers;
mod read_back;

pub use compact::{push_written_f64, write_compact, write_compact_node};
pub use edits::splice_edits;
pub(crate) use numbers::is_written;
pub use numbers::{number_text, written, written_f64, DECIMALS};
pub use read_back::reads_as_written;

use crate::asset::tape::Node;
use diff::diff;
use layout::Layout;
use serde_json::Value;

/// The text of `after` written as splices into `text`, whose index `root` is (the document as
/// loaded); `None` when the splices would overlap (the caller then writes the document afresh).
/// The loaded document is read off the index as the comparison goes, never held as a whole.
pub fn rewrite(text: &str, root: Node, after: &Value) -> Option<String> {
    let layout = Layout::detect(text, root);
    let mut splices = Vec::new();
    diff(text, root, after, &layout, &mut splices);
    Spliced::new(text, splices).map(|spliced| spliced.to_text())
}

/// A text written as splices into a source text, kept as the source and the splices (sorted,
/// none overlapping) rather than joined: an output of the size of its input is written to its
/// file piece by piece ([`Spliced::pieces`]) and never held as a second copy of the text.
#[derive(Debug)]
pub struct Spliced<'t> {
    source: &'t str,
    splices: Vec<Splice>,
}

impl<'t> Spliced<'t> {
    /// `None` if two splices overlap (never produced, but never risked).
    fn new(source: &'t str, mut splices: Vec<Splice>) -> Option<Spliced<'t>> {
        in_order(&mut splices, 0..source.len()).then_some(Spliced { source, splices })
    }

    /// The text in order: spans of the source and the splices' texts between them.
    fn runs(&self) -> impl Iterator<Item = &str> + '_ {
        runs(self.source, 0..self.source.len(), &self.splices)
    }

    /// The text's bytes in order, a run at a time.
    pub fn pieces(&self) -> impl Iterator<Item = &[u8]> + '_ {
        self.runs().map(str::as_bytes)
    }

    /// The byte of the source where the text first differs from it: the start of the first
    /// splice (`None` without one).
    pub fn first_change(&self) -> Option<usize> {
        self.splices.first().map(|s| s.start)
    }

    /// The text's length in bytes.
    pub fn len(&self) -> usize {
        let removed: usize = self.splices.iter().map(|s| s.end - s.start).sum();
        let added: usize = self.splices.iter().map(|s| s.text.len()).sum();
        self.source.len() - removed + added
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The text, joined.
    pub fn to_text(&self) -> String {
        let mut out = String::with_capacity(self.len());
        crate::asset::pages::advise_huge_text(&mut out);
        self.runs().for_each(|run| out.push_str(run));
        out
    }
}

/// Sorts `splices` and tells whether they lie inside `within`, none overlapping another.
fn in_order(splices: &mut [Splice], within: std::ops::Range<usize>) -> bool {
    splices.sort_by_key(|s| (s.start, s.end));
    let mut at = within.start;
    for s in splices.iter() {
        if s.start < at || s.end > within.end {
            return false;
        }
        at = s.end;
    }
    true
}

/// `text[within]` with `splices` (in order, inside `within`) made, a run at a time: spans of
/// the text and the splices' texts between them.
fn runs<'a>(
    text: &'a str,
    within: std::ops::Range<usize>,
    splices: &'a [Splice],
) -> impl Iterator<Item = &'a str> + 'a {
    let mut at = within.start;
    splices
        .iter()
        .flat_map(move |s| {
            let kept = &text[at..s.start];
            at = s.end;
            [kept, s.text.as_str()]
        })
        .chain(std::iter::once_with(move || {
            let last = splices.last().map_or(within.start, |s| s.end);
            &text[last..within.end]
        }))
}

/// A replacement of `text[start..end]`.
#[derive(Debug)]
struct Splice {
    start: usize,
    end: usize,
    text: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `after` written as splices into `text`.
    pub(super) fn spliced(text: &str, after: &Value) -> String {
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        rewrite(text, tape.root(text), after).unwrap()
    }

    /// Documents in the layouts a file may have: two spaces with number arrays on one line,
    /// tabs with CRLF, four spaces with one-line objects, minified.
    pub(super) const LAYOUTS: [&str; 4] = [
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"materials\": [\n    {\n      \"extensions\": {\n        \"KHR_materials_sheen\": {\n          \"sheenColorFactor\": [1, 0.5, 0]\n        }\n      }\n    }\n  ]\n}\n",
        "{\r\n\t\"asset\": {\r\n\t\t\"version\": \"2.0\"\r\n\t},\r\n\t\"materials\": [\r\n\t\t{\r\n\t\t\t\"extensions\": {\r\n\t\t\t\t\"KHR_materials_sheen\": {\r\n\t\t\t\t\t\"sheenColorFactor\": [\r\n\t\t\t\t\t\t1,\r\n\t\t\t\t\t\t0.5\r\n\t\t\t\t\t]\r\n\t\t\t\t}\r\n\t\t\t}\r\n\t\t}\r\n\t]\r\n}",
        "{\n    \"asset\": { \"version\": \"2.0\", \"generator\": \"x\" },\n    \"materials\": [\n        { \"extensions\": { \"KHR_materials_sheen\": { \"sheenColorFactor\": [1, 0.5, 0] } } }\n    ]\n}\n",
        "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,0.5,0]}}}]}",
    ];

    /// Values a layer object may hold: nested objects and arrays, empty ones, escaped and
    /// non-ASCII strings, the literals, numbers spelled with exponents and with more decimals
    /// than velvet writes.
    pub(super) fn layer_values() -> Vec<Value> {
        vec![
            serde_json::json!({"fuzzFactor": 0.9, "fuzzColorFactor": [1.0, 0.5, 0], "fuzzRoughnessFactor": 0.3089, "fuzzRoughnessTexture": {"index": 0}}),
            serde_json::json!({"t": {"index": 2, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0], "offset": []}}, "extras": {}}}),
            serde_json::from_str(r#"{"s": "a \"quoted\" \\ tab\t é \u0001", "b": [true, false, null], "n": [1E-1, -2.5e3, 0.12345678, 7.5e-8], "mixed": [1, "x", {"k": [2]}]}"#).unwrap(),
            serde_json::json!([]),
            serde_json::json!({}),
            serde_json::json!("plain"),
            serde_json::json!(0.7499999999999999),
        ]
    }

    #[test]
    fn a_spliced_text_is_written_piece_by_piece_as_the_joined_text() {
        let text = "{\"a\": [1, 2], \"b\": \"é\"}";
        let splice = |start: usize, end: usize, text: &str| Splice {
            start,
            end,
            text: text.to_string(),
        };
        // Given out of order; one at the very start, one replacing a span, one at the end.
        let spliced = Spliced::new(
            text,
            vec![
                splice(text.len(), text.len(), "\n"),
                splice(7, 8, "3"),
                splice(0, 0, ""),
            ],
        )
        .unwrap();
        let joined: Vec<u8> = spliced.pieces().flatten().copied().collect();
        assert_eq!(spliced.to_text(), "{\"a\": [3, 2], \"b\": \"é\"}\n");
        assert_eq!(joined, spliced.to_text().as_bytes());
        assert_eq!(spliced.len(), spliced.to_text().len());
        // Overlapping splices, or one past the end, are never taken.
        assert!(Spliced::new(text, vec![splice(1, 5, ""), splice(4, 6, "")]).is_none());
        assert!(Spliced::new(text, vec![splice(text.len(), text.len() + 1, "")]).is_none());
    }
}
