//! Source positions: the line and column where the value a JSON pointer names starts in the
//! JSON text.
//!
//! serde_json gives no spans, so this is a small scanner of our own. It walks the text once for
//! a whole set of pointers, descends only into containers on the way to one of them, and skips
//! everything else at byte speed; it is run only when a report has something to place.
//! Columns count characters (not bytes), both 1-based.

use super::pointer;
use std::borrow::Cow;
use std::collections::HashMap;

pub use crate::diagnostics::Position;

/// The position of byte `offset` in `text` (1-based line, character column).
pub fn at_offset(text: &str, offset: usize) -> Position {
    let offset = offset.min(text.len());
    let before = &text.as_bytes()[..offset];
    let line_start = before
        .iter()
        .rposition(|b| *b == b'\n')
        .map_or(0, |p| p + 1);
    Position {
        line: before.iter().filter(|b| **b == b'\n').count() + 1,
        column: String::from_utf8_lossy(&before[line_start..])
            .chars()
            .count()
            + 1,
        offset,
    }
}

/// The byte offset of 1-based `line` and character `column` in `text`.
pub fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let line_start = if line <= 1 {
        0
    } else {
        text.match_indices('\n')
            .nth(line - 2)
            .map_or(text.len(), |(i, _)| i + 1)
    };
    text[line_start..]
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(text.len(), |(i, _)| line_start + i)
}

/// The pointers asked for, as a tree of their tokens: the scanner descends along it, so each
/// value costs one lookup of its key, not a hash of its whole path. Tokens borrow from the
/// pointers (unescaped copies only for the rare `~0`/`~1`).
#[derive(Default)]
struct Wanted<'p> {
    /// Where in the order asked the pointers that end here stand.
    ends: Vec<usize>,
    children: HashMap<Cow<'p, str>, Wanted<'p>>,
}

/// Locates the values named by `pointers` in `text`: one entry per pointer, in the order
/// given, `None` where a pointer names nothing.
pub fn locate<'p>(
    text: &str,
    pointers: impl IntoIterator<Item = &'p str>,
) -> Vec<Option<Position>> {
    let mut wanted = Wanted::default();
    let mut count = 0;
    for (i, p) in pointers.into_iter().enumerate() {
        count = i + 1;
        let mut node = &mut wanted;
        if let Some(rest) = p.strip_prefix('/') {
            for token in rest.split('/') {
                let token = if token.contains('~') {
                    Cow::Owned(pointer::unescape(token))
                } else {
                    Cow::Borrowed(token)
                };
                node = node.children.entry(token).or_default();
            }
        }
        node.ends.push(i);
    }
    let mut scanner = Scanner {
        bytes: text.as_bytes(),
        text,
        at: 0,
        found: vec![None; count],
        line_starts: line_starts(text),
        index_text: String::new(),
    };
    scanner.skip_ws();
    scanner.value(Some(&wanted));
    scanner.found
}

