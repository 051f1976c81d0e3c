//! A large text indexed in two halves at once, on two threads of the pool.
//!
//! The text is cut after a line break near its middle. JSON allows no line break inside a
//! string, so in a valid text the cut falls between two tokens. The first half is indexed as
//! a front-to-back build indexes it, up to the cut, where its containers stand open. The second
//! half is indexed from the cut without knowing what holds it: its values, keys and
//! punctuation at the outer level are listed in order, with where each closing bracket fell.
//! The stitch then plays that list against the first half's open containers, checking the
//! grammar a front-to-back build would have checked; renumbers the second half's entries and
//! array runs after the first half's, and its keys in the first half's table. The result is the
//! index a front-to-back build gives, entry for entry and key number for key number.
//!
//! Whatever the stitch does not take is indexed front to back instead, which then gives the
//! exact error: an error in either half, a limit reached, a key whose colon is on the next
//! line. When no other thread is free to take the second half, the first half goes on past
//! the cut by itself.

use super::{
    duplicate_keys, Builder, Kind, Open, Tape, TapeError, COUNT_SHIFT, DUPLICATES, ESCAPED, KEY,
    MAX_AUX,
};
use crate::asset::key_table::KeyTable;
use rayon::prelude::*;

/// Texts from this size (bytes) are split: a megabyte takes the index some 0.7 ms, against a
/// few microseconds to hand half of it to another thread.
const SPLIT_FROM: usize = 1 << 20;

/// How many of the second half's entries one task of the pool renumbers at least: a few
/// nanoseconds each, against a few microseconds to hand a task over.
const RENUMBERED_PER_TASK: usize = 1 << 15;

/// Where the first half's text ran out, at the cut: what may come next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    /// The root value ended before the cut: nothing but whitespace.
    Done,
    /// A value ended: a comma, or the bracket that closes its container.
    AfterValue,
    /// A container opened: its first member or element, or its closing bracket.
    AfterOpen,
    /// A comma: the next member or element.
    AfterComma,
    /// A key (the stitch's own state; the first half never stops between a key and its colon).
    AfterKey,
    /// A key's colon: the member's value.
    AfterColon,
}

/// The first half: the builder where its text ran out, and the containers open there.
struct FirstHalf<'t> {
    builder: Builder<'t>,
    stack: Vec<Open>,
    stop: Stop,
}

/// What the second half holds at its outer level, in text order. Entry numbers are the
/// second half's own.
enum Token {
    Comma,
    Colon,
    Key,
    /// A value, and how many containers it nests on its deepest path (0 for a scalar).
    Value {
        entry: u32,
        depth: usize,
    },
    /// A closing bracket: `}` or `]`, the byte after it, and how many entries and run words
    /// the second half held when it came.
    Close {
        object: bool,
        end: u32,
        entries: u32,
        runs: usize,
    },
}

struct SecondHalf {
    entries: Vec<super::Entry>,
    elements: Vec<u32>,
    keys: KeyTable,
    tokens: Vec<Token>,
}

/// `text` indexed in two halves when it is large enough and has a line break past its middle,
/// and the pool has another thread; `None` to index it front to back.
pub(super) fn build(text: &str, max_depth: usize) -> Option<Result<Tape, TapeError>> {
    if text.len() < SPLIT_FROM || rayon::current_num_threads() < 2 {
        return None;
    }
    let cut = cut(text)?;
    Some(build_at(text, max_depth, cut, true))
}

/// The byte after the first line break from the middle of `text` on, if it is not the end.
fn cut(text: &str) -> Option<usize> {
    let middle = text.len() / 2;
    memchr::memchr(b'\n', &text.as_bytes()[middle..])
        .map(|at| middle + at + 1)
        .filter(|&cut| cut < text.len())
}

