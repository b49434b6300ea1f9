//! Test helpers shared by the indices' unit tests (compiled only under `cfg(test)`).

use crate::broad::{BruteForce, Nearest, RayHit, SpatialIndex, SpatialIndexExt};
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

/// Checks k-nearest queries at `p` (both metrics, with and without a limit)
/// and the sweep `sw` (every hit and the first) on `index` against `brute`,
/// which must hold the same objects inserted in the same order (so equal
/// handles, and ties broken alike): the same payloads in the same order with
/// bit-identical distances and times.
pub(crate) fn check_knn_sweep(
    index: &impl SpatialIndex<u32>,
    brute: &BruteForce<u32>,
    p: glam::Vec3,
    k: usize,
    sw: &crate::geom::SphereSweep,
) {
    use crate::broad::{Metric, Nearest};
    let named = |i: &dyn SpatialIndex<u32>, q: &Nearest| {
        let mut out = Vec::new();
        i.nearest_into(q, None, &mut out).unwrap();
        out.iter()
            .map(|n| (*i.get(n.handle).unwrap().1, n.distance.to_bits()))
            .collect::<Vec<_>>()
    };
    for metric in [Metric::Surface, Metric::Center] {
        for limit in [f32::INFINITY, 3.0] {
            let q = Nearest::new(p, k).metric(metric).within(limit);
            assert_eq!(named(index, &q), named(brute, &q), "{q:?}");
        }
    }
    let hits = |i: &dyn SpatialIndex<u32>| {
        i.sweep_hits(sw)
            .unwrap()
            .iter()
            .map(|h| (*i.get(h.handle).unwrap().1, h.t.to_bits()))
            .collect::<Vec<_>>()
    };
    assert_eq!(hits(index), hits(brute), "{sw:?}");
    let first = |i: &dyn SpatialIndex<u32>| {
        i.sweep_first(sw, None)
            .unwrap()
            .map(|h| (*i.get(h.handle).unwrap().1, h.t.to_bits()))
    };
    assert_eq!(first(index), first(brute), "{sw:?}");
}

/// The grids' k-nearest and sweep paths against brute force on one index
/// (empty, or holding what the caller inserted into it and into `brute`):
/// objects added in two tight clusters far apart (a hash grid's sparse
/// scan), spread through `world` and beyond it, a few too large for the
/// cells (the large/oversized lists), and duplicates at one point (ties);
/// queries at stored centres, inside, between the clusters and far outside
/// (1e7 away), with k from 1 to past the count, and sweeps along the
/// clusters, across them, of no length, with radius 0, tiny and huge.
pub(crate) fn knn_sweep_suite<I: SpatialIndex<u32>>(
    mut index: I,
    world: crate::geom::Aabb,
    seed: u64,
) {
    use crate::geom::{Sphere, SphereSweep};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut brute = BruteForce::new();
    let size = world.max - world.min;
    let point = |rng: &mut rand_pcg::Pcg64, lo: Vec3, hi: Vec3| {
        vec3(
            rng.gen_range(lo.x..=hi.x),
            rng.gen_range(lo.y..=hi.y),
            rng.gen_range(lo.z..=hi.z),
        )
    };
    let empty = Nearest::new(Vec3::ZERO, 3);
    let mut out = vec![];
    index.nearest_into(&empty, None, &mut out).unwrap();
    assert!(out.is_empty());
    let clusters = [world.min + size * 0.1, world.max + size * 30.0];
    let r_cell = 0.05 * size.min_element().max(1.0);
    for i in 0..900u32 {
        let c = match i % 9 {
            0..=2 => {
                clusters[(i % 2) as usize] + point(&mut rng, Vec3::splat(-2.0), Vec3::splat(2.0))
            }
            3 => Vec3::splat(1.25),
            4 => point(&mut rng, world.min - size, world.max + size),
            _ => point(&mut rng, world.min, world.max),
        };
        let r = match i % 37 {
            0 => 40.0 * r_cell,
            1 | 2 => 0.0,
            _ => rng.gen_range(0.0..r_cell),
        };
        let s = Sphere::new(c, if i % 9 == 3 { 0.5 } else { r });
        index.insert(s, i).unwrap();
        brute.insert(s, i).unwrap();
        if i % 150 != 149 {
            continue;
        }
        index.validate().unwrap();
        for j in 0..60 {
            let p = match j % 6 {
                0 => clusters[j % 2] + point(&mut rng, Vec3::splat(-3.0), Vec3::splat(3.0)),
                1 => (clusters[0] + clusters[1]) * 0.5,
                2 => {
                    world.center()
                        + point(&mut rng, -Vec3::ONE, Vec3::ONE).normalize_or(Vec3::X) * 1e7
                }
                3 => Vec3::splat(1.25),
                _ => point(&mut rng, world.min - size * 0.2, world.max + size * 0.2),
            };
            let k = [1, 3, 10, 64, brute.len() + 5][j % 5];
            let to = match j % 7 {
                0 => p,
                1 => clusters[1 - j % 2],
                2 => p + point(&mut rng, -size, size),
                _ => p + point(&mut rng, -Vec3::splat(5.0), Vec3::splat(5.0)),
            };
            let radius = [0.0, 0.0, 0.3 * r_cell, r_cell, 20.0 * r_cell][j % 5];
            check_knn_sweep(&index, &brute, p, k, &SphereSweep::new(p, to, radius));
        }
    }
}
