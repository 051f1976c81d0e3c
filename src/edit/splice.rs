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
//! [`splice_edits`] takes a plan's edits instead of a whole edited document: only the parts
//! they touch are read, each part's new text is checked alone (where the edits only add
//! members, by reading the inserted text; otherwise by reading the part's new text back), and
//! the result is a [`Spliced`] text, written to its file piece by piece rather than joined.
//! A value an edit holds as compact text ([`write_compact`], as a conversion writes its layer
//! object) is laid out from that text in one pass, and the inserted text is checked against it
//! token by token.
//!
//! The spans come from the document's index ([`crate::asset::tape`]), built when it was loaded:
//! the source is not read a second time. No maintained crate offers format-preserving edits of
//! JSON text (toml_edit's equivalent for JSON does not exist). The check a spliced text passes
//! before it is written reads that new text with a small streaming scanner, written here for the
//! same reason.

use super::{Edit, EditError, SetValue};
use crate::asset::json_text::push_quoted;
use crate::asset::tape::{Kind, Node};
use rayon::prelude::*;
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
    Spliced::new(text, splices).map(|spliced| spliced.to_text())
}

/// A part of the document an edit plan changes: a top-level member, or one element of a
/// top-level array (a material, an image).
#[derive(Debug, Clone)]
struct Unit {
    /// The member's name, shared by every edit of it (a plan may name the same member by the
    /// ten thousand).
    member: std::sync::Arc<str>,
    element: Option<usize>,
}

/// A top-level member some edit of a plan names, while [`splice_edits`] groups the edits.
struct EditedMember {
    name: std::sync::Arc<str>,
    /// Its length, when it is an array.
    len: Option<usize>,
    /// Whether some edit adds, removes or replaces its elements (it is then one unit).
    whole: bool,
    /// Its unit as a whole, and each element's unit, once they have one (indices into the
    /// units).
    whole_unit: Option<usize>,
    element_units: Vec<Option<usize>>,
}

/// The text of `text` (indexed by `root`) with `edits` applied, written as splices, and whether
/// they changed anything. Only the parts the edits touch are read into values: each material
/// an edit names, each top-level member that gains or loses elements. `Ok(None)` for a plan
/// this does not take (an edit of the root itself, a document that is not an object with
/// members); the caller then applies it to the whole document.
pub fn splice_edits<'t, 'e>(
    text: &'t str,
    root: Node,
    edits: impl IntoIterator<Item = &'e Edit>,
) -> Result<Option<(Spliced<'t>, bool)>, EditError> {
    let Some(object) = root
        .as_object()
        .filter(|o| !o.is_empty() && !o.has_duplicate_keys())
    else {
        return Ok(None);
    };
    // Each edit's unit: the element its pointer enters, unless some edit of that member adds,
    // removes or replaces elements (then the whole member). A plan names the same member by
    // the ten thousand: each member is looked up once, and its units are found by element.
    let mut members: Vec<EditedMember> = Vec::new();
    let mut placed: Vec<(&Edit, usize, Option<usize>)> = Vec::new();
    for edit in edits {
        let pointer = match edit {
            Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer } => pointer.as_str(),
            Edit::DeclareUsed { .. } => "/extensionsUsed",
        };
        if pointer.is_empty() {
            return Ok(None);
        }
        // The first two reference tokens, and whether more follow.
        let mut tokens = pointer.get(1..).unwrap_or_default().splitn(3, '/');
        let member = crate::asset::pointer::unescape(tokens.next().unwrap_or_default());
        let second = tokens.next();
        let deeper = tokens.next().is_some();
        let within_element =
            deeper || (second.is_some() && matches!(edit, Edit::Set { .. } | Edit::Replace { .. }));
        let m = match members.iter().position(|m| *m.name == *member) {
            Some(m) => m,
            None => {
                members.push(EditedMember {
                    len: object
                        .get(&member)
                        .and_then(|m| m.as_array())
                        .map(|a| a.len()),
                    name: member.into(),
                    whole: false,
                    whole_unit: None,
                    element_units: Vec::new(),
                });
                members.len() - 1
            }
        };
        let element = second
            .filter(|_| within_element)
            // An escape (`~0`, `~1`) never reads as a digit: the token is read as it stands.
            .and_then(crate::asset::pointer::array_index)
            .filter(|i| members[m].len.is_some_and(|len| *i < len));
        if element.is_none() {
            members[m].whole = true;
        }
        placed.push((edit, m, element));
    }
    // Each edit's unit, in the order units are first named; then the edits are laid out unit
    // by unit in one list (in their order within each), so that a unit's edits are a slice of
    // it: a plan names a unit per material, and a list each cost an allocation apiece.
    let mut units: Vec<(Unit, std::ops::Range<usize>)> = Vec::new();
    let mut unit_of: Vec<usize> = Vec::with_capacity(placed.len());
    for &(_, m, element) in &placed {
        let member = &mut members[m];
        let element = element.filter(|_| !member.whole);
        let slot = match element {
            None => &mut member.whole_unit,
            Some(i) => {
                if member.element_units.is_empty() {
                    member.element_units = vec![None; member.len.unwrap_or(0)];
                }
                &mut member.element_units[i]
            }
        };
        let at = *slot.get_or_insert_with(|| {
            units.push((
                Unit {
                    member: member.name.clone(),
                    element,
                },
                0..0,
            ));
            units.len() - 1
        });
        units[at].1.end += 1;
        unit_of.push(at);
    }
    let mut next = 0;
    for (_, range) in &mut units {
        let count = range.end;
        *range = next..next;
        next += count;
    }
    let mut by_unit: Vec<Option<&Edit>> = vec![None; placed.len()];
    for ((edit, _, _), at) in placed.iter().zip(unit_of) {
        let range = &mut units[at].1;
        by_unit[range.end] = Some(*edit);
        range.end += 1;
    }
    let by_unit: Vec<&Edit> = by_unit.into_iter().flatten().collect();
    let layout = Layout::detect(text, root);
    let entries = object.entries();
    let members: Vec<(usize, Node)> = entries.iter().map(|(k, v)| (k.span().start, *v)).collect();
    let mut splices = Vec::new();
    let mut changed = false;
    // What each unit not read back alone must read back as from the whole text: (its
    // pointer, its value's digest; `None` when removed).
    let mut meant: Vec<(String, Option<u64>)> = Vec::new();
    let done: Vec<Result<Option<UnitSplices>, EditError>> = units
        .par_iter()
        .map(|(unit, edits)| {
            let edits = &by_unit[edits.clone()];
            splice_unit(text, root, object, &entries, &members, &layout, unit, edits)
        })
        .collect();
    let mut all_checked = true;
    for unit in done {
        let Some(unit) = unit? else {
            return Ok(None);
        };
        match unit.check {
            UnitCheck::Alone(false) => return Ok(None),
            UnitCheck::Alone(true) => {}
            // Only what was not read back alone is read back from the whole text.
            UnitCheck::Whole(pointer, digest) => {
                all_checked = false;
                meant.push((pointer, digest));
            }
        }
        splices.extend(unit.splices);
        changed |= unit.changed;
    }
    let Some(spliced) = Spliced::new(text, splices) else {
        return Ok(None);
    };
    if all_checked {
        // Every unit's value was read back alone, and every byte outside them was copied: the
        // whole text need not be indexed again, nor held as one string.
        return Ok(Some((spliced, changed)));
    }
    let out = spliced.to_text();
    // The check a spliced text passes before it is written: it is JSON, every part the plan
    // touched reads back as meant (numbers as velvet writes them), and the root has the
    // members it should; every other byte was copied.
    let Ok(index) = crate::asset::tape::Tape::build(&out) else {
        return Ok(None);
    };
    let new_root = index.root(&out);
    let reads_back =
        meant.par_iter().all(
            |(pointer, digest)| match (new_root.pointer(pointer), digest) {
                (Some(node), Some(digest)) => node_digest(node) == *digest,
                (None, None) => true,
                _ => false,
            },
        );
    let members_before = object.len();
    let members_after = new_root.as_object().map_or(0, |o| o.len());
    let added = meant
        .iter()
        .filter(|(p, v)| v.is_some() && root.pointer(p).is_none())
        .count();
    let removed = meant.iter().filter(|(_, v)| v.is_none()).count();
    if !reads_back || members_after + removed != members_before + added {
        return Ok(None);
    }
    Ok(Some((spliced, changed)))
}

