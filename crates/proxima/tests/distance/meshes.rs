//! Mesh–mesh distance, `within` and pairs within a margin against brute force
//! over all triangle pairs, for every bounding volume, on the shared meshes at
//! random, touching and intersecting poses, and on constructed meshes with
//! parallel faces, shared corners and degenerate triangles.

use super::common::*;
use super::reference::{point_triangle, triangle_triangle};
use super::shapes::{cube, degenerate_only, with_degenerate};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Mat3, Vec3};
use proxima::narrow::{
    triangle_distance, BoundingVolume, BuildOptions, Collider, Kdop14, Kdop18, Kdop26, Mesh, Obb,
    Proximity, RotationUpdate, SplitRule, TriMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// What brute force says about one pose.
struct Want {
    pose: Affine3A,
    /// The minimum [`triangle_distance`] over all pairs.
    distance: f64,
    /// Every pair at that distance.
    at: Vec<(u32, u32)>,
    posed: Vec<[Vec3; 3]>,
    /// Tolerance for points: 1e-9 of the scene's extent.
    tol: f64,
    /// Checked against brute force of pairs within this margin, if any.
    margin: Option<(f64, Vec<(u32, u32)>)>,
}

fn wants(a: &TriMesh, b: &TriMesh, poses: &[Affine3A], margins: usize) -> Vec<Want> {
    let tb = triangles(b);
    poses
        .iter()
        .enumerate()
        .map(|(k, pose)| {
            let ta = posed(a, pose);
            let (distance, at) = brute_nearest(&ta, &tb, |x, y| triangle_distance(x, y).distance);
            let ext = extent(&ta).max(extent(&tb));
            let margin = (k < margins).then(|| {
                let m = distance + 0.02 * ext;
                (m, brute_within(&ta, &tb, m))
            });
            Want {
                pose: *pose,
                distance,
                at,
                posed: ta,
                tol: 1e-9 * ext.max(1.0),
                margin,
            }
        })
        .collect()
}

/// The previous `f64` (for a positive finite `x`).
fn below(x: f64) -> f64 {
    f64::from_bits(x.to_bits() - 1)
}

/// Every query on every pose with one volume type, both rotation updates, and
/// two tree shapes, one query object reused throughout.
fn check<BV: BoundingVolume>(a: &TriMesh, b: &TriMesh, wants: &[Want]) {
    let tb_tris = triangles(b);
    let builds = [
        BuildOptions::default(),
        BuildOptions {
            split: SplitRule::Median,
            leaf_size: 4,
        },
    ];
    for o in builds {
        let (ta, tb) = (
            Mesh::<BV>::from_trimesh(a.clone(), o).unwrap(),
            Mesh::<BV>::from_trimesh(b.clone(), o).unwrap(),
        );
        let mut col = Collider::<BV>::default();
        for rot in [
            RotationUpdate::Auto,
            RotationUpdate::Conservative,
            RotationUpdate::Refit,
        ] {
            let mut q = Proximity::<BV>::new(rot);
            for (k, w) in wants.iter().enumerate() {
                let ctx = format!("{} {:?} {rot:?} pose {k}", BV::NAME, o.split);
                let got = q.distance(&ta, &w.pose, &tb).unwrap();
                assert_eq!(got.distance, w.distance, "{ctx}");
                assert!(w.at.contains(&got.triangles), "{ctx}: {:?}", got.triangles);
                let (i, j) = got.triangles;
                let [p, r] = got.points;
                let (ti, tj) = (
                    w.posed[i as usize].map(|v| v.as_dvec3()),
                    tb_tris[j as usize].map(|v| v.as_dvec3()),
                );
                assert!(
                    point_triangle(p, ti) <= w.tol,
                    "{ctx}: point off its triangle"
                );
                assert!(
                    point_triangle(r, tj) <= w.tol,
                    "{ctx}: point off its triangle"
                );
                assert!((p.distance(r) - got.distance).abs() <= w.tol, "{ctx}");
                assert!(got.counters.np > 0 && got.counters.nv > 0, "{ctx}");
                // Contact iff the collider finds one.
                let hit = col.first_contact(&ta, &w.pose, &tb).unwrap();
                assert_eq!(hit.pair.is_some(), w.distance == 0.0, "{ctx}");
                // `within` agrees with the distance on both sides of it.
                let d = w.distance;
                assert!(q.within(&ta, &w.pose, &tb, d).unwrap(), "{ctx}");
                assert!(q.within(&ta, &w.pose, &tb, d * 2.0 + 1.0).unwrap());
                if d > 0.0 {
                    assert!(!q.within(&ta, &w.pose, &tb, below(d)).unwrap(), "{ctx}");
                    assert!(!q.within(&ta, &w.pose, &tb, d * 0.5).unwrap());
                }
                if let Some((m, pairs)) = &w.margin {
                    let near = q.pairs_within(&ta, &w.pose, &tb, *m).unwrap();
                    let mut got: Vec<(u32, u32)> = near.pairs.iter().map(|p| p.triangles).collect();
                    got.sort_unstable();
                    assert_eq!(&got, pairs, "{ctx}: pairs within {m}");
                    for p in &near.pairs {
                        let (x, y) = p.triangles;
                        let want = triangle_distance(&w.posed[x as usize], &tb_tris[y as usize]);
                        assert_eq!(p.distance, want.distance, "{ctx}");
                    }
                    // Margin 0: exactly the collider's pairs.
                    let mut zero: Vec<(u32, u32)> = q
                        .pairs_within(&ta, &w.pose, &tb, 0.0)
                        .unwrap()
                        .pairs
                        .iter()
                        .map(|p| p.triangles)
                        .collect();
                    zero.sort_unstable();
                    let mut all = col.all_pairs(&ta, &w.pose, &tb).unwrap().pairs;
                    all.sort_unstable();
                    assert_eq!(zero, all, "{ctx}");
                }
            }
        }
    }
}

fn check_all(a: &TriMesh, b: &TriMesh, wants: &[Want]) {
    check::<Aabb>(a, b, wants);
    check::<Kdop14>(a, b, wants);
    check::<Kdop18>(a, b, wants);
    check::<Kdop26>(a, b, wants);
    check::<Obb>(a, b, wants);
    check::<Sphere>(a, b, wants);
}

/// Random poses around `b`, then for some of the apart ones the same pose moved
/// along the nearest points' direction to within `1e-3` and `1e-6` of their
/// distance (near contact: tiny positive distances, or contact within rounding)
/// and a little past them (intersecting).
fn poses_with_contacts(a: &TriMesh, b: &TriMesh, n: usize, seed: u64) -> Vec<Affine3A> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut poses = poses_around(a, b, n, 0.2..1.3, &mut rng);
    let mut q = Proximity::<Kdop18>::default();
    let o = BuildOptions::default();
    let (ta, tb) = (
        Mesh::from_trimesh(a.clone(), o).unwrap(),
        Mesh::from_trimesh(b.clone(), o).unwrap(),
    );
    let mut extra = Vec::new();
    for p in poses.iter().take(n / 2) {
        let d = q.distance(&ta, p, &tb).unwrap();
        if d.distance > 0.0 {
            let step = (d.points[1] - d.points[0]).as_vec3();
            for f in [1.0 - 1e-3, 1.0 - 1e-6, 1.02] {
                extra.push(Affine3A::from_translation(step * f) * *p);
            }
        }
    }
    poses.extend(extra);
    poses
}

