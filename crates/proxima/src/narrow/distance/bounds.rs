//! Lower bounds of the moving tree's volumes against the fixed tree's, from
//! wherever the collision traversal gets the moved volumes (the pose applied
//! inside the test, an exact refit, or lazily transformed volumes): the same
//! three sources, extended with [`BoundingVolume::distance_lower_bound`].

use crate::narrow::bv::BoundingVolume;
use crate::narrow::bvh::traverse::{Lazy, Local, Precomputed, VolumeSource};
use crate::narrow::Node;

/// A [`VolumeSource`] that also bounds distances.
pub(crate) trait LowerBounds<BV>: VolumeSource<BV> {
    /// A lower bound on the distance between node `i` of the moving tree (moved)
    /// and `other` (a fixed-tree volume); `0` if they may overlap.
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32;
}

impl<BV: BoundingVolume> LowerBounds<BV> for Local<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.nodes[i].bv.distance_lower_bound(&self.motion, other)
    }
}

impl<BV: BoundingVolume> LowerBounds<BV> for Precomputed<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.0[i].distance_lower_bound_fixed(other)
    }
}

impl<BV: BoundingVolume> LowerBounds<BV> for Lazy<'_, BV> {
    #[inline]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).distance_lower_bound_fixed(other)
    }
}

/// Subtrees of at most this many triangles get exact moved volumes in
/// [`ExactLeaves`].
const EXACT_BELOW: usize = 8;

/// The number of triangles below node `i`: its subtree covers the contiguous
/// leaf-order range from its leftmost leaf's start to its rightmost leaf's end.
/// O(depth of the subtree).
fn subtree_len<BV>(nodes: &[Node<BV>], i: usize) -> usize {
    let mut lo = i;
    while !nodes[lo].is_leaf() {
        lo += 1; // left child
    }
    let mut hi = i;
    while !nodes[hi].is_leaf() {
        hi = nodes[hi].children(hi as u32).1 as usize;
    }
    nodes[hi].triangle_range().end - nodes[lo].triangle_range().start
}

/// [`Lazy`] with exact volumes near the leaves: a leaf's volume is fitted to its
/// triangles' posed corners (`f32`, as the triangle tests see them), an internal
/// node with a small subtree (at most [`EXACT_BELOW`] triangles) merges its
/// children's, a larger one takes the conservative
/// [`BoundingVolume::transformed`] bound; all enlarged by the slack and computed
/// on first use (one node update each).
///
/// Distance queries are decided near the leaves, where the transformed bound of
/// a rotated k-DOP is loosest relative to its content (up to `√3` times its
/// size): exact volumes there cost three vertex transforms per reached leaf and
/// roughly halve the pairs a near-miss query visits.
pub(crate) struct ExactLeaves<'a, BV> {
    pub lazy: Lazy<'a, BV>,
    pub tris: &'a [[u32; 3]],
    pub vertices: &'a [glam::Vec3],
}

impl<BV: BoundingVolume> ExactLeaves<'_, BV> {
    fn get(&mut self, i: usize) -> &BV {
        if self.lazy.cache.is_set(i) {
            return self.lazy.get(i);
        }
        let nodes = self.lazy.nodes;
        let n = &nodes[i];
        if n.is_leaf() {
            self.lazy.updates += 1;
            let (pose, slack, tris, verts) =
                (&self.lazy.pose, self.lazy.slack, self.tris, self.vertices);
            return self.lazy.cache.get(i, || {
                let mut range = n.triangle_range();
                let corners = |k: usize| tris[k].map(|v| pose.transform_point3(verts[v as usize]));
                let mut bv = BV::from_points(&corners(range.next().unwrap_or(0)));
                for k in range {
                    bv = bv.merge(&BV::from_points(&corners(k)));
                }
                bv.inflated(slack)
            });
        }
        if subtree_len(nodes, i) > EXACT_BELOW {
            return self.lazy.get(i);
        }
        // A small subtree: the merge of the children's (exact) volumes.
        let (l, r) = n.children(i as u32);
        let left = *self.get(l as usize);
        let merged = left.merge(self.get(r as usize));
        self.lazy.updates += 1;
        self.lazy.cache.get(i, || merged)
    }
}

impl<BV: BoundingVolume> VolumeSource<BV> for ExactLeaves<'_, BV> {
    #[inline]
    fn overlaps(&mut self, i: usize, other: &BV) -> bool {
        self.get(i).overlaps_fixed(other)
    }
    #[inline]
    fn size(&mut self, i: usize) -> f32 {
        self.get(i).size()
    }
}

impl<BV: BoundingVolume> LowerBounds<BV> for ExactLeaves<'_, BV> {
    #[inline]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).distance_lower_bound_fixed(other)
    }
}
