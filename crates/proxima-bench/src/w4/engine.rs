//! One object-safe interface over every structure W4 queries: Proxima's indices
//! (through [`Proxima`], over the library's [`AnyIndex<u32>`]) and the peers.
//!
//! Every answer is exact and closed: a peer's own traversal yields candidates
//! (AABB, ray or point-radius hits), and the same tests of `proxima::geom::overlap`
//! (through `Selection::selects`) filter them, so hit counts are comparable.

use super::queries::{Batches, QueryKind};
use proxima::broad::{par_query_counts, AnyIndex, Query, SpatialIndex};
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

/// Hits of `q` in `index` through `AnyIndex::for_each_in` (the index's walk for
/// the query's shape, the counting closure inlined).
#[inline]
pub fn visit_count(index: &AnyIndex<u32>, q: impl Into<Query>) -> usize {
    let mut n = 0usize;
    let _ = index.for_each_in(q, |_, _, _| {
        n += 1;
        ControlFlow::Continue(())
    });
    n
}

/// Any Proxima index: built by inserting sphere `i` with payload `i`, queried with
/// `AnyIndex::for_each_in` (sequential) or `broad::par_query_counts` (parallel).
pub struct Proxima(pub AnyIndex<u32>);

impl Proxima {
    /// Inserts every sphere into the empty `index`, in the given order (sphere
    /// `i` always gets payload `i`).
    pub fn build(mut index: AnyIndex<u32>, spheres: &[Sphere], order: &[u32]) -> Self {
        for &i in order {
            let s = &spheres[i as usize];
            index
                .insert(*s, i)
                .unwrap_or_else(|e| panic!("insert of sphere {i} {s:?} failed: {e}"));
        }
        Proxima(index)
    }
}

/// The sphere indices sorted by the Morton (Z-order) code of their centres
/// ([`proxima::broad::morton_order`]): the order a static set is bulk-loaded
/// into an incremental index, so that nodes and object lists created one after
/// the other are neighbours in space as well as in memory (the peers' bulk
/// builds sort spatially too).
pub fn morton_order(spheres: &[Sphere]) -> Vec<u32> {
    let centres: Vec<_> = spheres.iter().map(|s| s.center).collect();
    proxima::broad::morton_order(&centres)
}

impl Engine for Proxima {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        Some(match kind {
            QueryKind::Sphere => visit_count(&self.0, b.spheres[i]),
            QueryKind::Aabb => visit_count(&self.0, b.boxes[i]),
            QueryKind::Ray => visit_count(&self.0, b.rays[i]),
            QueryKind::Frustum => visit_count(&self.0, b.frusta[i]),
        })
    }

    fn supports(&self, _: QueryKind) -> bool {
        true
    }

    fn counts(&self, b: &Batches, kind: QueryKind, parallel: bool) -> Option<Vec<usize>> {
        fn run<Q: Into<Query> + Copy + Sync>(
            index: &AnyIndex<u32>,
            qs: &[Q],
            parallel: bool,
        ) -> Vec<usize> {
            if parallel {
                par_query_counts(index, qs, None).expect("valid queries")
            } else {
                qs.iter().map(|&q| visit_count(index, q)).collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use proxima_harness::workloads::{Kind, Workload};

    #[test]
    fn morton_order_is_a_permutation_that_keeps_neighbours_close() {
        let w = Workload::new(Kind::W1, 4000, 3);
        let order = morton_order(&w.spheres);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..4000).collect::<Vec<u32>>());
        // Consecutive spheres are much closer in Morton order than in input order.
        let step = |o: &[u32]| -> f32 {
            o.windows(2)
                .map(|p| {
                    w.spheres[p[0] as usize]
                        .center
                        .distance(w.spheres[p[1] as usize].center)
                })
                .sum()
        };
        let input: Vec<u32> = (0..4000).collect();
        assert!(step(&order) * 4.0 < step(&input));
    }
}
