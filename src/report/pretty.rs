//! Pretty-printed JSON for the JSON and SARIF reports: the bytes of serde_json's
//! `PrettyFormatter` with a two-space indent, written with one call per line break.
//!
//! serde_json's formatter writes a line break and then the indent one level at a time, a call
//! each; a report of many findings is mostly line breaks and indents, and those calls were a
//! tenth of writing it. serde_json offers no indent written in one piece, so this formatter
//! keeps a line break followed by enough spaces for the deepest level so far and writes a
//! slice of it.

use serde::Serialize;
use serde_json::ser::Formatter;
use std::io::{self, Write};

/// The indent of one level, as the reports have always had it.
const INDENT: usize = 2;

/// serde_json's pretty layout (two-space indent), line breaks and indents written in one piece.
#[derive(Debug, Default)]
pub struct LineFormatter {
    /// How many containers are open.
    depth: usize,
    /// Whether the innermost open container has had a value (it then closes on its own line).
    has_value: bool,
    /// ",\n" followed by `INDENT * depth` spaces, for the deepest depth so far; a line break
    /// and its indent is a slice of it from the second byte, a comma before them from the first.
    line: Vec<u8>,
}

impl LineFormatter {
    /// A line break and the indent of the current depth, after a comma when `comma`.
    fn line_break<W: ?Sized + Write>(&mut self, writer: &mut W, comma: bool) -> io::Result<()> {
        let end = 2 + INDENT * self.depth;
        if self.line.len() < end {
            if self.line.is_empty() {
                self.line.extend_from_slice(b",\n");
            }
            self.line.resize(end, b' ');
        }
        writer.write_all(&self.line[usize::from(!comma)..end])
    }

    fn open<W: ?Sized + Write>(&mut self, writer: &mut W, bracket: &[u8]) -> io::Result<()> {
        self.depth += 1;
        self.has_value = false;
        writer.write_all(bracket)
    }

    fn close<W: ?Sized + Write>(&mut self, writer: &mut W, bracket: &[u8]) -> io::Result<()> {
        self.depth -= 1;
        if self.has_value {
            self.line_break(writer, false)?;
        }
        writer.write_all(bracket)
    }
}

impl Formatter for LineFormatter {
    #[inline]
    fn begin_array<W: ?Sized + Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.open(writer, b"[")
    }

    #[inline]
    fn end_array<W: ?Sized + Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.close(writer, b"]")
    }

    #[inline]
    fn begin_array_value<W: ?Sized + Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.line_break(writer, !first)
    }

    #[inline]
    fn end_array_value<W: ?Sized + Write>(&mut self, _writer: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }

    #[inline]
    fn begin_object<W: ?Sized + Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.open(writer, b"{")
    }

    #[inline]
    fn end_object<W: ?Sized + Write>(&mut self, writer: &mut W) -> io::Result<()> {
        self.close(writer, b"}")
    }

    #[inline]
    fn begin_object_key<W: ?Sized + Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> io::Result<()> {
        self.line_break(writer, !first)
    }

    #[inline]
    fn begin_object_value<W: ?Sized + Write>(&mut self, writer: &mut W) -> io::Result<()> {
        writer.write_all(b": ")
    }

    #[inline]
    fn end_object_value<W: ?Sized + Write>(&mut self, _writer: &mut W) -> io::Result<()> {
        self.has_value = true;
        Ok(())
    }
}

/// `value` pretty-printed into `writer`, byte for byte as `serde_json::to_writer_pretty`.
pub fn to_writer<W: Write, T: ?Sized + Serialize>(writer: W, value: &T) -> serde_json::Result<()> {
    let mut serializer = serde_json::Serializer::with_formatter(writer, LineFormatter::default());
    value.serialize(&mut serializer)
}

/// `value` pretty-printed, byte for byte as `serde_json::to_string_pretty`.
pub fn to_string<T: ?Sized + Serialize>(value: &T) -> serde_json::Result<String> {
    let mut text = Vec::with_capacity(128);
    to_writer(&mut text, value)?;
    // The serializer writes only UTF-8: its strings are `str`s, escaped.
    Ok(String::from_utf8(text).expect("serde_json writes UTF-8"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn nested_values_are_written_as_serde_json_pretty_prints_them() {
        let values = [
            json!({}),
            json!([]),
            json!({"a": [], "b": {}, "c": [1, [2, [3, {"d": [[[]]]}]]]}),
            json!([{"issues": {"messages": [{"code": "X", "pointer": "/a/0", "n": 1.5e300}]}}, null, "é\n\"", -0.0]),
            json!({"deep": [[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]], "after": true}),
        ];
        for value in values {
            assert_eq!(
                to_string(&value).unwrap(),
                serde_json::to_string_pretty(&value).unwrap()
            );
        }
    }

    #[test]
    fn byte_arrays_are_written_as_serde_json_pretty_prints_them() {
        struct Bytes<'a>(&'a [u8]);
        impl Serialize for Bytes<'_> {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_bytes(self.0)
            }
        }
        let value = (Bytes(&[0, 7, 255]), Bytes(&[]));
        assert_eq!(
            to_string(&value).unwrap(),
            serde_json::to_string_pretty(&value).unwrap()
        );
    }
}
