//! Region queries on the world: objects near a point ([`World::overlap_sphere`],
//! the source's radius query refined exactly [sources: near-objects]) and
//! objects in a view frustum ([`World::cull`], [sources: octree-cull]).

use super::{grown_radius, Shape, World};
use crate::broad::{Filter, Query};
use crate::geom::{overlap, Frustum, Sphere};
use crate::narrow::BoundingVolume;
use crate::{Error, Handle, Result};
use glam::Vec3;

impl<T, BV: BoundingVolume> World<T, BV> {
    /// The objects (filtered as in [`World::ray_cast`]) with some point within
    /// `radius` of `center` (closed): a mesh with a triangle that close
    /// ([`sphere_triangle`](crate::narrow::sphere_triangle), in the mesh's
    /// frame), a ball that overlaps the query ball. Sorted by handle.
    ///
    /// Cost: the broad phase's sphere query, then for each candidate mesh a walk
    /// of its collision tree with the ball's box ([`crate::narrow::Mesh::
    /// intersects_sphere`]) that stops at the first triangle within reach.
    /// Fails on a non-finite centre or a negative or non-finite radius.
    pub fn overlap_sphere(&self, center: Vec3, radius: f32, filter: Filter) -> Result<Vec<Handle>> {
        let ball = Sphere::new(center, radius);
        ball.validate()?;
        // Candidates with the radius grown as the objects' spheres are: the
        // exact test runs in each mesh's frame, whose pose may scale distances
        // by up to its allowed deviation from a rotation.
        let reach = Sphere::new(
            center,
            grown_radius(radius, center.abs().max_element() + radius),
        );
        let mut slots = Vec::new();
        self.broad
            .visit(&self.objects, &Query::Sphere(reach), |s| slots.push(s))?;
        slots.sort_unstable();
        let (mut stack, mut hits) = (Vec::new(), Vec::new());
        let mut out = Vec::new();
        for slot in slots {
            let (h, o) = self.objects.get_by_index(slot).expect("a live slot");
            if !filter.interacts(o.filter) {
                continue;
            }
            let near = match &o.shape {
                Shape::Mesh(m) => {
                    let c = o.inverse.transform_point3(center);
                    if !c.is_finite() {
                        return Err(Error::NonFinite {
                            what: "query centre in an object's frame",
                        });
                    }
                    hits.clear();
                    m.visit_sphere(&Sphere::new(c, radius), true, &mut stack, &mut hits);
                    !hits.is_empty()
                }
                Shape::Sphere(r) => {
                    overlap::sphere_sphere(&ball, &Sphere::new(o.pose.translation.into(), *r))
                }
            };
            if near {
                out.push(h);
            }
        }
        Ok(out)
    }

    /// The objects (filtered as in [`World::ray_cast`]) whose bounding sphere
    /// (the broad phase's, see [`ObjectRef::bounding_sphere`](super::ObjectRef))
    /// is not entirely outside any plane of `frustum`: what a renderer must
    /// draw, conservatively. Sorted by handle. Cost: the broad phase's frustum
    /// query. Fails on a non-finite frustum.
    pub fn cull(&self, frustum: &Frustum, filter: Filter) -> Result<Vec<Handle>> {
        let mut out = Vec::new();
        self.broad
            .visit(&self.objects, &Query::Frustum(*frustum), |slot| {
                let (h, o) = self.objects.get_by_index(slot).expect("a live slot");
                if filter.interacts(o.filter) {
                    out.push(h);
                }
            })?;
        out.sort_unstable();
        Ok(out)
    }
}
