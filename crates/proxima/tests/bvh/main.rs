//! BVH tests against brute force: structure, traversal, collision, ray casts, refit.

mod meshes;
mod rays;
mod real;

use meshes::*;
use proxima::geom::{Aabb, Ray, Segment, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{
    ray_triangle, triangles_intersect, BoundingVolume, BuildOptions, Bvh, Collider, Kdop14, Kdop18,
    Kdop26, Mesh, Obb, RayBvh, RotationUpdate, SplitRule, TriMesh,
};
use proxima::Error;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const SPLITS: [SplitRule; 3] = [SplitRule::Mean, SplitRule::Median, SplitRule::Sah];

fn opts(split: SplitRule, leaf_size: usize) -> BuildOptions {
    BuildOptions { split, leaf_size }
}

/// A stand-in triangle predicate that implies a shared point: some edge of one
/// triangle crosses the other (with the watertight ray–triangle test). Used to check
/// the traversal's culling before and independently of the exact triangle test.
fn edge_crosses(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    let crosses = |p: &[Vec3; 3], q: &[Vec3; 3]| {
        (0..3).any(|i| {
            let (s, e) = (p[i], p[(i + 1) % 3]);
            s != e && ray_triangle(&Segment::new(s, e).to_ray(), q).is_some()
        })
    };
    crosses(a, b) || crosses(b, a)
}

fn moved(m: &TriMesh, pose: &Affine3A, i: usize) -> [Vec3; 3] {
    m.triangle(i).map(|v| pose.transform_point3(v))
}

fn brute_pairs(
    a: &TriMesh,
    pose: &Affine3A,
    b: &TriMesh,
    test: impl Fn(&[Vec3; 3], &[Vec3; 3]) -> bool,
) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for i in 0..a.len() {
        let ta = moved(a, pose, i);
        for j in 0..b.len() {
            if test(&ta, &b.triangle(j)) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

fn sorted(mut v: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
    v.sort_unstable();
    v
}

fn check_structure<BV: BoundingVolume>(m: &TriMesh) {
    for split in SPLITS {
        for leaf in [1, 3, 8] {
            let t = Bvh::<BV>::build(m, opts(split, leaf)).unwrap();
            t.validate(m).unwrap();
            if split == SplitRule::Median {
                let bound = ((m.len() as f64 / leaf as f64).log2().ceil() as usize) + 2;
                assert!(t.depth() <= bound, "{} depth {}", BV::NAME, t.depth());
            }
        }
    }
}

#[test]
fn structure_every_bv_and_split() {
    for m in [
        uv_sphere(Vec3::ZERO, 2.0, 16, 10),
        torus(3.0, 1.0, 20, 12),
        terrain(5.0, 12, 1),
    ] {
        check_structure::<Aabb>(&m);
        check_structure::<Kdop14>(&m);
        check_structure::<Kdop18>(&m);
        check_structure::<Kdop26>(&m);
        check_structure::<Obb>(&m);
        check_structure::<Sphere>(&m);
    }
    // One triangle, and all-equal centroids.
    let one = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
    let same = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]; 9]).unwrap();
    for m in [one, same] {
        check_structure::<Kdop18>(&m);
        check_structure::<Obb>(&m);
    }
}

