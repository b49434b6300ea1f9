//! The peer: parry3d 0.31's dynamic BVH (`parry3d::partitioning::Bvh`), driven in
//! each of the ways its own docs offer for a moving scene ([`ParryMode`]); the
//! bench runs every mode as its own row and takes ratios against the fastest.
//!
//! - build: `Bvh::from_leaves(BvhBuildStrategy::Binned, aabbs)` (parry's bulk SAH
//!   build; leaf `i` = sphere `i`);
//! - update, per frame ([`ParryMode`]): `insert_or_update_partially(aabb, i, 0.0)`
//!   for every leaf, then (optionally) `optimize_incremental`, then one `refit` —
//!   the order rapier uses (refit after optimization re-lays the nodes out
//!   depth-first); or a fresh `from_leaves` over the new AABBs;
//! - pairs: `traverse_bvtt_single_tree::<false>` (the tree against itself, every
//!   leaf pair whose AABBs overlap), each candidate filtered by the exact closed
//!   sphere–sphere test of `proxima::geom::overlap`, so the count is comparable;
//! - collision filters (`--inert`): parry's `Bvh` stores no filter bits, so the
//!   pair callback drops the pairs whose filters do not interact, before the
//!   sphere test — the way rapier applies `InteractionGroups` to the broad
//!   phase's pairs (its documented way: parry has no pruning by groups).
//!
//! Change detection (a fattened leaf margin plus `CHANGE_DETECTION = true`) is what
//! rapier uses to report only *new* pairs; the workloads ask for *all* pairs every
//! frame, so it is off: margin `0.0`, every leaf rewritten, full traversal.

use crate::structure::Structure;
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::Vector;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhNodeWide, BvhWorkspace};
use proxima::broad::Filter;
use proxima::geom::{overlap, Sphere};

/// How the BVH is maintained from one frame to the next: the three documented
/// ways of keeping a `Bvh` over moving leaves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParryMode {
    /// `insert_or_update_partially` for every leaf, then `refit`: the cheapest
    /// maintenance; the tree's topology stays the one of the first build.
    Refit,
    /// As [`ParryMode::Refit`] with `optimize_incremental` before the `refit`
    /// (rapier's default `SubtreeOptimizer` strategy): keeps a long-running
    /// tree's quality at a cost per frame.
    OptimizeRefit,
    /// A full binned SAH build (`Bvh::from_leaves`) over the new AABBs every
    /// frame: the best tree, at the price of a build.
    Rebuild,
}

impl ParryMode {
    /// Every mode, in the order the bench runs them.
    pub const ALL: [ParryMode; 3] = [
        ParryMode::Refit,
        ParryMode::OptimizeRefit,
        ParryMode::Rebuild,
    ];

    /// The name shown in the table's mode column and the JSON's `mode` field.
    pub fn name(self) -> &'static str {
        match self {
            ParryMode::Refit => "refit",
            ParryMode::OptimizeRefit => "optimize+refit",
            ParryMode::Rebuild => "rebuild",
        }
    }
}

/// parry3d's BVH over the spheres' AABBs, plus the spheres for the exact test.
pub struct ParryBvh {
    bvh: Bvh,
    workspace: BvhWorkspace,
    spheres: Vec<Sphere>,
    /// The leaves' AABBs, kept for [`ParryMode::Rebuild`] (no allocation per frame).
    aabbs: Vec<PAabb>,
    /// Leaf `i`'s collision filter; empty when none was set (no test at all).
    filters: Vec<Filter>,
    mode: ParryMode,
}

fn aabb(s: &Sphere) -> PAabb {
    let (c, r) = (s.center, s.radius);
    PAabb::new(
        Vector::new(c.x - r, c.y - r, c.z - r),
        Vector::new(c.x + r, c.y + r, c.z + r),
    )
}

impl ParryBvh {
    /// An empty BVH maintained in `mode` every frame.
    pub fn new(mode: ParryMode) -> Self {
        ParryBvh {
            bvh: Bvh::new(),
            workspace: BvhWorkspace::default(),
            spheres: Vec::new(),
            aabbs: Vec::new(),
            filters: Vec::new(),
            mode,
        }
    }

