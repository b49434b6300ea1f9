//! One object-safe interface over everything the benchmarks run: Proxima's indices
//! (through [`Indexed`], generic over [`SpatialIndex<u32>`]) and the peers.

use proxima::broad::{Handle, ParallelPairs, SpatialIndex};
use proxima::geom::Sphere;
use std::ops::ControlFlow;

/// A broad-phase structure as the workloads drive it: object `i` is sphere `i` of
/// the workload, inserted once, moved every frame, and all overlapping pairs
/// counted every frame.
pub trait Structure {
    /// Inserts every sphere (object `i` = `spheres[i]`) into the empty structure.
    fn build(&mut self, spheres: &[Sphere]);

    /// Moves every object to its new sphere (same length and order as `build`).
    fn update(&mut self, spheres: &[Sphere]);

    /// Number of unordered pairs of objects whose spheres overlap (closed), each
    /// pair counted once.
    fn count_pairs(&mut self) -> u64;

    /// As [`Structure::count_pairs`], split over the threads of `pool` by the
    /// structures that implement [`ParallelPairs`] (`--threads K`). The default
    /// counts sequentially on the calling thread.
    fn count_pairs_par(&mut self, pool: &rayon::ThreadPool) -> u64 {
        let _ = pool;
        self.count_pairs()
    }

    /// Bytes the structure holds, its copy of the spheres included.
    fn memory_bytes(&self) -> usize;
}

/// Drives any Proxima index through [`SpatialIndex<u32>`]: the payload of object
/// `i` is `i`, and the handles are kept in insertion order.
pub struct Indexed<I> {
    index: I,
    handles: Vec<Handle>,
}

impl<I: SpatialIndex<u32>> Indexed<I> {
    /// Wraps an empty index.
    pub fn new(index: I) -> Self {
        Indexed {
            index,
            handles: Vec::new(),
        }
    }

    /// The wrapped index.
    pub fn index(&self) -> &I {
        &self.index
    }
}

impl<I: SpatialIndex<u32>> Structure for Indexed<I> {
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

    fn update(&mut self, spheres: &[Sphere]) {
        for (h, s) in self.handles.iter().zip(spheres) {
            self.index
                .update(*h, *s)
                .unwrap_or_else(|e| panic!("update to {s:?} failed: {e}"));
        }
    }

    fn count_pairs(&mut self) -> u64 {
        let mut n = 0u64;
        let _ = self.index.for_each_pair(|_, _, _, _| {
            n += 1;
            ControlFlow::Continue(())
        });
        n
    }

    fn memory_bytes(&self) -> usize {
        // The handle list is the benchmark's, not the index's: not counted.
        self.index.memory_bytes()
    }
}

/// [`Indexed`] for an index with parallel pair finding: `count_pairs_par` runs
/// `par_count_pairs` inside the given pool.
pub struct IndexedPar<I>(pub Indexed<I>);

impl<I: ParallelPairs<u32>> Structure for IndexedPar<I> {
    fn build(&mut self, spheres: &[Sphere]) {
        self.0.build(spheres)
    }

    fn update(&mut self, spheres: &[Sphere]) {
        self.0.update(spheres)
    }

    fn count_pairs(&mut self) -> u64 {
        self.0.count_pairs()
    }

    fn count_pairs_par(&mut self, pool: &rayon::ThreadPool) -> u64 {
        let index = &self.0.index;
        pool.install(|| index.par_count_pairs())
    }

    fn memory_bytes(&self) -> usize {
        self.0.memory_bytes()
    }
}
