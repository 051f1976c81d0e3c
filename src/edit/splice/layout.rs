//! The file's own layout, read from the text as loaded, and new values written in it: its
//! indent unit (tabs or N spaces, and a container's own unit where the file mixes them), its
//! line ending, its spacing after `:` and `,`; an object or array written on one line stays on
//! one line, a minified file stays minified, and arrays of numbers are inline when the file
//! writes them so. A value is written from a `Value` or, one pass over its text, from compact
//! text ([`Layout::write_text`]).

use super::numbers::with_written_number;
use super::read_back::{scalar_end, string_end};
use crate::asset::json_text::push_quoted;
use crate::asset::tape::{Kind, Node};
use serde_json::{Map, Value};

/// How the file is laid out, read once; what only some edits need (the comma of a one-line
/// container, whether number arrays are inline) is read on first use: a pretty-printed file
/// without one-line containers proves it only by a walk of the whole document, 9 ms of a
/// 10 MB library's migration that most migrations never use.
#[derive(Clone)]
pub(super) struct Layout<'t> {
    /// The indent unit; `None` for a minified file (no line breaks).
    pub(super) unit: Option<String>,
    pub(super) newline: &'static str,
    /// Between a key and its value (`": "` or `":"`, from the first member in the file).
    pub(super) colon: String,
    /// The document, for what is read on first use; `None` for [`Layout::compact`], which
    /// reads nothing.
    root: Option<Node<'t>>,
    /// Between the elements of a one-line container (`", "` or `","`), from the first such
    /// container in the file.
    inline_comma: std::sync::Arc<std::sync::OnceLock<String>>,
    /// Whether arrays of numbers are written on one line in a pretty file, as the first array
    /// of two or more numbers in the file is.
    inline_number_arrays: std::sync::Arc<std::sync::OnceLock<bool>>,
    /// Where the text's line breaks are, found on first use (shared by the local layouts).
    line_breaks: std::sync::Arc<std::sync::OnceLock<LineBreaks>>,
}

/// The line breaks of one text, and which text (its address and length) they are of.
struct LineBreaks {
    text: (usize, usize),
    at: Vec<u32>,
}