#[test]
fn bad_input_is_an_error() {
    let m = torus(3.0, 1.0, 8, 6);
    // A leaf size of 0 is a bad parameter, for every tree and for a mesh.
    assert!(matches!(
        Bvh::<Kdop18>::build(&m, opts(SplitRule::Mean, 0)),
        Err(Error::InvalidParameter(_))
    ));
    assert!(matches!(
        RayBvh::build(&m, opts(SplitRule::Sah, 0)),
        Err(Error::InvalidParameter(_))
    ));
    assert!(matches!(
        Mesh::<Kdop18>::from_trimesh(m.clone(), opts(SplitRule::Sah, 0)),
        Err(Error::InvalidParameter(_))
    ));
    let mut mesh = Mesh::<Kdop18>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
    assert!(matches!(
        mesh.clone().with_ray_options(opts(SplitRule::Sah, 0)),
        Err(Error::InvalidParameter(_))
    ));
    // A failed deformation changes nothing (geometry, both trees).
    mesh.ray_bvh();
    let before = mesh.bvh().nodes().to_vec();
    let ray_before = mesh.ray_bvh().bounds();
    assert!(mesh.set_vertices(&m.vertices()[1..]).is_err());
    let mut nan = m.vertices().to_vec();
    nan[3].x = f32::NAN;
    assert!(mesh.set_vertices(&nan).is_err());
    assert_eq!(mesh.bvh().nodes(), &before[..]);
    assert_eq!(mesh.ray_bvh().bounds(), ray_before);
    assert_eq!(mesh.trimesh(), &m);
    let mut c = Collider::<Kdop18>::default();
    let bad = [
        Affine3A::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)),
        Affine3A::from_scale(Vec3::splat(2.0)),
        Affine3A::from_scale(Vec3::new(1.0, 1.0, -1.0)),
    ];
    for p in bad {
        assert!(matches!(
            c.all_pairs_with(&mesh, &p, &mesh, edge_crosses),
            Err(Error::InvalidPose(_))
        ));
        assert!(matches!(
            mesh.collide(&p, &mesh),
            Err(Error::InvalidPose(_))
        ));
        assert!(matches!(
            mesh.collide_first(&p, &mesh),
            Err(Error::InvalidPose(_))
        ));
    }
    // The low-level tree refuses any mesh but its own: another mesh (even with as
    // many vertices), or its own deformed and not refit; a clone is its own.
    let mut t = Bvh::<Kdop18>::build(&m, BuildOptions::default()).unwrap();
    let before = t.nodes().to_vec();
    let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.1, 0.2, -1.0));
    for other in [torus(3.0, 1.0, 9, 6), torus(3.0, 1.1, 8, 6)] {
        assert!(matches!(
            t.cast_ray(&other, &ray),
            Err(Error::MeshMismatch(_))
        ));
        assert!(t.intersects_ray(&other, &ray).is_err());
        assert!(t.validate(&other).is_err());
        assert!(RayBvh::from_bvh(&t, &other).is_err());
        assert!(matches!(t.refit(&other), Err(Error::MeshMismatch(_))));
        assert_eq!(t.nodes(), &before[..]);
    }
    assert!(t.cast_ray(&m.clone(), &ray).is_ok());
    let mut moved = m.clone();
    let v: Vec<Vec3> = m.vertices().iter().map(|&p| p * 1.5).collect();
    moved.set_vertices(&v).unwrap();
    assert!(matches!(
        t.cast_ray(&moved, &ray),
        Err(Error::MeshMismatch(_))
    ));
    assert!(t.cast_ray(&m, &ray).is_ok());
    t.refit(&moved).unwrap();
    t.validate(&moved).unwrap();
    assert!(t.cast_ray(&m, &ray).is_err());
    assert!(t.cast_ray(&moved, &ray).is_ok());
    assert!(t.cast_ray(&m, &Ray::new(Vec3::ZERO, Vec3::ZERO)).is_err());
    assert!(mesh.cast_ray(&Ray::new(Vec3::ZERO, Vec3::ZERO)).is_err());
    assert!(mesh
        .intersects_ray(&Ray::with_max_t(Vec3::ZERO, Vec3::X, -1.0))
        .is_err());
    assert!(mesh
        .cast_segment(&Segment::new(Vec3::ONE, Vec3::ONE))
        .is_err());
}

/// The culling of every BV type, split rule, rotation update and leaf size keeps
/// every pair the stand-in predicate finds by brute force, at random poses near
/// contact (translations, rotations, and pure translations).
fn traversal_matches_brute<BV: BoundingVolume>(seed: u64, poses: usize) {
    let a = torus(2.0, 0.6, 18, 10);
    let b = terrain(4.0, 14, seed);
    let mut rng = Pcg64::seed_from_u64(seed);
    let meshes: Vec<(Mesh<BV>, Mesh<BV>)> = SPLITS
        .iter()
        .flat_map(|&s| [1, 4].map(move |l| opts(s, l)))
        .map(|o| {
            (
                Mesh::from_trimesh(a.clone(), o).unwrap(),
                Mesh::from_trimesh(b.clone(), o).unwrap(),
            )
        })
        .collect();
    let mut total = 0;
    for k in 0..poses {
        let mut pose = random_pose(
            &mut rng,
            Vec3::new(-3.0, -3.0, -1.0),
            Vec3::new(3.0, 3.0, 1.0),
        );
        if k % 4 == 0 {
            pose.matrix3 = proxima::glam::Mat3A::IDENTITY;
        }
        let want = brute_pairs(&a, &pose, &b, edge_crosses);
        total += want.len();
        for (ma, mb) in &meshes {
            for rot in [RotationUpdate::Refit, RotationUpdate::Conservative] {
                let mut c = Collider::<BV>::new(rot);
                let got = c.all_pairs_with(ma, &pose, mb, edge_crosses).unwrap();
                assert_eq!(
                    sorted(got.pairs.clone()),
                    want,
                    "{} {:?} pose {k}",
                    BV::NAME,
                    ma.bvh().options()
                );
                assert!(got.counters.np >= want.len() as u64);
                assert!(got.counters.np <= (a.len() * b.len()) as u64);
            }
        }
    }
    assert!(
        total > poses,
        "poses too far apart to test anything: {total}"
    );
}

