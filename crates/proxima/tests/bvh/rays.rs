//! Ray casts on the shared meshes against brute force over every triangle with
//! `ray_triangle`: random rays from outside and inside, rays aimed exactly at
//! vertices and edge points, axis-parallel rays, rays in a triangle's plane,
//! bounded rays; for [`RayBvh`] (every split rule and leaf size, and the k-DOP
//! topology), for `Bvh<BV>` with every volume, and for [`Mesh`] (its own ray tree).

use super::meshes::{torus, uv_sphere};
use proxima::geom::{Aabb, Ray, Segment, Sphere};
use proxima::glam::Vec3;
use proxima::narrow::{
    ray_triangle, BoundingVolume, BuildOptions, Bvh, Kdop14, Kdop18, Kdop26, Mesh, Obb, RayBvh,
    SplitRule, TriMesh, TriangleHit,
};
use proxima::Result;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn data(name: &str) -> TriMesh {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    proxima::io::load(format!("{dir}{name}")).unwrap()
}

/// The oracle: smallest `t`, ties to the smaller triangle index.
fn brute(m: &TriMesh, ray: &Ray) -> Option<(u32, f32)> {
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

fn bounds(m: &TriMesh) -> (Vec3, Vec3) {
    m.vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        })
}

/// `n` rays of every family (see the module doc) around `m`.
fn ray_mix(m: &TriMesh, n: usize, seed: u64) -> Vec<Ray> {
    let (lo, hi) = bounds(m);
    let (c, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
    let r = h.length();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n);
    let unit = |rng: &mut Pcg64| loop {
        let v = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    };
    let in_box = |rng: &mut Pcg64, s: f32| {
        c + h
            * s
            * Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
    };
    for i in 0..n {
        let outside = c + unit(&mut rng) * (2.0 * r);
        let tri = m.triangle(rng.gen_range(0..m.len()));
        let ray = match i % 9 {
            // From outside at a random point of the box.
            0 => Ray::new(outside, in_box(&mut rng, 1.0) - outside),
            // From inside (often inside the mesh), any direction.
            1 => Ray::new(in_box(&mut rng, 0.8), unit(&mut rng)),
            // Exactly at a vertex.
            2 => Ray::new(outside, tri[rng.gen_range(0..3)] - outside),
            // At a point of an edge (rounded to f32: on or next to the edge).
            3 => {
                let k = rng.gen_range(0..3);
                let p = tri[k].lerp(tri[(k + 1) % 3], rng.gen_range(0.0..1.0));
                Ray::new(outside, p - outside)
            }
            // Axis-parallel, through a vertex's coordinates or a random point.
            4 => {
                let axis = rng.gen_range(0..3);
                let mut d = Vec3::ZERO;
                d[axis] = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
                let mut o = if rng.gen_bool(0.5) {
                    tri[0]
                } else {
                    in_box(&mut rng, 1.0)
                };
                o[axis] = c[axis] - d[axis] * 2.0 * r;
                Ray::new(o, d)
            }
            // In a triangle's plane, along an edge, from a corner or from outside.
            5 => {
                let d = tri[1] - tri[0];
                if d == Vec3::ZERO {
                    Ray::new(outside, c - outside)
                } else if rng.gen_bool(0.5) {
                    Ray::new(tri[0], d)
                } else {
                    Ray::new(tri[0] - d * 3.0, d)
                }
            }
            // Starting exactly on a vertex (t = 0 hits), any direction.
            6 => Ray::new(tri[rng.gen_range(0..3)], unit(&mut rng)),
            // Bounded: stops around the surface.
            7 => {
                let p = in_box(&mut rng, 1.0);
                let d = p - outside;
                Ray::with_max_t(outside, d, rng.gen_range(0.3..1.0))
            }
            // A segment ending exactly on a vertex (hit at t = 1 or earlier).
            _ => Segment::new(outside, tri[rng.gen_range(0..3)]).to_ray(),
        };
        out.push(ray);
    }
    out
}

/// A structure that owns its triangles: its closest-hit and any-hit casts.
trait Caster {
    fn cast_ray(&self, ray: &Ray) -> Result<Option<TriangleHit>>;
    fn intersects_ray(&self, ray: &Ray) -> Result<bool>;
}

impl Caster for RayBvh {
    fn cast_ray(&self, ray: &Ray) -> Result<Option<TriangleHit>> {
        RayBvh::cast_ray(self, ray)
    }
    fn intersects_ray(&self, ray: &Ray) -> Result<bool> {
        RayBvh::intersects_ray(self, ray)
    }
}

