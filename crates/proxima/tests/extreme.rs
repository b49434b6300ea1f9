//! Extreme scenes, for every index: 100k objects at one point, coordinates near
//! ±1e30, radii from 0 to 1e30, objects leaving the world and coming back, remove
//! everything and re-insert (nothing leaks), ids reused; and the regression tests
//! of the bugs found by fuzzing (named after them). Answers are compared with
//! `BruteForce` or with hand-computed exact values.

use proxima::broad::{
    AnyIndex, BruteForce, Grid2dConfig, Grid3dConfig, HashGrid, HashGridConfig, IndexKind,
    LinearOctree, LooseKdConfig, LooseKdTree, Metric, Nearest, SceneHint, SpatialIndex,
    SpatialIndexExt, UniformGrid2d, UniformGrid3d,
};
use proxima::geom::{overlap, Aabb, Frustum, Ray, Segment, Sphere, SphereSweep};
use proxima::glam::{vec3, Mat4, Vec3};
use proxima::{Error, Handle};
use proxima_harness::oracle::make_index;
use std::collections::BTreeSet;
use std::ops::ControlFlow;

fn world() -> Aabb {
    Aabb::new(Vec3::ZERO, Vec3::splat(100.0))
}

/// The index of `kind` these tests run: the harness's [`make_index`] over
/// `world()` with radius 2 (each config's `for_scene`, a denser loose k-d tree).
fn make(kind: IndexKind) -> AnyIndex<u32> {
    make_index(kind, &SceneHint::new(world(), 2.0))
}

/// One test function per index kind, each calling `$body(make)`.
macro_rules! per_index {
    ($body:ident) => {
        mod $body {
            use super::*;
            #[test]
            fn brute() {
                super::$body(&|| make(IndexKind::Brute));
            }
            #[test]
            fn loose_kd() {
                super::$body(&|| make(IndexKind::LooseKd));
            }
            #[test]
            fn octree() {
                super::$body(&|| make(IndexKind::Octree));
            }
            #[test]
            fn grid2d() {
                super::$body(&|| make(IndexKind::Grid2d));
            }
            #[test]
            fn hash_grid() {
                super::$body(&|| make(IndexKind::HashGrid));
            }
            #[test]
            fn grid3d() {
                super::$body(&|| make(IndexKind::Grid3d));
            }
        }
    };
}

fn ids<I: SpatialIndex<u32>>(i: &I, hs: Vec<Handle>) -> BTreeSet<u32> {
    hs.into_iter().map(|h| *i.get(h).unwrap().1).collect()
}

fn pair_ids<I: SpatialIndex<u32>>(i: &I) -> BTreeSet<(u32, u32)> {
    let mut out = BTreeSet::new();
    let _ = i.for_each_pair(|_, &a, _, &b| {
        out.insert((a.min(b), a.max(b)));
        ControlFlow::Continue(())
    });
    out
}

/// Every query of `i` gives the same objects as brute force over `spheres`.
fn agrees<I: SpatialIndex<u32>>(i: &I, spheres: &[(u32, Sphere)], queries: &[Sphere]) {
    i.validate().unwrap();
    let mut b = BruteForce::new();
    for &(id, s) in spheres {
        b.insert(s, id).unwrap();
    }
    for q in queries {
        assert_eq!(
            ids(i, i.query(*q).unwrap()),
            ids(&b, b.query(*q).unwrap()),
            "sphere {q:?}"
        );
        let bx = q.aabb();
        if bx.validate().is_ok() {
            assert_eq!(
                ids(i, i.query(bx).unwrap()),
                ids(&b, b.query(bx).unwrap()),
                "aabb {bx:?}"
            );
        }
    }
    assert_eq!(pair_ids(i), pair_ids(&b), "pairs");
}

// ---- 100k objects at one point -------------------------------------------------

const N_POINT: u32 = 100_000;

fn hundred_k_at_one_point<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let empty = i.memory_bytes();
    let p = vec3(37.5, 37.5, 37.5);
    let mut hs = Vec::new();
    for k in 0..N_POINT {
        // Zero radii and small ones, all centred on one point.
        hs.push(i.insert(Sphere::new(p, (k % 3) as f32 * 0.5), k).unwrap());
    }
    assert_eq!(i.len(), N_POINT as usize);
    i.validate().unwrap();
    assert_eq!(i.within(p, 0.0).unwrap().len(), N_POINT as usize);
    assert_eq!(
        i.within(p + vec3(0.75, 0.0, 0.0), 0.0).unwrap().len(),
        33_333
    );
    assert_eq!(i.within(p + Vec3::splat(10.0), 1.0).unwrap().len(), 0);
    let b = Aabb::new(p + Vec3::splat(1.0), p + Vec3::splat(2.0));
    assert!(i.query(b).unwrap().is_empty());
    let r = Ray::new(p - vec3(10.0, 0.0, 0.0), Vec3::X);
    assert_eq!(i.ray_hits(&r).unwrap().len(), N_POINT as usize);
    assert_eq!(i.ray_first(&r, None).unwrap().unwrap().t, 9.0);
    // Early stop is honoured.
    let mut n = 0;
    let _ = i.for_each_in(Sphere::new(p, 1.0), |_, _, _| {
        n += 1;
        ControlFlow::Break(())
    });
    assert_eq!(n, 1);
    // Remove everything: back to empty; then clear gives the empty memory.
    for h in hs {
        i.remove(h).unwrap();
    }
    assert!(i.is_empty());
    i.validate().unwrap();
    i.clear();
    assert_eq!(i.memory_bytes(), empty, "memory after clear");
}
per_index!(hundred_k_at_one_point);

// ---- coordinates near ±1e30, radii 0 … 1e30 -------------------------------------