#[test]
fn traversal_aabb() {
    traversal_matches_brute::<Aabb>(1, 40);
}
#[test]
fn traversal_kdop14() {
    traversal_matches_brute::<Kdop14>(2, 40);
}
#[test]
fn traversal_kdop18() {
    traversal_matches_brute::<Kdop18>(3, 40);
}
#[test]
fn traversal_kdop26() {
    traversal_matches_brute::<Kdop26>(4, 40);
}
#[test]
fn traversal_obb() {
    traversal_matches_brute::<Obb>(5, 40);
}
#[test]
fn traversal_sphere() {
    traversal_matches_brute::<Sphere>(6, 40);
}

/// Closest hit by brute force: smallest t, ties to the smaller triangle index.
fn brute_ray(m: &TriMesh, ray: &Ray) -> Option<(u32, f32)> {
    let mut best: Option<(u32, f32)> = None;
    for i in 0..m.len() {
        if let Some(h) = ray_triangle(ray, &m.triangle(i)) {
            if best.is_none_or(|(_, t)| h.t < t) {
                best = Some((i as u32, h.t));
            }
        }
    }
    best
}

fn rays_match_brute<BV: BoundingVolume>(m: &TriMesh, seed: u64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    for split in SPLITS {
        let t = Bvh::<BV>::build(m, opts(split, 2)).unwrap();
        let mut hits = 0;
        for _ in 0..300 {
            let o = Vec3::new(
                rng.gen_range(-6.0..6.0),
                rng.gen_range(-6.0..6.0),
                rng.gen_range(-6.0..6.0),
            );
            let target = Vec3::new(
                rng.gen_range(-2.0..2.0),
                rng.gen_range(-2.0..2.0),
                rng.gen_range(-1.0..1.0),
            );
            let max_t = if rng.gen_bool(0.5) {
                f32::INFINITY
            } else {
                rng.gen_range(0.2..1.5)
            };
            let ray = Ray::with_max_t(o, target - o, max_t);
            let want = brute_ray(m, &ray);
            let got = t.cast_ray(m, &ray).unwrap();
            assert_eq!(got.map(|h| (h.triangle, h.t)), want, "{}", BV::NAME);
            if let Some(h) = got {
                hits += 1;
                let [p, q, r] = m.triangle(h.triangle as usize);
                let on_tri = p * (1.0 - h.u - h.v) + q * h.u + r * h.v;
                assert!((on_tri - ray.at(h.t)).length() < 1e-3);
            }
            assert_eq!(t.intersects_ray(m, &ray).unwrap(), want.is_some());
            if max_t == 1.0 {
                let s = Segment::new(o, target);
                assert_eq!(
                    t.cast_segment(m, &s).unwrap().map(|h| h.triangle),
                    want.map(|w| w.0)
                );
            }
        }
        assert!(hits > 30, "{hits}");
    }
}

#[test]
fn ray_casts_match_brute_force() {
    for (i, m) in [
        torus(2.0, 0.6, 24, 12),
        terrain(4.0, 16, 9),
        uv_sphere(Vec3::ZERO, 1.5, 12, 8),
    ]
    .iter()
    .enumerate()
    {
        let s = i as u64 * 10;
        rays_match_brute::<Aabb>(m, s);
        rays_match_brute::<Kdop14>(m, s + 1);
        rays_match_brute::<Kdop18>(m, s + 2);
        rays_match_brute::<Kdop26>(m, s + 3);
        rays_match_brute::<Obb>(m, s + 4);
        rays_match_brute::<Sphere>(m, s + 5);
    }
}

