//! Node layout, the derivation of child boxes from their parent, the conservative
//! region of a subtree, and a fixed-size traversal stack.

use super::LooseKdTree;
use crate::geom::{Aabb, Sphere};
use glam::Vec3;

/// "No node / no item".
pub(super) const NIL: u32 = u32::MAX;

/// A tree node (the source's `NODE`, [sources: kd-tree]), flat in a [`Pool`](crate::arena::Pool).
///
/// Laid out by hand (`repr(C)`, one cache line per node start): the fields the
/// pair walk reads at every node (objects, children, split) and those a move
/// reads (the cell and `h_up`) fill the first line; the box, read by insertion
/// and queries, follows.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Node {
    /// The objects attached here are at positions `start .. start + len` of the
    /// tree's object array (`store.rs`), in no particular order (removal swaps the
    /// last one into the hole); the range has room for `cap`.
    pub start: u32,
    pub len: u32,
    pub cap: u32,
    /// `[negative, positive]`.
    pub child: [u32; 2],
    /// Centre of `bbox` on the split axis.
    pub m: f32,
    /// Border half-width `min(R_max, extent_axis(bbox) · d / 4)`.
    pub h: f32,
    /// Split axis: the longest of `bbox` (ties to the lower index, [sources: kd-insert]).
    pub axis: u8,
    pub depth: u8,
    /// Set by a move that kept its node without growing its chunk bound: the
    /// chunk bounds of this node's range may miss its objects (`store.rs`), so
    /// queries test every object. Cleared when the range is rewritten.
    pub loose: bool,
    /// The parent's `h` (∞ at the root): a sphere is routed here only if `r < h_up`.
    /// `h` never grows downwards, so this is the smallest `h` on the path.
    pub h_up: f32,
    pub parent: u32,
    /// Where the centres of spheres routed through this node lie: per split above,
    /// `c_a > m` (positive side, `cell.min` exclusive) or `c_a <= m` (negative side,
    /// `cell.max` inclusive). Unsplit faces are infinite: the rule ignores the
    /// world box. Lets a move check in O(1) that the placement is unchanged.
    /// In the first cache line, with `h_up`, `h`, `depth` and `start`: a move
    /// that keeps its node reads only that line.
    pub cell: Aabb,
    /// The box `B` of [sources: kd-border]: the world box, narrowed by one face per split above.
    pub bbox: Aabb,
    /// OR of the groups and of the masks of the filters of every object in
    /// the subtree, or a superset (they only grow while the node lives): a
    /// filtered query skips the subtree when its filter cannot interact with
    /// them ([`Filter::may_interact`](crate::broad::Filter::may_interact)).
    /// After the box, in the second cache line: only filtered walks read it.
    pub groups: u32,
    pub masks: u32,
}

impl Node {
    /// A node over `bbox` holding nothing yet (no room either: the first object
    /// placed gives it a range); split axis, `m` and `h` are derived from it.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        bbox: Aabb,
        cell: Aabb,
        h_up: f32,
        parent: u32,
        depth: u8,
        r_max: f32,
        density: f32,
    ) -> Node {
        let (axis, m, h) = split_of(&bbox, r_max, density);
        Node {
            bbox,
            cell,
            m,
            h,
            h_up,
            parent,
            child: [NIL, NIL],
            start: 0,
            len: 0,
            cap: 0,
            axis,
            depth,
            loose: false,
            groups: 0,
            masks: 0,
        }
    }

    /// Box and cell of the child on `side` (0 negative, 1 positive): the source's
    /// `B2.Max[a] -= UnusedSpace` / `B2.Min[a] += UnusedSpace` [sources: kd-border], written as
    /// `m + h` / `m - h` directly.
    pub fn child_bounds(&self, side: usize) -> (Aabb, Aabb) {
        let a = self.axis as usize;
        let (mut b, mut c) = (self.bbox, self.cell);
        // The cell is intersected, not overwritten: `m` is the centre of the loose
        // box, which need not lie inside this node's (tighter) cell.
        if side == 1 {
            b.min[a] = self.m - self.h;
            c.min[a] = c.min[a].max(self.m);
        } else {
            b.max[a] = self.m + self.h;
            c.max[a] = c.max[a].min(self.m);
        }
        (b, c)
    }

    /// Positions of the node's objects in the object array.
    #[inline]
    pub fn range(&self) -> std::ops::Range<usize> {
        self.start as usize..(self.start + self.len) as usize
    }

    /// True when the node holds no item and has no child (it must then be freed).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0 && self.child[0] == NIL && self.child[1] == NIL
    }

    /// True if the placement rule routes `s` through this node: its centre is on
    /// this node's side of every split above, and `r` is below every `h` above.
    #[inline]
    pub fn routes(&self, s: &Sphere) -> bool {
        s.radius < self.h_up
            && s.center.cmpgt(self.cell.min).all()
            && s.center.cmple(self.cell.max).all()
    }
}

