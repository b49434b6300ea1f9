//! The objects of every node in one array, each node owning a contiguous range
//! (`Node::start .. start + cap`, of which the first `len` are live), laid out in
//! depth-first order of the tree when the array is compacted.
//!
//! Why: the pair walk and the queries visit nodes depth-first and read each
//! node's spheres. With one vector per node those reads jump to a separate heap
//! block per node (a cache miss each, at 100k objects the dominant cost of the
//! W1 pair search); with the ranges in visiting order the walk streams through
//! one array, and the node array itself is renumbered in the same order.
//!
//! Maintenance: a move that keeps its node writes one sphere; a node that runs
//! out of room moves its range to the end of the array with twice the room
//! (amortized O(1)), leaving a dead range behind; when the dead entries outgrow
//! a fraction of the live ones the tree is compacted (`LooseKdTree::compact`):
//! O(objects + nodes), rare, and it restores the depth-first order.
//!
//! Chunk bounds: every [`CHUNK`] consecutive positions share one box that
//! contains the box of every sphere written there through [`Store::set`] since
//! the last compaction (writes only grow it; compaction rebuilds it exact). A
//! move that keeps its node writes the sphere alone (`Store::sphere` directly)
//! and marks the node `loose` instead: keeping the bound there cost W1 one more
//! cache miss per move (~+40% update time), and queries scan a loose node
//! without its chunk bounds until the next compaction or relocation. Queries test a chunk's
//! box before its spheres: a W4 profile showed the queries spend their time
//! scanning nodes of ~100 objects one sphere at a time (density 0.15 stops a
//! sphere of radius `r` in a cell ~27·r wide), and most chunks of such a node
//! are far from a small query. A box may cover objects of two neighbouring
//! ranges (ranges are not aligned to chunks): it is looser, never wrong.

use crate::broad::Filter;
use crate::geom::{Aabb, Sphere};
use crate::Handle;
use glam::Vec3;

/// Positions per chunk bound: 8 spheres are two cache lines, so a pruned chunk
/// saves two lines and eight tests for one 24-byte box.
pub(super) const CHUNK: usize = 8;

/// Spheres, and handle, filter and payload, by position. Positions in dead
/// ranges or past a node's `len` hold an old sphere and `None`. The filter is
/// kept with the handle and payload, not with the sphere: only reported
/// objects read it (the pair search's and queries' inner loops read spheres
/// only), so it costs them nothing.
#[derive(Clone, Debug)]
pub(super) struct Store<T> {
    /// Written through [`Store::set`], which keeps `chunk`, except by in-place
    /// moves, which mark their node `loose` instead.
    pub sphere: Vec<Sphere>,
    /// `chunk[p / CHUNK]` contains `sphere[p].aabb()` for every live position
    /// `p` of a node that is not `loose`.
    pub chunk: Vec<Aabb>,
    pub entry: Vec<Option<(Handle, Filter, T)>>,
    /// Positions in ranges no node owns any more (freed nodes, moved ranges).
    pub dead: usize,
    /// Ranges moved to the end and nodes created since the last compaction: each
    /// is a node out of depth-first order.
    pub disorder: usize,
}

impl<T> Default for Store<T> {
    fn default() -> Self {
        Store {
            sphere: Vec::new(),
            chunk: Vec::new(),
            entry: Vec::new(),
            dead: 0,
            disorder: 0,
        }
    }
}

impl<T> Store<T> {
    /// Positions in use or reserved (live, spare room and dead).
    #[inline]
    pub fn len(&self) -> usize {
        self.sphere.len()
    }

    /// Appends `n` empty positions, returning the first.
    pub fn grow(&mut self, n: usize) -> u32 {
        let at = self.sphere.len();
        let filler = Sphere::new(glam::Vec3::ZERO, 0.0);
        self.sphere.resize(at + n, filler);
        self.entry.resize_with(at + n, || None);
        self.chunk.resize((at + n).div_ceil(CHUNK), Aabb::EMPTY);
        at as u32
    }

    /// An empty store with the capacity of this one.
    pub fn empty_like(&self) -> Self {
        Store {
            sphere: Vec::with_capacity(self.sphere.capacity()),
            chunk: Vec::with_capacity(self.chunk.capacity()),
            entry: Vec::with_capacity(self.entry.capacity()),
            dead: 0,
            disorder: 0,
        }
    }

    /// Writes the sphere at position `p` and grows its chunk's bound. O(1).
    #[inline]
    pub fn set(&mut self, p: usize, s: Sphere) {
        self.sphere[p] = s;
        let c = &mut self.chunk[p / CHUNK];
        let r = Vec3::splat(s.radius);
        c.min = c.min.min(s.center - r);
        c.max = c.max.max(s.center + r);
    }

    /// Handle and payload at live position `p`.
    #[inline]
    pub fn at(&self, p: usize) -> (Handle, &T) {
        let (h, _, v) = self.entry[p].as_ref().expect("live position");
        (*h, v)
    }

    /// Handle, filter and payload at live position `p`.
    #[inline]
    pub fn full(&self, p: usize) -> (Handle, Filter, &T) {
        let (h, f, v) = self.entry[p].as_ref().expect("live position");
        (*h, *f, v)
    }

    /// Bytes of heap memory held.
    pub fn heap_bytes(&self) -> usize {
        self.sphere.capacity() * std::mem::size_of::<Sphere>()
            + self.chunk.capacity() * std::mem::size_of::<Aabb>()
            + self.entry.capacity() * std::mem::size_of::<Option<(Handle, Filter, T)>>()
    }
}

/// Room given to a range of `len` live objects when the array is compacted:
/// some spare so that objects moving in do not immediately relocate the range.
#[inline]
pub(super) fn room_for(len: u32) -> u32 {
    len + len / 2 + 1
}
