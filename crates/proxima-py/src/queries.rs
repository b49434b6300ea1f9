//! The batch queries of [`Index`](crate::index::Index): every query of a batch
//! validated first, then run on the calling thread or on a pool, results
//! concatenated in CSR form (`ids`, `offsets`) like scipy's sparse rows and
//! Open3D's ragged outputs.

use crate::errors::OrRaise;
use crate::workers::Workers;
use proxima::broad::{
    par_nearest, AnyIndex, Filter, Metric, Nearest, Neighbor, ParallelPairs, Query, SpatialIndex,
};
use proxima::geom::{overlap, Ray, Sphere, SphereSweep};
use proxima::Handle;
use pyo3::PyResult;
use rayon::prelude::*;
use std::ops::ControlFlow;

/// Queries per parallel task: a query costs about a microsecond, a task must
/// cost much more than its scheduling.
const CHUNK: usize = 256;

/// The answer to a batch of region queries: query `i` selected
/// `ids[offsets[i]..offsets[i + 1]]`, and for rays `t` holds each hit's entry
/// parameter beside its id.
pub struct Csr {
    /// The selected ids, query after query.
    pub ids: Vec<i64>,
    /// `m + 1` offsets into `ids`.
    pub offsets: Vec<i64>,
    /// Each hit's entry parameter (rays; 0 for other shapes).
    pub t: Vec<f32>,
}

/// Checks every query of a batch, naming the first bad one (`what: row i: ...`),
/// so that a bad batch fails before any work.
pub fn validate(queries: &[Query], what: &str) -> PyResult<()> {
    for (i, q) in queries.iter().enumerate() {
        q.validate().or_raise_at(|| format!("{what}: row {i}"))?;
    }
    Ok(())
}

/// Every object each query selects among those `filter` admits: sorted by id,
/// or for a ray (a sweep) by entry `t` along the ray (time of impact), ties by
/// id. The queries must be validated.
pub fn select(
    index: &AnyIndex<u64>,
    queries: &[Query],
    filter: Option<Filter>,
    workers: &Workers,
) -> Csr {
    if !workers.parallel() {
        return chunk(index, queries, filter);
    }
    let parts: Vec<Csr> = workers.run(|| {
        queries
            .par_chunks(CHUNK)
            .map(|qs| chunk(index, qs, filter))
            .collect()
    });
    let total = parts.iter().map(|p| p.ids.len()).sum();
    let mut out = Csr {
        ids: Vec::with_capacity(total),
        offsets: Vec::with_capacity(queries.len() + 1),
        t: Vec::with_capacity(total),
    };
    out.offsets.push(0);
    for p in parts {
        let base = out.ids.len() as i64;
        out.offsets.extend(p.offsets[1..].iter().map(|o| o + base));
        out.ids.extend(p.ids);
        out.t.extend(p.t);
    }
    out
}

/// [`SpatialIndex::visit`] with a closure: statically dispatched when
/// unfiltered (the common case), through the trait object otherwise.
fn each_in(
    index: &AnyIndex<u64>,
    q: &Query,
    filter: Option<Filter>,
    mut f: impl FnMut(Handle, &Sphere, &u64) -> ControlFlow<()>,
) {
    // Validated by the caller: the walk cannot fail.
    let _ = match filter {
        None => index.for_each_in(*q, f),
        Some(_) => index.visit(q, filter, &mut f),
    };
}

/// [`select`] on the calling thread.
fn chunk(index: &AnyIndex<u64>, queries: &[Query], filter: Option<Filter>) -> Csr {
    let mut hits: Vec<(f32, u64)> = Vec::new();
    let mut out = Csr {
        ids: Vec::new(),
        offsets: Vec::with_capacity(queries.len() + 1),
        t: Vec::new(),
    };
    out.offsets.push(0);
    for q in queries {
        hits.clear();
        each_in(index, q, filter, |_, s, &id| {
            let t = match q {
                // The index selected the sphere, so the exact test hits.
                Query::Ray(r) => overlap::ray_sphere(r, s).unwrap_or(0.0),
                Query::Sweep(w) => overlap::sweep_sphere(w, s).unwrap_or(0.0),
                _ => 0.0,
            };
            hits.push((t, id));
            ControlFlow::Continue(())
        });
        hits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out.ids.extend(hits.iter().map(|&(_, id)| id as i64));
        out.t.extend(hits.iter().map(|&(t, _)| t));
        out.offsets.push(out.ids.len() as i64);
    }
    out
}

/// The first object each ray enters among those `filter` admits (smallest
/// `t`, ties by id when `by_id`, else by handle): `(id, t)`, or `(-1, inf)` for
/// a miss. The rays must be validated.
pub fn first_hits(
    index: &AnyIndex<u64>,
    rays: &[Ray],
    filter: Option<Filter>,
    workers: &Workers,
) -> (Vec<i64>, Vec<f32>) {
    let one = |r: &Ray| hit_id(index, index.ray_first(r, filter));
    first_each(rays, workers, one)
}

