//! Parallel pair finding and batch queries [sources: parallel], behind the `parallel`
//! feature. Work runs on rayon's current pool: the global one, or whatever pool the
//! caller `install`s (the benchmarks compare 1 and 2 threads that way).
//!
//! Results are combined rayon-style (`init` / `fold` / `reduce`), so each thread
//! accumulates into its own value and nothing is shared while pairs are found.

use super::{Filter, Nearest, Neighbor, Query, SpatialIndex};
use crate::geom::Sphere;
use crate::{Handle, Result};
use rayon::prelude::*;
use std::ops::ControlFlow;

/// Pair finding split across rayon's threads.
///
/// Implementors report exactly the pairs of [`SpatialIndex::visit_pairs`] — each
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

/// Validates every query of a batch, so a batch query fails before any work with
/// the error of the first bad query (and the index is only read, never changed).
fn validate_all<Q: Into<Query> + Copy>(queries: &[Q]) -> Result<()> {
    queries.iter().try_for_each(|&q| q.into().validate())
}

/// Number of objects each query selects among those `filter` admits (see
/// [`SpatialIndex`]'s filters), `out[i]` for `queries[i]`, the queries split
/// over rayon's threads (one [`SpatialIndex::visit`] per query; the index is
/// shared read-only, which its `Sync` bound allows). Cost: the sequential
/// queries divided over the pool's threads. Errors, before any query runs, if a
/// query's numbers are invalid.
pub fn par_query_counts<T, I, Q>(
    index: &I,
    queries: &[Q],
    filter: Option<Filter>,
) -> Result<Vec<usize>>
where
    I: SpatialIndex<T> + ?Sized,
    Q: Into<Query> + Copy + Sync,
{
    validate_all(queries)?;
    queries
        .par_iter()
        .map(|&q| {
            let mut n = 0usize;
            let _ = index.visit(&q.into(), filter, &mut |_, _, _| {
                n += 1;
                ControlFlow::Continue(())
            })?;
            Ok(n)
        })
        .collect()
}

/// Folds every (query, selected object) of a batch — the objects `filter`
/// admits — into per-task accumulators made by `init` —
/// `fold(acc, i, handle, sphere, value)` with `i` the query's position in
/// `queries` — then merges them with `reduce` (rayon's fold/reduce). Objects
/// are reported in no particular order across queries. Cost: the sequential
/// queries divided over the pool's threads plus one `reduce` per task. Errors,
/// before any query runs, if a query's numbers are invalid.
#[allow(clippy::too_many_arguments)]
pub fn par_visit_batch<T, I, Q, A, Init, F, R>(
    index: &I,
    queries: &[Q],
    filter: Option<Filter>,
    init: Init,
    fold: F,
    reduce: R,
) -> Result<A>
where
    I: SpatialIndex<T> + ?Sized,
    Q: Into<Query> + Copy + Sync,
    A: Send,
    Init: Fn() -> A + Sync + Send,
    F: Fn(A, usize, Handle, &Sphere, &T) -> A + Sync + Send,
    R: Fn(A, A) -> A + Sync + Send,
{
    validate_all(queries)?;
    Ok(queries
        .par_iter()
        .enumerate()
        .fold(&init, |acc, (i, &q)| {
            // `visit` takes an `FnMut`, so the accumulator moves through an Option.
            let mut acc = Some(acc);
            // Validated above: the walk cannot fail.
            let _ = index.visit(&q.into(), filter, &mut |h, s, v| {
                acc = acc.take().map(|a| fold(a, i, h, s, v));
                ControlFlow::Continue(())
            });
            acc.expect("the accumulator is put back after every object")
        })
        .reduce(&init, &reduce))
}

/// The answers of a batch of k-nearest queries, flat: query `i`'s neighbours
/// are `neighbors[offsets[i]..offsets[i + 1]]`, nearest first (the layout of
/// ragged results that array libraries use).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NearestBatch {
    /// Every query's neighbours, one query after another.
    pub neighbors: Vec<Neighbor>,
    /// `queries.len() + 1` positions into `neighbors`.
    pub offsets: Vec<usize>,
}

impl NearestBatch {
    /// Query `i`'s neighbours, nearest first. Panics if `i` is not a query of
    /// the batch.
    pub fn get(&self, i: usize) -> &[Neighbor] {
        &self.neighbors[self.offsets[i]..self.offsets[i + 1]]
    }