    /// Calls `f(a, b)` once for every pair of leaves whose spheres overlap
    /// (closed test); the pair search behind [`Structure::count_pairs`].
    /// With filters set, only pairs whose filters interact (tested first).
    pub fn for_each_pair(&mut self, mut f: impl FnMut(u32, u32)) {
        let spheres = &self.spheres;
        if self.filters.is_empty() {
            self.bvh
                .traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                    if overlap::sphere_sphere(&spheres[a as usize], &spheres[b as usize]) {
                        f(a, b);
                    }
                });
            return;
        }
        let filters = &self.filters;
        self.bvh
            .traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                let (a, b) = (a as usize, b as usize);
                if filters[a].interacts(filters[b])
                    && overlap::sphere_sphere(&spheres[a], &spheres[b])
                {
                    f(a as u32, b as u32);
                }
            });
    }
}

impl Structure for ParryBvh {
    fn build(&mut self, spheres: &[Sphere]) {
        self.spheres = spheres.to_vec();
        self.aabbs = spheres.iter().map(aabb).collect();
        self.bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &self.aabbs);
    }

    fn set_filters(&mut self, filters: &[Filter]) {
        self.filters = filters.to_vec();
    }

    fn update(&mut self, spheres: &[Sphere]) {
        self.spheres.copy_from_slice(spheres);
        if self.mode == ParryMode::Rebuild {
            for (dst, s) in self.aabbs.iter_mut().zip(spheres) {
                *dst = aabb(s);
            }
            self.bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &self.aabbs);
            return;
        }
        for (i, s) in spheres.iter().enumerate() {
            self.bvh.insert_or_update_partially(aabb(s), i as u32, 0.0);
        }
        if self.mode == ParryMode::OptimizeRefit {
            self.bvh.optimize_incremental(&mut self.workspace);
        }
        self.bvh.refit(&mut self.workspace);
    }

    fn count_pairs(&mut self) -> u64 {
        let mut n = 0u64;
        self.for_each_pair(|_, _| n += 1);
        n
    }

    /// parry's own `total_memory_size()` (nodes, parents, leaf map, free list: by
    /// capacity), plus the workspace's refit buffer, which parry does not expose but
    /// which after a `refit` holds the previous node array (estimated as one
    /// `BvhNodeWide` per leaf: a binary tree of `L` leaves has `L - 1` two-child
    /// nodes; not held in [`ParryMode::Rebuild`], which keeps the leaf AABBs
    /// instead), plus the sphere copy the exact test reads (16 B/object, as
    /// Proxima's indices store their spheres too).
    fn memory_bytes(&self) -> usize {
        let side = match self.mode {
            ParryMode::Rebuild => self.aabbs.capacity() * std::mem::size_of::<PAabb>(),
            _ => self.bvh.leaf_count() as usize * std::mem::size_of::<BvhNodeWide>(),
        };
        std::mem::size_of::<Self>()
            + self.bvh.total_memory_size()
            + side
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
            + self.filters.capacity() * std::mem::size_of::<Filter>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proxima_harness::workloads::{Kind, Workload};
    use std::collections::BTreeSet;

    fn brute(s: &[Sphere]) -> BTreeSet<(u32, u32)> {
        let mut out = BTreeSet::new();
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                if overlap::sphere_sphere(&s[i], &s[j]) {
                    out.insert((i as u32, j as u32));
                }
            }
        }
        out
    }

    /// Every mode finds exactly the brute-force pairs (the pairs themselves, not
    /// only their number), each once, frame after frame of a small moving scene.
    #[test]
    fn every_mode_finds_the_brute_force_pairs() {
        for kind in [Kind::W1, Kind::W3, Kind::W9] {
            for mode in ParryMode::ALL {
                let mut w = Workload::new(kind, 300, 5);
                let mut p = ParryBvh::new(mode);
                p.build(&w.spheres);
                let mut seen = 0;
                for _ in 0..8 {
                    w.step();
                    p.update(&w.spheres);
                    let mut got = BTreeSet::new();
                    let mut calls = 0;
                    p.for_each_pair(|a, b| {
                        calls += 1;
                        got.insert((a.min(b), a.max(b)));
                    });
                    let want = brute(&w.spheres);
                    assert_eq!(calls, got.len(), "{kind:?} {mode:?}: a pair reported twice");
                    assert_eq!(got, want, "{kind:?} {mode:?} frame {}", w.frame());
                    assert_eq!(p.count_pairs(), want.len() as u64);
                    seen += want.len();
                }
                assert!(seen > 0, "{kind:?}: a scene without pairs proves nothing");
            }
        }
    }
}