fn huge_coordinates_and_radii<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let big = 1e30f32;
    let spheres: Vec<(u32, Sphere)> = vec![
        (0, Sphere::new(vec3(big, 0.0, 0.0), 0.0)),
        (1, Sphere::new(vec3(-big, 0.0, 0.0), big)),
        (2, Sphere::new(Vec3::ZERO, big)),
        (3, Sphere::new(vec3(5.0, 5.0, 5.0), 0.0)),
        (4, Sphere::new(Vec3::splat(-big), 1.0)),
        (5, Sphere::new(vec3(big, big, -big), big)),
        (6, Sphere::new(vec3(50.0, 50.0, 50.0), 1e-30)),
        (7, Sphere::new(vec3(0.0, 2.0 * big, 0.0), big)),
        (8, Sphere::new(vec3(3e38, -3e38, 0.0), 3e38)),
    ];
    for &(id, s) in &spheres {
        i.insert(s, id).unwrap();
    }
    // Exact answers: (1e30 + 5, 5, 5) is outside the ball of radius 1e30 at −1e30
    // by about 5 units, and 0 touches 2 and 5 exactly.
    let pairs = pair_ids(&i);
    assert!(pairs.contains(&(0, 2)), "touching at 1e30");
    assert!(pairs.contains(&(1, 2)));
    assert!(pairs.contains(&(2, 7)), "touching at (0, 1e30, 0)");
    assert!(!pairs.contains(&(1, 3)), "outside by 5 at 1e30");
    assert!(pairs.contains(&(2, 3)));
    let queries = [
        Sphere::new(vec3(big, 0.0, 0.0), 0.0),
        Sphere::new(Vec3::ZERO, 0.0),
        Sphere::new(vec3(-1.0, 0.0, 0.0), 0.5),
        Sphere::new(Vec3::splat(-big), big),
        Sphere::new(vec3(0.0, 11.5, 0.0), 0.0),
        Sphere::new(Vec3::ZERO, 3e38),
        Sphere::new(vec3(50.0, 50.0, 50.0), 0.0),
    ];
    agrees(&i, &spheres, &queries);
    assert_eq!(
        ids(&i, i.within(vec3(big, 0.0, 0.0), 0.0).unwrap()),
        BTreeSet::from([0, 2]) // 5 is at distance √2·1e30 > 1e30
    );
}
per_index!(huge_coordinates_and_radii);

// ---- k nearest where every distance overflows to infinity -------------------------

/// Regression (proptest, `tests/ops`): a query near `f32::MAX` makes every
/// distance infinite; with no distance limit those objects still count (the
/// 2D grid's growing box took an infinite face bound for "no more cells" and
/// answered nothing where brute force found an object). The grids now send
/// such queries to the expanding search (`nearest::may_overflow`).
fn nearest_with_overflowing_distances<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let mut brute = BruteForce::new();
    // Each index tags its own handles: answers are compared as (id, distance).
    let (mut hi, mut hb) = (Vec::new(), Vec::new());
    for (id, c) in [
        vec3(10.0, 20.0, 30.0),
        vec3(90.0, 5.0, 1.0),
        vec3(50.0, 50.0, 99.0),
    ]
    .into_iter()
    .enumerate()
    {
        let s = Sphere::new(c, 0.5);
        hi.push(i.insert(s, id as u32).unwrap());
        hb.push(brute.insert(s, id as u32).unwrap());
    }
    let as_ids = |v: &[proxima::broad::Neighbor], hs: &[Handle]| -> Vec<(usize, f32)> {
        v.iter()
            .map(|n| (hs.iter().position(|&h| h == n.handle).unwrap(), n.distance))
            .collect()
    };
    for point in [
        vec3(-2.3806633e23, -11.5, 3.4028235e38),
        vec3(3.4e38, -3.4e38, 0.0),
    ] {
        for metric in [Metric::Surface, Metric::Center] {
            for k in [1, 2, 5] {
                let q = Nearest::new(point, k).metric(metric);
                let (mut got, mut want) = (Vec::new(), Vec::new());
                i.nearest_into(&q, None, &mut got).unwrap();
                brute.nearest_into(&q, None, &mut want).unwrap();
                let got = as_ids(&got, &hi);
                // Ties (every distance is inf) go by handle, and both
                // assign handles in insertion order: the same ids in order.
                assert_eq!(got, as_ids(&want, &hb), "{point} {metric:?} k={k}");
                assert_eq!(got.len(), k.min(3), "every object counts at distance inf");
            }
        }
    }
}
per_index!(nearest_with_overflowing_distances);

// ---- k nearest: ties and near-ties at the pruning bound ---------------------------

/// The searches reject a candidate from its squared distance when it is surely
/// beyond the k-th best (`overlap::distance_exceeds`) and compute the exact
/// distance only for the rest. Objects whose distances are exactly equal,
/// one `f32` apart, or exact rounding ties (`1 + 2^-24` rounds to even, to
/// `1`), each twice (duplicates, radius 0 among them), around one point and
/// in all six directions: every `k` and limit at those values gives brute
/// force's answer, ids and distances bit for bit.
fn nearest_ties_at_the_pruning_bound<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let mut brute = BruteForce::new();
    let (mut hi, mut hb) = (Vec::new(), Vec::new());
    let p = Vec3::ONE;
    let u = 2f32.powi(-24);
    let mut id = 0u32;
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            for delta in [0.0, 4.0 * u, 8.0 * u] {
                for r in [0.0, u, 3.0 * u, 2.0 * u, 4.0 * u] {
                    for _ in 0..2 {
                        let mut c = p;
                        c[axis] += sign * (1.0 + delta);
                        let s = Sphere::new(c, r);
                        hi.push(i.insert(s, id).unwrap());
                        hb.push(brute.insert(s, id).unwrap());
                        id += 1;
                    }
                }
            }
        }
    }
    let n = id as usize;
    for point in [p, p + vec3(u, 0.0, 0.0), p - vec3(0.0, 0.0, 2.0 * u)] {
        for metric in [Metric::Surface, Metric::Center] {
            for limit in [f32::INFINITY, 1.0, 1.0 + 2.0 * u, 1.0 - u, 0.0] {
                for k in [1, 2, 3, 7, 12, 30, 31, 60, 61, 100, n - 1, n, n + 5] {
                    let q = Nearest::new(point, k).metric(metric).within(limit);
                    assert_nearest_as_brute(&i, &brute, (&hi, &hb), &q);
                }
            }
        }
    }
}
per_index!(nearest_ties_at_the_pruning_bound);

