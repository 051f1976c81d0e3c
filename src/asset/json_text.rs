//! JSON string text, read and written: where a run of plain string text ends, for the index
//! builder ([`crate::asset::tape`]), and a string written as serde_json writes it, for the
//! JSON report and the splice writer. One scanner serves both directions: the bytes that end a
//! plain run when reading (quote, backslash, control character) are the bytes a writer must
//! escape.

/// Where the first byte that ends a run of plain string text stands: a quote, a backslash or a
/// control character. Eight bytes are tested at a time (the bit tricks for "has a zero byte" and
/// "has a byte below n"): strings are most of a glTF's bytes, keys and URIs among them. In each
/// test only bytes above a true hit can be false hits, so the lowest hit of the three is exact.
pub fn string_stop(bytes: &[u8]) -> Option<usize> {
    const ONES: u64 = u64::from_ne_bytes([1; 8]);
    const HIGHS: u64 = u64::from_ne_bytes([0x80; 8]);
    let zero_in = |v: u64| v.wrapping_sub(ONES) & !v;
    let mut at = 0;
    while let Some(word) = bytes.get(at..at + 8) {
        let w = u64::from_le_bytes(word.try_into().expect("eight bytes"));
        let hits = (zero_in(w ^ (ONES * u64::from(b'"')))
            | zero_in(w ^ (ONES * u64::from(b'\\')))
            | (w.wrapping_sub(ONES * 0x20) & !w))
            & HIGHS;
        if hits != 0 {
            return Some(at + (hits.trailing_zeros() / 8) as usize);
        }
        at += 8;
    }
    bytes[at..]
        .iter()
        .position(|&b| b == b'"' || b == b'\\' || b < 0x20)
        .map(|i| at + i)
}

/// `text` as a JSON string, escaped as serde_json escapes it: quote, backslash and control
/// characters (`\b \f \n \r \t` by name, the others as `\u00xx`), nothing else. Plain runs
/// are found eight bytes at a time ([`string_stop`]) and copied whole.
pub fn push_quoted(out: &mut String, text: &str) {
    let mut rest = text;
    out.push('"');
    while let Some(stop) = string_stop(rest.as_bytes()) {
        // The stop is an ASCII byte, so a character boundary on both sides.
        out.push_str(&rest[..stop]);
        match rest.as_bytes()[stop] {
            b'"' => out.push_str("\\\""),
            b'\\' => out.push_str("\\\\"),
            0x08 => out.push_str("\\b"),
            0x0C => out.push_str("\\f"),
            b'\n' => out.push_str("\\n"),
            b'\r' => out.push_str("\\r"),
            b'\t' => out.push_str("\\t"),
            control => {
                const HEX: &[u8; 16] = b"0123456789abcdef";
                out.push_str("\\u00");
                out.push(char::from(HEX[usize::from(control >> 4)]));
                out.push(char::from(HEX[usize::from(control & 0xF)]));
            }
        }
        rest = &rest[stop + 1..];
    }
    out.push_str(rest);
    out.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_written_as_serde_json_writes_them() {
        let ascii: String = (0u8..=0x7F).map(char::from).collect();
        let shifted: String = ascii.chars().cycle().skip(37).take(300).collect();
        for text in [
            ascii.as_str(),
            shifted.as_str(),
            "",
            "plain text past eight bytes",
            "é\u{1F600}\u{2028}\u{7f}",
            "\"\\\"\\",
            "a\u{0}b",
        ] {
            let mut ours = String::new();
            push_quoted(&mut ours, text);
            assert_eq!(ours, serde_json::to_string(text).unwrap());
        }
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The word-at-a-time scan stops where a byte-at-a-time scan does, on any bytes.
        #[test]
        fn string_stop_finds_the_first_quote_backslash_or_control_byte(
            bytes in prop::collection::vec(
                prop_oneof![Just(b'"'), Just(b'\\'), 0u8..0x20, 0x20u8..=0xFF, 0x20u8..0x7F],
                0..40,
            ),
        ) {
            let expected = bytes.iter().position(|&b| b == b'"' || b == b'\\' || b < 0x20);
            prop_assert_eq!(string_stop(&bytes), expected);
        }
    }
}
