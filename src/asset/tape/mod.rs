//! The read model: a compact index of the JSON text. One pass over the text records every
//! value's kind and byte span in a flat array (16 bytes a value, no allocation per value);
//! [`Node`] reads values from it on demand: a string is borrowed from the text unless it holds
//! escapes, a number is parsed from its span when asked. Validation reads the document through
//! this index and never builds a `serde_json::Value` of the whole document, which took about
//! eight times the text in memory and most of a run's time to build and free.
//!
//! Written by hand because the JSON crates at hand either build a tree of owned values
//! (serde_json's `Value`) or hand out borrowed events without random access (its `RawValue`
//! keeps a span but no index of what is inside it). The grammar accepted is serde_json's,
//! RFC 8259 without extensions: a text serde_json refuses is refused here, and the loader then
//! asks serde_json for its exact message. A unit test and a property test hold the two parsers
//! to the same verdict and the same values.
//!
//! Object members keep their order and their duplicates; lookups give the last duplicate and
//! iteration gives each key once at its first place with its last value, as serde_json's
//! order-preserving map does. Each key entry holds the key's number in the document's table of
//! distinct keys (`asset/key_table.rs`): a lookup finds the number of the key it wants once,
//! then compares numbers, and a key the document never writes is answered without a scan.

mod split;

use super::key_table::KeyTable;
use serde_json::Value;
use std::borrow::Cow;

/// What a value is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Null,
    Bool,
    Number,
    String,
    Array,
    Object,
}

const KIND_BITS: u32 = 3;
/// A string that holds escapes.
const ESCAPED: u32 = 1 << KIND_BITS;
/// A string that is an object key.
const KEY: u32 = 1 << (KIND_BITS + 1);
/// An object that writes a key more than once.
const DUPLICATES: u32 = 1 << (KIND_BITS + 2);
const COUNT_SHIFT: u32 = KIND_BITS + 3;
/// The largest number the word shared with the kind holds: an object's member count, where
/// an array's run starts in `Tape::elements`, or a key's number in [`Tape::keys`].
const MAX_AUX: u32 = (1 << (32 - COUNT_SHIFT)) - 1;

/// One value (or one object key) in the index.
#[derive(Debug, Clone, Copy)]
struct Entry {
    /// Byte span of the value in the text; for a string, quotes included.
    start: u32,
    end: u32,
    /// Index of the entry after this value and everything inside it.
    next: u32,
    /// Kind (3 bits), the flags above (3 bits), and for an object its member count, for an
    /// array where its run starts in `Tape::elements`, for a key its number in
    /// [`Tape::keys`].
    meta: u32,
}

impl Entry {
    fn kind(&self) -> Kind {
        match self.meta & ((1 << KIND_BITS) - 1) {
            0 => Kind::Null,
            1 => Kind::Bool,
            2 => Kind::Number,
            3 => Kind::String,
            4 => Kind::Array,
            _ => Kind::Object,
        }
    }

    fn aux(&self) -> usize {
        (self.meta >> COUNT_SHIFT) as usize
    }
}

fn kind_bits(kind: Kind) -> u32 {
    match kind {
        Kind::Null => 0,
        Kind::Bool => 1,
        Kind::Number => 2,
        Kind::String => 3,
        Kind::Array => 4,
        Kind::Object => 5,
    }
}

/// The index of one JSON text. It holds no text: [`Tape::root`] pairs it with the text it was
/// built from.
#[derive(Debug, Default)]
pub struct Tape {
    entries: Vec<Entry>,
    /// One run per array: its element count, then its elements' entry indices.
    elements: Vec<u32>,
    /// The distinct keys, whose numbers the key entries hold: a lookup by key compares
    /// numbers and reads no text.
    keys: KeyTable,
}

/// A key's number in the table of keys of one document ([`Node::key_id`]). A lookup by number
/// ([`Object::get_id`]) compares numbers only; a rule that looks the same key up in thousands
/// of objects finds its number once. Meaningful only for the document it came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct KeyId(u32);

/// Why a text has no index: it is not JSON as serde_json reads it, or it is too large to index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TapeError {
    /// Not JSON at this byte offset; serde_json gives the message.
    Syntax(usize),
    /// A text over 4 GiB, or more than 2^26 members in an object or elements in all arrays.
    TooLarge,
    /// An array or object at this byte offset nests deeper than the limit.
    TooDeep(usize),
}

/// An open container while the index is built.
struct Open {
    entry: u32,
    count: u32,
    /// For an array: where its elements start in the scratch stack.
    scratch: usize,
    is_object: bool,
}

/// Where a [`Resumption`] takes over from an earlier index.
struct ResumePoint {
    /// The containers open there, outermost first, each with the value entries of its
    /// children so far (the open child last).
    open: Vec<(u32, Vec<u32>)>,
    /// The first entry not taken from the earlier index.
    after: u32,
    /// The byte offset the parse resumes at: the end of the last value taken.
    at: usize,
}

struct Builder<'t> {
    text: &'t str,
    bytes: &'t [u8],
    at: usize,
    max_depth: usize,
    entries: Vec<Entry>,
    elements: Vec<u32>,
    /// Element indices of the arrays still open, innermost last.
    scratch: Vec<u32>,
    /// The numbers of the keys of the object being closed.
    member_keys: Vec<u32>,
    keys: KeyTable,
    /// The most containers open at once since this was last reset (the second half of a split
    /// build, [`split`], checks the depth limit once it knows how deep its start lies).
    deepest: usize,
}

impl Tape {
    /// Indexes `text`, which must be one JSON value with optional whitespace around it.
    pub fn build(text: &str) -> Result<Tape, TapeError> {
        Tape::build_within(text, usize::MAX)
    }

    /// Indexes `text`, refusing arrays and objects nested deeper than `max_depth` (the root is
    /// depth 1). The builder does not recurse; the limit protects what reads the index.
    ///
    /// A large text is indexed in two halves on two threads of the pool when another is free
    /// ([`split`]); the index is the same either way.
    pub fn build_within(text: &str, max_depth: usize) -> Result<Tape, TapeError> {
        if text.len() >= u32::MAX as usize {
            return Err(TapeError::TooLarge);
        }
        if let Some(tape) = split::build(text, max_depth) {
            return tape;
        }
        Tape::build_serial(text, max_depth)
    }

    /// [`Tape::build_within`] on this thread alone, front to back.
    fn build_serial(text: &str, max_depth: usize) -> Result<Tape, TapeError> {
        // A value takes at least two bytes of pretty-printed text on average.
        let mut builder = Builder::new(text, max_depth, text.len() / 16);
        builder.document()?;
        Ok(builder.finish())
    }

    /// What a build of a text of `text_len` bytes that equals this index's text up to byte
    /// `first_change` (a text with fixes spliced in: its first edit is often near its end)
    /// takes from this index: the entries of the values that end before that byte, and the
    /// containers open there, to be opened again; [`Resumption::build`] parses only the rest.
    /// A key only the earlier text had keeps its number (and finds no member); what any
    /// reading of the index gives is what a fresh build ([`Tape::build_within`]) gives. Taken
    /// before the text exists: a fix's trial copies it while the fixed text is joined. `None`
    /// when nothing is taken.
    pub fn resumption(&self, first_change: usize, text_len: usize) -> Option<Resumption> {
        if text_len >= u32::MAX as usize {
            return None;
        }
        let point = self.resume_point(first_change.min(text_len))?;
        let mut entries = Vec::with_capacity((text_len / 16).max(point.after as usize));
        super::pages::advise_huge(&mut entries);
        entries.extend_from_slice(&self.entries[..point.after as usize]);
        // The runs of the arrays that closed before the resumed value's end, which come before
        // the runs of every array that closes after it.
        let closing_later = self.entries[point.after as usize..]
            .iter()
            .chain(
                point
                    .open
                    .iter()
                    .map(|(entry, _)| &self.entries[*entry as usize]),
            )
            .filter(|e| e.kind() == Kind::Array)
            .map(Entry::aux)
            .min();
        let cut = closing_later.unwrap_or(self.elements.len());
        Some(Resumption {
            text_len,
            entries,
            elements: self.elements[..cut].to_vec(),
            keys: self.keys.clone(),
            point,
        })
    }
}

/// The part of an earlier index a build of a changed text takes over ([`Tape::resumption`]).
pub struct Resumption {
    /// The length of the text it was taken for.
    text_len: usize,
    entries: Vec<Entry>,
    elements: Vec<u32>,
    keys: KeyTable,
    point: ResumePoint,
}