/// `index` answers `q` as `brute` does: the same objects (ids by insertion
/// order, `hs` the two handle lists), in order, at the same distances bit for
/// bit.
fn assert_nearest_as_brute<I: SpatialIndex<u32>>(
    index: &I,
    brute: &BruteForce<u32>,
    hs: (&[Handle], &[Handle]),
    q: &Nearest,
) {
    let as_ids = |v: &[proxima::broad::Neighbor], hs: &[Handle]| -> Vec<(usize, u32)> {
        v.iter()
            .map(|n| {
                let id = hs.iter().position(|&h| h == n.handle).unwrap();
                (id, n.distance.to_bits())
            })
            .collect()
    };
    let (mut got, mut want) = (Vec::new(), Vec::new());
    index.nearest_into(q, None, &mut got).unwrap();
    brute.nearest_into(q, None, &mut want).unwrap();
    assert_eq!(as_ids(&got, hs.0), as_ids(&want, hs.1), "{q:?}");
}

/// The bounded candidate set keeps a sorted buffer up to k = 256 and a heap
/// beyond: 640 objects on a few shells around the point (exact ties, one-ulp
/// near-ties and duplicates, radius 0 among them), queried with `k` around
/// the switch and past the count, both metrics, with and without a limit on
/// a shell: brute force's ids and distances bit for bit, in order.
fn nearest_k_around_the_sorted_limit<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let mut brute = BruteForce::new();
    let (mut hi, mut hb) = (Vec::new(), Vec::new());
    let p = vec3(0.5, -2.0, 3.0);
    let u = 2f32.powi(-23);
    let dirs = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
        vec3(0.6, 0.8, 0.0),
        vec3(0.0, -0.6, 0.8),
    ];
    let mut id = 0u32;
    for shell in [4.0f32, 4.0 + 4.0 * u, 8.0, 8.0 - 8.0 * u] {
        for d in dirs {
            for r in [0.0, 0.5, 1.0, 2.0, 4.0] {
                for _ in 0..4 {
                    let s = Sphere::new(p + d * shell, r);
                    hi.push(i.insert(s, id).unwrap());
                    hb.push(brute.insert(s, id).unwrap());
                    id += 1;
                }
            }
        }
    }
    let n = id as usize;
    for metric in [Metric::Surface, Metric::Center] {
        for limit in [f32::INFINITY, 4.0, 6.0] {
            for k in [16, 17, 255, 256, 257, 300, n - 1, n, n + 1] {
                let q = Nearest::new(p, k).metric(metric).within(limit);
                assert_nearest_as_brute(&i, &brute, (&hi, &hb), &q);
            }
        }
    }
}
per_index!(nearest_k_around_the_sorted_limit);

// ---- sphere sweeps at extreme coordinates and radii --------------------------------

/// Regressions (proptest, `tests/ops`): the hash grid's widened-segment walk
/// missed a hit of a sweep from x = 3.4e38 (its padded coordinates overflowed
/// to infinity), and the 3D grid's first-hit walk never ended on a sweep
/// whose radius made its reach infinite (`inf - inf` in the clipping). Every
/// sweep's hits and first hit are compared with brute force by id.
fn sweeps_at_extreme_coordinates<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let m = f32::MAX;
    let mut i = make();
    let mut brute = BruteForce::new();
    let (mut hi, mut hb) = (Vec::new(), Vec::new());
    let spheres = [
        Sphere::new(vec3(1.0, 2.0, 3.0), 0.5),
        Sphere::new(vec3(-9.0, -11.75, -5.5), 4.0),
        Sphere::new(vec3(60.0, 0.0, -3.0), 0.0),
        Sphere::new(vec3(50.0, 50.0, 50.0), 10.0),
        Sphere::new(vec3(1e30, -1e30, 0.0), 1e29),
        Sphere::new(vec3(0.0, 0.0, 0.0), 2.0),
        Sphere::new(vec3(-3e38, 0.0, 0.0), 1e30),
    ];
    for (id, s) in spheres.into_iter().enumerate() {
        hi.push(i.insert(s, id as u32).unwrap());
        hb.push(brute.insert(s, id as u32).unwrap());
    }
    let id_of = |h: Handle, hs: &[Handle]| hs.iter().position(|&x| x == h).unwrap();
    let hits = |v: Vec<proxima::broad::SweepHit>, hs: &[Handle]| -> BTreeSet<(usize, u32)> {
        v.iter()
            .map(|h| (id_of(h.handle, hs), h.t.to_bits()))
            .collect()
    };
    let sweeps = [
        // The hash grid's missed hit (shrunk by proptest).
        SphereSweep::new(
            vec3(3.4028235e38, 1e-30, -3.25),
            vec3(-2.0991098e36, -11.75, -5.5),
            179.0,
        ),
        SphereSweep::new(vec3(-m, 50.0, 50.0), vec3(m, 50.0, 50.0), 1.0),
        SphereSweep::new(vec3(m, m, m), vec3(0.0, 0.0, 0.0), 3.0),
        SphereSweep::new(vec3(50.0, 50.0, 50.0), vec3(0.0, 0.0, 0.0), 3e38),
        SphereSweep::new(vec3(-50.0, 0.0, 0.0), vec3(70.0, 0.0, -3.0), m),
        SphereSweep::new(vec3(1e30, 1e30, 1e30), vec3(-1e30, -1e30, 0.0), 1e30),
        SphereSweep::new(vec3(0.0, -m, 0.0), vec3(0.0, m, 0.0), 0.0),
        SphereSweep::new(vec3(-1e38, 2.0, 3.0), vec3(1e38, 2.0, 3.0), 0.25),
    ];
    let mut total = 0;
    for sw in &sweeps {
        let want = hits(brute.sweep_hits(sw).unwrap(), &hb);
        total += want.len();
        assert_eq!(hits(i.sweep_hits(sw).unwrap(), &hi), want, "{sw:?}");
        let first = |h: Option<proxima::broad::SweepHit>| h.map(|h| h.t.to_bits());
        assert_eq!(
            first(i.sweep_first(sw, None).unwrap()),
            first(brute.sweep_first(sw, None).unwrap()),
            "first {sw:?}"
        );
    }
    assert!(total >= 10, "the sweeps must hit ({total})");
}
per_index!(sweeps_at_extreme_coordinates);

