//! Simultaneous traversal of two BVHs [sources: bvh-traverse].

use super::tree::{Bvh, Node};
use crate::narrow::bv::BoundingVolume;

/// Where the moving tree's volumes come from during a traversal, and how they are
/// tested against the fixed tree's.
pub(crate) trait VolumeSource<BV> {
    /// Whether node `i` of the moving tree overlaps `other` (a fixed-tree volume).
    fn overlaps(&mut self, i: usize, other: &BV) -> bool;
    /// The size of node `i` (to pick the tree to descend).
    fn size(&mut self, i: usize) -> f32;
}

/// The tree's own volumes, moved by a prepared motion inside the test.
pub(crate) struct Local<'a, BV: BoundingVolume> {
    pub nodes: &'a [Node<BV>],
    pub motion: BV::Motion,
}

impl<BV: BoundingVolume> VolumeSource<BV> for Local<'_, BV> {
    #[inline(always)]
    fn overlaps(&mut self, i: usize, other: &BV) -> bool {
        self.nodes[i].bv.overlaps(&self.motion, other)
    }
    #[inline(always)]
    fn size(&mut self, i: usize) -> f32 {
        self.nodes[i].bv.size()
    }
}

/// Volumes precomputed per node in the fixed frame, already enlarged by the slack
/// (the exact refit): the test is plain interval comparisons.
pub(crate) struct Precomputed<'a, BV>(pub &'a [BV]);

impl<BV: BoundingVolume> VolumeSource<BV> for Precomputed<'_, BV> {
    #[inline(always)]
    fn overlaps(&mut self, i: usize, other: &BV) -> bool {
        self.0[i].overlaps_fixed(other)
    }
    #[inline(always)]
    fn size(&mut self, i: usize) -> f32 {
        self.0[i].size()
    }
}

/// Volumes transformed on first use ([`BoundingVolume::transformed`]) and enlarged
/// by the slack, counting each as one node update. A [`VolumeSource`] as every
/// source of volumes posed in the fixed frame (`moving.rs`).
pub(crate) struct Lazy<'a, BV> {
    pub nodes: &'a [Node<BV>],
    pub pose: glam::Affine3A,
    pub slack: f32,
    pub cache: &'a mut super::tri_cache::QueryCache<BV>,
    pub updates: u64,
}

impl<BV: BoundingVolume> Lazy<'_, BV> {
    #[inline]
    pub(crate) fn get(&mut self, i: usize) -> &BV {
        if !self.cache.is_set(i) {
            self.updates += 1;
        }
        let (nodes, pose, slack) = (self.nodes, &self.pose, self.slack);
        self.cache
            .get(i, || nodes[i].bv.transformed(pose).inflated(slack))
    }
}

/// Descends both trees from their roots: a pair of nodes whose volumes overlap is
/// split on the side that is not a leaf, or on the larger volume when neither is
/// ([sources: bvh-traverse], with the usual "descend the larger" refinement); a pair of
/// overlapping leaves goes to `leaf(a_node, b_node)`, which returns true to stop.
/// Each pair of leaves is reached at most once, so each triangle pair is tested at
/// most once. Counts volume tests in `nv`. Returns true if stopped early.
pub(crate) fn traverse<BV: BoundingVolume>(
    a: &Bvh<BV>,
    src: &mut impl VolumeSource<BV>,
    b: &Bvh<BV>,
    stack: &mut Vec<(u32, u32)>,
    nv: &mut u64,
    mut leaf: impl FnMut(usize, usize) -> bool,
) -> bool {
    stack.clear();
    stack.push((0, 0));
    while let Some((ia, ib)) = stack.pop() {
        let nb = &b.nodes[ib as usize];
        *nv += 1;
        if !src.overlaps(ia as usize, &nb.bv) {
            continue;
        }
        let na = &a.nodes[ia as usize];
        match (na.is_leaf(), nb.is_leaf()) {
            (true, true) => {
                if leaf(ia as usize, ib as usize) {
                    return true;
                }
            }
            (false, true) => push_a(stack, na, ia, ib),
            (true, false) => push_b(stack, nb, ia, ib),
            (false, false) => {
                if src.size(ia as usize) >= nb.bv.size() {
                    push_a(stack, na, ia, ib)
                } else {
                    push_b(stack, nb, ia, ib)
                }
            }
        }
    }
    false
}

#[inline]
fn push_a<BV>(stack: &mut Vec<(u32, u32)>, na: &Node<BV>, ia: u32, ib: u32) {
    let (l, r) = na.children(ia);
    stack.push((r, ib));
    stack.push((l, ib));
}

#[inline]
fn push_b<BV>(stack: &mut Vec<(u32, u32)>, nb: &Node<BV>, ia: u32, ib: u32) {
    let (l, r) = nb.children(ib);
    stack.push((ia, r));
    stack.push((ia, l));
}
