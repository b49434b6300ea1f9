//! Every mesh loader on arbitrary bytes: an error or a valid mesh, never a panic,
//! and never an allocation beyond what the input size allows (libFuzzer's
//! `-rss_limit_mb` / `-malloc_limit_mb` catch those). Every mesh loaded then
//! becomes a `narrow::Mesh` with its trees: they must be valid, contain it, and
//! find it touching itself.
#![no_main]

use proxima::geom::Ray;
use proxima::glam::{Affine3A, Vec3};
use proxima::io::{parse, Format};
use proxima::narrow::{Kdop18, Mesh, TriMesh};

fn trees(mesh: TriMesh) {
    let m = Mesh::<Kdop18>::from_trimesh(mesh, Default::default()).expect("default options");
    m.bvh()
        .validate(m.trimesh())
        .expect("a fresh tree is valid");
    let (b, s) = (m.aabb(), m.bounding_sphere());
    for &v in m.trimesh().triangles().iter().flatten() {
        let p = m.trimesh().vertices()[v as usize];
        assert!(b.contains_point(p));
        assert!(p.as_dvec3().distance(s.center.as_dvec3()) <= s.radius as f64);
    }
    // Every triangle touches itself (closed sets, degenerate ones too).
    let first = m
        .collide_first(&Affine3A::IDENTITY, &m)
        .expect("identity pose");
    assert!(first.pair.is_some());
    // A ray down through the box: the cast and the any-hit test agree.
    let ray = Ray::new(b.center() + Vec3::Z, -Vec3::Z);
    if ray.validate().is_ok() {
        let hit = m.cast_ray(&ray).expect("valid ray");
        assert_eq!(m.intersects_ray(&ray).expect("valid ray"), hit.is_some());
    }
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    for format in [Format::Obj, Format::Stl, Format::Ply] {
        if let Ok(mesh) = parse("fuzz", data, format) {
            // A loaded mesh is valid: every index in range, every vertex finite.
            let n = mesh.vertices().len();
            assert!(!mesh.is_empty());
            assert!(mesh.triangles().iter().flatten().all(|&v| (v as usize) < n));
            assert!(mesh.vertices().iter().all(|v| v.is_finite()));
            trees(mesh);
        }
    }
    if let Some(f) = Format::sniff(data) {
        let _ = parse("fuzz", data, f);
    }
});