impl Resumption {
    /// Indexes `text`, the changed text of the length it was taken for, from where the
    /// earlier index stops holding; a text of another length is indexed from its first byte.
    pub fn build(self, text: &str, max_depth: usize) -> Result<Tape, TapeError> {
        if text.len() != self.text_len {
            return Tape::build_within(text, max_depth);
        }
        let point = self.point;
        let mut builder =
            Builder::with_parts(text, max_depth, self.entries, self.elements, self.keys);
        builder.at = point.at;
        let mut stack = Vec::with_capacity(point.open.len());
        for (entry, children) in &point.open {
            let reopened = &mut builder.entries[*entry as usize];
            let is_object = reopened.kind() == Kind::Object;
            // What the close of the earlier text wrote (its end, count or run, duplicates) is
            // written again by this one's.
            reopened.meta = kind_bits(reopened.kind());
            let scratch = builder.scratch.len();
            if !is_object {
                builder.scratch.extend_from_slice(children);
            }
            stack.push(Open {
                entry: *entry,
                count: children.len() as u32,
                scratch,
                is_object,
            });
        }
        builder.after_value(&mut stack)?;
        Ok(builder.finish())
    }
}

impl Tape {
    /// Where a build of a text equal to this index's up to byte `first_change` can resume:
    /// after the last value that ends by then inside the deepest container that holds the
    /// change and such a value. `None` when no value of the root ends before the change.
    fn resume_point(&self, first_change: usize) -> Option<ResumePoint> {
        let entries = &self.entries;
        let root = entries.first()?;
        if !matches!(root.kind(), Kind::Object | Kind::Array) || root.end as usize <= first_change {
            return None;
        }
        // The children of container `at`: (the entry it starts with, a key's or the value's;
        // the value's entry).
        let children = |at: u32| -> Vec<(u32, u32)> {
            let e = &entries[at as usize];
            if e.kind() == Kind::Object {
                let mut out = Vec::new();
                let mut key = at + 1;
                while key < e.next {
                    out.push((key, key + 1));
                    key = entries[key as usize + 1].next;
                }
                out
            } else {
                let run = e.aux();
                let count = self.elements[run] as usize;
                self.elements[run + 1..run + 1 + count]
                    .iter()
                    .map(|&v| (v, v))
                    .collect()
            }
        };
        // Strictly before: the byte after the value is then the earlier text's too, so the
        // value ends there in the new text as well (a number followed by a changed digit
        // would not).
        let ends_before = |value: u32| (entries[value as usize].end as usize) < first_change;
        let mut open: Vec<(u32, Vec<u32>)> = Vec::new();
        let mut container = 0u32;
        loop {
            let list = children(container);
            let before = list.iter().take_while(|(_, v)| ends_before(*v)).count();
            let values = |n: usize| list[..n].iter().map(|(_, v)| *v).collect::<Vec<u32>>();
            // The child the change starts inside, when it is a container with a value of its
            // own that ends before the change: the build resumes deeper.
            let deeper = list.get(before).filter(|(first, value)| {
                let child = &entries[*value as usize];
                (entries[*first as usize].start as usize) < first_change
                    && matches!(child.kind(), Kind::Object | Kind::Array)
                    && children(*value)
                        .first()
                        .is_some_and(|(_, v)| ends_before(*v))
            });
            if let Some((_, value)) = deeper {
                open.push((container, values(before + 1)));
                container = *value;
                continue;
            }
            if before == 0 {
                // Only the root can hold no value that ends before the change: a deeper
                // container is entered for one.
                return None;
            }
            let last = &entries[list[before - 1].1 as usize];
            open.push((container, values(before)));
            return Some(ResumePoint {
                open,
                after: last.next,
                at: last.end as usize,
            });
        }
    }

    /// The root value of `text`, which must be the text this index was built from.
    pub fn root<'a>(&'a self, text: &'a str) -> Node<'a> {
        Node {
            text,
            tape: self,
            at: 0,
        }
    }
}

impl<'t> Builder<'t> {
    /// A builder at the start of `text`, with room for `entries` entries (advised huge pages
    /// when that is large).
    fn new(text: &'t str, max_depth: usize, entries: usize) -> Builder<'t> {
        let mut room = Vec::with_capacity(entries);
        super::pages::advise_huge(&mut room);
        Builder::with_parts(
            text,
            max_depth,
            room,
            Vec::new(),
            KeyTable::for_text(text.len()),
        )
    }

    /// A builder at the start of `text` that goes on from `entries`, `elements` and `keys`
    /// (empty for a fresh build, an earlier index's for a resumed one).
    fn with_parts(
        text: &'t str,
        max_depth: usize,
        entries: Vec<Entry>,
        elements: Vec<u32>,
        keys: KeyTable,
    ) -> Builder<'t> {
        Builder {
            text,
            bytes: text.as_bytes(),
            at: 0,
            max_depth,
            entries,
            elements,
            scratch: Vec::new(),
            member_keys: Vec::new(),
            keys,
            deepest: 0,
        }
    }

    fn finish(self) -> Tape {
        Tape {
            entries: self.entries,
            elements: self.elements,
            keys: self.keys,
        }
    }

    fn skip_whitespace(&mut self) {
        const SPACES: u64 = u64::from_ne_bytes([b' '; 8]);
        let bytes = self.bytes;
        let mut at = self.at;
        loop {
            match bytes.get(at) {
                Some(b'\n') => {
                    at += 1;
                    // Indentation, a large part of a pretty-printed file, is passed eight
                    // spaces at a time, and the spaces that start the last word at once.
                    while let Some(word) = bytes.get(at..at + 8) {
                        let others =
                            u64::from_le_bytes(word.try_into().expect("eight bytes")) ^ SPACES;
                        if others != 0 {
                            at += (others.trailing_zeros() / 8) as usize;
                            break;
                        }
                        at += 8;
                    }
                }
                Some(b' ' | b'\r' | b'\t') => at += 1,
                _ => break,
            }
        }
        self.at = at;
    }

    fn fail<T>(&self) -> Result<T, TapeError> {
        Err(TapeError::Syntax(self.at))
    }

    fn push(&mut self, kind: Kind, start: usize, meta_extra: u32) -> u32 {
        let index = self.entries.len() as u32;
        self.entries.push(Entry {
            start: start as u32,
            end: self.at as u32,
            next: index + 1,
            meta: kind_bits(kind) | meta_extra,
        });
        index
    }

    /// The whole text: one value, whitespace around it, nothing else.
    fn document(&mut self) -> Result<(), TapeError> {
        let mut stack: Vec<Open> = Vec::new();
        self.skip_whitespace();
        self.value_start(&mut stack)?;
        self.after_value(&mut stack)
    }

    /// The rest of the text from the end of a value, with the containers `stack` still open.
    fn after_value(&mut self, stack: &mut Vec<Open>) -> Result<(), TapeError> {
        self.after_value_until::<false>(stack)
    }

    /// [`Builder::after_value`], or with `ONE_VALUE` only up to the end of the value whose
    /// containers `stack` holds (what follows it is left where it is).
    fn after_value_until<const ONE_VALUE: bool>(
        &mut self,
        stack: &mut Vec<Open>,
    ) -> Result<(), TapeError> {
        loop {
            // Close what ends here, then find where the next value starts.
            loop {
                self.skip_whitespace();
                let Some(open) = stack.last_mut() else {
                    return if ONE_VALUE || self.at == self.bytes.len() {
                        Ok(())
                    } else {
                        self.fail()
                    };
                };
                match self.bytes.get(self.at) {
                    Some(b',') => {
                        self.at += 1;
                        self.skip_whitespace();
                        if open.is_object {
                            self.key()?;
                        }
                        break;
                    }
                    Some(b']') if !open.is_object => {
                        self.at += 1;
                        let open = stack.pop().expect("an open array");
                        self.close(open)?;
                    }
                    Some(b'}') if open.is_object => {
                        self.at += 1;
                        let open = stack.pop().expect("an open object");
                        self.close(open)?;
                    }
                    _ => return self.fail(),
                }
            }
            // A value starts here.
            self.value_start(stack)?;
        }
    }