/// The first object each sweep touches among those `filter` admits: smallest
/// time of impact, ties by smaller id. `(id, t)`, or `(-1, inf)` for a miss.
/// The library breaks ties by handle, which is id order while `ordered`
/// ([`Ids::ordered`](crate::ids::Ids::ordered)); otherwise the first hit is
/// taken from every hit. The sweeps must be validated.
pub fn first_sweeps(
    index: &AnyIndex<u64>,
    sweeps: &[SphereSweep],
    filter: Option<Filter>,
    ordered: bool,
    workers: &Workers,
) -> (Vec<i64>, Vec<f32>) {
    let one = |w: &SphereSweep| {
        if ordered {
            return hit_id(index, index.sweep_first(w, filter));
        }
        let all = chunk(index, &[Query::Sweep(*w)], filter);
        match (all.ids.first(), all.t.first()) {
            (Some(&id), Some(&t)) => (id, t),
            _ => (-1, f32::INFINITY),
        }
    };
    first_each(sweeps, workers, one)
}

/// A first-hit answer as `(id, t)`, `(-1, inf)` for none.
fn hit_id(
    index: &AnyIndex<u64>,
    hit: proxima::Result<Option<proxima::broad::RayHit>>,
) -> (i64, f32) {
    match hit {
        Ok(Some(hit)) => match index.get(hit.handle) {
            Ok((_, &id)) => (id as i64, hit.t),
            Err(_) => (-1, f32::INFINITY),
        },
        _ => (-1, f32::INFINITY),
    }
}

/// `one` on every item, on the calling thread or the pool, unzipped.
fn first_each<Q: Sync>(
    items: &[Q],
    workers: &Workers,
    one: impl Fn(&Q) -> (i64, f32) + Sync,
) -> (Vec<i64>, Vec<f32>) {
    let hits: Vec<(i64, f32)> = if workers.parallel() {
        workers.run(|| items.par_iter().with_min_len(CHUNK).map(&one).collect())
    } else {
        items.iter().map(one).collect()
    };
    hits.into_iter().unzip()
}

/// How many bytes of rows (12 an entry: an `f32` distance and an `i64` id)
/// a one-worker `nearest` batch stages at a time: 4096 rows at k = 10, few
/// enough to stay in the L2 cache of the machine measured (2 MiB a core).
const STAGED_BYTES: usize = 480 * 1024;

/// The answers of a batch of k-nearest queries as `(M, k)` row-major arrays:
/// distances (`inf` where fewer than `k` were found) and ids (`-1` there).
pub struct KnnTable {
    /// `m * k` distances, nearest first in each row.
    pub distances: Vec<f32>,
    /// `m * k` ids beside them.
    pub ids: Vec<i64>,
}

