//! The closed overlap tests, one function per shape pair. Every index and every
//! method on the shape types calls these; nothing re-implements them.
//!
//! Closed means boundaries count: touching shapes overlap. Costs are O(1).

use crate::geom::{Aabb, Frustum, Ray, Relation, Sphere};
use glam::{Vec3, Vec4};

// The sphere tests are exact: whether `|p - q| <= r1 + r2` is decided for the
// real numbers the `f32` inputs denote, at every magnitude. A fast `f64`
// evaluation decides unless the two sides agree to 1e-12 relative; then an exact
// evaluation (error-free transformations, see `exact.rs`) decides. In `f64` no
// square of a finite `f32` overflows (x² <= 1.2e77), so there is no `inf <= inf`.
// The other tests (rays, frustums) compute in `f64`: no overflow for finite
// inputs, rounding ~1e-16 relative.

#[inline]
fn d3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Exactly: `|p - q| <= r1 + r2` (radii non-negative).
#[inline]
pub(crate) fn within(p: Vec3, q: Vec3, r1: f32, r2: f32) -> bool {
    // `f32` filter first: this test is the inner loop of every pair search. The
    // computed squares carry a relative error below 6·2⁻²⁴ ≈ 4e-7 (one rounding per
    // subtraction, square and sum), so a gap wider than 1e-5 of their size (plus
    // an absolute term for underflow) decides with a 25× safety factor. An overflow
    // to ∞ makes both comparisons false and falls through to `f64`.
    let d = p - q;
    let d2f = d.length_squared();
    let rsf = r1 + r2;
    let rs2f = rsf * rsf;
    let marginf = f32_margin(d2f, rs2f);
    if d2f < rs2f - marginf {
        return true;
    }
    if d2f > rs2f + marginf {
        return false;
    }
    let (a, b) = (d3(p), d3(q));
    let d2: f64 = (0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum();
    let rs = r1 as f64 + r2 as f64;
    let rs2 = rs * rs;
    // The fast path's relative error is below 1e-15 (a few roundings of 2^-53).
    let margin = 1e-12 * (d2 + rs2);
    if d2 < rs2 - margin {
        true
    } else if d2 > rs2 + margin {
        false
    } else {
        super::exact::within(a, b, r1 as f64, r2 as f64)
    }
}

/// Rounding margin of the `f32` filter of [`within`] for computed squares `d2f`
/// (distance) and `rs2f` (radius sum).
#[inline(always)]
fn f32_margin(d2f: f32, rs2f: f32) -> f32 {
    1e-5 * (d2f + rs2f) + 1e-35
}

/// Conservative pre-test for batched sphere–sphere loops, on plain coordinates
/// (structure-of-arrays callers): `false` only if [`sphere_sphere`] is `false`
/// for the spheres `(a, ar)` and `(b, br)`, so those need no exact test; `true`
/// means "run [`sphere_sphere`]". It is the rejection step of `sphere_sphere`'s
/// own `f32` filter (same operations, so the same rounding; a square is
/// unchanged by the sign of the difference), branch-free so that loops over
/// many spheres vectorize. O(1).
#[allow(clippy::too_many_arguments, clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub fn sphere_sphere_candidate(
    ax: f32,
    ay: f32,
    az: f32,
    ar: f32,
    bx: f32,
    by: f32,
    bz: f32,
    br: f32,
) -> bool {
    let (dx, dy, dz) = (ax - bx, ay - by, az - bz);
    let d2f = dx * dx + dy * dy + dz * dz;
    let rsf = ar + br;
    let rs2f = rsf * rsf;
    // Written as `!(>)` so that a NaN or an overflow to ∞ stays a candidate,
    // exactly as `within` falls through to `f64` then.
    !(d2f > rs2f + f32_margin(d2f, rs2f))
}

