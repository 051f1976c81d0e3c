//! How velvet writes numbers: rounded to [`DECIMALS`] decimal places and written as the
//! shortest decimal that reads back as that value, with no float noise such as
//! `0.7499999999999999`; a number already at that precision (copied from the input, or an
//! integer) keeps its spelling. The writer, the read-back checks and the digests all spell
//! numbers here, so a number is checked as it is written.

use serde_json::Value;

/// Decimal places of the numbers velvet writes.
pub const DECIMALS: i32 = 6;

/// A number as velvet writes it: its own spelling when it is already at [`DECIMALS`] decimals
/// or fewer, otherwise rounded to that many and written as the shortest decimal that reads
/// back.
pub fn number_text(n: &serde_json::Number) -> String {
    raw_number_text(n.as_str()).into_owned()
}

/// [`number_text`] of a number written `text` (as serde_json writes and reads numbers, with
/// their spelling kept): borrowed exactly when the spelling stays.
fn raw_number_text(text: &str) -> std::borrow::Cow<'_, str> {
    use std::borrow::Cow;
    match written_number(text) {
        WrittenNumber::Kept(text) => Cow::Borrowed(text),
        WrittenNumber::Zero => Cow::Owned("0".to_string()),
        WrittenNumber::Rounded(x) => {
            let mut text = StackText::new();
            write_rounded(x, &mut text);
            Cow::Owned(text.as_str().to_string())
        }
    }
}

/// What [`raw_number_text`] makes of a number's text.
enum WrittenNumber<'a> {
    /// The text itself: at most [`DECIMALS`] decimals, or already at that precision (`5E-1`).
    Kept(&'a str),
    /// Rounded to nothing.
    Zero,
    /// Rounded to this value, written as the shortest decimal that reads back.
    Rounded(f64),
}

fn written_number(text: &str) -> WrittenNumber<'_> {
    // One pass over the bytes (a number's text is short, and this runs for every number of
    // every unit written and checked): an exponent, or the digits after the point.
    let mut decimals = 0;
    let mut point = None;
    for (i, b) in text.bytes().enumerate() {
        match b {
            b'e' | b'E' => {
                decimals = usize::MAX;
                break;
            }
            b'.' => point = Some(i),
            _ => {}
        }
    }
    if decimals == 0 {
        decimals = point.map_or(0, |dot| text.len() - dot - 1);
    }
    if decimals <= DECIMALS as usize {
        return WrittenNumber::Kept(text);
    }
    let Some(x) = text.parse::<f64>().ok().filter(|x| x.is_finite()) else {
        return WrittenNumber::Kept(text);
    };
    match rounding(x) {
        // Already at that precision (`5E-1`): the spelling stays.
        Rounding::Same => WrittenNumber::Kept(text),
        Rounding::Zero => WrittenNumber::Zero,
        Rounding::To(rounded) => WrittenNumber::Rounded(rounded),
    }
}

/// What rounding a finite `x` to [`DECIMALS`] places does to it.
pub(super) enum Rounding {
    /// Nothing: it is at that precision already.
    Same,
    /// Rounds it to nothing.
    Zero,
    /// Rounds it to this value.
    To(f64),
}

pub(super) fn rounding(x: f64) -> Rounding {
    let scale = 10f64.powi(DECIMALS);
    let rounded = (x * scale).round() / scale;
    if rounded == x {
        Rounding::Same
    } else if rounded == 0.0 {
        Rounding::Zero
    } else {
        Rounding::To(rounded)
    }
}

/// Calls `f` with the text [`raw_number_text`] gives, written on the stack when it is rounded:
/// the read-back check spells every number of every unit it checks, and a heap string for each
/// was a tenth of its time.
pub(super) fn with_written_number<R>(text: &str, f: impl FnOnce(&str) -> R) -> R {
    match written_number(text) {
        WrittenNumber::Kept(text) => f(text),
        WrittenNumber::Zero => f("0"),
        WrittenNumber::Rounded(x) => {
            let mut text = StackText::new();
            write_rounded(x, &mut text);
            f(text.as_str())
        }
    }
}

