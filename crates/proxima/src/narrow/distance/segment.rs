//! Closest points of two segments and of a point and a segment, in `f64`.

use glam::DVec3;

/// Below this `sin²` of the angle between two segments they are treated as
/// parallel: the `f64` solve would divide by a denominator made of rounding
/// error, while any parameter on the parallel branch is within
/// `sin · length` of the optimum (below `1e-8` relative).
const PARALLEL_SIN2: f64 = 1e-16;

/// The closest points `(c1, c2)` of the closed segments `[p1, q1]` and `[p2, q2]`;
/// either may be a single point. `c1` lies on the first segment and `c2` on the
/// second (up to rounding), so `|c1 - c2|` is never below their true distance by
/// more than rounding.
///
/// Ericson, *Real-Time Collision Detection*, §5.1.9: minimize
/// `|p1 + s d1 - p2 - t d2|²` over `[0, 1]²` by the unconstrained `s`, then `t`
/// for it, re-solving `s` when `t` clamps. Parallel (or nearly parallel) segments
/// start from `s = 0`, which the re-solve makes optimal. O(1), ~40 flops.
#[inline]
pub(crate) fn closest_segment_segment(
    p1: DVec3,
    q1: DVec3,
    p2: DVec3,
    q2: DVec3,
) -> (DVec3, DVec3) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t);
    if a == 0.0 && e == 0.0 {
        (s, t) = (0.0, 0.0);
    } else if a == 0.0 {
        (s, t) = (0.0, (f / e).clamp(0.0, 1.0));
    } else {
        let c = d1.dot(r);
        if e == 0.0 {
            (s, t) = ((-c / a).clamp(0.0, 1.0), 0.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > PARALLEL_SIN2 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            (s, t) = if t0 < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t0 > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s0, t0)
            };
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

/// The point of the closed segment `[a, b]` (possibly a point) closest to `p`.
#[inline]
pub(crate) fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let dd = d.dot(d);
    if dd == 0.0 {
        return a;
    }
    a + d * ((p - a).dot(d) / dd).clamp(0.0, 1.0)
}
