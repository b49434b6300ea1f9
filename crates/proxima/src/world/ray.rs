//! Ray casts into the world ([`World::ray_cast`], [`World::ray_hits`]): the
//! broad phase's ray walk over the bounding spheres, then each mesh's ray tree
//! in the object's own frame [sources: world, mesh-rays].

use super::{Object, Shape, World};
use crate::broad::{Filter, Query};
use crate::geom::{overlap, Ray, Sphere};
use crate::narrow::BoundingVolume;
use crate::{Handle, Result};

/// Where a ray meets an object: the object, the primitive (triangle index of a
/// mesh, `0` for a ball) and the ray parameter `t` (units of the world ray's
/// direction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldRayHit {
    /// The object hit.
    pub object: Handle,
    /// The triangle hit (`0` for a ball).
    pub triangle: u32,
    /// Ray parameter of the hit, in `[0, ray.max_t]`.
    pub t: f32,
}

impl WorldRayHit {
    /// The world's order of hits: smaller `t`, then smaller handle, then smaller
    /// triangle.
    #[inline]
    fn key(&self) -> (f32, Handle, u32) {
        (self.t, self.object, self.triangle)
    }
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// The first primitive `ray` hits among the objects whose filter interacts
    /// with `filter` ([`Filter::ALL`]: every object that has a bit in each
    /// field): smallest `t` in `[0, ray.max_t]`, ties to the smaller handle,
    /// then the smaller triangle index. A mesh is hit on its triangles (edges
    /// included, [`ray_triangle`](crate::narrow::ray_triangle)); a ball is solid
    /// (`t = 0` from inside).
    ///
    /// Cost: the broad phase's ray query, then the objects whose spheres the
    /// ray enters, nearest entry first, each cast in its own frame (the inverse
    /// pose maps the ray to the mesh's frame with the same `t`) through the
    /// mesh's ray tree, `O(log n)` typical; the search stops at the first
    /// sphere entered beyond the best hit. Fails on an invalid ray.
    pub fn ray_cast(&self, ray: &Ray, filter: Filter) -> Result<Option<WorldRayHit>> {
        let mut best: Option<WorldRayHit> = None;
        for (entry, slot) in self.ray_candidates(ray, filter)? {
            if best.is_some_and(|b| entry > b.t) {
                break;
            }
            let (h, o) = self.objects.get_by_index(slot).expect("a live slot");
            if let Some(hit) = object_hit(h, o, ray)? {
                if best.is_none_or(|b| hit.key() < b.key()) {
                    best = Some(hit);
                }
            }
        }
        Ok(best)
    }

    /// Every object `ray` hits (filtered as in [`World::ray_cast`]), each with
    /// its first hit, sorted by `t`, then handle. Cost: one cast per object
    /// whose sphere the ray enters. Fails on an invalid ray.
    pub fn ray_hits(&self, ray: &Ray, filter: Filter) -> Result<Vec<WorldRayHit>> {
        let mut hits = Vec::new();
        for (_, slot) in self.ray_candidates(ray, filter)? {
            let (h, o) = self.objects.get_by_index(slot).expect("a live slot");
            hits.extend(object_hit(h, o, ray)?);
        }
        hits.sort_by(|a, b| a.key().partial_cmp(&b.key()).expect("finite t"));
        Ok(hits)
    }

    /// The objects whose broad sphere the ray enters, with the entry `t`,
    /// sorted by `(t, slot)`.
    fn ray_candidates(&self, ray: &Ray, filter: Filter) -> Result<Vec<(f32, u32)>> {
        ray.validate()?;
        let mut out = Vec::new();
        self.broad.visit(&self.objects, &Query::Ray(*ray), |slot| {
            let (_, o) = self.objects.get_by_index(slot).expect("a live slot");
            if filter.interacts(o.filter) {
                // The broad phase selected it with this same closed test.
                let t = overlap::ray_sphere(ray, &o.sphere).unwrap_or(0.0);
                out.push((t, slot));
            }
        })?;
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Ok(out)
    }
}

/// The first hit of `ray` (world frame) on one object.
fn object_hit<T, BV: BoundingVolume>(
    h: Handle,
    o: &Object<T, BV>,
    ray: &Ray,
) -> Result<Option<WorldRayHit>> {
    Ok(match &o.shape {
        Shape::Mesh(m) => {
            // An affine map keeps the parameter: inv(origin + t·dir) =
            // inv(origin) + t·inv_linear(dir).
            let local = Ray::with_max_t(
                o.inverse.transform_point3(ray.origin),
                o.inverse.transform_vector3(ray.dir),
                ray.max_t,
            );
            m.cast_ray(&local)?.map(|hit| WorldRayHit {
                object: h,
                triangle: hit.triangle,
                t: hit.t,
            })
        }
        Shape::Sphere(r) => {
            let ball = Sphere::new(o.pose.translation.into(), *r);
            overlap::ray_sphere(ray, &ball).map(|t| WorldRayHit {
                object: h,
                triangle: 0,
                t,
            })
        }
    })
}
