//! Index-based storage shared by every structure: a generational [`Arena`] for the
//! user's objects (stable [`Handle`]s, O(1) insert/remove/lookup) and a plain
//! [`Pool`] with a free list for tree nodes. Both are flat `Vec`s, as in Box2D's
//! `b2DynamicTree`; this is the "equal-size block allocator" of [sources: block-alloc].

use crate::{Error, Handle, Result};
use std::sync::atomic::{AtomicU32, Ordering};

static NEXT_TAG: AtomicU32 = AtomicU32::new(1);

fn fresh_tag() -> u32 {
    NEXT_TAG.fetch_add(1, Ordering::Relaxed)
}

const NONE: u32 = u32::MAX;

/// The number of slot indices an arena may use: `0..NONE`. Tests lower it per
/// thread to reach the limit cheaply (`arena::tests::capacity`).
#[cfg(not(test))]
#[inline]
fn slot_limit() -> usize {
    NONE as usize
}

#[cfg(test)]
thread_local! {
    static TEST_SLOT_LIMIT: std::cell::Cell<usize> = const { std::cell::Cell::new(NONE as usize) };
}

#[cfg(test)]
fn slot_limit() -> usize {
    TEST_SLOT_LIMIT.with(|c| c.get())
}

#[derive(Clone, Debug)]
enum Entry<V> {
    Occupied(V),
    Vacant { next_free: u32 },
}

#[derive(Clone, Debug)]
struct Slot<V> {
    generation: u32,
    entry: Entry<V>,
}

/// Generational slot arena: values addressed by [`Handle`], with a free list.
/// `insert`, `remove`, `get` are O(1).
#[derive(Clone, Debug)]
pub struct Arena<V> {
    tag: u32,
    slots: Vec<Slot<V>>,
    free_head: u32,
    len: usize,
}

impl<V> Default for Arena<V> {
    fn default() -> Self {
        Self::new()
    }
}

impl<V> Arena<V> {
    /// An empty arena with a fresh tag.
    pub fn new() -> Self {
        Arena {
            tag: fresh_tag(),
            slots: Vec::new(),
            free_head: NONE,
            len: 0,
        }
    }

    /// Number of live values.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when no value is stored.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of slots (live or free): the capacity in use (slot indices are
    /// below it).
    pub fn slot_count(&self) -> usize {
        self.slots.len()
    }

    /// The handle the next `insert` will return (lets a caller store the handle
    /// inside structures before inserting).
    pub fn next_handle(&self) -> Handle {
        if self.free_head != NONE {
            let s = &self.slots[self.free_head as usize];
            Handle {
                tag: self.tag,
                index: self.free_head,
                generation: s.generation,
            }
        } else {
            Handle {
                tag: self.tag,
                index: self.slots.len() as u32,
                generation: 0,
            }
        }
    }

    /// Fails with [`Error::CapacityExceeded`] when the next `insert` would: no
    /// free slot and all 2^32 - 1 slot indices in use (`u32::MAX` marks the end of
    /// the free list). Indices call it before changing anything, so a full index
    /// is left exactly as it was. O(1).
    pub fn check_room(&self) -> Result<()> {
        let limit = slot_limit();
        if self.free_head == NONE && self.slots.len() >= limit {
            return Err(Error::CapacityExceeded {
                what: "object slots",
                limit,
            });
        }
        Ok(())
    }

    /// Stores `value` and returns its handle, or fails with
    /// [`Error::CapacityExceeded`] (see [`Arena::check_room`]), storing nothing.
    /// O(1) amortized.
    pub fn insert(&mut self, value: V) -> Result<Handle> {
        self.check_room()?;
        let h = self.next_handle();
        if self.free_head != NONE {
            let slot = &mut self.slots[self.free_head as usize];
            let Entry::Vacant { next_free } = slot.entry else {
                unreachable!("free list points at an occupied slot")
            };
            self.free_head = next_free;
            slot.entry = Entry::Occupied(value);
        } else {
            self.slots.push(Slot {
                generation: 0,
                entry: Entry::Occupied(value),
            });
        }
        self.len += 1;
        Ok(h)
    }

    fn slot_of(&self, h: Handle) -> Result<usize> {
        if h.tag != self.tag {
            return Err(Error::StaleHandle);
        }
        match self.slots.get(h.index as usize) {
            Some(s) if s.generation == h.generation && matches!(s.entry, Entry::Occupied(_)) => {
                Ok(h.index as usize)
            }
            _ => Err(Error::StaleHandle),
        }
    }