fn line_starts(text: &str) -> Vec<usize> {
    std::iter::once(0)
        .chain(
            text.bytes()
                .enumerate()
                .filter(|(_, b)| *b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .collect()
}

struct Scanner<'a> {
    bytes: &'a [u8],
    text: &'a str,
    at: usize,
    found: Vec<Option<Position>>,
    line_starts: Vec<usize>,
    /// Reused for array indices as keys.
    index_text: String,
}

impl<'a> Scanner<'a> {
    fn position(&self, offset: usize) -> Position {
        let line = self.line_starts.partition_point(|&s| s <= offset);
        let start = self.line_starts[line - 1];
        let column = self.text[start..offset].chars().count() + 1;
        Position {
            line,
            column,
            offset,
        }
    }

    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.at).copied()
    }

    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.at += 1;
        }
    }

    /// Scans one value at `self.at`; records it if wanted, descends if a wanted pointer lies
    /// below it.
    fn value(&mut self, wanted: Option<&Wanted>) {
        if let Some(w) = wanted.filter(|w| !w.ends.is_empty()) {
            let pos = self.position(self.at);
            for &i in &w.ends {
                self.found[i] = Some(pos);
            }
        }
        let below = wanted.filter(|w| !w.children.is_empty());
        match (self.peek(), below) {
            (Some(b'{'), Some(w)) => self.object(w),
            (Some(b'['), Some(w)) => self.array(w),
            (Some(b'{' | b'['), _) => self.skip_container(),
            (Some(b'"'), _) => {
                self.string();
            }
            (Some(_), _) => self.scalar(),
            (None, _) => {}
        }
    }

    fn object(&mut self, wanted: &Wanted) {
        self.at += 1;
        loop {
            self.skip_ws();
            match self.peek() {
                Some(b'}') | None => {
                    self.at += 1;
                    return;
                }
                Some(b',') => {
                    self.at += 1;
                    continue;
                }
                Some(b'"') => {
                    let key = self.string();
                    self.skip_ws();
                    if self.peek() == Some(b':') {
                        self.at += 1;
                    }
                    self.skip_ws();
                    let child = wanted.children.get(key.as_ref());
                    self.value(child);
                }
                Some(_) => {
                    // Not JSON we understand: stop rather than guess.
                    self.at = self.bytes.len();
                    return;
                }
            }
        }
    }

    fn array(&mut self, wanted: &Wanted) {
        self.at += 1;
        let mut index = 0usize;
        loop {
            self.skip_ws();
            match self.peek() {
                Some(b']') | None => {
                    self.at += 1;
                    return;
                }
                Some(b',') => {
                    self.at += 1;
                    index += 1;
                    continue;
                }
                Some(_) => {
                    use std::fmt::Write;
                    self.index_text.clear();
                    let _ = write!(self.index_text, "{index}");
                    let child = wanted.children.get(self.index_text.as_str());
                    self.value(child);
                }
            }
        }
    }

    /// Reads a string token, returning its decoded content (borrowed when it has no escapes).
    fn string(&mut self) -> std::borrow::Cow<'a, str> {
        let start = self.at;
        self.at += 1;
        while let Some(b) = self.peek() {
            self.at += 1;
            match b {
                b'\\' => self.at += 1,
                b'"' => break,
                _ => {}
            }
        }
        let text: &'a str = self.text;
        let raw = &text[start..self.at.min(self.bytes.len())];
        if !raw.contains('\\') && raw.len() >= 2 && raw.ends_with('"') {
            return std::borrow::Cow::Borrowed(&raw[1..raw.len() - 1]);
        }
        std::borrow::Cow::Owned(
            serde_json::from_str::<String>(raw)
                .unwrap_or_else(|_| raw.trim_matches('"').to_string()),
        )
    }

    fn scalar(&mut self) {
        while let Some(b) = self.peek() {
            if matches!(b, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r') {
                break;
            }
            self.at += 1;
        }
    }

    fn skip_container(&mut self) {
        let mut depth = 0usize;
        while let Some(b) = self.peek() {
            match b {
                b'"' => {
                    self.at += 1;
                    while let Some(c) = self.peek() {
                        self.at += 1;
                        match c {
                            b'\\' => self.at += 1,
                            b'"' => break,
                            _ => {}
                        }
                    }
                    continue;
                }
                b'{' | b'[' => depth += 1,
                b'}' | b']' => {
                    depth -= 1;
                    if depth == 0 {
                        self.at += 1;
                        return;
                    }
                }
                _ => {}
            }
            self.at += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn digit_tokens_name_array_elements_and_object_keys_alike() {
        let text = "{\"a\": {\"5\": 1, \"05\": 2}, \"b\": [10, 20, 30]}";
        let at = |found: Option<Position>| found.map(|p| &text[p.offset..p.offset + 2]);
        let found = locate(
            text,
            ["/a/5", "/a/05", "/b/2", "/b/02", "/b/1", "/a/x", "/b/3"],
        );
        let found: Vec<_> = found.into_iter().map(at).collect();
        assert_eq!(
            found,
            [
                Some("1,"),
                Some("2}"),
                Some("30"),
                None,
                Some("20"),
                None,
                None
            ]
        );
    }

    #[test]
    fn truncated_text_with_a_multibyte_key_is_scanned_without_panic() {
        for text in ["{\"é", "{\"a\\\"é"] {
            assert_eq!(locate(text, ["/é/1/ü"]), vec![None], "{text}");
        }
        // A key cut off at the end of the text: its value is placed at the end.
        assert_eq!(at("{\"é\": [1, {\"ü", "/é/1/ü"), Some((1, 14)));
    }

    use super::*;

    fn at(text: &str, p: &str) -> Option<(usize, usize)> {
        locate(text, [p])[0].map(|pos| (pos.line, pos.column))
    }

    #[test]
    fn finds_values_in_pretty_printed_json() {
        let text = "{\n  \"materials\": [\n    {\n      \"name\": \"a\",\n      \"x\": [1, 2]\n    }\n  ]\n}\n";
        assert_eq!(at(text, "/materials/0/name"), Some((4, 15)));
        assert_eq!(at(text, "/materials/0/x/1"), Some((5, 16)));
        assert_eq!(at(text, "/materials/0"), Some((3, 5)));
        assert_eq!(at(text, ""), Some((1, 1)));
        assert_eq!(at(text, "/materials/1"), None);
    }

    #[test]
    fn finds_values_in_minified_json_skipping_siblings_with_brackets_in_strings() {
        let text = r#"{"a":{"s":"]}{["},"b":[{"c":true},{"c":false}]}"#;
        assert_eq!(at(text, "/b/1/c"), Some((1, 40)));
        assert_eq!(at(text, "/a/s"), Some((1, 11)));
    }

    #[test]
    fn pretty_printed_escaped_keys_and_non_ascii_before_the_value() {
        // Line 3 holds "ü/ß~" (4 characters, 6 bytes) before the value: the column counts
        // characters, the offset counts bytes.
        let text = "{\n  \"extras\": {\n    \"ü/ß~\": [true, {\"a~b/c\": \"ö\"}]\n  }\n}";
        let p = "/extras/ü~1ß~0";
        let pos = locate(text, [p])[0].unwrap();
        assert_eq!((pos.line, pos.column), (3, 13));
        assert_eq!(&text[pos.offset..pos.offset + 5], "[true");
        assert_eq!(at(text, "/extras/ü~1ß~0/1/a~0b~1c"), Some((3, 30)));
        assert_eq!(
            at(text, "/extras/ü~1ß~0/1/a~1b~0c"),
            None,
            "~0 and ~1 are not interchangeable"
        );
    }

    #[test]
    fn minified_keys_with_json_escapes_match_their_decoded_pointer() {
        // The key is written with \u00fc and an escaped quote; the pointer uses the decoded text.
        let text = r#"{"k\u00fc\"y":{"x":[0,"\"]",{"z":null}]}}"#;
        assert_eq!(at(text, "/kü\"y/x/2/z"), Some((1, 34)));
        assert_eq!(at(text, "/kü\"y/x/1"), Some((1, 23)));
    }

    #[test]
    fn crlf_line_ends_and_multibyte_strings_before_a_value_on_the_same_line() {
        let text = "{\r\n\"name\": \"日本語\", \"v\": 1.5\r\n}";
        assert_eq!(at(text, "/v"), Some((2, 21)));
        let p = "/v";
        assert_eq!(&text[locate(text, [p])[0].unwrap().offset..][..3], "1.5");
    }

    #[test]
    fn escaped_keys_and_non_ascii_columns_count_characters() {
        let text = "{\"név\": \"ü\", \"a/b\": {\"~k\": 1}}";
        assert_eq!(at(text, "/a~1b/~0k"), Some((1, 28)));
        assert_eq!(at(text, "/név"), Some((1, 9)));
    }
}