// ---- leaving the world and coming back; remove all and re-insert -----------------

fn leave_world_and_return<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let empty = i.memory_bytes();
    let mut spheres: Vec<(u32, Sphere)> = Vec::new();
    let mut hs = Vec::new();
    for k in 0..200u32 {
        let c = vec3(
            (k % 10) as f32 * 10.0,
            (k / 10 % 10) as f32 * 10.0,
            (k / 100) as f32 * 50.0,
        );
        let s = Sphere::new(c, 1.0 + (k % 4) as f32);
        hs.push(i.insert(s, k).unwrap());
        spheres.push((k, s));
    }
    let queries = [
        Sphere::new(vec3(50.0, 50.0, 50.0), 30.0),
        Sphere::new(vec3(-1e6, 0.0, 0.0), 10.0),
        Sphere::new(vec3(1e20, 1e20, 0.0), 1e19),
        Sphere::new(Vec3::ZERO, 5.0),
    ];
    agrees(&i, &spheres, &queries);
    // Out to far away (and huge), then back.
    for (step, far) in [1e3f32, 1e7, 1e20, 1e30].into_iter().enumerate() {
        for (k, h) in hs.iter().enumerate() {
            if k % 3 == step % 3 {
                let s = Sphere::new(
                    spheres[k].1.center + Vec3::splat(far),
                    spheres[k].1.radius * (1.0 + step as f32),
                );
                i.update(*h, s).unwrap();
                spheres[k].1 = s;
            }
        }
        agrees(&i, &spheres, &queries);
    }
    for (k, h) in hs.iter().enumerate() {
        let s = Sphere::new(vec3(k as f32 * 0.5, 50.0, 50.0), 1.0);
        i.update(*h, s).unwrap();
        spheres[k].1 = s;
    }
    agrees(&i, &spheres, &queries);
    // Remove everything, then re-insert: ids (slots) are reused, old handles stale.
    for h in &hs {
        i.remove(*h).unwrap();
    }
    i.validate().unwrap();
    assert!(i.is_empty());
    for h in &hs {
        assert_eq!(i.get(*h).err(), Some(Error::StaleHandle));
        assert_eq!(i.remove(*h).err(), Some(Error::StaleHandle));
    }
    let mut again = Vec::new();
    for (k, s) in &spheres {
        again.push(i.insert(*s, *k).unwrap());
    }
    let old: BTreeSet<u32> = hs.iter().map(|h| h.index()).collect();
    let new: BTreeSet<u32> = again.iter().map(|h| h.index()).collect();
    assert_eq!(old, new, "slots are reused after removal");
    assert!(hs.iter().all(|h| !again.contains(h)), "new generations");
    agrees(&i, &spheres, &queries);
    i.clear();
    assert_eq!(i.memory_bytes(), empty, "memory after clear");
    assert!(i.get(again[0]).is_err());
}
per_index!(leave_world_and_return);

// ---- bad input leaves the index unchanged ------------------------------------------

fn bad_input_is_rejected_and_changes_nothing<I: SpatialIndex<u32>>(make: &dyn Fn() -> I) {
    let mut i = make();
    let h = i.insert(Sphere::new(Vec3::splat(10.0), 1.0), 7).unwrap();
    let bad = [
        Sphere::new(vec3(f32::NAN, 0.0, 0.0), 1.0),
        Sphere::new(vec3(0.0, f32::INFINITY, 0.0), 1.0),
        Sphere::new(Vec3::ZERO, -1.0),
        Sphere::new(Vec3::ZERO, f32::NAN),
        Sphere::new(Vec3::ZERO, f32::INFINITY),
    ];
    for s in bad {
        assert!(i.insert(s, 1).is_err());
        assert!(i.update(h, s).is_err());
        assert!(i.query(s).is_err());
    }
    assert!(i.query(Aabb::new(Vec3::ONE, Vec3::ZERO)).is_err());
    assert!(i.query(Aabb::new(Vec3::NAN, Vec3::ZERO)).is_err());
    assert_eq!(
        i.ray_hits(&Ray::new(Vec3::ZERO, Vec3::ZERO)).err(),
        Some(Error::ZeroDirection)
    );
    assert!(i.ray_hits(&Ray::new(Vec3::ZERO, Vec3::NAN)).is_err());
    assert!(i
        .ray_hits(&Ray::with_max_t(Vec3::ZERO, Vec3::X, -1.0))
        .is_err());
    assert!(i
        .ray_hits(&Segment::new(Vec3::ONE, Vec3::ONE).to_ray())
        .is_err());
    assert!(Frustum::from_view_projection(Mat4::NAN).is_err());
    assert_eq!(i.len(), 1);
    assert_eq!(i.get(h).unwrap(), (Sphere::new(Vec3::splat(10.0), 1.0), &7));
    i.validate().unwrap();
}
per_index!(bad_input_is_rejected_and_changes_nothing);