impl<BV: BoundingVolume> Caster for Mesh<BV> {
    fn cast_ray(&self, ray: &Ray) -> Result<Option<TriangleHit>> {
        Mesh::cast_ray(self, ray)
    }
    fn intersects_ray(&self, ray: &Ray) -> Result<bool> {
        Mesh::intersects_ray(self, ray)
    }
}

fn check_ray_bvh(
    m: &TriMesh,
    t: &impl Caster,
    rays: &[Ray],
    wants: &[Option<(u32, f32)>],
    what: &str,
) {
    for (k, (ray, want)) in rays.iter().zip(wants).enumerate() {
        let got = t.cast_ray(ray).unwrap();
        assert_eq!(
            got.map(|h| (h.triangle, h.t)),
            *want,
            "{what} ray {k} {ray:?}"
        );
        if let Some(h) = got {
            let [p, q, r] = m.triangle(h.triangle as usize);
            let on = p * (1.0 - h.u - h.v) + q * h.u + r * h.v;
            let scale = 1.0 + ray.origin.abs().max_element() + (h.t * ray.dir).length();
            assert!(
                (on - ray.at(h.t)).length() <= 1e-4 * scale,
                "{what} ray {k}"
            );
        }
        assert_eq!(
            t.intersects_ray(ray).unwrap(),
            want.is_some(),
            "{what} any ray {k}"
        );
    }
}

fn check_bvh<BV: BoundingVolume>(m: &TriMesh, rays: &[Ray], wants: &[Option<(u32, f32)>]) {
    let t = Bvh::<BV>::build(m, BuildOptions::default()).unwrap();
    for (k, (ray, want)) in rays.iter().zip(wants).enumerate() {
        let got = t.cast_ray(m, ray).unwrap().map(|h| (h.triangle, h.t));
        assert_eq!(got, *want, "{} ray {k} {ray:?}", BV::NAME);
    }
}

/// Every structure against brute force on `n` rays of the mix.
fn check_mesh(m: &TriMesh, n: usize, seed: u64) {
    let rays = ray_mix(m, n, seed);
    let wants: Vec<_> = rays.iter().map(|r| brute(m, r)).collect();
    let hits = wants.iter().filter(|w| w.is_some()).count();
    assert!(hits * 5 > n && hits < n, "{hits} of {n} rays hit");
    for split in [SplitRule::Sah, SplitRule::Median, SplitRule::Mean] {
        for leaf in [1, 4, 8] {
            let o = BuildOptions {
                split,
                leaf_size: leaf,
            };
            let t = RayBvh::build(m, o).unwrap();
            check_ray_bvh(m, &t, &rays, &wants, &format!("RayBvh {o:?}"));
        }
    }
    let k = Bvh::<Kdop18>::build(m, BuildOptions::default()).unwrap();
    let t = RayBvh::from_bvh(&k, m).unwrap();
    check_ray_bvh(m, &t, &rays, &wants, "RayBvh from k-DOP");
    let mesh = Mesh::<Kdop18>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
    check_ray_bvh(m, &mesh, &rays, &wants, "Mesh");
    let mesh = Mesh::<Obb>::from_trimesh(m.clone(), BuildOptions::default())
        .unwrap()
        .with_ray_options(BuildOptions {
            split: SplitRule::Median,
            leaf_size: 2,
        })
        .unwrap();
    check_ray_bvh(m, &mesh, &rays, &wants, "Mesh, median ray tree");
    check_bvh::<Aabb>(m, &rays, &wants);
    check_bvh::<Kdop14>(m, &rays, &wants);
    check_bvh::<Kdop18>(m, &rays, &wants);
    check_bvh::<Kdop26>(m, &rays, &wants);
    check_bvh::<Obb>(m, &rays, &wants);
    check_bvh::<Sphere>(m, &rays, &wants);
}

#[test]
fn rays_bunny() {
    check_mesh(&data("bunny.obj"), 1500, 1);
}

#[test]
fn rays_teapot() {
    check_mesh(&data("teapot.obj"), 1500, 2);
}

#[test]
fn rays_env_and_rob() {
    check_mesh(&data("env.obj"), 1000, 3);
    check_mesh(&data("rob.obj"), 1000, 4);
}

#[test]
fn rays_skin_body() {
    check_mesh(&data("SKINbody.stl"), 250, 5);
}

