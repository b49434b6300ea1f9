//! Exact orientation predicates on `f32` points: the single source of every sign
//! decision in the narrow phase (triangle–triangle, segment–triangle, ray casts).
//!
//! Each predicate evaluates its determinant in `f64` and returns its sign when a
//! forward error bound proves that sign right; otherwise it falls back to
//! Shewchuk's adaptive exact arithmetic. Both stages come from the `robust` crate (a
//! transcript of Shewchuk's "Adaptive Precision Floating-Point Arithmetic and Fast
//! Robust Geometric Predicates"). The answer is exact for every finite `f32` input:
//! `f32 -> f64` is exact, and with `f32` magnitudes (at most 2^128, at least 2^-149)
//! no product in the expansions can overflow or underflow `f64`, the only
//! conditions under which Shewchuk's predicates may err. Non-finite input gives an
//! unspecified sign, never a panic.
//!
//! Cost: a few dozen flops when the filter succeeds (nearly always); a few hundred
//! when the input is (nearly) degenerate.

use glam::Vec3;
use robust::{Coord, Coord3D};

/// A point projected onto a coordinate plane (see [`project`]).
pub type Point2 = [f32; 2];

#[inline]
fn c3(p: Vec3) -> Coord3D<f32> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

#[inline]
fn c2(p: Point2) -> Coord<f32> {
    Coord { x: p[0], y: p[1] }
}

#[inline]
fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Exact sign of `det[b - a, c - a, d - a] = ((b - a) × (c - a)) · (d - a)`:
/// `1` when `d` lies on the side of the plane `abc` that the normal
/// `(b - a) × (c - a)` points to, `-1` on the other side, `0` when the four points
/// are coplanar (or `a, b, c` are collinear). Swapping two arguments negates it.
///
/// Inlined filter first: the determinant of the rounded `f64` differences as a
/// cofactor expansion, certified when it exceeds `O3D_ERRBOUND` times its
/// permanent (Shewchuk's stage A); otherwise the `robust` crate's adaptive exact
/// evaluation decides.
#[inline]
pub fn orient3d(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> i8 {
    let o = a.as_dvec3();
    let (u, v, w) = (b.as_dvec3() - o, c.as_dvec3() - o, d.as_dvec3() - o);
    // Written out (no fused multiply-add): the bound is for this evaluation.
    let (yz, zy) = (u.y * v.z, u.z * v.y);
    let (zx, xz) = (u.z * v.x, u.x * v.z);
    let (xy, yx) = (u.x * v.y, u.y * v.x);
    let det = w.x * (yz - zy) + w.y * (zx - xz) + w.z * (xy - yx);
    let permanent = w.x.abs() * (yz.abs() + zy.abs())
        + w.y.abs() * (zx.abs() + xz.abs())
        + w.z.abs() * (xy.abs() + yx.abs());
    let bound = O3D_ERRBOUND * permanent;
    if det > bound {
        1
    } else if det < -bound {
        -1
    } else {
        // `robust` returns det[a - d, b - d, c - d], the negation of ours.
        -sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
    }
}

/// Relative error bound of the `f64` evaluation of `det[u, v, w]` (each entry a
/// rounded difference of `f32` coordinates) as `w · (u × v)`, relative to the
/// permanent (the same expansion with absolute values). Shewchuk's
/// `o3derrboundA = (7 + 56ε)ε`, `ε = 2^-53`, bounds this operation structure (three
/// rounded differences per vector, 2×2 minors, one dot product); `8ε` covers it.
/// No product can underflow or overflow for `f32` inputs (see the module docs).
pub(crate) const O3D_ERRBOUND: f64 = 8.0 * (f64::EPSILON / 2.0);

/// Exact sign of `det[b - a, c - a]`: `1` when `a, b, c` turn counter-clockwise,
/// `-1` clockwise, `0` when collinear (or two points coincide).
#[inline]
pub fn orient2d(a: Point2, b: Point2, c: Point2) -> i8 {
    sign(robust::orient2d(c2(a), c2(b), c2(c)))
}

/// Drops coordinate `axis` (0 = x, 1 = y, 2 = z), keeping the other two in cyclic
/// order (`yz`, `zx`, `xy`). Exact: no arithmetic.
#[inline]
pub fn project(p: Vec3, axis: usize) -> Point2 {
    match axis {
        0 => [p.y, p.z],
        1 => [p.z, p.x],
        _ => [p.x, p.y],
    }
}

/// Exact sign of component `axis` of the normal `(b - a) × (c - a)`, i.e. the
/// orientation of the triangle projected along that axis.
#[inline]
pub fn normal_sign(a: Vec3, b: Vec3, c: Vec3, axis: usize) -> i8 {
    orient2d(project(a, axis), project(b, axis), project(c, axis))
}

/// A coordinate axis along which the triangle projects to a non-degenerate 2D
/// triangle (its normal has a non-zero component there), or `None` when the
/// triangle is degenerate: its corners are collinear or coincide. Exact. Dropping
/// the returned axis maps the triangle's plane bijectively onto a coordinate plane,
/// so coplanar tests may run in 2D there.
#[inline]
pub fn proper_axis(t: &[Vec3; 3]) -> Option<usize> {
    [2, 0, 1]
        .into_iter()
        .find(|&k| normal_sign(t[0], t[1], t[2], k) != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sign_conventions() {
        let (o, x, y, z) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        assert_eq!(orient3d(o, x, y, z), 1);
        assert_eq!(orient3d(o, x, y, -z), -1);
        assert_eq!(orient3d(o, x, y, x + y), 0);
        assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1);
        assert_eq!(orient2d([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), -1);
        assert_eq!(proper_axis(&[o, x, y]), Some(2));
        assert_eq!(proper_axis(&[o, x, z]), Some(1));
        assert_eq!(proper_axis(&[o, x, 2.0 * x]), None);
        assert_eq!(proper_axis(&[y, y, y]), None);
    }

    #[test]
    fn exact_where_floats_fail() {
        // d is off the plane by one ulp-scale step that naive f32 arithmetic loses.
        let a = Vec3::new(1.0e30, 1.0, 0.0);
        let b = Vec3::new(-1.0e30, -1.0, 0.0);
        let c = Vec3::new(0.0, 0.0, 1.0);
        let on = Vec3::new(0.0, 0.0, 0.0);
        assert_eq!(orient3d(a, b, c, on), 0);
        let off = Vec3::new(0.0, f32::from_bits(1), 0.0); // smallest subnormal
        assert_ne!(orient3d(a, b, c, off), 0);
        assert_eq!(orient3d(a, b, c, off), -orient3d(a, b, c, -off));
        // Extreme magnitudes neither overflow nor underflow.
        let m = f32::MAX;
        assert_eq!(
            orient3d(
                Vec3::splat(-m),
                Vec3::new(m, -m, -m),
                Vec3::new(-m, m, -m),
                Vec3::splat(m)
            ),
            1
        );
    }
}
