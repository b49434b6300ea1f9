//! Bad input: a typed error, and the world exactly as it was.

use super::oracle::Sim;
use proxima::broad::Filter;
use proxima::geom::{Aabb, Frustum, Plane, Ray};
use proxima::glam::{Affine3A, Mat3A, Vec3, Vec3A};
use proxima::narrow::Kdop18;
use proxima::world::{Shape, World, WorldConfig};
use proxima::{Error, Handle};

/// Everything observable about a world.
fn snapshot(w: &mut World<u64>) -> String {
    let objects: Vec<String> = w
        .iter()
        .map(|o| format!("{:?} {:?} {:?} {}", o.handle, o.pose, o.filter, o.value))
        .collect();
    let probe = w
        .ray_hits(&Ray::new(Vec3::splat(-5.0), Vec3::ONE), Filter::ALL)
        .unwrap();
    format!(
        "{objects:?} {} {probe:?} {:?}",
        w.ignored_len(),
        w.clone_contacts()
    )
}

trait CloneContacts {
    fn clone_contacts(&mut self) -> (Vec<(Handle, Handle)>, usize);
}

impl CloneContacts for World<u64> {
    fn clone_contacts(&mut self) -> (Vec<(Handle, Handle)>, usize) {
        let r = self.contacts().unwrap();
        (
            r.pairs.iter().map(|c| (c.a, c.b)).collect(),
            r.triangles.len(),
        )
    }
}

fn bad_poses() -> Vec<Affine3A> {
    let t = Vec3A::new(0.1, 0.2, 0.3);
    vec![
        Affine3A::from_scale(Vec3::splat(2.0)),
        Affine3A::from_scale(Vec3::new(1.0, 1.0, 1.01)),
        Affine3A {
            matrix3: Mat3A::from_cols(Vec3A::X, Vec3A::new(0.1, 1.0, 0.0), Vec3A::Z),
            translation: t,
        },
        // A reflection: orthonormal, determinant -1.
        Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)),
        Affine3A {
            matrix3: Mat3A::IDENTITY,
            translation: Vec3A::new(f32::NAN, 0.0, 0.0),
        },
        Affine3A {
            matrix3: Mat3A::from_cols(Vec3A::X, Vec3A::Y, Vec3A::new(0.0, 0.0, f32::INFINITY)),
            translation: t,
        },
        // Rigid, but moving the shape beyond the coordinate limit.
        Affine3A::from_translation(Vec3::new(f32::MAX, 0.0, 0.0)),
        Affine3A::from_translation(Vec3::new(0.0, -2e30, 0.0)),
    ]
}

