//! Simultaneous traversal of two BVHs (seed 003, Fig. 2).

use super::tree::Bvh;
use crate::narrow::bv::BoundingVolume;

/// Where the moving tree's volumes come from during a traversal.
pub(crate) trait VolumeSource<BV> {
    /// The volume of node `i` of the moving tree, in the frame `motion` expects.
    fn volume(&mut self, i: usize) -> BV;
}

/// The tree's own volumes (a motion does the moving).
pub(crate) struct Local<'a, BV>(pub &'a [super::Node<BV>]);

impl<BV: Copy> VolumeSource<BV> for Local<'_, BV> {
    #[inline]
    fn volume(&mut self, i: usize) -> BV {
        self.0[i].bv
    }
}

/// Volumes precomputed per node (the exact refit).
pub(crate) struct Precomputed<'a, BV>(pub &'a [BV]);

impl<BV: Copy> VolumeSource<BV> for Precomputed<'_, BV> {
    #[inline]
    fn volume(&mut self, i: usize) -> BV {
        self.0[i]
    }
}

/// Volumes transformed on first use ([`BoundingVolume::transformed`]), counting
/// each transform as one node update.
pub(crate) struct Lazy<'a, BV> {
    pub nodes: &'a [super::Node<BV>],
    pub pose: glam::Affine3A,
    pub cache: &'a mut Vec<Option<BV>>,
    pub updates: u64,
}

impl<BV: BoundingVolume> VolumeSource<BV> for Lazy<'_, BV> {
    #[inline]
    fn volume(&mut self, i: usize) -> BV {
        if let Some(v) = self.cache[i] {
            return v;
        }
        let v = self.nodes[i].bv.transformed(&self.pose);
        self.cache[i] = Some(v);
        self.updates += 1;
        v
    }
}

/// Descends both trees from their roots: a pair of nodes whose volumes overlap is
/// split on the side that is not a leaf, or on the larger volume when neither is
/// (seed 003, Fig. 2 with the usual "descend the larger" refinement); a pair of
/// overlapping leaves goes to `leaf(a_node, b_node)`, which returns true to stop.
/// Each pair of leaves is reached at most once, so each triangle pair is tested at
/// most once. Counts volume tests in `nv`. Returns true if stopped early.
pub(crate) fn traverse<BV: BoundingVolume>(
    a: &Bvh<BV>,
    src: &mut impl VolumeSource<BV>,
    motion: &BV::Motion,
    b: &Bvh<BV>,
    stack: &mut Vec<(u32, u32)>,
    nv: &mut u64,
    mut leaf: impl FnMut(usize, usize) -> bool,
) -> bool {
    stack.clear();
    stack.push((0, 0));
    while let Some((ia, ib)) = stack.pop() {
        let va = src.volume(ia as usize);
        let nb = &b.nodes[ib as usize];
        *nv += 1;
        if !va.overlaps(motion, &nb.bv) {
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
                if va.size() >= nb.bv.size() {
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
fn push_a<BV>(stack: &mut Vec<(u32, u32)>, na: &super::Node<BV>, ia: u32, ib: u32) {
    let (l, r) = na.children(ia);
    stack.push((r, ib));
    stack.push((l, ib));
}

#[inline]
fn push_b<BV>(stack: &mut Vec<(u32, u32)>, nb: &super::Node<BV>, ia: u32, ib: u32) {
    let (l, r) = nb.children(ib);
    stack.push((ia, r));
    stack.push((ia, l));
}
