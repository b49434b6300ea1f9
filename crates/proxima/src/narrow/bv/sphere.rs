//! The sphere as a BVH bounding volume.

use super::{positive, BoundingVolume};
use crate::geom::{Ray, Sphere};
use glam::{Affine3A, Vec3, Vec3A};

/// Bounding spheres: the cheapest test (one distance) and free under rotation, but
/// the loosest fit [sources: bv-kinds]. Fitted around the centre of the points' AABB.
impl BoundingVolume for Sphere {
    /// The pose and the slack.
    type Motion = (Affine3A, f32);

    const NAME: &'static str = "sphere";
    const AXIS_ALIGNED: bool = false;

    fn from_points(points: &[Vec3]) -> Self {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for &p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let c = (lo + hi) * 0.5;
        let r2 = points
            .iter()
            .map(|&p| p.distance_squared(c))
            .fold(0.0f32, f32::max);
        Sphere::new(c, r2.sqrt())
    }

    /// The smallest sphere containing both spheres.
    fn merge(&self, o: &Self) -> Self {
        let d = o.center - self.center;
        let dist = d.length();
        if dist + o.radius <= self.radius {
            return *self;
        }
        if dist + self.radius <= o.radius {
            return *o;
        }
        let r = (dist + self.radius + o.radius) * 0.5;
        // dist > 0 here, else one sphere would contain the other.
        let c = self.center + d * ((r - self.radius) / dist);
        Sphere::new(c, r)
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

    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32> {
        let grown = Sphere::new(self.center, self.radius + slack);
        crate::geom::overlap::ray_sphere(ray, &grown)
            .map(|t| (t - t.abs() * 4.0 * f32::EPSILON).max(0.0))
    }

    /// Exact up to the slack: the centre distance minus both radii.
    #[inline]
    fn distance_lower_bound(&self, m: &Self::Motion, o: &Self) -> f32 {
        let c = m.0.transform_point3a(Vec3A::from(self.center));
        positive((c - Vec3A::from(o.center)).length() - self.radius - o.radius - m.1)
    }

    #[inline]
    fn distance_lower_bound_fixed(&self, o: &Self) -> f32 {
        positive(self.center.distance(o.center) - self.radius - o.radius)
    }
}