/// [`sphere_sphere_candidate`] for four spheres at once, given lane by lane
/// (`x[j]`, `y[j]`, `z[j]`, `r[j]` for sphere `j`), against `s`: bit `j` of the
/// result is set when sphere `j` is a candidate, i.e. clear only if
/// [`sphere_sphere`] is `false` for it. The same operations as the scalar
/// pre-test in each SIMD lane, so the same rounding. O(1).
#[inline(always)]
pub fn sphere_sphere_candidates4(x: Vec4, y: Vec4, z: Vec4, r: Vec4, s: &Sphere) -> u32 {
    let dx = x - Vec4::splat(s.center.x);
    let dy = y - Vec4::splat(s.center.y);
    let dz = z - Vec4::splat(s.center.z);
    let d2f = dx * dx + dy * dy + dz * dz;
    let rsf = r + Vec4::splat(s.radius);
    let rs2f = rsf * rsf;
    let margin = Vec4::splat(1e-5) * (d2f + rs2f) + Vec4::splat(1e-35);
    // `>` is false for NaN, so NaN and ∞ lanes stay candidates, as in the scalar test.
    !d2f.cmpgt(rs2f + margin).bitmask() & 0xF
}

/// Sphere–sphere: `|c1 - c2| <= r1 + r2`, decided exactly (see the module).
#[inline]
pub fn sphere_sphere(a: &Sphere, b: &Sphere) -> bool {
    within(a.center, b.center, a.radius, b.radius)
}

/// Sphere–AABB: the distance from the centre to the box (its closest point) is at
/// most `r`, decided exactly.
#[inline]
pub fn sphere_aabb(s: &Sphere, b: &Aabb) -> bool {
    let q = s.center.clamp(b.min, b.max);
    within(s.center, q, s.radius, 0.0)
}

/// AABB–AABB: the intervals overlap on all three axes.
#[inline]
pub fn aabb_aabb(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Ray (or segment) against a sphere: the smallest `t` in `[0, ray.max_t]` at which
/// the ray is in the closed ball, or `None`. An origin inside the ball gives `0`.
///
/// Uses the closest-approach form (distance of the centre from the line computed
/// from the projected point, not from `b² - ac`) to avoid cancellation for long
/// rays, in `f64`; the returned `t` is that value rounded to `f32`, and it is that
/// rounded value which is compared with `max_t`.
#[inline]
pub fn ray_sphere(ray: &Ray, s: &Sphere) -> Option<f32> {
    let (o, c, d) = (d3(ray.origin), d3(s.center), d3(ray.dir));
    let m = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let r = s.radius as f64;
    let r2 = r * r;
    if within(ray.origin, s.center, s.radius, 0.0) {
        return Some(0.0);
    }
    let b = dot(m, d);
    if b >= 0.0 {
        // Outside and not approaching: the distance only grows with t.
        return None;
    }
    let a = dot(d, d);
    let tc = -b / a;
    let closest = [m[0] + d[0] * tc, m[1] + d[1] * tc, m[2] + d[2] * tc];
    let h2 = r2 - dot(closest, closest);
    if h2 < 0.0 {
        return None;
    }
    let t = ((tc - (h2 / a).sqrt()).max(0.0)) as f32;
    (t <= ray.max_t).then_some(t)
}

/// Ray (or segment) against a box: the parameter interval `[t_enter, t_exit]` of the
/// ray inside the closed box, clipped to `[0, ray.max_t]`, or `None`.
///
/// A zero direction component is handled explicitly (the ray is inside that slab for
/// all `t` or for none), so no `0 * ∞` NaN arises. Computed in `f64` (a tiny
/// direction component gives a huge but finite inverse); the interval is rounded
/// outward to `f32`, so it always contains the exact one.
#[inline]
pub fn ray_aabb(ray: &Ray, b: &Aabb) -> Option<(f32, f32)> {
    let mut t0 = 0.0f64;
    let mut t1 = ray.max_t as f64;
    for axis in 0..3 {
        let o = ray.origin[axis] as f64;
        let d = ray.dir[axis] as f64;
        let (lo, hi) = (b.min[axis] as f64, b.max[axis] as f64);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d;
        let (mut ta, mut tb) = ((lo - o) * inv, (hi - o) * inv);
        if ta > tb {
            std::mem::swap(&mut ta, &mut tb);
        }
        // `max`/`min` ignore a NaN operand (a NaN box), which keeps the test
        // conservative.
        t0 = t0.max(ta);
        t1 = t1.min(tb);
        if t0 > t1 {
            return None;
        }
    }
    Some((round_down(t0), round_up(t1)))
}

/// The largest `f32` not above `x`.
#[inline]
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) > x {
        step_down(y)
    } else {
        y
    }
}

