//! [`Sphere`]: the closed ball every broad-phase index stores.

use crate::error::{check_radius, check_vec3};
use crate::geom::Aabb;
use crate::Result;
use glam::Vec3;

/// A ball: every point within `radius` of `center` (boundary included).
///
/// This is what every broad-phase index stores. A zero radius is a point.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius, `>= 0`.
    pub radius: f32,
}

impl Sphere {
    /// A sphere; not validated (see [`Sphere::validate`]).
    pub const fn new(center: Vec3, radius: f32) -> Self {
        Sphere { center, radius }
    }

    /// Checks that the centre and radius are finite and the radius is not negative.
    pub fn validate(&self) -> Result<()> {
        check_vec3(self.center, "sphere centre")?;
        check_radius(self.radius, "sphere radius")
    }

    /// The smallest AABB containing the sphere.
    #[inline]
    pub fn aabb(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        Aabb::new(self.center - r, self.center + r)
    }

    /// Closed sphere–sphere overlap; see [`overlap::sphere_sphere`](crate::geom::overlap::sphere_sphere).
    #[inline]
    pub fn intersects_sphere(&self, other: &Sphere) -> bool {
        crate::geom::overlap::sphere_sphere(self, other)
    }

    /// Closed sphere–box overlap; see [`overlap::sphere_aabb`](crate::geom::overlap::sphere_aabb).
    #[inline]
    pub fn intersects_aabb(&self, aabb: &Aabb) -> bool {
        crate::geom::overlap::sphere_aabb(self, aabb)
    }
}
