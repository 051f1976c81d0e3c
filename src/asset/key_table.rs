//! The distinct object keys of one JSON text, each with a number. The index ([`super::tape`])
//! stores each key's number in its entry, so that finding a member by its key compares
//! numbers and never reads the text. In a large document the keys lie scattered over
//! megabytes of text, and reading a key's text to confirm a match was what lookups spent their
//! time on (a sixth of validate's time on a 20,000-material file, most of it waiting on
//! memory). Two spellings of one key (`"a"` and `"\u0061"`) have one number.
//!
//! Written by hand because std's map hashes with SipHash, which costs about as much per key as
//! indexing the rest of it. Here a table of slots, chosen by a cheap hash of the key's ends,
//! holds the first key of each slot; a glTF document has a few hundred distinct keys, and
//! nearly all of them are found there, in a few kilobytes that stay in cache. A key whose slot
//! another key holds goes to a map hashed with foldhash, seeded at random for each table, so a
//! document whose keys were made to share slots costs a hash per key, never a long search.

use std::collections::HashMap;

/// A table has at most 2^MAX_SLOT_BITS slots (4 KiB), at least 2^MIN_SLOT_BITS (256 bytes).
const MAX_SLOT_BITS: u32 = 10;
const MIN_SLOT_BITS: u32 = 6;

/// The distinct keys of a text, numbered from 0 in the order they first appear.
#[derive(Debug, Clone)]
pub(crate) struct KeyTable {
    /// Each key (unescaped, UTF-8), one after another. Members' keys are read from here rather
    /// than from the text: a few kilobytes in cache, where a large document's keys lie
    /// scattered over megabytes.
    bytes: Vec<u8>,
    /// Where each key starts in `bytes`, and after the last one where it ends: key `id` is
    /// `bytes[bounds[id]..bounds[id + 1]]`.
    bounds: Vec<u32>,
    /// For each slot, the number + 1 of the first key whose hash chose it; 0 while empty.
    slots: Vec<u32>,
    /// 64 less the bits of a slot's number: a hash shifted right by this is a slot.
    shift: u32,
    /// The keys whose slot already held another key when they were first seen.
    overflow: HashMap<Box<[u8]>, u32, foldhash::quality::RandomState>,
}

impl Default for KeyTable {
    fn default() -> KeyTable {
        KeyTable::for_text(usize::MAX)
    }
}

impl KeyTable {
    /// A table for the keys of a text of `len` bytes: a slot for every 16 bytes of a short
    /// text (a key takes at least four, and most are written once or twice), 1,024 from 16
    /// KiB on. A 4 KiB document's index, built again by each fix's trial and each check of a
    /// spliced value, zeroed 4 KiB of slots for its few dozen keys: 2 % of validating 500
    /// such files.
    pub(crate) fn for_text(len: usize) -> KeyTable {
        let bits = (len / 16)
            .checked_next_power_of_two()
            .map_or(MAX_SLOT_BITS, usize::trailing_zeros)
            .clamp(MIN_SLOT_BITS, MAX_SLOT_BITS);
        // Room for a small document's keys (a few dozen, some twenty bytes each) from the
        // start: grown from nothing, the two lists were reallocated a dozen times a document.
        KeyTable {
            bytes: Vec::with_capacity(1024),
            bounds: {
                let mut bounds = Vec::with_capacity(64);
                bounds.push(0);
                bounds
            },
            slots: vec![0; 1 << bits],
            shift: 64 - bits,
            overflow: HashMap::default(),
        }
    }
}

