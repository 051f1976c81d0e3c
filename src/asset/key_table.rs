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
//! another key holds goes to a SipHash map, so a document whose keys were made to share slots
//! costs a SipHash per key, never a long search.

use std::collections::HashMap;

/// The table has 2^SLOT_BITS slots (4 KiB).
const SLOT_BITS: u32 = 10;

/// The distinct keys of a text, numbered from 0 in the order they first appear.
#[derive(Debug, Clone)]
pub(crate) struct KeyTable {
    /// Each key (unescaped), one after another. Members' keys are read from here rather than
    /// from the text: a few kilobytes in cache, where a large document's keys lie scattered
    /// over megabytes.
    bytes: String,
    /// Where each key ends in `bytes`; key `id` starts where key `id - 1` ends.
    ends: Vec<u32>,
    /// For each slot, the number + 1 of the first key whose hash chose it; 0 while empty.
    slots: Vec<u32>,
    /// The keys whose slot already held another key when they were first seen.
    overflow: HashMap<Box<[u8]>, u32>,
}

impl Default for KeyTable {
    fn default() -> KeyTable {
        // Room for a small document's keys (a few dozen, some twenty bytes each) from the
        // start: grown from nothing, the two lists were reallocated a dozen times a document.
        KeyTable {
            bytes: String::with_capacity(1024),
            ends: Vec::with_capacity(64),
            slots: vec![0; 1 << SLOT_BITS],
            overflow: HashMap::new(),
        }
    }
}

/// The slot of `key`: its length and up to eight bytes from each end, mixed by one multiply.
fn slot_of(key: &[u8]) -> usize {
    let n = key.len();
    let (head, tail) = if n >= 8 {
        (word(&key[..8]), word(&key[n - 8..]))
    } else {
        let mut short = [0u8; 8];
        short[..n].copy_from_slice(key);
        (u64::from_le_bytes(short), 0)
    };
    let mixed = (head ^ tail.rotate_left(29) ^ n as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (mixed >> (64 - SLOT_BITS)) as usize
}

/// Whether two keys are equal. Most glTF keys are 8 to 16 bytes long: two overlapping words
/// compare them, where a slice comparison calls `memcmp` (with this, validating the
/// 20,000-material library took 6 % less processor time).
fn same(a: &[u8], b: &[u8]) -> bool {
    let n = a.len();
    if n != b.len() {
        return false;
    }
    if (8..=16).contains(&n) {
        word(&a[..8]) == word(&b[..8]) && word(&a[n - 8..]) == word(&b[n - 8..])
    } else {
        a == b
    }
}

fn word(eight: &[u8]) -> u64 {
    u64::from_le_bytes(eight.try_into().expect("eight bytes"))
}

impl KeyTable {
    /// How many distinct keys the table holds.
    pub(crate) fn len(&self) -> usize {
        self.ends.len()
    }

    /// The key numbered `id`.
    pub(crate) fn key(&self, id: u32) -> &str {
        let id = id as usize;
        let start = if id == 0 {
            0
        } else {
            self.ends[id - 1] as usize
        };
        &self.bytes[start..self.ends[id] as usize]
    }

    /// The number of `key`, if the text has it as a key anywhere.
    pub(crate) fn id(&self, key: &str) -> Option<u32> {
        // A key goes to the overflow map only when its slot is taken, and a slot is never
        // emptied: an empty slot means no key of the text has this slot.
        let first = self.slots[slot_of(key.as_bytes())].checked_sub(1)?;
        if same(self.key(first).as_bytes(), key.as_bytes()) {
            Some(first)
        } else {
            self.overflow.get(key.as_bytes()).copied()
        }
    }

    /// The number of `key`, given a new one if the table does not hold it yet.
    pub(crate) fn intern(&mut self, key: &str) -> u32 {
        let slot = slot_of(key.as_bytes());
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
        let id = self.ends.len() as u32;
        self.bytes.push_str(key);
        // The keys are taken from a text under 4 GiB, each distinct key once.
        self.ends.push(self.bytes.len() as u32);
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

    #[test]
    fn keys_are_equal_only_when_every_byte_is() {
        let keys = [
            "",
            "a",
            "abcdefg",
            "abcdefgh",
            "abcdefghi",
            "sheenColorFactor",
            "sheenColorFactorX",
            "KHR_materials_sheen",
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
