//! Simultaneous traversal of two BVHs [sources: bvh-traverse].

use super::tree::{Bvh, Node};
use crate::narrow::bv::BoundingVolume;
use glam::Vec3;

/// Where the moving tree's volumes come from during a traversal, and how they are
/// tested against the fixed tree's.
pub(crate) trait VolumeSource<BV> {
    /// Whether node `i` of the moving tree overlaps `other` (a fixed-tree volume).
    fn overlaps(&mut self, i: usize, other: &BV) -> bool;
    /// The size of node `i` (to pick the tree to descend).
    fn size(&mut self, i: usize) -> f32;
    /// [`BoundingVolume::overlap_depth`] of node `i` and `other`: negative iff
    /// [`VolumeSource::overlaps`] is false.
    fn overlap_depth(&mut self, i: usize, other: &BV) -> f32;
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
    #[inline(always)]
    fn overlap_depth(&mut self, i: usize, other: &BV) -> f32 {
        self.nodes[i].bv.overlap_depth(&self.motion, other)
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
    #[inline(always)]
    fn overlap_depth(&mut self, i: usize, other: &BV) -> f32 {
        self.0[i].overlap_depth_fixed(other)
    }
}

/// Volumes transformed on first use ([`BoundingVolume::transformed`]) and enlarged
/// by the slack, counting each as one node update.
pub(crate) struct Lazy<'a, BV> {
    pub nodes: &'a [Node<BV>],
    pub pose: glam::Affine3A,
    pub slack: f32,
    pub cache: &'a mut super::tri_cache::QueryCache<BV>,
    pub updates: u64,
    /// Take [`BoundingVolume::transformed_tight`] (the distance descent) rather
    /// than [`BoundingVolume::transformed`] (collision).
    pub tight: bool,
}

/// The conservative moved volume of `bv`: the tight bound or the cheap one.
#[inline(always)]
fn moved_bound<BV: BoundingVolume>(bv: &BV, pose: &glam::Affine3A, tight: bool) -> BV {
    if tight {
        bv.transformed_tight(pose)
    } else {
        bv.transformed(pose)
    }
}

impl<BV: BoundingVolume> Lazy<'_, BV> {
    #[inline]
    pub(crate) fn get(&mut self, i: usize) -> &BV {
        if !self.cache.is_set(i) {
            self.updates += 1;
        }
        let (nodes, pose, slack, tight) = (self.nodes, &self.pose, self.slack, self.tight);
        self.cache
            .get(i, || moved_bound(&nodes[i].bv, pose, tight).inflated(slack))
    }
}

impl<BV: BoundingVolume> VolumeSource<BV> for Lazy<'_, BV> {
    #[inline]
    fn overlaps(&mut self, i: usize, other: &BV) -> bool {
        self.get(i).overlaps_fixed(other)
    }
    #[inline]
    fn size(&mut self, i: usize) -> f32 {
        self.get(i).size()
    }
    #[inline]
    fn overlap_depth(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).overlap_depth_fixed(other)
    }
}

/// [`Lazy`] with exact volumes near the leaves: a leaf's volume is fitted to its
/// triangles' posed corners (`pose.transform_point3`, the `f32` points the
/// triangle tests see), an internal node with a small subtree (at most
/// `below` triangles: the query's choice) merges its children's, a larger one takes the
/// conservative [`BoundingVolume::transformed`] bound; all enlarged by the slack
/// and computed on first use (one node update each).
///
/// Collisions are decided near the leaves, where the transformed bound of a
/// rotated k-DOP is loosest relative to its content (up to `√3` times its
/// size): exact volumes there cost three vertex transforms per reached leaf and
/// cut the volume and triangle tests by about half (W5, k-DOP18: as few as the
/// source's full refit, [sources: bvh-rotate], which updates every node).
pub(crate) struct ExactLeaves<'a, BV> {
    pub lazy: Lazy<'a, BV>,
    /// The moving tree's triangles in leaf order, and its mesh's vertices.
    pub tris: &'a [[u32; 3]],
    pub vertices: &'a [Vec3],
    /// Triangles below each node of the moving tree (`Bvh::subtree`).
    pub sizes: &'a [u32],
    /// Subtrees of at most this many triangles get exact volumes.
    pub below: u32,
}