    /// True if `h` names a live value of this arena.
    pub fn contains(&self, h: Handle) -> bool {
        self.slot_of(h).is_ok()
    }

    /// The value of `h`.
    pub fn get(&self, h: Handle) -> Result<&V> {
        let i = self.slot_of(h)?;
        match &self.slots[i].entry {
            Entry::Occupied(v) => Ok(v),
            Entry::Vacant { .. } => unreachable!(),
        }
    }

    /// The value of `h`, mutably.
    pub fn get_mut(&mut self, h: Handle) -> Result<&mut V> {
        let i = self.slot_of(h)?;
        match &mut self.slots[i].entry {
            Entry::Occupied(v) => Ok(v),
            Entry::Vacant { .. } => unreachable!(),
        }
    }

    /// Starts loading `h`'s slot into the caches, for a [`Arena::get`] of it
    /// that will likely follow (a search's answer, which its caller looks
    /// up): the slot's first line and the next slot's, so that a slot
    /// straddling two lines comes whole. Only a hint: it reads no slot, and
    /// a stale or foreign handle is harmless. O(1).
    #[inline(always)]
    pub fn prefetch(&self, h: Handle) {
        let i = h.index as usize;
        for s in self.slots.get(i..).unwrap_or(&[]).iter().take(2) {
            crate::prefetch::prefetch(s);
        }
    }

    /// The live value in slot `index` with its current handle, or `None` for a
    /// free or out-of-range slot. O(1). For structures that link their values by
    /// slot number (intrusive lists) instead of by full handle.
    #[inline]
    pub fn get_by_index(&self, index: u32) -> Option<(Handle, &V)> {
        let s = self.slots.get(index as usize)?;
        match &s.entry {
            Entry::Occupied(v) => Some((
                Handle {
                    tag: self.tag,
                    index,
                    generation: s.generation,
                },
                v,
            )),
            Entry::Vacant { .. } => None,
        }
    }

    /// The live value in slot `index`, mutably, or `None` for a free or
    /// out-of-range slot. O(1).
    #[inline]
    pub fn get_by_index_mut(&mut self, index: u32) -> Option<&mut V> {
        match &mut self.slots.get_mut(index as usize)?.entry {
            Entry::Occupied(v) => Some(v),
            Entry::Vacant { .. } => None,
        }
    }

    /// Removes and returns the value of `h`; the slot's generation advances so `h`
    /// becomes stale. A slot whose generation would wrap is retired, never reused.
    pub fn remove(&mut self, h: Handle) -> Result<V> {
        let i = self.slot_of(h)?;
        let slot = &mut self.slots[i];
        slot.generation = slot.generation.wrapping_add(1);
        let retire = slot.generation == 0;
        let next_free = if retire { NONE } else { self.free_head };
        let old = std::mem::replace(&mut slot.entry, Entry::Vacant { next_free });
        if !retire {
            self.free_head = i as u32;
        }
        self.len -= 1;
        match old {
            Entry::Occupied(v) => Ok(v),
            Entry::Vacant { .. } => unreachable!(),
        }
    }

    /// Removes everything and frees the memory; every earlier handle becomes stale
    /// (the arena draws a new tag).
    pub fn clear(&mut self) {
        *self = Arena::new();
    }

    /// Live `(handle, value)` pairs in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (Handle, &V)> + '_ {
        let tag = self.tag;
        self.slots
            .iter()
            .enumerate()
            .filter_map(move |(i, s)| match &s.entry {
                Entry::Occupied(v) => Some((
                    Handle {
                        tag,
                        index: i as u32,
                        generation: s.generation,
                    },
                    v,
                )),
                Entry::Vacant { .. } => None,
            })
    }

    /// Live `(handle, value)` pairs in slot order, the values mutably.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (Handle, &mut V)> + '_ {
        let tag = self.tag;
        self.slots
            .iter_mut()
            .enumerate()
            .filter_map(move |(i, s)| match &mut s.entry {
                Entry::Occupied(v) => Some((
                    Handle {
                        tag,
                        index: i as u32,
                        generation: s.generation,
                    },
                    v,
                )),
                Entry::Vacant { .. } => None,
            })
    }

    /// Bytes of heap memory held (capacity, not just length).
    pub fn heap_bytes(&self) -> usize {
        self.slots.capacity() * std::mem::size_of::<Slot<V>>()
    }

    /// Checks the free list and the live count.
    pub fn validate(&self) -> Result<()> {
        let live = self
            .slots
            .iter()
            .filter(|s| matches!(s.entry, Entry::Occupied(_)))
            .count();
        if live != self.len {
            return Err(Error::Invalid(format!(
                "arena counts {} live slots but len is {}",
                live, self.len
            )));
        }
        let mut seen = 0usize;
        let mut cur = self.free_head;
        while cur != NONE {
            let Some(s) = self.slots.get(cur as usize) else {
                return Err(Error::Invalid("free list leaves the arena".into()));
            };
            let Entry::Vacant { next_free } = s.entry else {
                return Err(Error::Invalid("free list reaches a live slot".into()));
            };
            seen += 1;
            if seen > self.slots.len() {
                return Err(Error::Invalid("free list has a cycle".into()));
            }
            cur = next_free;
        }
        Ok(())
    }
}