    /// Reads the value starting here. A scalar is read whole; a container is opened, and so is
    /// the first value inside it, down to the first scalar or empty container.
    fn value_start(&mut self, stack: &mut Vec<Open>) -> Result<(), TapeError> {
        loop {
            let start = self.at;
            // The end of the text, where a value should start: nothing is counted for it (the
            // first half of a split build stops here, its containers as they stand).
            if start == self.bytes.len() {
                return self.fail();
            }
            // A value that is an array element is recorded for its array.
            if let Some(open) = stack.last_mut() {
                if open.count == MAX_AUX {
                    return Err(TapeError::TooLarge);
                }
                open.count += 1;
                if !open.is_object {
                    self.scratch.push(self.entries.len() as u32);
                }
            }
            match self.bytes.get(self.at) {
                Some(b'{') | Some(b'[') => {
                    if stack.len() >= self.max_depth {
                        return Err(TapeError::TooDeep(self.at));
                    }
                    let is_object = self.bytes[self.at] == b'{';
                    self.at += 1;
                    let kind = if is_object { Kind::Object } else { Kind::Array };
                    let entry = self.push(kind, start, 0);
                    let open = Open {
                        entry,
                        count: 0,
                        scratch: self.scratch.len(),
                        is_object,
                    };
                    self.skip_whitespace();
                    let closer = if is_object { b'}' } else { b']' };
                    if self.bytes.get(self.at) == Some(&closer) {
                        self.at += 1;
                        return self.close(open);
                    }
                    stack.push(open);
                    self.deepest = self.deepest.max(stack.len());
                    if is_object {
                        self.key()?;
                    }
                }
                Some(b'"') => {
                    let escaped = self.string()?;
                    self.push(Kind::String, start, if escaped { ESCAPED } else { 0 });
                    return Ok(());
                }
                Some(b'-' | b'0'..=b'9') => {
                    self.number()?;
                    self.push(Kind::Number, start, 0);
                    return Ok(());
                }
                Some(b't') => return self.literal(b"true", Kind::Bool, start),
                Some(b'f') => return self.literal(b"false", Kind::Bool, start),
                Some(b'n') => return self.literal(b"null", Kind::Null, start),
                _ => return self.fail(),
            }
        }
    }

    /// Records the end of a container: its span, and its count or (for an array) its run of
    /// elements.
    fn close(&mut self, open: Open) -> Result<(), TapeError> {
        let next = self.entries.len() as u32;
        let aux = if open.is_object {
            open.count
        } else {
            let run = self.elements.len();
            if run > MAX_AUX as usize {
                return Err(TapeError::TooLarge);
            }
            self.elements.push(open.count);
            self.elements.extend(self.scratch.drain(open.scratch..));
            run as u32
        };
        let duplicates = open.is_object
            && open.count > 1
            && duplicate_keys(&self.entries, open.entry, next, &mut self.member_keys);
        let entry = &mut self.entries[open.entry as usize];
        entry.end = self.at as u32;
        entry.next = next;
        entry.meta |= aux << COUNT_SHIFT;
        if duplicates {
            entry.meta |= DUPLICATES;
        }
        Ok(())
    }

    /// An object key and its colon; leaves `at` on the value.
    fn key(&mut self) -> Result<(), TapeError> {
        if self.bytes.get(self.at) != Some(&b'"') {
            return self.fail();
        }
        let start = self.at;
        let escaped = self.string()?;
        self.key_entry(start, escaped)?;
        self.skip_whitespace();
        if self.bytes.get(self.at) != Some(&b':') {
            return self.fail();
        }
        self.at += 1;
        self.skip_whitespace();
        Ok(())
    }

    /// Records the string from `start` to here as an object key, numbered in the key table.
    #[inline]
    fn key_entry(&mut self, start: usize, escaped: bool) -> Result<u32, TapeError> {
        let id = if escaped {
            // Numbered by what it spells, as the same key written without escapes is.
            let key: String = serde_json::from_str(&self.text[start..self.at]).unwrap_or_default();
            self.keys.intern(&key)
        } else {
            // Between two quotes, which are character boundaries.
            self.keys.intern(&self.text[start + 1..self.at - 1])
        };
        if id > MAX_AUX {
            return Err(TapeError::TooLarge);
        }
        let flags = if escaped { KEY | ESCAPED } else { KEY };
        Ok(self.push(Kind::String, start, flags | id << COUNT_SHIFT))
    }

    fn literal(&mut self, word: &[u8], kind: Kind, start: usize) -> Result<(), TapeError> {
        for &expected in word {
            if self.bytes.get(self.at) != Some(&expected) {
                return self.fail();
            }
            self.at += 1;
        }
        self.push(kind, start, 0);
        Ok(())
    }

    /// A string from its opening quote; says whether it holds escapes. Escapes are checked as
    /// serde_json checks them, lone surrogates included.
    fn string(&mut self) -> Result<bool, TapeError> {
        let start = self.at;
        self.at += 1;
        let mut escaped = false;
        loop {
            // The text is UTF-8 already: only quotes, backslashes and control characters matter.
            match super::json_text::string_stop(&self.bytes[self.at..]) {
                None => {
                    self.at = self.bytes.len();
                    return self.fail();
                }
                Some(i) => {
                    self.at += i;
                    match self.bytes[self.at] {
                        b'"' => {
                            self.at += 1;
                            break;
                        }
                        b'\\' => {
                            escaped = true;
                            self.at += 1;
                            match self.bytes.get(self.at) {
                                Some(b'"' | b'\\' | b'/' | b'b' | b'f' | b'n' | b'r' | b't') => {
                                    self.at += 1
                                }
                                Some(b'u') => {
                                    self.at += 1;
                                    for _ in 0..4 {
                                        match self.bytes.get(self.at) {
                                            Some(b) if b.is_ascii_hexdigit() => self.at += 1,
                                            _ => return self.fail(),
                                        }
                                    }
                                }
                                _ => return self.fail(),
                            }
                        }
                        _ => return self.fail(),
                    }
                }
            }
        }
        if escaped {
            // Surrogate pairing is serde_json's to judge; escapes are rare in glTF.
            let text = std::str::from_utf8(&self.bytes[start..self.at])
                .map_err(|_| TapeError::Syntax(start))?;
            if serde_json::from_str::<String>(text).is_err() {
                return Err(TapeError::Syntax(start));
            }
        }
        Ok(escaped)
    }

    /// `-? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [+-]? [0-9]+)?`
    fn number(&mut self) -> Result<(), TapeError> {
        let digits = |b: &mut Self| {
            let from = b.at;
            while let Some(b'0'..=b'9') = b.bytes.get(b.at) {
                b.at += 1;
            }
            b.at > from
        };
        if self.bytes.get(self.at) == Some(&b'-') {
            self.at += 1;
        }
        match self.bytes.get(self.at) {
            Some(b'0') => self.at += 1,
            Some(b'1'..=b'9') => {
                digits(self);
            }
            _ => return self.fail(),
        }
        if self.bytes.get(self.at) == Some(&b'.') {
            self.at += 1;
            if !digits(self) {
                return self.fail();
            }
        }
        if let Some(b'e' | b'E') = self.bytes.get(self.at) {
            self.at += 1;
            if let Some(b'+' | b'-') = self.bytes.get(self.at) {
                self.at += 1;
            }
            if !digits(self) {
                return self.fail();
            }
        }
        Ok(())
    }
}

/// Whether the object at entry `object`, whose members end before entry `end`, writes a key
/// twice. Checked once when the object closes, so that reading its members needs no check.
/// Keys are compared by their numbers; `keys` is scratch room.
#[inline]
fn duplicate_keys(entries: &[Entry], object: u32, end: u32, keys: &mut Vec<u32>) -> bool {
    keys.clear();
    let mut at = object + 1;
    while at < end {
        keys.push(entries[at as usize].aux() as u32);
        at = entries[at as usize + 1].next;
    }
    if keys.len() <= 16 {
        (1..keys.len()).any(|i| keys[..i].contains(&keys[i]))
    } else {
        keys.sort_unstable();
        keys.windows(2).any(|pair| pair[0] == pair[1])
    }
}

/// One value of an indexed text. Cheap to copy.
#[derive(Clone, Copy)]
pub struct Node<'a> {
    text: &'a str,
    tape: &'a Tape,
    at: u32,
}

impl std::fmt::Debug for Node<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.raw())
    }
}

