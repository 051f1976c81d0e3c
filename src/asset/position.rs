//! Source positions: the line and column where the value a JSON pointer names starts in the
//! JSON text.
//!
//! Values are found through the document's index ([`super::tape`]), which holds every value's
//! byte span; this module turns byte offsets into lines and columns. It is run only when a
//! report has something to place. Columns count characters (not bytes), both 1-based.

use super::tape::Node;

pub use crate::diagnostics::Position;

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

/// The line and column of byte `offset` (on a character boundary) in `text`.
pub fn position_of(text: &str, offset: usize) -> Position {
    Cursor::new(text).advance_to(offset.min(text.len()))
}

/// Locates the values named by `pointers` in `text`, whose index `root` is: one entry per
/// pointer, in the order given, `None` where a pointer names nothing. Each value's offset
/// comes from its span in the index; the offsets are then sorted and the text read once, front
/// to back, counting lines and characters up to each in turn. Counting each column from the
/// start of its line instead costs the line's length per finding, which on a one-line
/// (minified) document is the whole text per finding.
pub fn locate<'p>(
    text: &str,
    root: Node<'_>,
    pointers: impl IntoIterator<Item = &'p str>,
) -> Vec<Option<Position>> {
    let offsets: Vec<Option<usize>> = pointers
        .into_iter()
        .map(|p| Some(root.pointer(p)?.span().start))
        .collect();
    let mut order: Vec<(usize, usize)> = offsets
        .iter()
        .enumerate()
        .filter_map(|(i, offset)| Some(((*offset)?, i)))
        .collect();
    order.sort_unstable();
    let mut positions = vec![None; offsets.len()];
    let mut cursor = Cursor::new(text);
    for (offset, i) in order {
        positions[i] = Some(cursor.advance_to(offset));
    }
    positions
}

/// A place in a text that only moves forward, knowing its line and column.
pub(crate) struct Cursor<'a> {
    bytes: &'a [u8],
    at: Position,
}