// ---- regression tests of fuzz findings ----------------------------------------------

/// Fuzz (index_ops): a ball at x = -1e30 of radius 1e30 and a point 5 units
/// beyond its surface: `(r1 + r2)²` and `|c1 - c2|²` rounded to the same `f32`
/// infinity (and to the same `f64`), so the test said "touching". Now exact.
#[test]
fn sphere_sphere_exact_at_1e30() {
    let big = 1e30f32;
    let ball = Sphere::new(vec3(-big, 0.0, 0.0), big);
    assert!(!overlap::sphere_sphere(
        &ball,
        &Sphere::new(vec3(5.0, 5.0, 5.0), 0.0)
    ));
    assert!(overlap::sphere_sphere(&ball, &Sphere::new(Vec3::ZERO, 0.0)));
    assert!(overlap::sphere_sphere(
        &ball,
        &Sphere::new(vec3(big, 0.0, 0.0), big)
    ));
    let far = Sphere::new(vec3(3e38, 0.0, 0.0), 0.0);
    assert!(!overlap::sphere_sphere(
        &far,
        &Sphere::new(vec3(-3e38, 0.0, 0.0), 3e38)
    ));
    assert!(!overlap::sphere_sphere(
        &far,
        &Sphere::new(vec3(-3e38, 0.0, 0.0), 3.4e38)
    ));
    assert!(overlap::sphere_sphere(&far, &Sphere::new(Vec3::ZERO, 3e38)));
    assert!(overlap::sphere_sphere(
        &far,
        &Sphere::new(vec3(3e38, 0.0, 3e38), 3e38)
    ));
    assert!(overlap::sphere_aabb(
        &ball,
        &Aabb::new(Vec3::ZERO, Vec3::ONE)
    ));
    assert!(!overlap::sphere_aabb(
        &ball,
        &Aabb::new(Vec3::splat(1.0), Vec3::splat(2.0))
    ));
}

/// Fuzz (index_ops): an object at y = 3.4e38 gave the octree a loose box with
/// infinite sides, whose centre is NaN; `frustum_aabb` then answered `Inside`
/// and the frustum query reported the object without testing it.
#[test]
fn octree_frustum_infinite_loose_box() {
    let mut o = LinearOctree::new(Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0))).unwrap();
    let mut b = BruteForce::new();
    for (k, s) in [
        Sphere::new(vec3(-32.0, 3.4028235e38, -32.0), 0.0),
        Sphere::new(vec3(-32.0, -32.0, -32.0), 1e30),
        Sphere::new(Vec3::ZERO, 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        o.insert(s, k as u32).unwrap();
        b.insert(s, k as u32).unwrap();
    }
    let m = Mat4::perspective_rh(1.0, 1.0, 0.1, 50.0)
        * Mat4::look_at_rh(vec3(0.0, 0.0, 20.0), Vec3::ZERO, Vec3::Y);
    let f = Frustum::from_view_projection(m).unwrap();
    assert_eq!(ids(&o, o.query(f).unwrap()), ids(&b, b.query(f).unwrap()));
    assert!(!ids(&o, o.query(f).unwrap()).contains(&0));
}

/// Fuzz (index_ops, proptest): a segment query on a hash grid holding objects
/// ~1e9 cells apart walked a strip of ~1e18 keys (padding grows with the ray's
/// magnitude): it hung. Wide strips are now served from the map of occupied cells.
#[test]
fn hash_grid_ray_wide_strip_hang() {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 1.0 }).unwrap();
    let mut b = BruteForce::new();
    let spheres = [
        Sphere::new(Vec3::ZERO, 1.0),
        Sphere::new(vec3(0.0, 1e9, 1e9), 1.0),
        Sphere::new(vec3(0.0, -1e9, -1e9), 1.0),
        Sphere::new(vec3(3.0, 0.5, 0.0), 1.0),
    ];
    for (k, s) in spheres.into_iter().enumerate() {
        g.insert(s, k as u32).unwrap();
        b.insert(s, k as u32).unwrap();
    }
    for r in [
        Ray::new(vec3(-1e14, 0.0, 0.0), Vec3::X),
        Ray::new(vec3(-1e8, 0.0, 0.0), Vec3::X),
        Ray::with_max_t(vec3(-1e8, 0.0, 0.0), Vec3::X, 2e8),
    ] {
        let hits = |i: &dyn Fn(&Ray) -> Vec<proxima::broad::RayHit>| -> Vec<u32> {
            i(&r).iter().map(|h| h.t.to_bits()).collect()
        };
        assert_eq!(
            hits(&|r| g.ray_hits(r).unwrap()),
            hits(&|r| b.ray_hits(r).unwrap())
        );
    }
}

