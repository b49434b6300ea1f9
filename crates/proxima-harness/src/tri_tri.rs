//! A slow reference for `proxima::narrow::triangles_intersect` [sources: tri-tri],
//! shared by the library's exactness tests (`crates/proxima/tests/tri_tri`) and
//! the `tri_tri` fuzz target. Built from the exact `robust` predicates with a
//! decomposition different from the library's (which is Guigue–Devillers plus
//! special cases):
//!
//! Two closed triangles A, B meet iff an edge of A meets B or an edge of B meets A.
//! Proof: if A is degenerate it *is* the union of its edges (likewise B). If both
//! are proper, take an extreme point x of the compact convex set A ∩ B. Were x in
//! the relative interior of both, then (planes equal) a disc around x in the plane,
//! or (planes different) an interval around x on the common line, would lie in
//! A ∩ B, contradicting extremality; so x is on an edge of A or of B.
//!
//! Segment vs triangle: a degenerate triangle is its edges (segment vs segment);
//! otherwise, endpoints strictly on one side: no; both on the plane: coplanar 2D;
//! else the line crosses the plane inside the segment, at a point inside the
//! closed triangle iff the three Plücker signs are not mixed.
//! Coplanar 3D configurations are decided by requiring intersection in *all three*
//! coordinate projections (an injective one exists since the hull has dimension
//! <= 2, and the others can only add intersections). 2D segment intersection is
//! the textbook (CLRS) "proper crossing or an endpoint on the other segment".

use proxima::glam::Vec3;
use robust::{Coord, Coord3D};

type P2 = [f64; 2];

fn o3(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> i32 {
    let c3 = |p: Vec3| Coord3D {
        x: p.x as f64,
        y: p.y as f64,
        z: p.z as f64,
    };
    let r = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    (r > 0.0) as i32 - (r < 0.0) as i32
}

fn o2(a: P2, b: P2, c: P2) -> i32 {
    let c2 = |p: P2| Coord { x: p[0], y: p[1] };
    let r = robust::orient2d(c2(a), c2(b), c2(c));
    (r > 0.0) as i32 - (r < 0.0) as i32
}

fn proj(p: Vec3, k: usize) -> P2 {
    let v = p.to_array();
    [v[(k + 1) % 3] as f64, v[(k + 2) % 3] as f64]
}

fn on_segment(a: P2, b: P2, x: P2) -> bool {
    o2(a, b, x) == 0
        && a[0].min(b[0]) <= x[0]
        && x[0] <= a[0].max(b[0])
        && a[1].min(b[1]) <= x[1]
        && x[1] <= a[1].max(b[1])
}

fn seg_seg_2d(p: P2, q: P2, r: P2, s: P2) -> bool {
    let proper = o2(p, q, r) * o2(p, q, s) < 0 && o2(r, s, p) * o2(r, s, q) < 0;
    proper
        || on_segment(p, q, r)
        || on_segment(p, q, s)
        || on_segment(r, s, p)
        || on_segment(r, s, q)
}

fn point_in_tri_2d(x: P2, t: [P2; 3]) -> bool {
    let d = [o2(t[0], t[1], x), o2(t[1], t[2], x), o2(t[2], t[0], x)];
    let strict_inside =
        o2(t[0], t[1], t[2]) != 0 && (d.iter().all(|&s| s >= 0) || d.iter().all(|&s| s <= 0));
    strict_inside || (0..3).any(|i| on_segment(t[i], t[(i + 1) % 3], x))
}

fn seg_tri_2d(p: P2, q: P2, t: [P2; 3]) -> bool {
    point_in_tri_2d(p, t) || (0..3).any(|i| seg_seg_2d(p, q, t[i], t[(i + 1) % 3]))
}

fn seg_seg(p: Vec3, q: Vec3, r: Vec3, s: Vec3) -> bool {
    o3(p, q, r, s) == 0
        && (0..3).all(|k| seg_seg_2d(proj(p, k), proj(q, k), proj(r, k), proj(s, k)))
}

fn collinear(t: &[Vec3; 3]) -> bool {
    (0..3).all(|k| o2(proj(t[0], k), proj(t[1], k), proj(t[2], k)) == 0)
}

/// Closed segment `pq` meets closed triangle `t`.
pub fn seg_tri(p: Vec3, q: Vec3, t: &[Vec3; 3]) -> bool {
    if collinear(t) {
        return (0..3).any(|i| seg_seg(p, q, t[i], t[(i + 1) % 3]));
    }
    let (sp, sq) = (o3(t[0], t[1], t[2], p), o3(t[0], t[1], t[2], q));
    if sp == 0 && sq == 0 {
        return (0..3).all(|k| seg_tri_2d(proj(p, k), proj(q, k), t.map(|v| proj(v, k))));
    }
    if sp * sq > 0 {
        return false;
    }
    let s = [
        o3(p, q, t[0], t[1]),
        o3(p, q, t[1], t[2]),
        o3(p, q, t[2], t[0]),
    ];
    s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
}

/// The reference answer: closed triangles `a` and `b` share a point. Exact for
/// every finite input; about 40 orientation predicates.
pub fn intersect(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    (0..3).any(|i| seg_tri(a[i], a[(i + 1) % 3], b))
        || (0..3).any(|i| seg_tri(b[i], b[(i + 1) % 3], a))
}