impl<BV: BoundingVolume> ExactLeaves<'_, BV> {
    #[inline]
    pub(crate) fn get(&mut self, i: usize) -> &BV {
        if !self.lazy.cache.is_set(i) {
            let bv = self.exact_or_transformed(i);
            self.lazy.updates += 1;
            return self.lazy.cache.put(i, bv);
        }
        self.lazy.cache.value(i)
    }

    /// The moved volume of node `i` (not cached yet; its children may be).
    fn exact_or_transformed(&mut self, i: usize) -> BV {
        let nodes = self.lazy.nodes;
        let n = &nodes[i];
        if n.is_leaf() {
            let (pose, tris, verts) = (&self.lazy.pose, self.tris, self.vertices);
            let corners = |k: usize| tris[k].map(|v| pose.transform_point3(verts[v as usize]));
            let mut range = n.triangle_range();
            let mut bv = BV::from_points(&corners(range.start));
            range.start += 1;
            for k in range {
                bv = bv.merge(&BV::from_points(&corners(k)));
            }
            return bv.inflated(self.lazy.slack);
        }
        if self.sizes[i] > self.below {
            return moved_bound(&n.bv, &self.lazy.pose, self.lazy.tight).inflated(self.lazy.slack);
        }
        // A small subtree: the merge of the children's exact volumes (each
        // cached, as the descent will likely need them).
        let (l, r) = n.children(i as u32);
        let left = *self.get(l as usize);
        left.merge(self.get(r as usize))
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
    #[inline]
    fn overlap_depth(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).overlap_depth_fixed(other)
    }
}

/// Where a traversal ended: every node pair it did not split (a disjoint pair, or
/// a pair of overlapping leaves), in the order met. These pairs form a cut of the
/// two trees' pair tree: their leaf products partition all leaf pairs, so a later
/// traversal may start from them instead of the roots and reach the same
/// triangle pairs (the collision world's coherence, [sources: bvh-next]).
pub(crate) trait Terminal {
    /// Records a pair the traversal did not split.
    fn reached(&mut self, ia: u32, ib: u32);
}

/// Records nothing: a plain traversal.
impl Terminal for () {
    #[inline(always)]
    fn reached(&mut self, _: u32, _: u32) {}
}

/// Records the cut into `out` while it has at most `cap` pairs past `base` (the
/// length of `out` when recording began); beyond that it stops and sets `full`
/// (the caller drops the partial cut).
#[derive(Debug)]
pub(crate) struct CutRecorder<'a> {
    pub out: &'a mut Vec<(u32, u32)>,
    pub base: usize,
    pub cap: usize,
    pub full: bool,
}

impl Terminal for CutRecorder<'_> {
    #[inline]
    fn reached(&mut self, ia: u32, ib: u32) {
        if self.full {
            return;
        }
        if self.out.len() - self.base >= self.cap {
            self.full = true;
        } else {
            self.out.push((ia, ib));
        }
    }
}