#[test]
fn bad_input_is_a_typed_error_and_changes_nothing() {
    let mut sim = Sim::<Kdop18>::new(WorldConfig::default(), 21);
    for _ in 0..12 {
        sim.insert();
    }
    let shape = sim.shapes[0].0.clone();
    let ball = Shape::<Kdop18>::sphere(0.5).unwrap();
    let mut w = sim.world;
    let live: Vec<Handle> = w.iter().map(|o| o.handle).collect();
    let (a, b) = (live[0], live[1]);
    let before = snapshot(&mut w);
    for pose in bad_poses() {
        for s in [&shape, &ball] {
            let e = w.insert(s.clone(), pose, 99).unwrap_err();
            assert!(matches!(e, Error::InvalidPose(_)), "{e:?}");
        }
        let e = w.set_pose(a, pose).unwrap_err();
        assert!(matches!(e, Error::InvalidPose(_)), "{e:?}");
        // A batch with one bad pose applies none.
        let good = Affine3A::from_translation(Vec3::splat(0.25));
        let e = w
            .set_poses(&[(a, good), (b, pose), (live[2], good)])
            .unwrap_err();
        assert!(matches!(e, Error::InvalidPose(_)), "{e:?}");
        w.validate().unwrap();
    }
    assert_eq!(snapshot(&mut w), before);

    // Stale handles: removed, and from another world.
    let gone = w.insert(ball.clone(), Affine3A::IDENTITY, 7).unwrap();
    w.remove(gone).unwrap();
    let mut other: World<u64> = World::new(WorldConfig::default()).unwrap();
    let foreign = other.insert(ball.clone(), Affine3A::IDENTITY, 1).unwrap();
    let before = snapshot(&mut w);
    for h in [gone, foreign] {
        assert_eq!(w.remove(h).unwrap_err(), Error::StaleHandle);
        assert_eq!(
            w.set_pose(h, Affine3A::IDENTITY).unwrap_err(),
            Error::StaleHandle
        );
        assert_eq!(
            w.set_poses(&[(a, Affine3A::IDENTITY), (h, Affine3A::IDENTITY)])
                .unwrap_err(),
            Error::StaleHandle
        );
        assert_eq!(
            w.set_filter(h, Filter::new(1, 1)).unwrap_err(),
            Error::StaleHandle
        );
        assert_eq!(w.get(h).unwrap_err(), Error::StaleHandle);
        assert_eq!(w.get_mut(h).unwrap_err(), Error::StaleHandle);
        assert_eq!(w.pose(h).unwrap_err(), Error::StaleHandle);
        assert!(w.object(h).is_err());
        assert_eq!(w.ignore(a, h).unwrap_err(), Error::StaleHandle);
        assert_eq!(w.unignore(h, a).unwrap_err(), Error::StaleHandle);
        assert_eq!(w.is_ignored(h, a).unwrap_err(), Error::StaleHandle);
        assert!(!w.contains(h));
    }
    assert!(matches!(w.ignore(a, a), Err(Error::InvalidParameter(_))));
    // Bad shapes and queries.
    assert!(matches!(
        Shape::<Kdop18>::sphere(-1.0),
        Err(Error::NegativeRadius { .. })
    ));
    assert!(matches!(
        Shape::<Kdop18>::sphere(f32::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert!(w
        .insert(Shape::Sphere(-0.5), Affine3A::IDENTITY, 5)
        .is_err());
    assert!(w
        .insert(Shape::Sphere(f32::INFINITY), Affine3A::IDENTITY, 5)
        .is_err());
    assert!(w
        .ray_cast(&Ray::new(Vec3::ZERO, Vec3::ZERO), Filter::ALL)
        .is_err());
    assert!(w
        .ray_hits(&Ray::new(Vec3::NAN, Vec3::X), Filter::ALL)
        .is_err());
    assert!(w
        .ray_cast(&Ray::with_max_t(Vec3::ZERO, Vec3::X, -1.0), Filter::ALL)
        .is_err());
    assert!(w.overlap_sphere(Vec3::ZERO, -1.0, Filter::ALL).is_err());
    assert!(w
        .overlap_sphere(Vec3::splat(f32::NAN), 1.0, Filter::ALL)
        .is_err());
    let nan = Plane::from_vec4_normalized(proxima::glam::Vec4::new(f32::NAN, 0.0, 1.0, 0.0));
    assert!(w
        .cull(&Frustum::from_planes([nan; 6]), Filter::ALL)
        .is_err());
    assert_eq!(snapshot(&mut w), before);
    w.validate().unwrap();

    // Bad configurations and files.
    let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
    let cfg = WorldConfig {
        bounds: Some(inverted),
        ..WorldConfig::default()
    };
    assert!(matches!(
        World::<u64>::new(cfg),
        Err(Error::InvalidParameter(_))
    ));
    let cfg = WorldConfig {
        cut_limit: usize::MAX,
        ..WorldConfig::default()
    };
    assert!(matches!(
        World::<u64>::new(cfg),
        Err(Error::InvalidParameter(_))
    ));
    assert!(matches!(
        Shape::<Kdop18>::load("/no/such/file.obj"),
        Err(Error::Io { .. })
    ));
    let dir = std::env::temp_dir().join(format!("proxima-world-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2 9\n").unwrap();
    assert!(matches!(
        Shape::<Kdop18>::load(&bad),
        Err(Error::Parse { .. })
    ));
    let good = dir.join("tri.obj");
    std::fs::write(&good, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_eq!(Shape::<Kdop18>::load(&good).unwrap().primitive_count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn removing_an_object_drops_its_ignored_pairs_and_reused_slots_start_fresh() {
    let mut w: World<u64> = World::new(WorldConfig::default()).unwrap();
    let s = Shape::sphere(1.0).unwrap();
    let a = w.insert(s.clone(), Affine3A::IDENTITY, 0).unwrap();
    let b = w.insert(s.clone(), Affine3A::IDENTITY, 1).unwrap();
    let c = w.insert(s.clone(), Affine3A::IDENTITY, 2).unwrap();
    w.ignore(a, b).unwrap();
    w.ignore(c, a).unwrap();
    assert_eq!(w.contacts().unwrap().pairs.len(), 1);
    w.remove(a).unwrap();
    assert_eq!(w.ignored_len(), 0);
    // The slot of `a` is reused by a new object: not ignored with anything.
    let d = w.insert(s.clone(), Affine3A::IDENTITY, 3).unwrap();
    assert_eq!(d.index(), a.index());
    assert!(!w.is_ignored(d, b).unwrap() && !w.is_ignored(c, d).unwrap());
    let r = w.contacts().unwrap();
    assert_eq!(r.pairs.len(), 3);
    assert!(r.pairs.iter().all(|p| r.triangles_of(p) == [(0, 0)]));
    // Unignore brings a pair back even though neither object moved.
    w.ignore(b, c).unwrap();
    assert_eq!(w.contacts().unwrap().pairs.len(), 2);
    assert!(w.unignore(c, b).unwrap());
    assert!(!w.unignore(c, b).unwrap());
    assert_eq!(w.contacts().unwrap().pairs.len(), 3);
    // A filter change counts too.
    w.set_filter(b, Filter::new(1, 0)).unwrap();
    assert_eq!(w.contacts().unwrap().pairs.len(), 1);
    w.set_filter(b, Filter::ALL).unwrap();
    assert_eq!(w.contacts().unwrap().pairs.len(), 3);
    w.validate().unwrap();
}
