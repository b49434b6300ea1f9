//! Closest points on triangles in `f64`: point–triangle and triangle–triangle.
//!
//! Inputs are `f32` corners (widened exactly); every candidate point is built on
//! its triangle, so a reported distance is the length of a real pair of points
//! (up to rounding) and never below the true distance by more than rounding.

use super::segment::{closest_on_segment, closest_segment_segment};
use crate::narrow::triangles_intersect;
use glam::{DVec3, Vec3};

/// A triangle is used through its plane only if `sin²` of its angle at the first
/// corner exceeds this. Thinner triangles are handled as the union of their edges,
/// which lie within `sin · length` (< `1e-8` relative) of every point of the
/// triangle, while the plane of a thinner one is known to no better than
/// `ε / sin` (see the module docs of [`distance`](super)).
const PROPER_SIN2: f64 = 1e-16;

/// The plane bound ([`plane_gap`]) uses a triangle's plane only if `sin²` of its
/// angle at the first corner exceeds this: then the unit normal's direction is
/// known to `~ε / sin < 1e-12`, so signed distances to the plane are good to
/// `1e-12` of the coordinates.
const PLANE_SIN2: f64 = 1e-8;

/// Relative safety margin of [`plane_gap`] (of the largest coordinate): it
/// covers the rounding of the plane distances and of the triangle distance it
/// is compared with, so the bound never cuts a pair the full computation would
/// have kept.
const PLANE_MARGIN: f64 = 1e-10;

/// A triangle prepared for distance queries: corners in `f32` (for the exact
/// intersection test) and `f64`, the normal, the inward edge normals, and the
/// unit plane for [`plane_gap`].
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Tri64 {
    /// The corners as given.
    pub f: [Vec3; 3],
    /// The corners in `f64` (exact).
    pub v: [DVec3; 3],
    /// `(v1 - v0) × (v2 - v0)`.
    n: DVec3,
    /// `n · n`, or `0` for a triangle handled as its edges.
    nn: f64,
    /// `n × (v[i+1] - v[i])`: points into the triangle from edge `i`.
    m: [DVec3; 3],
    /// The unit normal, or zero if the plane is too uncertain for [`plane_gap`].
    unit: DVec3,
    /// `unit · v[0]`.
    offset: f64,
    /// The largest coordinate magnitude of the corners.
    scale: f64,
}

impl Tri64 {
    /// Prepares a triangle (any finite corners; degenerate ones allowed). ~70
    /// flops and a square root.
    #[inline]
    pub(crate) fn new(f: [Vec3; 3]) -> Tri64 {
        let v = f.map(|p| p.as_dvec3());
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let n = e1.cross(e2);
        let nn = n.dot(n);
        let ee = e1.dot(e1) * e2.dot(e2);
        let unit = if nn > PLANE_SIN2 * ee {
            n / nn.sqrt()
        } else {
            DVec3::ZERO
        };
        Tri64 {
            f,
            v,
            n,
            nn: if nn > PROPER_SIN2 * ee { nn } else { 0.0 },
            m: [
                n.cross(v[1] - v[0]),
                n.cross(v[2] - v[1]),
                n.cross(v[0] - v[2]),
            ],
            unit,
            offset: unit.dot(v[0]),
            scale: v[0].abs().max(v[1].abs()).max(v[2].abs()).max_element(),
        }
    }

    /// The projection of `p` on the triangle's plane if it falls in the closed
    /// triangle (and the triangle is used through its plane), else `None`.
    #[inline]
    pub(crate) fn project_inside(&self, p: DVec3) -> Option<DVec3> {
        if self.nn == 0.0 {
            return None;
        }
        for i in 0..3 {
            if (p - self.v[i]).dot(self.m[i]) < 0.0 {
                return None;
            }
        }
        Some(p - self.n * ((p - self.v[0]).dot(self.n) / self.nn))
    }

    /// The point of the closed triangle closest to `p`: the projection if it
    /// falls inside, else the closest point of the three edges.
    pub(crate) fn closest_point(&self, p: DVec3) -> DVec3 {
        if let Some(q) = self.project_inside(p) {
            return q;
        }
        let mut best = self.v[0];
        let mut bd = f64::INFINITY;
        for i in 0..3 {
            let q = closest_on_segment(p, self.v[i], self.v[(i + 1) % 3]);
            let d = p.distance_squared(q);
            if d < bd {
                (best, bd) = (q, d);
            }
        }
        best
    }
}

/// The closest points `(on a, on b)` and their squared distance, over the
/// candidates that contain the closest pair of two disjoint triangles: the 9
/// edge–edge pairs and the 6 corners whose projection falls inside the other
/// triangle (when the closest point of a face is on its boundary, an edge pair
/// has it). A degenerate triangle is the union of its edges, so the same
/// candidates serve. For intersecting triangles this is only an upper bound: the
/// callers decide intersection with the exact test first.
///
/// Early exit (Larsen et al.'s PQP `TriDist`): when the closest points `p, q` of
/// an edge pair have each triangle's third corner on its own side of the slab
/// between the planes through `p` and `q` orthogonal to `p - q`, the whole
/// triangles are on either side of it (each edge is, by optimality of `p, q`),
/// so `|p - q|` is the distance. ~100 flops when the first edge pair settles
/// it, ~500 at most.
#[inline]
pub(crate) fn disjoint_closest(a: &Tri64, b: &Tri64) -> (f64, DVec3, DVec3) {
    let mut best = (f64::INFINITY, a.v[0], b.v[0]);
    for i in 0..3 {
        let (p1, q1, r1) = (a.v[i], a.v[(i + 1) % 3], a.v[(i + 2) % 3]);
        for j in 0..3 {
            let (p2, q2, r2) = (b.v[j], b.v[(j + 1) % 3], b.v[(j + 2) % 3]);
            let (p, q) = closest_segment_segment(p1, q1, p2, q2);
            let w = p - q;
            let d = w.dot(w);
            if d < best.0 {
                best = (d, p, q);
                if (r1 - p).dot(w) >= 0.0 && (r2 - q).dot(w) <= 0.0 {
                    return best;
                }
            }
        }
    }
    let mut offer = |p: DVec3, q: DVec3| {
        let d = p.distance_squared(q);
        if d < best.0 {
            best = (d, p, q);
        }
    };
    for &p in &a.v {
        if let Some(q) = b.project_inside(p) {
            offer(p, q);
        }
    }
    for &q in &b.v {
        if let Some(p) = a.project_inside(q) {
            offer(p, q);
        }
    }
    best
}

