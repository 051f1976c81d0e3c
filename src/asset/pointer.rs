//! RFC 6901 JSON pointers: building them from path segments and resolving them.

use serde_json::Value;

/// Escapes one reference token (`~` → `~0`, `/` → `~1`).
pub fn escape(segment: &str) -> String {
    let mut out = String::with_capacity(segment.len());
    push_escaped(&mut out, segment);
    out
}

/// Appends `segment` to `out` escaped as [`escape`] escapes it, without a copy of its own.
pub fn push_escaped(out: &mut String, segment: &str) {
    let mut rest = segment;
    while let Some(at) = rest.find(['~', '/']) {
        out.push_str(&rest[..at]);
        out.push_str(if rest.as_bytes()[at] == b'~' {
            "~0"
        } else {
            "~1"
        });
        rest = &rest[at + 1..];
    }
    out.push_str(rest);
}

/// Undoes `escape`; borrowed when there is nothing to undo.
pub fn unescape(token: &str) -> std::borrow::Cow<'_, str> {
    // Byte by byte: tokens are short, and `str::contains`' searcher costs more than the scan.
    if !token.bytes().any(|b| b == b'~') {
        return std::borrow::Cow::Borrowed(token);
    }
    std::borrow::Cow::Owned(token.replace("~1", "/").replace("~0", "~"))
}

/// `base` followed by one more segment.
pub fn join(base: &str, segment: impl std::fmt::Display) -> String {
    use std::fmt::Write;
    // One allocation in the common case: findings build a pointer each, by the ten thousand.
    let mut out = String::with_capacity(base.len() + 24);
    out.push_str(base);
    out.push('/');
    let start = out.len();
    // Writing to a String cannot fail.
    let _ = write!(out, "{segment}");
    if out[start..].contains(['~', '/']) {
        let escaped = escape(&out[start..]);
        out.truncate(start);
        out.push_str(&escaped);
    }
    out
}

/// The array index a reference token names: decimal digits without a leading zero (but `0`),
/// as RFC 6901 and serde_json read it; `None` for any other token (`-`, a sign, `01`, a
/// number past `usize`).
pub fn array_index(token: &str) -> Option<usize> {
    let canonical = !token.is_empty()
        && token.bytes().all(|b| b.is_ascii_digit())
        && (token == "0" || !token.starts_with('0'));
    canonical.then(|| token.parse().ok()).flatten()
}

/// The reference tokens of a pointer, unescaped. `""` has none.
pub fn tokens(pointer: &str) -> Vec<String> {
    if pointer.is_empty() {
        return Vec::new();
    }
    pointer[1..]
        .split('/')
        .map(|token| unescape(token).into_owned())
        .collect()
}

/// The value a pointer names, if any.
pub fn resolve<'a>(root: &'a Value, pointer: &str) -> Option<&'a Value> {
    root.pointer(pointer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_tilde_before_slash_so_both_round_trip() {
        assert_eq!(escape("a/b~c"), "a~1b~0c");
        assert_eq!(escape("~1"), "~01");
        assert_eq!(escape("/~/"), "~1~0~1");
        assert_eq!(escape("plain"), "plain");
        assert_eq!(escape(""), "");
        let mut pointer = String::from("/materials");
        push_escaped(&mut pointer, "é/x");
        assert_eq!(pointer, "/materialsé~1x");
        assert_eq!(unescape("a~1b~0c"), "a/b~c");
        assert_eq!(unescape("~01"), "~1");
        assert_eq!(join("/extras", "x/y"), "/extras/x~1y");
        assert_eq!(tokens("/a~1b/0/~0"), vec!["a/b", "0", "~"]);
        assert!(tokens("").is_empty());
    }

    #[test]
    fn array_indices_are_digits_without_a_leading_zero_or_sign() {
        assert_eq!(array_index("0"), Some(0));
        assert_eq!(array_index("12"), Some(12));
        for token in [
            "",
            "-",
            "01",
            "00",
            "+1",
            "-1",
            "1a",
            " 1",
            "99999999999999999999999",
        ] {
            assert_eq!(array_index(token), None, "{token:?}");
        }
    }
}
