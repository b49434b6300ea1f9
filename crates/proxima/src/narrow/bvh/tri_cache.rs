//! A per-query cache of [`PreparedTriangle`]s, indexed by leaf-order position.
//!
//! A collision query tests each reached triangle against several others; the cache
//! prepares it on first use only. Entries are valid for one query (the moving
//! mesh's corners depend on the pose), so each query starts a new generation
//! instead of clearing the array: O(1) per query, no allocation once warmed up.

use crate::narrow::PreparedTriangle;
use glam::Vec3;

#[derive(Clone, Debug, Default)]
pub(crate) struct TriangleCache {
    /// `stamp[k] == generation` iff `data[k]` was prepared in this query.
    stamp: Vec<u32>,
    data: Vec<PreparedTriangle>,
    generation: u32,
}

impl TriangleCache {
    /// Starts a query over `n` triangles: every entry becomes stale.
    pub(crate) fn begin(&mut self, n: usize) {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 || self.stamp.len() != n {
            self.stamp.clear();
            self.stamp.resize(n, 0);
            self.data.resize(n, PreparedTriangle::default());
            self.generation = 1;
        }
    }

    /// The prepared triangle at position `k`, from `corners()` on first use.
    #[inline]
    pub(crate) fn get(
        &mut self,
        k: usize,
        corners: impl FnOnce() -> [Vec3; 3],
    ) -> &PreparedTriangle {
        if self.stamp[k] != self.generation {
            self.stamp[k] = self.generation;
            self.data[k] = PreparedTriangle::new(corners());
        }
        &self.data[k]
    }
}