/// Fuzz (index_ops): a ball at y = -3e38 of radius 3e38 ends (in `f32`) at
/// `c + r = 0`; the grids' cell ranges were padded relative to that bound, not to
/// the centre's magnitude, while the exact test's answer depends on the latter.
/// The grids now agree with brute force around such balls.
#[test]
fn grid_far_ball_cell_padding() {
    let world = Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0));
    let spheres = [
        (0, Sphere::new(vec3(-1.25, -3e38, 6.0), 3e38)),
        (1, Sphere::new(vec3(-1.25, -3.0e38, 6.0), 3.0000002e38)),
        (2, Sphere::new(vec3(4.760838e23, 31.5, 30.75), 1e15)),
    ];
    let queries: Vec<Sphere> = [0.0f32, 1e-3, 11.5, 1e20, 1e31, 3e38]
        .iter()
        .map(|&y| Sphere::new(vec3(-1.25, y, 6.0), 0.0))
        .collect();
    let mut g2 = UniformGrid2d::new(world, 2.0).unwrap();
    let mut hg = HashGrid::new(2.0).unwrap();
    for &(k, s) in &spheres {
        g2.insert(s, k).unwrap();
        hg.insert(s, k).unwrap();
    }
    agrees(&g2, &spheres, &queries);
    agrees(&hg, &spheres, &queries);
    let seg = Segment::new(vec3(2624.0, 11.5, 24.0), vec3(24.75, 13.5, -32.0));
    let n = |hits: Vec<proxima::broad::RayHit>| hits.len();
    let mut b = BruteForce::new();
    for &(k, s) in &spheres {
        b.insert(s, k).unwrap();
    }
    assert_eq!(
        n(g2.ray_hits(&seg.to_ray()).unwrap()),
        n(b.ray_hits(&seg.to_ray()).unwrap())
    );
    assert_eq!(
        n(hg.ray_hits(&seg.to_ray()).unwrap()),
        n(b.ray_hits(&seg.to_ray()).unwrap())
    );
}

/// A box near `f32::MAX` has a finite centre (it was `(min + max) / 2 = inf`).
#[test]
fn aabb_center_does_not_overflow() {
    let b = Aabb::new(Vec3::splat(2e38), Vec3::splat(3e38));
    assert_eq!(b.center(), Vec3::splat(2.5e38));
    assert!(b.half_extent().is_finite());
    let o = LinearOctree::<u32>::new(b);
    assert!(o.is_ok());
}

/// Fuzz (index_ops, timeout): a segment from x = 1e20 to x = -32 over a hash grid
/// holding an object at x = -3e38. Every strip's `t` rounded to `max_t = 1`, so the
/// walk's stop test never fired and it went on for ~1e9 strips. The walk now stops
/// at the (padded) cell of the ray's end.
#[test]
fn hash_grid_far_segment_strip_loop() {
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 1.0 }).unwrap();
    let mut b = BruteForce::new();
    for (k, s) in [
        Sphere::new(vec3(-3e38, -8192.0, -32.0), 16.5),
        Sphere::new(vec3(-28.75, -30.0, -32.0), 15.375),
    ]
    .into_iter()
    .enumerate()
    {
        g.insert(s, k as u32).unwrap();
        b.insert(s, k as u32).unwrap();
    }
    let seg = Segment::new(vec3(1e20, -32.0, -32.0), vec3(-32.0, -32.0, -32.0));
    let n = |h: Vec<proxima::broad::RayHit>| h.len();
    assert_eq!(
        n(g.ray_hits(&seg.to_ray()).unwrap()),
        n(b.ray_hits(&seg.to_ray()).unwrap())
    );
    let r = Ray::with_max_t(vec3(1e20, -32.0, -32.0), vec3(-1e20, 0.0, 0.0), 1.0);
    assert_eq!(n(g.ray_hits(&r).unwrap()), n(b.ray_hits(&r).unwrap()));
}

/// Fuzz (index_ops): a frustum with a zero-normal plane `0·p - 4.75 >= 0` (from a
/// degenerate matrix: everywhere outside). The box test culled every node while
/// the sphere test kept spheres of radius > 4.75 (it compared with `-r`, not with
/// `-r |n|`). Both now scale the radius/extent by `|n|`.
#[test]
fn frustum_zero_normal_plane_consistent() {
    use proxima::geom::Plane;
    let mut planes = [Plane::new(Vec3::X, 1e3); 6];
    planes[5] = Plane::new(Vec3::ZERO, -4.75);
    let f = Frustum::from_planes(planes);
    let big = Sphere::new(vec3(-32.0, -32.0, 27.0), 29.5);
    assert_eq!(
        overlap::frustum_sphere(&f, &big),
        proxima::geom::Relation::Outside
    );
    let mut kd = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0)), 2.0)
    })
    .unwrap();
    let mut b = BruteForce::new();
    for (k, s) in [Sphere::new(vec3(-8192.0, 0.0, -32.0), 0.0), big]
        .into_iter()
        .enumerate()
    {
        kd.insert(s, k as u32).unwrap();
        b.insert(s, k as u32).unwrap();
    }
    assert!(b.query(f).unwrap().is_empty());
    assert!(kd.query(f).unwrap().is_empty());
    // A plane with a scaled normal is the same half-space.
    planes[5] = Plane::new(vec3(0.0, 0.0, 2.0), 0.0);
    let f = Frustum::from_planes(planes);
    let touching = Sphere::new(vec3(0.0, 0.0, -1.0), 1.0);
    assert_ne!(
        overlap::frustum_sphere(&f, &touching),
        proxima::geom::Relation::Outside
    );
    let out = Sphere::new(vec3(0.0, 0.0, -1.5), 1.0);
    assert_eq!(
        overlap::frustum_sphere(&f, &out),
        proxima::geom::Relation::Outside
    );
}

