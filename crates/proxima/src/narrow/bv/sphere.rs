//! The sphere as a BVH bounding volume.

use super::{f32_below, positive, BoundingVolume};
use crate::geom::{Ray, Sphere};
use glam::{Affine3A, Vec3, Vec3A};

/// `r` widened by `1e-12` of itself (far beyond the few `f64` roundings of the
/// distances it comes from) and rounded up to `f32`: a radius that contains
/// exactly what `r` contains up to that rounding. Infinite beyond `f32::MAX`.
fn radius_up(r: f64) -> f32 {
    let r = r * (1.0 + 1e-12);
    let radius = r as f32;
    if (radius as f64) < r {
        f32::from_bits(radius.to_bits() + 1)
    } else {
        radius
    }
}

/// The radius of a ball around `c` containing every point of `points`, from
/// `f64` distances ([`radius_up`]): the containment is exact, not up to
/// rounding. Infinite only when the distance exceeds `f32::MAX` (points near
/// opposite ends of the `f32` range). O(points).
pub(crate) fn enclosing_radius(c: Vec3, points: impl IntoIterator<Item = Vec3>) -> f32 {
    let c = c.as_dvec3();
    let r2 = points
        .into_iter()
        .map(|p| (p.as_dvec3() - c).length_squared())
        .fold(0.0f64, f64::max);
    radius_up(r2.sqrt())
}

/// The distance `d` between the centres `a` and `b` as computed in `f32` (whose
/// rounding the callers' slack covers), or, where the squares overflowed
/// (beyond `√f32::MAX ≈ 1.8e19`), in `f64` ([`f32_below`]): for lower bounds.
#[inline]
fn center_distance(d: f32, a: Vec3, b: Vec3) -> f32 {
    if d <= f32::MAX {
        d
    } else {
        f32_below(a.as_dvec3().distance(b.as_dvec3()))
    }
}

/// Bounding spheres: the cheapest test (one distance) and free under rotation, but
/// the loosest fit [sources: bv-kinds]. Fitted around the centre of the points' AABB.
impl BoundingVolume for Sphere {
    /// The pose and the slack.
    type Motion = (Affine3A, f32);

    const NAME: &'static str = "sphere";
    const AXIS_ALIGNED: bool = false;

    /// The radius in `f32` (its rounding is covered by the queries' slack);
    /// where that overflows (coordinates beyond `√f32::MAX ≈ 1.8e19`), from
    /// `enclosing_radius`, finite up to `f32::MAX`.
    fn from_points(points: &[Vec3]) -> Self {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for &p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let mut c = (lo + hi) * 0.5;
        if !c.is_finite() {
            // lo + hi overflowed; halving first is exact for these magnitudes.
            c = lo * 0.5 + hi * 0.5;
        }
        let r2 = points
            .iter()
            .map(|&p| p.distance_squared(c))
            .fold(0.0f32, f32::max);
        if r2.is_finite() {
            Sphere::new(c, r2.sqrt())
        } else {
            Sphere::new(c, enclosing_radius(c, points.iter().copied()))
        }
    }

    /// The smallest sphere containing both spheres, in `f32`; where that
    /// overflows (distances beyond `√f32::MAX`), in `f64` with the radius
    /// rounded up (`enclosing_radius`'s containment).
    fn merge(&self, o: &Self) -> Self {
        let d = o.center - self.center;
        let dist = d.length();
        if dist.is_finite() {
            if dist + o.radius <= self.radius {
                return *self;
            }
            if dist + self.radius <= o.radius {
                return *o;
            }
            let r = (dist + self.radius + o.radius) * 0.5;
            // dist > 0 here, else one sphere would contain the other.
            let c = self.center + d * ((r - self.radius) / dist);
            if r.is_finite() && c.is_finite() {
                return Sphere::new(c, r);
            }
        }
        let (c1, c2) = (self.center.as_dvec3(), o.center.as_dvec3());
        let (r1, r2) = (self.radius as f64, o.radius as f64);
        let dist = c1.distance(c2);
        if dist + r2 <= r1 {
            return *self;
        }
        if dist + r1 <= r2 {
            return *o;
        }
        let r = (dist + r1 + r2) * 0.5;
        let c = (c1 + (c2 - c1) * ((r - r1) / dist)).as_vec3();
        // The centre rounded to f32: a radius from it that contains both.
        let cd = c.as_dvec3();
        Sphere::new(
            c,
            radius_up((cd.distance(c1) + r1).max(cd.distance(c2) + r2)),
        )
    }

    fn transformed(&self, pose: &Affine3A) -> Self {
        Sphere::new(pose.transform_point3(self.center), self.radius)
    }

    fn motion(pose: &Affine3A, slack: f32) -> Self::Motion {
        (*pose, slack)
    }

    #[inline]
    fn overlaps(&self, m: &Self::Motion, o: &Self) -> bool {
        let c = m.0.transform_point3a(Vec3A::from(self.center));
        let rs = self.radius + o.radius + m.1;
        (c - Vec3A::from(o.center)).length_squared() <= rs * rs
    }

    fn inflated(&self, slack: f32) -> Self {
        Sphere::new(self.center, self.radius + slack)
    }

    #[inline]
    fn size(&self) -> f32 {
        self.radius
    }

    /// An infinite radius (a sphere fitted to points farther apart than
    /// `f32::MAX`) contains every point: entered at `0`.
    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32> {
        let grown = Sphere::new(self.center, self.radius + slack);
        if grown.radius == f32::INFINITY {
            return Some(0.0);
        }
        crate::geom::overlap::ray_sphere(ray, &grown)
            .map(|t| (t - t.abs() * 4.0 * f32::EPSILON).max(0.0))
    }

    /// Exact up to the slack: the centre distance minus both radii.
    #[inline]
    fn distance_lower_bound(&self, m: &Self::Motion, o: &Self) -> f32 {
        let c = m.0.transform_point3a(Vec3A::from(self.center));
        let d = center_distance((c - Vec3A::from(o.center)).length(), c.into(), o.center);
        positive(d - self.radius - o.radius - m.1)
    }

    #[inline]
    fn distance_lower_bound_fixed(&self, o: &Self) -> f32 {
        let d = center_distance(self.center.distance(o.center), self.center, o.center);
        positive(d - self.radius - o.radius)
    }
}
