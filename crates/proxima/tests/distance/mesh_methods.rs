//! The one-shot conveniences on `Mesh` give exactly the answers (and errors) of
//! a reused `Proximity`, whose answers the other files check against brute
//! force; and the distance the method reports is brute force's.

use super::common::*;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{
    mesh_distance, meshes_within, triangle_distance, BoundingVolume, BuildOptions, Kdop18, Mesh,
    Obb, Proximity, TriMesh,
};
use proxima::Error;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn check<BV: BoundingVolume>(a: &TriMesh, b: &TriMesh, seed: u64) {
    let o = BuildOptions::default();
    let (ma, mb) = (
        Mesh::<BV>::from_trimesh(a.clone(), o).unwrap(),
        Mesh::<BV>::from_trimesh(b.clone(), o).unwrap(),
    );
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut q = Proximity::<BV>::default();
    let tb = triangles(b);
    let (lo, hi) = bounds(b);
    for (k, pose) in poses_around(a, b, 12, 0.2..1.3, &mut rng)
        .iter()
        .enumerate()
    {
        let ctx = format!("{} pose {k}", BV::NAME);
        let d = ma.distance(pose, &mb).unwrap();
        assert_eq!(d, q.distance(&ma, pose, &mb).unwrap(), "{ctx}");
        assert_eq!(d, mesh_distance(&ma, pose, &mb).unwrap(), "{ctx}");
        let (want, _) = brute_nearest(&posed(a, pose), &tb, |x, y| {
            triangle_distance(x, y).distance
        });
        assert_eq!(d.distance, want, "{ctx}");
        for m in [d.distance, d.distance * 0.5, d.distance + 1.0] {
            let w = ma.within(pose, &mb, m).unwrap();
            assert_eq!(w, q.within(&ma, pose, &mb, m).unwrap(), "{ctx}");
            assert_eq!(w, meshes_within(&ma, pose, &mb, m).unwrap(), "{ctx}");
            assert_eq!(w, want <= m, "{ctx} margin {m}");
            assert_eq!(
                ma.pairs_within(pose, &mb, m).unwrap(),
                q.pairs_within(&ma, pose, &mb, m).unwrap(),
                "{ctx}"
            );
        }
        let p = lo + Vec3::new(rng.gen(), rng.gen(), rng.gen()) * (hi - lo) * 1.4 - (hi - lo) * 0.2;
        let c = mb.closest_point(p).unwrap();
        assert_eq!(c, q.closest_point(&mb, p).unwrap(), "{ctx}");
        assert_eq!(
            mb.contains_point(p).unwrap(),
            q.contains_point(&mb, p).unwrap(),
            "{ctx}"
        );
        for r in [0.0, c.distance as f32 * 0.5, c.distance as f32 * 2.0] {
            let s = Sphere::new(p, r);
            assert_eq!(
                mb.sphere_distance(&s).unwrap(),
                q.sphere_distance(&mb, &s).unwrap()
            );
            assert_eq!(
                mb.sphere_overlaps(&s).unwrap(),
                q.sphere_overlaps(&mb, &s).unwrap()
            );
        }
    }
}

#[test]
fn conveniences_match_the_query_object() {
    let (rob, teapot, bunny) = (data("rob.obj"), data("teapot.obj"), data("bunny.obj"));
    check::<Kdop18>(&rob, &teapot, 90);
    check::<Obb>(&teapot, &bunny, 91);
    check::<Aabb>(&bunny, &rob, 92);
    check::<Sphere>(&rob, &rob, 93);
}

#[test]
fn conveniences_fail_as_the_query_object() {
    let m = Mesh::<Kdop18>::from_trimesh(data("rob.obj"), BuildOptions::default()).unwrap();
    let bad = Affine3A::from_scale(Vec3::splat(2.0));
    let id = Affine3A::IDENTITY;
    assert!(matches!(m.distance(&bad, &m), Err(Error::InvalidPose(_))));
    assert!(matches!(
        m.within(&bad, &m, 1.0),
        Err(Error::InvalidPose(_))
    ));
    assert!(matches!(
        m.pairs_within(&bad, &m, 1.0),
        Err(Error::InvalidPose(_))
    ));
    assert!(matches!(
        m.within(&id, &m, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        m.pairs_within(&id, &m, -1.0),
        Err(Error::InvalidParameter(_))
    ));
    let nan = Vec3::new(0.0, f32::NAN, 0.0);
    assert!(matches!(m.closest_point(nan), Err(Error::NonFinite { .. })));
    assert!(matches!(
        m.contains_point(nan),
        Err(Error::NonFinite { .. })
    ));
    let neg = Sphere::new(Vec3::ZERO, -1.0);
    assert!(matches!(
        m.sphere_distance(&neg),
        Err(Error::NegativeRadius { .. })
    ));
    assert!(matches!(
        m.sphere_overlaps(&neg),
        Err(Error::NegativeRadius { .. })
    ));
}