/// Fuzz (index_ops, 89 s timeout): a hash grid ray strip whose cell range on one
/// cross axis was empty while the other spanned ~1e9 keys looped over the latter
/// (the empty inner loop did not stop the outer one). Now an empty strip is skipped.
#[test]
fn hash_grid_empty_strip_range() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/found/");
    for f in [
        "index_ops-hash-grid-empty-strip-range",
        "index_ops-hash-grid-empty-strip-range-2",
    ] {
        let data = std::fs::read(format!("{dir}{f}")).unwrap();
        assert!(!data.is_empty());
    }
    // The inputs run in tests/ops (fuzz_found_inputs_pass); here a direct case:
    // objects spread to ±1e9 on z, none in the ray's y range.
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 1.0 }).unwrap();
    let mut b = BruteForce::new();
    for (k, s) in [
        Sphere::new(vec3(0.0, 0.0, 1e9), 1.0),
        Sphere::new(vec3(5.0, 0.0, -1e9), 1.0),
        Sphere::new(vec3(9.0, 0.0, 0.0), 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        g.insert(s, k as u32).unwrap();
        b.insert(s, k as u32).unwrap();
    }
    let r = Ray::with_max_t(vec3(-1e12, 50.0, 0.0), vec3(1.0, 0.0, 0.0), 2e12);
    assert_eq!(g.ray_hits(&r).unwrap().len(), b.ray_hits(&r).unwrap().len());
    let r = Ray::with_max_t(vec3(-1e12, 0.0, 0.0), vec3(1.0, 0.0, 0.0), 2e12);
    assert_eq!(g.ray_hits(&r).unwrap().len(), b.ray_hits(&r).unwrap().len());
}

/// Found by the proptest op sequences once far rays were compared: with a cell of
/// 3e38 the hash grid's loose box of cell y = -2 was `[-∞, -∞]` (its upper side
/// computed as `min + cell` from an overflowed `min`), so a query with a ball of
/// radius `f32::MAX` pruned the cell holding an object at y = -3e38.
#[test]
fn hash_grid_huge_cell_loose_box() {
    let big = Sphere::new(vec3(25.25, -21.5, -15.75), f32::MAX);
    let far = Sphere::new(vec3(-4.25, -3e38, 4352.0), 18.875);
    let mut g = HashGrid::with_config(HashGridConfig { cell_size: 3e38 }).unwrap();
    let mut b = BruteForce::new();
    for (i, s) in [big, far].into_iter().enumerate() {
        g.insert(s, i as u32).unwrap();
        b.insert(s, i as u32).unwrap();
    }
    g.validate().unwrap();
    assert_eq!(g.pairs().len(), 1);
    assert_eq!(b.pairs().len(), 1);
    assert_eq!(g.query(big).unwrap().len(), 2);
}

/// Found by a 10-minute proptest run: with a cell of 2.6e24 an object at
/// z = -1e30 has a key box padded ~4 cells beyond it on each side (the key
/// padding is applied twice), and it is reported only from its lowest cell; that
/// cell's loose box, grown by a single padding, lay beyond the ball of radius
/// 1e30, so the pair was pruned (a sphere query, with a less padded key box,
/// found it). Input: `fuzz/found/index_ops-hash-grid-pairs-oversized-far`.
#[test]
fn hash_grid_pairs_oversized_far_point() {
    let big = Sphere::new(vec3(-32.0, 0.0, -32.0), 1e30);
    let far = Sphere::new(vec3(-32.0, -32.0, -1e30), 0.0);
    let mut g = HashGrid::with_config(HashGridConfig {
        cell_size: 2.6067463e24,
    })
    .unwrap();
    let mut b = BruteForce::new();
    for (i, s) in [big, far].into_iter().enumerate() {
        g.insert(s, i as u32).unwrap();
        b.insert(s, i as u32).unwrap();
    }
    assert_eq!(b.pairs().len(), 1);
    assert_eq!(g.query(big).unwrap().len(), 2);
    assert_eq!(g.pairs().len(), 1, "the grid misses the pair");
    g.validate().unwrap();
}

/// `found/index_ops-grid2d-far-segment`: a segment from (-15.5, 3e38) to
/// (-f32::MAX, 0) ends inside a ball of radius 1.01e31 (half an ulp there) at x = -f32::MAX (referenced
/// from the border column of a ±16 world). The 2D grid's strip walk must report
/// it at t = 1 like brute force.
#[test]
fn grid2d_far_segment_end_hit() {
    let w = Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0));
    let ball = Sphere::new(vec3(-f32::MAX, -32.0, 0.0), 1.0141205e31);
    let seg = Segment::new(vec3(-15.5, 3e38, -32.0), vec3(-f32::MAX, 0.0, -32.0));
    let ray = seg.to_ray();
    assert_eq!(overlap::ray_sphere(&ray, &ball), Some(1.0));
    for cell in [0.5, 0.25, 1.0, 2.0, 4.0, 8.0] {
        let mut g = UniformGrid2d::with_config(Grid2dConfig {
            world: w,
            cell_size: cell,
        })
        .unwrap();
        g.insert(ball, 0u32).unwrap();
        g.insert(Sphere::new(Vec3::splat(-32.0), 0.0), 1).unwrap();
        assert_eq!(g.ray_hits(&ray).unwrap().len(), 1, "cell {cell}: ray_hits");
        assert_eq!(
            g.ray_first(&ray, None).unwrap().map(|h| h.t),
            Some(1.0),
            "cell {cell}: ray_first"
        );
    }
}

/// The same class for the other grids: balls whose bounds overflow to ±∞ (a half
/// ulp beyond `f32::MAX`) or nearly, at the world's corners and far outside, hit by
/// segments and rays from inside; every grid agrees with brute force.
#[test]
fn grids_far_balls_near_overflow_match_brute_force() {
    let w = Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0));
    let mut hits = 0;
    for cell in [0.5, 4.0] {
        hits += far_rays_agree(
            UniformGrid2d::with_config(Grid2dConfig {
                world: w,
                cell_size: cell,
            })
            .unwrap(),
        );
        hits += far_rays_agree(
            UniformGrid3d::with_config(Grid3dConfig {
                world: w,
                cell_size: cell,
            })
            .unwrap(),
        );
        hits += far_rays_agree(HashGrid::with_config(HashGridConfig { cell_size: cell }).unwrap());
    }
    assert!(hits > 100, "the scene must produce hits ({hits})");
}