/// A text written as splices into a source text, kept as the source and the splices (sorted,
/// none overlapping) rather than joined: an output of the size of its input is written to its
/// file piece by piece ([`Spliced::pieces`]) and never held as a second copy of the text.
#[derive(Debug)]
pub struct Spliced<'t> {
    source: &'t str,
    splices: Vec<Splice>,
}

impl<'t> Spliced<'t> {
    /// `None` if two splices overlap (never produced, but never risked).
    fn new(source: &'t str, mut splices: Vec<Splice>) -> Option<Spliced<'t>> {
        in_order(&mut splices, 0..source.len()).then_some(Spliced { source, splices })
    }

    /// The text in order: spans of the source and the splices' texts between them.
    fn runs(&self) -> impl Iterator<Item = &str> + '_ {
        runs(self.source, 0..self.source.len(), &self.splices)
    }

    /// The text's bytes in order, a run at a time.
    pub fn pieces(&self) -> impl Iterator<Item = &[u8]> + '_ {
        self.runs().map(str::as_bytes)
    }

    /// The text's length in bytes.
    pub fn len(&self) -> usize {
        let removed: usize = self.splices.iter().map(|s| s.end - s.start).sum();
        let added: usize = self.splices.iter().map(|s| s.text.len()).sum();
        self.source.len() - removed + added
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The text, joined.
    pub fn to_text(&self) -> String {
        let mut out = String::with_capacity(self.len());
        self.runs().for_each(|run| out.push_str(run));
        out
    }
}

/// What one unit contributes: its splices, whether its edits changed it, and how it was
/// checked.
struct UnitSplices {
    splices: Vec<Splice>,
    changed: bool,
    check: UnitCheck,
}

/// How a unit's new text is known to read back as meant.
enum UnitCheck {
    /// Checked alone, when all its splices lie inside one value of the loaded text: whether
    /// that value reads back as meant ([`reads_back_within`], or for members inserted into
    /// objects, [`inserted_members_read_as`]).
    Alone(bool),
    /// Only the whole written text can tell (a top-level member added or removed): the unit's
    /// pointer and the [`value_digest`] of its value (`None` when removed). A digest, not the
    /// value, is kept so that a plan touching every material does not hold them all.
    Whole(String, Option<u64>),
}

/// A digest of what a value reads as when velvet writes it: key order, decoded strings, and
/// numbers as [`number_text`] writes them. [`value_digest`] (what a unit is meant to hold) and
/// [`node_digest`] (what the written text holds) feed the same stream, so a unit is checked
/// without rebuilding either side as a value.
///
/// The hash is foldhash's fast one, with a fixed seed: the digest guards against velvet's own
/// mistakes, not against crafted input, and std's SipHash took a tenth of the check's time.
struct Digest(foldhash::fast::FoldHasher<'static>);

impl Digest {
    fn new() -> Digest {
        use std::hash::BuildHasher;
        Digest(foldhash::fast::FixedState::with_seed(0).build_hasher())
    }

    fn tag(&mut self, tag: u8) {
        std::hash::Hasher::write_u8(&mut self.0, tag);
    }

    /// A tagged, length-prefixed run of bytes, so that no two streams run together.
    fn text(&mut self, tag: u8, text: &str) {
        use std::hash::Hasher;
        self.0.write_u8(tag);
        self.0.write_usize(text.len());
        self.0.write(text.as_bytes());
    }

    fn finish(&self) -> u64 {
        std::hash::Hasher::finish(&self.0)
    }
}

/// The [`Digest`] of `value` as velvet writes it.
fn value_digest(value: &Value) -> u64 {
    let mut d = Digest::new();
    feed_value(&mut d, value);
    d.finish()
}

fn feed_value(d: &mut Digest, value: &Value) {
    match value {
        Value::Null => d.tag(b'n'),
        Value::Bool(b) => d.tag(if *b { b't' } else { b'f' }),
        Value::Number(n) => with_written_number(n.as_str(), |text| d.text(b'#', text)),
        Value::String(s) => d.text(b'"', s),
        Value::Array(items) => {
            d.tag(b'[');
            items.iter().for_each(|v| feed_value(d, v));
            d.tag(b']');
        }
        Value::Object(map) => {
            d.tag(b'{');
            for (k, v) in map {
                d.text(b':', k);
                feed_value(d, v);
            }
            d.tag(b'}');
        }
    }
}

/// The [`Digest`] of the value `node` indexes, read as a `Value` would read it (a key written
/// twice: at its first place, with its last value).
fn node_digest(node: Node) -> u64 {
    let mut d = Digest::new();
    feed_node(&mut d, node);
    d.finish()
}

fn feed_node(d: &mut Digest, node: Node) {
    match node.kind() {
        Kind::Null => d.tag(b'n'),
        Kind::Bool => d.tag(if node.as_bool() == Some(true) {
            b't'
        } else {
            b'f'
        }),
        // Spelled as serde_json reads it (`1E-1` as `1e-1`), as the meant value holds it. A
        // number without an exponent it reads as written (its digits are kept, and an integer
        // it reads as one prints as written), so only an exponent takes the parse.
        Kind::Number => match node.raw() {
            raw if !raw.contains(['e', 'E']) => with_written_number(raw, |text| d.text(b'#', text)),
            raw => match raw.parse::<serde_json::Number>() {
                Ok(n) => with_written_number(n.as_str(), |text| d.text(b'#', text)),
                Err(_) => d.text(b'#', raw),
            },
        },
        Kind::String => d.text(b'"', &node.as_str().unwrap_or_default()),
        Kind::Array => {
            d.tag(b'[');
            node.as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .for_each(|v| feed_node(d, v));
            d.tag(b']');
        }
        Kind::Object => {
            d.tag(b'{');
            for (k, v) in node.as_object().into_iter().flat_map(|o| o.iter()) {
                d.text(b':', &k);
                feed_node(d, v);
            }
            d.tag(b'}');
        }
    }
}

/// One edit of [`members_set_in_place`]: where it sets, as tokens below the element, and the
/// value the text will hold (a [`Edit::Set`]'s as velvet writes it, a [`Edit::Replace`]'s as
/// given).
struct MemberSet<'e> {
    tokens: Vec<std::borrow::Cow<'e, str>>,
    value: SetTo<'e>,
}

/// What a member is set to: a value, or compact text as [`write_compact`] writes it.
enum SetTo<'e> {
    Value(std::borrow::Cow<'e, Value>),
    Text(&'e str),
}

impl SetTo<'_> {
    fn meant(&self) -> Meant<'_> {
        match self {
            SetTo::Value(value) => Meant::Value(value),
            SetTo::Text(text) => Meant::Text(text),
        }
    }

    /// The value (a text read: only where it replaces a member, which a conversion's text
    /// does not).
    fn value(&self) -> std::borrow::Cow<'_, Value> {
        match self {
            SetTo::Value(value) => std::borrow::Cow::Borrowed(value.as_ref()),
            SetTo::Text(text) => std::borrow::Cow::Owned(super::value_of_text(text)),
        }
    }
}

