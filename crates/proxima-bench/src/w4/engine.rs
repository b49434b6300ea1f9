//! One object-safe interface over every structure W4 queries: Proxima's indices
//! (through [`Proxima`], generic over [`SpatialIndex<u32>`]) and the peers.
//!
//! Every answer is exact and closed: a peer's own traversal yields candidates
//! (AABB, ray or point-radius hits), and the same tests of `proxima::geom::overlap`
//! (through [`Selection::selects`]) filter them, so hit counts are comparable.

use super::queries::{Batches, QueryKind};
use proxima::broad::{par_query_counts, Selection, SpatialIndex};
use proxima::geom::Sphere;
use rayon::prelude::*;
use std::ops::ControlFlow;

/// A structure built once over the set, then queried.
pub trait Engine: Sync {
    /// Hits of one query of `kind` (query `i` of that batch), or `None` when the
    /// structure has no such query.
    fn count(&self, batches: &Batches, kind: QueryKind, i: usize) -> Option<usize>;

    /// Whether the structure answers queries of `kind`.
    fn supports(&self, kind: QueryKind) -> bool;

    /// Hits of every query of a batch: sequential on the calling thread, or over
    /// rayon's current pool when `parallel`.
    fn counts(&self, batches: &Batches, kind: QueryKind, parallel: bool) -> Option<Vec<usize>> {
        if !self.supports(kind) {
            return None;
        }
        let one = |i| self.count(batches, kind, i).expect("supported kind");
        let n = batches.len(kind);
        Some(if parallel {
            (0..n).into_par_iter().map(one).collect()
        } else {
            (0..n).map(one).collect()
        })
    }

    /// Bytes held by the structure, its copy of the spheres included (an estimate
    /// where the crate does not say).
    fn memory_bytes(&self) -> usize;
}

/// Hits of `q` in `index` through the generic `visit`.
#[inline]
pub fn visit_count<I: SpatialIndex<u32>, Q: Selection + ?Sized>(index: &I, q: &Q) -> usize {
    let mut n = 0usize;
    let _ = index.visit(q, |_, _, _| {
        n += 1;
        ControlFlow::Continue(())
    });
    n
}

/// Any Proxima index: built by inserting sphere `i` with payload `i`, queried with
/// `SpatialIndex::visit` (sequential) or `broad::par_query_counts` (parallel).
pub struct Proxima<I>(pub I);

impl<I: SpatialIndex<u32>> Proxima<I> {
    /// Inserts every sphere into the empty `index`.
    pub fn build(mut index: I, spheres: &[Sphere]) -> Self {
        for (i, s) in spheres.iter().enumerate() {
            index
                .insert(*s, i as u32)
                .unwrap_or_else(|e| panic!("insert of sphere {i} {s:?} failed: {e}"));
        }
        Proxima(index)
    }
}

impl<I: SpatialIndex<u32>> Engine for Proxima<I> {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        Some(match kind {
            QueryKind::Sphere => visit_count(&self.0, &b.spheres[i]),
            QueryKind::Aabb => visit_count(&self.0, &b.boxes[i]),
            QueryKind::Ray => visit_count(&self.0, &b.rays[i]),
            QueryKind::Frustum => visit_count(&self.0, &b.frusta[i]),
        })
    }

    fn supports(&self, _: QueryKind) -> bool {
        true
    }

    fn counts(&self, b: &Batches, kind: QueryKind, parallel: bool) -> Option<Vec<usize>> {
        fn run<I: SpatialIndex<u32>, Q: Selection + Sync>(
            index: &I,
            qs: &[Q],
            parallel: bool,
        ) -> Vec<usize> {
            if parallel {
                par_query_counts(index, qs).expect("valid queries")
            } else {
                qs.iter().map(|q| visit_count(index, q)).collect()
            }
        }
        Some(match kind {
            QueryKind::Sphere => run(&self.0, &b.spheres, parallel),
            QueryKind::Aabb => run(&self.0, &b.boxes, parallel),
            QueryKind::Ray => run(&self.0, &b.rays, parallel),
            QueryKind::Frustum => run(&self.0, &b.frusta, parallel),
        })
    }

    fn memory_bytes(&self) -> usize {
        self.0.memory_bytes()
    }
}