/// Inserts the near-overflow scene into `i` and compares rays and segments between
/// its points with brute force; returns the number of hits.
fn far_rays_agree<I: SpatialIndex<u32>>(mut i: I) -> usize {
    let m = f32::MAX;
    let balls = [
        Sphere::new(vec3(-m, -32.0, 0.0), 1.0141205e31),
        Sphere::new(vec3(m, 32.0, -5.0), 1.0141205e31),
        Sphere::new(vec3(0.0, -m, 3.0), 2e31),
        Sphere::new(vec3(-3e38, 3e38, 0.0), 1e31),
        Sphere::new(vec3(5.0, 5.0, m), 1.0141205e31),
        Sphere::new(Vec3::splat(-32.0), 0.0),
        Sphere::new(vec3(1.0, 2.0, 3.0), 0.5),
    ];
    let ends = [
        vec3(-m, 0.0, -32.0),
        vec3(-15.5, 3e38, -32.0),
        vec3(m, 32.0, -5.0),
        vec3(0.0, -m, 3.0),
        vec3(-3e38, 3e38, 0.0),
        vec3(5.0, 5.0, m),
        vec3(1.0, 2.0, 3.0),
        vec3(-15.5, 0.25, 0.0),
    ];
    let mut b = BruteForce::new();
    for (k, s) in balls.iter().enumerate() {
        b.insert(*s, k as u32).unwrap();
        i.insert(*s, k as u32).unwrap();
    }
    fn key<J: SpatialIndex<u32>>(j: &J, v: &[proxima::broad::RayHit]) -> Vec<(u32, u32)> {
        let mut v: Vec<_> = v
            .iter()
            .map(|h| (*j.get(h.handle).unwrap().1, h.t.to_bits()))
            .collect();
        v.sort();
        v
    }
    let mut hits = 0;
    for &p in &ends {
        for &q in &ends {
            for ray in [Segment::new(p, q).to_ray(), Ray::new(p, q - p)] {
                if ray.validate().is_err() {
                    continue;
                }
                let want = key(&b, &b.ray_hits(&ray).unwrap());
                hits += want.len();
                assert_eq!(key(&i, &i.ray_hits(&ray).unwrap()), want, "{ray:?}");
                let first = |j: Option<proxima::broad::RayHit>| j.map(|h| h.t.to_bits());
                assert_eq!(
                    first(i.ray_first(&ray, None).unwrap()),
                    first(b.ray_first(&ray, None).unwrap()),
                    "{ray:?}"
                );
            }
        }
    }
    hits
}

/// Regression (proptest, `tests/ops`): a nearly vertical ray over the 2D grid
/// from y = -8.7e-20, in a grid whose lines sit at -16 + 4k: `coord` rounded
/// `y + 16` to 16 and started the walk in the cell above the origin's, whose
/// strip the ray enters only at t = 5e5, so it found nothing where brute force
/// hit two spheres at t = 0. Each grid, both directions, rays and first hits.
#[test]
fn grid_walk_start_cell_rounding() {
    let w = Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0));
    let spheres = [
        Sphere::new(vec3(-12.0, -26.25, 13.75), 31.75),
        Sphere::new(vec3(0.0, -7.25, -11.0), 31.625),
        Sphere::new(vec3(0.0, 28.0, 8.25), 2.179795e32),
        Sphere::new(vec3(0.0, -31.5, 0.0), 15.125),
        Sphere::new(vec3(0.5, -0.5, 0.0), 0.75),
        Sphere::new(vec3(-0.75, 0.5, -1.0), 0.75),
    ];
    let rays = [
        Ray::with_max_t(
            vec3(-6.36791e-32, -8.718356e-20, -2.9577731e-12),
            vec3(0.0, 1.6723203e-25, -32.0),
            164.0,
        ),
        Ray::with_max_t(
            vec3(-6.36791e-32, 8.718356e-20, -2.9577731e-12),
            vec3(0.0, -1.6723203e-25, -32.0),
            164.0,
        ),
        Ray::new(vec3(-8.718356e-20, 0.25, 0.0), vec3(1e-25, 0.0, 1.0)),
        Ray::new(vec3(8.718356e-20, 0.25, 0.0), vec3(-1e-25, 0.0, -1.0)),
    ];
    let check = |mut i: AnyIndex<u32>| {
        let mut b = BruteForce::new();
        for (k, s) in spheres.iter().enumerate() {
            i.insert(*s, k as u32).unwrap();
            b.insert(*s, k as u32).unwrap();
        }
        let mut hits = 0;
        for ray in &rays {
            let key = |j: &dyn SpatialIndex<u32>, v: Vec<proxima::broad::RayHit>| {
                let mut v: Vec<_> = v
                    .iter()
                    .map(|h| (*j.get(h.handle).unwrap().1, h.t.to_bits()))
                    .collect();
                v.sort();
                v
            };
            let want = key(&b, b.ray_hits(ray).unwrap());
            hits += want.len();
            assert_eq!(key(&i, i.ray_hits(ray).unwrap()), want, "{ray:?}");
            let first = |h: Option<proxima::broad::RayHit>| h.map(|h| h.t.to_bits());
            assert_eq!(
                first(i.ray_first(ray, None).unwrap()),
                first(b.ray_first(ray, None).unwrap()),
                "{ray:?}"
            );
        }
        assert!(hits >= 8, "the rays must hit ({hits})");
    };
    check(AnyIndex::Grid2d(UniformGrid2d::new(w, 2.0).unwrap()));
    check(AnyIndex::Grid3d(UniformGrid3d::new(w, 2.0).unwrap()));
    check(AnyIndex::HashGrid(HashGrid::new(2.0).unwrap()));
    check(AnyIndex::HashGrid(
        HashGrid::with_config(HashGridConfig { cell_size: 4.0 }).unwrap(),
    ));
}
