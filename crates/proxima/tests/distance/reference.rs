//! Independent `f64` references for the distance primitives, written as the
//! minimum of a convex quadratic over its domain (interior critical point, or
//! the boundary), not as the library's region-by-region algorithms; checked
//! against dense sampling and hand-computed cases in `triangles.rs`.

use proxima::glam::{DMat2, DVec2, DVec3, Vec3};
use proxima::narrow::triangles_intersect;

/// Distance from `p` to the closed segment `[a, b]`: the minimum of the
/// quadratic `|a + t (b - a) - p|²` at its critical point if inside `[0, 1]`,
/// else at an end.
pub fn point_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let mut best = p.distance(a).min(p.distance(b));
    let d = b - a;
    if d.length_squared() > 0.0 {
        let t = (p - a).dot(d) / d.length_squared();
        if (0.0..=1.0).contains(&t) {
            best = best.min(p.distance(a + d * t));
        }
    }
    best
}

/// Distance between closed segments: the convex quadratic in `(s, t)` over the
/// unit square has its minimum at the interior critical point (if the 2×2
/// system is regular and its solution is inside) or on an edge of the square,
/// where it is a point–segment distance from an end.
pub fn segment_segment(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let mut best = point_segment(p1, p2, q2)
        .min(point_segment(q1, p2, q2))
        .min(point_segment(p2, p1, q1))
        .min(point_segment(q2, p1, q1));
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    // Gradient zero: [d1·d1, -d1·d2; -d1·d2, d2·d2] (s, t) = (-d1·r, d2·r).
    let m = DMat2::from_cols(
        DVec2::new(d1.dot(d1), -d1.dot(d2)),
        DVec2::new(-d1.dot(d2), d2.dot(d2)),
    );
    let det = m.determinant();
    if det.abs() > 1e-12 * d1.length_squared() * d2.length_squared() {
        let st = m.inverse() * DVec2::new(-d1.dot(r), d2.dot(r));
        if (0.0..=1.0).contains(&st.x) && (0.0..=1.0).contains(&st.y) {
            best = best.min((p1 + d1 * st.x).distance(p2 + d2 * st.y));
        }
    }
    best
}

/// Distance from `p` to the closed triangle: the projection on the plane if it
/// is inside (tested with 2D cross products in an orthonormal frame of the
/// plane, built by Gram–Schmidt so that thin triangles stay accurate), else the
/// boundary (three point–segment distances). Degenerate triangles (no frame)
/// are their boundary.
pub fn point_triangle(p: DVec3, t: [DVec3; 3]) -> f64 {
    let mut best = point_segment(p, t[0], t[1])
        .min(point_segment(p, t[1], t[2]))
        .min(point_segment(p, t[2], t[0]));
    let (e1, e2, r) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let u = e1.normalize_or_zero();
    let w = (e2 - u * e2.dot(u)).normalize_or_zero();
    if u != DVec3::ZERO && w != DVec3::ZERO && (e2 - u * e2.dot(u)).length() > 1e-7 * e2.length() {
        let q = |x: DVec3| DVec2::new(x.dot(u), x.dot(w));
        let (a, b, c, x) = (DVec2::ZERO, q(e1), q(e2), q(r));
        let cross = |o: DVec2, p: DVec2, z: DVec2| (p - o).perp_dot(z - o);
        let s = [cross(a, b, x), cross(b, c, x), cross(c, a, x)];
        let area = cross(a, b, c);
        if s.iter().all(|&v| v * area >= 0.0) {
            best = best.min(p.distance(t[0] + u * x.x + w * x.y));
        }
    }
    best
}

/// Triangle–triangle distance: `0` if the exact test says they intersect, else
/// the minimum over the 6 corner–triangle and 9 edge–edge distances.
pub fn triangle_triangle(a: &[Vec3; 3], b: &[Vec3; 3]) -> f64 {
    if triangles_intersect(a, b) {
        return 0.0;
    }
    let (x, y) = (a.map(|v| v.as_dvec3()), b.map(|v| v.as_dvec3()));
    let mut best = f64::INFINITY;
    for i in 0..3 {
        best = best
            .min(point_triangle(x[i], y))
            .min(point_triangle(y[i], x));
        for j in 0..3 {
            best = best.min(segment_segment(x[i], x[(i + 1) % 3], y[j], y[(j + 1) % 3]));
        }
    }
    best
}

/// Points on a triangle: a barycentric grid of `n` steps per side (edges and
/// corners included).
pub fn samples(t: [DVec3; 3], n: usize) -> Vec<DVec3> {
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            let (s, u) = (i as f64 / n as f64, j as f64 / n as f64);
            out.push(t[0] + (t[1] - t[0]) * s + (t[2] - t[0]) * u);
        }
    }
    out
}
