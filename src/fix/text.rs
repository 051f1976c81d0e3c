//! A fix seen as text: the edits of the JSON text that a plan's splices make (what the JSON
//! and SARIF reports carry), and the unified diff `--diff` prints.

use crate::asset::position::{position_of, Cursor, Position};
use crate::diagnostics::fixes::TextEdit;
use crate::edit::splice::Spliced;

/// A replacement of `source[start..end]` by `text`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Replacement {
    pub start: usize,
    pub end: usize,
    pub text: String,
}

/// The replacements that turn `source` into `spliced`. A spliced text is the source's spans
/// with the splices' texts between them, run by run ([`Spliced::pieces`]): each kept run is a
/// slice of the source, so where it starts says where the splice before it ended. The result
/// is checked by applying it; should the runs ever be laid out otherwise, the one replacement
/// between the common prefix and suffix of the two texts is given instead.
pub fn replacements(source: &str, spliced: &Spliced) -> Vec<Replacement> {
    let base = source.as_ptr() as usize;
    let offset_in_source = |piece: &[u8]| -> Option<usize> {
        let at = (piece.as_ptr() as usize).checked_sub(base)?;
        (at + piece.len() <= source.len()).then_some(at)
    };
    let pieces: Vec<&[u8]> = spliced.pieces().collect();
    let mut out = Vec::new();
    let mut laid_out = pieces.len() % 2 == 1;
    let mut i = 0;
    while laid_out && i + 2 < pieces.len() {
        let (kept, text, next) = (pieces[i], pieces[i + 1], pieces[i + 2]);
        match (offset_in_source(kept), offset_in_source(next)) {
            (Some(k), Some(n)) if k + kept.len() <= n => {
                let start = k + kept.len();
                if start != n || !text.is_empty() {
                    out.push(Replacement {
                        start,
                        end: n,
                        text: String::from_utf8_lossy(text).into_owned(),
                    });
                }
            }
            _ => laid_out = false,
        }
        i += 2;
    }
    // Kept pieces of the source in order, from its first byte to its last, with the new texts
    // between them: the replacements give the spliced text by construction, and the text is
    // not joined to be compared (two copies of a large document for each round of fixes).
    let end_of = |piece: &[u8]| offset_in_source(piece).map(|at| at + piece.len());
    let covers_source = pieces.first().and_then(|p| offset_in_source(p)) == Some(0)
        && pieces.last().and_then(|p| end_of(p)) == Some(source.len());
    if laid_out && covers_source {
        debug_assert_eq!(apply(source, &out), spliced.to_text());
        return out;
    }
    let joined = spliced.to_text();
    if laid_out && apply(source, &out) == joined {
        return out;
    }
    whole_difference(source, &joined).into_iter().collect()
}

/// The one replacement between the common prefix and suffix of `before` and `after` (on
/// character boundaries); none when they are equal.
pub fn whole_difference(before: &str, after: &str) -> Option<Replacement> {
    if before == after {
        return None;
    }
    let mut prefix = before
        .bytes()
        .zip(after.bytes())
        .take_while(|(a, b)| a == b)
        .count();
    while !before.is_char_boundary(prefix) || !after.is_char_boundary(prefix) {
        prefix -= 1;
    }
    let max_suffix = before.len().min(after.len()) - prefix;
    let mut suffix = before
        .bytes()
        .rev()
        .zip(after.bytes().rev())
        .take(max_suffix)
        .take_while(|(a, b)| a == b)
        .count();
    while !before.is_char_boundary(before.len() - suffix)
        || !after.is_char_boundary(after.len() - suffix)
    {
        suffix -= 1;
    }
    Some(Replacement {
        start: prefix,
        end: before.len() - suffix,
        text: after[prefix..after.len() - suffix].to_string(),
    })
}

/// `source` with `replacements` (sorted, not overlapping) made.
pub fn apply(source: &str, replacements: &[Replacement]) -> String {
    let mut out = String::with_capacity(source.len());
    let mut at = 0;
    for r in replacements {
        out.push_str(&source[at..r.start]);
        out.push_str(&r.text);
        at = r.end;
    }
    out.push_str(&source[at..]);
    out
}