#[test]
fn rays_procedural() {
    check_mesh(&torus(2.0, 0.6, 24, 12), 1500, 6);
    check_mesh(&uv_sphere(Vec3::ZERO, 1.5, 12, 8), 1500, 7);
}

/// A random soup of `n` triangles in a cube of side 100: axis-aligned quads of
/// every size (two triangles sharing a diagonal, walls like `env.obj`'s), thin
/// slivers, small random triangles, and repeated and degenerate ones, so that
/// leaves of the SAH plan hold overlapping boxes, several triangles one ray
/// crosses, and shared edges.
fn soup(n: usize, seed: u64) -> TriMesh {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut v: Vec<Vec3> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    let p = |rng: &mut Pcg64| {
        Vec3::new(
            rng.gen_range(-50.0..50.0f32).round(),
            rng.gen_range(-50.0..50.0f32).round(),
            rng.gen_range(-50.0..50.0f32).round(),
        )
    };
    while t.len() < n {
        let b = v.len() as u32;
        match rng.gen_range(0..5) {
            0 | 1 => {
                let axis = rng.gen_range(0..3);
                let (a, c) = (p(&mut rng), p(&mut rng));
                let mut q = [a, a, c, c];
                q[1][(axis + 1) % 3] = c[(axis + 1) % 3];
                q[3][(axis + 1) % 3] = a[(axis + 1) % 3];
                for x in &mut q {
                    x[axis] = a[axis];
                }
                v.extend(q);
                t.push([b, b + 1, b + 2]);
                t.push([b, b + 2, b + 3]);
            }
            2 => {
                let a = p(&mut rng);
                v.extend([a, p(&mut rng), a + Vec3::splat(0.01)]);
                t.push([b, b + 1, b + 2]);
            }
            3 => {
                let a = p(&mut rng);
                let s = rng.gen_range(0.1..5.0f32);
                v.extend([a, a + Vec3::X * s, a + Vec3::new(0.3, 0.7, -0.2) * s]);
                t.push([b, b + 1, b + 2]);
            }
            _ => {
                // A copy of an earlier triangle, or a degenerate one.
                if let Some(&old) = t.get(rng.gen_range(0..t.len().max(1))) {
                    t.push(old);
                } else {
                    let a = p(&mut rng);
                    v.extend([a, a, a]);
                    t.push([b, b + 1, b + 2]);
                }
            }
        }
    }
    TriMesh::new(v, t).unwrap()
}

/// [`RayBvh`] (its SAH leaf plan, every leaf size up to two packets and more)
/// against brute force on random soups, rays of the whole mix (grazing vertices
/// and edges, in-plane, axis-parallel, bounded).
#[test]
fn ray_bvh_random_soups_match_brute_force() {
    for seed in 0..6 {
        let m = soup(40 + 60 * seed as usize, 100 + seed);
        let rays = ray_mix(&m, 600, 200 + seed);
        let wants: Vec<_> = rays.iter().map(|r| brute(&m, r)).collect();
        let hits = wants.iter().filter(|w| w.is_some()).count();
        assert!(hits > 100, "{hits} hits");
        for split in [SplitRule::Sah, SplitRule::Median] {
            for leaf in [1, 2, 3, 4, 5, 7, 9] {
                let o = BuildOptions {
                    split,
                    leaf_size: leaf,
                };
                let t = RayBvh::build(&m, o).unwrap();
                check_ray_bvh(&m, &t, &rays, &wants, &format!("soup {seed} {o:?}"));
            }
        }
    }
}

/// Deform, refit, and compare again.
#[test]
fn ray_bvh_refit_matches_brute_force() {
    let mut m = data("bunny.obj");
    let mut t = RayBvh::build(&m, BuildOptions::default()).unwrap();
    for step in 0..3 {
        let v: Vec<Vec3> = m
            .vertices()
            .iter()
            .map(|&p| p * (1.0 + 0.1 * (p.y * 20.0 + step as f32).sin()))
            .collect();
        m.set_vertices(&v).unwrap();
        t.refit(m.vertices()).unwrap();
        let rays = ray_mix(&m, 300, 10 + step);
        let wants: Vec<_> = rays.iter().map(|r| brute(&m, r)).collect();
        check_ray_bvh(&m, &t, &rays, &wants, "refit");
    }
    assert!(t.refit(&m.vertices()[1..]).is_err());
    let mut nan = m.vertices().to_vec();
    nan[0].x = f32::NAN;
    assert!(t.refit(&nan).is_err());
    assert!(t.cast_ray(&Ray::new(Vec3::ZERO, Vec3::ZERO)).is_err());
    assert!(t
        .cast_ray(&Ray::with_max_t(Vec3::ZERO, Vec3::X, -1.0))
        .is_err());
}