impl<'a> Cursor<'a> {
    pub(crate) fn new(text: &'a str) -> Cursor<'a> {
        Cursor {
            bytes: text.as_bytes(),
            at: Position {
                line: 1,
                column: 1,
                offset: 0,
            },
        }
    }

    /// The position of byte `offset` (at or after the cursor's, on a character boundary),
    /// where the cursor then stands. The lines passed are counted, and the column is counted
    /// from the last newline passed (or carried on from the cursor's): a one-line (minified)
    /// document's places are each counted from the one before, not from the line's start.
    pub(crate) fn advance_to(&mut self, offset: usize) -> Position {
        debug_assert!(offset >= self.at.offset, "the cursor only moves forward");
        let passed = &self.bytes[self.at.offset..offset];
        match memchr::memrchr(b'\n', passed) {
            Some(last) => {
                self.at.line += bytecount::count(passed, b'\n');
                // A character is counted at its first byte (bytecount counts UTF-8 characters
                // so).
                self.at.column = bytecount::num_chars(&passed[last + 1..]) + 1;
            }
            None => self.at.column += bytecount::num_chars(passed),
        }
        self.at.offset = offset;
        self.at
    }

    /// The byte the cursor stands at.
    pub(crate) fn offset(&self) -> usize {
        self.at.offset
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn digit_tokens_name_array_elements_and_object_keys_alike() {
        let text = "{\"a\": {\"5\": 1, \"05\": 2}, \"b\": [10, 20, 30]}";
        let at = |found: Option<Position>| found.map(|p| &text[p.offset..p.offset + 2]);
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let found = locate(
            text,
            tape.root(text),
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

    use super::*;

    fn find(text: &str, p: &str) -> Option<Position> {
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        locate(text, tape.root(text), [p])[0]
    }

    fn at(text: &str, p: &str) -> Option<(usize, usize)> {
        find(text, p).map(|pos| (pos.line, pos.column))
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
        let pos = find(text, p).unwrap();
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
        assert_eq!(&text[find(text, p).unwrap().offset..][..3], "1.5");
    }

    /// The position of byte `offset`, counted from the text's start on its own.
    fn counted_alone(text: &str, offset: usize) -> (usize, usize) {
        let before = &text[..offset];
        let line_start = before.rfind('\n').map_or(0, |p| p + 1);
        (
            before.matches('\n').count() + 1,
            before[line_start..].chars().count() + 1,
        )
    }

    #[test]
    fn positions_found_in_one_pass_equal_each_counted_alone_in_any_pointer_order() {
        // Minified and pretty-printed layouts, multibyte characters before values on the same
        // line, pointers given out of text order, repeated, and naming nothing.
        let values: Vec<String> = (0..40)
            .map(|i| format!(r#"{{"näme":"ü{i}","v":[{i},"日本",{{"x":{i}}}]}}"#))
            .collect();
        let minified = format!(r#"{{"m":[{}],"ß":true}}"#, values.join(","));
        let value: serde_json::Value = serde_json::from_str(&minified).unwrap();
        let pretty = serde_json::to_string_pretty(&value).unwrap();
        let pointers: Vec<String> = (0..40)
            .rev()
            .flat_map(|i| {
                [
                    format!("/m/{i}/v/2/x"),
                    format!("/m/{i}/näme"),
                    format!("/m/{}/v/1", (i * 7) % 40),
                    "/ß".to_string(),
                    format!("/m/{i}/absent"),
                ]
            })
            .collect();
        for text in [minified.as_str(), pretty.as_str()] {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let found = locate(text, tape.root(text), pointers.iter().map(String::as_str));
            assert_eq!(found.len(), pointers.len());
            for (pointer, position) in pointers.iter().zip(found) {
                if pointer.ends_with("/absent") {
                    assert_eq!(position, None, "{pointer}");
                    continue;
                }
                let position = position.unwrap_or_else(|| panic!("{pointer} is found"));
                let offset = tape.root(text).pointer(pointer).unwrap().span().start;
                assert_eq!(position.offset, offset, "{pointer}");
                assert_eq!(
                    (position.line, position.column),
                    counted_alone(text, offset),
                    "{pointer}"
                );
            }
        }
    }

    /// Places far apart (the counts then run over whole vector registers) in a long line and
    /// in a text with newlines, CR LF line ends and characters of one to four bytes, ends of
    /// lines and the text's last byte among them: each as counted alone.
    #[test]
    fn places_far_apart_are_counted_as_each_alone() {
        let piece = "ab日\r\nü€ 😀x\n\n";
        // A long line first, then many lines.
        let mut text = "ü€😀a".repeat(600);
        for i in 0..3000 {
            text.push_str(
                &piece[..piece
                    .char_indices()
                    .nth(i % 9)
                    .map_or(piece.len(), |(b, _)| b)],
            );
            text.push_str(if i % 97 == 0 {
                ""
            } else {
                "long line of plain text "
            });
        }
        let offsets: Vec<usize> = (0..text.len())
            .step_by(997)
            .chain([text.len()])
            .map(|mut at| {
                while !text.is_char_boundary(at) {
                    at += 1;
                }
                at
            })
            .collect();
        let mut cursor = Cursor::new(&text);
        for offset in offsets {
            let found = cursor.advance_to(offset);
            assert_eq!(found.offset, offset);
            assert_eq!(
                (found.line, found.column),
                counted_alone(&text, offset),
                "{offset}"
            );
        }
    }

    #[test]
    fn escaped_keys_and_non_ascii_columns_count_characters() {
        let text = "{\"név\": \"ü\", \"a/b\": {\"~k\": 1}}";
        assert_eq!(at(text, "/a~1b/~0k"), Some((1, 28)));
        assert_eq!(at(text, "/név"), Some((1, 9)));
    }
}