/// Deform (through the mesh, which refits both its trees), and check structure,
/// rays and collisions against brute force.
fn refit_after_deformation<BV: BoundingVolume>(seed: u64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let a = torus(2.0, 0.6, 16, 10);
    let b = terrain(4.0, 12, seed);
    let mb = Mesh::<BV>::from_trimesh(b.clone(), BuildOptions::default()).unwrap();
    let mut ma = Mesh::<BV>::from_trimesh(a, opts(SplitRule::Sah, 2)).unwrap();
    // Built now, so every step refits it.
    ma.ray_bvh();
    for step in 0..8 {
        let v: Vec<Vec3> = ma
            .trimesh()
            .vertices()
            .iter()
            .map(|&p| {
                p * (1.0 + 0.05 * (p.z + step as f32).sin())
                    + Vec3::new(0.0, 0.0, rng.gen_range(-0.1..0.1))
            })
            .collect();
        ma.set_vertices(&v).unwrap();
        let a = ma.trimesh();
        assert_eq!(a.vertices(), &v[..]);
        ma.bvh().validate(a).unwrap();
        let mut c = Collider::<BV>::default();
        for _ in 0..5 {
            let pose = random_pose(
                &mut rng,
                Vec3::new(-2.0, -2.0, -0.5),
                Vec3::new(2.0, 2.0, 0.5),
            );
            let want = brute_pairs(a, &pose, &b, edge_crosses);
            let got = c.all_pairs_with(&ma, &pose, &mb, edge_crosses).unwrap();
            assert_eq!(sorted(got.pairs), want);
        }
        let ray = Ray::new(Vec3::new(5.0, 0.3, 0.2), Vec3::new(-1.0, 0.01, 0.0));
        let want = brute_ray(a, &ray);
        assert_eq!(
            ma.bvh()
                .cast_ray(a, &ray)
                .unwrap()
                .map(|h| (h.triangle, h.t)),
            want
        );
        assert_eq!(ma.cast_ray(&ray).unwrap().map(|h| (h.triangle, h.t)), want);
        // The bounds follow the vertices.
        let s = ma.bounding_sphere();
        for p in &v {
            assert!(ma.aabb().contains_point(*p));
            assert!(p.as_dvec3().distance(s.center.as_dvec3()) <= s.radius as f64);
        }
    }
}

#[test]
fn refit_every_bv() {
    refit_after_deformation::<Aabb>(1);
    refit_after_deformation::<Kdop14>(2);
    refit_after_deformation::<Kdop18>(3);
    refit_after_deformation::<Kdop26>(4);
    refit_after_deformation::<Obb>(5);
    refit_after_deformation::<Sphere>(6);
}

/// Exact collision (all pairs and first contact) against brute force with
/// `triangles_intersect`, for every BV type, split rule and rotation update.
fn exact_matches_brute<BV: BoundingVolume>(a: &TriMesh, b: &TriMesh, poses: &[Affine3A]) -> usize {
    let meshes: Vec<(Mesh<BV>, Mesh<BV>)> = SPLITS
        .iter()
        .flat_map(|&s| [1, 3].map(move |l| opts(s, l)))
        .map(|o| {
            (
                Mesh::from_trimesh(a.clone(), o).unwrap(),
                Mesh::from_trimesh(b.clone(), o).unwrap(),
            )
        })
        .collect();
    let mut nonempty = 0;
    for (k, pose) in poses.iter().enumerate() {
        let want = brute_pairs(a, pose, b, triangles_intersect);
        nonempty += !want.is_empty() as usize;
        for (ma, mb) in &meshes {
            // The one-shot forms are the collider's with `RotationUpdate::Auto`.
            let once = ma.collide(pose, mb).unwrap();
            assert_eq!(sorted(once.pairs), want, "{} collide pose {k}", BV::NAME);
            let once = ma.collide_first(pose, mb).unwrap();
            assert_eq!(once.pair.is_some(), !want.is_empty());
            for rot in [
                RotationUpdate::Refit,
                RotationUpdate::Conservative,
                RotationUpdate::Auto,
            ] {
                let mut c = Collider::<BV>::new(rot);
                let got = c.all_pairs(ma, pose, mb).unwrap();
                assert_eq!(
                    sorted(got.pairs),
                    want,
                    "{} {:?} {rot:?} pose {k}",
                    BV::NAME,
                    ma.bvh().options()
                );
                let first = c.first_contact(ma, pose, mb).unwrap();
                assert_eq!(first.pair.is_some(), !want.is_empty());
                if let Some(p) = first.pair {
                    assert!(want.binary_search(&p).is_ok());
                }
                assert!(first.counters.np <= got.counters.np);
            }
        }
    }
    nonempty
}