/// The batch helpers give exactly the sequential answers, and fail on a bad ray.
#[cfg(feature = "parallel")]
#[test]
fn parallel_batches_equal_sequential_casts() {
    let m = data("teapot.obj");
    let rays = ray_mix(&m, 3000, 11);
    let t = RayBvh::build(&m, BuildOptions::default()).unwrap();
    let b = Bvh::<Kdop18>::build(&m, BuildOptions::default()).unwrap();
    let mesh = Mesh::<Kdop18>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
    let seq: Vec<_> = rays.iter().map(|r| t.cast_ray(r).unwrap()).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        assert_eq!(t.cast_rays_par(&rays).unwrap(), seq);
        assert_eq!(b.cast_rays_par(&m, &rays).unwrap(), seq);
        assert_eq!(mesh.cast_rays_par(&rays).unwrap(), seq);
    });
    let mut bad = rays.clone();
    bad[1234].dir = Vec3::ZERO;
    assert!(t.cast_rays_par(&bad).is_err());
    assert!(b.cast_rays_par(&m, &bad).is_err());
    assert!(mesh.cast_rays_par(&bad).is_err());
    // A mesh of the same content built apart is another mesh to the tree.
    let apart = TriMesh::new(m.vertices().to_vec(), m.triangles().to_vec()).unwrap();
    assert!(b.cast_rays_par(&apart, &rays).is_err());
    assert!(b.cast_rays_par(mesh.trimesh(), &rays).is_ok());
}

/// Regression: coordinates beyond `√f32::MAX ≈ 1.8e19` (where a squared
/// distance overflows `f32`) up to `f32::MAX`. A sphere volume fitted there had
/// an infinite radius, and its ray test then missed everything; an OBB fitted to
/// points near `±f32::MAX` had a NaN centre (its `lo + hi` overflowed). Every
/// volume's tree and the mesh's ray tree must cast as brute force.
#[test]
fn huge_coordinates_cast_with_every_volume() {
    fn cast_all<BV: BoundingVolume>(m: &TriMesh, rays: &[Ray], wants: &[Option<(u32, f32)>]) {
        check_bvh::<BV>(m, rays, wants);
        let mesh = Mesh::<BV>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
        for (k, (ray, want)) in rays.iter().zip(wants).enumerate() {
            let got = mesh.cast_ray(ray).unwrap().map(|h| (h.triangle, h.t));
            assert_eq!(got, *want, "Mesh<{}> ray {k} {ray:?}", BV::NAME);
            assert_eq!(mesh.intersects_ray(ray).unwrap(), want.is_some());
        }
    }
    let mut rng = Pcg64::seed_from_u64(77);
    for s in [1e18f32, 2e19, 1e25, 1e30, 1e38, f32::MAX] {
        // A closed ball of radius `s` and, near its centre, one small triangle.
        let ball = uv_sphere(Vec3::ZERO, s, 12, 8);
        let mut v = ball.vertices().to_vec();
        let mut t = ball.triangles().to_vec();
        let base = v.len() as u32;
        v.extend([
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(2.0, 2.0, 3.0),
            Vec3::new(1.0, 3.0, 3.0),
        ]);
        t.push([base, base + 1, base + 2]);
        let m = TriMesh::new(v, t).unwrap();
        // From inside (the centre, the small triangle's neighbourhood, half way
        // out) in random directions, and from outside towards the centre where
        // that is in range.
        let mut rays = vec![
            Ray::new(Vec3::new(1.2, 2.2, 0.0), Vec3::Z),
            Ray::new(Vec3::new(1.2, 2.2, 0.0), -Vec3::Z),
        ];
        for k in 0..60 {
            let d = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
            .normalize_or(Vec3::X);
            let o = match k % 3 {
                0 => Vec3::ZERO,
                1 => Vec3::new(1.0, 2.0, 2.0),
                _ => d.any_orthonormal_vector() * (s * 0.5),
            };
            rays.push(Ray::new(o, d));
            if s <= 1e30 {
                rays.push(Ray::new(-d * (s * 3.0), d));
            }
        }
        let wants: Vec<_> = rays.iter().map(|r| brute(&m, r)).collect();
        assert!(
            wants.iter().all(|w| w.is_some()),
            "scale {s}: every ray hits"
        );
        assert_eq!(wants[0].map(|w| w.0), Some(ball.len() as u32), "scale {s}");
        cast_all::<Aabb>(&m, &rays, &wants);
        cast_all::<Kdop14>(&m, &rays, &wants);
        cast_all::<Kdop18>(&m, &rays, &wants);
        cast_all::<Kdop26>(&m, &rays, &wants);
        cast_all::<Obb>(&m, &rays, &wants);
        cast_all::<Sphere>(&m, &rays, &wants);
    }
}