/// A lower bound on the distance of two triangles from their planes: if every
/// corner of one lies strictly on one side of the other's plane, the smallest
/// of those distances (lowered by a rounding margin); else `0` (also for
/// triangles too thin to trust their plane). Never above the distance
/// [`pair_distance`] computes. ~40 flops.
#[inline]
pub(crate) fn plane_gap(a: &Tri64, b: &Tri64) -> f64 {
    let side = |t: &Tri64, o: &Tri64| {
        let s = o.v.map(|p| t.unit.dot(p) - t.offset);
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        lo.max(-hi)
    };
    let g = side(a, b).max(side(b, a));
    g - PLANE_MARGIN * a.scale.max(b.scale)
}

/// A pair of (nearly) coincident points, one on each of two triangles known to
/// intersect: the disjoint candidates, and where an edge of one triangle crosses
/// the other's plane, the crossing point with its closest point on that triangle
/// (an intersection of two triangles always contains a point of an edge of one
/// of them). Only for the rare pairs in contact, so it favours simplicity.
pub(crate) fn contact_witness(a: &Tri64, b: &Tri64) -> (DVec3, DVec3) {
    let (mut bd, mut pa, mut pb) = disjoint_closest(a, b);
    for (s, t, swap) in [(a, b, false), (b, a, true)] {
        if t.nn == 0.0 {
            continue; // a degenerate `t` is its edges: the edge pairs cover it
        }
        for i in 0..3 {
            let (p, q) = (s.v[i], s.v[(i + 1) % 3]);
            let (sp, sq) = ((p - t.v[0]).dot(t.n), (q - t.v[0]).dot(t.n));
            if sp * sq > 0.0 || sp == sq {
                continue;
            }
            let x = p + (q - p) * (sp / (sp - sq));
            let y = t.closest_point(x);
            let d = x.distance_squared(y);
            if d < bd {
                bd = d;
                (pa, pb) = if swap { (y, x) } else { (x, y) };
            }
        }
    }
    (pa, pb)
}

/// The distance of two triangles and their closest points `(on a, on b)`:
/// exactly `0` when they intersect by [`triangles_intersect`] (only consulted if
/// `may_touch`; a caller passes `false` only when the triangles are known to be
/// apart), else the `f64` distance of [`disjoint_closest`].
#[inline]
pub(crate) fn pair_distance(a: &Tri64, b: &Tri64, may_touch: bool) -> (f64, DVec3, DVec3) {
    if may_touch && triangles_intersect(&a.f, &b.f) {
        let (p, q) = contact_witness(a, b);
        return (0.0, p, q);
    }
    let (d2, p, q) = disjoint_closest(a, b);
    (d2.sqrt(), p, q)
}

/// The distance of two closed triangles and a closest pair of points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleDistance {
    /// The distance: exactly `0` when the triangles intersect according to
    /// [`triangles_intersect`] (exact), else the `f64` distance of the closest
    /// points below.
    pub distance: f64,
    /// A closest point on the first triangle, then one on the second. For
    /// intersecting triangles, two points (nearly) in common: on their triangles
    /// and within rounding of each other.
    pub points: [DVec3; 2],
}

/// The distance between two closed triangles (any finite `f32` corners;
/// degenerate triangles, segments and points included) and a closest pair of
/// points, computed in `f64`.
///
/// Intersection (touching included) is decided by the exact
/// [`triangles_intersect`] and gives exactly `0`. Otherwise the closest pair is
/// among the 9 edge–edge closest pairs and the 6 corners that project inside
/// the other triangle, each computed in `f64` from the exactly widened corners:
/// the result is within a few units of rounding of the exact distance of the
/// `f32` triangles (for triangles thinner than `1e-8` of their size, within
/// `1e-8` of their size: they count as the union of their edges). The distance
/// of disjoint triangles closer than rounding may come out as `0.0`.
///
/// Cost: ~500 flops, plus the exact test when their boxes overlap.
pub fn triangle_distance(a: &[Vec3; 3], b: &[Vec3; 3]) -> TriangleDistance {
    let (d, p, q) = pair_distance(&Tri64::new(*a), &Tri64::new(*b), true);
    TriangleDistance {
        distance: d,
        points: [p, q],
    }
}

/// The point of the closed triangle `t` (any finite corners, degenerate
/// included) closest to `p`, in `f64`: the projection on the plane if it falls
/// inside, else the closest point of the edges. O(1).
pub fn closest_point_on_triangle(p: Vec3, t: &[Vec3; 3]) -> DVec3 {
    Tri64::new(*t).closest_point(p.as_dvec3())
}
