//! The text of a contact sheet: DejaVu Sans, an open-licensed TrueType font embedded in the
//! binary (`assets/fonts/`, with its licence), laid out and rasterised by `ab_glyph` at
//! [`SIZE`] pixels with its kerning, so names keep their own case and any character the font
//! has (Latin, Greek and Cyrillic letters, accents, arrows, mathematical signs) is drawn as
//! itself; a character it lacks is drawn as the font's box. Rasterising is a pure function of
//! the text, so sheets stay byte-identical at any thread count.

use ab_glyph::{point, Font, FontRef, GlyphId, PxScale, ScaleFont};
use std::sync::OnceLock;

/// The font's bytes.
const DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The text's size: pixels from the font's ascender to its descender.
pub const SIZE: f32 = 15.0;
/// Vertical advance per line, in pixels.
pub const LINE_HEIGHT: usize = 19;

fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(DEJAVU_SANS).expect("the embedded font is a valid TrueType font")
    })
}

/// The glyphs of `text` with their pen positions (x from 0, kerning applied).
fn layout(text: &str) -> Vec<(GlyphId, f32)> {
    let scaled = font().as_scaled(PxScale::from(SIZE));
    let mut x = 0.0;
    let mut previous: Option<GlyphId> = None;
    text.chars()
        .map(|c| {
            let id = scaled.glyph_id(c);
            if let Some(p) = previous {
                x += scaled.kern(p, id);
            }
            let at = x;
            x += scaled.h_advance(id);
            previous = Some(id);
            (id, at)
        })
        .collect()
}

/// The width of `text` in pixels, rounded up.
pub fn width(text: &str) -> usize {
    let scaled = font().as_scaled(PxScale::from(SIZE));
    let end = layout(text)
        .last()
        .map_or(0.0, |&(id, x)| x + scaled.h_advance(id));
    end.ceil() as usize
}

/// Calls `plot(x, y, coverage)` for every pixel `text` covers when its line's top-left corner
/// is at (`x`, `y`); coverage is in (0, 1].
pub fn draw(text: &str, x: usize, y: usize, mut plot: impl FnMut(usize, usize, f32)) {
    let f = font();
    let scale = PxScale::from(SIZE);
    let baseline = y as f32 + f.as_scaled(scale).ascent();
    for (id, at) in layout(text) {
        let glyph = id.with_scale_and_position(scale, point(x as f32 + at, baseline));
        if let Some(outlined) = f.outline_glyph(glyph) {
            let bounds = outlined.px_bounds();
            outlined.draw(|gx, gy, coverage| {
                let (px, py) = (bounds.min.x + gx as f32, bounds.min.y + gy as f32);
                if coverage > 0.0 && px >= 0.0 && py >= 0.0 {
                    plot(px as usize, py as usize, coverage.min(1.0));
                }
            });
        }
    }
}

/// Splits `text` into lines at most `max_width` pixels wide, at spaces; a word wider than a
/// line is cut between characters.
pub fn wrap(text: &str, max_width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        let candidate = if line.is_empty() {
            word.to_string()
        } else {
            format!("{line} {word}")
        };
        if width(&candidate) <= max_width {
            line = candidate;
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        // The word alone, cut where it must be.
        for c in word.chars() {
            line.push(c);
            if width(&line) > max_width && line.chars().count() > 1 {
                line.pop();
                lines.push(std::mem::take(&mut line));
                line.push(c);
            }
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_breaks_at_spaces_within_the_width_and_cuts_long_words() {
        let text = "the quick brown fox jumps over the lazy dog";
        let lines = wrap(text, width("the quick brown"));
        assert_eq!(lines.join(" "), text);
        assert!(lines.iter().all(|l| width(l) <= width("the quick brown")));
        assert_eq!(lines[0], "the quick brown");
        let cut = wrap("abcdefghij", width("abcd"));
        assert_eq!(cut.concat(), "abcdefghij");
        assert!(cut.len() >= 3 && cut.iter().all(|l| width(l) <= width("abcd")));
        assert_eq!(wrap("", 100), [""]);
    }

    #[test]
    fn accents_and_arrows_are_glyphs_of_their_own_and_case_is_kept() {
        let ink = |text: &str| {
            let mut pixels = Vec::new();
            draw(text, 0, 0, |x, y, c| pixels.push((x, y, (c * 255.0) as u8)));
            pixels
        };
        assert_ne!(ink("é"), ink("e"));
        assert_ne!(ink("a"), ink("A"));
        assert_ne!(ink("→"), ink("?"));
        assert!(!ink("→").is_empty());
        // Kerning: "AV" is narrower than "A" and "V" side by side.
        assert!(width("AV") < width("A") + width("V"));
    }
}
