//! [`splice_edits`]: a plan's edits written as splices part by part, without the edited
//! document. The edits are grouped by the part they touch (a top-level member, or one element
//! of a top-level array: a material, an image), and the parts are spliced in parallel, each
//! read into a value only where it must be: a member set in an object the element already
//! holds is spliced from the index alone. Each part's new text is checked alone, by reading
//! the inserted text or by the digest of the part's new text; only a part that adds or removes
//! a top-level member needs the whole output indexed.

use super::diff::{self, diff, insert_members, matches, member_starts, removal};
use super::digest::{feed_edited, node_digest, value_digest, Digest};
use super::layout::Layout;
use super::read_back::{inserted_members_read_as, Compare, Meant};
use super::{in_order, is_written, runs, written, Splice, Spliced};
use crate::asset::tape::{Kind, Node};
use crate::edit::{Edit, EditError, SetValue};
use rayon::prelude::*;
use serde_json::{Map, Value};

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
    let members = member_starts(&entries);
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

/// One edit of [`members_set_in_place`]: where it sets, as tokens below the element, and the
/// value the text will hold (a [`Edit::Set`]'s as velvet writes it, a [`Edit::Replace`]'s as
/// given), or `None` where an [`Edit::Remove`] takes the member away.
struct MemberSet<'e> {
    tokens: Vec<std::borrow::Cow<'e, str>>,
    value: Option<SetTo<'e>>,
}

/// What a member is set to: a value, or compact text as [`write_compact`] writes it.
///
/// [`write_compact`]: super::write_compact
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
            SetTo::Text(text) => std::borrow::Cow::Owned(crate::edit::value_of_text(text)),
        }
    }
}

