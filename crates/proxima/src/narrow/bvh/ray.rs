//! Ray and segment casts against a mesh [`Bvh`] of any bounding volume.

use super::stack::Stack;
use super::tree::Bvh;
use crate::geom::{Ray, Segment};
use crate::narrow::bv::{slack_for, BoundingVolume};
use crate::narrow::ray_triangle::{prepare_triangle, RayFilter, TriangleHit, WoopRay};
use crate::narrow::TriMesh;
use crate::Result;
use glam::Vec3A;

impl<BV: BoundingVolume> Bvh<BV> {
    /// The closest hit of `ray` on `mesh` (smallest `t`; ties go to the smaller
    /// triangle index), with the watertight test of
    /// [`ray_triangle`](crate::narrow::ray_triangle), after a conservative `f32`
    /// pre-test that only skips triangles the exact test certainly misses. Descends
    /// the nearer child first and prunes nodes entered beyond the best hit: O(log n)
    /// typical. ([`RayBvh`](crate::narrow::RayBvh) gives the same answers faster.)
    ///
    /// Fails on an invalid ray (non-finite, zero direction, negative or NaN
    /// `max_t`), or with [`Error::MeshMismatch`](crate::Error::MeshMismatch) on a
    /// mesh other than the tree's (see [`Bvh`]).
    pub fn cast_ray(&self, mesh: &TriMesh, ray: &Ray) -> Result<Option<TriangleHit>> {
        self.cast(mesh, ray, false)
    }

    /// Whether `ray` hits `mesh` at all: stops at the first hit found, which need
    /// not be the closest. Fails as [`Bvh::cast_ray`] does.
    pub fn intersects_ray(&self, mesh: &TriMesh, ray: &Ray) -> Result<bool> {
        Ok(self.cast(mesh, ray, true)?.is_some())
    }

    /// [`Bvh::cast_ray`] for the segment from `seg.a` (`t = 0`) to `seg.b` (`t = 1`).
    pub fn cast_segment(&self, mesh: &TriMesh, seg: &Segment) -> Result<Option<TriangleHit>> {
        self.cast(mesh, &seg.to_ray(), false)
    }

    fn cast(&self, mesh: &TriMesh, ray: &Ray, any: bool) -> Result<Option<TriangleHit>> {
        ray.validate()?;
        self.check_mesh(mesh)?;
        Ok(self.cast_valid(mesh, ray, any))
    }

    /// The cast of a validated ray on the tree's own mesh (`any`: stop at the
    /// first hit found).
    pub(crate) fn cast_valid(&self, mesh: &TriMesh, ray: &Ray, any: bool) -> Option<TriangleHit> {
        let scale = 2.0 * (self.coord_bound + ray.origin.abs().element_sum());
        let slack = slack_for(scale, 0.0);
        let verts = mesh.vertices();
        let filter = RayFilter::new(ray);
        // The exact test's per-ray setup, on the first triangle that needs it.
        let mut woop: Option<WoopRay> = None;
        let mut best: Option<TriangleHit> = None;
        let mut limit = ray.max_t;
        let mut stack = Stack::new();
        if let Some(t) = self.nodes[0].bv.ray_entry(ray, slack) {
            stack.push((0, t));
        }
        while let Some((i, entry)) = stack.pop() {
            if entry > limit {
                continue;
            }
            let n = &self.nodes[i as usize];
            if n.is_leaf() {
                for k in n.triangle_range() {
                    let tri = self.tris[k].map(|v| verts[v as usize]);
                    // The conservative f32 pre-test, then the exact test.
                    let (e1, e2, ng, l1) = prepare_triangle(&tri.map(Vec3A::from));
                    if !filter.may_hit(Vec3A::from(tri[0]), e1, e2, ng, l1, limit) {
                        continue;
                    }
                    let w = woop.get_or_insert_with(|| WoopRay::new(ray));
                    if let Some(h) = w.hit(&tri) {
                        let id = self.ids[k];
                        if h.precedes(id, &best) {
                            best = Some(h.on(id));
                            if any {
                                return best;
                            }
                            limit = h.t;
                        }
                    }
                }
                continue;
            }
            let (l, r) = n.children(i);
            let el = self.nodes[l as usize].bv.ray_entry(ray, slack);
            let er = self.nodes[r as usize].bv.ray_entry(ray, slack);
            // Push the farther child first so the nearer one is popped next.
            match (el, er) {
                (Some(a), Some(b)) => {
                    if a <= b {
                        stack.push((r, b));
                        stack.push((l, a));
                    } else {
                        stack.push((l, a));
                        stack.push((r, b));
                    }
                }
                (Some(a), None) => stack.push((l, a)),
                (None, Some(b)) => stack.push((r, b)),
                (None, None) => {}
            }
        }
        best
    }
}