/// `text` indexed in two halves cut at byte `cut` (just after a line break). The second half
/// is indexed by another thread if one takes it (with `share`); otherwise the first half goes
/// on past the cut.
fn build_at(text: &str, max_depth: usize, cut: usize, share: bool) -> Result<Tape, TapeError> {
    let here = rayon::current_thread_index();
    let (first, second) = rayon::join(
        || first_half(text, cut, max_depth),
        // Run on this thread after the first half, the second would only add the stitch.
        || (share && rayon::current_thread_index() != here).then(|| second_half(text, cut)),
    );
    let tape = match (first, second) {
        (Some(first), Some(Ok(second))) => stitch(first, second, max_depth),
        (Some(first), None) => go_on(first, text).ok(),
        _ => None,
    };
    tape.map_or_else(|| Tape::build_serial(text, max_depth), Ok)
}

/// The first half indexed up to `cut`, where its text runs out; `None` when it fails for
/// another reason, or stops where the stitch does not take over (between a key and its colon,
/// or before the root).
fn first_half(text: &str, cut: usize, max_depth: usize) -> Option<FirstHalf<'_>> {
    // Room for the whole text's entries: the second half's are appended.
    let mut builder = Builder::new(&text[..cut], max_depth, text.len() / 16);
    let mut stack = Vec::new();
    builder.skip_whitespace();
    let ended = builder
        .value_start(&mut stack)
        .and_then(|()| builder.after_value(&mut stack));
    let stop = match ended {
        Ok(()) => Stop::Done,
        // Out of text, which in a valid text happens between two tokens (the byte before the
        // cut is a line break): the last of them says what may follow.
        Err(TapeError::Syntax(at)) if at == cut => {
            let before = text[..cut].trim_end_matches([' ', '\t', '\n', '\r']);
            match before.as_bytes().last()? {
                b'{' | b'[' => Stop::AfterOpen,
                b',' => Stop::AfterComma,
                b':' => Stop::AfterColon,
                _ if builder
                    .entries
                    .last()
                    .is_some_and(|e| e.meta & KEY != 0 && e.end as usize == before.len()) =>
                {
                    return None;
                }
                _ => Stop::AfterValue,
            }
        }
        Err(_) => return None,
    };
    Some(FirstHalf {
        builder,
        stack,
        stop,
    })
}

/// The first half indexed on past the cut to the end of `text`, as a front-to-back build goes
/// on from there.
fn go_on<'t>(first: FirstHalf<'t>, text: &'t str) -> Result<Tape, TapeError> {
    let FirstHalf {
        mut builder,
        mut stack,
        stop,
    } = first;
    builder.text = text;
    builder.bytes = text.as_bytes();
    builder.skip_whitespace();
    let top_is_object = stack.last().map(|open| open.is_object);
    match (stop, top_is_object) {
        (Stop::AfterOpen, Some(is_object)) => {
            let closer = if is_object { b'}' } else { b']' };
            if builder.bytes.get(builder.at) == Some(&closer) {
                builder.at += 1;
                let open = stack.pop().expect("the container opened last");
                builder.close(open)?;
            } else {
                if is_object {
                    builder.key()?;
                }
                builder.value_start(&mut stack)?;
            }
        }
        (Stop::AfterComma, Some(is_object)) => {
            if is_object {
                builder.key()?;
            }
            builder.value_start(&mut stack)?;
        }
        (Stop::AfterColon, Some(_)) => builder.value_start(&mut stack)?,
        (Stop::Done | Stop::AfterValue, _) => {}
        _ => return builder.fail(),
    }
    builder.after_value(&mut stack)?;
    Ok(builder.finish())
}