/// A value a new member is meant to hold, as given to the writer and to the check of what it
/// wrote.
#[derive(Clone, Copy)]
enum Meant<'v> {
    Value(&'v Value),
    /// Compact text as [`write_compact`] writes it.
    Text(&'v str),
}

/// The splices of an element unit whose edits each set or replace a member of an object the
/// element already holds (the fuzz object a migration adds to a material's `extensions`, a factor it
/// replaces), made from the index alone: the element is not read into a value, edited and
/// compared with its text, which for a migration of every material was most of the writer's
/// work. Returns the splices, whether they change anything, and how the element reads back
/// as meant: when every edit adds a member, whether each inserted text reads as its members
/// ([`inserted_members_read_as`]); otherwise the digest the element must read back as, fed
/// from the index with the set values in their places, as the edited value would feed it. `None` for edits of another kind (a removal, an array element, a path through
/// a missing key or an object that writes a key twice, two edits of one place); the caller then
/// takes the general way.
fn members_set_in_place(
    text: &str,
    element: Node,
    prefix: &str,
    edits: &[&Edit],
    layout: &Layout,
) -> Option<(Vec<Splice>, bool, ElementCheck)> {
    use std::borrow::Cow;
    let mut sets: Vec<MemberSet> = Vec::with_capacity(edits.len());
    for edit in edits {
        let (pointer, value) = match edit {
            // Borrowed unless a number is rounded: a plan's values are not copied.
            Edit::Set {
                pointer,
                value: SetValue::Text(text),
            } => (pointer, SetTo::Text(text)),
            Edit::Set {
                pointer,
                value: SetValue::Value(value),
            } if is_written(value) => (pointer, SetTo::Value(Cow::Borrowed(value))),
            Edit::Set {
                pointer,
                value: SetValue::Value(value),
            } => (pointer, SetTo::Value(Cow::Owned(written(value.clone())))),
            Edit::Replace { pointer, value } => (pointer, SetTo::Value(Cow::Borrowed(value))),
            _ => return None,
        };
        let within = pointer
            .strip_prefix(prefix)
            .filter(|w| w.starts_with('/'))?;
        sets.push(MemberSet {
            // Borrowed from the pointer unless a token holds an escape.
            tokens: within[1..]
                .split('/')
                .map(crate::asset::pointer::unescape)
                .collect(),
            value,
        });
    }
    // No edit's place lies at or inside another's: each is made on the text as loaded.
    for (i, a) in sets.iter().enumerate() {
        for b in &sets[i + 1..] {
            let n = a.tokens.len().min(b.tokens.len());
            if a.tokens[..n] == b.tokens[..n] {
                return None;
            }
        }
    }
    // Most elements take one splice (their new members, inserted at one place); the list is
    // kept to the end of the write, by the twenty thousand.
    let mut splices = Vec::with_capacity(1);
    let mut changed = false;
    // Whether some edit sets a member the element holds already.
    let mut replaced = false;
    // New members by the object that receives them, in the order the edits add them.
    let mut inserts: Vec<(Node, Vec<(&str, Meant)>)> = Vec::new();
    for set in &sets {
        let (key, path) = set.tokens.split_last()?;
        let mut parent = element;
        for token in path {
            parent = member_or_element(parent, token)?;
        }
        let object = parent
            .as_object()
            .filter(|o| !o.is_empty() && !o.has_duplicate_keys())?;
        match object.get(key) {
            Some(old) => {
                replaced = true;
                let value = set.value.value();
                changed |= !matches(old, &value, Compare::Exact);
                diff(text, old, &value, layout, &mut splices);
            }
            None => {
                changed = true;
                let at = parent.span().start;
                match inserts.iter_mut().find(|(p, _)| p.span().start == at) {
                    Some((_, new)) => new.push((key, set.value.meant())),
                    None => inserts.push((parent, vec![(key.as_ref(), set.value.meant())])),
                }
            }
        }
    }
    for (parent, new) in &inserts {
        let members: Vec<(usize, Node)> = parent
            .as_object()?
            .entries()
            .iter()
            .map(|(k, v)| (k.span().start, *v))
            .collect();
        // A new key goes last, as the edit applier puts it: after the last member.
        let last = Some(members.len() - 1);
        let placed: Vec<(Option<usize>, &str, Meant)> = new
            .iter()
            .map(|(key, value)| (last, *key, *value))
            .collect();
        insert_members(text, *parent, &members, &placed, layout, &mut splices);
    }
    if !replaced {
        // Only new members, each put after the last member of an object that holds no such
        // key (checked above, with no key written twice): every other byte of the element is
        // its own, so it reads back as meant exactly when each inserted text reads as the
        // members it adds. One insertion per object, in the order of `inserts`.
        let reads_back = splices.len() == inserts.len()
            && splices
                .iter()
                .zip(&inserts)
                .all(|(splice, (_, new))| inserted_members_read_as(&splice.text, new));
        return Some((splices, changed, ElementCheck::Inserted(reads_back)));
    }
    let mut d = Digest::new();
    let values: Vec<std::borrow::Cow<Value>> = sets.iter().map(|s| s.value.value()).collect();
    let sets: Vec<(&[std::borrow::Cow<str>], &Value)> = sets
        .iter()
        .zip(&values)
        .map(|(s, value)| (s.tokens.as_slice(), value.as_ref()))
        .collect();
    feed_edited(&mut d, element, &sets);
    Some((splices, changed, ElementCheck::Digest(d.finish())))
}

/// How [`members_set_in_place`] knows its element reads back as meant.
enum ElementCheck {
    /// Members were only added: whether each inserted text reads as its members.
    Inserted(bool),
    /// The digest the element's new text must read back as.
    Digest(u64),
}

/// Whether `inserted`, the text put after an object's last member, reads as `members` added
/// after it: for each, a comma, its key, a colon and its value as velvet writes it; then
/// nothing but whitespace. The scan validates what it reads (a key's characters and escapes,
/// each scalar parsed), so the object stays JSON with exactly these members added.
fn inserted_members_read_as(inserted: &str, members: &[(&str, Meant)]) -> bool {
    let mut scanner = Scanner {
        text: inserted,
        at: 0,
    };
    for (key, value) in members {
        if scanner.eat(b',').is_none() {
            return false;
        }
        let Some(at) = scanner.key() else {
            return false;
        };
        if key_at(inserted, at).as_deref() != Some(*key) {
            return false;
        }
        let holds = match value {
            Meant::Value(value) => scanner.holds(value),
            Meant::Text(text) => {
                scanner.skip_ws();
                reads_as_compact(&inserted[scanner.at..], text).map(|len| {
                    scanner.at += len;
                    true
                })
            }
        };
        if holds != Some(true) {
            return false;
        }
    }
    scanner.skip_ws();
    scanner.at == inserted.len()
}

/// The member `token` of an object that writes each key once, or element `token` (written
/// without leading zeros) of an array.
fn member_or_element<'a>(node: Node<'a>, token: &str) -> Option<Node<'a>> {
    match node.kind() {
        Kind::Object => node
            .as_object()
            .filter(|o| !o.has_duplicate_keys())?
            .get(token),
        Kind::Array => node
            .as_array()?
            .get(crate::asset::pointer::array_index(token)?),
        _ => None,
    }
}

/// Feeds `node` as [`feed_node`] does, with each of `sets` (tokens below `node`, value) in its
/// place: a set member where the member stands, a new one after the object's members, in
/// order. Every set's path exists in `node` up to its last token (see [`members_set_in_place`]).
fn feed_edited<T: AsRef<str>>(d: &mut Digest, node: Node, sets: &[(&[T], &Value)]) {
    if sets.is_empty() {
        return feed_node(d, node);
    }
    let below = |token: &str| -> Vec<(&[T], &Value)> {
        sets.iter()
            .filter(|(t, _)| t.len() > 1 && t[0].as_ref() == token)
            .map(|(t, v)| (&t[1..], *v))
            .collect()
    };
    match node.kind() {
        Kind::Object => {
            let Some(object) = node.as_object() else {
                return feed_node(d, node);
            };
            d.tag(b'{');
            for (key, member) in object.iter() {
                d.text(b':', &key);
                match sets
                    .iter()
                    .find(|(t, _)| t.len() == 1 && t[0].as_ref() == key)
                {
                    Some((_, new)) => feed_value(d, new),
                    None => feed_edited(d, member, &below(&key)),
                }
            }
            for (tokens, new) in sets {
                if tokens.len() == 1 && !object.contains_key(tokens[0].as_ref()) {
                    d.text(b':', tokens[0].as_ref());
                    feed_value(d, new);
                }
            }
            d.tag(b'}');
        }
        Kind::Array => {
            d.tag(b'[');
            for (i, item) in node
                .as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .enumerate()
            {
                feed_edited(d, item, &below(&i.to_string()));
            }
            d.tag(b']');
        }
        _ => feed_node(d, node),
    }
}

/// Sorts `splices` and tells whether they lie inside `within`, none overlapping another.
fn in_order(splices: &mut [Splice], within: std::ops::Range<usize>) -> bool {
    splices.sort_by_key(|s| (s.start, s.end));
    let mut at = within.start;
    for s in splices.iter() {
        if s.start < at || s.end > within.end {
            return false;
        }
        at = s.end;
    }
    true
}

/// `text[within]` with `splices` (in order, inside `within`) made, a run at a time: spans of
/// the text and the splices' texts between them.
fn runs<'a>(
    text: &'a str,
    within: std::ops::Range<usize>,
    splices: &'a [Splice],
) -> impl Iterator<Item = &'a str> + 'a {
    let mut at = within.start;
    splices
        .iter()
        .flat_map(move |s| {
            let kept = &text[at..s.start];
            at = s.end;
            [kept, s.text.as_str()]
        })
        .chain(std::iter::once_with(move || {
            let last = splices.last().map_or(within.start, |s| s.end);
            &text[last..within.end]
        }))
}