/// The next `f32` toward −∞ (`f32::next_down` needs Rust 1.86; the MSRV is 1.80).
#[inline]
fn step_down(y: f32) -> f32 {
    if y.is_nan() || y == f32::NEG_INFINITY {
        y
    } else if y == 0.0 {
        -f32::from_bits(1)
    } else if y > 0.0 {
        f32::from_bits(y.to_bits() - 1)
    } else {
        f32::from_bits(y.to_bits() + 1)
    }
}

/// The smallest `f32` not below `x`.
#[inline]
fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        -step_down(-y)
    } else {
        y
    }
}

#[inline]
fn signed_distance(p: &crate::geom::Plane, c: [f64; 3]) -> f64 {
    let n = d3(p.normal);
    n[0] * c[0] + n[1] * c[1] + n[2] * c[2] + p.d as f64
}

/// Frustum–sphere, per plane: `Outside` if the sphere is entirely on the outer side of
/// some plane (`n·c + d < -r |n|`; `|n| = 1` for normalized planes), `Inside` if it is at least `r` inside every plane,
/// else `Intersecting`. A sphere exactly touching a plane from outside is not culled.
/// In `f64`; a NaN distance (only from a NaN plane) never culls.
#[inline]
pub fn frustum_sphere(f: &Frustum, s: &Sphere) -> Relation {
    let mut rel = Relation::Inside;
    let c = d3(s.center);
    for p in &f.planes {
        let d = signed_distance(p, c);
        // The radius in the plane's units: `r |n|`. For the unit normals of
        // `from_view_projection` this is `r`; for a zero normal (a degenerate
        // matrix: the plane is everywhere inside or everywhere outside) it is 0,
        // consistent with `frustum_aabb`, whose box extent also scales with |n|.
        let n = d3(p.normal);
        let r = s.radius as f64 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        if d < -r {
            return Relation::Outside;
        }
        if d < r || d.is_nan() {
            rel = Relation::Intersecting;
        }
    }
    rel
}

/// Frustum–AABB over the planes whose bit is set in `mask` (bit `i` = plane `i`).
///
/// Returns the relation and the mask of planes that still cut the box: planes that
/// contain the box entirely are dropped, so a child of this box needs to be tested
/// only against the returned mask (plane masking). `Inside` when the returned mask
/// is empty. A box that merely touches a plane from outside is not culled.
///
/// In `f64`, and conservative for boxes with infinite sides (loose bounds of huge
/// objects): a NaN distance neither culls nor proves a plane contains the box.
#[inline]
pub fn frustum_aabb(f: &Frustum, b: &Aabb, mask: u8) -> (Relation, u8) {
    let (lo, hi) = (d3(b.min), d3(b.max));
    let c = [0, 1, 2].map(|i| lo[i] * 0.5 + hi[i] * 0.5);
    let h = [0, 1, 2].map(|i| hi[i] * 0.5 - lo[i] * 0.5);
    let mut out_mask = 0u8;
    for (i, p) in f.planes.iter().enumerate() {
        let bit = 1u8 << i;
        if mask & bit == 0 {
            continue;
        }
        let s = signed_distance(p, c);
        let n = d3(p.normal.abs());
        let e = n[0] * h[0] + n[1] * h[1] + n[2] * h[2];
        if s + e < 0.0 {
            return (Relation::Outside, 0);
        }
        if s - e < 0.0 || (s - e).is_nan() {
            out_mask |= bit;
        }
    }
    if out_mask == 0 {
        (Relation::Inside, 0)
    } else {
        (Relation::Intersecting, out_mask)
    }
}

/// Squared distance between two points (helper for callers that need it; in `f32`,
/// so it overflows to infinity beyond about 1.8e19).
#[inline]
pub fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    (a - b).length_squared()
}

#[cfg(test)]
mod tests {

