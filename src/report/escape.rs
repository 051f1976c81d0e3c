//! Text that came from an asset (URIs, names, keys, paths), made safe to print. An asset is
//! untrusted: a name holding `ESC ] 0; … BEL` retitles a terminal, one holding a newline and
//! `::error file=…::` starts a line that GitHub Actions takes for a workflow command. Every
//! renderer of text for people (validate's text and GitHub formats, migrate's and bake's text
//! reports) passes such text through [`terminal`], which shows each character that could act
//! rather than print as its escape (`\u001b`), so the line stays one line and says what the
//! asset holds. The JSON and SARIF reports need nothing more: JSON escapes control characters.

use std::borrow::Cow;
use std::fmt::Write;

/// Whether `c` is shown as its escape: the C0 and C1 control characters and DEL (newlines,
/// ESC, BEL…), the line and paragraph separators, and the bidirectional overrides and isolates,
/// which reorder what a terminal or a log viewer shows.
fn acts(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{2028}' | '\u{2029}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with every control character, line or paragraph separator and bidirectional mark
/// shown as `\uXXXX` (its code point in four hex digits, as JSON writes it).
pub fn terminal(text: &str) -> Cow<'_, str> {
    if !text.chars().any(acts) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if acts(c) {
            let _ = write!(out, "\\u{:04x}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// Appends `line` to `out` as one line: escaped by [`terminal`] (a newline inside it shown as
/// `\u000a`, not started), then a newline. For renderers whose lines mix velvet's words with
/// an asset's text.
pub fn push_line(out: &mut String, line: &str) {
    out.push_str(&terminal(line));
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_and_reordering_marks_are_shown_as_their_escapes() {
        assert_eq!(terminal("cloth"), Cow::Borrowed("cloth"));
        assert_eq!(
            terminal("x\n::error file=README.md::INJECTED\r\n.png"),
            "x\\u000a::error file=README.md::INJECTED\\u000d\\u000a.png"
        );
        assert_eq!(
            terminal("\u{1b}]0;owned\u{7}\u{7f}\u{9b}"),
            "\\u001b]0;owned\\u0007\\u007f\\u009b"
        );
        assert_eq!(
            terminal("a\u{202e}b\u{2066}c\u{2028}"),
            "a\\u202eb\\u2066c\\u2028"
        );
        // Printable text beyond ASCII stays as it is.
        assert_eq!(terminal("velours é 絨"), "velours é 絨");
    }

    #[test]
    fn a_pushed_line_is_one_line() {
        let mut out = String::new();
        push_line(&mut out, "material 0 \"a\nb\": skipped");
        assert_eq!(out, "material 0 \"a\\u000ab\": skipped\n");
    }
}
