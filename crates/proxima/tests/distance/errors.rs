//! Bad input gives typed errors, never a panic, and leaves the query object
//! usable.

use super::common::data;
use proxima::geom::Sphere;
use proxima::glam::{Affine3A, Mat3, Vec3};
use proxima::narrow::{
    mesh_distance, meshes_within, BuildOptions, Kdop18, Mesh, Obb, Proximity, TriMesh,
};
use proxima::Error;

#[test]
fn bad_poses_margins_points_and_balls() {
    let rob = data("rob.obj");
    let t = Mesh::<Kdop18>::from_trimesh(rob.clone(), BuildOptions::default()).unwrap();
    let m = &t;
    let good = Affine3A::from_translation(Vec3::new(1e4, 0.0, 0.0));
    let bad_poses = [
        Affine3A::from_translation(Vec3::new(f32::NAN, 0.0, 0.0)),
        Affine3A::from_translation(Vec3::new(0.0, f32::INFINITY, 0.0)),
        Affine3A::from_scale(Vec3::splat(2.0)),
        Affine3A::from_mat3(Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0))),
        Affine3A::from_mat3(Mat3::ZERO),
        Affine3A::from_mat3(Mat3::from_cols(Vec3::X, Vec3::X, Vec3::Z)),
    ];
    let mut q = Proximity::<Kdop18>::default();
    for pose in &bad_poses {
        assert!(
            matches!(q.distance(m, pose, m), Err(Error::InvalidPose(_))),
            "{pose:?}"
        );
        assert!(matches!(
            q.within(m, pose, m, 1.0),
            Err(Error::InvalidPose(_))
        ));
        assert!(matches!(
            q.pairs_within(m, pose, m, 1.0),
            Err(Error::InvalidPose(_))
        ));
        assert!(matches!(
            mesh_distance(m, pose, m),
            Err(Error::InvalidPose(_))
        ));
    }
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(matches!(
            q.within(m, &good, m, bad),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            q.pairs_within(m, &good, m, bad),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            meshes_within(m, &good, m, bad),
            Err(Error::NonFinite { .. })
        ));
    }
    for bad in [-1.0, -1e-300] {
        assert!(matches!(
            q.within(m, &good, m, bad),
            Err(Error::InvalidParameter(_))
        ));
        assert!(matches!(
            q.pairs_within(m, &good, m, bad),
            Err(Error::InvalidParameter(_))
        ));
    }
    for p in [
        Vec3::new(f32::NAN, 0.0, 0.0),
        Vec3::splat(f32::NEG_INFINITY),
    ] {
        assert!(matches!(
            q.closest_point(m, p),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            q.contains_point(m, p),
            Err(Error::NonFinite { .. })
        ));
        let s = Sphere::new(p, 1.0);
        assert!(matches!(
            q.sphere_distance(m, &s),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            q.sphere_overlaps(m, &s),
            Err(Error::NonFinite { .. })
        ));
    }
    let neg = Sphere::new(Vec3::ZERO, -1.0);
    assert!(matches!(
        q.sphere_distance(m, &neg),
        Err(Error::NegativeRadius { .. })
    ));
    assert!(matches!(
        q.sphere_overlaps(m, &neg),
        Err(Error::NegativeRadius { .. })
    ));
    let nan_r = Sphere::new(Vec3::ZERO, f32::NAN);
    assert!(matches!(
        q.sphere_overlaps(m, &nan_r),
        Err(Error::NonFinite { .. })
    ));
    // A tree built over another mesh cannot be passed any more (a `Mesh` owns
    // both); the way to a mismatch is a deformation with another vertex count,
    // which fails, leaving the mesh (and every answer on it) as it was.
    let before = (
        q.distance(m, &good, m).unwrap(),
        q.closest_point(m, Vec3::ZERO).unwrap(),
        q.contains_point(m, Vec3::ZERO).unwrap(),
    );
    let mut deformed = t.clone();
    let fewer = &rob.vertices()[1..];
    assert!(matches!(
        deformed.set_vertices(fewer),
        Err(Error::InvalidMesh(_))
    ));
    let after = (
        q.distance(&deformed, &good, m).unwrap(),
        q.closest_point(&deformed, Vec3::ZERO).unwrap(),
        q.contains_point(&deformed, Vec3::ZERO).unwrap(),
    );
    assert_eq!(before, after);
    // Still usable, and the same as a fresh object.
    let d = q.distance(m, &good, m).unwrap();
    assert_eq!(
        d,
        Proximity::<Kdop18>::default()
            .distance(m, &good, m)
            .unwrap()
    );
    assert!(d.distance > 0.0);
}

#[test]
fn slightly_imperfect_rotations_are_accepted() {
    // A rotation rounded to f32 (within check_pose's tolerance) works, for
    // oriented volumes too.
    let rob = data("rob.obj");
    let t = Mesh::<Obb>::from_trimesh(rob.clone(), BuildOptions::default()).unwrap();
    let r = Mat3::from_rotation_z(0.3) * (1.0 + 2e-4);
    let pose = Affine3A::from_mat3_translation(r, Vec3::new(50.0, 0.0, 0.0));
    let d = mesh_distance(&t, &pose, &t).unwrap();
    assert!(d.distance.is_finite());
}

#[test]
fn extreme_coordinates_never_panic() {
    // Corners at ±f32::MAX: every query answers; a pose that would move a
    // vertex beyond the f32 range is a typed error, not an unspecified answer.
    fn run<BV: proxima::narrow::BoundingVolume>() {
        let m = f32::MAX;
        let v = vec![
            Vec3::new(m, m, m),
            Vec3::new(-m, m, 0.0),
            Vec3::new(0.0, -m, m),
            Vec3::new(1.0, 2.0, 3.0),
        ];
        let mesh = TriMesh::new(v, vec![[0, 1, 2], [1, 2, 3], [3, 3, 3]]).unwrap();
        let t = Mesh::<BV>::from_trimesh(mesh.clone(), BuildOptions::default()).unwrap();
        let x = &t;
        let mut q = Proximity::<BV>::default();
        let d = q.distance(x, &Affine3A::IDENTITY, x).unwrap();
        assert_eq!(d.distance, 0.0, "{}", BV::NAME);
        let far = Affine3A::from_translation(Vec3::new(m, 0.0, 0.0));
        assert!(matches!(
            q.distance(x, &far, x),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            q.within(x, &far, x, 1.0),
            Err(Error::NonFinite { .. })
        ));
        assert!(matches!(
            q.pairs_within(x, &far, x, 1.0),
            Err(Error::NonFinite { .. })
        ));
        // A half turn keeps every corner in range; a turn by 0.5 takes (m, m, m)
        // to x + y = 1.36 m.
        let half = Affine3A::from_mat3(Mat3::from_cols(-Vec3::X, -Vec3::Y, Vec3::Z));
        let t2 = q.distance(x, &half, x).unwrap();
        assert!(t2.distance.is_finite());
        let turned = Affine3A::from_rotation_z(0.5);
        assert!(matches!(
            q.distance(x, &turned, x),
            Err(Error::NonFinite { .. })
        ));
        let c = q.closest_point(x, Vec3::new(m, -m, m)).unwrap();
        assert!(c.distance.is_finite() && c.distance > 0.0);
        let on = q.contains_point(x, Vec3::new(1.0, 2.0, 3.0)).unwrap();
        assert!(on, "{}", BV::NAME);
    }
    run::<Kdop18>();
    run::<Obb>();
    run::<proxima::geom::Aabb>();
    run::<Sphere>();
}
