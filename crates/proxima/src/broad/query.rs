//! [`Query`]: the query shapes every index answers, as one `Copy` value, so that
//! the object-safe [`SpatialIndex::visit`](super::SpatialIndex::visit) takes any
//! of them and each index still runs a walk compiled for the shape.

use crate::geom::{Aabb, Frustum, Ray, Sphere, SphereSweep};
use crate::Result;

/// A region to find stored spheres in. Overlap is closed everywhere: touching
/// counts.
///
/// Build one with `From` (`index.visit(&sphere.into(), ..)`,
/// `index.query(aabb)`); a [`Segment`](crate::geom::Segment) is queried as the
/// ray [`Segment::to_ray`](crate::geom::Segment::to_ray) (parameters `t` in
/// `[0, 1]`). New shapes may be added, so matches need a wildcard arm.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Query {
    /// Spheres overlapping this sphere (also the point-radius query: spheres
    /// within `radius` of `center`).
    Sphere(Sphere),
    /// Spheres overlapping this box.
    Aabb(Aabb),
    /// Spheres the ray touches for some `t` in `[0, max_t]`.
    Ray(Ray),
    /// Spheres not entirely outside any plane of the frustum (culling).
    Frustum(Frustum),
    /// Spheres the moving sphere touches on its way (continuous collision):
    /// distance from the centre to the segment `<= r + R`, decided exactly by
    /// [`overlap::sweep_sphere`](crate::geom::overlap::sweep_sphere). The
    /// first one and the times of impact:
    /// [`SpatialIndex::sweep_first`](super::SpatialIndex::sweep_first),
    /// [`SpatialIndexExt::sweep_hits`](super::SpatialIndexExt::sweep_hits).
    Sweep(SphereSweep),
}

impl Query {
    /// Checks the query's own numbers (finite, non-negative radius, non-zero ray
    /// direction, ...), as every validated query does before it walks. O(1).
    pub fn validate(&self) -> Result<()> {
        match self {
            Query::Sphere(s) => s.validate(),
            Query::Aabb(b) => b.validate(),
            Query::Ray(r) => r.validate(),
            Query::Frustum(f) => f.validate(),
            Query::Sweep(s) => s.validate(),
        }
    }
}

impl From<Sphere> for Query {
    fn from(s: Sphere) -> Self {
        Query::Sphere(s)
    }
}

impl From<Aabb> for Query {
    fn from(b: Aabb) -> Self {
        Query::Aabb(b)
    }
}

impl From<Ray> for Query {
    fn from(r: Ray) -> Self {
        Query::Ray(r)
    }
}

impl From<Frustum> for Query {
    fn from(f: Frustum) -> Self {
        Query::Frustum(f)
    }
}

impl From<SphereSweep> for Query {
    fn from(s: SphereSweep) -> Self {
        Query::Sweep(s)
    }
}
