//! Peer: the `bvh` crate (0.13), its SAH BVH built over the spheres' AABBs. Every
//! kind runs through `Bvh::traverse_iterator` with an `IntersectsAabb` query: rays
//! with the crate's own `bvh::ray::Ray` (its slab test; the crate's rays are
//! unbounded, so `max_t` is left to the exact filter), spheres, boxes and frusta
//! with `Selection::classify_box`. Candidates are filtered by the exact test.

use super::engine::Engine;
use super::queries::{Batches, QueryKind};
use bvh::aabb::{Aabb as BAabb, Bounded, IntersectsAabb};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::Bvh;
use nalgebra::{Point3, Vector3};
use proxima::broad::Selection;
use proxima::geom::{Aabb, Frustum, Relation, Sphere};
use proxima::glam::Vec3;

/// A stored sphere as a `bvh` shape.
pub struct Shape {
    sphere: Sphere,
    node: usize,
}

impl Bounded<f32, 3> for Shape {
    fn aabb(&self) -> BAabb<f32, 3> {
        let b = self.sphere.aabb();
        BAabb::with_bounds(
            Point3::new(b.min.x, b.min.y, b.min.z),
            Point3::new(b.max.x, b.max.y, b.max.z),
        )
    }
}

impl BHShape<f32, 3> for Shape {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// Any [`Selection`] as a `bvh` node test.
struct Select<'a, Q: ?Sized>(&'a Q);

impl<Q: Selection + ?Sized> IntersectsAabb<f32, 3> for Select<'_, Q> {
    fn intersects_aabb(&self, b: &BAabb<f32, 3>) -> bool {
        let b = Aabb::new(
            Vec3::new(b.min.x, b.min.y, b.min.z),
            Vec3::new(b.max.x, b.max.y, b.max.z),
        );
        self.0.classify_box(&b, Frustum::ALL_PLANES).0 != Relation::Outside
    }
}

/// The `bvh` crate's tree and its shapes.
pub struct BvhQuery {
    bvh: Bvh<f32, 3>,
    shapes: Vec<Shape>,
}

impl BvhQuery {
    /// SAH build over the spheres' AABBs.
    pub fn build(spheres: &[Sphere]) -> Self {
        let mut shapes: Vec<Shape> = spheres
            .iter()
            .map(|s| Shape {
                sphere: *s,
                node: 0,
            })
            .collect();
        let bvh = Bvh::build(&mut shapes);
        BvhQuery { bvh, shapes }
    }

    fn count_with<Q: Selection, N: IntersectsAabb<f32, 3>>(&self, q: &Q, node_test: &N) -> usize {
        self.bvh
            .traverse_iterator(node_test, &self.shapes)
            .filter(|s| q.selects(&s.sphere))
            .count()
    }
}

impl Engine for BvhQuery {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        Some(match kind {
            QueryKind::Sphere => self.count_with(&b.spheres[i], &Select(&b.spheres[i])),
            QueryKind::Aabb => self.count_with(&b.boxes[i], &Select(&b.boxes[i])),
            QueryKind::Ray => {
                let r = &b.rays[i];
                let native = bvh::ray::Ray::new(
                    Point3::new(r.origin.x, r.origin.y, r.origin.z),
                    Vector3::new(r.dir.x, r.dir.y, r.dir.z),
                );
                self.count_with(r, &native)
            }
            QueryKind::Frustum => self.count_with(&b.frusta[i], &Select(&b.frusta[i])),
        })
    }

    fn supports(&self, _: QueryKind) -> bool {
        true
    }

    /// The node array and the shapes (each holding its sphere and node index).
    fn memory_bytes(&self) -> usize {
        self.bvh.nodes.capacity() * std::mem::size_of_val(&self.bvh.nodes[0])
            + self.shapes.capacity() * std::mem::size_of::<Shape>()
    }
}
