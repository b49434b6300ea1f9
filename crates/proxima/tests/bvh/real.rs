//! The shared meshes (`shared/data`) against brute force.

use super::meshes::random_pose;
use proxima::geom::{Aabb, Ray, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{
    triangles_intersect, BoundingVolume, BuildOptions, Bvh, Collider, Kdop14, Kdop18, Kdop26, Mesh,
    Obb, RotationUpdate, SplitRule, TriMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn data(name: &str) -> TriMesh {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    proxima::io::load(format!("{dir}{name}")).unwrap()
}

/// Brute force over every triangle pair. The box pre-check is exact (comparisons
/// only) and `triangles_intersect` starts with the same check, so it changes no
/// answer; it only makes the oracle fast enough for hundreds of poses.
fn brute(a: &TriMesh, pose: &Affine3A, b: &TriMesh) -> Vec<(u32, u32)> {
    let bt: Vec<([Vec3; 3], Vec3, Vec3)> = (0..b.len())
        .map(|j| {
            let t = b.triangle(j);
            (t, t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
        })
        .collect();
    let mut out = Vec::new();
    for i in 0..a.len() {
        let t = a.triangle(i).map(|v| pose.transform_point3(v));
        let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        for (j, (u, ulo, uhi)) in bt.iter().enumerate() {
            if lo.cmple(*uhi).all() && ulo.cmple(hi).all() && triangles_intersect(&t, u) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

fn check<BV: BoundingVolume>(
    a: &TriMesh,
    b: &TriMesh,
    poses: &[Affine3A],
    wants: &[Vec<(u32, u32)>],
) {
    for split in [SplitRule::Mean, SplitRule::Median, SplitRule::Sah] {
        let o = BuildOptions {
            split,
            leaf_size: 1 + (split == SplitRule::Sah) as usize * 3,
        };
        let (ma, mb) = (
            Mesh::<BV>::from_trimesh(a.clone(), o).unwrap(),
            Mesh::<BV>::from_trimesh(b.clone(), o).unwrap(),
        );
        for rot in [RotationUpdate::Refit, RotationUpdate::Conservative] {
            let mut c = Collider::<BV>::new(rot);
            for (k, (pose, want)) in poses.iter().zip(wants).enumerate() {
                let mut got = c.all_pairs(&ma, pose, &mb).unwrap().pairs;
                got.sort_unstable();
                assert_eq!(&got, want, "{} {split:?} {rot:?} pose {k}", BV::NAME);
                let f = c.first_contact(&ma, pose, &mb).unwrap();
                assert_eq!(f.pair.is_some(), !want.is_empty(), "{} pose {k}", BV::NAME);
            }
        }
    }
}

fn check_all(a: &TriMesh, b: &TriMesh, poses: &[Affine3A], min_contacts: usize) {
    let wants: Vec<Vec<(u32, u32)>> = poses.iter().map(|p| brute(a, p, b)).collect();
    let contacts = wants.iter().filter(|w| !w.is_empty()).count();
    assert!(contacts >= min_contacts, "{contacts} poses in contact");
    assert!(contacts < poses.len(), "every pose in contact");
    check::<Aabb>(a, b, poses, &wants);
    check::<Kdop14>(a, b, poses, &wants);
    check::<Kdop18>(a, b, poses, &wants);
    check::<Kdop26>(a, b, poses, &wants);
    check::<Obb>(a, b, poses, &wants);
    check::<Sphere>(a, b, poses, &wants);
}

#[test]
fn rob_vs_env_random_poses() {
    let (rob, env) = (data("rob.obj"), data("env.obj"));
    let mut rng = Pcg64::seed_from_u64(2024);
    // FCL's pose distribution, plus pure translations.
    let mut poses: Vec<Affine3A> = (0..300)
        .map(|_| {
            random_pose(
                &mut rng,
                Vec3::new(-3000.0, -3000.0, 0.0),
                Vec3::new(3000.0, 3000.0, 3000.0),
            )
        })
        .collect();
    for p in poses.iter_mut().step_by(5) {
        p.matrix3 = proxima::glam::Mat3A::IDENTITY;
    }
    check_all(&rob, &env, &poses, 100);
}

/// Near-contact poses: the second copy moved by about its own size.
fn near_contact(m: &TriMesh, n: usize, seed: u64) -> Vec<Affine3A> {
    let (lo, hi) = m
        .vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let ext = hi - lo;
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let rot = random_pose(&mut rng, Vec3::ZERO, Vec3::ZERO);
            let dir = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            let c = (lo + hi) * 0.5;
            let dist = rng.gen_range(0.6..1.1);
            // Rotate about the centre, then push out along `dir`.
            Affine3A::from_translation(c + dir * ext * dist) * rot * Affine3A::from_translation(-c)
        })
        .collect()
}

#[test]
fn bunny_vs_bunny_near_contact() {
    let bunny = data("bunny.obj");
    check_all(&bunny, &bunny, &near_contact(&bunny, 12, 7), 3);
}

#[test]
fn teapot_vs_teapot_near_contact() {
    let teapot = data("teapot.obj");
    check_all(&teapot, &teapot, &near_contact(&teapot, 30, 8), 5);
}

#[test]
fn rays_on_bunny_match_brute_force() {
    let bunny = data("bunny.obj");
    let mut rng = Pcg64::seed_from_u64(5);
    let t = Bvh::<Kdop18>::build(&bunny, BuildOptions::default()).unwrap();
    let o = Bvh::<Obb>::build(
        &bunny,
        BuildOptions {
            split: SplitRule::Sah,
            leaf_size: 4,
        },
    )
    .unwrap();
    let mesh = Mesh::<Kdop18>::from_trimesh(bunny.clone(), BuildOptions::default()).unwrap();
    let (lo, hi) = bunny
        .vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let mut hits = 0;
    for _ in 0..300 {
        let p = |r: &mut Pcg64| {
            Vec3::new(
                r.gen_range(lo.x..hi.x),
                r.gen_range(lo.y..hi.y),
                r.gen_range(lo.z..hi.z),
            )
        };
        let (from, to) = (p(&mut rng) * 3.0, p(&mut rng));
        let ray = Ray::new(from, to - from);
        let mut want: Option<(u32, f32)> = None;
        for i in 0..bunny.len() {
            if let Some(h) = proxima::narrow::ray_triangle(&ray, &bunny.triangle(i)) {
                if want.is_none_or(|(_, t)| h.t < t) {
                    want = Some((i as u32, h.t));
                }
            }
        }
        hits += want.is_some() as usize;
        assert_eq!(
            t.cast_ray(&bunny, &ray).unwrap().map(|h| (h.triangle, h.t)),
            want
        );
        assert_eq!(
            o.cast_ray(&bunny, &ray).unwrap().map(|h| (h.triangle, h.t)),
            want
        );
        assert_eq!(
            mesh.cast_ray(&ray).unwrap().map(|h| (h.triangle, h.t)),
            want
        );
    }
    assert!(hits > 50, "{hits}");
}
