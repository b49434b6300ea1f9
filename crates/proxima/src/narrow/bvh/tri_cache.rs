//! Per-query caches indexed by position (triangles in leaf order, tree nodes):
//! the prepared triangles of both meshes and the lazily moved volumes.
//!
//! A collision query fills an entry on first use only. Entries are valid for one
//! query (they depend on the pose), so each query starts a new generation instead
//! of clearing the array: O(1) per query however large the mesh, no allocation once
//! warmed up (clearing a 68k-node volume cache cost ~100 µs per query).

use crate::narrow::PreparedTriangle;

/// Entries of type `T`, each valid iff stamped with the current generation.
#[derive(Clone, Debug)]
pub(crate) struct QueryCache<T> {
    /// `stamp[k] == generation` iff `data[k]` was filled in this query.
    stamp: Vec<u32>,
    data: Vec<T>,
    generation: u32,
}

/// Prepared triangles by leaf-order position.
pub(crate) type TriangleCache = QueryCache<PreparedTriangle>;

impl<T> Default for QueryCache<T> {
    fn default() -> Self {
        QueryCache {
            stamp: Vec::new(),
            data: Vec::new(),
            generation: 0,
        }
    }
}

impl<T: Copy> QueryCache<T> {
    /// Starts a query over `n` entries: every entry becomes stale. `fill` only
    /// initializes new storage (never read before being overwritten).
    pub(crate) fn begin(&mut self, n: usize, fill: T) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.clear();
            self.generation = 1;
        }
        // Grow only: a collider that alternates between meshes of different
        // sizes (a collision world's pairs) keeps its storage. Entries past `n`
        // are never read in this query; new ones carry stamp 0, never current.
        if self.stamp.len() < n {
            self.stamp.resize(n, 0);
            self.data.resize(n, fill);
        }
    }

    /// Whether entry `k` was filled in this query.
    #[inline]
    pub(crate) fn is_set(&self, k: usize) -> bool {
        self.stamp[k] == self.generation
    }

    /// Sets entry `k` for this query and returns it.
    #[inline]
    pub(crate) fn put(&mut self, k: usize, value: T) -> &T {
        self.stamp[k] = self.generation;
        self.data[k] = value;
        &self.data[k]
    }

    /// Entry `k`, which must be set in this query ([`QueryCache::is_set`]); a
    /// stale entry otherwise (never undefined: every entry is initialized).
    #[inline]
    pub(crate) fn value(&self, k: usize) -> &T {
        debug_assert!(self.is_set(k));
        &self.data[k]
    }

    /// The entry at `k`, from `make()` on first use in this query.
    #[inline]
    pub(crate) fn get(&mut self, k: usize, make: impl FnOnce() -> T) -> &T {
        if self.stamp[k] != self.generation {
            self.stamp[k] = self.generation;
            self.data[k] = make();
        }
        &self.data[k]
    }
}
