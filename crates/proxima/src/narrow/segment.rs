//! Closed, exact segment–segment and segment–triangle tests in 3D, for segments
//! that may be points. They serve degenerate triangles (a zero-area triangle is the
//! union of its edges) and segment casts.

use super::coplanar::{project3, segments_2d, triangles_2d};
use super::predicates::{orient3d, project, proper_axis};
use glam::Vec3;

/// Closed segments `pq` and `rs` share a point; either may be a single point.
/// Exact for finite input. Cost: one `orient3d`, and when coplanar up to twelve
/// `orient2d`.
pub fn segments_intersect(p: Vec3, q: Vec3, r: Vec3, s: Vec3) -> bool {
    if orient3d(p, q, r, s) != 0 {
        return false;
    }
    // Coplanar: the affine hull H of the four points has dimension <= 2, so some
    // coordinate projection is injective on H and there the 2D answer is the 3D
    // one; every other projection can only add intersections. Hence: the segments
    // meet iff all three projections do. (No need to pick the injective one.)
    (0..3).all(|k| segments_2d(project(p, k), project(q, k), project(r, k), project(s, k)))
}

/// Closed segment `pq` (possibly a point) and closed triangle `t` (possibly
/// degenerate) share a point. Exact for finite input. Cost: 2–5 `orient3d` in the
/// usual case.
pub fn segment_triangle_intersect(p: Vec3, q: Vec3, t: &[Vec3; 3]) -> bool {
    match proper_axis(t) {
        Some(axis) => segment_proper_triangle(p, q, t, axis),
        None => (0..3).any(|i| segments_intersect(p, q, t[i], t[(i + 1) % 3])),
    }
}

/// As [`segment_triangle_intersect`] for a triangle known to be non-degenerate,
/// with `axis` from [`proper_axis`].
pub(crate) fn segment_proper_triangle(p: Vec3, q: Vec3, t: &[Vec3; 3], axis: usize) -> bool {
    let sp = orient3d(t[0], t[1], t[2], p);
    let sq = orient3d(t[0], t[1], t[2], q);
    if sp == 0 && sq == 0 {
        // In the triangle's plane, which `axis` maps bijectively to 2D.
        let (p2, q2) = (project(p, axis), project(q, axis));
        return triangles_2d(&[p2, q2, q2], &project3(t, axis));
    }
    if sp * sq > 0 {
        return false;
    }
    // The line pq crosses the plane once, inside the closed segment; it passes
    // through the closed triangle iff it does not pass strictly on opposite sides
    // of two edges (Plücker signs).
    let s = [
        orient3d(p, q, t[0], t[1]),
        orient3d(p, q, t[1], t[2]),
        orient3d(p, q, t[2], t[0]),
    ];
    !(s.contains(&1) && s.contains(&-1))
}
