//! Peer: parry3d 0.31's BVH (`parry3d::partitioning::Bvh`), built once from the
//! spheres' AABBs with its binned SAH build or its PLOC build (one W4 row each). Sphere and box queries use
//! `Bvh::intersect_aabb` with the query's bounding box (parry's SIMD node test);
//! rays and frusta use `Bvh::leaves` with the same conservative box test Proxima's
//! indices use (`Selection::classify_box`). Every candidate leaf then goes through
//! the exact closed test.

use super::engine::Engine;
use super::queries::{Batches, QueryKind};
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::Vector;
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use proxima::broad::Selection;
use proxima::geom::{Aabb, Frustum, Relation, Sphere};
use proxima::glam::Vec3;

/// parry3d's BVH over the spheres' AABBs, plus the spheres for the exact test.
pub struct ParryQuery {
    bvh: Bvh,
    spheres: Vec<Sphere>,
}

fn to_parry(b: &Aabb) -> PAabb {
    PAabb::new(
        Vector::new(b.min.x, b.min.y, b.min.z),
        Vector::new(b.max.x, b.max.y, b.max.z),
    )
}

fn from_parry(b: &PAabb) -> Aabb {
    Aabb::new(
        Vec3::new(b.mins.x, b.mins.y, b.mins.z),
        Vec3::new(b.maxs.x, b.maxs.y, b.maxs.z),
    )
}

impl ParryQuery {
    /// Bulk build with one of parry's strategies (`Binned`: binned SAH, its
    /// default; `Ploc`: locally-ordered clustering, slower to build, documented
    /// as the better tree); leaf `i` = sphere `i`.
    pub fn build(spheres: &[Sphere], strategy: BvhBuildStrategy) -> Self {
        let aabbs: Vec<PAabb> = spheres.iter().map(|s| to_parry(&s.aabb())).collect();
        ParryQuery {
            bvh: Bvh::from_leaves(strategy, &aabbs),
            spheres: spheres.to_vec(),
        }
    }

    /// Candidates of the query's bounding box, filtered exactly.
    fn by_bounds<Q: Selection>(&self, q: &Q) -> usize {
        let b = to_parry(&q.bounds().expect("bounded query"));
        self.bvh
            .intersect_aabb(&b)
            .filter(|&i| q.selects(&self.spheres[i as usize]))
            .count()
    }

    /// Candidates of a traversal pruned by `classify_box`, filtered exactly.
    fn by_classify<Q: Selection>(&self, q: &Q) -> usize {
        self.bvh
            .leaves(|node| {
                q.classify_box(&from_parry(&node.aabb()), Frustum::ALL_PLANES)
                    .0
                    != Relation::Outside
            })
            .filter(|&i| q.selects(&self.spheres[i as usize]))
            .count()
    }
}

impl Engine for ParryQuery {
    fn count(&self, b: &Batches, kind: QueryKind, i: usize) -> Option<usize> {
        Some(match kind {
            QueryKind::Sphere => self.by_bounds(&b.spheres[i]),
            QueryKind::Aabb => self.by_bounds(&b.boxes[i]),
            QueryKind::Ray => self.by_classify(&b.rays[i]),
            QueryKind::Frustum => self.by_classify(&b.frusta[i]),
        })
    }

    fn supports(&self, _: QueryKind) -> bool {
        true
    }

    /// parry's `total_memory_size()` plus the sphere copy.
    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.bvh.total_memory_size()
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
    }
}
