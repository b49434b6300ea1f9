//! W5 for Proxima: one bounding-volume type, SAH trees, all-pairs and
//! first-contact queries timed one by one, with the cost counters of [sources: bvh-cost].

use crate::run::Clock;
use proxima::glam::Affine3A;
use proxima::narrow::{BoundingVolume, BuildOptions, Collider, Mesh, RotationUpdate, TriMesh};
use std::time::Duration;

/// A [`Clock`] for queries of a microsecond: each reading has the clock's own
/// cost beyond a wall-clock reading removed (the thread CPU clock is a system
/// call, ~0.5 µs here, while the peers' harness reads `steady_clock`, ~20 ns,
/// like `Instant`), so that short queries compare with the peers' on equal terms.
#[derive(Clone, Copy, Debug)]
pub struct QueryClock {
    /// The clock.
    pub clock: Clock,
    /// Median empty interval of `clock` minus that of the wall clock.
    pub excess: Duration,
}

impl QueryClock {
    /// Calibrates `clock` (10,000 empty intervals of each clock, medians).
    pub fn new(clock: Clock) -> Self {
        let empty = |c: Clock| {
            let mut v: Vec<Duration> = (0..10_000).map(|_| c.time(|| ()).1).collect();
            v.sort_unstable();
            v[v.len() / 2]
        };
        QueryClock {
            clock,
            excess: empty(clock).saturating_sub(empty(Clock::Wall)),
        }
    }

    /// Runs `f` and returns its result and its time, less the excess.
    pub fn time<R>(&self, f: impl FnOnce() -> R) -> (R, Duration) {
        let (r, t) = self.clock.time(f);
        (r, t.saturating_sub(self.excess))
    }
}

/// One bounding-volume type on one mesh pair.
pub struct BvRun {
    /// Bounding-volume name.
    pub name: &'static str,
    /// Building each tree (moving mesh, fixed mesh).
    pub build: (Duration, Duration),
    /// Per pose: the all-pairs query.
    pub all: Vec<Duration>,
    /// Per pose: the first-contact query.
    pub first: Vec<Duration>,
    /// Per pose: number of intersecting triangle pairs.
    pub counts: Vec<u64>,
    /// Per pose: whether the first-contact query found a pair.
    pub hits: Vec<bool>,
    /// Means over poses of the all-pairs counters `Nv`, `Np`, `Nu`.
    pub nv: f64,
    /// See `nv`.
    pub np: f64,
    /// See `nv`.
    pub nu: f64,
    /// The sorted pairs of the first `keep` poses (for the brute-force check).
    pub sample: Vec<Vec<(u32, u32)>>,
}

/// Runs every pose through one bounding-volume type.
pub fn measure<BV: BoundingVolume>(
    a: &TriMesh,
    b: &TriMesh,
    poses: &[Affine3A],
    qc: QueryClock,
    keep: usize,
    rotation: RotationUpdate,
) -> Result<BvRun, String> {
    let opts = BuildOptions::default();
    // The copies of the geometry are made outside the build's clock.
    let (a, b) = (a.clone(), b.clone());
    let clock = qc.clock;
    let (ma, build_a) = clock.time(|| Mesh::<BV>::from_trimesh(a, opts));
    let (mb, build_b) = clock.time(|| Mesh::<BV>::from_trimesh(b, opts));
    let (ma, mb) = (
        ma.map_err(|e| e.to_string())?,
        mb.map_err(|e| e.to_string())?,
    );
    let mut col = Collider::<BV>::new(rotation);
    let mut r = BvRun {
        name: BV::NAME,
        build: (build_a, build_b),
        all: Vec::with_capacity(poses.len()),
        first: Vec::with_capacity(poses.len()),
        counts: Vec::with_capacity(poses.len()),
        hits: Vec::with_capacity(poses.len()),
        nv: 0.0,
        np: 0.0,
        nu: 0.0,
        sample: Vec::new(),
    };
    // Warm-up: scratch buffers sized, code and data in cache.
    if let Some(p) = poses.first() {
        col.all_pairs(&ma, p, &mb).map_err(|e| e.to_string())?;
    }
    // All pairs over every pose, then first contact over every pose: as the
    // peers' harness runs them (one mode per pass), so that a first-contact
    // query never finds the caches warmed by an all-pairs query of its pose.
    for (i, p) in poses.iter().enumerate() {
        let (c, t) = qc.time(|| col.all_pairs(&ma, p, &mb));
        let c = c.map_err(|e| e.to_string())?;
        r.all.push(t);
        r.counts.push(c.pairs.len() as u64);
        r.nv += c.counters.nv as f64;
        r.np += c.counters.np as f64;
        r.nu += c.counters.nu as f64;
        if i < keep {
            let mut s = c.pairs;
            s.sort_unstable();
            r.sample.push(s);
        }
    }
    if let Some(p) = poses.first() {
        col.first_contact(&ma, p, &mb).map_err(|e| e.to_string())?;
    }
    for p in poses {
        let (f, t) = qc.time(|| col.first_contact(&ma, p, &mb));
        let f = f.map_err(|e| e.to_string())?;
        r.first.push(t);
        r.hits.push(f.pair.is_some());
    }
    let n = poses.len().max(1) as f64;
    (r.nv, r.np, r.nu) = (r.nv / n, r.np / n, r.nu / n);
    Ok(r)
}