/// The text from `cut` on, indexed as the list of what it holds at its outer level (see
/// [`Token`]), each value inside indexed as a front-to-back build indexes it. The depth limit
/// is the stitch's to check, once it knows how deep the cut lies.
fn second_half(text: &str, cut: usize) -> Result<SecondHalf, TapeError> {
    let mut builder = Builder::new(text, usize::MAX, (text.len() - cut) / 16);
    builder.at = cut;
    let mut tokens = Vec::new();
    let mut stack = Vec::new();
    loop {
        builder.skip_whitespace();
        let Some(&byte) = builder.bytes.get(builder.at) else {
            break;
        };
        let token = match byte {
            b',' => {
                builder.at += 1;
                Token::Comma
            }
            b':' => {
                builder.at += 1;
                Token::Colon
            }
            b'}' | b']' => {
                builder.at += 1;
                Token::Close {
                    object: byte == b'}',
                    end: builder.at as u32,
                    entries: builder.entries.len() as u32,
                    runs: builder.elements.len(),
                }
            }
            b'"' => {
                // A key if a colon follows, else a string value.
                let start = builder.at;
                let escaped = builder.string()?;
                let end = builder.at;
                builder.skip_whitespace();
                let is_key = builder.bytes.get(builder.at) == Some(&b':');
                builder.at = end;
                if is_key {
                    builder.key_entry(start, escaped)?;
                    Token::Key
                } else {
                    let flags = if escaped { ESCAPED } else { 0 };
                    let entry = builder.push(Kind::String, start, flags);
                    Token::Value { entry, depth: 0 }
                }
            }
            _ => {
                let entry = builder.entries.len() as u32;
                builder.deepest = 0;
                builder.value_start(&mut stack)?;
                builder.after_value_until::<true>(&mut stack)?;
                Token::Value {
                    entry,
                    depth: builder.deepest,
                }
            }
        };
        tokens.push(token);
    }
    Ok(SecondHalf {
        entries: builder.entries,
        elements: builder.elements,
        keys: builder.keys,
        tokens,
    })
}

/// A container the first half left open, closed in the second.
struct Closed {
    open: Open,
    /// Its elements from the second half (entries renumbered), for an array.
    elements: Vec<u32>,
    end: u32,
    /// How many entries and run words the second half held at its closing bracket.
    entries: u32,
    runs: usize,
    /// Where its run starts in the joined runs, for an array.
    run: u32,
}