/// Writes `x`, a number rounded to [`DECIMALS`] places, as the shortest decimal that reads back
/// as it: what `Display` writes for an `f64`. Below 10⁹ that is its whole millionths written
/// out, trailing zeros cut, and is made so with integer arithmetic: doubles there lie closer
/// together than half a millionth, so no shorter decimal reads back as `x`, and the one
/// written does (`x` is the double nearest to it). Larger magnitudes take `Display`.
pub(super) fn write_rounded(x: f64, out: &mut StackText) {
    use std::fmt::Write;
    const SCALE: f64 = 1e6;
    if x.abs() < 1e9 {
        let millionths = (x * SCALE).round();
        let whole = millionths.abs() as u64;
        if millionths < 0.0 {
            out.push(b'-');
        }
        // Digit by digit: the formatting machinery cost more than the rest of the number.
        let (int, fraction) = (whole / 1_000_000, whole % 1_000_000);
        out.push_digits(int, 1);
        if fraction != 0 {
            out.push(b'.');
            let (mut digits, mut trimmed) = (6, fraction);
            while trimmed % 10 == 0 {
                trimmed /= 10;
                digits -= 1;
            }
            out.push_digits(trimmed, digits);
        }
        return;
    }
    if write!(out, "{x}").is_err() {
        // Longer than the buffer (a large magnitude, written without an exponent).
        out.overflow = Some(format!("{x}"));
    }
}

/// A short text written on the stack; a write past its end fails (the text is then kept in
/// `overflow` by its writer).
pub(super) struct StackText {
    bytes: [u8; 40],
    len: usize,
    overflow: Option<String>,
}

impl StackText {
    pub(super) fn new() -> StackText {
        StackText {
            bytes: [0; 40],
            len: 0,
            overflow: None,
        }
    }

    fn push(&mut self, byte: u8) {
        if let Some(room) = self.bytes.get_mut(self.len) {
            *room = byte;
            self.len += 1;
        }
    }

    /// Appends `n` in decimal, padded with leading zeros to at least `width` digits.
    fn push_digits(&mut self, mut n: u64, width: usize) {
        let mut digits = [b'0'; 20];
        let mut at = digits.len();
        while n > 0 || digits.len() - at < width {
            at -= 1;
            digits[at] = b'0' + (n % 10) as u8;
            n /= 10;
        }
        digits[at..].iter().for_each(|&d| self.push(d));
    }

    pub(super) fn as_str(&self) -> &str {
        match &self.overflow {
            Some(text) => text,
            // Only ASCII digits, sign and point are written.
            None => std::str::from_utf8(&self.bytes[..self.len]).unwrap_or_default(),
        }
    }
}

