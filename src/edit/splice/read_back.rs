//! The read-back checks of a spliced text: what velvet inserted or wrote is read as it is
//! compared with what it was meant to hold, holding neither a document nor a tree of spans.
//! A small streaming scanner reads the text against a value ([`reads_as_written`], the check
//! of a whole text; [`inserted_members_read_as`], of the members inserted into an object);
//! [`reads_as_compact`] reads a laid-out text against the compact text it was laid out from.
//! The token boundaries ([`string_end`], [`scalar_end`]) and the comparison of a scalar's text
//! with a value ([`scalar_matches`]) are shared with the layout and the diff.

use super::numbers::{number_text, with_written_number};
use serde_json::Value;

/// A value a new member is meant to hold, as given to the writer and to the check of what it
/// wrote.
#[derive(Clone, Copy)]
pub(super) enum Meant<'v> {
    Value(&'v Value),
    /// Compact text as [`write_compact`](super::write_compact) writes it.
    Text(&'v str),
}

/// Whether `inserted`, the text put after an object's last member, reads as `members` added
/// after it: for each, a comma, its key, a colon and its value as velvet writes it; then
/// nothing but whitespace. The scan validates what it reads (a key's characters and escapes,
/// each scalar parsed), so the object stays JSON with exactly these members added.
pub(super) fn inserted_members_read_as(inserted: &str, members: &[(&str, Meant)]) -> bool {
    let mut scanner = Scanner {
        text: inserted,
        at: 0,
    };
    for (key, value) in members {
        if scanner.eat(b',').is_none() {
            return false;
        }
        let Some(at) = scanner.key() else {
            return false;
        };
        if key_at(inserted, at).as_deref() != Some(*key) {
            return false;
        }
        let holds = match value {
            Meant::Value(value) => scanner.holds(value),
            Meant::Text(text) => {
                scanner.skip_ws();
                reads_as_compact(&inserted[scanner.at..], text).map(|len| {
                    scanner.at += len;
                    true
                })
            }
        };
        if holds != Some(true) {
            return false;
        }
    }
    scanner.skip_ws();
    scanner.at == inserted.len()
}

struct Scanner<'a> {
    text: &'a str,
    at: usize,
}

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.at).copied()
    }

    fn skip_ws(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.at += 1;
        }
    }

    fn eat(&mut self, byte: u8) -> Option<()> {
        self.skip_ws();
        (self.peek()? == byte).then(|| self.at += 1)
    }

    /// Steps over the string at the cursor ([`string_end`]).
    fn string(&mut self) -> Option<()> {
        self.at = string_end(self.text.as_bytes(), self.at)?;
        Some(())
    }

    /// Steps over the opening `{` or `[` at the cursor; true when `close` follows at once (an
    /// empty container, stepped over too).
    fn open(&mut self, close: u8) -> Option<bool> {
        self.at += 1;
        self.skip_ws();
        let empty = self.peek()? == close;
        if empty {
            self.at += 1;
        }
        Some(empty)
    }

    /// Reads a member's key and its colon; the key's opening quote stands at the offset given.
    fn key(&mut self) -> Option<usize> {
        self.skip_ws();
        let key_start = self.at;
        if self.peek()? != b'"' {
            return None;
        }
        self.string()?;
        self.eat(b':')?;
        Some(key_start)
    }

    /// After a member or element: true past a `,` (another follows), false past `close`.
    fn next(&mut self, close: u8) -> Option<bool> {
        self.skip_ws();
        match self.peek()? {
            b',' => {
                self.at += 1;
                Some(true)
            }
            b if b == close => {
                self.at += 1;
                Some(false)
            }
            _ => None,
        }
    }

    /// Scans the value at the cursor and tells whether it is `value` as velvet writes it
    /// (numbers compared as [`Compare::Written`]); `None` where the text is not JSON. It stops
    /// at the first difference.
    fn holds(&mut self, value: &Value) -> Option<bool> {
        self.skip_ws();
        match (self.peek()?, value) {
            (b'{', Value::Object(map)) => {
                if self.open(b'}')? {
                    return Some(map.is_empty());
                }
                // Members are compared in the map's order while the text follows it, as the
                // text velvet writes does: distinct keys, none looked up. From the first key
                // out of that order, each key is looked up and the keys read are tracked, so
                // that none is read twice.
                let mut in_order = map.iter();
                let mut seen: Option<std::collections::HashSet<std::borrow::Cow<str>>> = None;
                let mut count = 0;
                loop {
                    let key = key_at(self.text, self.key()?)?;
                    let next_in_order = in_order
                        .next()
                        .filter(|(k, _)| seen.is_none() && **k == *key);
                    let member = match next_in_order {
                        Some((_, member)) => member,
                        None => {
                            let seen = seen.get_or_insert_with(|| {
                                map.keys().take(count).map(|k| k.as_str().into()).collect()
                            });
                            let Some(member) = map.get(key.as_ref()) else {
                                return Some(false);
                            };
                            if !seen.insert(key) {
                                return Some(false);
                            }
                            member
                        }
                    };
                    if !self.holds(member)? {
                        return Some(false);
                    }
                    count += 1;
                    if !self.next(b'}')? {
                        return Some(count == map.len());
                    }
                }
            }
            (b'[', Value::Array(items)) => {
                if self.open(b']')? {
                    return Some(items.is_empty());
                }
                let mut count = 0;
                loop {
                    let Some(item) = items.get(count) else {
                        return Some(false);
                    };
                    if !self.holds(item)? {
                        return Some(false);
                    }
                    count += 1;
                    if !self.next(b']')? {
                        return Some(count == items.len());
                    }
                }
            }
            (b'{' | b'[', _) => Some(false),
            _ => {
                let (start, end) = self.scalar()?;
                Some(scalar_matches(
                    &self.text[start..end],
                    value,
                    Compare::Written,
                ))
            }
        }
    }

    /// Steps over the string, number or literal at the cursor; its span.
    fn scalar(&mut self) -> Option<(usize, usize)> {
        let start = self.at;
        if self.peek()? == b'"' {
            self.string()?;
        } else {
            self.at = scalar_end(self.text.as_bytes(), start);
        }
        (self.at > start).then_some((start, self.at))
    }
}