/// The two halves joined into the index of the whole text; `None` when the second half's list
/// does not continue the first half's grammar, or a limit is passed.
fn stitch(first: FirstHalf, second: SecondHalf, max_depth: usize) -> Option<Tape> {
    let FirstHalf {
        builder: mut joined,
        mut stack,
        stop,
    } = first;
    if stop == Stop::Done {
        return second.tokens.is_empty().then(|| joined.finish());
    }
    let offset = u32::try_from(joined.entries.len()).ok()?;
    // The second half's elements of each array the first left open (innermost last).
    let mut added: Vec<Vec<u32>> = stack.iter().map(|_| Vec::new()).collect();
    let mut closed: Vec<Closed> = Vec::new();
    let mut state = stop;
    for token in &second.tokens {
        let depth = stack.len();
        let open = stack.last_mut()?;
        state = match (token, state) {
            (Token::Comma, Stop::AfterValue) => Stop::AfterComma,
            (Token::Key, Stop::AfterOpen | Stop::AfterComma) if open.is_object => Stop::AfterKey,
            (Token::Colon, Stop::AfterKey) => Stop::AfterColon,
            (
                Token::Value {
                    entry,
                    depth: nested,
                },
                Stop::AfterOpen | Stop::AfterComma,
            ) if !open.is_object => {
                if open.count == MAX_AUX || depth + nested > max_depth {
                    return None;
                }
                open.count += 1;
                added.last_mut()?.push(entry + offset);
                Stop::AfterValue
            }
            (Token::Value { depth: nested, .. }, Stop::AfterColon) => {
                if open.count == MAX_AUX || depth + nested > max_depth {
                    return None;
                }
                open.count += 1;
                Stop::AfterValue
            }
            (
                &Token::Close {
                    object,
                    end,
                    entries,
                    runs,
                },
                Stop::AfterValue | Stop::AfterOpen,
            ) if object == open.is_object => {
                closed.push(Closed {
                    open: stack.pop()?,
                    elements: added.pop()?,
                    end,
                    entries,
                    runs,
                    run: 0,
                });
                Stop::AfterValue
            }
            _ => return None,
        };
    }
    if !stack.is_empty() {
        return None;
    }

    // The runs in the order their arrays close: the first half's, then the second half's
    // interleaved with those of the arrays the first half opened.
    let mut elements = std::mem::take(&mut joined.elements);
    let before = elements.len();
    // (second half's run words before it, words inserted up to and with it) per inserted run.
    let mut inserted: Vec<(usize, usize)> = Vec::new();
    let mut copied = 0;
    for close in &mut closed {
        copy_runs(&second.elements[copied..close.runs], offset, &mut elements);
        copied = close.runs;
        if !close.open.is_object {
            let run = elements.len();
            if run > MAX_AUX as usize {
                return None;
            }
            elements.push(close.open.count);
            elements.extend(joined.scratch.drain(close.open.scratch..));
            elements.extend_from_slice(&close.elements);
            let total = inserted.last().map_or(0, |&(_, n)| n) + (elements.len() - run);
            inserted.push((close.runs, total));
            close.run = run as u32;
        }
    }
    copy_runs(&second.elements[copied..], offset, &mut elements);
    // Where a run of the second half now starts.
    let moved = |run: usize| -> usize {
        let k = inserted.partition_point(|&(words, _)| words <= run);
        before + run + if k == 0 { 0 } else { inserted[k - 1].1 }
    };

    // The second half's keys numbered in the first half's table, in the order they first
    // appear, as a front-to-back build numbers them.
    let renumbered: Vec<u32> = (0..second.keys.len() as u32)
        .map(|id| joined.keys.intern(second.keys.key(id)))
        .collect();
    if renumbered.iter().any(|&id| id > MAX_AUX) {
        return None;
    }

    // Every run starts before the end of the joined runs: past the limit, an array's run
    // could be too, and the front-to-back build says what holds.
    if elements.len() > MAX_AUX as usize + 1 {
        return None;
    }
    let mut entries = std::mem::take(&mut joined.entries);
    let flags = (1 << COUNT_SHIFT) - 1;
    let renumber = |entry: &super::Entry| {
        let mut entry = *entry;
        entry.next += offset;
        if entry.meta & KEY != 0 {
            entry.meta = entry.meta & flags | renumbered[entry.aux()] << COUNT_SHIFT;
        } else if entry.kind() == Kind::Array {
            entry.meta = entry.meta & flags | (moved(entry.aux()) as u32) << COUNT_SHIFT;
        }
        entry
    };
    // The second half's entries are renumbered on the pool: the thread that indexed it is
    // free by now, and on the library's 9.8 MB the copy is some 4 MB.
    entries.par_extend(
        second
            .entries
            .par_iter()
            .with_min_len(RENUMBERED_PER_TASK)
            .map(renumber),
    );

    // The containers the first half opened, innermost first (each holds those closed before
    // it), written as their closing brackets write them.
    let mut keys = Vec::new();
    for close in closed {
        let next = offset + close.entries;
        let aux = if close.open.is_object {
            close.open.count
        } else {
            close.run
        };
        let duplicates = close.open.is_object
            && close.open.count > 1
            && duplicate_keys(&entries, close.open.entry, next, &mut keys);
        let entry = &mut entries[close.open.entry as usize];
        entry.end = close.end;
        entry.next = next;
        entry.meta |= aux << COUNT_SHIFT;
        if duplicates {
            entry.meta |= DUPLICATES;
        }
    }
    Some(Tape {
        entries,
        elements,
        keys: joined.keys,
    })
}