impl<'a> Node<'a> {
    fn entry(&self) -> &'a Entry {
        &self.tape.entries[self.at as usize]
    }

    fn node(&self, at: u32) -> Node<'a> {
        Node {
            text: self.text,
            tape: self.tape,
            at,
        }
    }

    pub fn kind(&self) -> Kind {
        self.entry().kind()
    }

    /// Whether this key entry is the key numbered `id` in [`Tape::keys`].
    fn key_is(&self, id: u32) -> bool {
        self.entry().aux() as u32 == id
    }

    /// The whole text the index was built from, of which this value is a span.
    pub fn text(&self) -> &'a str {
        self.text
    }

    /// The value's text, as written.
    pub fn raw(&self) -> &'a str {
        let e = self.entry();
        &self.text[e.start as usize..e.end as usize]
    }

    /// Byte span of the value in the text.
    pub fn span(&self) -> std::ops::Range<usize> {
        let e = self.entry();
        e.start as usize..e.end as usize
    }

    /// A number unique to this value within its document.
    pub fn id(&self) -> u32 {
        self.at
    }

    /// The address of the index this value belongs to: with [`Node::id`], a value's identity.
    pub fn document_address(&self) -> usize {
        std::ptr::from_ref(self.tape) as usize
    }

    pub fn is_object(&self) -> bool {
        self.kind() == Kind::Object
    }
    pub fn is_array(&self) -> bool {
        self.kind() == Kind::Array
    }
    pub fn is_string(&self) -> bool {
        self.kind() == Kind::String
    }
    pub fn is_number(&self) -> bool {
        self.kind() == Kind::Number
    }
    pub fn is_null(&self) -> bool {
        self.kind() == Kind::Null
    }

    pub fn as_bool(&self) -> Option<bool> {
        (self.kind() == Kind::Bool).then(|| self.raw() == "true")
    }

    /// A string's value: borrowed from the text when it holds no escapes.
    pub fn as_str(&self) -> Option<Cow<'a, str>> {
        let e = self.entry();
        if e.kind() != Kind::String {
            return None;
        }
        if e.meta & KEY != 0 {
            // A key as the table holds it (unescaped), in cache where the text may not be.
            return Some(Cow::Borrowed(self.tape.keys.key(e.aux() as u32)));
        }
        let raw = self.raw();
        if e.meta & ESCAPED == 0 {
            Some(Cow::Borrowed(&raw[1..raw.len() - 1]))
        } else {
            // Checked when the index was built.
            Some(Cow::Owned(serde_json::from_str(raw).unwrap_or_default()))
        }
    }

    /// Whether this is the string `s`.
    pub fn is_str(&self, s: &str) -> bool {
        self.as_str().is_some_and(|v| v == s)
    }

    /// A number as the nearest f64; `None` past its range (`1e400`), as serde_json reads it.
    pub fn as_f64(&self) -> Option<f64> {
        if self.kind() != Kind::Number {
            return None;
        }
        self.raw().parse().ok().filter(|f: &f64| f.is_finite())
    }

    /// A number written as a non-negative integer that fits in 64 bits (`1.0` is not).
    pub fn as_u64(&self) -> Option<u64> {
        let e = self.entry();
        if e.kind() != Kind::Number {
            return None;
        }
        let digits = &self.text.as_bytes()[e.start as usize..e.end as usize];
        // Up to 19 digits always fit; read here, as most indices and counts are short (the
        // standard parser's checks were two thirds of this function's instructions). A
        // number written otherwise (a sign, a fraction, an exponent, 20 digits) is left to it.
        if digits.len() <= 19 {
            let mut value: u64 = 0;
            for &digit in digits {
                if !digit.is_ascii_digit() {
                    return self.raw().parse().ok();
                }
                value = value * 10 + u64::from(digit - b'0');
            }
            return Some(value);
        }
        self.raw().parse().ok()
    }

    /// A number written as an integer that fits in 64 bits.
    pub fn as_i64(&self) -> Option<i64> {
        if self.kind() != Kind::Number {
            return None;
        }
        self.raw().parse().ok()
    }

    pub fn as_object(&self) -> Option<Object<'a>> {
        self.is_object().then_some(Object { node: *self })
    }

    pub fn as_array(&self) -> Option<Array<'a>> {
        self.is_array().then_some(Array { node: *self })
    }

    /// An object's member (the last, if the key is duplicated) or an array's element, as
    /// `serde_json::Value::get` reads them.
    pub fn get<I: Index>(&self, index: I) -> Option<Node<'a>> {
        index.index_into(*self)
    }

    /// The value an RFC 6901 pointer names, as `serde_json::Value::pointer` finds it.
    pub fn pointer(&self, pointer: &str) -> Option<Node<'a>> {
        if pointer.is_empty() {
            return Some(*self);
        }
        let mut rest = pointer.strip_prefix('/')?;
        let mut node = *self;
        loop {
            // The next token ends at the next '/', found byte by byte: `str::split`'s searcher
            // took more instructions than the lookups of a pointer a few tokens long.
            let end = rest.bytes().position(|b| b == b'/').unwrap_or(rest.len());
            let token = super::pointer::unescape(&rest[..end]);
            node = match node.kind() {
                Kind::Object => node.as_object()?.get(&token)?,
                // As serde_json: decimal digits without a leading zero (but "0").
                Kind::Array => node.as_array()?.get(super::pointer::array_index(&token)?)?,
                _ => return None,
            };
            if end == rest.len() {
                return Some(node);
            }
            rest = &rest[end + 1..];
        }
    }

    /// The number of `key` in this document, if any of its objects has that key.
    pub fn key_id(&self, key: &str) -> Option<KeyId> {
        self.tape.keys.id(key).map(KeyId)
    }

    /// An object's member by its key's number ([`Node::key_id`] on the same document; `None`,
    /// a key the document does not have, finds nothing): [`Node::get`] for a key a rule looks
    /// up in thousands of objects, found in the key table once rather than each time.
    pub fn get_by(&self, key: Option<KeyId>) -> Option<Node<'a>> {
        self.as_object()?.get_id(key?)
    }

    /// The value of every object member named `key` anywhere inside this value, in text order,
    /// found by one scan of the index rather than a walk. Rules use it to rule out a finding
    /// cheaply before walking for its path.
    pub fn members_named<'k>(&self, key: &'k str) -> impl Iterator<Item = Node<'a>> + 'k
    where
        'a: 'k,
    {
        let node = *self;
        let entries = &self.tape.entries[self.at as usize + 1..self.entry().next as usize];
        let first = self.at + 1;
        // A key the text does not have is the key of no member: no scan.
        let id = self.tape.keys.id(key);
        id.into_iter().flat_map(move |id| {
            entries
                .iter()
                .enumerate()
                .filter(move |(_, e)| e.meta & KEY != 0 && e.aux() as u32 == id)
                .map(move |(i, _)| node.node(first + i as u32 + 1))
        })
    }

    /// The value as a `serde_json::Value`, for the few places that need one (error reports,
    /// comparisons of whole values).
    pub fn to_value(&self) -> Value {
        // Made from the index, not parsed again from the text: the value serde_json reads from
        // this value's text, null where it refuses the text (nested deeper than its limit).
        self.value_within(SERDE_DEPTH_LIMIT).unwrap_or(Value::Null)
    }

    /// [`Node::to_value`] with `depth` more containers allowed inside this one (this one
    /// included); `None` past them, as serde_json refuses such a text.
    fn value_within(&self, depth: usize) -> Option<Value> {
        Some(match self.kind() {
            Kind::Null => Value::Null,
            Kind::Bool => Value::Bool(self.as_bool() == Some(true)),
            // The number keeps its text, as serde_json reads it (arbitrary precision).
            Kind::Number => Value::Number(self.raw().parse::<serde_json::Number>().ok()?),
            Kind::String => Value::String(self.as_str()?.into_owned()),
            Kind::Array => {
                let depth = depth.checked_sub(1)?;
                let array = self.as_array()?;
                let mut elements = Vec::with_capacity(array.len());
                for element in array.iter() {
                    elements.push(element.value_within(depth)?);
                }
                Value::Array(elements)
            }
            Kind::Object => {
                let depth = depth.checked_sub(1)?;
                let object = self.as_object()?;
                let mut members = serde_json::Map::with_capacity(object.len());
                // Each key once, at its first place, with its last value: serde_json's map
                // (insertion order) keeps a repeated key so.
                for (key, value) in object.iter() {
                    members.insert(key.into_owned(), value.value_within(depth)?);
                }
                Value::Object(members)
            }
        })
    }
}

/// How many containers serde_json reads one inside another: it refuses the 128th (its
/// recursion limit).
const SERDE_DEPTH_LIMIT: usize = 127;

