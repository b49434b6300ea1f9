//! The allowed-collision matrix: pairs of objects never reported as contacts
//! (robot links that always touch their neighbours), kept by arena slot.

use rustc_hash::{FxHashMap, FxHashSet};

/// An unordered pair of slots as one key: the smaller slot in the high half.
#[inline]
pub(crate) fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (lo as u64) << 32 | hi as u64
}

/// The two slots of a [`pair_key`], smaller first.
#[inline]
pub(crate) fn key_slots(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}

/// The ignored pairs, and for each slot the slots it is paired with (so that
/// removing an object drops its pairs in O(its pairs)).
#[derive(Clone, Debug, Default)]
pub(crate) struct IgnoredPairs {
    pairs: FxHashSet<u64>,
    partners: FxHashMap<u32, Vec<u32>>,
}

impl IgnoredPairs {
    /// Adds the pair; false if it was there. O(1) amortized.
    pub(crate) fn insert(&mut self, a: u32, b: u32) -> bool {
        if !self.pairs.insert(pair_key(a, b)) {
            return false;
        }
        self.partners.entry(a).or_default().push(b);
        self.partners.entry(b).or_default().push(a);
        true
    }

    /// Removes the pair; false if it was not there. O(partners of a and b).
    pub(crate) fn remove(&mut self, a: u32, b: u32) -> bool {
        if !self.pairs.remove(&pair_key(a, b)) {
            return false;
        }
        self.unlink(a, b);
        self.unlink(b, a);
        true
    }

    fn unlink(&mut self, a: u32, b: u32) {
        if let Some(list) = self.partners.get_mut(&a) {
            list.retain(|&x| x != b);
            if list.is_empty() {
                self.partners.remove(&a);
            }
        }
    }

    /// Whether the pair is ignored. O(1).
    #[inline]
    pub(crate) fn contains(&self, a: u32, b: u32) -> bool {
        !self.pairs.is_empty() && self.pairs.contains(&pair_key(a, b))
    }

    /// Drops every pair of slot `a` (its object is removed).
    pub(crate) fn drop_object(&mut self, a: u32) {
        if let Some(list) = self.partners.remove(&a) {
            for b in list {
                self.pairs.remove(&pair_key(a, b));
                self.unlink(b, a);
            }
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.pairs.len()
    }

    /// Every ignored pair, as slot keys.
    pub(crate) fn keys(&self) -> impl Iterator<Item = u64> + '_ {
        self.pairs.iter().copied()
    }

    /// The partner lists, for `validate`.
    pub(crate) fn partners(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        self.partners.iter().map(|(&a, l)| (a, l.as_slice()))
    }

    pub(crate) fn memory_bytes(&self) -> usize {
        self.pairs.capacity() * 9
            + self
                .partners
                .values()
                .map(|l| l.capacity() * 4 + 32)
                .sum::<usize>()
    }
}