/// A pool of nodes addressed by `u32`, with a free list: the arena for tree nodes.
/// Freed slots are reused by later allocations; nothing is allocated per node once
/// the pool has grown.
#[derive(Clone, Debug)]
pub struct Pool<N> {
    nodes: Vec<N>,
    free: Vec<u32>,
}

impl<N> Default for Pool<N> {
    fn default() -> Self {
        Pool {
            nodes: Vec::new(),
            free: Vec::new(),
        }
    }
}

impl<N> Pool<N> {
    /// Stores `node`, reusing a freed slot when there is one. O(1) amortized.
    pub fn alloc(&mut self, node: N) -> u32 {
        if let Some(i) = self.free.pop() {
            self.nodes[i as usize] = node;
            i
        } else {
            self.nodes.push(node);
            (self.nodes.len() - 1) as u32
        }
    }
    /// Returns slot `i` to the free list. The caller must not use `i` again until
    /// `alloc` hands it out.
    pub fn free(&mut self, i: u32) {
        debug_assert!((i as usize) < self.nodes.len());
        self.free.push(i);
    }
    /// Live node count.
    pub fn len(&self) -> usize {
        self.nodes.len() - self.free.len()
    }
    /// True when no node is live.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Drops every node and frees the memory.
    pub fn clear(&mut self) {
        *self = Pool::default();
    }
    /// The free slots (for validation).
    pub fn free_slots(&self) -> &[u32] {
        &self.free
    }
    /// Total slots, live or free.
    pub fn slot_count(&self) -> usize {
        self.nodes.len()
    }
    /// Bytes of heap memory held.
    pub fn heap_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<N>() + self.free.capacity() * 4
    }
}

impl<N> std::ops::Index<u32> for Pool<N> {
    type Output = N;
    fn index(&self, i: u32) -> &N {
        &self.nodes[i as usize]
    }
}