/// What [`Node::get`] takes: a key or an array index.
pub trait Index {
    fn index_into<'a>(&self, node: Node<'a>) -> Option<Node<'a>>;
}

impl Index for &str {
    fn index_into<'a>(&self, node: Node<'a>) -> Option<Node<'a>> {
        node.as_object()?.get(self)
    }
}

impl Index for usize {
    fn index_into<'a>(&self, node: Node<'a>) -> Option<Node<'a>> {
        node.as_array()?.get(*self)
    }
}

impl Index for &String {
    fn index_into<'a>(&self, node: Node<'a>) -> Option<Node<'a>> {
        node.as_object()?.get(self)
    }
}

/// An object's members.
#[derive(Clone, Copy)]
pub struct Object<'a> {
    node: Node<'a>,
}

impl<'a> Object<'a> {
    /// Members as written, duplicates included: (key entry, value entry).
    fn raw_members(&self) -> RawMembers<'a> {
        let e = self.node.entry();
        RawMembers {
            node: self.node,
            at: self.node.at + 1,
            end: e.next,
        }
    }

    /// The value of `key`: the last one, if the key is written more than once.
    pub fn get(&self, key: &str) -> Option<Node<'a>> {
        // A key the text does not have is the key of no member.
        self.get_key(self.node.tape.keys.id(key)?)
    }

    /// The value of the key numbered `key` (from [`Node::key_id`] on the same document), as
    /// [`Object::get`] gives it.
    pub fn get_id(&self, key: KeyId) -> Option<Node<'a>> {
        self.get_key(key.0)
    }

    /// The value of the key numbered `id`: the last one, if the key is written more than once.
    fn get_key(&self, id: u32) -> Option<Node<'a>> {
        let mut found = None;
        for (k, v) in self.raw_members() {
            if self.node.node(k).key_is(id) {
                found = Some(v);
                if !self.has_duplicates() {
                    break;
                }
            }
        }
        found.map(|at| self.node.node(at))
    }

    /// Members as written, a duplicated key at each of its places: (key, value).
    pub fn entries(&self) -> Vec<(Node<'a>, Node<'a>)> {
        self.raw_members()
            .map(|(k, v)| (self.node.node(k), self.node.node(v)))
            .collect()
    }

    /// Whether the object writes a key more than once.
    pub fn has_duplicate_keys(&self) -> bool {
        self.has_duplicates()
    }

    /// [`Object::contains_key`] by the key's number, as [`Node::get_by`] takes it.
    pub fn contains_id(&self, key: Option<KeyId>) -> bool {
        key.is_some_and(|id| {
            self.raw_members()
                .any(|(k, _)| self.node.node(k).key_is(id.0))
        })
    }

    pub fn contains_key(&self, key: &str) -> bool {
        self.contains_id(self.node.tape.keys.id(key).map(KeyId))
    }

    /// Distinct keys.
    pub fn len(&self) -> usize {
        let count = self.node.entry().aux();
        if self.has_duplicates() {
            self.iter().count()
        } else {
            count
        }
    }

    pub fn is_empty(&self) -> bool {
        self.node.entry().aux() == 0
    }

    fn has_duplicates(&self) -> bool {
        self.node.entry().meta & DUPLICATES != 0
    }

    /// Members in order: each key once, at its first place, with its last value.
    pub fn iter(&self) -> Members<'a> {
        let duplicates = self.has_duplicates();
        Members {
            object: *self,
            raw: self.raw_members(),
            duplicates,
        }
    }

    pub fn keys(&self) -> impl Iterator<Item = Cow<'a, str>> + 'a {
        self.iter().map(|(k, _)| k)
    }

    /// [`Object::iter`] with each key's number in the document ([`Node::key_id`]): a walk
    /// that decides by key can remember its decision by number rather than compare names.
    pub fn iter_keyed(&self) -> impl Iterator<Item = (KeyId, Cow<'a, str>, Node<'a>)> + 'a {
        let mut members = self.iter();
        std::iter::from_fn(move || members.next_keyed())
    }
}

#[derive(Clone)]
struct RawMembers<'a> {
    node: Node<'a>,
    at: u32,
    end: u32,
}

impl Iterator for RawMembers<'_> {
    /// (key entry, value entry)
    type Item = (u32, u32);
    fn next(&mut self) -> Option<(u32, u32)> {
        if self.at >= self.end {
            return None;
        }
        let key = self.at;
        let value = key + 1;
        self.at = self.node.tape.entries[value as usize].next;
        Some((key, value))
    }
}

/// The members of an object, as [`Object::iter`] gives them.
pub struct Members<'a> {
    object: Object<'a>,
    raw: RawMembers<'a>,
    duplicates: bool,
}

impl<'a> Members<'a> {
    /// The next member with its key's number. Inlined where members are walked: this is the
    /// walk of every member by every rule and schema check, and a call for each member took
    /// half its instructions.
    #[inline]
    fn next_keyed(&mut self) -> Option<(KeyId, Cow<'a, str>, Node<'a>)> {
        let (k, v) = self.raw.next()?;
        if self.duplicates {
            return self.next_of_duplicated(k, v);
        }
        let node = self.object.node;
        let id = node.node(k).entry().aux() as u32;
        // The key as the table holds it (unescaped), as `as_str` reads a key entry, without
        // asking the entry's kind again.
        Some((
            KeyId(id),
            Cow::Borrowed(node.tape.keys.key(id)),
            node.node(v),
        ))
    }

    /// [`Members::next_keyed`] of an object that writes a key twice, from its member at key
    /// entry `k` and value entry `v`: a key seen before was given at its first place, and a
    /// first one takes its last value.
    #[cold]
    #[inline(never)]
    fn next_of_duplicated(
        &mut self,
        mut k: u32,
        mut v: u32,
    ) -> Option<(KeyId, Cow<'a, str>, Node<'a>)> {
        let node = self.object.node;
        loop {
            let id = node.node(k).entry().aux() as u32;
            let mut earlier = RawMembers {
                node,
                at: node.at + 1,
                end: k,
            };
            if !earlier.any(|(e, _)| node.node(e).key_is(id)) {
                let value = self.object.get_key(id).unwrap_or(node.node(v));
                return Some((KeyId(id), Cow::Borrowed(node.tape.keys.key(id)), value));
            }
            (k, v) = self.raw.next()?;
        }
    }
}

impl<'a> Iterator for Members<'a> {
    type Item = (Cow<'a, str>, Node<'a>);
    fn next(&mut self) -> Option<Self::Item> {
        self.next_keyed().map(|(_, key, value)| (key, value))
    }
}

/// An array's elements.
#[derive(Clone, Copy)]
pub struct Array<'a> {
    node: Node<'a>,
}

impl<'a> Array<'a> {
    fn indices(&self) -> &'a [u32] {
        let e = self.node.entry();
        let run = e.aux();
        let elements = &self.node.tape.elements;
        let count = elements[run] as usize;
        &elements[run + 1..run + 1 + count]
    }

    pub fn len(&self) -> usize {
        self.node.tape.elements[self.node.entry().aux()] as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn get(&self, index: usize) -> Option<Node<'a>> {
        self.indices().get(index).map(|&at| self.node.node(at))
    }

    pub fn iter(&self) -> Elements<'a> {
        Elements {
            node: self.node,
            indices: self.indices().iter(),
        }
    }
}

/// The elements of an array, in order.
pub struct Elements<'a> {
    node: Node<'a>,
    indices: std::slice::Iter<'a, u32>,
}

impl<'a> Iterator for Elements<'a> {
    type Item = Node<'a>;
    fn next(&mut self) -> Option<Node<'a>> {
        self.indices.next().map(|&at| self.node.node(at))
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.indices.size_hint()
    }
}

impl ExactSizeIterator for Elements<'_> {}

impl<'a> DoubleEndedIterator for Elements<'a> {
    fn next_back(&mut self) -> Option<Node<'a>> {
        self.indices.next_back().map(|&at| self.node.node(at))
    }
}

