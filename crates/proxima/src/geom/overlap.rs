//! The closed overlap tests, one function per shape pair. Every index and every
//! method on the shape types calls these; nothing re-implements them.
//!
//! Closed means boundaries count: touching shapes overlap. Costs are O(1).

use crate::geom::{Aabb, Frustum, Ray, Relation, Sphere};
use glam::Vec3;

/// Sphere–sphere: `|c1 - c2|² <= (r1 + r2)²`.
#[inline]
pub fn sphere_sphere(a: &Sphere, b: &Sphere) -> bool {
    let rs = a.radius + b.radius;
    (a.center - b.center).length_squared() <= rs * rs
}

/// Sphere–AABB: the squared distance from the centre to the box is at most `r²`.
#[inline]
pub fn sphere_aabb(s: &Sphere, b: &Aabb) -> bool {
    b.distance_squared_to_point(s.center) <= s.radius * s.radius
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
/// from the projected point, not from `b² - ac`) to avoid cancellation for long rays.
#[inline]
pub fn ray_sphere(ray: &Ray, s: &Sphere) -> Option<f32> {
    let m = ray.origin - s.center;
    let r2 = s.radius * s.radius;
    let c = m.length_squared() - r2;
    if c <= 0.0 {
        return Some(0.0);
    }
    let b = m.dot(ray.dir);
    if b >= 0.0 {
        // Outside and not approaching: the distance only grows with t.
        return None;
    }
    let a = ray.dir.length_squared();
    let tc = -b / a;
    let closest = m + ray.dir * tc;
    let h2 = r2 - closest.length_squared();
    if h2 < 0.0 {
        return None;
    }
    let t = (tc - (h2 / a).sqrt()).max(0.0);
    (t <= ray.max_t).then_some(t)
}

/// Ray (or segment) against a box: the parameter interval `[t_enter, t_exit]` of the
/// ray inside the closed box, clipped to `[0, ray.max_t]`, or `None`.
///
/// A zero direction component is handled explicitly (the ray is inside that slab for
/// all `t` or for none), so no `0 * ∞` NaN arises.
#[inline]
pub fn ray_aabb(ray: &Ray, b: &Aabb) -> Option<(f32, f32)> {
    let mut t0 = 0.0f32;
    let mut t1 = ray.max_t;
    for axis in 0..3 {
        let o = ray.origin[axis];
        let d = ray.dir[axis];
        let (lo, hi) = (b.min[axis], b.max[axis]);
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
        // `max`/`min` ignore a NaN operand (∞ · 0 for an infinite box), which keeps
        // the test conservative.
        t0 = t0.max(ta);
        t1 = t1.min(tb);
        if t0 > t1 {
            return None;
        }
    }
    Some((t0, t1))
}

/// Frustum–sphere, per plane: `Outside` if the sphere is entirely on the outer side of
/// some plane (`distance < -r`), `Inside` if it is at least `r` inside every plane,
/// else `Intersecting`. A sphere exactly touching a plane from outside is not culled.
#[inline]
pub fn frustum_sphere(f: &Frustum, s: &Sphere) -> Relation {
    let mut rel = Relation::Inside;
    for p in &f.planes {
        let d = p.signed_distance(s.center);
        if d < -s.radius {
            return Relation::Outside;
        }
        if d < s.radius {
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
#[inline]
pub fn frustum_aabb(f: &Frustum, b: &Aabb, mask: u8) -> (Relation, u8) {
    let c = b.center();
    let h = b.half_extent();
    let mut out_mask = 0u8;
    for (i, p) in f.planes.iter().enumerate() {
        let bit = 1u8 << i;
        if mask & bit == 0 {
            continue;
        }
        let s = p.signed_distance(c);
        let e = p.normal.abs().dot(h);
        if s + e < 0.0 {
            return (Relation::Outside, 0);
        }
        if s - e < 0.0 {
            out_mask |= bit;
        }
    }
    if out_mask == 0 {
        (Relation::Inside, 0)
    } else {
        (Relation::Intersecting, out_mask)
    }
}

/// Squared distance between two points (helper for callers that need it).
#[inline]
pub fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    (a - b).length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Mat4};

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