/// The replacements as the reports give them, placed at lines and columns of `source`, their
/// offsets counted from `text_start`, where the text starts in its file (or JSON chunk).
pub fn text_edits(source: &str, replacements: &[Replacement], text_start: usize) -> Vec<TextEdit> {
    let offsets: Vec<usize> = replacements.iter().flat_map(|r| [r.start, r.end]).collect();
    let positions = positions_of(source, &offsets);
    let shifted = |p: Position| Position {
        offset: text_start + p.offset,
        ..p
    };
    replacements
        .iter()
        .zip(positions.chunks(2))
        .map(|(r, p)| TextEdit {
            start: shifted(p[0]),
            end: shifted(p[1]),
            content: r.text.clone(),
        })
        .collect()
}

/// The edit that removes what precedes the JSON text (a byte-order mark, `text_start` bytes):
/// the mark is the first character of the file's first line (U+FEFF), the text's first
/// position ends it.
pub fn lead_removed(text_start: usize) -> TextEdit {
    let at = |column, offset| Position {
        line: 1,
        column,
        offset,
    };
    TextEdit {
        start: at(1, 0),
        end: at(2, text_start),
        content: String::new(),
    }
}

/// The positions of `offsets` (on character boundaries, in increasing order as replacements
/// give them) in `source`, read front to back once rather than from the start for each.
fn positions_of(source: &str, offsets: &[usize]) -> Vec<Position> {
    let mut cursor = Cursor::new(source);
    offsets
        .iter()
        .map(|&offset| {
            if offset < cursor.offset() {
                position_of(source, offset)
            } else {
                cursor.advance_to(offset.min(source.len()))
            }
        })
        .collect()
}

/// The unified diff from `before` to `after` of the file shown as `name` (three lines of
/// context), as `diff -u` and `git diff` write it.
pub fn unified_diff(name: &str, before: &str, after: &str) -> String {
    // A name with a space ends with a tab, as git writes it: `patch` reads a file name up to
    // the first tab, or else up to the first space.
    let end = if name.contains(' ') { "\t" } else { "" };
    similar::TextDiff::from_lines(before, after)
        .unified_diff()
        .context_radius(3)
        .header(&format!("a/{name}{end}"), &format!("b/{name}{end}"))
        .to_string()
}

/// What `--diff` prints for a .glb in place of a diff: a line that `patch` and `git apply`
/// pass over (text before a diff's header), saying how to apply its fixes. A text diff of the
/// JSON chunk would be applied by `patch` to the binary file and break it.
pub fn glb_not_diffed(name: &str) -> String {
    format!(
        "# {name}: not shown as a diff (a .glb is binary; patch would break it): `velvet validate --fix {name}` applies its fixes, and --format json gives its JSON chunk's edits\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_whole_difference_is_the_span_between_common_prefix_and_suffix() {
        let r = whole_difference("[1, 2]", "[1, 2, 3]").unwrap();
        assert_eq!((r.start, r.end, r.text.as_str()), (5, 5, ", 3"));
        assert_eq!(apply("[1, 2]", &[r]), "[1, 2, 3]");
        let r = whole_difference("aéb", "aéc").unwrap();
        assert_eq!(apply("aéb", &[r]), "aéc");
        assert_eq!(whole_difference("x", "x"), None);
    }

    #[test]
    fn the_diff_names_the_file_and_shows_the_changed_lines() {
        let diff = unified_diff("m.gltf", "{\n  \"a\": 1\n}\n", "{\n  \"a\": 2\n}\n");
        assert!(
            diff.starts_with("--- a/m.gltf\n+++ b/m.gltf\n@@ -1,3 +1,3 @@\n"),
            "{diff}"
        );
        assert!(diff.contains("-  \"a\": 1\n+  \"a\": 2\n"), "{diff}");
    }

    #[test]
    fn positions_read_in_one_pass_are_those_read_one_by_one() {
        let text = "{\n  \"é\": [1,\n 2]\n}";
        let offsets: Vec<usize> = (0..=text.len())
            .filter(|&i| text.is_char_boundary(i))
            .collect();
        let one_pass = positions_of(text, &offsets);
        for (offset, p) in offsets.iter().zip(one_pass) {
            assert_eq!(p, position_of(text, *offset), "{offset}");
        }
    }
}
