//! Query shapes as selection functions (the `rstar` idea): an index traverses its
//! nodes with [`Selection::classify_box`] and tests stored spheres with
//! [`Selection::selects`], so one traversal serves every query shape.

use crate::geom::{overlap, Aabb, Frustum, Ray, Relation, Sphere};
use crate::Result;

/// A query over stored spheres.
///
/// Implementations must be consistent: `classify_box(b)` may say `Outside` only if
/// no sphere lying inside `b` is selected, and `Inside` only if every sphere lying
/// inside `b` is selected. Index nodes bound whole spheres (loose bounds), which is
/// what makes these box answers valid for the spheres below a node.
pub trait Selection {
    /// Checks the query's own numbers (finite, non-negative radius, …).
    fn validate(&self) -> Result<()>;

    /// Exact, closed test: is the stored sphere `s` selected?
    fn selects(&self, s: &Sphere) -> bool;

    /// Conservative box test over the planes in `mask` (only frustums use the mask:
    /// others pass it through). Returns the relation and the mask for the children.
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8);

    /// A box that every selected sphere intersects, if the query has one; indices
    /// use it for one-comparison pruning and for cell ranges. May be infinite.
    fn bounds(&self) -> Option<Aabb>;

    /// The query as a [`Ray`], if it is one. Grids use it to walk the cells along
    /// the ray instead of the ray's (possibly unbounded) bounding box; every other
    /// index may ignore it.
    fn as_ray(&self) -> Option<&Ray> {
        None
    }
}

impl Selection for Sphere {
    fn validate(&self) -> Result<()> {
        Sphere::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::sphere_sphere(self, s)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if overlap::sphere_aabb(self, b) {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        Some(self.aabb())
    }
}

impl Selection for Aabb {
    fn validate(&self) -> Result<()> {
        Aabb::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::sphere_aabb(s, self)
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if !overlap::aabb_aabb(self, b) {
            (Relation::Outside, mask)
        } else if self.contains_aabb(b) {
            // Every sphere inside `b` is inside `self`, so it overlaps it.
            (Relation::Inside, mask)
        } else {
            (Relation::Intersecting, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        Some(*self)
    }
}

impl Selection for Frustum {
    fn validate(&self) -> Result<()> {
        Frustum::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::frustum_sphere(self, s) != Relation::Outside
    }
    /// Conservative for spheres inside `b`: if `b` is wholly outside a plane, so is
    /// every sphere in it (culled); if `b` is inside every plane, so is every sphere.
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        overlap::frustum_aabb(self, b, mask)
    }
    /// None: a selected sphere may lie outside the frustum near a corner, by up to
    /// its radius, so no radius-independent box bounds it.
    fn bounds(&self) -> Option<Aabb> {
        None
    }
}

impl Selection for Ray {
    fn validate(&self) -> Result<()> {
        Ray::validate(self)
    }
    #[inline]
    fn selects(&self, s: &Sphere) -> bool {
        overlap::ray_sphere(self, s).is_some()
    }
    #[inline]
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        if overlap::ray_aabb(self, b).is_some() {
            (Relation::Intersecting, mask)
        } else {
            (Relation::Outside, mask)
        }
    }
    fn bounds(&self) -> Option<Aabb> {
        let end = if self.max_t.is_finite() {
            self.at(self.max_t)
        } else {
            // Infinite ray: unbounded on the axes it moves along.
            let inf = glam::Vec3::splat(f32::INFINITY);
            glam::Vec3::select(
                self.dir.cmpgt(glam::Vec3::ZERO),
                inf,
                glam::Vec3::select(self.dir.cmplt(glam::Vec3::ZERO), -inf, self.origin),
            )
        };
        Some(Aabb::new(self.origin.min(end), self.origin.max(end)))
    }
    fn as_ray(&self) -> Option<&Ray> {
        Some(self)
    }
}