impl<N> std::ops::IndexMut<u32> for Pool<N> {
    fn index_mut(&mut self, i: u32) -> &mut N {
        &mut self.nodes[i as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::LooseKdConfig;
    use crate::broad::SpatialIndexExt;

    #[test]
    fn stale_and_foreign_handles_are_rejected() {
        let mut a = Arena::new();
        let mut b: Arena<i32> = Arena::new();
        let h1 = a.insert(1).unwrap();
        assert_eq!(b.get(h1), Err(Error::StaleHandle));
        assert_eq!(a.remove(h1), Ok(1));
        assert_eq!(a.get(h1), Err(Error::StaleHandle));
        let h2 = a.insert(2).unwrap();
        assert_eq!(h2.index(), h1.index(), "slot is reused");
        assert_eq!(a.get(h1), Err(Error::StaleHandle));
        assert_eq!(a.get(h2), Ok(&2));
        a.clear();
        assert_eq!(a.get(h2), Err(Error::StaleHandle));
        let h3 = a.insert(3).unwrap();
        assert_eq!(h3.index(), 0);
        assert_eq!(a.get(h2), Err(Error::StaleHandle));
        a.validate().unwrap();
        b.insert(5).unwrap();
        b.validate().unwrap();
    }

    /// `prefetch` is only a hint: the last slot (no next one), a freed
    /// slot, a foreign handle and one past the end change nothing and panic
    /// nowhere.
    #[test]
    fn prefetch_is_harmless_for_any_handle() {
        let mut a = Arena::new();
        let h = [a.insert(1).unwrap(), a.insert(2).unwrap()];
        let mut other: Arena<i32> = Arena::new();
        for _ in 0..5 {
            other.insert(0).unwrap();
        }
        let far = other.insert(9).unwrap();
        a.remove(h[0]).unwrap();
        for x in [h[0], h[1], far] {
            a.prefetch(x);
        }
        Arena::<i32>::new().prefetch(h[1]);
        assert_eq!((a.len(), a.get(h[1])), (1, Ok(&2)));
        assert_eq!(a.get(h[0]), Err(Error::StaleHandle));
        a.validate().unwrap();
    }

    /// With the slot limit lowered (for this test thread only), the insert past
    /// it fails with `CapacityExceeded` on the arena and on every index, which is
    /// left exactly as it was; a removal makes room again.
    #[test]
    fn capacity() {
        use crate::broad::{
            BruteForce, HashGrid, LinearOctree, LooseKdTree, SpatialIndex, UniformGrid2d,
            UniformGrid3d,
        };
        use crate::geom::{Aabb, Sphere};
        use glam::{vec3, Vec3};

        fn check<I: SpatialIndex<u32>>(mut i: I) {
            let spheres = [
                Sphere::new(vec3(1.0, 2.0, 3.0), 1.0),
                Sphere::new(vec3(2.0, 2.0, 3.0), 0.5),
                Sphere::new(vec3(90.0, 2.0, 3.0), 3.0),
            ];
            let hs: Vec<Handle> = spheres
                .iter()
                .enumerate()
                .map(|(k, s)| i.insert(*s, k as u32).unwrap())
                .collect();
            let snapshot = |i: &I| {
                let mut all = Vec::new();
                i.for_each(&mut |h, s, v| all.push((h, *s, *v)));
                (all, i.pairs(), i.memory_bytes(), i.len())
            };
            let before = snapshot(&i);
            // Far away, huge, tiny: whatever the index would do with it, it must not.
            for s in [
                Sphere::new(Vec3::splat(1e30), 5.0),
                Sphere::new(Vec3::ZERO, 1e20),
                Sphere::new(vec3(1.5, 2.0, 3.0), 0.0),
            ] {
                let full = Error::CapacityExceeded {
                    what: "object slots",
                    limit: 3,
                };
                assert_eq!(i.insert(s, 9), Err(full));
                assert_eq!(snapshot(&i), before);
                i.validate().unwrap();
            }
            assert_eq!(i.remove(hs[1]), Ok(1));
            let h = i.insert(spheres[1], 7).unwrap();
            assert_eq!(h.index(), hs[1].index(), "the freed slot is reused");
            i.validate().unwrap();
        }

        TEST_SLOT_LIMIT.with(|c| c.set(3));
        let mut a = Arena::new();
        for k in 0..3 {
            a.insert(k).unwrap();
        }
        assert!(matches!(a.insert(3), Err(Error::CapacityExceeded { .. })));
        assert_eq!((a.len(), a.slot_count()), (3, 3));
        a.validate().unwrap();
        let world = Aabb::new(Vec3::ZERO, Vec3::splat(100.0));
        check(BruteForce::new());
        check(
            LooseKdTree::with_config(LooseKdConfig {
                density: 0.5,
                ..LooseKdConfig::new(world, 2.0)
            })
            .unwrap(),
        );
        check(LinearOctree::new(world).unwrap());
        check(UniformGrid2d::new(world, 2.0).unwrap());
        check(HashGrid::new(2.0).unwrap());
        check(UniformGrid3d::new(world, 2.0).unwrap());
        TEST_SLOT_LIMIT.with(|c| c.set(NONE as usize));
    }

    #[test]
    fn by_index_access() {
        let mut a = Arena::new();
        let h = a.insert(5).unwrap();
        assert_eq!(a.get_by_index(h.index()), Some((h, &5)));
        *a.get_by_index_mut(h.index()).unwrap() = 6;
        a.remove(h).unwrap();
        assert!(a.get_by_index(h.index()).is_none());
        assert!(a.get_by_index_mut(h.index()).is_none());
        assert!(a.get_by_index(99).is_none());
    }

    #[test]
    fn generation_wrap_retires_slot() {
        let mut a = Arena::new();
        let h = a.insert(0u8).unwrap();
        a.slots[0].generation = u32::MAX;
        let h = Handle {
            generation: u32::MAX,
            ..h
        };
        a.remove(h).unwrap();
        let h2 = a.insert(1).unwrap();
        assert_ne!(h2.index(), 0, "wrapped slot must not be reused");
        a.validate().unwrap();
    }
}