/// Appends the runs `runs` (each a count, then that many entry numbers), the entry numbers
/// moved by `offset`.
fn copy_runs(runs: &[u32], offset: u32, out: &mut Vec<u32>) {
    out.reserve(runs.len());
    let mut at = 0;
    while at < runs.len() {
        let count = runs[at] as usize;
        out.push(runs[at]);
        out.extend(runs[at + 1..at + 1 + count].iter().map(|e| e + offset));
        at += count + 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    type Whole = (Vec<(u32, u32, u32, u32)>, Vec<u32>, Vec<String>);

    /// Everything an index holds, in a form two indexes of one text are compared by: entries
    /// (key numbers included), runs, and the key table in number order.
    fn whole(tape: &Tape) -> Whole {
        (
            tape.entries
                .iter()
                .map(|e| (e.start, e.end, e.next, e.meta))
                .collect(),
            tape.elements.clone(),
            (0..tape.keys.len() as u32)
                .map(|id| tape.keys.key(id).to_string())
                .collect(),
        )
    }

    fn outcome(built: Result<Tape, TapeError>) -> Result<Whole, TapeError> {
        built.as_ref().map(whole).map_err(Clone::clone)
    }

    /// The two halves of `text` cut at `cut`, indexed and stitched, with no fallback.
    fn stitched(text: &str, max_depth: usize, cut: usize) -> Option<Tape> {
        let first = first_half(text, cut, max_depth)?;
        stitch(first, second_half(text, cut).ok()?, max_depth)
    }

    /// The places just after each line break of `text` but its last byte.
    fn cuts(text: &str) -> Vec<usize> {
        text.match_indices('\n')
            .map(|(at, _)| at + 1)
            .filter(|&cut| cut < text.len())
            .collect()
    }

    /// At every cut of `text`: the stitched index and the first half gone on alone are the
    /// front-to-back index, and so is what [`build_at`] gives either way (the same error
    /// included). Stitching is required to succeed when `stitches` says so.
    fn every_cut_agrees(text: &str, max_depth: usize, stitches: bool) -> Result<(), String> {
        let serial = outcome(Tape::build_serial(text, max_depth));
        for cut in cuts(text) {
            let stitch = stitched(text, max_depth, cut).map(|t| whole(&t));
            let alone = first_half(text, cut, max_depth).map(|first| outcome(go_on(first, text)));
            let checks = [
                ("stitched", stitch.clone().map(Ok)),
                ("gone on", alone),
                (
                    "shared",
                    Some(outcome(build_at(text, max_depth, cut, true))),
                ),
                (
                    "alone",
                    Some(outcome(build_at(text, max_depth, cut, false))),
                ),
            ];
            for (how, got) in checks {
                if got.as_ref().is_some_and(|got| *got != serial) {
                    return Err(format!("{how} at {cut} differs on {text:?}"));
                }
            }
            if stitches && stitch.is_none() {
                return Err(format!("not stitched at {cut}: {text:?}"));
            }
        }
        Ok(())
    }

    /// Containers open across the cut at several depths, closed in the second half among
    /// arrays opened and closed there (whose runs interleave with theirs), an empty object and
    /// array split by a line break, an escaped key and a key written twice on either side of
    /// a cut; a scalar root; and a key whose colon is on the next line and a cut before the
    /// root, which the stitch leaves to a front-to-back build.
    #[test]
    fn every_cut_of_a_few_texts_gives_the_front_to_back_index() {
        let texts = [
            "{\n\"a\": [1,\n[2, [3,\n4], 5],\n{\"b\": [6,\n7]}],\n\"c\": {\n}, \"d\": [\n], \"e\": [[[\n]]]\n}",
            "[\n{\"k\": 1,\n\"\\u006b\": 2,\n\"k\": 3},\n\"s\",\n\"t\\n\"\n,\n[\n[],\n{}\n]\n]\n",
            "{\"x\": {\"y\": {\"z\": [\n1, {\"y\": 2, \"x\": [3]}\n]}, \"w\": null}\n, \"v\": true}",
            "[1,\n2]",
        ];
        for text in texts {
            every_cut_agrees(text, 64, true).unwrap();
        }
        // A cut before the root is left to a front-to-back build; one after it is stitched.
        let scalar = "  \n 42 \n ";
        assert!(stitched(scalar, 64, 3).is_none());
        assert!(stitched(scalar, 64, 8).is_some());
        every_cut_agrees(scalar, 64, false).unwrap();
        // The key of the member that straddles the cut is written twice: both halves' share.
        let twice = "{\"k\": 1,\n\"k\": 2}";
        let tape = stitched(twice, 64, twice.find('\n').unwrap() + 1).unwrap();
        assert!(tape.root(twice).as_object().unwrap().has_duplicate_keys());
        // A colon on the next line: not stitched, still indexed as front to back.
        let colon = "{\"a\": 1, \"b\"\n: 2}";
        assert!(stitched(colon, 64, colon.find('\n').unwrap() + 1).is_none());
        every_cut_agrees(colon, 64, false).unwrap();
    }

    /// The depth limit holds across the cut: a text nesting six deep, cut inside its deepest
    /// containers, is refused at five for the first container too deep and indexed at six.
    #[test]
    fn the_depth_limit_counts_the_containers_open_at_the_cut() {
        let text = "[[[\n[[[\n1]]]\n]]]";
        assert_eq!(
            Tape::build_serial(text, 5).err(),
            Some(TapeError::TooDeep(text.find("[[[\n1").unwrap() + 2))
        );
        every_cut_agrees(text, 5, false).unwrap();
        every_cut_agrees(text, 6, true).unwrap();
    }

    /// Broken texts get the error a front-to-back build gives, at every cut.
    #[test]
    fn a_broken_text_gets_the_front_to_back_error_at_every_cut() {
        for text in [
            "[1,\n2,\n]",
            "{\"a\": 1\n\"b\": 2}",
            "[1,\n2]\n]",
            "[1,\n2",
            "{\"a\":\n[1, 2}\n]",
            "[\"a\n\"]",
            "[1\n, 2]\nx",
        ] {
            every_cut_agrees(text, 64, false).unwrap();
        }
    }

    /// A large document is split where the pool has a thread to take its second half, and
    /// indexed as front to back.
    #[test]
    fn a_large_text_indexed_through_the_pool_is_the_front_to_back_index() {
        let value: serde_json::Value = serde_json::json!({
            "materials": (0..12_000).map(|i| serde_json::json!({
                "name": format!("m{i}"),
                "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.25, i % 7], "sheenRoughnessFactor": 0.5}}
            })).collect::<Vec<_>>(),
        });
        let text = serde_json::to_string_pretty(&value).unwrap();
        assert!(text.len() > SPLIT_FROM);
        let cut = cut(&text).unwrap();
        assert!(stitched(&text, 64, cut).is_some());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let built = pool.install(|| Tape::build_within(&text, 64));
        assert_eq!(outcome(built), outcome(Tape::build_serial(&text, 64)));
    }

    proptest! {
        /// Any JSON value written pretty, at every cut: the front-to-back index, stitched.
        #[test]
        fn every_cut_of_a_pretty_text_gives_the_front_to_back_index(
            value in super::super::properties::json_value(),
            depth in 3usize..8,
        ) {
            let text = serde_json::to_string_pretty(&value).unwrap();
            let valid = Tape::build_serial(&text, depth).is_ok();
            if let Err(differ) = every_cut_agrees(&text, depth, valid) {
                return Err(TestCaseError::fail(differ));
            }
        }

        /// The same with one byte of the text changed, which may break it anywhere.
        #[test]
        fn every_cut_of_a_changed_text_gives_the_front_to_back_outcome(
            value in super::super::properties::json_value(),
            at in any::<prop::sample::Index>(),
            byte in prop::sample::select(b"{}[]\",:0-.eE tfn\\\n".to_vec()),
        ) {
            let mut bytes = serde_json::to_string_pretty(&value).unwrap().into_bytes();
            let i = at.index(bytes.len());
            bytes[i] = byte;
            if let Ok(text) = String::from_utf8(bytes) {
                if let Err(differ) = every_cut_agrees(&text, 64, false) {
                    return Err(TestCaseError::fail(differ));
                }
            }
        }
    }
}