/// How [`matches`](super::diff::matches) compares numbers.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Compare {
    /// As values: the text holds exactly this document.
    Exact,
    /// As velvet writes them: numbers rounded as [`number_text`] rounds.
    Written,
}

/// The key whose opening quote stands at `at`, decoded (borrowed when it has no escapes).
fn key_at(text: &str, at: usize) -> Option<std::borrow::Cow<'_, str>> {
    let mut scanner = Scanner { text, at };
    scanner.string()?;
    let raw = &text[at..scanner.at];
    if !raw.contains('\\') {
        return Some(std::borrow::Cow::Borrowed(&raw[1..raw.len() - 1]));
    }
    serde_json::from_str::<String>(raw)
        .ok()
        .map(std::borrow::Cow::Owned)
}

/// True when the scalar written `raw` is `value`.
pub(super) fn scalar_matches(raw: &str, value: &Value, compare: Compare) -> bool {
    // The scalars velvet writes and checks by the ten thousand, compared as text: a number
    // without an exponent (serde_json reads it with its text as written), a string without
    // escapes, a literal. Anything else is read by serde_json.
    match value {
        Value::Number(b) if is_plain_number(raw) => {
            return raw == b.as_str()
                || (compare == Compare::Written && with_written_number(b.as_str(), |t| t == raw));
        }
        Value::String(b) if raw.len() >= 2 && !raw.contains('\\') => {
            let bytes = raw.as_bytes();
            return bytes[0] == b'"'
                && bytes[raw.len() - 1] == b'"'
                && !bytes[1..raw.len() - 1]
                    .iter()
                    .any(|&c| c < 0x20 || c == b'"')
                && raw[1..raw.len() - 1] == **b;
        }
        Value::Bool(b) if matches!(raw, "true" | "false") => return (raw == "true") == *b,
        Value::Null if raw == "null" => return true,
        _ => {}
    }
    match serde_json::from_str::<Value>(raw) {
        Ok(Value::Number(a)) if compare == Compare::Written => {
            // A number the edit left keeps its spelling (`0.800000011920929` from an
            // exporter); one velvet wrote is as `number_text` writes it.
            matches!(value, Value::Number(b) if a == *b || a.to_string() == number_text(b))
        }
        Ok(v) => v == *value,
        Err(_) => false,
    }
}

