//! The peer: parry3d 0.31's dynamic BVH (`parry3d::partitioning::Bvh`), driven the
//! way its own docs and rapier's `BroadPhaseBvh` drive it for a moving scene.
//!
//! - build: `Bvh::from_leaves(BvhBuildStrategy::Binned, aabbs)` (parry's bulk SAH
//!   build; leaf `i` = sphere `i`);
//! - update, per frame: `insert_or_update_partially(aabb, i, 0.0)` for every leaf,
//!   then (optionally) `optimize_incremental`, then one `refit` — the order rapier
//!   uses (refit after optimization re-lays the nodes out depth-first);
//! - pairs: `traverse_bvtt_single_tree::<false>` (the tree against itself, every
//!   leaf pair whose AABBs overlap), each candidate filtered by the exact closed
//!   sphere–sphere test of `proxima::geom::overlap`, so the count is comparable.
//!
//! Change detection (a fattened leaf margin plus `CHANGE_DETECTION = true`) is what
//! rapier uses to report only *new* pairs; the workloads ask for *all* pairs every
//! frame, so it is off: margin `0.0`, every leaf rewritten, full traversal.

use crate::structure::Structure;
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::Vector;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhNodeWide, BvhWorkspace};
use proxima::geom::{overlap, Sphere};

/// parry3d's BVH over the spheres' AABBs, plus the spheres for the exact test.
pub struct ParryBvh {
    bvh: Bvh,
    workspace: BvhWorkspace,
    spheres: Vec<Sphere>,
    optimize: bool,
}

fn aabb(s: &Sphere) -> PAabb {
    let (c, r) = (s.center, s.radius);
    PAabb::new(
        Vector::new(c.x - r, c.y - r, c.z - r),
        Vector::new(c.x + r, c.y + r, c.z + r),
    )
}

impl ParryBvh {
    /// An empty BVH. With `optimize`, every frame also runs
    /// `optimize_incremental` (rapier's default `SubtreeOptimizer` strategy).
    pub fn new(optimize: bool) -> Self {
        ParryBvh {
            bvh: Bvh::new(),
            workspace: BvhWorkspace::default(),
            spheres: Vec::new(),
            optimize,
        }
    }
}

impl Structure for ParryBvh {
    fn build(&mut self, spheres: &[Sphere]) {
        self.spheres = spheres.to_vec();
        let aabbs: Vec<PAabb> = spheres.iter().map(aabb).collect();
        self.bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
    }

    fn update(&mut self, spheres: &[Sphere]) {
        for (i, (dst, s)) in self.spheres.iter_mut().zip(spheres).enumerate() {
            *dst = *s;
            self.bvh.insert_or_update_partially(aabb(s), i as u32, 0.0);
        }
        if self.optimize {
            self.bvh.optimize_incremental(&mut self.workspace);
        }
        self.bvh.refit(&mut self.workspace);
    }

    fn count_pairs(&mut self) -> u64 {
        let spheres = &self.spheres;
        let mut n = 0u64;
        self.bvh
            .traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                if overlap::sphere_sphere(&spheres[a as usize], &spheres[b as usize]) {
                    n += 1;
                }
            });
        n
    }

    /// parry's own `total_memory_size()` (nodes, parents, leaf map, free list: by
    /// capacity), plus the workspace's refit buffer, which parry does not expose but
    /// which after a `refit` holds the previous node array (estimated as one
    /// `BvhNodeWide` per leaf: a binary tree of `L` leaves has `L - 1` two-child
    /// nodes), plus the sphere copy the exact test reads (16 B/object, as Proxima's
    /// indices store their spheres too).
    fn memory_bytes(&self) -> usize {
        let refit_buffer = self.bvh.leaf_count() as usize * std::mem::size_of::<BvhNodeWide>();
        std::mem::size_of::<Self>()
            + self.bvh.total_memory_size()
            + refit_buffer
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
    }
}