/// Whether the value spanning `within` in `text` reads back as `digest` once `splices` (all
/// inside that span; sorted here) are made: the read-back check of one unit. The rest of the
/// text is copied as it was, so a text whose every changed span reads back holds the whole
/// document meant.
fn reads_back_within(
    text: &str,
    within: std::ops::Range<usize>,
    splices: &mut [Splice],
    digest: u64,
) -> bool {
    if !in_order(splices, within.clone()) {
        return false;
    }
    let added: usize = splices.iter().map(|s| s.text.len()).sum();
    let mut out = String::with_capacity(within.len() + added);
    runs(text, within, splices).for_each(|run| out.push_str(run));
    match crate::asset::tape::Tape::build(&out) {
        Ok(index) => node_digest(index.root(&out)) == digest,
        Err(_) => false,
    }
}

/// The splices of one unit of [`splice_edits`]; `Ok(None)` for one it does not take.
#[allow(clippy::too_many_arguments)]
fn splice_unit(
    text: &str,
    root: Node,
    object: crate::asset::tape::Object,
    entries: &[(Node, Node)],
    members: &[(usize, Node)],
    layout: &Layout,
    unit: &Unit,
    edits: &[&Edit],
) -> Result<Option<UnitSplices>, EditError> {
    let mut splices = Vec::new();
    let mut changed = false;
    let check: UnitCheck;
    let node = object.get(&unit.member);
    match (unit.element, node) {
        (Some(i), Some(node)) => {
            let Some(element) = node.get(i) else {
                return Ok(None);
            };
            let prefix = {
                use std::fmt::Write;
                let mut prefix = String::with_capacity(unit.member.len() + 8);
                prefix.push('/');
                crate::asset::pointer::push_escaped(&mut prefix, &unit.member);
                let _ = write!(prefix, "/{i}"); // writing to a String cannot fail
                prefix
            };
            if let Some((mut splices, changed, check)) =
                members_set_in_place(text, element, &prefix, edits, layout)
            {
                let reads_back = match check {
                    ElementCheck::Inserted(reads_back) => {
                        reads_back && in_order(&mut splices, element.span())
                    }
                    ElementCheck::Digest(digest) => {
                        reads_back_within(text, element.span(), &mut splices, digest)
                    }
                };
                return Ok(Some(UnitSplices {
                    splices,
                    changed,
                    check: UnitCheck::Alone(reads_back),
                }));
            }
            let mut value = element.to_value();
            for edit in edits {
                let (Edit::Set { pointer, .. }
                | Edit::Replace { pointer, .. }
                | Edit::Remove { pointer }) = edit
                else {
                    return Ok(None); // a declaration is never within an element
                };
                let Some(within) = pointer
                    .strip_prefix(&prefix)
                    .filter(|w| w.is_empty() || w.starts_with('/'))
                else {
                    return Ok(None);
                };
                match edit {
                    Edit::Set { value: new, .. } if within.is_empty() => {
                        let new = written(new.to_value().into_owned());
                        changed |= value != new;
                        value = new;
                    }
                    Edit::Replace { value: new, .. } if within.is_empty() => {
                        changed |= value != *new;
                        value = new.clone();
                    }
                    _ => {
                        changed |= super::apply(&mut value, &[edit.at(within)])
                            .map_err(|e| from_root(e, &prefix))?;
                    }
                }
            }
            diff(text, element, &value, layout, &mut splices);
            let digest = value_digest(&value);
            check = UnitCheck::Alone(reads_back_within(
                text,
                element.span(),
                &mut splices,
                digest,
            ));
        }
        (_, node) => {
            let mut part = Map::new();
            if let Some(node) = node {
                part.insert(unit.member.to_string(), node.to_value());
            }
            let mut part = Value::Object(part);
            let owned: Vec<Edit> = edits.iter().map(|e| (*e).clone()).collect();
            changed |= super::apply(&mut part, &owned)?;
            let new = part.get(&*unit.member);
            let pointer = || format!("/{}", crate::asset::pointer::escape(&unit.member));
            check = match (node, new) {
                (Some(node), Some(new)) => {
                    diff(text, node, new, layout, &mut splices);
                    let digest = value_digest(new);
                    UnitCheck::Alone(reads_back_within(text, node.span(), &mut splices, digest))
                }
                (Some(_), None) => {
                    let Some(i) = entries
                        .iter()
                        .position(|(k, _)| k.as_str().is_some_and(|k| *k == *unit.member))
                    else {
                        return Ok(None);
                    };
                    match removal(members, i) {
                        Some(splice) => splices.push(splice),
                        None => return Ok(None),
                    }
                    UnitCheck::Whole(pointer(), None)
                }
                (None, Some(new)) => {
                    // Where the edit applier puts it: `extensionsUsed` after `asset` (or
                    // first), anything else last.
                    let anchor = if &*unit.member == "extensionsUsed" {
                        entries
                            .iter()
                            .position(|(k, _)| k.as_str().is_some_and(|k| k == "asset"))
                    } else {
                        Some(members.len() - 1)
                    };
                    insert_members(
                        text,
                        root,
                        members,
                        &[(anchor, &unit.member[..], Meant::Value(new))],
                        layout,
                        &mut splices,
                    );
                    UnitCheck::Whole(pointer(), Some(value_digest(new)))
                }
                (None, None) => UnitCheck::Whole(pointer(), None),
            };
        }
    }
    Ok(Some(UnitSplices {
        splices,
        changed,
        check,
    }))
}