/// The slot of `key`: its length and up to eight bytes from each end, mixed by one multiply.
fn slot_of(key: &[u8], shift: u32) -> usize {
    let n = key.len();
    let (head, tail) = if n >= 8 {
        (word(&key[..8]), word(&key[n - 8..]))
    } else {
        (short(key), 0)
    };
    let mixed = (head ^ tail.rotate_left(29) ^ n as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (mixed >> shift) as usize
}

/// A key of fewer than eight bytes as one word that tells it from every other key of its
/// length: from four bytes, its first four and its last four (overlapping); below, its
/// first, middle and last byte, which are all its bytes. Copying a short key into a word
/// called `memcpy`, and comparing two called `memcmp`, for `uri`, `name`, `index` and the
/// other short keys of every lookup.
#[inline(always)]
fn short(key: &[u8]) -> u64 {
    let n = key.len();
    match n {
        0 => 0,
        1..=3 => u64::from(key[0]) | u64::from(key[n / 2]) << 8 | u64::from(key[n - 1]) << 16,
        _ => u64::from(half(&key[..4])) | u64::from(half(&key[n - 4..])) << 32,
    }
}

fn half(four: &[u8]) -> u32 {
    u32::from_le_bytes(four.try_into().expect("four bytes"))
}

/// Whether two keys are equal. Most glTF keys are 32 bytes long or shorter (`uri`,
/// `sheenColorFactor`, `KHR_materials_sheen`, `metallicRoughnessTexture`): a word or two, or
/// four overlapping words compare them, where a slice comparison calls `memcmp` (with the
/// words for 8 to 16 bytes, validating the 20,000-material library took 6 % less processor
/// time).
#[inline(always)]
fn same(a: &[u8], b: &[u8]) -> bool {
    let n = a.len();
    if n != b.len() {
        return false;
    }
    match n {
        0..=7 => short(a) == short(b),
        8..=16 => word(&a[..8]) == word(&b[..8]) && word(&a[n - 8..]) == word(&b[n - 8..]),
        17..=32 => {
            word(&a[..8]) == word(&b[..8])
                && word(&a[8..16]) == word(&b[8..16])
                && word(&a[n - 16..n - 8]) == word(&b[n - 16..n - 8])
                && word(&a[n - 8..]) == word(&b[n - 8..])
        }
        _ => a == b,
    }
}

fn word(eight: &[u8]) -> u64 {
    u64::from_le_bytes(eight.try_into().expect("eight bytes"))
}

impl KeyTable {
    /// How many distinct keys the table holds.
    pub(crate) fn len(&self) -> usize {
        self.bounds.len() - 1
    }

    /// The key numbered `id`.
    #[inline]
    pub(crate) fn key(&self, id: u32) -> &str {
        let id = id as usize;
        let (start, end) = (self.bounds[id] as usize, self.bounds[id + 1] as usize);
        // SAFETY: `bytes` holds whole keys one after another, each copied from a `&str`
        // (`push`), and `bounds` where each starts and ends: the range is one key's UTF-8.
        // Unchecked, as every member read and every lookup by key reads a key here: the
        // checks of a slice of a `String` were a third of this function's instructions, and
        // it a sixteenth of a validation's.
        unsafe { std::str::from_utf8_unchecked(&self.bytes[start..end]) }
    }

    /// The number of `key`, if the text has it as a key anywhere.
    #[inline]
    pub(crate) fn id(&self, key: &str) -> Option<u32> {
        // A key goes to the overflow map only when its slot is taken, and a slot is never
        // emptied: an empty slot means no key of the text has this slot.
        let first = self.slots[slot_of(key.as_bytes(), self.shift)].checked_sub(1)?;
        if same(self.key(first).as_bytes(), key.as_bytes()) {
            Some(first)
        } else {
            self.overflowed(key)
        }
    }

    /// The number of `key` among the keys whose slot another key held. Out of line: inlined,
    /// the map's lookup made every lookup save and restore registers for it, which took a
    /// third of [`KeyTable::id`]'s instructions.
    #[cold]
    #[inline(never)]
    fn overflowed(&self, key: &str) -> Option<u32> {
        self.overflow.get(key.as_bytes()).copied()
    }

    /// The number of `key`, given a new one if the table does not hold it yet.
    pub(crate) fn intern(&mut self, key: &str) -> u32 {
        let slot = slot_of(key.as_bytes(), self.shift);
        match self.slots[slot].checked_sub(1) {
            None => {
                let id = self.push(key);
                self.slots[slot] = id + 1;
                id
            }
            Some(first) if same(self.key(first).as_bytes(), key.as_bytes()) => first,
            Some(_) => {
                if let Some(&id) = self.overflow.get(key.as_bytes()) {
                    return id;
                }
                let id = self.push(key);
                self.overflow.insert(key.as_bytes().into(), id);
                id
            }
        }
    }

    fn push(&mut self, key: &str) -> u32 {
        let id = self.len() as u32;
        self.bytes.extend_from_slice(key.as_bytes());
        // The keys are taken from a text under 4 GiB, each distinct key once.
        self.bounds.push(self.bytes.len() as u32);
        id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_distinct_key_has_one_number_in_order_of_first_sight() {
        let mut table = KeyTable::default();
        let keys: [&str; 6] = ["extensions", "", "a", "KHR_materials_sheen", "a", ""];
        let ids: Vec<u32> = keys.iter().map(|k| table.intern(k)).collect();
        assert_eq!(ids, [0, 1, 2, 3, 2, 1]);
        assert_eq!(table.len(), 4);
        assert_eq!(table.id("KHR_materials_sheen"), Some(3));
        assert_eq!(table.id(""), Some(1));
        assert_eq!(table.id("KHR_materials_fuzz"), None);
        assert_eq!(table.id("extension"), None);
    }

    #[test]
    fn keys_that_share_a_slot_keep_their_own_numbers() {
        // Forty thousand keys in 1,024 slots: most share theirs with others.
        let mut table = KeyTable::default();
        let keys: Vec<String> = (0..40_000).map(|i| format!("k{i}_{}", i % 7)).collect();
        for (i, key) in keys.iter().enumerate() {
            assert_eq!(table.intern(key), i as u32);
        }
        assert!(table.overflow.len() > 30_000);
        for (i, key) in keys.iter().enumerate() {
            assert_eq!(table.id(key), Some(i as u32));
            assert_eq!(table.intern(key), i as u32);
        }
        assert_eq!(table.id("k40000_0"), None);
        assert_eq!(table.len(), keys.len());
    }

    /// A table has a slot for every 16 bytes of its text, 64 to 1,024; a small one holds
    /// more keys than slots, each under its own number.
    #[test]
    fn a_short_text_gets_a_small_table_that_still_numbers_every_key() {
        let slots = |len: usize| KeyTable::for_text(len).slots.len();
        assert_eq!(
            [0, 1024, 1040, 4096, 16 << 10, 1 << 20, usize::MAX].map(slots),
            [64, 64, 128, 256, 1024, 1024, 1024]
        );
        let mut table = KeyTable::for_text(100);
        let keys: Vec<String> = (0..200).map(|i| format!("key{i}")).collect();
        for (i, key) in keys.iter().enumerate() {
            assert_eq!(table.intern(key), i as u32);
        }
        assert!(!table.overflow.is_empty());
        for (i, key) in keys.iter().enumerate() {
            assert_eq!(table.id(key), Some(i as u32));
            assert_eq!(table.key(i as u32), key);
        }
        assert_eq!(table.id("key200"), None);
    }

    #[test]
    fn keys_are_equal_only_when_every_byte_is() {
        let keys = [
            "",
            "a",
            "ab",
            "abc",
            "abd",
            "abcd",
            "abce",
            "abcde",
            "abcdef",
            "abcdefg",
            "abcdefgh",
            "abcdefghi",
            "sheenColorFactor",
            "sheenColorFactorX",
            "KHR_materials_sheen",
            "metallicRoughnessTexture",
            "KHR_materials_emissive_strength",
            "KHR_materials_emissive_strength_",
            "KHR_materials_emissive_strength__",
        ];
        for a in keys {
            for b in keys {
                assert_eq!(same(a.as_bytes(), b.as_bytes()), a == b, "{a} {b}");
            }
            // One byte changed anywhere is told apart.
            for i in 0..a.len() {
                let mut changed = a.as_bytes().to_vec();
                changed[i] ^= 1;
                assert!(!same(a.as_bytes(), &changed), "{a} at {i}");
            }
        }
    }

    #[test]
    fn keys_alike_at_both_ends_are_told_apart() {
        let mut table = KeyTable::default();
        let a = table.intern("sheenColor_____Texture");
        let b = table.intern("sheenColor_x___Texture");
        let c = table.intern("sheenColor______Texture");
        assert_eq!((a, b, c), (0, 1, 2));
        assert_eq!(table.id("sheenColor_x___Texture"), Some(1));
        assert_eq!(table.id("sheenColor_y___Texture"), None);
    }
}