/// The splices of an element unit whose edits each set, replace or remove a member of an
/// object the element already holds, or set an element of an array it holds (the fuzz object a
/// migration adds to a material's `extensions`, a factor it replaces, a texture a fix removes,
/// a component a fix clamps), made from the index alone: the element is not read into a value,
/// edited and compared with its text, which for a migration of every material was most of the
/// writer's work. A removal takes the member and one separator, as the general way does; an
/// object that both loses and gains members (a draft sheen upgraded) is written anew with the
/// edits inside it made, as the general way writes it, and only it is read into a value.
/// Returns the splices, whether they change anything, and how the element reads back as meant:
/// when every edit adds a member, whether each inserted text reads as its members
/// ([`inserted_members_read_as`]); otherwise the digest the element must read back as, fed from
/// the index with the set values in their places and the removed members left out, as the
/// edited value would feed it. `None` for edits the general way writes otherwise or that it
/// refuses (an array element removed or appended, a path through a missing key or an object
/// that writes a key twice, two edits of one place, a removal of an absent or only member, two
/// removals from one object that gains nothing, an object to be written anew inside another);
/// the caller then takes the general way.
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
            } => (pointer, Some(SetTo::Text(text))),
            Edit::Set {
                pointer,
                value: SetValue::Value(value),
            } if is_written(value) => (pointer, Some(SetTo::Value(Cow::Borrowed(value)))),
            Edit::Set {
                pointer,
                value: SetValue::Value(value),
            } => (
                pointer,
                Some(SetTo::Value(Cow::Owned(written(value.clone())))),
            ),
            Edit::Replace { pointer, value } => (pointer, Some(SetTo::Value(Cow::Borrowed(value)))),
            Edit::Remove { pointer } => (pointer, None),
            Edit::DeclareUsed { .. } => return None,
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
    // Whether some edit sets or removes a member the element holds already.
    let mut replaced = false;
    // New members by the object that receives them, in the order the edits add them.
    let mut inserts: Vec<(Node, Vec<(&str, Meant)>)> = Vec::new();
    // Where each object that loses a member starts.
    let mut removed_from: Vec<usize> = Vec::new();
    // Each edit's parent: the object or array whose member or element it sets or removes.
    let mut parents: Vec<Node> = Vec::with_capacity(sets.len());
    for set in &sets {
        let (_, path) = set.tokens.split_last()?;
        let mut parent = element;
        for token in path {
            parent = member_or_element(parent, token)?;
        }
        parents.push(parent);
    }
    // The objects that both lose and gain members (a draft sheen upgraded: two properties out,
    // two in), with how deep each lies below the element: the general way writes each anew,
    // with the edits inside it made, and so is it written here.
    let inside = |inner: &Node, outer: &Node| {
        outer.span().start <= inner.span().start && inner.span().end <= outer.span().end
    };
    let mut rewritten: Vec<(Node, usize)> = Vec::new();
    for (set, parent) in sets.iter().zip(&parents) {
        // An object that writes each key once: the only kind whose members are told apart.
        let object = parent.as_object().filter(|o| !o.has_duplicate_keys());
        let Some((object, key)) = object.zip(set.tokens.last()) else {
            continue;
        };
        // A member there to remove (removing an absent one changes nothing), and a member the
        // object lacks set in it.
        let loses = set.value.is_none() && object.contains_key(key);
        let gains = || {
            sets.iter().zip(&parents).any(|(other, p)| {
                p.span() == parent.span()
                    && other.value.is_some()
                    && other.tokens.last().is_some_and(|k| !object.contains_key(k))
            })
        };
        if loses && gains() && !rewritten.iter().any(|(r, _)| r.span() == parent.span()) {
            rewritten.push((*parent, set.tokens.len() - 1));
        }
    }
    let within_rewritten = |node: &Node| rewritten.iter().position(|(r, _)| inside(node, r));
    // One rewritten object inside another: left to the general way.
    if rewritten
        .iter()
        .any(|(r, _)| rewritten.iter().filter(|(o, _)| inside(r, o)).count() > 1)
    {
        return None;
    }
    for (set, parent) in sets.iter().zip(&parents) {
        if within_rewritten(parent).is_some() {
            continue;
        }
        let parent = *parent;
        let key = set.tokens.last()?;
        if let Some(array) = parent.as_array() {
            // An element the array holds, set (a factor's component clamped): the general way
            // diffs it with its new value too. A removal or an append moves or adds elements:
            // the general way.
            let value = set.value.as_ref()?.value();
            let old = array.get(crate::asset::pointer::array_index(key)?)?;
            replaced = true;
            changed |= !matches(old, &value, Compare::Exact);
            diff(text, old, &value, layout, &mut splices);
            continue;
        }
        let object = parent
            .as_object()
            .filter(|o| !o.is_empty() && !o.has_duplicate_keys())?;
        match (&set.value, object.get(key)) {
            (Some(value), Some(old)) => {
                replaced = true;
                let value = value.value();
                changed |= !matches(old, &value, Compare::Exact);
                diff(text, old, &value, layout, &mut splices);
            }
            (Some(value), None) => {
                changed = true;
                let at = parent.span().start;
                match inserts.iter_mut().find(|(p, _)| p.span().start == at) {
                    Some((_, new)) => new.push((key, value.meant())),
                    None => inserts.push((parent, vec![(key.as_ref(), value.meant())])),
                }
            }
            (None, Some(_)) => {
                // Two members of one object: the general way removes them one by one, and
                // side by side their separators would overlap; left to it.
                if removed_from.contains(&parent.span().start) {
                    return None;
                }
                removed_from.push(parent.span().start);
                let entries = object.entries();
                let i = entries
                    .iter()
                    .position(|(k, _)| k.as_str().is_some_and(|k| k == *key))?;
                // An only member's object is written anew by the general way.
                splices.push(removal(&member_starts(&entries), i)?);
                replaced = true;
                changed = true;
            }
            // Nothing to remove: the general way says what that does.
            (None, None) => return None,
        }
    }
    // Each rewritten object: its value with the edits inside it made, written over it.
    for (at, (r, depth)) in rewritten.iter().enumerate() {
        let mut value = r.to_value();
        for (parent, edit) in parents.iter().zip(edits) {
            if within_rewritten(parent) != Some(at) {
                continue;
            }
            let (Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer }) = edit
            else {
                return None;
            };
            // The edit's pointer below the object: past the element's prefix and `depth` tokens.
            let below_element = &pointer[prefix.len()..];
            let at = below_element
                .match_indices('/')
                .nth(*depth)
                .map(|(at, _)| at)?;
            crate::edit::apply(&mut value, &[edit.at(&below_element[at..])]).ok()?;
        }
        diff::replace(text, *r, &value, layout, &mut splices);
        replaced = true;
        changed = true;
    }
    for (parent, new) in &inserts {
        let members = member_starts(&parent.as_object()?.entries());
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
    let values: Vec<Option<std::borrow::Cow<Value>>> = sets
        .iter()
        .map(|s| s.value.as_ref().map(SetTo::value))
        .collect();
    let sets: Vec<(&[std::borrow::Cow<str>], Option<&Value>)> = sets
        .iter()
        .zip(&values)
        .map(|(s, value)| (s.tokens.as_slice(), value.as_deref()))
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
                        changed |= crate::edit::apply(&mut value, &[edit.at(within)])
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
            changed |= crate::edit::apply(&mut part, &owned)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::splice::tests::{layer_values, spliced, LAYOUTS};
    use crate::edit::splice::{reads_as_written, write_compact};

    /// [`splice_edits`] with its text joined.
    fn splice_edits_text<'e>(
        text: &str,
        root: Node,
        edits: impl IntoIterator<Item = &'e Edit>,
    ) -> Result<Option<(String, bool)>, EditError> {
        splice_edits(text, root, edits).map(|o| o.map(|(s, c)| (s.to_text(), c)))
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
        crate::edit::apply(&mut whole, &edits).unwrap();
        assert_eq!(out, spliced(text, &whole));
        assert!(reads_as_written(&out, &whole));
        // A top-level member removed takes its separator with it.
        let remove = [Edit::remove("/extras")];
        let (out, _) = splice_edits_text(text, tape.root(text), &remove)
            .unwrap()
            .unwrap();
        let mut whole: Value = serde_json::from_str(text).unwrap();
        crate::edit::apply(&mut whole, &remove).unwrap();
        assert_eq!(out, spliced(text, &whole));
        assert!(out.ends_with("[{\"uri\": \"a.png\"}]\n}\n"));
        // An edit that cannot be applied within an element fails as on the whole document.
        let bad = [Edit::set("/materials/0/name/x", serde_json::json!(1))];
        let mut whole: Value = serde_json::from_str(text).unwrap();
        assert_eq!(
            splice_edits_text(text, tape.root(text), &bad).unwrap_err(),
            crate::edit::apply(&mut whole, &bad).unwrap_err()
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
    fn members_removed_and_array_elements_set_are_spliced_from_the_index_as_the_general_way_does() {
        // The element in three layouts: one-line objects, tabs with CRLF, minified.
        let texts = [
            "{\n  \"materials\": [\n    {\"name\": \"a\"},\n    {\"name\": \"b\", \"extensions\": {\"KHR_materials_sheen\": {\"sheenColorFactor\": [1.5, 0, 0], \"sheenColorTexture\": {\"index\": 0}, \"sheenRoughnessFactor\": 0.5}}, \"extras\": {\"k\": 1}}\n  ]\n}\n",
            "{\r\n\t\"materials\": [\r\n\t\t{\"name\": \"a\"},\r\n\t\t{\r\n\t\t\t\"name\": \"b\",\r\n\t\t\t\"extensions\": {\r\n\t\t\t\t\"KHR_materials_sheen\": {\r\n\t\t\t\t\t\"sheenColorFactor\": [1.5, 0, 0],\r\n\t\t\t\t\t\"sheenColorTexture\": {\"index\": 0},\r\n\t\t\t\t\t\"sheenRoughnessFactor\": 0.5\r\n\t\t\t\t}\r\n\t\t\t},\r\n\t\t\t\"extras\": {\"k\": 1}\r\n\t\t}\r\n\t]\r\n}",
            "{\"materials\":[{\"name\":\"a\"},{\"name\":\"b\",\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[1.5,0,0],\"sheenColorTexture\":{\"index\":0},\"sheenRoughnessFactor\":0.5}},\"extras\":{\"k\":1}}]}",
        ];
        let sheen = "/materials/1/extensions/KHR_materials_sheen";
        // (the edits, whether the index's way takes them)
        let cases: Vec<(Vec<Edit>, bool)> = vec![
            // The first, a middle and the last member; with a set beside it in its object and
            // in another; with a member added to another object.
            (vec![Edit::remove("/materials/1/name")], true),
            (
                vec![Edit::remove(format!("{sheen}/sheenColorTexture"))],
                true,
            ),
            (vec![Edit::remove("/materials/1/extras")], true),
            (
                vec![
                    Edit::set(
                        format!("{sheen}/sheenColorFactor/0"),
                        serde_json::json!(1.0),
                    ),
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                ],
                true,
            ),
            // An element of an array set, alone and as an object.
            (
                vec![Edit::set(
                    format!("{sheen}/sheenColorFactor/2"),
                    serde_json::json!(0.25),
                )],
                true,
            ),
            (
                vec![Edit::set(
                    format!("{sheen}/sheenColorFactor/1"),
                    serde_json::json!({"a": [1]}),
                )],
                true,
            ),
            (
                vec![
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                    Edit::set(
                        format!("{sheen}/sheenRoughnessFactor"),
                        serde_json::json!(0.25),
                    ),
                    Edit::set("/materials/1/extras/j", serde_json::json!(2)),
                ],
                true,
            ),
            // An object that loses one member and gains another: written anew, as the general
            // way writes it.
            (
                vec![
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                    Edit::set(
                        format!("{sheen}/sheenRoughnessTexture"),
                        serde_json::json!({"index": 0}),
                    ),
                ],
                true,
            ),
            // The draft's upgrade: two members out, two in, the object written anew.
            (
                vec![
                    Edit::remove(format!("{sheen}/sheenColorFactor")),
                    Edit::set(format!("{sheen}/sheenFactor"), serde_json::json!(1.0)),
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                    Edit::set(
                        format!("{sheen}/sheenColor"),
                        serde_json::json!([1, 0.5, 0]),
                    ),
                    Edit::set("/materials/1/name", serde_json::json!("c")),
                ],
                true,
            ),
            // Left to the general way: two members of one object, side by side or not; an
            // only member; an absent member; an array element removed or appended.
            (
                vec![
                    Edit::remove(format!("{sheen}/sheenColorFactor")),
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                ],
                false,
            ),
            (
                vec![
                    Edit::remove("/materials/1/name"),
                    Edit::remove("/materials/1/extras"),
                ],
                false,
            ),
            // An object to be written anew inside another one to be written anew.
            (
                vec![
                    Edit::remove("/materials/1/name"),
                    Edit::set("/materials/1/x", serde_json::json!(1)),
                    Edit::remove(format!("{sheen}/sheenColorTexture")),
                    Edit::set(format!("{sheen}/y"), serde_json::json!(2)),
                ],
                false,
            ),
            (vec![Edit::remove("/materials/1/extras/k")], false),
            (vec![Edit::remove("/materials/1/absent")], false),
            (
                vec![Edit::remove(format!("{sheen}/sheenColorFactor/2"))],
                false,
            ),
            (
                vec![Edit::set(
                    format!("{sheen}/sheenColorFactor/3"),
                    serde_json::json!(1),
                )],
                false,
            ),
            (
                vec![Edit::set(
                    format!("{sheen}/sheenColorFactor/-"),
                    serde_json::json!(1),
                )],
                false,
            ),
        ];
        for text in texts {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let root = tape.root(text);
            let element = root.pointer("/materials/1").unwrap();
            let layout = Layout::detect(text, root);
            for (edits, in_place) in &cases {
                let refs: Vec<&Edit> = edits.iter().collect();
                let taken = members_set_in_place(text, element, "/materials/1", &refs, &layout);
                assert_eq!(taken.is_some(), *in_place, "{edits:?} in {text}");
                let mut whole: Value = serde_json::from_str(text).unwrap();
                crate::edit::apply(&mut whole, edits).unwrap();
                if let Some((_, changed, check)) = taken {
                    assert!(changed);
                    let ElementCheck::Digest(digest) = check else {
                        panic!("removals are checked by digest")
                    };
                    assert_eq!(digest, value_digest(&whole["materials"][1]), "{edits:?}");
                }
                // The splicer may decline what the general way writes (the caller then writes
                // the whole document); never what the index's way takes.
                match splice_edits_text(text, root, edits).unwrap() {
                    Some((out, _)) => {
                        assert_eq!(out, spliced(text, &whole), "{edits:?} in {text}");
                        assert!(reads_as_written(&out, &whole), "{edits:?} in {text}");
                    }
                    None => assert!(!in_place, "{edits:?} in {text}"),
                }
            }
        }
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
            crate::edit::apply(&mut whole, &edits).unwrap();
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
            crate::edit::apply(&mut whole, added).unwrap();
            let (out, _) = splice_edits_text(text, root, added).unwrap().unwrap();
            assert_eq!(out, spliced(text, &whole), "{text}");
            assert!(reads_as_written(&out, &whole));
        }
        // Paths through missing objects and two edits of one place take the general way,
        // which gives the same text.
        let text = texts[0];
        let tape = crate::asset::tape::Tape::build(text).unwrap();
        let root = tape.root(text);
        let element = root.pointer("/materials/1").unwrap();
        let layout = Layout::detect(text, root);
        for others in [
            vec![Edit::set("/materials/1/extras/a", serde_json::json!(1))],
            vec![
                Edit::set("/materials/1/extensions", serde_json::json!({})),
                Edit::set("/materials/1/extensions/x", serde_json::json!(1)),
            ],
        ] {
            let refs: Vec<&Edit> = others.iter().collect();
            assert!(members_set_in_place(text, element, "/materials/1", &refs, &layout).is_none());
            let mut whole: Value = serde_json::from_str(text).unwrap();
            crate::edit::apply(&mut whole, &others).unwrap();
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
        crate::edit::apply(&mut whole, &fuzz).unwrap();
        let written = crate::asset::tape::Tape::build(&out).unwrap();
        assert_eq!(node_digest(written.root(&out)), value_digest(&whole));
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
                crate::edit::apply(&mut whole, &as_value).unwrap();
                assert!(reads_as_written(&spliced.0, &whole));
            }
        }
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        use crate::asset::tape::properties::json_value;

        /// Every pointer below `value` (its members and elements, at any depth).
        fn places(at: &str, value: &Value, out: &mut Vec<String>) {
            let children: Vec<(String, &Value)> = match value {
                Value::Object(m) => m
                    .iter()
                    .map(|(k, v)| (crate::asset::pointer::escape(k), v))
                    .collect(),
                Value::Array(a) => a
                    .iter()
                    .enumerate()
                    .map(|(i, v)| (i.to_string(), v))
                    .collect(),
                _ => Vec::new(),
            };
            for (token, child) in children {
                let pointer = format!("{at}/{token}");
                out.push(pointer.clone());
                places(&pointer, child, out);
            }
        }

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(256))]

            /// Sets and removals of members and elements inside a material, in any layout,
            /// spliced by whichever way takes them, give the text the whole edited document
            /// is written as. They are declined (the caller then writes the whole document)
            /// only where the whole document's splices are too: what the index's way takes
            /// reads back as meant unless the shared diff itself cannot write it (two removed
            /// members side by side, whose separators overlap).
            #[test]
            fn members_and_elements_set_or_removed_are_spliced_as_the_whole_edited_document_is_written(
                material in prop::collection::vec(("[a-d]", json_value()), 1..5),
                picks in prop::collection::vec(
                    (any::<prop::sample::Index>(), any::<bool>(), json_value()), 1..4),
                pretty in any::<bool>(),
            ) {
                let material = Value::Object(material.into_iter().collect());
                let doc = serde_json::json!({"asset": {"version": "2.0"},
                    "materials": [{"name": "first"}, material, {"name": "last"}]});
                let text = if pretty {
                    serde_json::to_string_pretty(&doc).unwrap()
                } else {
                    serde_json::to_string(&doc).unwrap()
                };
                let mut at = Vec::new();
                places("/materials/1", &doc["materials"][1], &mut at);
                prop_assume!(!at.is_empty());
                let edits: Vec<Edit> = picks
                    .iter()
                    .map(|(index, remove, value)| {
                        let pointer = index.get(&at).clone();
                        if *remove {
                            Edit::remove(pointer)
                        } else {
                            Edit::set(pointer, value.clone())
                        }
                    })
                    .collect();
                let mut whole = doc.clone();
                prop_assume!(crate::edit::apply(&mut whole, &edits).is_ok());
                let tape = crate::asset::tape::Tape::build(&text).unwrap();
                let root = tape.root(&text);
                let element = root.pointer("/materials/1").unwrap();
                let refs: Vec<&Edit> = edits.iter().collect();
                let layout = Layout::detect(&text, root);
                let taken =
                    members_set_in_place(&text, element, "/materials/1", &refs, &layout).is_some();
                match splice_edits_text(&text, root, &edits).unwrap() {
                    Some((out, _)) => {
                        prop_assert_eq!(&out, &spliced(&text, &whole));
                        prop_assert!(reads_as_written(&out, &whole));
                    }
                    None => prop_assert!(
                        !taken || crate::edit::splice::rewrite(&text, root, &whole).is_none(),
                        "the index's way took {:?}, which did not read back", edits
                    ),
                }
            }
        }
    }
}
