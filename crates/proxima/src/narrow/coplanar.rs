//! Closed, exact 2D intersection tests for points, segments and triangles that
//! were projected onto a coordinate plane (see [`predicates::project`]). Every one
//! accepts degenerate input: a segment may be a point, a triangle may be a
//! segment or a point. Signs come only from [`predicates::orient2d`].

use super::predicates::{self, orient2d, Point2};
use glam::Vec3;

/// Closed segments `pq` and `rs` share a point. Either may be a single point.
pub(crate) fn segments_2d(p: Point2, q: Point2, r: Point2, s: Point2) -> bool {
    let (o1, o2) = (orient2d(p, q, r), orient2d(p, q, s));
    let (o3, o4) = (orient2d(r, s, p), orient2d(r, s, q));
    if o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0 {
        // All four on one line (or both segments are points, or one is a point on
        // the other's line): the segments meet iff their boxes do.
        return overlap_1d(p[0], q[0], r[0], s[0]) && overlap_1d(p[1], q[1], r[1], s[1]);
    }
    // Otherwise the supporting lines are distinct (or one segment is a point off
    // the other's line, which the sign product rejects): each segment must reach
    // the other's line, closed.
    o1 * o2 <= 0 && o3 * o4 <= 0
}

fn overlap_1d(a: f32, b: f32, c: f32, d: f32) -> bool {
    a.min(b) <= c.max(d) && c.min(d) <= a.max(b)
}

/// Point `x` lies in the closed triangle `t`, which may be degenerate.
pub(crate) fn point_in_triangle_2d(x: Point2, t: &[Point2; 3]) -> bool {
    if orient2d(t[0], t[1], t[2]) == 0 {
        // A degenerate triangle is the union of its edges.
        return (0..3).any(|i| segments_2d(x, x, t[i], t[(i + 1) % 3]));
    }
    let d = [
        orient2d(t[0], t[1], x),
        orient2d(t[1], t[2], x),
        orient2d(t[2], t[0], x),
    ];
    // The three signs sum (as areas) to the triangle's non-zero orientation, so x
    // is outside iff some sign opposes another.
    !(d.contains(&1) && d.contains(&-1))
}

/// Closed triangles `a` and `b` (either possibly degenerate) share a point.
///
/// Characterization: two compact convex polygons meet iff an edge of one meets an
/// edge of the other, or one contains a vertex of the other (if no boundaries
/// cross, one lies inside the other; a degenerate triangle is its edges).
pub(crate) fn triangles_2d(a: &[Point2; 3], b: &[Point2; 3]) -> bool {
    for i in 0..3 {
        for j in 0..3 {
            if segments_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]) {
                return true;
            }
        }
    }
    point_in_triangle_2d(a[0], b) || point_in_triangle_2d(b[0], a)
}

/// Projects a 3D triangle along `axis`.
#[inline]
pub(crate) fn project3(t: &[Vec3; 3], axis: usize) -> [Point2; 3] {
    t.map(|p| predicates::project(p, axis))
}
