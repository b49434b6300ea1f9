//! W5 for Proxima: one bounding-volume type, SAH trees, all-pairs and
//! first-contact queries timed one by one, with the cost counters of [sources: bvh-cost].

use crate::run::Clock;
use proxima::glam::Affine3A;
use proxima::narrow::{BoundingVolume, BuildOptions, Collider, Mesh, RotationUpdate, TriMesh};
use std::time::Duration;

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
    clock: Clock,
    keep: usize,
    rotation: RotationUpdate,
) -> Result<BvRun, String> {
    let opts = BuildOptions::default();
    // The copies of the geometry are made outside the build's clock.
    let (a, b) = (a.clone(), b.clone());
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
    for (i, p) in poses.iter().enumerate() {
        let (c, t) = clock.time(|| col.all_pairs(&ma, p, &mb));
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
        let (f, t) = clock.time(|| col.first_contact(&ma, p, &mb));
        let f = f.map_err(|e| e.to_string())?;
        r.first.push(t);
        r.hits.push(f.pair.is_some());
    }
    let n = poses.len().max(1) as f64;
    (r.nv, r.np, r.nu) = (r.nv / n, r.np / n, r.nu / n);
    Ok(r)
}
