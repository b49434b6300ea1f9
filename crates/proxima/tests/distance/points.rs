//! Point and ball queries on one mesh against brute force; the inside test
//! against the winding number and closed-form answers, through edges and
//! corners.

use super::common::*;
use super::reference::point_triangle;
use super::shapes::{cube, flipped, weld};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{DVec3, Vec3};
use proxima::narrow::{
    closest_point_on_triangle, BoundingVolume, BuildOptions, Kdop14, Kdop18, Kdop26, Mesh, Obb,
    Proximity, TriMesh,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Random query points: in and around the mesh's box, some far away, some on
/// the surface (at a vertex, on an edge, inside a triangle).
fn query_points(m: &TriMesh, n: usize, rng: &mut Pcg64) -> Vec<Vec3> {
    let (lo, hi) = bounds(m);
    let (c, e) = ((lo + hi) * 0.5, hi - lo);
    (0..n)
        .map(|k| match k % 6 {
            0 => m.vertices()[rng.gen_range(0..m.vertices().len())],
            1 => {
                let t = m.triangle(rng.gen_range(0..m.len()));
                t[0] + (t[1] - t[0]) * 0.5
            }
            2 => {
                let t = m.triangle(rng.gen_range(0..m.len()));
                (t[0] + t[1] + t[2]) / 3.0
            }
            3 => c + Vec3::new(rng.gen(), rng.gen(), rng.gen()) * e * 6.0 - e * 3.0,
            _ => c + Vec3::new(rng.gen(), rng.gen(), rng.gen()) * e * 1.2 - e * 0.6,
        })
        .collect()
}

/// [`check_closest`] with every volume kind.
fn check_closest_all(m: &TriMesh, points: &[Vec3]) {
    check_closest::<Aabb>(m, points);
    check_closest::<Kdop14>(m, points);
    check_closest::<Kdop18>(m, points);
    check_closest::<Kdop26>(m, points);
    check_closest::<Obb>(m, points);
    check_closest::<Sphere>(m, points);
}

fn check_closest<BV: BoundingVolume>(m: &TriMesh, points: &[Vec3]) {
    let tris = triangles(m);
    let tol = 1e-9 * extent(&tris);
    for o in [
        BuildOptions::default(),
        BuildOptions {
            split: proxima::narrow::SplitRule::Mean,
            leaf_size: 3,
        },
    ] {
        let t = Mesh::<BV>::from_trimesh(m.clone(), o).unwrap();
        let mut q = Proximity::<BV>::default();
        for (k, &p) in points.iter().enumerate() {
            // Brute force with the library's point–triangle, and the reference.
            let (mut want, mut at) = (f64::INFINITY, Vec::new());
            let mut reference = f64::INFINITY;
            for (i, tri) in tris.iter().enumerate() {
                let d = closest_point_on_triangle(p, tri).distance(p.as_dvec3());
                if d < want {
                    (want, at) = (d, vec![i as u32]);
                } else if d == want {
                    at.push(i as u32);
                }
                reference = reference.min(point_triangle(p.as_dvec3(), tri.map(|v| v.as_dvec3())));
            }
            let ctx = format!("{} point {k} {p}", BV::NAME);
            let got = q.closest_point(&t, p).unwrap();
            assert_eq!(got.distance, want, "{ctx}");
            assert!(at.contains(&got.triangle), "{ctx}");
            assert!((got.distance - reference).abs() <= tol, "{ctx}");
            let tri = tris[got.triangle as usize].map(|v| v.as_dvec3());
            assert!(point_triangle(got.point, tri) <= tol, "{ctx}");
            assert!((got.point.distance(p.as_dvec3()) - got.distance).abs() <= tol);
            // Balls: the distance minus the radius, overlap iff within it.
            for r in [
                0.0f32,
                (want * 0.5) as f32,
                want as f32,
                (want * 1.5) as f32 + 1e-3,
            ] {
                let s = Sphere::new(p, r);
                let d = q.sphere_distance(&t, &s).unwrap();
                assert_eq!(d.distance, (want - r as f64).max(0.0), "{ctx} r {r}");
                let hit = q.sphere_overlaps(&t, &s).unwrap();
                assert_eq!(hit, want <= r as f64, "{ctx} r {r}");
            }
        }
    }
}

#[test]
fn closest_points_match_brute_force() {
    let mut rng = Pcg64::seed_from_u64(70);
    for name in ["bunny.obj", "teapot.obj", "rob.obj", "forearm.stl"] {
        let m = data(name);
        let pts = query_points(&m, 60, &mut rng);
        check_closest_all(&m, &pts);
    }
}

/// The generalized winding number of a closed mesh around `p` (sum of signed
/// solid angles / 4π, Van Oosterom–Strackee), in `f64`: ±1 inside, 0 outside
/// for points not too near the surface.
fn winding(m: &TriMesh, p: Vec3) -> f64 {
    let p = p.as_dvec3();
    let mut sum = 0.0;
    for i in 0..m.len() {
        let [a, b, c] = m.triangle(i).map(|v| v.as_dvec3() - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c));
        let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        sum += 2.0 * num.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

fn check_inside<BV: BoundingVolume>(m: &TriMesh, cases: &[(Vec3, bool)]) {
    let t = Mesh::<BV>::from_trimesh(m.clone(), BuildOptions::default()).unwrap();
    let mut q = Proximity::<BV>::default();
    for (k, &(p, want)) in cases.iter().enumerate() {
        let got = q.contains_point(&t, p).unwrap();
        assert_eq!(got, want, "{} case {k}: {p}", BV::NAME);
    }
}

fn check_inside_all(m: &TriMesh, cases: &[(Vec3, bool)]) {
    check_inside::<Aabb>(m, cases);
    check_inside::<Kdop14>(m, cases);
    check_inside::<Kdop18>(m, cases);
    check_inside::<Kdop26>(m, cases);
    check_inside::<Obb>(m, cases);
    check_inside::<Sphere>(m, cases);
}

#[test]
fn inside_the_bunny_agrees_with_the_winding_number() {
    let bunny = data("bunny.obj");
    let (lo, hi) = bounds(&bunny);
    let e = hi - lo;
    let t = Mesh::<Kdop18>::from_trimesh(bunny.clone(), BuildOptions::default()).unwrap();
    let mut q = Proximity::<Kdop18>::default();
    let mut rng = Pcg64::seed_from_u64(71);
    let mut cases = Vec::new();
    while cases.len() < 300 {
        let p = lo + Vec3::new(rng.gen(), rng.gen(), rng.gen()) * e * 1.2 - e * 0.1;
        // Away from the surface, the float winding number is unambiguous.
        if q.closest_point(&t, p).unwrap().distance < 1e-3 * e.length() as f64 {
            continue;
        }
        let w = winding(&bunny, p);
        assert!((w.abs() - w.abs().round()).abs() < 1e-3, "{w}");
        cases.push((p, w.abs().round() == 1.0));
    }
    let inside = cases.iter().filter(|c| c.1).count();
    assert!(inside > 30 && inside < 270, "{inside}");
    // Points exactly on the surface (vertices) count as inside.
    for i in (0..bunny.len()).step_by(47) {
        cases.push((bunny.triangle(i)[0], true));
    }
    check_inside_all(&bunny, &cases);
    check_inside_all(&flipped(&bunny), &cases);
}

#[test]
fn inside_a_cube_through_edges_and_corners() {
    // Coordinates on the grid of the cube's vertices (quarters): vertical rays
    // through vertices, along edges, along the triangulation's diagonals, and
    // points on faces, edges and corners. Inside iff in [0, 1]³ (closed).
    let m = cube(4, 1.0);
    let vals = [-0.25f32, 0.0, 0.25, 0.5, 0.75, 1.0, 1.25];
    let mut cases = Vec::new();
    for &x in &vals {
        for &y in &vals {
            for &z in &vals {
                let inside = [x, y, z].iter().all(|c| (0.0..=1.0).contains(c));
                cases.push((Vec3::new(x, y, z), inside));
            }
        }
    }
    // Off-grid but on the diagonals of the top and bottom faces' squares.
    for k in 0..8 {
        let s = 0.03125 + 0.125 * k as f32;
        cases.push((Vec3::new(s, s, 0.5), true));
        cases.push((Vec3::new(s, 1.0 - s, 0.5), true));
        cases.push((Vec3::new(s, s, -0.5), false));
    }
    check_inside_all(&m, &cases);
    check_inside_all(&flipped(&m), &cases);
    // Two disjoint cubes (one closed surface of two shells), and a cube inside a
    // cube (a hollow shell: parity).
    let outer = cube(2, 4.0);
    let mut v = outer.vertices().to_vec();
    let mut t = outer.triangles().to_vec();
    let base = v.len() as u32;
    v.extend(m.vertices().iter().map(|&p| p + Vec3::splat(1.5)));
    t.extend(m.triangles().iter().map(|tr| tr.map(|i| i + base)));
    let shell = weld(v, t);
    let shell_cases = [
        (Vec3::splat(0.5), true),
        (Vec3::splat(2.0), false),
        (Vec3::new(2.0, 2.0, 1.5), true), // on the inner cube's face
        (Vec3::new(2.0, 2.0, 3.0), true),
        (Vec3::splat(5.0), false),
    ];
    check_inside_all(&shell, &shell_cases);
}

#[test]
fn open_meshes_give_a_deterministic_parity() {
    // The teapot is open: the answer is the documented parity, not an inside
    // test, but it never panics and every volume type agrees.
    let teapot = data("teapot.obj");
    let mut rng = Pcg64::seed_from_u64(72);
    let pts = query_points(&teapot, 200, &mut rng);
    let t = Mesh::<Aabb>::from_trimesh(teapot.clone(), BuildOptions::default()).unwrap();
    let mut q = Proximity::<Aabb>::default();
    let cases: Vec<(Vec3, bool)> = pts
        .iter()
        .map(|&p| (p, q.contains_point(&t, p).unwrap()))
        .collect();
    check_inside_all(&teapot, &cases);
    // One triangle: only points on it are "inside".
    let tri = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]).unwrap();
    let t = Mesh::<Obb>::from_trimesh(tri.clone(), BuildOptions::default()).unwrap();
    let mut q = Proximity::<Obb>::default();
    assert!(q.contains_point(&t, Vec3::new(0.25, 0.25, 0.0)).unwrap());
    // Below the triangle, its ray crosses it once: parity 1.
    assert!(q.contains_point(&t, Vec3::new(0.25, 0.25, -1.0)).unwrap());
    assert!(!q.contains_point(&t, Vec3::new(0.25, 0.25, 1.0)).unwrap());
    let far = q.closest_point(&t, Vec3::new(0.25, 0.25, 2.0)).unwrap();
    assert_eq!(far.distance, 2.0);
    assert_eq!(far.point, DVec3::new(0.25, 0.25, 0.0));
}

#[test]
fn huge_coordinates() {
    // Regression: beyond √f32::MAX ≈ 1.8e19 a sphere volume's fitted radius
    // overflowed to infinity and its ray test missed (the inside test then
    // answered "outside" for inside points). Every volume answers as brute
    // force and the closed form, up to f32::MAX / 2 (`cube` forms `2 s`).
    for s in [2e19f32, 1e30, f32::MAX / 2.0] {
        let m = cube(2, s);
        let cases = [
            (Vec3::splat(0.5 * s), true),
            (Vec3::new(0.25 * s, 0.75 * s, 0.5 * s), true),
            (Vec3::new(0.5 * s, 0.5 * s, s), true), // on the top face
            (Vec3::splat(s), true),                 // a corner
            (Vec3::new(0.5 * s, 0.5 * s, -0.5 * s), false),
            (Vec3::new(-0.25 * s, 0.5 * s, 0.5 * s), false),
            (Vec3::new(1.0, 2.0, -3.0), false),
        ];
        check_inside_all(&m, &cases);
        let pts: Vec<Vec3> = cases.iter().map(|c| c.0).collect();
        check_closest_all(&m, &pts);
    }
}
