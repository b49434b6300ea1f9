//! Parallel pair finding and batch queries (design §6), behind the `parallel`
//! feature. Work runs on rayon's current pool: the global one, or whatever pool the
//! caller `install`s (the benchmarks compare 1 and 2 threads that way).
//!
//! Results are combined rayon-style (`init` / `fold` / `reduce`), so each thread
//! accumulates into its own value and nothing is shared while pairs are found.

use super::{Handle, SpatialIndex};
use rayon::prelude::*;

/// Pair finding split across rayon's threads.
///
/// Implementors report exactly the pairs of [`SpatialIndex::for_each_pair`] — each
/// overlapping pair once — but from several threads and in no particular order.
pub trait ParallelPairs<T: Sync>: SpatialIndex<T> {
    /// Folds every overlapping pair into per-task accumulators made by `init`, then
    /// merges them with `reduce`. Cost: the sequential pair search divided over the
    /// pool's threads, plus one `reduce` per task.
    fn par_fold_pairs<A, I, F, R>(&self, init: I, fold: F, reduce: R) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, Handle, &T, Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send;

    /// Number of overlapping pairs, counted in parallel.
    fn par_count_pairs(&self) -> u64 {
        self.par_fold_pairs(|| 0u64, |n, _, _, _, _| n + 1, |a, b| a + b)
    }

    /// Every overlapping pair once, as `(smaller handle, larger handle)`, sorted.
    fn par_pairs(&self) -> Vec<(Handle, Handle)> {
        let mut out = self.par_fold_pairs(
            Vec::new,
            |mut v, a, _, b, _| {
                v.push(if a < b { (a, b) } else { (b, a) });
                v
            },
            |mut a, mut b| {
                a.append(&mut b);
                a
            },
        );
        out.par_sort_unstable();
        out
    }
}