/// Split axis, centre and border half-width of a node box ([sources: kd-insert]: `RecursivePush`,
/// steps 1 and 3). `m` is computed as `min/2 + max/2` so huge boxes do not overflow.
pub(super) fn split_of(b: &Aabb, r_max: f32, density: f32) -> (u8, f32, f32) {
    let axis = b.longest_axis();
    let (lo, hi) = (b.min[axis], b.max[axis]);
    let m = lo * 0.5 + hi * 0.5;
    let h = r_max.min((hi - lo) * density * 0.25);
    (axis as u8, m, h)
}

/// Slack for pruning bounds: about 80 ulps of the largest coordinate stored.
pub(super) fn slack(span: &Aabb) -> f32 {
    let mag = span.min.abs().max(span.max.abs()).max_element();
    (mag * 1e-5).max(f32::MIN_POSITIVE)
}

/// The cell of the root: every centre.
pub(super) fn all_space() -> Aabb {
    Aabb::new(Vec3::splat(f32::NEG_INFINITY), Vec3::splat(f32::INFINITY))
}

impl<T> LooseKdTree<T> {
    /// A box containing every sphere stored in the subtree of `n`, with `eps` to
    /// spare on every side. Used by frustum, ray and pair pruning.
    ///
    /// Why it is conservative: a face of `bbox` that comes from a split above is
    /// `m - h` (positive side) or `m + h` (negative side) of that split, and every
    /// sphere routed through it has `c_a > m` and `r < h` (or `c_a <= m`, `r < h`),
    /// so it lies strictly on the inner side of that face — whether or not it is
    /// inside the world box. A face of `bbox` that equals the world box's face was
    /// never split (split faces lie strictly inside the world) and bounds nothing
    /// for spheres outside the world, so it is replaced by the face of `span`, which
    /// covers every stored sphere. (If rounding ever made a split face equal the
    /// world face, using `span` there is merely looser.) The outward `eps` absorbs
    /// rounding in the callers' `f32` tests, so pruning never disagrees with the
    /// exact tests of `geom::overlap` on a sphere that touches a face.
    #[inline]
    pub(super) fn region(&self, n: &Node) -> Aabb {
        self.region_of_box(&n.bbox)
    }

    /// [`LooseKdTree::region`] of the node whose box is `bbox`: lets a walk derive
    /// a child's region from its parent without loading the child.
    #[inline]
    pub(super) fn region_of_box(&self, bbox: &Aabb) -> Aabb {
        let e = Vec3::splat(self.eps);
        let min = Vec3::select(bbox.min.cmpeq(self.world.min), self.span.min, bbox.min);
        let max = Vec3::select(bbox.max.cmpeq(self.world.max), self.span.max, bbox.max);
        Aabb::new(min - e, max + e)
    }

    /// Lower bound on the split axis of every sphere in the positive subtree of `n`
    /// (`c_a - r > m - h`), minus slack.
    #[inline]
    pub(super) fn pos_floor(&self, n: &Node) -> f32 {
        n.m - n.h - self.eps
    }

    /// Upper bound on the split axis of every sphere in the negative subtree of `n`
    /// (`c_a + r < m + h`), plus slack.
    #[inline]
    pub(super) fn neg_ceil(&self, n: &Node) -> f32 {
        n.m + n.h + self.eps
    }
}

/// Capacity of [`FixedStack`]. A depth-first walk that pops a node and pushes at
/// most its two children holds at most one pending sibling per level plus two, so
/// `MAX_DEPTH_LIMIT + 2` entries suffice; the rest is margin.
const STACK: usize = super::MAX_DEPTH_LIMIT as usize + 8;

/// A traversal stack on the call stack: queries allocate nothing. The depth bound
/// above is an argument, not a check, so entries beyond [`STACK`] spill into a heap
/// `Vec` instead of indexing out of bounds: a wrong bound costs an allocation,
/// never a panic.
pub(super) struct FixedStack<E: Copy + Default> {
    buf: [E; STACK],
    len: usize,
    /// Entries pushed while `buf` was full (the most recent ones, so popped first).
    spill: Vec<E>,
}

impl<E: Copy + Default> FixedStack<E> {
    pub fn new() -> Self {
        FixedStack {
            buf: [E::default(); STACK],
            len: 0,
            spill: Vec::new(),
        }
    }
    #[inline]
    pub fn push(&mut self, e: E) {
        if self.len < STACK {
            self.buf[self.len] = e;
            self.len += 1;
        } else {
            self.spill.push(e);
        }
    }
    #[inline]
    pub fn pop(&mut self) -> Option<E> {
        if let Some(e) = self.spill.pop() {
            Some(e)
        } else if self.len == 0 {
            None
        } else {
            self.len -= 1;
            Some(self.buf[self.len])
        }
    }
}

#[cfg(test)]
mod stack_tests {
    use super::*;

    #[test]
    fn fixed_stack_spills_instead_of_overflowing() {
        let mut s = FixedStack::<u32>::new();
        for i in 0..(3 * STACK as u32) {
            s.push(i);
        }
        for i in (0..(3 * STACK as u32)).rev() {
            assert_eq!(s.pop(), Some(i));
        }
        assert_eq!(s.pop(), None);
    }
}
