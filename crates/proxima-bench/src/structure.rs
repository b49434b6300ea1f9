//! One object-safe interface over everything the benchmarks run: Proxima's indices
//! (through [`Indexed`], over the library's [`AnyIndex`]) and the peers.

use proxima::broad::{AnyIndex, Filter, ParallelPairs, SpatialIndex};
use proxima::geom::Sphere;
use proxima::Handle;

/// A broad-phase structure as the workloads drive it: object `i` is sphere `i` of
/// the workload, inserted once, moved every frame, and all overlapping pairs
/// counted every frame.
pub trait Structure {
    /// Inserts every sphere (object `i` = `spheres[i]`) into the empty structure.
    fn build(&mut self, spheres: &[Sphere]);

    /// Gives object `i` the collision filter `filters[i]` (after `build`; same
    /// length), the way the structure's users apply filters: from then on
    /// [`Structure::count_pairs`] counts only pairs whose filters interact.
    fn set_filters(&mut self, filters: &[Filter]);

    /// Moves every object to its new sphere (same length and order as `build`).
    fn update(&mut self, spheres: &[Sphere]);

    /// Number of unordered pairs of objects whose spheres overlap (closed), each
    /// pair counted once.
    fn count_pairs(&mut self) -> u64;

    /// As [`Structure::count_pairs`], split over the threads of `pool` by the
    /// structures that have a parallel search (`--threads K`). The default
    /// counts sequentially on the calling thread.
    fn count_pairs_par(&mut self, pool: &rayon::ThreadPool) -> u64 {
        let _ = pool;
        self.count_pairs()
    }

    /// Bytes the structure holds, its copy of the spheres included.
    fn memory_bytes(&self) -> usize;
}

/// Drives any Proxima index through [`AnyIndex<u32>`]: the payload of object
/// `i` is `i`, and the handles are kept in insertion order. Pairs are counted
/// with `AnyIndex`'s statically dispatched search, in parallel with its
/// [`ParallelPairs`] (sequential for the indices without a parallel search).
pub struct Indexed {
    index: AnyIndex<u32>,
    handles: Vec<Handle>,
}

impl Indexed {
    /// Wraps an empty index.
    pub fn new(index: AnyIndex<u32>) -> Self {
        Indexed {
            index,
            handles: Vec::new(),
        }
    }

    /// The wrapped index.
    pub fn index(&self) -> &AnyIndex<u32> {
        &self.index
    }
}

impl Structure for Indexed {
    fn build(&mut self, spheres: &[Sphere]) {
        self.handles.reserve(spheres.len());
        for (i, s) in spheres.iter().enumerate() {
            let h = self
                .index
                .insert(*s, i as u32)
                .unwrap_or_else(|e| panic!("insert of sphere {i} {s:?} failed: {e}"));
            self.handles.push(h);
        }
    }

    /// `set_filter` per object: the index prunes its pair search by them.
    fn set_filters(&mut self, filters: &[Filter]) {
        for (&h, &f) in self.handles.iter().zip(filters) {
            self.index
                .set_filter(h, f)
                .unwrap_or_else(|e| panic!("set_filter failed: {e}"));
        }
    }

    fn update(&mut self, spheres: &[Sphere]) {
        let moves = self.handles.iter().copied().zip(spheres.iter().copied());
        self.index
            .update_many(moves)
            .unwrap_or_else(|e| panic!("update failed: {e}"));
    }

    fn count_pairs(&mut self) -> u64 {
        self.index.count_pairs()
    }

    fn count_pairs_par(&mut self, pool: &rayon::ThreadPool) -> u64 {
        let index = &self.index;
        pool.install(|| index.par_count_pairs())
    }

    fn memory_bytes(&self) -> usize {
        // The handle list is the benchmark's, not the index's: not counted.
        self.index.memory_bytes()
    }
}