/// An error from an edit applied within the element at `prefix`, its pointer given from the
/// document's root as the whole-document applier gives it.
fn from_root(mut error: EditError, prefix: &str) -> EditError {
    if let EditError::Root { pointer }
    | EditError::NotAContainer { pointer, .. }
    | EditError::BadIndex { pointer, .. } = &mut error
    {
        pointer.insert_str(0, prefix);
    }
    error
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

    /// Steps over the string at the cursor ([`string_end`]).
    fn string(&mut self) -> Option<()> {
        self.at = string_end(self.text.as_bytes(), self.at)?;
        Some(())
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
                // Members are compared in the map's order while the text follows it, as the
                // text velvet writes does: distinct keys, none looked up. From the first key
                // out of that order, each key is looked up and the keys read are tracked, so
                // that none is read twice.
                let mut in_order = map.iter();
                let mut seen: Option<std::collections::HashSet<std::borrow::Cow<str>>> = None;
                let mut count = 0;
                loop {
                    let key = key_at(self.text, self.key()?)?;
                    let next_in_order = in_order
                        .next()
                        .filter(|(k, _)| seen.is_none() && **k == *key);
                    let member = match next_in_order {
                        Some((_, member)) => member,
                        None => {
                            let seen = seen.get_or_insert_with(|| {
                                map.keys().take(count).map(|k| k.as_str().into()).collect()
                            });
                            let Some(member) = map.get(key.as_ref()) else {
                                return Some(false);
                            };
                            if !seen.insert(key) {
                                return Some(false);
                            }
                            member
                        }
                    };
                    if !self.holds(member)? {
                        return Some(false);
                    }
                    count += 1;
                    if !self.next(b'}')? {
                        return Some(count == map.len());
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
            self.at = scalar_end(self.text.as_bytes(), start);
        }
        (self.at > start).then_some((start, self.at))
    }
}

/// How the file is laid out, read once; what only some edits need (the comma of a one-line
/// container, whether number arrays are inline) is read on first use: a pretty-printed file
/// without one-line containers proves it only by a walk of the whole document, 9 ms of a
/// 10 MB library's migration that most migrations never use.
#[derive(Clone)]
struct Layout<'t> {
    /// The indent unit; `None` for a minified file (no line breaks).
    unit: Option<String>,
    newline: &'static str,
    /// Between a key and its value (`": "` or `":"`, from the first member in the file).
    colon: String,
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
    fn detect(text: &str, root: Node<'t>) -> Layout<'t> {
        let newline = if text.contains("\r\n") { "\r\n" } else { "\n" };
        let pretty = text.trim_end().contains('\n');
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
    fn inline_comma(&self) -> &str {
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
    fn compact() -> &'static Layout<'static> {
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
    fn local(
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
    fn write_text(&self, compact: &str, indent: &str, inline: bool, out: &mut String) {
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

/// Writes `value` as compact JSON text (no whitespace), its numbers as velvet writes them
/// and its strings quoted as velvet quotes them: the text of an [`super::SetValue::Text`].
pub fn write_compact(value: &Value, out: &mut String) {
    Layout::compact().write(value, "", true, out);
}

/// [`write_compact`] of the value `node` holds, read from the index: what
/// `write_compact(&node.to_value())` writes, with no value made (a textureInfo a conversion
/// carries into its layer object, by the ten thousand). A key written twice is written once, at
/// its first place with its last value, as the value holds it.
pub fn write_compact_node(node: Node, out: &mut String) {
    match node.kind() {
        Kind::Object => match node.as_object().filter(|o| !o.is_empty()) {
            Some(object) => {
                out.push('{');
                for (i, (key, member)) in object.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    push_quoted(out, &key);
                    out.push(':');
                    write_compact_node(member, out);
                }
                out.push('}');
            }
            None => out.push_str("{}"),
        },
        Kind::Array => match node.as_array().filter(|a| !a.is_empty()) {
            Some(items) => {
                out.push('[');
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    write_compact_node(item, out);
                }
                out.push(']');
            }
            None => out.push_str("[]"),
        },
        Kind::String => push_quoted(out, &node.as_str().unwrap_or_default()),
        // serde_json reads an exponent as `e` with its sign (`1E5` holds `1e+5`): such a number
        // is written as the value holds it.
        Kind::Number if node.raw().bytes().any(|b| b == b'e' || b == b'E') => {
            write_compact(&node.to_value(), out)
        }
        Kind::Number => with_written_number(node.raw(), |text| out.push_str(text)),
        Kind::Bool | Kind::Null => out.push_str(node.raw()),
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
enum Rounding {
    /// Nothing: it is at that precision already.
    Same,
    /// Rounds it to nothing.
    Zero,
    /// Rounds it to this value.
    To(f64),
}

fn rounding(x: f64) -> Rounding {
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
fn with_written_number<R>(text: &str, f: impl FnOnce(&str) -> R) -> R {
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
fn write_rounded(x: f64, out: &mut StackText) {
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
struct StackText {
    bytes: [u8; 40],
    len: usize,
    overflow: Option<String>,
}

impl StackText {
    fn new() -> StackText {
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

    fn as_str(&self) -> &str {
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

/// Writes the text of [`written_f64`]`(x)` as [`write_compact`] writes it, with no value
/// made: the numbers a conversion computes (a sheen's fuzz colour, three by the twenty
/// thousand in a library) go straight into its layer object's text.
pub fn push_written_f64(x: f64, out: &mut String) {
    if !x.is_finite() || x.abs() >= 1e9 {
        return write_compact(&written_f64(x), out); // not finite, or large: the general way
    }
    match rounding(x) {
        // What `Value::from` holds: serde_json's own writing of an f64.
        Rounding::Same => push_serde_f64(x, out),
        Rounding::Zero => out.push('0'),
        Rounding::To(rounded) => {
            let mut text = StackText::new();
            write_rounded(rounded, &mut text);
            out.push_str(text.as_str());
        }
    }
}

/// serde_json's writing of a finite `x` (the text `Value::from(x)` holds), made on the stack
/// by its own formatter.
fn push_serde_f64(x: f64, out: &mut String) {
    use serde_json::ser::Formatter;
    const ROOM: usize = 40;
    let mut buffer = [0u8; ROOM];
    let mut rest: &mut [u8] = &mut buffer;
    let formatted = serde_json::ser::CompactFormatter
        .write_f64(&mut rest, x)
        .is_ok();
    let len = ROOM - rest.len();
    match std::str::from_utf8(&buffer[..len]) {
        Ok(text) if formatted => out.push_str(text),
        _ => out.push_str(&Value::from(x).to_string()),
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
    fn line_indent<'t>(&self, text: &'t str, at: usize) -> &'t str {
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
fn concat(parts: &[&str]) -> String {
    let mut out = String::with_capacity(parts.iter().map(|p| p.len()).sum());
    parts.iter().for_each(|p| out.push_str(p));
    out
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
    // The scalars velvet writes and checks by the ten thousand, compared as text: a number
    // without an exponent (serde_json reads it with its text as written), a string without
    // escapes, a literal. Anything else is read by serde_json.
    match value {
        Value::Number(b) if is_plain_number(raw) => {
            return raw == b.as_str()
                || (compare == Compare::Written && with_written_number(b.as_str(), |t| t == raw));
        }
        Value::String(b) if raw.len() >= 2 && !raw.contains('\\') => {
            let bytes = raw.as_bytes();
            return bytes[0] == b'"'
                && bytes[raw.len() - 1] == b'"'
                && !bytes[1..raw.len() - 1]
                    .iter()
                    .any(|&c| c < 0x20 || c == b'"')
                && raw[1..raw.len() - 1] == **b;
        }
        Value::Bool(b) if matches!(raw, "true" | "false") => return (raw == "true") == *b,
        Value::Null if raw == "null" => return true,
        _ => {}
    }
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

/// Whether `written`, from its start, is the value `compact` holds (as [`write_compact`]
/// writes it) laid out: the same tokens in the same order, each number as
/// [`with_written_number`] writes the compact one, with whitespace only between tokens (next
/// to a bracket, brace, comma or colon, never inside a string or splitting a number); the
/// length of `written` it spans. One pass over both texts, as [`Layout::write_text`] writes
/// them. Every token is checked as JSON: strings without raw control characters and with
/// valid escapes, numbers JSON allows, the three literals. The compact text's own structure
/// is what [`write_compact`] made of a value.
fn reads_as_compact(written: &str, compact: &str) -> Option<usize> {
    let (w, c) = (written.as_bytes(), compact.as_bytes());
    let structural = |b: Option<&u8>| matches!(b, Some(b'{' | b'}' | b'[' | b']' | b',' | b':'));
    let (mut i, mut j) = (0, 0);
    while j < c.len() {
        let byte = *w.get(i)?;
        if matches!(byte, b' ' | b'\t' | b'\n' | b'\r') {
            // Between tokens only: a structural byte before or after. The run of whitespace
            // (a line break and its indentation) stands in one place, so it is passed whole.
            if !(structural(c.get(j)) || structural(j.checked_sub(1).and_then(|k| c.get(k)))) {
                return None;
            }
            i += 1 + w[i + 1..]
                .iter()
                .take_while(|b| matches!(b, b' ' | b'\t' | b'\n' | b'\r'))
                .count();
            continue;
        }
        match c[j] {
            b'"' => {
                let end = string_end(c, j)?;
                let token = &compact[j..end];
                if written.get(i..i + token.len())? != token
                    || (token.contains('\\') && serde_json::from_str::<String>(token).is_err())
                {
                    return None;
                }
                i += token.len();
                j = end;
            }
            b'{' | b'}' | b'[' | b']' | b',' | b':' => {
                if byte != c[j] {
                    return None;
                }
                i += 1;
                j += 1;
            }
            _ => {
                let end = scalar_end(c, j);
                let meant = &compact[j..end];
                let written_end = scalar_end(w, i);
                let raw = &written[i..written_end];
                let literal = matches!(raw, "true" | "false" | "null");
                let same = if literal {
                    raw == meant
                } else {
                    (raw == meant || with_written_number(meant, |text| text == raw))
                        && (is_plain_number(raw)
                            || serde_json::from_str::<serde_json::Number>(raw).is_ok())
                };
                if !same || end == j {
                    return None;
                }
                i = written_end;
                j = end;
            }
        }
    }
    Some(i)
}

/// Where the string whose opening quote stands at `at` ends (past its closing quote); `None`
/// where it has no end or holds a control character, which JSON allows only escaped (escapes
/// are read where the string is decoded).
fn string_end(bytes: &[u8], at: usize) -> Option<usize> {
    let mut i = at + 1;
    loop {
        // Plain text is passed eight bytes at a time, as the index passes it.
        i += crate::asset::json_text::string_stop(bytes.get(i..)?)?;
        match bytes[i] {
            b'"' => return Some(i + 1),
            b'\\' => i += 2,
            _ => return None,
        }
    }
}

/// Where the number or literal starting at `at` ends: at the next comma, colon, bracket, brace
/// or whitespace.
fn scalar_end(bytes: &[u8], at: usize) -> usize {
    bytes[at..]
        .iter()
        .position(|b| matches!(b, b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r' | b':'))
        .map_or(bytes.len(), |n| at + n)
}

/// Whether `raw` is a JSON number without an exponent: `-?(0|[1-9][0-9]*)(\.[0-9]+)?`.
fn is_plain_number(raw: &str) -> bool {
    let digits = raw.strip_prefix('-').unwrap_or(raw).as_bytes();
    let int_end = digits
        .iter()
        .position(|b| !b.is_ascii_digit())
        .unwrap_or(digits.len());
    let int_ok = int_end == 1 || (int_end > 1 && digits[0] != b'0');
    match &digits[int_end..] {
        [] => int_ok,
        [b'.', fraction @ ..] => {
            int_ok && !fraction.is_empty() && fraction.iter().all(u8::is_ascii_digit)
        }
        _ => false,
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
        text: layout.render(
            after,
            layout.line_indent(text, span.start),
            was_one_line_container,
        ),
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
    for (i, ((_, value), key)) in members.iter().zip(&keys).enumerate() {
        if removed[i] {
            out.extend(removal(&members, i));
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
    // A new key goes after the member that precedes it in the edited document (the edit
    // applier puts `extensionsUsed` after `asset`, say), or first when none does.
    let position: std::collections::HashMap<&str, usize> = keys
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_ref(), i))
        .collect();
    let mut anchor: Option<usize> = None;
    let mut placed: Vec<(Option<usize>, &str, Meant)> = Vec::new();
    for (key, value) in after {
        match position.get(key.as_str()) {
            Some(i) => anchor = Some(*i),
            None => placed.push((anchor, key, Meant::Value(value))),
        }
    }
    insert_members(text, span, &members, &placed, layout, out);
}

/// The splice that removes member `i` of an object with `members` (as (where the key starts,
/// the value)) with one separator; `None` for an only member (its object is written anew).
fn removal(members: &[(usize, Node)], i: usize) -> Option<Splice> {
    let (start, end) = match (i, members.get(i + 1)) {
        // A member after the first takes the separator before it.
        (i, _) if i > 0 => (members[i - 1].1.span().end, members[i].1.span().end),
        // The first member takes the separator after it.
        (_, Some((next_key, _))) => (members[i].0, *next_key),
        (_, None) => return None,
    };
    Some(Splice {
        start,
        end,
        text: String::new(),
    })
}

/// Inserts new members into the object `span` (whose members are `members`, as (where the key
/// starts, the value)): each after the member its anchor names, or first without one, in the
/// order given, laid out as the object's own members are.
fn insert_members(
    text: &str,
    span: Node,
    members: &[(usize, Node)],
    placed: &[(Option<usize>, &str, Meant)],
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(first) = members.first() else {
        return;
    };
    let layout = &layout.local(text, span.span().start, first.0);
    let inline = layout.unit.is_none() || one_line(text, span);
    let indent = layout.line_indent(text, first.0);
    // Between members: what the object's first two members have between them, or a comma
    // and a line break to the members' indentation.
    let between = match (inline, members.get(1)) {
        (true, Some((k, _))) => &text[first.1.span().end..*k],
        (true, None) => layout.inline_comma(),
        (false, _) => "",
    };
    let push_separator = |text: &mut String| {
        if inline {
            text.push_str(between);
        } else {
            text.push(',');
            text.push_str(layout.newline);
            text.push_str(indent);
        }
    };
    let push_member = |text: &mut String, key: &str, value: Meant| {
        push_quoted(text, key);
        text.push_str(&layout.colon);
        let inline = inline || layout.unit.is_none();
        match value {
            Meant::Value(value) => layout.write(value, indent, inline, text),
            Meant::Text(compact) => layout.write_text(compact, indent, inline, text),
        }
    };
    // Room for a layer object of a few members, so that writing one grows a string once at
    // most.
    const ROOM: usize = 256;
    let mut leading = String::new();
    let mut after_member: Vec<(usize, String)> = Vec::new();
    for &(anchor, key, value) in placed {
        match anchor {
            None => {
                leading.reserve(ROOM);
                push_member(&mut leading, key, value);
                push_separator(&mut leading);
            }
            Some(i) => {
                if !matches!(after_member.last(), Some((at, _)) if *at == i) {
                    after_member.push((i, String::with_capacity(ROOM)));
                }
                if let Some((_, insert)) = after_member.last_mut() {
                    push_separator(insert);
                    push_member(insert, key, value);
                }
            }
        }
    }
    if !leading.is_empty() {
        leading.shrink_to_fit();
        out.push(Splice {
            start: first.0,
            end: first.0,
            text: leading,
        });
    }
    for (i, mut insert) in after_member {
        // Kept to the end of the write, by the twenty thousand: cut to its length.
        insert.shrink_to_fit();
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
    let indent = layout.line_indent(text, last.span().start).to_string();
    let separator = if inline {
        existing
            .get(1)
            .map(|second| text[first.span().end..second.span().start].to_string())
            .unwrap_or_else(|| layout.inline_comma().to_string())
    } else {
        concat(&[",", layout.newline, &indent])
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

    /// [`splice_edits`] with its text joined.
    fn splice_edits_text<'e>(
        text: &str,
        root: Node,
        edits: impl IntoIterator<Item = &'e Edit>,
    ) -> Result<Option<(String, bool)>, EditError> {
        splice_edits(text, root, edits).map(|o| o.map(|(s, c)| (s.to_text(), c)))
    }

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

    /// The edits written as splices give the bytes the whole-document path gives: an element
    /// changed within, one replaced, a declaration created after `asset`, a member appended to,
    /// a new top-level member; and a top-level member removed.
    #[test]
    fn edits_spliced_part_by_part_match_the_whole_document_path() {
        let text = "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"materials\": [\n    {\"name\": \"a\"},\n    {\"name\": \"b\", \"extensions\": {\"KHR_materials_sheen\": {\"sheenRoughnessFactor\": 0.800000011920929}}}\n  ],\n  \"images\": [{\"uri\": \"a.png\"}],\n  \"extras\": {\"k\": 1}\n}\n";
        let edits = vec![
            Edit::set(
                "/materials/1/extensions/KHR_materials_fuzz",
                serde_json::json!({"fuzzFactor": 1.0, "fuzzRoughnessFactor": 0.7499999999999999}),
            ),
            Edit::set("/materials/0", serde_json::json!({"name": "c"})),
            Edit::declare_used("KHR_materials_fuzz"),
            Edit::set("/images/1", serde_json::json!({"uri": "b.png"})),
            Edit::set("/textures/0", serde_json::json!({"source": 1})),
        ];
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let (out, changed) = splice_edits_text(text, tape.root(text), &edits)
            .unwrap()
            .unwrap();
        assert!(changed);
        let mut whole: Value = serde_json::from_str(text).unwrap();
        super::super::apply(&mut whole, &edits).unwrap();
        assert_eq!(out, spliced(text, &whole));
        assert!(reads_as_written(&out, &whole));
        // A top-level member removed takes its separator with it.
        let remove = [Edit::remove("/extras")];
        let (out, _) = splice_edits_text(text, tape.root(text), &remove)
            .unwrap()
            .unwrap();
        let mut whole: Value = serde_json::from_str(text).unwrap();
        super::super::apply(&mut whole, &remove).unwrap();
        assert_eq!(out, spliced(text, &whole));
        assert!(out.ends_with("[{\"uri\": \"a.png\"}]\n}\n"));
        // An edit that cannot be applied within an element fails as on the whole document.
        let bad = [Edit::set("/materials/0/name/x", serde_json::json!(1))];
        let mut whole: Value = serde_json::from_str(text).unwrap();
        assert_eq!(
            splice_edits_text(text, tape.root(text), &bad).unwrap_err(),
            super::super::apply(&mut whole, &bad).unwrap_err()
        );
        // A plan that sets what is there changes nothing, and writes the text as it was.
        let same = [Edit::set("/materials/0/name", serde_json::json!("a"))];
        let (out, changed) = splice_edits_text(text, tape.root(text), &same)
            .unwrap()
            .unwrap();
        assert!(!changed);
        assert_eq!(out, text);
    }

    #[test]
    fn members_set_in_an_existing_object_are_spliced_from_the_index_as_the_general_way_does() {
        // Layouts: two spaces with one-line objects, tabs with CRLF, minified; a number
        // spelled with an exponent.
        let texts = [
            "{\n  \"materials\": [\n    {\"name\": \"a\", \"extras\": {\"k\": 1}},\n    {\n      \"name\": \"b\",\n      \"extensions\": {\n        \"KHR_materials_sheen\": {\"sheenRoughnessFactor\": 5E-1}\n      }\n    }\n  ]\n}\n",
            "{\r\n\t\"materials\": [\r\n\t\t{\"name\": \"a\"},\r\n\t\t{\r\n\t\t\t\"extensions\": {\r\n\t\t\t\t\"KHR_materials_sheen\": {\r\n\t\t\t\t\t\"sheenRoughnessFactor\": 0.5\r\n\t\t\t\t}\r\n\t\t\t},\r\n\t\t\t\"name\": \"b\"\r\n\t\t}\r\n\t]\r\n}",
            "{\"materials\":[{\"name\":\"a\"},{\"name\":\"b\",\"extensions\":{\"KHR_materials_sheen\":{\"sheenRoughnessFactor\":0.5}}}]}",
        ];
        let edits = vec![
            Edit::set(
                "/materials/1/extensions/KHR_materials_fuzz",
                serde_json::json!({"fuzzColorFactor": [1, 0.5, 0.25], "fuzzRoughnessFactor": 0.7499999999999999}),
            ),
            Edit::set(
                "/materials/1/extensions/KHR_materials_sheen/sheenRoughnessFactor",
                serde_json::json!(0.25),
            ),
            Edit::set("/materials/1/name", serde_json::json!("b2")),
        ];
        for text in texts {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let root = tape.root(text);
            let element = root.pointer("/materials/1").unwrap();
            let refs: Vec<&Edit> = edits.iter().collect();
            let layout = Layout::detect(text, root);
            let (_, changed, check) =
                members_set_in_place(text, element, "/materials/1", &refs, &layout)
                    .expect("sets of members of existing objects take the index's way");
            assert!(changed);
            let ElementCheck::Digest(digest) = check else {
                panic!("members replaced are checked by digest")
            };
            let mut whole: Value = serde_json::from_str(text).unwrap();
            super::super::apply(&mut whole, &edits).unwrap();
            assert_eq!(digest, value_digest(&whole["materials"][1]), "{text}");
            let (out, _) = splice_edits_text(text, root, &edits).unwrap().unwrap();
            assert_eq!(out, spliced(text, &whole), "{text}");
            assert!(reads_as_written(&out, &whole));
            // Members only added are checked by reading the inserted text alone, and give the
            // text the general way gives.
            let added = &edits[..1];
            let refs: Vec<&Edit> = added.iter().collect();
            let (_, _, check) =
                members_set_in_place(text, element, "/materials/1", &refs, &layout).unwrap();
            assert!(matches!(check, ElementCheck::Inserted(true)), "{text}");
            let mut whole: Value = serde_json::from_str(text).unwrap();
            super::super::apply(&mut whole, added).unwrap();
            let (out, _) = splice_edits_text(text, root, added).unwrap().unwrap();
            assert_eq!(out, spliced(text, &whole), "{text}");
            assert!(reads_as_written(&out, &whole));
        }
        // Removals, paths through missing objects and two edits of one place take the general
        // way, which gives the same text.
        let text = texts[0];
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let root = tape.root(text);
        let element = root.pointer("/materials/1").unwrap();
        let layout = Layout::detect(text, root);
        for others in [
            vec![Edit::remove("/materials/1/name")],
            vec![Edit::set("/materials/1/extras/a", serde_json::json!(1))],
            vec![
                Edit::set("/materials/1/extensions", serde_json::json!({})),
                Edit::set("/materials/1/extensions/x", serde_json::json!(1)),
            ],
        ] {
            let refs: Vec<&Edit> = others.iter().collect();
            assert!(members_set_in_place(text, element, "/materials/1", &refs, &layout).is_none());
            let mut whole: Value = serde_json::from_str(text).unwrap();
            super::super::apply(&mut whole, &others).unwrap();
            let (out, _) = splice_edits_text(text, root, &others).unwrap().unwrap();
            assert_eq!(out, spliced(text, &whole));
        }
        // An object that writes a key twice, beside the path an edit takes, stays as written
        // (the whole-document way writes it anew) and reads as a value reads it.
        let text =
            "{\"materials\": [{\"extras\": {\"k\": 1, \"k\": 2}, \"extensions\": {\"x\": 1}}]}";
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let fuzz = [Edit::set("/materials/0/extensions/y", serde_json::json!(2))];
        let (out, _) = splice_edits_text(text, tape.root(text), &fuzz)
            .unwrap()
            .unwrap();
        assert_eq!(
            out,
            "{\"materials\": [{\"extras\": {\"k\": 1, \"k\": 2}, \"extensions\": {\"x\": 1, \"y\": 2}}]}"
        );
        let mut whole: Value = serde_json::from_str(text).unwrap();
        super::super::apply(&mut whole, &fuzz).unwrap();
        let written = crate::asset::tape::Tape::build(&out).unwrap();
        assert_eq!(node_digest(written.root(&out)), value_digest(&whole));
    }

    #[test]
    fn a_spliced_text_is_written_piece_by_piece_as_the_joined_text() {
        let text = "{\"a\": [1, 2], \"b\": \"é\"}";
        let splice = |start: usize, end: usize, text: &str| Splice {
            start,
            end,
            text: text.to_string(),
        };
        // Given out of order; one at the very start, one replacing a span, one at the end.
        let spliced = Spliced::new(
            text,
            vec![
                splice(text.len(), text.len(), "\n"),
                splice(7, 8, "3"),
                splice(0, 0, ""),
            ],
        )
        .unwrap();
        let joined: Vec<u8> = spliced.pieces().flatten().copied().collect();
        assert_eq!(spliced.to_text(), "{\"a\": [3, 2], \"b\": \"é\"}\n");
        assert_eq!(joined, spliced.to_text().as_bytes());
        assert_eq!(spliced.len(), spliced.to_text().len());
        // Overlapping splices, or one past the end, are never taken.
        assert!(Spliced::new(text, vec![splice(1, 5, ""), splice(4, 6, "")]).is_none());
        assert!(Spliced::new(text, vec![splice(text.len(), text.len() + 1, "")]).is_none());
    }

    #[test]
    fn a_unit_is_read_back_alone_and_refused_when_its_text_holds_something_else() {
        let text = r#"{"m": [{"a": 1}, {"b": [2, 3]}]}"#;
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let element = tape.root(text).pointer("/m/1").unwrap();
        let span = element.span();
        let meant = value_digest(&serde_json::json!({"b": [2, 3], "c": 0.5}));
        let splice = |start: usize, end: usize, text: &str| Splice {
            start,
            end,
            text: text.to_string(),
        };
        let end = span.end - 1; // before the element's closing brace
        assert!(reads_back_within(
            text,
            span.clone(),
            &mut [splice(end, end, r#", "c": 0.5"#)],
            meant
        ));
        for mut wrong in [
            vec![splice(end, end, r#", "c": 0.25"#)],
            vec![splice(end, end, r#" "c": 0.5"#)],
            vec![splice(end, end, r#", "c": 0.5}"#)],
            vec![splice(end, end, r#", "c": 0.5, "c": 1"#)],
            // A splice outside the unit's span is never taken for it.
            vec![splice(span.end, span.end, r#", "c": 0.5"#)],
        ] {
            assert!(!reads_back_within(text, span.clone(), &mut wrong, meant));
        }
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
    fn a_value_and_the_text_velvet_writes_for_it_have_one_digest_and_other_texts_another() {
        let digest_of_text = |text: &str| {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            node_digest(tape.root(text))
        };
        let spelled: Value = serde_json::from_str(r#"[1E-1, 2e+3]"#).unwrap();
        assert_eq!(
            value_digest(&spelled),
            digest_of_text("[\n  1E-1,\n  2e+3\n]"),
            "a number reads alike from the text and from the value read from it, whatever its spelling"
        );
        let meant = serde_json::json!({
            "name": "caf\u{e9} \"1\"",
            "f": [0.7499999999999999, 1.0, 2, 7.5e-8],
            "on": true,
            "none": null,
            "inner": {"k": -0.5}
        });
        let digest = value_digest(&meant);
        // As written: noise rounded, escapes of either spelling, any layout; a key written twice
        // reads as its last value at its first place.
        for text in [
            r#"{"name":"caf\u00e9 \"1\"","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":-0.5}}"#,
            "{\n  \"name\": \"café \\\"1\\\"\",\n  \"f\": [0.75, 1.0, 2, 0],\n  \"on\": true,\n  \"none\": null,\n  \"inner\": {\"k\": -0.5}\n}",
            r#"{"name":"x","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":-0.5},"name":"café \"1\""}"#,
        ] {
            assert_eq!(digest_of_text(text), digest, "{text}");
        }
        for other in [
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0.1],"on":true,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"f":[0.75,1.0,2,0],"name":"café \"1\"","on":true,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0],"on":false,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":"-0.5"}}"#,
            r#"{"name":"café \"1\"","f":[[0.75,1.0],2,0],"on":true,"none":null,"inner":{"k":-0.5}}"#,
        ] {
            assert_ne!(digest_of_text(other), digest, "{other}");
        }
    }

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

    /// An inserted text passes only when it reads as exactly the members meant: a comma before
    /// each, the keys and values (numbers as velvet writes them), nothing after but whitespace,
    /// and no character JSON forbids.
    #[test]
    fn inserted_members_are_checked_by_reading_the_inserted_text() {
        let value =
            serde_json::json!({"fuzzFactor": 0.7499999999999999, "fuzzColorFactor": [1, 0.5]});
        let second = serde_json::json!("b");
        let members = [
            ("KHR_materials_fuzz", Meant::Value(&value)),
            ("name", Meant::Value(&second)),
        ];
        let good = ",\n  \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"\n";
        assert!(inserted_members_read_as(good, &members));
        // The members of an object in another order read as the same object.
        let reordered = ", \"KHR_materials_fuzz\": {\"fuzzColorFactor\": [1, 0.5], \"fuzzFactor\": 0.75}, \"name\": \"b\"";
        assert!(inserted_members_read_as(reordered, &members));
        for bad in [
            // No comma before the first member.
            " \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            // Another key.
            ", \"KHR_materials_fuz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            // Another number, a member missing, a member twice.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.7, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzFactor\": 0.75}, \"name\": \"b\"",
            // A number JSON does not allow, a raw control character in a string.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": .75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [01, 0.5]}, \"name\": \"b\"",
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"na\tme\": \"b\"",
            // Something after the members.
            ", \"KHR_materials_fuzz\": {\"fuzzFactor\": 0.75, \"fuzzColorFactor\": [1, 0.5]}, \"name\": \"b\",",
        ] {
            assert!(!inserted_members_read_as(bad, &members), "{bad}");
        }
    }

    /// Documents in the layouts a file may have: two spaces with number arrays on one line,
    /// tabs with CRLF, four spaces with one-line objects, minified.
    const LAYOUTS: [&str; 4] = [
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"materials\": [\n    {\n      \"extensions\": {\n        \"KHR_materials_sheen\": {\n          \"sheenColorFactor\": [1, 0.5, 0]\n        }\n      }\n    }\n  ]\n}\n",
        "{\r\n\t\"asset\": {\r\n\t\t\"version\": \"2.0\"\r\n\t},\r\n\t\"materials\": [\r\n\t\t{\r\n\t\t\t\"extensions\": {\r\n\t\t\t\t\"KHR_materials_sheen\": {\r\n\t\t\t\t\t\"sheenColorFactor\": [\r\n\t\t\t\t\t\t1,\r\n\t\t\t\t\t\t0.5\r\n\t\t\t\t\t]\r\n\t\t\t\t}\r\n\t\t\t}\r\n\t\t}\r\n\t]\r\n}",
        "{\n    \"asset\": { \"version\": \"2.0\", \"generator\": \"x\" },\n    \"materials\": [\n        { \"extensions\": { \"KHR_materials_sheen\": { \"sheenColorFactor\": [1, 0.5, 0] } } }\n    ]\n}\n",
        "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,0.5,0]}}}]}",
    ];

    /// Values a layer object may hold: nested objects and arrays, empty ones, escaped and
    /// non-ASCII strings, the literals, numbers spelled with exponents and with more decimals
    /// than velvet writes.
    fn layer_values() -> Vec<Value> {
        vec![
            serde_json::json!({"fuzzFactor": 0.9, "fuzzColorFactor": [1.0, 0.5, 0], "fuzzRoughnessFactor": 0.3089, "fuzzRoughnessTexture": {"index": 0}}),
            serde_json::json!({"t": {"index": 2, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0], "offset": []}}, "extras": {}}}),
            serde_json::from_str(r#"{"s": "a \"quoted\" \\ tab\t é \u0001", "b": [true, false, null], "n": [1E-1, -2.5e3, 0.12345678, 7.5e-8], "mixed": [1, "x", {"k": [2]}]}"#).unwrap(),
            serde_json::json!([]),
            serde_json::json!({}),
            serde_json::json!("plain"),
            serde_json::json!(0.7499999999999999),
        ]
    }

    /// Compact text written in a file's layout is, byte for byte, what the value it holds
    /// gives, on one line and over lines, at any indentation; and it reads back as that text.
    #[test]
    fn compact_text_is_laid_out_as_its_value_is() {
        for text in LAYOUTS {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let layout = Layout::detect(text, tape.root(text));
            for value in layer_values() {
                let mut compact = String::new();
                write_compact(&value, &mut compact);
                let reread: Value = serde_json::from_str(&compact).unwrap();
                assert_eq!(reread, written(value.clone()), "{compact}");
                for (indent, inline) in [("", false), ("\t\t", false), ("    ", true), ("", true)] {
                    let mut from_value = String::new();
                    layout.write(&value, indent, inline, &mut from_value);
                    let mut from_text = String::new();
                    layout.write_text(&compact, indent, inline, &mut from_text);
                    assert_eq!(from_text, from_value, "{text:?} {compact}");
                    assert_eq!(
                        reads_as_compact(&from_text, &compact),
                        Some(from_text.len()),
                        "{from_text}"
                    );
                }
            }
        }
    }

    /// Compact text written from the index is what the value read from it gives: escapes,
    /// exponent spellings, long decimals, empty and nested containers, a key written twice.
    #[test]
    fn compact_text_from_the_index_is_the_texts_value_written() {
        for text in [
            r#"{"index": 2, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0], "offset": [], "rotation": 1E-1}}, "extras": {}}"#,
            r#"{"s": "a \"q\" \\ \u00e9 \u0001 é", "t": true, "f": false, "n": null, "x": [0.12345678, -0, 7.5e-8, 1.0, 1e9, 2E+3, 1e5, 1.50]}"#,
            r#"{"k": 1, "j": 2, "k": 3}"#,
            r#"[]"#,
            r#"{}"#,
            r#""plain""#,
            r#"0.7499999999999999"#,
        ] {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let node = tape.root(text);
            let mut from_node = String::new();
            write_compact_node(node, &mut from_node);
            let mut from_value = String::new();
            write_compact(&node.to_value(), &mut from_value);
            assert_eq!(from_node, from_value, "{text}");
        }
    }

    /// A layer object set as text is spliced as the same object set as a value is, in every
    /// layout, and both read back alone.
    #[test]
    fn a_layer_set_as_text_is_spliced_as_the_value_is() {
        let pointer = "/materials/0/extensions/KHR_materials_fuzz";
        for text in LAYOUTS {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            for value in layer_values() {
                let mut compact = String::new();
                write_compact(&value, &mut compact);
                let as_value = [Edit::set(pointer, value.clone())];
                let as_text = [Edit::set_text(pointer, compact)];
                let spliced = splice_edits_text(text, tape.root(text), &as_value)
                    .unwrap()
                    .unwrap();
                assert_eq!(
                    splice_edits_text(text, tape.root(text), &as_text)
                        .unwrap()
                        .unwrap(),
                    spliced
                );
                let mut whole: Value = serde_json::from_str(text).unwrap();
                super::super::apply(&mut whole, &as_value).unwrap();
                assert!(reads_as_written(&spliced.0, &whole));
            }
        }
    }

    /// The check of a laid-out text against compact text refuses any other token, whitespace
    /// inside a token, a string with a raw control character or a bad escape, and a text that
    /// ends early; it accepts whitespace between tokens and numbers written as velvet writes
    /// the compact ones.
    #[test]
    fn laid_out_text_is_checked_against_its_compact_text_token_by_token() {
        let compact = r#"{"a":[1,0.5,true],"b":"x y","c":{}}"#;
        let good = "{\n  \"a\": [1, 0.5, true],\r\n  \"b\" : \"x y\",\t\"c\": {}\n}";
        assert_eq!(reads_as_compact(good, compact), Some(good.len()));
        let followed = format!("{compact} ,");
        assert_eq!(reads_as_compact(&followed, compact), Some(compact.len()));
        assert_eq!(
            reads_as_compact("0.75", "0.7499999999999999"),
            Some(4),
            "a number as velvet writes it"
        );
        for bad in [
            r#"{"a":[1,0. 5,true],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,tr ue],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"b":"x  y","c":{}}"#,
            r#"{"a":[1,0.25,true],"b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"B":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true] "b":"x y","c":{}}"#,
            r#"{"a":[1,0.5,true],"b":"x y","c":{}"#,
            r#"{"a":[1,0.5,1],"b":"x y","c":{}}"#,
            r#"{"a":[1,.5,true],"b":"x y","c":{}}"#,
        ] {
            assert_eq!(reads_as_compact(bad, compact), None, "{bad}");
        }
        assert_eq!(reads_as_compact("\"a\tb\"", "\"a\tb\""), None, "a raw tab");
        assert_eq!(
            reads_as_compact(r#""a\qb""#, r#""a\qb""#),
            None,
            "a bad escape"
        );
        assert_eq!(reads_as_compact("tru", "tru"), None, "not a literal");
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
