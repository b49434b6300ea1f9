//! Shared helpers: meshes, poses, and the brute-force oracles over all triangle
//! pairs.

use proxima::glam::{Affine3A, DVec3, Quat, Vec3};
use proxima::narrow::{triangle_distance, TriMesh};
use rand::Rng;
use std::f32::consts::TAU;

/// A mesh of `shared/data`.
pub fn data(name: &str) -> TriMesh {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    proxima::io::load(format!("{dir}{name}")).unwrap()
}

/// The bounding box of a mesh's vertices.
pub fn bounds(m: &TriMesh) -> (Vec3, Vec3) {
    m.vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        })
}

/// A uniformly random rotation (Shoemake).
pub fn random_rotation(rng: &mut impl Rng) -> Quat {
    let (u1, u2, u3): (f32, f32, f32) = (rng.gen(), rng.gen(), rng.gen());
    Quat::from_xyzw(
        (1.0 - u1).sqrt() * (TAU * u2).sin(),
        (1.0 - u1).sqrt() * (TAU * u2).cos(),
        u1.sqrt() * (TAU * u3).sin(),
        u1.sqrt() * (TAU * u3).cos(),
    )
    .normalize()
}

/// Poses of `a` around `b`: a random rotation about `a`'s centre, then `a`'s
/// centre placed at `b`'s centre plus a random direction times `reach` (in units
/// of the two meshes' half-diagonals), so that small reaches intersect and large
/// ones are apart.
pub fn poses_around(
    a: &TriMesh,
    b: &TriMesh,
    n: usize,
    reach: std::ops::Range<f32>,
    rng: &mut impl Rng,
) -> Vec<Affine3A> {
    let ((la, ha), (lb, hb)) = (bounds(a), bounds(b));
    let (ca, cb) = ((la + ha) * 0.5, (lb + hb) * 0.5);
    let r = ((ha - la).length() + (hb - lb).length()) * 0.5;
    (0..n)
        .map(|k| {
            let dir = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
            .normalize_or(Vec3::X);
            let rot = Affine3A::from_quat(random_rotation(rng));
            let mut p = Affine3A::from_translation(cb + dir * r * rng.gen_range(reach.clone()))
                * rot
                * Affine3A::from_translation(-ca);
            if k % 5 == 4 {
                // Pure translations too (the axis-aligned volumes' shift path).
                p.matrix3 = proxima::glam::Mat3A::IDENTITY;
            }
            p
        })
        .collect()
}

/// `a`'s triangles moved by `pose` as the queries move them (`f32`).
pub fn posed(a: &TriMesh, pose: &Affine3A) -> Vec<[Vec3; 3]> {
    (0..a.len())
        .map(|i| a.triangle(i).map(|v| pose.transform_point3(v)))
        .collect()
}

pub fn triangles(m: &TriMesh) -> Vec<[Vec3; 3]> {
    (0..m.len()).map(|i| m.triangle(i)).collect()
}

/// The `f64` box of a triangle.
fn tbox(t: &[Vec3; 3]) -> (DVec3, DVec3) {
    let lo = t[0].min(t[1]).min(t[2]).as_dvec3();
    let hi = t[0].max(t[1]).max(t[2]).as_dvec3();
    (lo, hi)
}

/// Distance between two boxes, slightly lowered so that rounding can never make
/// it exceed the distance of their contents.
fn box_gap(a: &(DVec3, DVec3), b: &(DVec3, DVec3)) -> f64 {
    let g = (b.0 - a.1).max(a.0 - b.1).max(DVec3::ZERO);
    g.length() * (1.0 - 1e-12)
}

/// The brute force: every triangle pair of `ta × tb` measured by `dist` unless
/// its boxes are farther apart than the best distance so far (a box's distance
/// is a lower bound on its triangles': skipping changes no minimum). Returns the
/// minimum distance and every pair that attains it.
pub fn brute_nearest(
    ta: &[[Vec3; 3]],
    tb: &[[Vec3; 3]],
    dist: impl Fn(&[Vec3; 3], &[Vec3; 3]) -> f64,
) -> (f64, Vec<(u32, u32)>) {
    let bb: Vec<_> = tb.iter().map(tbox).collect();
    let mut best = f64::INFINITY;
    let mut at = Vec::new();
    for (i, t) in ta.iter().enumerate() {
        let ab = tbox(t);
        for (j, u) in tb.iter().enumerate() {
            if box_gap(&ab, &bb[j]) > best {
                continue;
            }
            let d = dist(t, u);
            if d < best {
                best = d;
                at.clear();
            }
            if d == best {
                at.push((i as u32, j as u32));
            }
        }
    }
    (best, at)
}

/// Every pair of `ta × tb` whose [`triangle_distance`] is at most `margin`,
/// sorted.
pub fn brute_within(ta: &[[Vec3; 3]], tb: &[[Vec3; 3]], margin: f64) -> Vec<(u32, u32)> {
    let bb: Vec<_> = tb.iter().map(tbox).collect();
    let mut out = Vec::new();
    for (i, t) in ta.iter().enumerate() {
        let ab = tbox(t);
        for (j, u) in tb.iter().enumerate() {
            if box_gap(&ab, &bb[j]) <= margin && triangle_distance(t, u).distance <= margin {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

/// The largest coordinate magnitude of a scene (for tolerances).
pub fn extent(ts: &[[Vec3; 3]]) -> f64 {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for t in ts {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    // In f64: beyond √f32::MAX the f32 length overflows.
    (hi.as_dvec3() - lo.as_dvec3()).length()
}

/// A sub-mesh: the triangles whose centroid is within `r` of `c` (vertices
/// compacted).
pub fn patch(m: &TriMesh, c: Vec3, r: f32) -> TriMesh {
    let mut map = vec![u32::MAX; m.vertices().len()];
    let (mut v, mut t) = (Vec::new(), Vec::new());
    for (i, tri) in m.triangles().iter().enumerate() {
        let cen = m.triangle(i).iter().copied().sum::<Vec3>() / 3.0;
        if cen.distance(c) > r {
            continue;
        }
        t.push(tri.map(|k| {
            if map[k as usize] == u32::MAX {
                map[k as usize] = v.len() as u32;
                v.push(m.vertices()[k as usize]);
            }
            map[k as usize]
        }));
    }
    TriMesh::new(v, t).unwrap()
}
