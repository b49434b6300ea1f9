//! Test helpers shared by the indices' unit tests (compiled only under `cfg(test)`).

use crate::broad::{BruteForce, RayHit, SpatialIndex, SpatialIndexExt};
use crate::geom::Ray;
use std::ops::ControlFlow;

/// Payload ids and the bit patterns of the entry `t`s of `hits`, sorted.
fn ids(hits: Vec<RayHit>, index: &impl SpatialIndex<u32>) -> Vec<(u32, u32)> {
    let mut v: Vec<_> = hits
        .iter()
        .map(|h| (*index.get(h.handle).unwrap().1, h.t.to_bits()))
        .collect();
    v.sort_unstable();
    v
}

/// Checks one ray on `index` against the oracle `brute` holding the same objects:
/// no object reported twice by the raw query, the same hits with bit-identical
/// `t`, and the same first-hit `t`.
pub(crate) fn check_ray(index: &impl SpatialIndex<u32>, brute: &BruteForce<u32>, r: &Ray) {
    let mut seen = Vec::new();
    let _ = index.for_each_in(*r, |h, _, _| {
        seen.push(h);
        ControlFlow::Continue(())
    });
    let n = seen.len();
    seen.sort();
    seen.dedup();
    assert_eq!(n, seen.len(), "reported twice: {r:?}");
    assert_eq!(
        ids(index.ray_hits(r).unwrap(), index),
        ids(brute.ray_hits(r).unwrap(), brute),
        "{r:?}"
    );
    let (fi, fb) = (
        index.ray_first(r, None).unwrap(),
        brute.ray_first(r, None).unwrap(),
    );
    assert_eq!(fi.map(|h| h.t), fb.map(|h| h.t), "{r:?}");
}