    #[test]
    fn candidates4_agree_with_the_scalar_pre_test_and_never_drop_an_overlap() {
        // Near-tangent, overlapping, far, huge and tiny spheres.
        let mut st = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            (st >> 40) as f32 / (1u64 << 24) as f32
        };
        for k in 0..20_000 {
            let scale = [1e-3f32, 1.0, 1e3, 1e30][k % 4];
            let s = Sphere::new(Vec3::new(next(), next(), next()) * scale, next() * scale);
            let mut lanes = [Sphere::default(); 4];
            for l in &mut lanes {
                let dir = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize_or(Vec3::X);
                let r = next() * scale;
                // Around tangency: distance = (r + s.r) * (1 +- small).
                let t = (r + s.radius) * (1.0 + (next() - 0.5) * 1e-5);
                *l = Sphere::new(s.center + dir * t, r);
            }
            let v = |f: fn(&Sphere) -> f32| Vec4::from_array(lanes.map(|l| f(&l)));
            let mask = sphere_sphere_candidates4(
                v(|l| l.center.x),
                v(|l| l.center.y),
                v(|l| l.center.z),
                v(|l| l.radius),
                &s,
            );
            for (j, l) in lanes.iter().enumerate() {
                let c = l.center;
                let scalar = sphere_sphere_candidate(
                    c.x, c.y, c.z, l.radius, s.center.x, s.center.y, s.center.z, s.radius,
                );
                assert_eq!(mask >> j & 1 == 1, scalar, "{l:?} vs {s:?}");
                if sphere_sphere(l, &s) {
                    assert!(scalar, "overlap rejected: {l:?} vs {s:?}");
                }
            }
        }
    }

    use super::*;
    use glam::{vec3, Mat4};

    /// The 4-lane prefilter never clears a lane that overlaps, at any magnitude,
    /// and clears most of those far apart.
    #[test]
    fn candidates4_never_rejects_an_overlap_at_any_magnitude() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mut cleared = 0;
        for k in 0..20_000 {
            let scale = [1e-20f32, 1e-3, 1.0, 1e3, 1e18, 1e30][k % 6];
            let mut v = || rng.gen_range(-4.0f32..4.0) * scale;
            let a = Sphere::new(vec3(v(), v(), v()), v().abs());
            let lanes: Vec<Sphere> = (0..4)
                .map(|_| Sphere::new(vec3(v(), v(), v()), v().abs()))
                .collect();
            let col = |f: fn(&Sphere) -> f32| Vec4::from_array([0, 1, 2, 3].map(|i| f(&lanes[i])));
            let bits = sphere_sphere_candidates4(
                col(|s| s.center.x),
                col(|s| s.center.y),
                col(|s| s.center.z),
                col(|s| s.radius),
                &a,
            );
            for (i, l) in lanes.iter().enumerate() {
                if bits & (1 << i) == 0 {
                    assert!(!sphere_sphere(&a, l), "{a:?} {l:?}");
                    cleared += 1;
                }
            }
        }
        assert!(cleared > 20_000, "{cleared}");
        // Touching spheres on a coarse grid (exact ties) are kept.
        let a = Sphere::new(Vec3::ZERO, 1.0);
        let bits = sphere_sphere_candidates4(
            Vec4::new(2.0, 0.0, 3.0, 1.0),
            Vec4::ZERO,
            Vec4::ZERO,
            Vec4::ONE,
            &a,
        );
        assert_eq!(bits, 0b1011);
    }

    /// The `f32` filter of `within` never decides differently from the exact
    /// predicate: on a coarse grid exact ties are common, and magnitudes up to
    /// 1e30 overflow `f32` squares.
    #[test]
    fn f32_filter_agrees_with_exact_predicate() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut ties = 0;
        for k in 0..400_000 {
            let scale = [1.0f32, 1.0 / 64.0, 1e-20, 1e15, 1e30][k % 5];
            let mut g = || rng.gen_range(-8i32..=8) as f32 * scale;
            let p = glam::vec3(g(), g(), g());
            let q = glam::vec3(g(), g(), g());
            let (r1, r2) = (g().abs(), g().abs());
            let d = |v: glam::Vec3| [v.x as f64, v.y as f64, v.z as f64];
            let exact = crate::geom::exact::within(d(p), d(q), r1 as f64, r2 as f64);
            assert_eq!(within(p, q, r1, r2), exact, "{p} {q} {r1} {r2}");
            let (dd, rs) = ((p - q).length_squared(), (r1 + r2) * (r1 + r2));
            ties += (scale == 1.0 && dd == rs) as u32;
        }
        assert!(ties > 100, "the grid must produce exact ties ({ties})");
    }

    #[test]
    fn touching_counts() {
        let a = Sphere::new(Vec3::ZERO, 1.0);
        let b = Sphere::new(vec3(2.0, 0.0, 0.0), 1.0);
        assert!(sphere_sphere(&a, &b));
        let bx = Aabb::new(vec3(1.0, -1.0, -1.0), vec3(3.0, 1.0, 1.0));
        assert!(sphere_aabb(&a, &bx));
        let bx2 = Aabb::new(vec3(3.0, -1.0, -1.0), vec3(4.0, 1.0, 1.0));
        assert!(aabb_aabb(&bx, &bx2));
        assert!(!sphere_aabb(&a, &bx2));
    }

    #[test]
    fn ray_sphere_cases() {
        let s = Sphere::new(vec3(5.0, 0.0, 0.0), 1.0);
        let r = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(ray_sphere(&r, &s), Some(4.0));
        let r2 = Ray::new(Vec3::ZERO, -Vec3::X);
        assert_eq!(ray_sphere(&r2, &s), None);
        let short = Ray::with_max_t(Vec3::ZERO, Vec3::X, 3.9);
        assert_eq!(ray_sphere(&short, &s), None);
        let exact = Ray::with_max_t(Vec3::ZERO, Vec3::X, 4.0);
        assert_eq!(ray_sphere(&exact, &s), Some(4.0));
        let inside = Ray::new(vec3(5.5, 0.0, 0.0), Vec3::Y);
        assert_eq!(ray_sphere(&inside, &s), Some(0.0));
        // Tangent ray touches.
        let tangent = Ray::new(vec3(0.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray_sphere(&tangent, &s), Some(5.0));
        // Unnormalized direction: t is in units of dir.
        let scaled = Ray::new(Vec3::ZERO, vec3(2.0, 0.0, 0.0));
        assert_eq!(ray_sphere(&scaled, &s), Some(2.0));
    }

    #[test]
    fn ray_aabb_cases() {
        let b = Aabb::new(vec3(1.0, -1.0, -1.0), vec3(2.0, 1.0, 1.0));
        assert_eq!(
            ray_aabb(&Ray::new(Vec3::ZERO, Vec3::X), &b),
            Some((1.0, 2.0))
        );
        // Axis-parallel ray on the box face: touching counts, no NaN.
        let on_face = Ray::new(vec3(0.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&on_face, &b), Some((1.0, 2.0)));
        let above = Ray::new(vec3(0.0, 1.5, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&above, &b), None);
        let behind = Ray::new(vec3(3.0, 0.0, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&behind, &b), None);
        let short = Ray::with_max_t(Vec3::ZERO, Vec3::X, 0.5);
        assert_eq!(ray_aabb(&short, &b), None);
    }

    #[test]
    fn frustum_from_perspective() {
        let proj = Mat4::perspective_rh(1.0, 1.0, 1.0, 100.0);
        let view = Mat4::look_at_rh(Vec3::ZERO, -Vec3::Z, Vec3::Y);
        let f = Frustum::from_view_projection(proj * view).unwrap();
        let inside = Sphere::new(vec3(0.0, 0.0, -10.0), 1.0);
        assert_eq!(f.classify_sphere(&inside), Relation::Inside);
        let behind = Sphere::new(vec3(0.0, 0.0, 10.0), 1.0);
        assert_eq!(f.classify_sphere(&behind), Relation::Outside);
        let across_near = Sphere::new(vec3(0.0, 0.0, -1.0), 0.5);
        assert_eq!(f.classify_sphere(&across_near), Relation::Intersecting);
        let far = Sphere::new(vec3(0.0, 0.0, -102.0), 1.0);
        assert_eq!(f.classify_sphere(&far), Relation::Outside);
        let b = Aabb::new(vec3(-1.0, -1.0, -11.0), vec3(1.0, 1.0, -9.0));
        assert_eq!(f.classify_aabb(&b, Frustum::ALL_PLANES).0, Relation::Inside);
        let b2 = Aabb::new(vec3(-0.1, -0.1, -5.0), vec3(0.1, 0.1, 5.0));
        let (rel, mask) = f.classify_aabb(&b2, Frustum::ALL_PLANES);
        assert_eq!(rel, Relation::Intersecting);
        assert_ne!(mask & (1 << 4), 0, "near plane still cuts");
        assert!(Frustum::from_view_projection(Mat4::NAN).is_err());
    }
}