/// Read access that the index's [`Node`] and `&serde_json::Value` share, for the helpers that
/// both the rules (which read the index) and the editors (which read and change a `Value`) use.
/// The names differ from the inherent methods so that a call always says which it means.
pub trait JsonView<'a>: Copy + 'a {
    /// An object's member (the last, if duplicated).
    fn member(self, key: &str) -> Option<Self>;
    /// An array's element.
    fn element(self, index: usize) -> Option<Self>;
    /// An array's length.
    fn length(self) -> Option<usize>;
    /// An object's members in order, each key once.
    fn members(self) -> Option<Vec<(Cow<'a, str>, Self)>>;
    fn number(self) -> Option<f64>;
    fn unsigned(self) -> Option<u64>;
    fn text(self) -> Option<Cow<'a, str>>;
    fn object(self) -> bool;
}

impl<'a> JsonView<'a> for Node<'a> {
    fn member(self, key: &str) -> Option<Self> {
        self.as_object()?.get(key)
    }
    fn element(self, index: usize) -> Option<Self> {
        self.as_array()?.get(index)
    }
    fn length(self) -> Option<usize> {
        Some(self.as_array()?.len())
    }
    fn members(self) -> Option<Vec<(Cow<'a, str>, Self)>> {
        Some(self.as_object()?.iter().collect())
    }
    fn number(self) -> Option<f64> {
        self.as_f64()
    }
    fn unsigned(self) -> Option<u64> {
        self.as_u64()
    }
    fn text(self) -> Option<Cow<'a, str>> {
        self.as_str()
    }
    fn object(self) -> bool {
        self.is_object()
    }
}

impl<'a> JsonView<'a> for &'a Value {
    fn member(self, key: &str) -> Option<Self> {
        self.as_object()?.get(key)
    }
    fn element(self, index: usize) -> Option<Self> {
        self.as_array()?.get(index)
    }
    fn length(self) -> Option<usize> {
        Some(self.as_array()?.len())
    }
    fn members(self) -> Option<Vec<(Cow<'a, str>, Self)>> {
        Some(
            self.as_object()?
                .iter()
                .map(|(k, v)| (Cow::Borrowed(k.as_str()), v))
                .collect(),
        )
    }
    fn number(self) -> Option<f64> {
        self.as_f64()
    }
    fn unsigned(self) -> Option<u64> {
        self.as_u64()
    }
    fn text(self) -> Option<Cow<'a, str>> {
        self.as_str().map(Cow::Borrowed)
    }
    fn object(self) -> bool {
        self.is_object()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value of `text`, made from the index, is the value serde_json reads from the
    /// value's own text (null where it refuses it).
    fn assert_values_are_serde_jsons(text: &str) {
        let tape = Tape::build(text).unwrap();
        let mut stack = vec![tape.root(text)];
        while let Some(node) = stack.pop() {
            let read: Value = serde_json::from_str(node.raw()).unwrap_or(Value::Null);
            assert_eq!(node.to_value(), read, "{}", node.raw());
            // Compared as text too: a map's order and a number's spelling.
            assert_eq!(node.to_value().to_string(), read.to_string());
            if let Some(array) = node.as_array() {
                stack.extend(array.iter());
            }
            if let Some(object) = node.as_object() {
                stack.extend(object.iter().map(|(_, v)| v));
            }
        }
    }

    #[test]
    fn a_value_made_from_the_index_is_what_serde_json_reads_from_its_text() {
        assert_values_are_serde_jsons(
            r#"{"b": [1, 1.50, -0, 1e400, 12345678901234567890123, 2E-3], "a": {"x": null, "y": true},
                "esc\u0041\n": "\u00e9\ud83d\ude00\"", "a": {"z": false}, "": [[], {}, ""],
                "b": "last"}"#,
        );
    }

    #[test]
    fn a_value_nested_past_serde_jsons_limit_is_null_as_serde_json_refuses_its_text() {
        for depth in [126, 127, 128, 129, 140] {
            let text = format!("{}1{}", "[".repeat(depth), "]".repeat(depth));
            let tape = Tape::build(&text).unwrap();
            let root = tape.root(&text);
            let expected: Value = serde_json::from_str(&text).unwrap_or(Value::Null);
            assert_eq!(root.to_value(), expected, "depth {depth}");
            assert_eq!(root.to_value().is_null(), depth >= 128, "depth {depth}");
            let objects = format!("{}1{}", "{\"k\":".repeat(depth), "}".repeat(depth));
            let tape = Tape::build(&objects).unwrap();
            assert_eq!(
                tape.root(&objects).to_value().is_null(),
                depth >= 128,
                "depth {depth}"
            );
        }
    }

    /// Rebuilds a `Value` through the index's own accessors (not `to_value`).
    pub(super) fn rebuild(node: Node) -> Value {
        match node.kind() {
            Kind::Null => Value::Null,
            Kind::Bool => Value::Bool(node.as_bool().unwrap()),
            Kind::Number => serde_json::from_str(node.raw()).unwrap(),
            Kind::String => Value::String(node.as_str().unwrap().into_owned()),
            Kind::Array => Value::Array(node.as_array().unwrap().iter().map(rebuild).collect()),
            Kind::Object => Value::Object(
                node.as_object()
                    .unwrap()
                    .iter()
                    .map(|(k, v)| (k.into_owned(), rebuild(v)))
                    .collect(),
            ),
        }
    }

    fn agrees(text: &str) {
        let ours = Tape::build(text);
        let theirs = serde_json::from_str::<Value>(text);
        match (&ours, &theirs) {
            (Ok(tape), Ok(value)) => {
                assert_eq!(&rebuild(tape.root(text)), value, "{text:?}");
                // Key order too.
                assert_eq!(
                    serde_json::to_string(&rebuild(tape.root(text))).unwrap(),
                    serde_json::to_string(value).unwrap()
                );
            }
            (Err(_), Err(_)) => {}
            _ => panic!(
                "{text:?}: index says {:?}, serde_json says {:?}",
                ours.is_ok(),
                theirs.is_ok()
            ),
        }
    }

    #[test]
    fn accepts_and_refuses_what_serde_json_does() {
        for text in [
            "{}",
            "[]",
            " { \"a\" : [1, -0, 0.5, 1e3, 1E-3, -1.5e+2, true, false, null, \"x\"] } ",
            "{\"a\":{\"b\":[[],[{}],[[1]]]}}",
            "\"\\u00e9\\n\\\"\\\\\\/\"",
            "\"\\ud83d\\ude00\"",
            "123",
            "[1,]",
            "{\"a\":1,}",
            "[01]",
            "[1.]",
            "[.5]",
            "[1e]",
            "[-]",
            "[+1]",
            "{\"a\" 1}",
            "{1:2}",
            "[tru]",
            "[nul]",
            "\"a\tb\"",
            "\"\\x\"",
            "\"\\u12\"",
            "\"\\ud800\"",
            "\"\\udc00\"",
            "{} {}",
            "[1] x",
            "",
            "   ",
            "[",
            "{\"a\":",
            "\"open",
            "[1 2]",
            "{\"a\":1 \"b\":2}",
            "\u{feff}{}",
            "[1e400, -1e400, 123456789012345678901234567890]",
            "{\"a\":1,\"b\":2,\"a\":3}",
        ] {
            agrees(text);
        }
    }

    #[test]
    fn duplicate_keys_read_as_serde_json_reads_them() {
        let text = r#"{"a":1,"b":2,"a":3}"#;
        let tape = Tape::build(text).unwrap();
        let obj = tape.root(text).as_object().unwrap();
        assert_eq!(obj.get("a").unwrap().as_u64(), Some(3));
        assert_eq!(obj.len(), 2);
        let keys: Vec<_> = obj.keys().collect();
        assert_eq!(keys, ["a", "b"]);
    }

    #[test]
    fn a_key_written_with_escapes_is_the_key_it_spells() {
        let text = r#"{"\u0061":1,"b":2,"a":3,"\"q\"":{"x":4},"none\/":5}"#;
        let tape = Tape::build(text).unwrap();
        let value: Value = serde_json::from_str(text).unwrap();
        let obj = tape.root(text).as_object().unwrap();
        assert!(obj.has_duplicate_keys());
        assert_eq!(obj.get("a").unwrap().as_u64(), Some(3));
        assert_eq!(obj.get("\"q\"").unwrap().to_value(), value["\"q\""]);
        assert_eq!(obj.get("none/").unwrap().as_u64(), Some(5));
        assert!(obj.get("\\u0061").is_none() && obj.get("none\\/").is_none());
        assert!(obj.get("x").is_none(), "a key of another object");
        assert!(obj.get("c").is_none() && !obj.contains_key("c"));
        let keys: Vec<_> = obj.keys().collect();
        assert_eq!(keys, ["a", "b", "\"q\"", "none/"]);
        assert_eq!(obj.len(), 4);
        let named: Vec<u64> = tape
            .root(text)
            .members_named("a")
            .filter_map(|n| n.as_u64())
            .collect();
        assert_eq!(named, [1, 3]);
        assert_eq!(tape.root(text).members_named("zz").count(), 0);
    }

    #[test]
    fn a_duplicate_among_many_keys_is_found() {
        let members = |last: &str| {
            let mut text: String = (0..40).map(|i| format!("\"k{i}\":{i},")).collect();
            text.push_str(last);
            format!("{{{text}}}")
        };
        for (last, duplicates, k7) in [(r#""k40":40"#, false, 7), (r#""k\u0037":70"#, true, 70)] {
            let text = members(last);
            let tape = Tape::build(&text).unwrap();
            let obj = tape.root(&text).as_object().unwrap();
            assert_eq!(obj.has_duplicate_keys(), duplicates, "{last}");
            assert_eq!(obj.get("k7").unwrap().as_u64(), Some(k7));
            let value: Value = serde_json::from_str(&text).unwrap();
            assert_eq!(obj.len(), value.as_object().unwrap().len());
        }
    }

    #[test]
    fn numbers_read_as_serde_json_reads_them() {
        let text = "[1, 1.0, -0, 18446744073709551615, 18446744073709551616, -3, 1e2, 0.1, 1e400, -1e400, 5e-400, 0, 5126, 9999999999999999999, 10000000000000000000, 99999999999999999999]";
        let tape = Tape::build(text).unwrap();
        let value: Value = serde_json::from_str(text).unwrap();
        for (i, node) in tape.root(text).as_array().unwrap().iter().enumerate() {
            assert_eq!(node.as_u64(), value[i].as_u64(), "{i}");
            assert_eq!(node.as_i64(), value[i].as_i64(), "{i}");
            assert_eq!(node.as_f64(), value[i].as_f64(), "{i}");
        }
    }

    /// A member found by its key's number is the member found by its key: the last of a
    /// duplicated key, nothing for a key the object lacks or the document never writes, and
    /// nothing in a value that is not an object.
    #[test]
    fn members_by_key_number_are_the_members_by_key() {
        let text = r#"{"a":1,"b":{"a":2,"a":3,"c":[]},"d":[{"a":4}]}"#;
        let tape = Tape::build(text).unwrap();
        let root = tape.root(text);
        let b = root.get("b").unwrap();
        let values = [
            root,
            b,
            root.pointer("/d/0").unwrap(),
            root.get("d").unwrap(),
        ];
        for key in ["a", "b", "c", "d", "e"] {
            let id = root.key_id(key);
            assert_eq!(id.is_some(), key != "e");
            for value in values {
                assert_eq!(
                    value.get_by(id).map(|n| n.raw()),
                    value.get(key).map(|n| n.raw()),
                    "{key} in {value:?}"
                );
                if let Some(object) = value.as_object() {
                    assert_eq!(object.contains_id(id), object.contains_key(key));
                }
            }
        }
        assert_eq!(b.get_by(root.key_id("a")).unwrap().raw(), "3");
    }

    #[test]
    fn pointers_resolve_as_serde_json_resolves_them() {
        let text = r#"{"a/b":{"~k":[10,[20,21]]},"":{"":5},"n":[1,2]}"#;
        let tape = Tape::build(text).unwrap();
        let value: Value = serde_json::from_str(text).unwrap();
        for p in [
            "",
            "/a~1b",
            "/a~1b/~0k/1/0",
            "/a~1b/~0k/01",
            "/a~1b/~0k/+1",
            "/",
            "//",
            "/n/2",
            "/n/-",
            "x",
            "/n/1/x",
        ] {
            assert_eq!(
                tape.root(text).pointer(p).map(|n| n.to_value()),
                value.pointer(p).cloned(),
                "{p}"
            );
        }
    }

    #[test]
    fn spans_cover_values_as_written() {
        let text = "{ \"k\" : [ 1 , \"s\\u0041\" ] }";
        let tape = Tape::build(text).unwrap();
        let k = tape.root(text).get("k").unwrap();
        assert_eq!(k.raw(), "[ 1 , \"s\\u0041\" ]");
        assert_eq!(k.get(1).unwrap().as_str().unwrap(), "sA");
        assert_eq!(k.get(0).unwrap().span(), 10..11);
        assert!(tape.root(text).get("s").is_none() && k.get(2).is_none());
    }

    #[test]
    fn nesting_past_the_limit_is_refused_at_its_bracket() {
        assert!(Tape::build_within("{\"a\":[[1]]}", 3).is_ok());
        assert_eq!(
            Tape::build_within("{\"a\":[[[1]]]}", 3).unwrap_err(),
            TapeError::TooDeep(7)
        );
        // Brackets inside strings do not nest.
        assert!(Tape::build_within("[\"[[[[\"]", 1).is_ok());
    }

    #[test]
    fn members_named_finds_every_member_of_that_name_in_text_order() {
        let text = r#"{"x":1,"a":{"x":2,"b":[{"x":3},{"\u0078":4}]},"y":{"xx":5}}"#;
        let tape = Tape::build(text).unwrap();
        let found: Vec<u64> = tape
            .root(text)
            .members_named("x")
            .filter_map(|n| n.as_u64())
            .collect();
        assert_eq!(found, [1, 2, 3, 4]);
        let inner = tape.root(text).get("a").unwrap();
        assert_eq!(inner.members_named("x").count(), 3);
        assert_eq!(tape.root(text).members_named("z").count(), 0);
    }

    #[test]
    fn errors_name_the_byte_where_reading_stopped() {
        assert_eq!(Tape::build("[1, x]").unwrap_err(), TapeError::Syntax(4));
        assert_eq!(
            Tape::build("{\"a\":1}  ,").unwrap_err(),
            TapeError::Syntax(9)
        );
    }
}