/// The `k` nearest objects to each point (among those `filter` admits, at
/// most `max_distance` away, in `metric`), nearest first, ties by smaller id.
/// The library breaks ties by handle: id order while `ordered`; otherwise
/// each answer's last distance `D` is re-queried for every object at most `D`
/// away, and those are ordered by (distance, id) (about twice the cost).
/// With `by_slot` a handle's id is its slot (`Ids::id_of_slot`), read
/// without a lookup. Points must be finite and `max_distance` not NaN or
/// negative.
#[allow(clippy::too_many_arguments)]
pub fn nearest(
    index: &AnyIndex<u64>,
    points: &[proxima::glam::Vec3],
    k: usize,
    max_distance: f32,
    metric: Metric,
    filter: Option<Filter>,
    ordered: bool,
    by_slot: bool,
    workers: &Workers,
) -> proxima::Result<KnnTable> {
    let m = points.len();
    if k == 0 || m == 0 {
        return Ok(KnnTable {
            distances: vec![f32::INFINITY; m * k],
            ids: vec![-1; m * k],
        });
    }
    // Run in Morton order: neighbouring queries walk the same nodes, which
    // stay in cache (measured on 100k points, 100k queries, octree: k = 1
    // 0.93 -> 0.76 us a query, k = 10 2.53 -> 2.23). Rows are written back
    // in the caller's order.
    let order = proxima::broad::morton_order(points);
    let query = |p: proxima::glam::Vec3| Nearest::new(p, k).within(max_distance).metric(metric);
    // A row: the neighbours (handles) as ids, re-ordered when needed, then
    // `inf` and -1 up to `k`.
    let fill = |q: &Nearest,
                found: &[Neighbor],
                scratch: &mut Vec<Neighbor>,
                d: &mut [f32],
                ids: &mut [i64]| {
        let id = |h: Handle| {
            if by_slot {
                h.index() as i64
            } else {
                index.get(h).map_or(-1, |(_, &id)| id as i64)
            }
        };
        let mut j = 0;
        if !ordered {
            let found: &[Neighbor] = if found.len() == k {
                // Every object as near as the k-th, so that ties at the
                // boundary go to the smaller ids.
                let wide = Nearest {
                    k: index.len(),
                    max_distance: found[k - 1].distance,
                    ..*q
                };
                let _ = index.nearest_into(&wide, filter, scratch);
                &scratch[..]
            } else {
                found
            };
            let mut by_id: Vec<(f32, i64)> =
                found.iter().map(|n| (n.distance, id(n.handle))).collect();
            by_id.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for (dist, i) in by_id.into_iter().take(k) {
                d[j] = dist;
                ids[j] = i;
                j += 1;
            }
        } else {
            for n in found {
                d[j] = n.distance;
                ids[j] = id(n.handle);
                j += 1;
            }
        }
        d[j..].fill(f32::INFINITY);
        ids[j..].fill(-1);
    };
    if workers.parallel() {
        // Row i of the answer is query `rank[i]` of the batch.
        let mut rank = vec![0u32; m];
        for (j, &i) in order.iter().enumerate() {
            rank[i as usize] = j as u32;
        }
        let queries: Vec<Nearest> = order.iter().map(|&i| query(points[i as usize])).collect();
        let batch = workers.run(|| par_nearest(index, &queries, filter))?;
        // Zeroed memory (fresh pages, not written twice): `fill` writes every
        // entry of every row, the padding included.
        let mut out = KnnTable {
            distances: vec![0.0; m * k],
            ids: vec![0; m * k],
        };
        workers.run(|| {
            (out.distances.par_chunks_mut(k))
                .zip(out.ids.par_chunks_mut(k))
                .zip(rank.par_iter())
                .with_min_len(CHUNK)
                .for_each_init(Vec::new, |scratch, ((d, ids), &j)| {
                    let j = j as usize;
                    fill(&queries[j], batch.get(j), scratch, d, ids)
                })
        });
        Ok(out)
    } else {
        // Zeroed memory (fresh pages, not written twice): every row is
        // written whole once.
        let mut out = KnnTable {
            distances: vec![0.0; m * k],
            ids: vec![0; m * k],
        };
        // In blocks of the Morton order: the block's points gathered first
        // (read at each query's turn, each was a cache miss the search
        // waited on, ~7% of a k = 1 batch, `perf`; in one loop the misses
        // overlap), its rows written one after another into a small table
        // that stays in cache, then copied to their places in the answer.
        // Written in place at each query's turn, a row was a store to a
        // random place of the answer that missed the cache (~9% of a k = 10
        // batch, `perf`). When the whole answer fits the staging budget, or
        // not even 16 rows do (a large k), the rows go straight to their
        // places: no second table as large as the answer. Each query is
        // built as its turn comes and validated by `nearest_into` itself.
        let fits = STAGED_BYTES / 12 / k;
        let block = if fits >= 16 && fits < m { fits } else { m };
        let mut staged = KnnTable {
            distances: vec![0.0; if block < m { block * k } else { 0 }],
            ids: vec![0; if block < m { block * k } else { 0 }],
        };
        let mut points_at = Vec::with_capacity(block);
        let (mut buf, mut scratch) = (Vec::new(), Vec::new());
        for rows in order.chunks(block) {
            points_at.clear();
            points_at.extend(rows.iter().map(|&i| points[i as usize]));
            if block == m {
                for (&p, &i) in points_at.iter().zip(rows) {
                    let q = query(p);
                    index.nearest_into(&q, filter, &mut buf)?;
                    let row = i as usize * k..(i as usize + 1) * k;
                    let (d, ids) = (&mut out.distances[row.clone()], &mut out.ids[row]);
                    fill(&q, &buf, &mut scratch, d, ids);
                }
                continue;
            }
            let at = staged
                .distances
                .chunks_exact_mut(k)
                .zip(staged.ids.chunks_exact_mut(k));
            for (&p, (d, ids)) in points_at.iter().zip(at) {
                let q = query(p);
                index.nearest_into(&q, filter, &mut buf)?;
                fill(&q, &buf, &mut scratch, d, ids);
            }
            for (j, &i) in rows.iter().enumerate() {
                let (from, to) = (j * k..(j + 1) * k, i as usize * k..(i as usize + 1) * k);
                out.distances[to.clone()].copy_from_slice(&staged.distances[from.clone()]);
                out.ids[to].copy_from_slice(&staged.ids[from]);
            }
        }
        Ok(out)
    }
}

/// Every overlapping pair once as `[smaller id, larger id]`, sorted if `sort`.
pub fn pairs(index: &AnyIndex<u64>, workers: &Workers, sort: bool) -> Vec<[i64; 2]> {
    let ordered = |a: u64, b: u64| [a.min(b) as i64, a.max(b) as i64];
    let mut out = if workers.parallel() {
        workers.run(|| {
            index.par_fold_pairs(
                Vec::new,
                |mut v, _, &a, _, &b| {
                    v.push(ordered(a, b));
                    v
                },
                |mut a, mut b| {
                    a.append(&mut b);
                    a
                },
            )
        })
    } else {
        let mut v = Vec::new();
        let _ = index.for_each_pair(|_, &a, _, &b| {
            v.push(ordered(a, b));
            ControlFlow::Continue(())
        });
        v
    };
    if sort {
        if workers.parallel() {
            workers.run(|| out.par_sort_unstable());
        } else {
            out.sort_unstable();
        }
    }
    out
}