fn summary(wants: &[Want]) -> (usize, usize) {
    let zero = wants.iter().filter(|w| w.distance == 0.0).count();
    (zero, wants.len() - zero)
}

#[test]
fn rob_vs_env() {
    let (rob, env) = (data("rob.obj"), data("env.obj"));
    let mut rng = Pcg64::seed_from_u64(15);
    // FCL's distribution (mostly apart from env's parts) and near poses.
    let mut poses: Vec<Affine3A> = (0..16)
        .map(|_| {
            Affine3A::from_rotation_translation(
                random_rotation(&mut rng),
                Vec3::new(
                    rng.gen_range(-3000.0..3000.0),
                    rng.gen_range(-3000.0..3000.0),
                    rng.gen_range(0.0..3000.0),
                ),
            )
        })
        .collect();
    poses.extend(poses_with_contacts(&rob, &env, 16, 16));
    let w = wants(&rob, &env, &poses, 8);
    let (zero, apart) = summary(&w);
    assert!(zero >= 4 && apart >= 10, "{zero} {apart}");
    // Some poses are in near contact: apart by less than 1e-3 of the extent.
    let near = w
        .iter()
        .filter(|w| w.distance > 0.0 && w.distance < 5.0)
        .count();
    assert!(near >= 2, "{near} poses in near contact");
    check_all(&rob, &env, &w);
}

#[test]
fn bunny_vs_bunny() {
    let bunny = data("bunny.obj");
    let poses = poses_with_contacts(&bunny, &bunny, 6, 17);
    let w = wants(&bunny, &bunny, &poses, 2);
    let (zero, apart) = summary(&w);
    assert!(zero >= 2 && apart >= 2, "{zero} {apart}");
    check_all(&bunny, &bunny, &w);
}

