//! Prepared triangles: the per-triangle part of the triangle–triangle test,
//! computed once and reused for every pair the triangle meets.
//!
//! In a mesh–mesh query each triangle is tested against several others (rob vs
//! env: ~200 pair tests per query over a few dozen distinct triangles), and the
//! plain [`triangles_intersect`] recomputes each triangle's box, projection axis
//! and plane for every pair. A [`PreparedTriangle`] keeps its box and its plane in
//! `f64` with the magnitudes needed for a rigorous error bound, so the common
//! verdicts cost a few dozen flops: "strictly on one side of the other plane"
//! (no contact), and the six corner-versus-plane signs that Guigue–Devillers
//! starts from. Whenever the bound cannot certify a sign (touching, coplanar,
//! degenerate or nearly so), the exact [`triangles_intersect`] decides, so the
//! answer is always the exact one.

use super::predicates::O3D_ERRBOUND;
use super::tri_tri::{guigue_devillers, one_strict_side, triangles_intersect};
use glam::{DVec3, Vec3};

/// The error bound of [`orient3d`](super::predicates::orient3d)'s filter: `side`
/// evaluates the same expansion with the triangle's part precomputed.
const ERRBOUND: f64 = O3D_ERRBOUND;

/// A triangle with its bounding box and plane precomputed for repeated
/// [`PreparedTriangle::intersects`] tests.
///
/// Size: 120 bytes. Building one costs ~30 flops; it pays off from the second
/// pair test that involves the triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreparedTriangle {
    corners: [Vec3; 3],
    lo: Vec3,
    hi: Vec3,
    /// The first corner in `f64` (exact).
    origin: DVec3,
    /// `(c1 - c0) × (c2 - c0)` evaluated in `f64` (rounded).
    normal: DVec3,
    /// Per component, the sum of the absolute values of the two products in the
    /// corresponding component of `normal` (the permanent's factors).
    normal_abs: DVec3,
}

impl PreparedTriangle {
    /// Prepares the triangle with these corners. Any finite input; degenerate
    /// triangles are allowed. O(1).
    pub fn new(corners: [Vec3; 3]) -> Self {
        let [p, q, r] = corners;
        let origin = p.as_dvec3();
        let e1 = q.as_dvec3() - origin;
        let e2 = r.as_dvec3() - origin;
        // Written out (no fused multiply-add) so the error bound's operation
        // structure is the one evaluated.
        let (yz, zy) = (e1.y * e2.z, e1.z * e2.y);
        let (zx, xz) = (e1.z * e2.x, e1.x * e2.z);
        let (xy, yx) = (e1.x * e2.y, e1.y * e2.x);
        PreparedTriangle {
            corners,
            lo: p.min(q).min(r),
            hi: p.max(q).max(r),
            origin,
            normal: DVec3::new(yz - zy, zx - xz, xy - yx),
            normal_abs: DVec3::new(
                yz.abs() + zy.abs(),
                zx.abs() + xz.abs(),
                xy.abs() + yx.abs(),
            ),
        }
    }

    /// The corners.
    #[inline]
    pub fn corners(&self) -> &[Vec3; 3] {
        &self.corners
    }

    /// `orient3d(c0, c1, c2, p)` when the `f64` evaluation certifies it (then it
    /// is `1` or `-1`), or `0` when the bound cannot decide (the exact sign may be
    /// anything). A degenerate triangle never certifies: its exact determinant is 0.
    #[inline]
    fn side(&self, p: Vec3) -> i8 {
        let c = p.as_dvec3() - self.origin;
        let n = self.normal;
        let det = n.x * c.x + n.y * c.y + n.z * c.z;
        let m = self.normal_abs;
        let c = c.abs();
        let bound = ERRBOUND * (m.x * c.x + m.y * c.y + m.z * c.z);
        if det > bound {
            1
        } else if det < -bound {
            -1
        } else {
            0
        }
    }

    /// Certified signs of `other`'s corners against this triangle's plane.
    #[inline]
    fn sides(&self, other: &PreparedTriangle) -> [i8; 3] {
        // Spelled out: `array::map` here compiles to a slower generic loop.
        let c = &other.corners;
        [self.side(c[0]), self.side(c[1]), self.side(c[2])]
    }

    /// Whether the two closed triangles share a point: always the same answer as
    /// [`triangles_intersect`] on their corners (exact, touching counts).
    ///
    /// Cost: a box test; then up to six corner-versus-plane evaluations in `f64`
    /// with an error bound (~20 flops each); a pair certified not to meet stops
    /// there, a certified crossing pair takes Guigue–Devillers' two final exact
    /// `orient3d`. Only uncertified configurations (touching, coplanar, degenerate
    /// or within rounding of it) run the full exact test.
    pub fn intersects(&self, other: &PreparedTriangle) -> bool {
        if !(self.lo.cmple(other.hi).all() && other.lo.cmple(self.hi).all()) {
            return false;
        }
        let sb = self.sides(other);
        if one_strict_side(sb) {
            return false;
        }
        let sa = other.sides(self);
        if one_strict_side(sa) {
            return false;
        }
        if sa.contains(&0) || sb.contains(&0) {
            // Uncertified (possibly zero) sign: the exact test decides.
            return triangles_intersect(&self.corners, &other.corners);
        }
        // All six signs are exact and non-zero: both triangles are proper, not
        // coplanar, and each crosses the other's plane.
        guigue_devillers(self.corners, sa, other.corners, sb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::predicates::orient3d;

    fn exact_side(t: &PreparedTriangle, p: Vec3) -> i8 {
        orient3d(t.corners[0], t.corners[1], t.corners[2], p)
    }

    #[test]
    fn certified_sides_are_exact() {
        // Points near and on planes, across magnitudes: a certified sign must be
        // the exact one.
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut certified = 0;
        for i in 0..20_000 {
            let s = [1.0f32, 1e-20, 1e20, 3.0][i % 4];
            let t = [(); 3].map(|_| Vec3::new(next(), next(), next()) * s);
            let pt = PreparedTriangle::new(t);
            // A point on the plane up to rounding: an affine combination.
            let (u, v) = (next(), next());
            let on = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v;
            let off = Vec3::new(next(), next(), next()) * s;
            for p in [on, off, t[0], t[1]] {
                let got = pt.side(p);
                if got != 0 {
                    certified += 1;
                    assert_eq!(got, exact_side(&pt, p), "{t:?} {p:?}");
                }
            }
        }
        assert!(certified > 20_000, "{certified}");
    }

    #[test]
    fn degenerate_triangles_never_certify() {
        let t = PreparedTriangle::new([Vec3::ZERO, Vec3::X, 2.0 * Vec3::X]);
        assert_eq!(t.side(Vec3::Y), 0);
        let u = PreparedTriangle::new([Vec3::ZERO, Vec3::Y, Vec3::Z]);
        // The degenerate triangle touches u at the origin.
        assert!(t.intersects(&u) && u.intersects(&t));
    }
}
