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
//! The spans come from the document's index ([`crate::asset::tape`]), built when it was loaded:
//! the source is not read a second time. No maintained crate offers format-preserving edits of
//! JSON text (toml_edit's equivalent for JSON does not exist). The check a spliced text passes
//! before it is written reads that new text with a small streaming scanner, written here for the
//! same reason.

use crate::asset::tape::{Kind, Node};
use serde_json::{Map, Value};

/// Decimal places of the numbers velvet writes.
pub const DECIMALS: i32 = 6;

/// The text of `after` written as splices into `text`, whose index `root` is (the document as
/// loaded); `None` when the splices would overlap (the caller then writes the document afresh).
/// The loaded document is read off the index as the comparison goes, never held as a whole.
pub fn rewrite(text: &str, root: Node, after: &Value) -> Option<String> {
    let layout = Layout::detect(text, root);
    let mut splices = Vec::new();
    diff(text, root, after, &layout, &mut splices);
    splices.sort_by_key(|s| (s.start, s.end));
    let mut out =
        String::with_capacity(text.len() + splices.iter().map(|s| s.text.len()).sum::<usize>());
    let mut at = 0;
    for s in &splices {
        if s.start < at {
            return None; // overlapping splices: never produced, but never risk a broken file
        }
        out.push_str(&text[at..s.start]);
        out.push_str(&s.text);
        at = s.end;
    }
    out.push_str(&text[at..]);
    Some(out)
}

/// A replacement of `text[start..end]`.
#[derive(Debug)]
struct Splice {
    start: usize,
    end: usize,
    text: String,
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