impl std::fmt::Write for StackText {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        let room = self.bytes.get_mut(self.len..end).ok_or(std::fmt::Error)?;
        room.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// A number velvet computed, as it writes it: what [`written`] makes of `Value::from(x)`,
/// without writing `x` out and reading it back (a sheen's fuzz colour is three such numbers,
/// by the twenty thousand in a library).
pub fn written_f64(x: f64) -> Value {
    if !x.is_finite() || x.abs() >= 1e9 {
        return written(Value::from(x)); // not finite, or large: the general way
    }
    match rounding(x) {
        // `Value::from` writes the shortest decimal that reads back.
        Rounding::Same => Value::from(x),
        Rounding::Zero => Value::from(0u8),
        Rounding::To(rounded) => {
            rounded_number(rounded).map_or_else(|| written(Value::from(x)), Value::Number)
        }
    }
}

/// The number written as [`write_rounded`] writes the rounded `x`.
fn rounded_number(x: f64) -> Option<serde_json::Number> {
    let mut text = StackText::new();
    write_rounded(x, &mut text);
    number_spelled(text.as_str(), x)
}

/// The number written `text`, which reads as `x`. serde_json makes a number of a given text
/// only by reading it; its own writing of `x` is taken where it is that text, which is cheaper.
fn number_spelled(text: &str, x: f64) -> Option<serde_json::Number> {
    match serde_json::Number::from_f64(x) {
        Some(n) if n.as_str() == text => Some(n),
        _ => text.parse().ok(),
    }
}

/// Whether every number in `value` is already as velvet writes it (see [`written`]).
pub(crate) fn is_written(value: &Value) -> bool {
    match value {
        Value::Number(n) => matches!(raw_number_text(n.as_str()), std::borrow::Cow::Borrowed(_)),
        Value::Array(items) => items.iter().all(is_written),
        Value::Object(map) => map.values().all(is_written),
        _ => true,
    }
}

/// `value` with every number as velvet writes it (see [`number_text`]): edits store what the
/// file will hold, so that planning again compares like with like.
pub fn written(value: Value) -> Value {
    match value {
        Value::Number(n) => match written_number(n.as_str()) {
            WrittenNumber::Kept(_) => Value::Number(n),
            WrittenNumber::Zero => Value::from(0u8),
            WrittenNumber::Rounded(x) => rounded_number(x).map_or(Value::Number(n), Value::Number),
        },
        Value::Array(items) => Value::Array(items.into_iter().map(written).collect()),
        Value::Object(map) => {
            Value::Object(map.into_iter().map(|(k, v)| (k, written(v))).collect())
        }
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::splice::push_written_f64;

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
    fn numbers_spelled_on_the_stack_match_the_written_text() {
        for text in [
            "0.7499999999999999",
            "-0.30000000000000004",
            "7.590065448456657e-8",
            "-7.5e-8",
            "1E-1",
            "5E-1",
            "0.1234565",
            "8999999999.1234567",
            "-0",
            "12",
            "1e400",
        ] {
            assert_eq!(
                with_written_number(text, str::to_string),
                raw_number_text(text),
                "{text}"
            );
        }
        assert_eq!(
            with_written_number("0.7499999999999999", str::to_string),
            "0.75"
        );
        assert_eq!(with_written_number("-7.5e-8", str::to_string), "0");
    }

    /// A computed number is written as the general way writes it once made a value: kept,
    /// rounded or zero, over a sweep of magnitudes, signs and the edges.
    #[test]
    fn computed_numbers_are_written_as_their_values_are() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            1.0,
            0.75,
            1.0 / 3.0,
            2.0 / 3.0,
            0.1 + 0.2,
            7.5e-8,
            -7.5e-8,
            5e-7,
            4.9e-7,
            1e-6,
            1.5e-6,
            0.1234565,
            0.12345650000000001,
            1e9,
            1e9 - 0.3,
            123_456_789.123_456_7,
            -5.5e12,
            1e300,
            f64::NAN,
            f64::INFINITY,
            f64::MIN_POSITIVE,
        ];
        let mut x = 1e-9;
        while x < 1e12 {
            xs.extend([x, -x, x * 0.999_999_7]);
            x *= 1.618;
        }
        for x in xs {
            let general = written(Value::from(x)).to_string();
            assert_eq!(written_f64(x).to_string(), general, "{x}");
            let mut pushed = String::new();
            push_written_f64(x, &mut pushed);
            assert_eq!(pushed, general, "{x}");
        }
    }

    /// The rounded numbers written with integer arithmetic are what `Display` writes, over a
    /// sweep of magnitudes and signs, at the 10⁹ edge and past it.
    #[test]
    fn rounded_numbers_written_from_their_millionths_match_display() {
        let mut millionths: Vec<f64> = vec![1.0, 5.0, 10.0, 999_999.0, 1_000_000.0, 1_000_001.0];
        // A multiplicative sweep over every magnitude below 10⁹ (in millionths: below 10¹⁵).
        let mut k: f64 = 3.0;
        while k < 1e15 {
            millionths.push(k.round());
            k *= 1.37;
        }
        millionths.push(999_999_999_999_999.0);
        millionths.extend((1..2000).map(|i| (i * 7919) as f64));
        for k in millionths {
            for x in [k / 1e6, -k / 1e6] {
                let mut text = StackText::new();
                write_rounded(x, &mut text);
                assert_eq!(text.as_str(), format!("{x}"), "{x}");
            }
        }
        for x in [1e9, 123_456_789_012.5, -4.5e15, 1e300] {
            let mut text = StackText::new();
            write_rounded(x, &mut text);
            assert_eq!(text.as_str(), format!("{x}"), "{x}");
        }
    }

    #[test]
    fn written_rounds_a_number_below_the_precision_to_zero() {
        assert_eq!(
            written(serde_json::json!([7.5e-8, 0.5])).to_string(),
            "[0,0.5]"
        );
    }

    #[test]
    fn written_values_hold_what_the_file_will_hold() {
        let value = written(serde_json::json!({"a": [0.30000000000000004, 1.0, 2], "b": "x"}));
        assert_eq!(value.to_string(), r#"{"a":[0.3,1.0,2],"b":"x"}"#);
    }
}