/// Descends both trees from the node pairs `start` (the roots `(0, 0)`, or a cut
/// recorded by an earlier traversal: see [`Terminal`]): a pair of nodes whose
/// volumes overlap is split on the side that is not a leaf, or on the larger
/// volume when neither is ([sources: bvh-traverse], with the usual "descend the
/// larger" refinement); a pair of overlapping leaves goes to
/// `leaf(a_node, b_node)`, which returns true to stop. Pairs not split are
/// reported to `cut`. Each pair of leaves is reached at most once, so each
/// triangle pair is tested at most once. The roots are tested first, which ends
/// the traversal when they are disjoint (one test instead of one per pair of a
/// cut). Counts volume tests in `nv`. Returns true if stopped early (then `cut`
/// saw only part of the cut).
///
/// The two child pairs of a split are tested before anything is pushed: only
/// overlapping pairs go on the stack, and the descent continues with the first
/// of them without a push and a pop (depth first). With `DEEPEST_FIRST` (the
/// first-contact query), the child pair whose volumes overlap more deeply
/// ([`BoundingVolume::overlap_depth`]) comes first, else the left one: the
/// same pairs are visited either way until the leaf callback stops the descent.
#[allow(clippy::too_many_arguments)]
pub(crate) fn traverse<BV: BoundingVolume, const DEEPEST_FIRST: bool>(
    a: &Bvh<BV>,
    src: &mut impl VolumeSource<BV>,
    b: &Bvh<BV>,
    start: &[(u32, u32)],
    stack: &mut Vec<(u32, u32)>,
    nv: &mut u64,
    cut: &mut impl Terminal,
    mut leaf: impl FnMut(usize, usize) -> bool,
) -> bool {
    stack.clear();
    *nv += 1;
    if !src.overlaps(0, &b.nodes[0].bv) {
        cut.reached(0, 0);
        return false;
    }
    // The current pair: its volumes overlap.
    let (mut ia, mut ib) = (0u32, 0u32);
    if start != [(0, 0)] {
        // A cut: its overlapping pairs go on the stack (the first on top), the
        // others are already part of the new cut.
        for &(ja, jb) in start.iter().rev() {
            *nv += 1;
            if src.overlaps(ja as usize, &b.nodes[jb as usize].bv) {
                stack.push((ja, jb));
            } else {
                cut.reached(ja, jb);
            }
        }
        match stack.pop() {
            Some(next) => (ia, ib) = next,
            None => return false,
        }
    }
    loop {
        let na = &a.nodes[ia as usize];
        let nb = &b.nodes[ib as usize];
        let descend_a = match (na.is_leaf(), nb.is_leaf()) {
            (true, true) => {
                cut.reached(ia, ib);
                if leaf(ia as usize, ib as usize) {
                    return true;
                }
                match stack.pop() {
                    Some(next) => {
                        (ia, ib) = next;
                        continue;
                    }
                    None => return false,
                }
            }
            (false, true) => true,
            (true, false) => false,
            (false, false) => src.size(ia as usize) >= nb.bv.size(),
        };
        // The two child pairs and whether (how deeply) each overlaps.
        *nv += 2;
        let (x, y, dx, dy) = if descend_a {
            let (l, r) = na.children(ia);
            let bv = &nb.bv;
            if DEEPEST_FIRST {
                let (dl, dr) = (
                    src.overlap_depth(l as usize, bv),
                    src.overlap_depth(r as usize, bv),
                );
                ((l, ib), (r, ib), dl, dr)
            } else {
                let d = |o: bool| if o { 0.0 } else { -1.0 };
                let (ol, or) = (src.overlaps(l as usize, bv), src.overlaps(r as usize, bv));
                ((l, ib), (r, ib), d(ol), d(or))
            }
        } else {
            let (l, r) = nb.children(ib);
            let (bl, br) = (&b.nodes[l as usize].bv, &b.nodes[r as usize].bv);
            let va = ia as usize;
            if DEEPEST_FIRST {
                let (dl, dr) = (src.overlap_depth(va, bl), src.overlap_depth(va, br));
                ((ia, l), (ia, r), dl, dr)
            } else {
                let d = |o: bool| if o { 0.0 } else { -1.0 };
                let (ol, or) = (src.overlaps(va, bl), src.overlaps(va, br));
                ((ia, l), (ia, r), d(ol), d(or))
            }
        };
        (ia, ib) = match (dx >= 0.0, dy >= 0.0) {
            (true, true) => {
                let (first, second) = if DEEPEST_FIRST && dy > dx {
                    (y, x)
                } else {
                    (x, y)
                };
                stack.push(second);
                first
            }
            (true, false) => {
                cut.reached(y.0, y.1);
                x
            }
            (false, true) => {
                cut.reached(x.0, x.1);
                y
            }
            (false, false) => {
                cut.reached(x.0, x.1);
                cut.reached(y.0, y.1);
                match stack.pop() {
                    Some(next) => next,
                    None => return false,
                }
            }
        };
    }
}