    fn string(&mut self) -> Option<()> {
        self.at += 1; // the opening quote
        loop {
            match self.peek()? {
                b'"' => {
                    self.at += 1;
                    return Some(());
                }
                b'\\' => self.at += 2,
                _ => self.at += 1,
            }
        }
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
                let mut seen = std::collections::HashSet::with_capacity(map.len());
                loop {
                    let key = key_at(self.text, self.key()?)?;
                    let Some(member) = map.get(key.as_ref()) else {
                        return Some(false);
                    };
                    if !seen.insert(key) || !self.holds(member)? {
                        return Some(false);
                    }
                    if !self.next(b'}')? {
                        return Some(seen.len() == map.len());
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
            while matches!(self.peek(), Some(b) if !matches!(b, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r'))
            {
                self.at += 1;
            }
        }
        (self.at > start).then_some((start, self.at))
    }
}

/// How the file is laid out, read once.
#[derive(Clone)]
struct Layout {
    /// The indent unit; `None` for a minified file (no line breaks).
    unit: Option<String>,
    newline: &'static str,
    /// Between a key and its value (`": "` or `":"`, from the first member in the file).
    colon: String,
    /// Between the elements of a one-line container (`", "` or `","`).
    inline_comma: String,
    /// Whether arrays of numbers are written on one line in a pretty file.
    inline_number_arrays: bool,
}

impl Layout {
    fn detect(text: &str, root: Node) -> Layout {
        let newline = if text.contains("\r\n") { "\r\n" } else { "\n" };
        let pretty = text.trim_end().contains('\n');
        let unit = pretty.then(|| {
            crate::asset::write::JsonStyle::detect(text)
                .indent
                .unwrap_or_else(|| "  ".to_string())
        });
        let mut layout = Layout {
            unit,
            newline,
            colon: ":".to_string(),
            inline_comma: ",".to_string(),
            inline_number_arrays: false,
        };
        let mut seen_colon = false;
        let mut seen_comma = false;
        let mut seen_numbers = false;
        visit(root, &mut |node| {
            let span = node.span();
            match node.kind() {
                Kind::Object => {
                    let Some(object) = node.as_object() else {
                        return true;
                    };
                    if seen_colon && (seen_comma || object.is_empty()) {
                        return true;
                    }
                    let members = object.entries();
                    if let (Some((key, value)), false) = (members.first(), seen_colon) {
                        let between = &text[key.span().start..value.span().start];
                        // The key's closing quote is the last '"' before the colon.
                        if let Some(colon) = between.rfind(':') {
                            let quote = between[..colon].rfind('"').unwrap_or(0);
                            layout.colon = between[quote + 1..].to_string();
                            seen_colon = true;
                        }
                    }
                    if members.len() >= 2 && !seen_comma && !text[span].contains('\n') {
                        layout.inline_comma =
                            text[members[0].1.span().end..members[1].0.span().start].to_string();
                        seen_comma = true;
                    }
                }
                Kind::Array => {
                    let Some(items) = node.as_array() else {
                        return true;
                    };
                    if items.len() < 2 || (seen_comma && seen_numbers) {
                        return true;
                    }
                    let (first, second) = (items.get(0), items.get(1));
                    let (Some(first), Some(second)) = (first, second) else {
                        return true;
                    };
                    let one_line = !text[span].contains('\n');
                    if !seen_comma && one_line {
                        layout.inline_comma =
                            text[first.span().end..second.span().start].to_string();
                        seen_comma = true;
                    }
                    if !seen_numbers && items.iter().all(|i| i.is_number()) {
                        layout.inline_number_arrays = one_line;
                        seen_numbers = true;
                    }
                }
                _ => {}
            }
            !(seen_colon && seen_comma && seen_numbers)
        });
        layout
    }

    /// This layout with the indent unit the container at `container_start` uses for its
    /// member at `member_start`, where the file mixes units (tabs in one place, spaces in
    /// another).
    fn local(&self, text: &str, container_start: usize, member_start: usize) -> Layout {
        let outer = line_indent(text, container_start);
        let inner = line_indent(text, member_start);
        let mut layout = self.clone();
        if self.unit.is_some() && inner.len() > outer.len() && inner.starts_with(outer) {
            layout.unit = Some(inner[outer.len()..].to_string());
        }
        layout
    }

    /// Renders `value` whose first line starts at indentation `indent`; `inline` keeps it on
    /// one line.
    fn render(&self, value: &Value, indent: &str, inline: bool) -> String {
        let mut out = String::new();
        self.write(value, indent, inline || self.unit.is_none(), &mut out);
        out
    }

    fn write(&self, value: &Value, indent: &str, inline: bool, out: &mut String) {
        match value {
            Value::Object(map) if !map.is_empty() => self.write_object(map, indent, inline, out),
            Value::Array(items) if !items.is_empty() => {
                let inline =
                    inline || (self.inline_number_arrays && items.iter().all(Value::is_number));
                if inline {
                    out.push('[');
                    for (i, item) in items.iter().enumerate() {
                        if i > 0 {
                            out.push_str(&self.inline_comma);
                        }
                        self.write(item, indent, true, out);
                    }
                    out.push(']');
                } else {
                    let inner = format!("{indent}{}", self.unit.as_deref().unwrap_or(""));
                    out.push('[');
                    for (i, item) in items.iter().enumerate() {
                        if i > 0 {
                            out.push(',');
                        }
                        out.push_str(self.newline);
                        out.push_str(&inner);
                        self.write(item, &inner, false, out);
                    }
                    out.push_str(self.newline);
                    out.push_str(indent);
                    out.push(']');
                }
            }
            Value::Number(n) => out.push_str(&number_text(n)),
            other => out.push_str(&other.to_string()),
        }
    }

    fn write_object(&self, map: &Map<String, Value>, indent: &str, inline: bool, out: &mut String) {
        if inline {
            out.push('{');
            for (i, (key, value)) in map.iter().enumerate() {
                if i > 0 {
                    out.push_str(&self.inline_comma);
                }
                out.push_str(&Value::String(key.clone()).to_string());
                out.push_str(&self.colon);
                self.write(value, indent, true, out);
            }
            out.push('}');
            return;
        }
        let inner = format!("{indent}{}", self.unit.as_deref().unwrap_or(""));
        out.push('{');
        for (i, (key, value)) in map.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(self.newline);
            out.push_str(&inner);
            out.push_str(&Value::String(key.clone()).to_string());
            out.push_str(&self.colon);
            self.write(value, &inner, false, out);
        }
        out.push_str(self.newline);
        out.push_str(indent);
        out.push('}');
    }
}

/// Calls `f` on `node` and everything inside it, depth first, until `f` returns false; false
/// when it stopped.
fn visit(node: Node, f: &mut dyn FnMut(Node) -> bool) -> bool {
    if !f(node) {
        return false;
    }
    match node.kind() {
        Kind::Object => node
            .as_object()
            .into_iter()
            .flat_map(|o| o.entries())
            .all(|(_, v)| visit(v, f)),
        Kind::Array => node
            .as_array()
            .into_iter()
            .flat_map(|a| a.iter())
            .all(|v| visit(v, f)),
        _ => true,
    }
}

/// A number as velvet writes it: its own spelling when it is already at [`DECIMALS`] decimals
/// or fewer, otherwise rounded to that many and written as the shortest decimal that reads
/// back.
pub fn number_text(n: &serde_json::Number) -> String {
    let text = n.to_string();
    let decimals = match text.find(['e', 'E']) {
        Some(_) => usize::MAX,
        None => text.find('.').map_or(0, |dot| text.len() - dot - 1),
    };
    if decimals <= DECIMALS as usize {
        return text;
    }
    let Some(x) = n.as_f64() else { return text };
    let scale = 10f64.powi(DECIMALS);
    let rounded = (x * scale).round() / scale;
    if rounded == x {
        return text; // already at that precision (`5E-1`): the spelling stays
    }
    if rounded == 0.0 {
        return "0".to_string();
    }
    // Display writes the shortest decimal that reads back as the same f64.
    format!("{rounded}")
}

/// `value` with every number as velvet writes it (see [`number_text`]): edits store what the
/// file will hold, so that planning again compares like with like.
pub fn written(value: Value) -> Value {
    match value {
        Value::Number(n) => {
            let text = number_text(&n);
            if text == n.to_string() {
                Value::Number(n)
            } else {
                serde_json::from_str(&text).map_or(Value::Number(n), Value::Number)
            }
        }
        Value::Array(items) => Value::Array(items.into_iter().map(written).collect()),
        Value::Object(map) => {
            Value::Object(map.into_iter().map(|(k, v)| (k, written(v))).collect())
        }
        other => other,
    }
}

/// The indentation of the line `at` lies on.
fn line_indent(text: &str, at: usize) -> &str {
    let line_start = text[..at].rfind('\n').map_or(0, |p| p + 1);
    let line = &text[line_start..];
    let len = line.len() - line.trim_start_matches([' ', '\t']).len();
    &line[..len]
}

fn one_line(text: &str, node: Node) -> bool {
    !text[node.span()].contains('\n')
}

fn diff(text: &str, node: Node, after: &Value, layout: &Layout, out: &mut Vec<Splice>) {
    if matches(node, after, Compare::Exact) {
        return;
    }
    match (node.kind(), after) {
        (Kind::Object, Value::Object(a)) => diff_object(text, node, a, layout, out),
        (Kind::Array, Value::Array(a))
            if node.as_array().is_some_and(|items| a.len() >= items.len()) =>
        {
            let items = node.as_array().expect("an array");
            for (item, new) in items.iter().zip(a) {
                diff(text, item, new, layout, out);
            }
            if a.len() > items.len() {
                append(
                    text,
                    node,
                    items.iter().next_back().map(|i| i.span().end),
                    &a[items.len()..],
                    layout,
                    out,
                );
            }
        }
        _ => replace(text, node, after, layout, out),
    }
}

/// How [`matches`] compares numbers.
#[derive(Clone, Copy, PartialEq)]
enum Compare {
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

/// True when the value `node` is `value`.
fn matches(node: Node, value: &Value, compare: Compare) -> bool {
    match (node.kind(), value) {
        (Kind::Object, Value::Object(map)) => {
            let Some(object) = node.as_object() else {
                return false;
            };
            // A key written twice never matches: the object is written anew.
            !object.has_duplicate_keys()
                && object.len() == map.len()
                && object.iter().all(|(key, member)| {
                    map.get(key.as_ref())
                        .is_some_and(|v| matches(member, v, compare))
                })
        }
        (Kind::Array, Value::Array(values)) => node.as_array().is_some_and(|items| {
            items.len() == values.len()
                && items
                    .iter()
                    .zip(values)
                    .all(|(item, v)| matches(item, v, compare))
        }),
        (Kind::Object | Kind::Array, _) => false,
        _ => scalar_matches(node.raw(), value, compare),
    }
}

/// True when the scalar written `raw` is `value`.
fn scalar_matches(raw: &str, value: &Value, compare: Compare) -> bool {
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

/// Writes `after` over `span`: on one line where the old value was a one-line container, laid
/// out over lines (at the indentation of the line it starts on) where it was a scalar or a
/// multi-line container.
fn replace(text: &str, node: Node, after: &Value, layout: &Layout, out: &mut Vec<Splice>) {
    let was_one_line_container =
        matches!(node.kind(), Kind::Object | Kind::Array) && one_line(text, node);
    let span = node.span();
    out.push(Splice {
        start: span.start,
        end: span.end,
        text: layout.render(after, line_indent(text, span.start), was_one_line_container),
    });
}

fn diff_object(
    text: &str,
    span: Node,
    after: &Map<String, Value>,
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(object) = span.as_object() else {
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    };
    if object.has_duplicate_keys() {
        // A key twice: the object is written anew, in place.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    // (where the key's opening quote stands, the value), and the keys decoded.
    let entries = object.entries();
    let members: Vec<(usize, Node)> = entries.iter().map(|(k, v)| (k.span().start, *v)).collect();
    let keys: Vec<std::borrow::Cow<str>> = entries
        .iter()
        .map(|(k, _)| k.as_str().unwrap_or_default())
        .collect();
    let removed: Vec<bool> = keys
        .iter()
        .map(|k| !after.contains_key(k.as_ref()))
        .collect();
    let added: Vec<(&String, &Value)> = after
        .iter()
        .filter(|(k, _)| !keys.iter().any(|have| have == *k))
        .collect();
    let any_removed = removed.iter().any(|r| *r);
    if any_removed && (!added.is_empty() || removed.iter().all(|r| *r)) {
        // Members both leave and arrive, or all leave: the object is written anew, in place.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    for (i, ((key_start, value), key)) in members.iter().zip(&keys).enumerate() {
        if removed[i] {
            let (start, end) = match (i, members.get(i + 1)) {
                // A member after the first takes the separator before it.
                (i, _) if i > 0 => (members[i - 1].1.span().end, value.span().end),
                // The first member takes the separator after it.
                (_, Some((next_key, _))) => (*key_start, *next_key),
                (_, None) => unreachable!("an object whose members all leave is replaced"),
            };
            out.push(Splice {
                start,
                end,
                text: String::new(),
            });
        } else {
            diff(text, *value, &after[key.as_ref()], layout, out);
        }
    }
    if added.is_empty() {
        return;
    }
    if members.is_empty() {
        // An empty object: written anew with its members.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    let layout = &layout.local(text, span.span().start, members[0].0);
    let inline = layout.unit.is_none() || one_line(text, span);
    let indent = line_indent(text, members[0].0).to_string();
    let separator = if inline {
        members
            .get(1)
            .map(|(k, _)| text[members[0].1.span().end..*k].to_string())
            .unwrap_or_else(|| layout.inline_comma.clone())
    } else {
        format!(",{}{indent}", layout.newline)
    };
    let member_text = |key: &str, value: &Value| {
        format!(
            "{}{}{}",
            Value::String(key.to_string()),
            layout.colon,
            layout.render(value, &indent, inline)
        )
    };
    // A new key goes after the member that precedes it in the edited document (the edit
    // applier puts `extensionsUsed` after `asset`, say), or first when none does.
    let position: std::collections::HashMap<&str, usize> = keys
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_ref(), i))
        .collect();
    let mut anchor: Option<usize> = None;
    let mut leading = String::new();
    let mut after_member: Vec<(usize, String)> = Vec::new();
    for (key, value) in after {
        match position.get(key.as_str()) {
            Some(i) => anchor = Some(*i),
            None => match anchor {
                None => {
                    leading.push_str(&member_text(key, value));
                    leading.push_str(&separator);
                }
                Some(i) => match after_member.last_mut() {
                    Some((at, insert)) if *at == i => {
                        insert.push_str(&separator);
                        insert.push_str(&member_text(key, value));
                    }
                    _ => after_member.push((i, separator.clone() + &member_text(key, value))),
                },
            },
        }
    }
    if !leading.is_empty() {
        out.push(Splice {
            start: members[0].0,
            end: members[0].0,
            text: leading,
        });
    }
    for (i, insert) in after_member {
        let end = members[i].1.span().end;
        out.push(Splice {
            start: end,
            end,
            text: insert,
        });
    }
}

fn append(
    text: &str,
    span: Node,
    last_end: Option<usize>,
    items: &[Value],
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(last_end) = last_end else {
        // An empty array: written anew with its elements.
        let mut all = Vec::with_capacity(items.len());
        all.extend_from_slice(items);
        return replace(text, span, &Value::Array(all), layout, out);
    };
    let inline = layout.unit.is_none() || one_line(text, span);
    let Some(existing) = span.as_array() else {
        return;
    };
    let (Some(first), Some(last)) = (existing.get(0), existing.iter().next_back()) else {
        return;
    };
    let layout = &layout.local(text, span.span().start, first.span().start);
    let indent = line_indent(text, last.span().start).to_string();
    let separator = if inline {
        existing
            .get(1)
            .map(|second| text[first.span().end..second.span().start].to_string())
            .unwrap_or_else(|| layout.inline_comma.clone())
    } else {
        format!(",{}{indent}", layout.newline)
    };
    let mut insert = String::new();
    for item in items {
        insert.push_str(&separator);
        insert.push_str(&layout.render(item, &indent, inline));
    }
    out.push(Splice {
        start: last_end,
        end: last_end,
        text: insert,
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `after` written as splices into `text`.
    fn spliced(text: &str, after: &Value) -> String {
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        rewrite(text, tape.root(text), after).unwrap()
    }

    /// Applies `edit` to the parsed `text` and splices the result back.
    fn edited(text: &str, edit: impl FnOnce(&mut Value)) -> String {
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = before.clone();
        edit(&mut after);
        let out = spliced(text, &after);
        let reread: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(
            reread, after,
            "the spliced text reads back as the edited document"
        );
        assert!(reads_as_written(&out, &after));
        out
    }

    fn add_fuzz(doc: &mut Value) {
        doc["materials"][0]["extensions"]["KHR_materials_fuzz"] =
            serde_json::json!({"fuzzColorFactor": [0.5, 0.25, 1.0], "fuzzRoughnessFactor": 0.5});
    }

    #[test]
    fn a_key_goes_into_its_object_in_the_files_layout() {
        let text = "{\n\t\"materials\": [\n\t\t{\n\t\t\t\"extensions\": {\n\t\t\t\t\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1, 1]}\n\t\t\t}\n\t\t}\n\t]\n}";
        let out = edited(text, add_fuzz);
        assert_eq!(
            out,
            "{\n\t\"materials\": [\n\t\t{\n\t\t\t\"extensions\": {\n\t\t\t\t\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1, 1]},\n\t\t\t\t\"KHR_materials_fuzz\": {\n\t\t\t\t\t\"fuzzColorFactor\": [0.5, 0.25, 1.0],\n\t\t\t\t\t\"fuzzRoughnessFactor\": 0.5\n\t\t\t\t}\n\t\t\t}\n\t\t}\n\t]\n}"
        );
    }

    #[test]
    fn a_minified_file_stays_minified_and_crlf_stays_crlf() {
        let text = r#"{"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":1E-1}}}]}"#;
        assert_eq!(
            edited(text, add_fuzz),
            r#"{"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":1E-1},"KHR_materials_fuzz":{"fuzzColorFactor":[0.5,0.25,1.0],"fuzzRoughnessFactor":0.5}}}]}"#
        );
        let text = "{\r\n  \"asset\": {\"version\": \"2.0\"},\r\n  \"extensionsUsed\": [\r\n    \"KHR_materials_sheen\"\r\n  ]\r\n}\r\n";
        let out = edited(text, |d| {
            d["extensionsUsed"]
                .as_array_mut()
                .unwrap()
                .push("KHR_materials_fuzz".into())
        });
        assert_eq!(
            out,
            "{\r\n  \"asset\": {\"version\": \"2.0\"},\r\n  \"extensionsUsed\": [\r\n    \"KHR_materials_sheen\",\r\n    \"KHR_materials_fuzz\"\r\n  ]\r\n}\r\n"
        );
    }

    #[test]
    fn one_line_objects_stay_on_one_line_and_untouched_spellings_stay() {
        let text = "{\n    \"a\": {\"x\": 1.0, \"y\": \"\\u00e9\"},\n    \"b\": 3E2\n}";
        let out = edited(text, |d| d["a"]["z"] = serde_json::json!([1, 2]));
        assert_eq!(
            out,
            "{\n    \"a\": {\"x\": 1.0, \"y\": \"\\u00e9\", \"z\": [1, 2]},\n    \"b\": 3E2\n}"
        );
    }

    #[test]
    fn a_changed_value_replaces_its_span_and_a_removed_member_takes_its_separator() {
        let text = "{\n  \"a\": 0.5,\n  \"b\": [1, 2],\n  \"c\": true\n}\n";
        let out = edited(text, |d| {
            d["a"] = serde_json::json!(0.25);
            d.as_object_mut().unwrap().remove("b");
        });
        assert_eq!(out, "{\n  \"a\": 0.25,\n  \"c\": true\n}\n");
        // A computed value with float noise is written rounded.
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = before.clone();
        after["a"] = serde_json::json!(0.7499999999999999);
        assert_eq!(
            spliced(text, &after),
            "{\n  \"a\": 0.75,\n  \"b\": [1, 2],\n  \"c\": true\n}\n"
        );
        let out = edited(text, |d| {
            d.as_object_mut().unwrap().remove("a");
        });
        assert_eq!(out, "{\n  \"b\": [1, 2],\n  \"c\": true\n}\n");
    }

    #[test]
    fn numbers_are_rounded_to_six_decimals_and_written_shortest() {
        let n = |x: f64| number_text(&serde_json::Number::from_f64(x).unwrap());
        assert_eq!(n(0.7499999999999999), "0.75");
        assert_eq!(n(7.590065448456657e-8), "0");
        assert_eq!(n(0.1234565), "0.123457");
        assert_eq!(n(0.5), "0.5");
        assert_eq!(n(1.0), "1.0");
        let spelled: serde_json::Number = serde_json::from_str("1E-1").unwrap();
        assert_eq!(number_text(&spelled), "1e-1"); // serde_json's own spelling of 1E-1
        let noisy: serde_json::Number = serde_json::from_str("7.5E-8").unwrap();
        assert_eq!(number_text(&noisy), "0");
    }

    #[test]
    fn a_new_key_follows_the_key_before_it_in_the_edited_document() {
        let text = "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"materials\": []\n}\n";
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = serde_json::Map::new();
        after.insert("first".into(), serde_json::json!(1));
        after.insert("asset".into(), before["asset"].clone());
        after.insert(
            "extensionsUsed".into(),
            serde_json::json!(["KHR_materials_fuzz"]),
        );
        after.insert("materials".into(), serde_json::json!([]));
        assert_eq!(
            spliced(text, &Value::Object(after)),
            "{\n  \"first\": 1,\n  \"asset\": {\"version\": \"2.0\"},\n  \"extensionsUsed\": [\n    \"KHR_materials_fuzz\"\n  ],\n  \"materials\": []\n}\n"
        );
    }

    #[test]
    fn written_values_hold_what_the_file_will_hold() {
        let value = written(serde_json::json!({"a": [0.30000000000000004, 1.0, 2], "b": "x"}));
        assert_eq!(value.to_string(), r#"{"a":[0.3,1.0,2],"b":"x"}"#);
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

    #[test]
    fn an_unchanged_document_is_the_same_text() {
        let text = "{ \"a\" :[ 1 ,2 ] ,\"b\":{} }";
        assert_eq!(edited(text, |_| {}), text);
    }
}