fn exact_every_bv(a: &TriMesh, b: &TriMesh, poses: &[Affine3A]) {
    let n = exact_matches_brute::<Aabb>(a, b, poses);
    assert!(
        n * 4 >= poses.len(),
        "only {n} of {} poses in contact",
        poses.len()
    );
    exact_matches_brute::<Kdop14>(a, b, poses);
    exact_matches_brute::<Kdop18>(a, b, poses);
    exact_matches_brute::<Kdop26>(a, b, poses);
    exact_matches_brute::<Obb>(a, b, poses);
    exact_matches_brute::<Sphere>(a, b, poses);
}

#[test]
fn exact_collision_procedural() {
    let mut rng = Pcg64::seed_from_u64(77);
    let a = torus(2.0, 0.6, 14, 8);
    let b = terrain(4.0, 10, 3);
    let poses: Vec<Affine3A> = (0..25)
        .map(|_| {
            random_pose(
                &mut rng,
                Vec3::new(-3.0, -3.0, -0.8),
                Vec3::new(3.0, 3.0, 0.8),
            )
        })
        .collect();
    exact_every_bv(&a, &b, &poses);
}

#[test]
fn exact_collision_touching_and_coplanar() {
    // The same mesh at the identity (every triangle touches itself and its
    // neighbours, coplanar), shifted by exactly one grid step (shared edges), and
    // rotated by 90° about z onto itself.
    let m = terrain(2.0, 6, 5);
    let step = 4.0 / 6.0;
    let poses = [
        Affine3A::IDENTITY,
        Affine3A::from_translation(Vec3::new(step, 0.0, 0.0)),
        Affine3A::from_translation(Vec3::new(4.0, 0.0, 0.0)),
        Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2),
    ];
    exact_every_bv(&m, &m, &poses);
    let s = uv_sphere(Vec3::ZERO, 1.0, 10, 6);
    let poses = [
        Affine3A::IDENTITY,
        Affine3A::from_translation(Vec3::new(2.0, 0.0, 0.0)),
        Affine3A::from_translation(Vec3::new(1.9, 0.1, 0.0)),
    ];
    exact_every_bv(&s, &s, &poses);
}

/// A mesh at the identity touches itself (every triangle meets itself, closed),
/// whatever its scale: near `f32::MAX`, tiny, degenerate (points and segments).
/// Its bounds contain it, and its ray cast agrees with brute force.
#[test]
fn meshes_of_every_scale_touch_themselves() {
    let big = f32::MAX / 4.0;
    let cases = [
        vec![
            Vec3::splat(-big),
            Vec3::new(big, 0.0, 0.0),
            Vec3::new(0.0, big, big),
        ],
        vec![Vec3::splat(1e30), Vec3::new(-1e30, 1.0, 0.0), Vec3::Z],
        vec![
            Vec3::splat(1e-30),
            Vec3::new(2e-30, 0.0, 0.0),
            Vec3::new(0.0, 1e-38, 0.0),
        ],
        // Degenerate: a point and a segment.
        vec![Vec3::ONE, Vec3::ONE, Vec3::ONE],
        vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
    ];
    for (k, v) in cases.iter().enumerate() {
        let tris = vec![[0, 1, 2], [2, 1, 0], [1, 1, 2]];
        let m = TriMesh::new(v.clone(), tris).unwrap();
        let mesh = Mesh::<Kdop18>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
        mesh.bvh().validate(mesh.trimesh()).unwrap();
        let want = brute_pairs(&m, &Affine3A::IDENTITY, &m, triangles_intersect);
        assert!((0..3).all(|i| want.contains(&(i, i))), "case {k}");
        let got = mesh.collide(&Affine3A::IDENTITY, &mesh).unwrap();
        assert_eq!(sorted(got.pairs), want, "case {k}");
        assert!(mesh
            .collide_first(&Affine3A::IDENTITY, &mesh)
            .unwrap()
            .pair
            .is_some());
        let s = mesh.bounding_sphere();
        for p in v {
            assert!(mesh.aabb().contains_point(*p), "case {k}");
            assert!(p.as_dvec3().distance(s.center.as_dvec3()) <= s.radius as f64);
        }
        let c = mesh.aabb().center();
        let ray = Ray::new(c + Vec3::new(0.3, 0.2, 1.0), Vec3::new(-0.3, -0.2, -1.0));
        let hit = mesh.cast_ray(&ray).unwrap().map(|h| (h.triangle, h.t));
        assert_eq!(hit, brute_ray(&m, &ray), "case {k}");
    }
}