#[cfg(test)]
pub(crate) mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Any JSON value: scalars, escaped strings, and arrays and objects of them a few deep.
    pub(crate) fn json_value() -> impl Strategy<Value = Value> {
        let leaf = prop_oneof![
            Just(Value::Null),
            any::<bool>().prop_map(Value::Bool),
            any::<i64>().prop_map(Value::from),
            (-1e6f64..1e6).prop_map(Value::from),
            "[a-z\\\\\"é\u{1F600}\n]{0,6}".prop_map(Value::String),
        ];
        leaf.prop_recursive(4, 40, 6, |inner| {
            prop_oneof![
                prop::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
                prop::collection::vec(("[ab~/]{0,3}", inner), 0..6)
                    .prop_map(|m| Value::Object(m.into_iter().collect())),
            ]
        })
    }

    /// An entry as [`canonical`] gives it: span, next entry, kind and flags (and count or
    /// run), and for a key what it spells in place of its number.
    type CanonicalEntry = (u32, u32, u32, u32, Option<Vec<u8>>);

    /// The index in a form two builds of one text must share: every entry (a key entry's
    /// number replaced by what the key table says it spells), the arrays' runs, and each key
    /// found by its spelling under the number its entries hold.
    fn canonical(tape: &Tape, text: &str) -> (Vec<CanonicalEntry>, Vec<u32>) {
        let entries = tape
            .entries
            .iter()
            .map(|e| {
                if e.meta & KEY != 0 {
                    let raw = &text[e.start as usize..e.end as usize];
                    let spelled: String = serde_json::from_str(raw).unwrap();
                    assert_eq!(
                        tape.keys.id(&spelled),
                        Some(e.aux() as u32),
                        "key {raw} found under its number"
                    );
                    let meta = e.meta & ((1 << COUNT_SHIFT) - 1);
                    (e.start, e.end, e.next, meta, Some(spelled.into_bytes()))
                } else {
                    (e.start, e.end, e.next, e.meta, None)
                }
            })
            .collect();
        (entries, tape.elements.clone())
    }

    /// `text`, which equals the text `earlier` indexes up to byte `first_change`, indexed from
    /// what a resumption takes of `earlier` (from its first byte when it takes nothing), as a
    /// fix's trial indexes a fixed text.
    fn build_resumed(
        text: &str,
        max_depth: usize,
        earlier: &Tape,
        first_change: usize,
    ) -> Result<Tape, TapeError> {
        match earlier.resumption(first_change, text.len()) {
            Some(resumption) => resumption.build(text, max_depth),
            None => Tape::build_within(text, max_depth),
        }
    }

    /// `changed`, a text that equals `text` (indexed as `earlier`) up to its first changed
    /// byte, indexed from there ([`build_resumed`]) and from its first byte: an error
    /// naming the text when the two differ (in the index, or in the refusal); else whether the
    /// build did resume.
    fn resumed_as_fresh(
        earlier: &Tape,
        text: &str,
        changed: &str,
        max_depth: usize,
    ) -> Result<bool, String> {
        let first_change = text
            .bytes()
            .zip(changed.bytes())
            .position(|(a, b)| a != b)
            .unwrap_or(text.len().min(changed.len()));
        let fresh = Tape::build_within(changed, max_depth);
        let resumed = build_resumed(changed, max_depth, earlier, first_change);
        let same = match (&fresh, &resumed) {
            (Ok(fresh), Ok(resumed)) => canonical(fresh, changed) == canonical(resumed, changed),
            _ => fresh.as_ref().err() == resumed.as_ref().err(),
        };
        if !same {
            return Err(format!("resumed and fresh index differ on {changed:?}"));
        }
        Ok(earlier.resume_point(first_change).is_some())
    }

    /// Every place of a few texts (nested objects and arrays, compact and pretty), each part of
    /// up to three bytes replaced by each of a list of texts: the resumed index is the fresh
    /// one, and most of the builds did resume.
    #[test]
    fn an_index_resumed_at_every_place_of_a_few_texts_is_the_fresh_index() {
        let value: Value = serde_json::from_str(
            r#"{"a":[1,[2,3],{"b":[4,{"c":5}]}],"d":{"e":{"f":[6,7],"g":"h"},"i":[]},"j":"k\u0061","a":0}"#,
        )
        .unwrap();
        let replacements = [
            "",
            "1",
            "\"a\"",
            "{}",
            "[]",
            "[1,[2]]",
            "{\"a\":{\"b\":1}}",
            ",\"k\":0",
            ",1",
            "]",
            "}",
            ",",
            " ",
            "\"a\":",
            "null,",
            "\"\\u0061\":2,",
            ",\"a\":[9]",
        ];
        let (mut resumed_builds, mut builds) = (0, 0);
        for text in [
            r#"{"a":[1,[2,3],{"b":[4,{"c":5}]}],"d":{"e":{"f":[6,7],"g":"h"},"i":[]},"j":"k\u0061","a":0}"#.to_string(),
            serde_json::to_string_pretty(&value).unwrap(),
        ] {
            let earlier = Tape::build(&text).unwrap();
            for start in (0..=text.len()).filter(|i| text.is_char_boundary(*i)) {
                for length in 0..=3 {
                    let end = (start + length).min(text.len());
                    if !text.is_char_boundary(end) {
                        continue;
                    }
                    for replacement in replacements {
                        let changed = format!("{}{}{}", &text[..start], replacement, &text[end..]);
                        let resumed = resumed_as_fresh(&earlier, &text, &changed, 5).unwrap();
                        builds += 1;
                        resumed_builds += usize::from(resumed);
                    }
                }
            }
        }
        assert!(
            resumed_builds * 4 > builds * 3,
            "{resumed_builds} of {builds} resumed"
        );
    }

    /// What a resumption copied ahead of the text indexes the text it was taken for as a fresh
    /// build does; given a text of another length (a caller's mistake, or padding trimmed
    /// after), it indexes that text from its first byte, still as a fresh build does.
    #[test]
    fn a_resumption_taken_ahead_indexes_its_text_and_only_its_text_from_the_earlier_index() {
        let text = r#"{"a":[1,2,{"b":3}],"c":{"d":[4,5]},"e":6}"#;
        let earlier = Tape::build(text).unwrap();
        let changed = r#"{"a":[1,2,{"b":3}],"c":{"d":[4,50]},"e":6}"#;
        let first_change = text.find("5]").unwrap();
        let fresh = canonical(&Tape::build(changed).unwrap(), changed);
        let resumption = earlier.resumption(first_change, changed.len()).unwrap();
        assert!(
            resumption.point.after > 1,
            "the build resumes past the root"
        );
        let resumed = resumption.build(changed, 64).unwrap();
        assert_eq!(canonical(&resumed, changed), fresh);
        // Another text, which differs from the earlier one before the resumption's place.
        let longer = r#"{"a":[100,2,{"b":3}],"c":{"d":[4,5]},"e":6}"#;
        let from_start = earlier
            .resumption(first_change, changed.len())
            .unwrap()
            .build(longer, 64)
            .unwrap();
        assert_eq!(
            canonical(&from_start, longer),
            canonical(&Tape::build(longer).unwrap(), longer)
        );
    }

    proptest! {
        /// Every value of any JSON text, made from the index, is what serde_json reads from
        /// that value's text.
        #[test]
        fn a_value_made_from_the_index_is_serde_jsons_reading_of_its_text(
            value in json_value(),
            pretty in any::<bool>(),
        ) {
            let text = if pretty {
                serde_json::to_string_pretty(&value).unwrap()
            } else {
                serde_json::to_string(&value).unwrap()
            };
            let tape = Tape::build(&text).unwrap();
            prop_assert_eq!(tape.root(&text).to_value(), value);
            let mut stack = vec![tape.root(&text)];
            while let Some(node) = stack.pop() {
                let read: Value = serde_json::from_str(node.raw()).unwrap();
                prop_assert_eq!(node.to_value(), read);
                if let Some(array) = node.as_array() {
                    stack.extend(array.iter());
                }
                if let Some(object) = node.as_object() {
                    stack.extend(object.iter().map(|(_, v)| v));
                }
            }
        }

        /// A text with a part replaced, indexed from the earlier text's index from the first
        /// changed byte on, is indexed as a fresh build indexes it: the same entries, runs and
        /// key lookups, or the same refusal.
        #[test]
        fn an_index_resumed_at_the_first_change_is_the_fresh_index(
            value in json_value(),
            pretty in any::<bool>(),
            from in any::<prop::sample::Index>(),
            length in 0usize..12,
            replacement in prop::sample::select(vec![
                "", "1", "\"a\"", "{}", "[]", "[1,[2]]", "{\"a\":{\"b\":1}}", ",\"k\":0",
                ",1", "]", "}", ",", " ", "\"a\":", "null,", "\"\\u0061\":2,",
            ]),
        ) {
            let text = if pretty {
                serde_json::to_string_pretty(&value).unwrap()
            } else {
                serde_json::to_string(&value).unwrap()
            };
            let earlier = Tape::build(&text).unwrap();
            let mut start = from.index(text.len() + 1);
            while !text.is_char_boundary(start) {
                start -= 1;
            }
            let mut end = (start + length).min(text.len());
            while !text.is_char_boundary(end) {
                end += 1;
            }
            let changed = format!("{}{}{}", &text[..start], replacement, &text[end..]);
            if let Err(differ) = resumed_as_fresh(&earlier, &text, &changed, 6) {
                return Err(TestCaseError::fail(differ));
            }
        }

        /// Any JSON text, and any cut or one-byte change of it, gets the same verdict from the
        /// index as from serde_json, and the same values when both read it.
        #[test]
        fn the_index_reads_what_serde_json_reads(
            value in json_value(),
            pretty in any::<bool>(),
            cut in any::<prop::sample::Index>(),
            at in any::<prop::sample::Index>(),
            byte in prop::sample::select(b"{}[]\",:0-.eE+ tfn\\x1".to_vec()),
        ) {
            let text = if pretty {
                serde_json::to_string_pretty(&value).unwrap()
            } else {
                serde_json::to_string(&value).unwrap()
            };
            let tape = Tape::build(&text).unwrap();
            prop_assert_eq!(&super::tests::rebuild(tape.root(&text)), &value);
            let mut bytes = text.clone().into_bytes();
            let cut_at = cut.index(bytes.len() + 1);
            let cut_text = String::from_utf8_lossy(&bytes[..cut_at]).into_owned();
            prop_assert_eq!(Tape::build(&cut_text).is_ok(), serde_json::from_str::<Value>(&cut_text).is_ok());
            let i = at.index(bytes.len());
            bytes[i] = byte;
            if let Ok(changed) = String::from_utf8(bytes) {
                let ours = Tape::build(&changed);
                let theirs = serde_json::from_str::<Value>(&changed);
                prop_assert_eq!(ours.is_ok(), theirs.is_ok(), "{:?}", changed);
                if let (Ok(tape), Ok(value)) = (ours, theirs) {
                    prop_assert_eq!(super::tests::rebuild(tape.root(&changed)), value);
                }
            }
        }
    }
}