impl<'t> Layout<'t> {
    pub(super) fn detect(text: &str, root: Node<'t>) -> Layout<'t> {
        // Searched with memchr's SIMD scans: `str::contains("\r\n")` went through the whole
        // of a text without one (the library's 9.8 MB: some 12 million instructions, for
        // each splice of a fix).
        let newline = if memchr::memmem::find(text.as_bytes(), b"\r\n").is_some() {
            "\r\n"
        } else {
            "\n"
        };
        let pretty = memchr::memchr(b'\n', text.trim_end().as_bytes()).is_some();
        let unit = pretty.then(|| {
            crate::edit::write::JsonStyle::detect(text)
                .indent
                .unwrap_or_else(|| "  ".to_string())
        });
        let mut colon = ":".to_string();
        visit(root, &mut |node| {
            let Some((key, value)) = node.as_object().and_then(|o| o.entries().first().copied())
            else {
                return true;
            };
            let between = &text[key.span().start..value.span().start];
            // The key's closing quote is the last '"' before the colon.
            match between.rfind(':') {
                Some(at) => {
                    let quote = between[..at].rfind('"').unwrap_or(0);
                    colon = between[quote + 1..].to_string();
                    false
                }
                None => true,
            }
        });
        Layout {
            unit,
            newline,
            colon,
            root: Some(root),
            inline_comma: Default::default(),
            inline_number_arrays: Default::default(),
            line_breaks: Default::default(),
        }
    }

    /// Between the elements of a one-line container.
    pub(super) fn inline_comma(&self) -> &str {
        self.inline_comma.get_or_init(|| {
            let mut comma = ",".to_string();
            let Some(root) = self.root else {
                return comma;
            };
            let text = root.text();
            visit(root, &mut |node| {
                // The first object with two members or array with two elements on one line.
                let pair = match node.kind() {
                    Kind::Object => node.as_object().and_then(|o| {
                        let members = o.entries();
                        Some((
                            members.first()?.1.span().end,
                            members.get(1)?.0.span().start,
                        ))
                    }),
                    Kind::Array => node
                        .as_array()
                        .and_then(|a| Some((a.get(0)?.span().end, a.get(1)?.span().start))),
                    _ => None,
                };
                match pair {
                    Some((end, start)) if one_line(text, node) => {
                        comma = text[end..start].to_string();
                        false
                    }
                    _ => true,
                }
            });
            comma
        })
    }

    /// Whether arrays of numbers are written on one line.
    fn inline_number_arrays(&self) -> bool {
        *self.inline_number_arrays.get_or_init(|| {
            let mut inline = false;
            let Some(root) = self.root else {
                return inline;
            };
            visit(root, &mut |node| match node.as_array() {
                Some(items) if items.len() >= 2 && items.iter().all(|i| i.is_number()) => {
                    inline = one_line(root.text(), node);
                    false
                }
                _ => true,
            });
            inline
        })
    }

    /// The layout of compact text: one line, `:` and `,` with no space.
    pub(super) fn compact() -> &'static Layout<'static> {
        static COMPACT: std::sync::LazyLock<Layout<'static>> =
            std::sync::LazyLock::new(|| Layout {
                unit: None,
                newline: "\n",
                colon: ":".to_string(),
                root: None,
                inline_comma: std::sync::Arc::new(std::sync::OnceLock::from(",".to_string())),
                inline_number_arrays: Default::default(),
                line_breaks: Default::default(),
            });
        &COMPACT
    }

    /// This layout with the indent unit the container at `container_start` uses for its
    /// member at `member_start`, where the file mixes units (tabs in one place, spaces in
    /// another).
    /// Borrowed where the unit is the file's own (a layout is not copied for every insertion).
    pub(super) fn local(
        &self,
        text: &str,
        container_start: usize,
        member_start: usize,
    ) -> std::borrow::Cow<'_, Layout<'t>> {
        let outer = self.line_indent(text, container_start);
        let inner = self.line_indent(text, member_start);
        if self.unit.is_some() && inner.len() > outer.len() && inner.starts_with(outer) {
            let unit = &inner[outer.len()..];
            if self.unit.as_deref() != Some(unit) {
                let mut layout = self.clone();
                layout.unit = Some(unit.to_string());
                return std::borrow::Cow::Owned(layout);
            }
        }
        std::borrow::Cow::Borrowed(self)
    }

    /// Renders `value` whose first line starts at indentation `indent`; `inline` keeps it on
    /// one line.
    pub(super) fn render(&self, value: &Value, indent: &str, inline: bool) -> String {
        let mut out = String::new();
        self.write(value, indent, inline || self.unit.is_none(), &mut out);
        out
    }

    pub(super) fn write(&self, value: &Value, indent: &str, inline: bool, out: &mut String) {
        match value {
            Value::Object(map) if !map.is_empty() => self.write_object(map, indent, inline, out),
            Value::Array(items) if !items.is_empty() => {
                let inline =
                    inline || (items.iter().all(Value::is_number) && self.inline_number_arrays());
                if inline {
                    out.push('[');
                    for (i, item) in items.iter().enumerate() {
                        if i > 0 {
                            out.push_str(self.inline_comma());
                        }
                        self.write(item, indent, true, out);
                    }
                    out.push(']');
                } else {
                    let inner = concat(&[indent, self.unit.as_deref().unwrap_or("")]);
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
            Value::Number(n) => with_written_number(n.as_str(), |text| out.push_str(text)),
            Value::String(text) => push_quoted(out, text),
            other => out.push_str(&other.to_string()),
        }
    }

    /// Writes the value `compact` holds (as [`write_compact`] writes it) as [`Layout::write`]
    /// writes that value, byte for byte, in one pass over the text: a layer object a
    /// conversion wrote as text is laid out without being read into a value. What is not such
    /// text is written as it comes (the check of the written text then refuses it).
    ///
    /// [`write_compact`]: super::write_compact
    pub(super) fn write_text(&self, compact: &str, indent: &str, inline: bool, out: &mut String) {
        let bytes = compact.as_bytes();
        let unit = self.unit.as_deref().unwrap_or("");
        // Containers are written over lines from the outermost down to the first written on
        // one line (whatever is inside a one-line container is on that line too), so the open
        // containers over lines are the outermost `lines` of the `depth` open: no list of them
        // is kept, and the indentation is `indent` and `lines` units.
        let (mut depth, mut lines) = (0usize, 0usize);
        let new_line = |out: &mut String, lines: usize| {
            out.push_str(self.newline);
            out.push_str(indent);
            (0..lines).for_each(|_| out.push_str(unit));
        };
        let mut at = 0;
        while let Some(&byte) = bytes.get(at) {
            let here_inline = if depth == 0 { inline } else { depth > lines };
            match byte {
                b'{' | b'[' => {
                    let close = if byte == b'{' { b'}' } else { b']' };
                    if bytes.get(at + 1) == Some(&close) {
                        out.push_str(&compact[at..at + 2]);
                        at += 2;
                        continue;
                    }
                    let one_line = here_inline
                        || (byte == b'['
                            && only_numbers_follow(&compact[at + 1..])
                            && self.inline_number_arrays());
                    depth += 1;
                    out.push(char::from(byte));
                    if !one_line {
                        lines += 1;
                        new_line(out, lines);
                    }
                    at += 1;
                }
                b'}' | b']' => {
                    if depth > 0 && depth == lines {
                        lines -= 1;
                        new_line(out, lines);
                    }
                    depth = depth.saturating_sub(1);
                    out.push(char::from(byte));
                    at += 1;
                }
                b',' => {
                    if here_inline {
                        out.push_str(self.inline_comma());
                    } else {
                        out.push(',');
                        new_line(out, lines);
                    }
                    at += 1;
                }
                b':' => {
                    out.push_str(&self.colon);
                    at += 1;
                }
                b'"' => {
                    // Quoted as velvet quotes, as `write` quotes the string it holds.
                    let end = string_end(bytes, at).unwrap_or(bytes.len());
                    out.push_str(&compact[at..end]);
                    at = end;
                }
                _ => {
                    let end = scalar_end(bytes, at);
                    with_written_number(&compact[at..end], |text| out.push_str(text));
                    at = end.max(at + 1);
                }
            }
        }
    }

    fn write_object(&self, map: &Map<String, Value>, indent: &str, inline: bool, out: &mut String) {
        if inline {
            out.push('{');
            for (i, (key, value)) in map.iter().enumerate() {
                if i > 0 {
                    out.push_str(self.inline_comma());
                }
                push_quoted(out, key);
                out.push_str(&self.colon);
                self.write(value, indent, true, out);
            }
            out.push('}');
            return;
        }
        let inner = concat(&[indent, self.unit.as_deref().unwrap_or("")]);
        out.push('{');
        for (i, (key, value)) in map.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(self.newline);
            out.push_str(&inner);
            push_quoted(out, key);
            out.push_str(&self.colon);
            self.write(value, &inner, false, out);
        }
        out.push_str(self.newline);
        out.push_str(indent);
        out.push('}');
    }
}

/// Whether the elements of a compact array, from its first element to its `]`, are all
/// numbers (each starts with a digit or a sign, and a number holds no `,` or `]`).
fn only_numbers_follow(elements: &str) -> bool {
    let mut rest = elements.as_bytes();
    loop {
        if !matches!(rest.first(), Some(b'-' | b'0'..=b'9')) {
            return false;
        }
        match rest.iter().position(|&b| b == b',' || b == b']') {
            Some(at) if rest[at] == b',' => rest = &rest[at + 1..],
            Some(_) => return true,
            None => return false,
        }
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

impl Layout<'_> {
    /// The indentation of the line `at` lies on. The line's start is searched for backwards
    /// over a short stretch (a pretty document's line); past that, line breaks are looked up:
    /// in a minified document (one line) a backward search from every edit would read the
    /// whole text before it each time. The table of line breaks is made only then, so a pretty
    /// document does not hold one (2 MiB for a 10 MB library).
    ///
    /// Once a line longer than that stretch has been met (always, in a minified document), the
    /// table is used for every later edit too: a backward search that finds no line break reads
    /// the whole stretch, and doing so for each of a minified library's 20,000 edits took more
    /// than half of its migration. The table names the text it was made of, so a layout asked
    /// about another text (the shared compact layout) never reads a table that is not its own.
    pub(super) fn line_indent<'t>(&self, text: &'t str, at: usize) -> &'t str {
        const NEAR: usize = 4096;
        let key = (text.as_ptr() as usize, text.len());
        let table = |build: bool| {
            let made = if build {
                Some(self.line_breaks.get_or_init(|| LineBreaks {
                    text: key,
                    at: text.match_indices('\n').map(|(i, _)| i as u32).collect(),
                }))
            } else {
                self.line_breaks.get()
            };
            made.filter(|t| t.text == key).map(|t| t.at.as_slice())
        };
        let after_break = |breaks: &[u32]| {
            let before = breaks.partition_point(|&b| (b as usize) < at);
            before.checked_sub(1).map_or(0, |i| breaks[i] as usize + 1)
        };
        let scan = |from: usize| {
            text.as_bytes()[from..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map(|i| from + i + 1)
        };
        let line_start = match table(self.unit.is_none()) {
            Some(breaks) => after_break(breaks),
            None => {
                let from = at.saturating_sub(NEAR);
                match scan(from) {
                    Some(start) => start,
                    None if from == 0 => 0,
                    None => match table(true) {
                        Some(breaks) => after_break(breaks),
                        None => scan(0).unwrap_or(0),
                    },
                }
            }
        };
        let line = &text[line_start..];
        let len = line.len() - line.trim_start_matches([' ', '\t']).len();
        &line[..len]
    }
}

/// `parts` joined, in a string made at its size (`format!` took a tenth of writing a layer
/// object, by the twenty thousand).
pub(super) fn concat(parts: &[&str]) -> String {
    let mut out = String::with_capacity(parts.iter().map(|p| p.len()).sum());
    parts.iter().for_each(|p| out.push_str(p));
    out
}

pub(super) fn one_line(text: &str, node: Node) -> bool {
    !text[node.span()].contains('\n')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_indent_is_the_indentation_of_the_line_a_position_lies_on() {
        let text = "{\r\n\t\"a\": {\r\n\t\t\"b\": 1\r\n\t},\n    \"c\": 2}";
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let layout = Layout::detect(text, tape.root(text));
        let at = |needle: &str| text.find(needle).unwrap();
        assert_eq!(layout.line_indent(text, 0), "");
        assert_eq!(layout.line_indent(text, at("\"a\"")), "\t");
        assert_eq!(layout.line_indent(text, at("\"b\"")), "\t\t");
        assert_eq!(layout.line_indent(text, at("1")), "\t\t");
        assert_eq!(layout.line_indent(text, at("\"c\"")), "    ");
        assert_eq!(layout.line_indent(text, text.len()), "    ");
        let minified = r#"{"a":{"b":1},"c":2}"#;
        let tape = crate::asset::tape::Tape::build(minified).unwrap();
        let layout = Layout::detect(minified, tape.root(minified));
        assert_eq!(
            layout.line_indent(minified, minified.find("\"c\"").unwrap()),
            ""
        );
    }

    #[test]
    fn a_minified_layout_asked_about_two_texts_reads_each_texts_own_lines() {
        // A minified document's layout looks line starts up in a table from the first text it
        // is asked about; a second text must not be read through the first one's table.
        let minified = r#"{"a":{"b":1},"c":2}"#;
        let tape = crate::asset::tape::Tape::build(minified).unwrap();
        let layout = Layout::detect(minified, tape.root(minified));
        let first = "{\n  \"a\": 1}";
        assert_eq!(
            layout.line_indent(first, first.find("\"a\"").unwrap()),
            "  "
        );
        let second = "{\t \"b\": 2}";
        assert_eq!(
            layout.line_indent(second, second.find("\"b\"").unwrap()),
            ""
        );
        // A long line of a pretty document: the table is made then, and used after.
        let long = format!("{{\n  \"x\": [{}1],\n\t\"y\": 2}}", "1, ".repeat(3000));
        let tape = crate::asset::tape::Tape::build(&long).unwrap();
        let layout = Layout::detect(&long, tape.root(&long));
        assert_eq!(layout.line_indent(&long, long.rfind("1]").unwrap()), "  ");
        assert_eq!(layout.line_indent(&long, long.find("\"y\"").unwrap()), "\t");
    }
}