/// [`RayBvh`]'s descent is specialised per octant of the ray direction, with the
/// slab sides and the widened inverse direction chosen per ray; rays with a zero
/// or subnormal direction component and one-leaf trees take the general path.
/// Against brute force: every octant (with components as small as `1e-30`,
/// inverse `1e30`), zero and subnormal components, rays along the faces of the
/// node boxes (through and along a vertex's coordinate planes, where the slab
/// test's entry equals its exit), rays starting on a box face, and meshes of one
/// to five triangles (one leaf with `leaf_size` 8).
#[test]
fn ray_bvh_every_octant_grazing_box_faces_and_one_leaf_trees() {
    let mut rng = Pcg64::seed_from_u64(41);
    let teapot = data("teapot.obj");
    let mut meshes = vec![soup(300, 40)];
    for n in 1..=5 {
        // The first n triangles of the teapot (a patch), all its vertices.
        let t = teapot.triangles()[..n].to_vec();
        meshes.push(TriMesh::new(teapot.vertices().to_vec(), t).unwrap());
    }
    meshes.push(teapot);
    for (mi, m) in meshes.iter().enumerate() {
        // The box of the triangles (a patch uses few of the vertices).
        let (lo, hi) = (0..m.len())
            .flat_map(|i| m.triangle(i))
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), v| {
                (l.min(v), h.max(v))
            });
        let (c, r) = ((lo + hi) * 0.5, (hi - lo).length().max(1e-3));
        let mut rays = Vec::new();
        for i in 0..1600 {
            let tri = m.triangle(rng.gen_range(0..m.len()));
            let corner = tri[rng.gen_range(0..3)];
            // A direction in octant `i % 8`, some components tiny, zero or
            // subnormal (one at least 0.05, so that hits stay at finite `t`).
            let mut d = Vec3::new(
                rng.gen_range(0.05..1.0),
                rng.gen_range(0.05..1.0),
                rng.gen_range(0.05..1.0),
            );
            let keep = rng.gen_range(0..3);
            for a in 0..3 {
                match rng.gen_range(0..10) {
                    _ if a == keep => {}
                    0 => d[a] = 1e-30,
                    1 => d[a] = 0.0,
                    2 => d[a] = 1e-40,
                    _ => {}
                }
                if (i % 8) >> a & 1 == 1 {
                    d[a] = -d[a];
                }
            }
            let ray = match (i / 8) % 4 {
                // Through a vertex from far away.
                0 => Ray::new(corner - d * (3.0 * r), d),
                // Starting on a vertex (on the faces of the boxes around it).
                1 => Ray::new(corner, d),
                // In a coordinate plane of a vertex (a box face), from outside.
                2 => {
                    let a = rng.gen_range(0..3);
                    let mut d = d;
                    d[a] = 0.0;
                    if d.abs().max_element() < 0.05 {
                        let b = (a + 1) % 3;
                        d[b] = if d[b] < 0.0 { -0.5 } else { 0.5 };
                    }
                    let mut o = c - d * (3.0 * r);
                    o[a] = corner[a];
                    Ray::new(o, d)
                }
                // From a random point of the box, bounded or not.
                _ => {
                    let o = lo + (hi - lo) * Vec3::new(rng.gen(), rng.gen(), rng.gen());
                    let max_t = if i % 3 == 0 {
                        rng.gen_range(0.0..r)
                    } else {
                        f32::INFINITY
                    };
                    Ray::with_max_t(o, d, max_t)
                }
            };
            rays.push(ray);
        }
        let wants: Vec<_> = rays.iter().map(|r| brute(m, r)).collect();
        let hits = wants.iter().filter(|w| w.is_some()).count();
        assert!(hits > 100, "mesh {mi}: {hits} hits");
        for leaf in [1, 4, 8] {
            let o = BuildOptions {
                split: SplitRule::Sah,
                leaf_size: leaf,
            };
            let t = RayBvh::build(m, o).unwrap();
            check_ray_bvh(m, &t, &rays, &wants, &format!("mesh {mi} {o:?}"));
        }
    }
}