    /// Number of queries.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// True for a batch of no queries.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Queries per rayon task of [`par_nearest`]: enough that a task's buffer
/// warms up, few enough that two threads share the work evenly.
const NEAREST_CHUNK: usize = 64;

/// Runs [`SpatialIndex::nearest_into`] for every query of a batch (among the
/// objects `filter` admits), the queries split over rayon's threads, and
/// returns the answers flat ([`NearestBatch`]). Each task reuses one buffer
/// for its queries, so the only allocations are the tasks' and the result's.
/// Errors, before any query runs, if a query is invalid. Cost: the sequential
/// queries divided over the pool's threads, plus copying the answers.
pub fn par_nearest<T, I>(
    index: &I,
    queries: &[Nearest],
    filter: Option<Filter>,
) -> Result<NearestBatch>
where
    I: SpatialIndex<T> + ?Sized,
{
    queries.iter().try_for_each(Nearest::validate)?;
    let parts: Vec<(Vec<Neighbor>, Vec<usize>)> = queries
        .par_chunks(NEAREST_CHUNK)
        .map(|chunk| {
            let mut buf = Vec::new();
            let mut flat = Vec::new();
            let mut counts = Vec::with_capacity(chunk.len());
            for q in chunk {
                // Validated above: the search cannot fail.
                let _ = index.nearest_into(q, filter, &mut buf);
                counts.push(buf.len());
                flat.extend_from_slice(&buf);
            }
            (flat, counts)
        })
        .collect();
    let total = parts.iter().map(|(f, _)| f.len()).sum();
    let mut out = NearestBatch {
        neighbors: Vec::with_capacity(total),
        offsets: Vec::with_capacity(queries.len() + 1),
    };
    out.offsets.push(0);
    for (flat, counts) in parts {
        out.neighbors.extend_from_slice(&flat);
        for c in counts {
            let last = *out.offsets.last().expect("starts with 0");
            out.offsets.push(last + c);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::{BruteForce, HashGrid, LinearOctree, LooseKdTree};
    use crate::broad::{LooseKdConfig, SpatialIndexExt};
    use crate::geom::{Aabb, Frustum, Ray};
    use crate::Error;
    use glam::{Mat4, Vec3};

    /// A deterministic stream in `[0, 1)`.
    fn rng(mut seed: u32) -> impl FnMut() -> f32 {
        move || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    fn fill<I: SpatialIndex<u32>>(index: &mut I) {
        let mut next = rng(11);
        for i in 0..3000u32 {
            let c = Vec3::new(next(), next(), next()) * 60.0;
            let h = index.insert(Sphere::new(c, 0.2 + 2.0 * next()), i).unwrap();
            if i % 10 == 0 {
                index.remove(h).unwrap();
            }
        }
    }

    /// Sequential reference: the per-query handle lists, sorted.
    fn sequential<T, I: SpatialIndex<T>, Q: Into<Query> + Copy>(
        index: &I,
        qs: &[Q],
    ) -> Vec<Vec<Handle>> {
        qs.iter()
            .map(|&q| {
                let mut v = index.query(q).unwrap();
                v.sort();
                v
            })
            .collect()
    }

    fn check<I: SpatialIndex<u32>, Q: Into<Query> + Copy + Sync>(index: &I, qs: &[Q]) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let seq = sequential(index, qs);
        let total: usize = seq.iter().map(Vec::len).sum();
        assert!(total > qs.len(), "the batch must select things: {total}");
        let counts = pool.install(|| par_query_counts(index, qs, None)).unwrap();
        assert_eq!(counts, seq.iter().map(Vec::len).collect::<Vec<_>>());
        let mut lists = pool
            .install(|| {
                par_visit_batch(
                    index,
                    qs,
                    None,
                    || vec![Vec::new(); qs.len()],
                    |mut acc: Vec<Vec<Handle>>, i, h, _, _| {
                        acc[i].push(h);
                        acc
                    },
                    |mut a, b| {
                        for (x, y) in a.iter_mut().zip(b) {
                            x.extend(y);
                        }
                        a
                    },
                )
            })
            .unwrap();
        lists.iter_mut().for_each(|l| l.sort());
        assert_eq!(lists, seq);
    }

    fn batches<I: SpatialIndex<u32>>(index: &I) {
        let mut next = rng(5);
        let mut p = || Vec3::new(next(), next(), next()) * 64.0 - 2.0;
        let spheres: Vec<_> = (0..300).map(|_| Sphere::new(p(), 4.0)).collect();
        let boxes: Vec<_> = (0..300)
            .map(|_| {
                let c = p();
                Aabb::new(c - 3.0, c + Vec3::new(5.0, 2.0, 4.0))
            })
            .collect();
        let rays: Vec<_> = (0..300)
            .map(|i| {
                let (o, d) = (p(), p() - 30.0);
                if i % 2 == 0 {
                    Ray::new(o, d)
                } else {
                    Ray::with_max_t(o, d, 0.3)
                }
            })
            .collect();
        let frusta: Vec<_> = (0..20)
            .map(|_| {
                let view = Mat4::look_at_rh(p(), p(), Vec3::Z);
                let proj = Mat4::perspective_rh(1.0, 1.5, 0.1, 30.0);
                Frustum::from_view_projection(proj * view).unwrap()
            })
            .collect();
        check(index, &spheres);
        check(index, &boxes);
        check(index, &rays);
        check(index, &frusta);
    }

    #[test]
    fn batch_queries_in_a_two_thread_pool_equal_sequential_ones() {
        let world = Aabb::new(Vec3::ZERO, Vec3::splat(60.0));
        let mut brute = BruteForce::new();
        fill(&mut brute);
        batches(&brute);
        let mut kd = LooseKdTree::with_config(LooseKdConfig {
            density: 0.25,
            ..LooseKdConfig::new(world, 2.2)
        })
        .unwrap();
        fill(&mut kd);
        batches(&kd);
        let mut oct = LinearOctree::new(world).unwrap();
        fill(&mut oct);
        batches(&oct);
        let mut grid = HashGrid::new(2.2).unwrap();
        fill(&mut grid);
        batches(&grid);
    }

    /// The batch k-nearest search gives, per query, exactly the sequential
    /// answer (filtered or not), in the flat layout, on a 2-thread pool, for
    /// every index kind; a bad query fails the batch.
    #[test]
    fn par_nearest_matches_sequential() {
        use crate::broad::{Filter, IndexKind, Metric, SceneHint};
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let mut next = rng(5);
        let mut qs: Vec<Nearest> = (0..300)
            .map(|i| {
                let p = Vec3::new(next(), next(), next()) * 70.0 - Vec3::splat(5.0);
                let q = Nearest::new(p, [0, 1, 8, 64, 5000][i % 5]);
                match i % 3 {
                    0 => q,
                    1 => q.within(3.0),
                    _ => q.metric(Metric::Center),
                }
            })
            .collect();
        qs.push(Nearest::new(Vec3::splat(1e7), 3));
        let hint = SceneHint::new(Aabb::new(Vec3::ZERO, Vec3::splat(60.0)), 2.2);
        for kind in IndexKind::ALL {
            let mut index = kind.build::<u32>(&hint).unwrap();
            fill(&mut index);
            let mut hs = Vec::new();
            index.for_each(&mut |h, _, _| hs.push(h));
            for (i, h) in hs.iter().enumerate() {
                index
                    .set_filter(*h, Filter::new(1 << (i % 3), 0b011))
                    .unwrap();
            }
            for filter in [None, Some(Filter::new(0b001, 0b001))] {
                let batch = pool.install(|| par_nearest(&index, &qs, filter)).unwrap();
                assert_eq!(batch.len(), qs.len());
                let mut total = 0;
                for (i, q) in qs.iter().enumerate() {
                    let mut one = Vec::new();
                    index.nearest_into(q, filter, &mut one).unwrap();
                    assert_eq!(batch.get(i), &one[..], "{kind:?} query {i}");
                    total += one.len();
                }
                assert!(total > qs.len(), "{kind:?}: the batch must find things");
            }
            let mut bad = qs.clone();
            bad[7].point.x = f32::NAN;
            assert!(par_nearest(&index, &bad, None).is_err());
        }
    }

    #[test]
    fn a_bad_query_fails_the_batch_before_any_work() {
        let mut kd = LooseKdTree::with_config(LooseKdConfig {
            density: 0.25,
            ..LooseKdConfig::new(Aabb::new(Vec3::ZERO, Vec3::ONE), 1.0)
        })
        .unwrap();
        kd.insert(Sphere::new(Vec3::ZERO, 1.0), 0u32).unwrap();
        let qs = [
            Sphere::new(Vec3::ZERO, 1.0),
            Sphere::new(Vec3::ZERO, f32::NAN),
        ];
        let bad = Err(Error::NonFinite {
            what: "sphere radius",
        });
        assert_eq!(par_query_counts(&kd, &qs, None), bad);
        let r = par_visit_batch(
            &kd,
            &qs,
            None,
            || 0,
            |n, _, _, _, _: &u32| n + 1,
            |a, b| a + b,
        );
        assert_eq!(r, bad.map(|_: Vec<usize>| 0));
    }
}
