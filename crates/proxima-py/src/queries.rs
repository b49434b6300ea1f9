//! The batch queries of [`Index`](crate::index::Index): every query of a batch
//! validated first, then run on the calling thread or on a pool, results
//! concatenated in CSR form (`ids`, `offsets`) like scipy's sparse rows and
//! Open3D's ragged outputs.

use crate::errors::OrRaise;
use crate::workers::Workers;
use proxima::broad::{AnyIndex, ParallelPairs, Query, SpatialIndex};
use proxima::geom::{overlap, Ray};
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

/// Every object each query selects: sorted by id, or for a ray by entry `t`
/// along the ray, ties by id. The queries must be validated.
pub fn select(index: &AnyIndex<u64>, queries: &[Query], workers: &Workers) -> Csr {
    if !workers.parallel() {
        return chunk(index, queries);
    }
    let parts: Vec<Csr> = workers.run(|| {
        queries
            .par_chunks(CHUNK)
            .map(|qs| chunk(index, qs))
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

/// [`select`] on the calling thread.
fn chunk(index: &AnyIndex<u64>, queries: &[Query]) -> Csr {
    let mut hits: Vec<(f32, u64)> = Vec::new();
    let mut out = Csr {
        ids: Vec::new(),
        offsets: Vec::with_capacity(queries.len() + 1),
        t: Vec::new(),
    };
    out.offsets.push(0);
    for q in queries {
        hits.clear();
        // Validated: the walk cannot fail.
        let _ = index.for_each_in(*q, |_, s, &id| {
            let t = match q {
                // The index selected the sphere, so the ray's exact test hits.
                Query::Ray(r) => overlap::ray_sphere(r, s).unwrap_or(0.0),
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

/// The first object each ray enters (smallest `t`, ties by id's handle order):
/// `(id, t)`, or `(-1, inf)` for a miss. The rays must be validated.
pub fn first_hits(index: &AnyIndex<u64>, rays: &[Ray], workers: &Workers) -> (Vec<i64>, Vec<f32>) {
    let one = |r: &Ray| -> (i64, f32) {
        match index.ray_first(r) {
            Ok(Some(hit)) => match index.get(hit.handle) {
                Ok((_, &id)) => (id as i64, hit.t),
                Err(_) => (-1, f32::INFINITY),
            },
            _ => (-1, f32::INFINITY),
        }
    };
    let hits: Vec<(i64, f32)> = if workers.parallel() {
        workers.run(|| rays.par_iter().with_min_len(CHUNK).map(one).collect())
    } else {
        rays.iter().map(one).collect()
    };
    hits.into_iter().unzip()
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