#[test]
fn teapot_and_arm_links() {
    let (teapot, hand, forearm) = (
        data("teapot.obj"),
        data("hand_3finger.stl"),
        data("forearm.stl"),
    );
    for (k, (a, b)) in [(&teapot, &teapot), (&hand, &forearm), (&forearm, &teapot)]
        .into_iter()
        .enumerate()
    {
        let poses = poses_with_contacts(a, b, 8, 20 + k as u64);
        let w = wants(a, b, &poses, 3);
        let (zero, apart) = summary(&w);
        assert!(zero >= 2 && apart >= 2, "{zero} {apart}");
        check_all(a, b, &w);
    }
}

#[test]
fn independent_reference_on_small_pairs() {
    // The brute force above uses the library's triangle distance; here the
    // minimum comes from the independent reference (1e-5 of the scene's extent).
    let (rob, hand, teapot) = (
        data("rob.obj"),
        data("hand_3finger.stl"),
        data("teapot.obj"),
    );
    for (k, (a, b)) in [(&rob, &teapot), (&hand, &rob)].into_iter().enumerate() {
        let poses = poses_with_contacts(a, b, 4, 30 + k as u64);
        let (ta, tb) = (
            Mesh::<Obb>::from_trimesh(a.clone(), BuildOptions::default()).unwrap(),
            Mesh::<Obb>::from_trimesh(b.clone(), BuildOptions::default()).unwrap(),
        );
        let mut q = Proximity::default();
        for pose in &poses {
            let (pa, pb) = (posed(a, pose), triangles(b));
            let (want, _) = brute_nearest(&pa, &pb, triangle_triangle);
            let got = q.distance(&ta, pose, &tb).unwrap();
            let ext = extent(&pa).max(extent(&pb));
            assert!(
                (got.distance - want).abs() <= 1e-5 * ext,
                "{} vs {want}",
                got.distance
            );
        }
    }
}

#[test]
fn big_meshes_complete_brute_force() {
    // The 34k- and 74k-triangle meshes: whole against a small mesh, and patches
    // of both against each other; brute force over every pair of what is tested.
    let (skin, ribs) = (data("SKINbody.stl"), data("BONERibcage.stl"));
    let (rob, hand) = (data("rob.obj"), data("hand_3finger.stl"));
    let mut rng = Pcg64::seed_from_u64(40);
    let small_rob = {
        // rob scaled into the dog's size.
        let (lo, hi) = bounds(&skin);
        let (rl, rh) = bounds(&rob);
        let s = 0.1 * (hi - lo).length() / (rh - rl).length();
        let v = rob.vertices().iter().map(|&p| p * s).collect();
        TriMesh::new(v, rob.triangles().to_vec()).unwrap()
    };
    let poses = poses_around(&small_rob, &skin, 3, 0.05..0.6, &mut rng);
    let w = wants(&small_rob, &skin, &poses, 1);
    check::<Kdop18>(&small_rob, &skin, &w);
    check::<Obb>(&small_rob, &skin, &w);
    let poses = poses_around(&hand, &ribs, 2, 0.05..0.5, &mut rng);
    let w = wants(&hand, &ribs, &poses, 0);
    check::<Kdop26>(&hand, &ribs, &w);
    check::<Sphere>(&hand, &ribs, &w);
    // Patches around a random vertex of each (about 2-3k triangles each).
    let (ls, hs) = bounds(&skin);
    let r = 0.12 * (hs - ls).length();
    let pa = patch(&skin, skin.vertices()[5000], r);
    let pb = patch(&ribs, ribs.vertices()[20000], r);
    assert!(
        pa.len() > 500 && pb.len() > 500,
        "{} {}",
        pa.len(),
        pb.len()
    );
    let poses = poses_with_contacts(&pa, &pb, 4, 41);
    let w = wants(&pa, &pb, &poses, 1);
    check::<Aabb>(&pa, &pb, &w);
    check::<Kdop14>(&pa, &pb, &w);
}

#[test]
fn degenerate_triangles() {
    let (rob, env) = (data("rob.obj"), data("env.obj"));
    let a = with_degenerate(&rob, 5);
    let dots = degenerate_only(&rob, 3);
    let mut rng = Pcg64::seed_from_u64(50);
    let mut poses = poses_around(&a, &a, 8, 0.1..1.2, &mut rng);
    poses.extend(poses_with_contacts(&a, &env, 6, 51));
    let w = wants(&a, &a, &poses[..8], 2);
    check_all(&a, &a, &w);
    let w = wants(&a, &env, &poses[8..], 2);
    check_all(&a, &env, &w);
    let w = wants(&dots, &env, &poses[8..], 2);
    check_all(&dots, &env, &w);
}