/// Whether `written`, from its start, is the value `compact` holds (as [`write_compact`]
/// writes it) laid out: the same tokens in the same order, each number as
/// [`with_written_number`] writes the compact one, with whitespace only between tokens (next
/// to a bracket, brace, comma or colon, never inside a string or splitting a number); the
/// length of `written` it spans. One pass over both texts, as [`Layout::write_text`] writes
/// them. Every token is checked as JSON: strings without raw control characters and with
/// valid escapes, numbers JSON allows, the three literals. The compact text's own structure
/// is what [`write_compact`] made of a value.
///
/// [`write_compact`]: super::write_compact
/// [`Layout::write_text`]: super::layout::Layout::write_text
fn reads_as_compact(written: &str, compact: &str) -> Option<usize> {
    let (w, c) = (written.as_bytes(), compact.as_bytes());
    let structural = |b: Option<&u8>| matches!(b, Some(b'{' | b'}' | b'[' | b']' | b',' | b':'));
    let (mut i, mut j) = (0, 0);
    while j < c.len() {
        let byte = *w.get(i)?;
        if matches!(byte, b' ' | b'\t' | b'\n' | b'\r') {
            // Between tokens only: a structural byte before or after. The run of whitespace
            // (a line break and its indentation) stands in one place, so it is passed whole.
            if !(structural(c.get(j)) || structural(j.checked_sub(1).and_then(|k| c.get(k)))) {
                return None;
            }
            i += 1 + w[i + 1..]
                .iter()
                .take_while(|b| matches!(b, b' ' | b'\t' | b'\n' | b'\r'))
                .count();
            continue;
        }
        match c[j] {
            b'"' => {
                let end = string_end(c, j)?;
                let token = &compact[j..end];
                if written.get(i..i + token.len())? != token
                    || (token.contains('\\') && serde_json::from_str::<String>(token).is_err())
                {
                    return None;
                }
                i += token.len();
                j = end;
            }
            b'{' | b'}' | b'[' | b']' | b',' | b':' => {
                if byte != c[j] {
                    return None;
                }
                i += 1;
                j += 1;
            }
            _ => {
                let end = scalar_end(c, j);
                let meant = &compact[j..end];
                let written_end = scalar_end(w, i);
                let raw = &written[i..written_end];
                let literal = matches!(raw, "true" | "false" | "null");
                let same = if literal {
                    raw == meant
                } else {
                    (raw == meant || with_written_number(meant, |text| text == raw))
                        && (is_plain_number(raw)
                            || serde_json::from_str::<serde_json::Number>(raw).is_ok())
                };
                if !same || end == j {
                    return None;
                }
                i = written_end;
                j = end;
            }
        }
    }
    Some(i)
}

/// Where the string whose opening quote stands at `at` ends (past its closing quote); `None`
/// where it has no end or holds a control character, which JSON allows only escaped (escapes
/// are read where the string is decoded).
pub(super) fn string_end(bytes: &[u8], at: usize) -> Option<usize> {
    let mut i = at + 1;
    loop {
        // Plain text is passed eight bytes at a time, as the index passes it.
        i += crate::asset::json_text::string_stop(bytes.get(i..)?)?;
        match bytes[i] {
            b'"' => return Some(i + 1),
            b'\\' => i += 2,
            _ => return None,
        }
    }
}

