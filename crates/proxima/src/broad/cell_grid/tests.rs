//! The shared core's traversals against brute force, on both stores: range and
//! frustum queries through the descent from the whole key box (a dense scene)
//! and through the scan of the occupied blocks (clusters far apart), with
//! perspective, orthographic and degenerate frusta (zero-thickness slabs, zero
//! normals, half-spaces, huge and tiny ones), and rays.

use crate::broad::test_util::check_ray;
use crate::broad::{
    BruteForce, Grid2dConfig, HashGrid, HashGridConfig, Query, SpatialIndex, SpatialIndexExt,
    UniformGrid2d,
};
use crate::geom::{Aabb, Frustum, Plane, Ray, Sphere};
use glam::{vec3, Mat4, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::ops::ControlFlow;

/// Payloads of the objects `q` selects, sorted; panics if one is reported twice.
fn selected(index: &impl SpatialIndex<u32>, q: impl Into<Query>) -> Vec<u32> {
    let mut v = Vec::new();
    let _ = index.for_each_in(q, |_, _, &id| {
        v.push(id);
        ControlFlow::Continue(())
    });
    let n = v.len();
    v.sort_unstable();
    v.dedup();
    assert_eq!(n, v.len(), "an object was reported twice");
    v
}

fn point(rng: &mut Pcg64, b: &Aabb) -> Vec3 {
    vec3(
        rng.gen_range(b.min.x..=b.max.x),
        rng.gen_range(b.min.y..=b.max.y),
        rng.gen_range(b.min.z..=b.max.z),
    )
}

/// A camera in `b` looking at another point of `b`: perspective (mostly) or
/// orthographic, with depths from tiny to far beyond the scene.
fn camera(rng: &mut Pcg64, b: &Aabb) -> Frustum {
    let eye = point(rng, b);
    let mut target = point(rng, b);
    if target.distance(eye) < 1e-2 {
        target = eye + Vec3::X;
    }
    let fwd = (target - eye).normalize();
    let up = if fwd.z.abs() > 0.99 { Vec3::Y } else { Vec3::Z };
    let view = Mat4::look_at_rh(eye, target, up);
    let far = [0.5, 20.0, 200.0, 1e6][rng.gen_range(0..4)];
    let proj = if rng.gen_bool(0.75) {
        Mat4::perspective_rh(rng.gen_range(0.05..2.5), rng.gen_range(0.3..3.0), 0.1, far)
    } else {
        let s = rng.gen_range(0.5..40.0);
        Mat4::orthographic_rh(-s, s, -s * 0.5, s * 0.5, 0.0, far)
    };
    Frustum::from_view_projection(proj * view).unwrap()
}

/// Frusta no camera makes: a zero-thickness slab (two opposite planes through
/// one point) cut by four planes or none, zero normals that keep everything or
/// nothing, one half-space six times, and a slab between two parallel planes.
fn degenerate(rng: &mut Pcg64, b: &Aabb) -> Vec<Frustum> {
    let p = point(rng, b);
    let n = vec3(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    )
    .normalize_or(Vec3::Z);
    let plane = |n: Vec3, through: Vec3| Plane::new(n, -n.dot(through));
    let keep = Plane::new(Vec3::ZERO, 0.0);
    let none = Plane::new(Vec3::ZERO, -1.0);
    let m = n.any_orthonormal_vector();
    let w = rng.gen_range(0.0..10.0);
    vec![
        Frustum::from_planes([plane(n, p), plane(-n, p), keep, keep, keep, keep]),
        Frustum::from_planes([
            plane(n, p),
            plane(-n, p),
            plane(m, p - m * w),
            plane(-m, p + m * w),
            keep,
            keep,
        ]),
        Frustum::from_planes([keep; 6]),
        Frustum::from_planes([keep, keep, none, keep, keep, keep]),
        Frustum::from_planes([plane(n, p); 6]),
        Frustum::from_planes([
            plane(n, p - n * w),
            plane(-n, p + n * w),
            keep,
            keep,
            keep,
            keep,
        ]),
        Frustum::from_planes([plane(Vec3::X, p); 6]),
    ]
}

/// Inserts `spheres` into `index` and a brute-force oracle.
fn fill<I: SpatialIndex<u32>>(mut index: I, spheres: &[Sphere]) -> (I, BruteForce<u32>) {
    let mut b = BruteForce::new();
    for (i, s) in spheres.iter().enumerate() {
        index.insert(*s, i as u32).unwrap();
        b.insert(*s, i as u32).unwrap();
    }
    index.validate().unwrap();
    (index, b)
}

/// `n` spheres in `b`, radii mostly in `[0.2, 2]`, some huge (oversized) and
/// some far outside.
fn scatter(rng: &mut Pcg64, b: &Aabb, n: usize) -> Vec<Sphere> {
    (0..n)
        .map(|i| match i % 97 {
            0 => Sphere::new(point(rng, b), rng.gen_range(20.0..60.0)),
            1 => Sphere::new(point(rng, b) * 50.0, rng.gen_range(0.2..2.0)),
            2 => Sphere::new(point(rng, b), 0.0),
            _ => Sphere::new(point(rng, b), rng.gen_range(0.2..2.0)),
        })
        .collect()
}

/// Frusta, big spheres and boxes and rays over `index` against `oracle`.
fn check_all(index: &impl SpatialIndex<u32>, oracle: &BruteForce<u32>, rng: &mut Pcg64, b: &Aabb) {
    for k in 0..60 {
        let f = camera(rng, b);
        assert_eq!(selected(index, f), selected(oracle, f), "camera {k}: {f:?}");
    }
    for f in degenerate(rng, b) {
        assert_eq!(selected(index, f), selected(oracle, f), "{f:?}");
    }
    for _ in 0..30 {
        let c = point(rng, b);
        let s = Sphere::new(c, rng.gen_range(0.0..40.0));
        assert_eq!(selected(index, s), selected(oracle, s), "{s:?}");
        let h = vec3(
            rng.gen_range(0.0..50.0),
            rng.gen_range(0.0..50.0),
            rng.gen_range(0.0..5.0),
        );
        let a = Aabb::new(c - h, c + h);
        assert_eq!(selected(index, a), selected(oracle, a), "{a:?}");
    }
    for k in 0..40 {
        let o = point(rng, b);
        let d = vec3(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        // Vertical (the 2D grid's column walk), tiny, and along an axis.
        let d = match k % 10 {
            0 => vec3(0.0, 0.0, -1.0),
            1 => d * 1e-20,
            2 => Vec3::X,
            _ => d,
        };
        let max_t = [f32::INFINITY, 0.0, 15.0][k % 3];
        let r = Ray::with_max_t(o, d, max_t);
        check_ray(index, oracle, &r);
    }
}

#[test]
fn hash_grid_descent_and_scan_match_brute_force() {
    let mut rng = Pcg64::seed_from_u64(0x6812);
    // Dense: the occupied box has few blocks per occupied one (descent).
    let b = Aabb::new(Vec3::ZERO, vec3(60.0, 60.0, 60.0));
    let spheres = scatter(&mut rng, &b, 3000);
    let (g, o) = fill(
        HashGrid::with_config(HashGridConfig { cell_size: 2.5 }).unwrap(),
        &spheres,
    );
    check_all(&g, &o, &mut rng, &b);
    // Sparse: three clusters far apart (scan of the occupied blocks).
    let mut spheres = Vec::new();
    for shift in [Vec3::ZERO, vec3(5e4, -3e4, 0.0), vec3(0.0, 0.0, 9e4)] {
        let c = Aabb::new(shift, shift + Vec3::splat(30.0));
        spheres.extend(scatter(&mut rng, &c, 400));
    }
    let (g, o) = fill(
        HashGrid::with_config(HashGridConfig { cell_size: 2.5 }).unwrap(),
        &spheres,
    );
    let whole = Aabb::new(Vec3::splat(-10.0), vec3(5e4, 30.0, 9e4));
    check_all(&g, &o, &mut rng, &whole);
    check_all(&g, &o, &mut rng, &Aabb::new(Vec3::ZERO, Vec3::splat(30.0)));
}

#[test]
fn grid2d_descent_matches_brute_force() {
    let mut rng = Pcg64::seed_from_u64(0x2d);
    let b = Aabb::new(Vec3::ZERO, vec3(200.0, 120.0, 8.0));
    let spheres = scatter(&mut rng, &b, 3000);
    let (g, o) = fill(
        UniformGrid2d::with_config(Grid2dConfig {
            world: b,
            cell_size: 3.0,
        })
        .unwrap(),
        &spheres,
    );
    check_all(&g, &o, &mut rng, &b);
}

/// k nearest and sweeps on both stores against brute force (see
/// [`knn_sweep_suite`](crate::broad::test_util::knn_sweep_suite)).
#[test]
fn nearest_and_sweeps_match_brute_force() {
    use crate::broad::test_util::knn_sweep_suite;
    let w = Aabb::new(Vec3::ZERO, vec3(60.0, 60.0, 6.0));
    for seed in 1..3 {
        knn_sweep_suite(HashGrid::new(1.0).unwrap(), w, seed);
        let flat = UniformGrid2d::with_config(Grid2dConfig {
            world: w,
            cell_size: 2.0,
        });
        knn_sweep_suite(flat.unwrap(), w, seed);
        knn_sweep_suite(UniformGrid2d::new(w, 0.0).unwrap(), w, seed);
    }
}