#[test]
fn cubes_with_parallel_faces_and_shared_corners() {
    // Exact coordinates and exact poses (translations and quarter turns): the
    // answers are known in closed form.
    let (a, b) = (cube(4, 1.0), cube(3, 1.0));
    let quarter = Mat3::from_cols(Vec3::Y, -Vec3::X, Vec3::Z);
    let cases: [(Vec3, bool, f64); 9] = [
        (Vec3::new(2.0, 0.0, 0.0), false, 1.0), // parallel faces 1 apart
        (Vec3::new(1.0, 0.0, 0.0), false, 0.0), // shared face
        (Vec3::new(1.0, 1.0, 1.0), false, 0.0), // shared corner
        (Vec3::new(1.0, 1.0, 0.0), false, 0.0), // shared edge
        (Vec3::new(2.0, 2.0, 2.0), false, 3f64.sqrt()), // corner to corner
        (Vec3::new(1.5, 0.25, 0.5), false, 0.5), // faces overlapping, 0.5 apart
        (Vec3::new(0.5, 0.5, 0.5), false, 0.0), // intersecting
        (Vec3::new(3.0, 1.0, 0.0), true, 1.0),  // turned: x in [2, 3]
        (Vec3::new(1.0, 0.0, 4.0), true, 3.0),  // turned, stacked 3 apart
    ];
    let mut poses = Vec::new();
    for (t, turned, want) in cases {
        let m = if turned { quarter } else { Mat3::IDENTITY };
        let pose = Affine3A::from_mat3_translation(m, t);
        let (ta, tb) = (posed(&a, &pose), triangles(&b));
        let (d, _) = brute_nearest(&ta, &tb, |x, y| triangle_distance(x, y).distance);
        assert!(
            (d - want).abs() < 1e-12,
            "{t}: brute force {d}, want {want}"
        );
        poses.push(pose);
    }
    let w = wants(&a, &b, &poses, poses.len());
    check_all(&a, &b, &w);
}

#[test]
fn huge_coordinates() {
    // Regression: beyond √f32::MAX ≈ 1.8e19 squared distances overflow f32; a
    // sphere volume's fit and distance bound did (an infinite radius, an
    // infinite "lower bound"). Every volume finds brute force's answers.
    let quarter = Mat3::from_cols(Vec3::Y, -Vec3::X, Vec3::Z);
    for s in [2e19f32, 1e30, 1e37] {
        let (a, b) = (cube(2, s), cube(3, s));
        let poses = [
            Affine3A::from_translation(Vec3::new(1.5 * s, 0.25 * s, 0.0)), // s/2 apart
            Affine3A::from_translation(Vec3::new(s, 0.0, 0.0)),            // shared face
            Affine3A::from_translation(Vec3::splat(0.5 * s)),              // intersecting
            Affine3A::from_mat3_translation(quarter, Vec3::new(2.5 * s, s, 3.0 * s)),
            Affine3A::from_rotation_translation(
                proxima::glam::Quat::from_rotation_arc(Vec3::X, Vec3::ONE.normalize()),
                Vec3::new(-1.5 * s, 0.5 * s, 0.25 * s),
            ),
        ];
        let w = wants(&a, &b, &poses, poses.len());
        let apart: Vec<f64> = w.iter().map(|w| w.distance / s as f64).collect();
        assert!((apart[0] - 0.5).abs() < 1e-6 && apart[1] == 0.0 && apart[2] == 0.0);
        assert!(apart[3] > 0.5 && apart[4] > 0.1, "{apart:?}");
        check_all(&a, &b, &w);
    }
}

#[test]
fn query_object_reuse_across_meshes() {
    // One query object over different mesh pairs and sizes gives the answers of
    // fresh ones (the per-query caches restart).
    let (rob, env, teapot) = (data("rob.obj"), data("env.obj"), data("teapot.obj"));
    let o = BuildOptions::default();
    let trees: Vec<(Mesh<Kdop18>, &TriMesh)> = [&rob, &env, &teapot]
        .into_iter()
        .map(|m| (Mesh::from_trimesh(m.clone(), o).unwrap(), m))
        .collect();
    let mut rng = Pcg64::seed_from_u64(60);
    let mut shared = Proximity::<Kdop18>::default();
    for _ in 0..30 {
        let (i, j) = (rng.gen_range(0..3), rng.gen_range(0..3));
        let (a, b) = (&trees[i], &trees[j]);
        let pose = poses_around(a.1, b.1, 1, 0.2..1.2, &mut rng)[0];
        let x = shared.distance(&a.0, &pose, &b.0).unwrap();
        let y = Proximity::default().distance(&a.0, &pose, &b.0).unwrap();
        assert_eq!(x.distance, y.distance);
        assert_eq!(x, y);
    }
}