/// Where the number or literal starting at `at` ends: at the next comma, colon, bracket, brace
/// or whitespace.
pub(super) fn scalar_end(bytes: &[u8], at: usize) -> usize {
    bytes[at..]
        .iter()
        .position(|b| matches!(b, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r' | b':'))
        .map_or(bytes.len(), |n| at + n)
}

/// Whether `raw` is a JSON number without an exponent: `-?(0|[1-9][0-9]*)(\.[0-9]+)?`.
fn is_plain_number(raw: &str) -> bool {
    let digits = raw.strip_prefix('-').unwrap_or(raw).as_bytes();
    let int_end = digits
        .iter()
        .position(|b| !b.is_ascii_digit())
        .unwrap_or(digits.len());
    let int_ok = int_end == 1 || (int_end > 1 && digits[0] != b'0');
    match &digits[int_end..] {
        [] => int_ok,
        [b'.', fraction @ ..] => {
            int_ok && !fraction.is_empty() && fraction.iter().all(u8::is_ascii_digit)
        }
        _ => false,
    }
}

/// True when `text` holds `value` with its numbers as velvet writes them: the check a spliced
/// text passes before it is written. It reads the text as it compares, holding neither a
/// document nor a tree of spans.
pub fn reads_as_written(text: &str, value: &Value) -> bool {
    let mut scanner = Scanner { text, at: 0 };
    if scanner.holds(value) != Some(true) {
        return false;
    }
    scanner.skip_ws();
    let rest = text[scanner.at..].trim_end_matches(['\0', ' ', '\t', '\n', '\r']);
    rest.is_empty() && serde_json::from_str::<serde::de::IgnoredAny>(text).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::splice::layout::Layout;
    use crate::edit::splice::tests::{layer_values, LAYOUTS};
    use crate::edit::splice::{write_compact, written};

    /// An inserted text passes only when it reads as exactly the members meant: a comma before
    /// each, the keys and values (numbers as velvet writes them), nothing after but whitespace,
    /// and no character JSON forbids.
    #[test]
    fn inserted_members_are_checked_by_reading_the_inserted_text() {
        let value =
            serde_json::json!({"fuzzFactor": 0.7499999999999999, "fuzzColorFactor": [1, 0.5]});
        let second = serde_json::json!("b");
        let members = [
            ("KHR_materials_fuzz", Meant::Value(&value)),
            ("name", Meant::Value(&second)),
        ];
        let good = ",\n  \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"\n";
        assert!(inserted_members_read_as(good, &members));
        // The members of an object in another order read as the same object.
        let reordered = ", \"KHR_materials_fuzz\": {\"fuzzColorFactor\": [1, 0.5], \"fuzzFactor\": 0.75}, \"name\": \"b\"";
        assert!(inserted_members_read_as(reordered, &members));
        for bad in [
            // No comma before the first member.
            " \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            // Another key.
            ", \"KHR_materials_fuz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            // Another number, a member missing, a member twice.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.7, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzFactor\": 0.75}, \"name\": \"b\"",
            // A number JSON does not allow, a raw control character in a string.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": .75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [01, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"na\tme\": \"b\"",
            // Something after the members.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\",",
        ] {
            assert!(!inserted_members_read_as(bad, &members), "{bad}");
        }
    }

    /// Compact text written in a file's layout is, byte for byte, what the value it holds
    /// gives, on one line and over lines, at any indentation; and it reads back as that text.
    #[test]
    fn compact_text_is_laid_out_as_its_value_is() {
        for text in LAYOUTS {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let layout = Layout::detect(text, tape.root(text));
            for value in layer_values() {
                let mut compact = String::new();
                write_compact(&value, &mut compact);
                let reread: Value = serde_json::from_str(&compact).unwrap();
                assert_eq!(reread, written(value.clone()), "{compact}");
                for (indent, inline) in [("", false), ("\t\t", false), ("    ", true), ("", true)] {
                    let mut from_value = String::new();
                    layout.write(&value, indent, inline, &mut from_value);
                    let mut from_text = String::new();
                    layout.write_text(&compact, indent, inline, &mut from_text);
                    assert_eq!(from_text, from_value, "{text:?} {compact}");
                    assert_eq!(
                        reads_as_compact(&from_text, &compact),
                        Some(from_text.len()),
                        "{from_text}"
                    );
                }
            }
        }
    }

    /// The check of a laid-out text against compact text refuses any other token, whitespace
    /// inside a token, a string with a raw control character or a bad escape, and a text that
    /// ends early; it accepts whitespace between tokens and numbers written as velvet writes
    /// the compact ones.
    #[test]
    fn laid_out_text_is_checked_against_its_compact_text_token_by_token() {
        let compact = r#"{"a":[1,0.5,true],"b":"x y","c":{}}"#;
        let good = "{\n  \"a\": [1, 0.5, true],\r\n  \"b\" : \"x y\",\t\"c\": {}\n}";
        assert_eq!(reads_as_compact(good, compact), Some(good.len()));
        let followed = format!("{compact} ,");
        assert_eq!(reads_as_compact(&followed, compact), Some(compact.len()));
        assert_eq!(
            reads_as_compact("0.75", "0.7499999999999999"),
            Some(4),
            "a number as velvet writes it"
        );
        for bad in [
            r#"{"a":[1,0. 5,true],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,tr ue],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"b":"x  y","c":{}}"#,
            r#"{"a":[1,0.25,true],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"B":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true] "b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"b":"x y","c":{}"#,
            r#"{"a":[1,0.5,1],"b":"x y","c":{}}"#,
            r#"{"a":[1,.5,true],"b":"x y","c":{}}"#,
        ] {
            assert_eq!(reads_as_compact(bad, compact), None, "{bad}");
        }
        assert_eq!(reads_as_compact("\"a\tb\"", "\"a\tb\""), None, "a raw tab");
        assert_eq!(
            reads_as_compact(r#""a\qb""#, r#""a\qb""#),
            None,
            "a bad escape"
        );
        assert_eq!(reads_as_compact("tru", "tru"), None, "not a literal");
    }

    #[test]
    fn the_read_back_check_refuses_a_text_that_holds_something_else() {
        let value = serde_json::json!({"a": [1, 0.7499999999999999], "b": "x"});
        assert!(reads_as_written(r#"{"a": [1, 0.75], "b": "x"}"#, &value));
        // The document's own spelling reads as the document too.
        assert!(reads_as_written(
            r#"{"a": [1, 0.7499999999999999], "b": "x"}"#,
            &value
        ));
        for wrong in [
            r#"{"a": [1, 0.75], "b": "y"}"#,
            r#"{"a": [1, 0.75]}"#,
            r#"{"a": [1, 0.75], "b": "x", "b": "x"}"#,
            r#"{"a": [1, 0.75], "b": "x"} {"#,
            r#"{"a": [1, 0.75] "b": "x"}"#,
            r#"{"a": [1, tru], "b": "x"}"#,
            r#"{"a": [1], "b": "x"}"#,
            r#"{"a": [1, 0.75, 2], "b": "x"}"#,
            r#"{"a": {"0": 1}, "b": "x"}"#,
            r#"{"a": [1, 0.75], "c": "x"}"#,
            r#"{"a": [1, 0.75], "b": "x", "c": 1}"#,
            r#"{"a": [1, 0.74999], "b": "x"}"#,
            r#"["a"]"#,
            "",
        ] {
            assert!(!reads_as_written(wrong, &value), "{wrong}");
        }
    }
}
