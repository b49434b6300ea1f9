//! Self-collision: every overlapping pair once, by walking the tree node against
//! node (not one query per object).
//!
//! A pair `(x, y)` with `x` at node `X` and `y` at node `Y` falls in exactly one
//! case, each handled once:
//! - `X == Y`: the items of a node against each other;
//! - `X` a proper ancestor of `Y`: during the depth-first walk each node carries
//!   the *active set*, the ancestors' items that can reach its region; it is
//!   filtered by one split-axis comparison per level and tested against the
//!   node's items;
//! - neither: `X` and `Y` lie in the two children of their lowest common ancestor
//!   `A`, which runs `cross(A⁻, A⁺)` once: the items of the negative subtree that
//!   reach the positive child's region are gathered, then carried down the
//!   positive subtree as an active set and tested only against the items there
//!   that reach back into the negative child's region. The two children's regions
//!   overlap only in the border zone `[m - h, m + h]`, so only items near it take
//!   part on either side.
//!
//! The search starts by copying the tree into a [`Flat`] snapshot in depth-first
//! order: the spheres of each node contiguously, and per node only what the walk
//! reads (children, the two split-axis bounds, the item range). The walks then
//! read memory almost linearly instead of chasing list links through the item
//! arena and scattered node slots; the snapshot costs one pass over the tree.

use super::node::{FixedStack, NIL};
use super::LooseKdTree;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
use std::ops::ControlFlow;

/// An item in the snapshot or carried down the tree: its sphere and arena slot.
#[derive(Clone, Copy, Default)]
struct Act {
    s: Sphere,
    idx: u32,
}

/// A node of the snapshot (indices are snapshot positions).
#[derive(Clone, Copy)]
struct FNode {
    /// `[negative, positive]` children, `NIL` if absent.
    child: [u32; 2],
    /// The node's own items: `Flat::s[own[0]..own[1]]`.
    own: [u32; 2],
    /// `pos_floor`: every sphere of the positive subtree has `c_a - r >=` this.
    floor: f32,
    /// `neg_ceil`: every sphere of the negative subtree has `c_a + r <=` this.
    ceil: f32,
    axis: u32,
}

/// The tree in depth-first order (root at 0, negative child first).
struct Flat {
    s: Vec<Act>,
    n: Vec<FNode>,
}

impl Flat {
    #[inline]
    fn own(&self, n: u32) -> &[Act] {
        let [a, b] = self.n[n as usize].own;
        &self.s[a as usize..b as usize]
    }
}

/// Appends to `buf` the entries of `buf[from..to]` that reach `bound` on `axis`
/// from below (`c_a + r >= bound`, `upper`) or stay under it (`c_a - r <= bound`).
/// Branch-free: every entry is written, the end advances only for kept ones.
#[inline]
fn refilter(buf: &mut Vec<Act>, from: usize, to: usize, axis: usize, bound: f32, upper: bool) {
    let base = buf.len();
    buf.resize(base + (to - from), Act::default());
    let mut k = base;
    for i in from..to {
        let x = buf[i];
        let keep = if upper {
            x.s.center[axis] + x.s.radius >= bound
        } else {
            x.s.center[axis] - x.s.radius <= bound
        };
        buf[k] = x;
        k += keep as usize;
    }
    buf.truncate(k);
}

impl<T> LooseKdTree<T> {
    pub(super) fn pairs_impl(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let mut fl = Flat {
            s: Vec::with_capacity(self.items.len()),
            n: Vec::with_capacity(self.nodes.len()),
        };
        self.flatten(self.root, &mut fl);
        let mut buf: Vec<Act> = Vec::with_capacity(1024);
        self.self_pairs(&fl, 0, 0, &mut buf, &mut f)
    }

    /// Appends the subtree of `n` to the snapshot; returns its position.
    fn flatten(&self, n: u32, fl: &mut Flat) -> u32 {
        let node = &self.nodes[n];
        let start = fl.s.len() as u32;
        let mut it = node.first;
        while it != NIL {
            let item = self.items.get_by_index(it).expect("listed item").1;
            fl.s.push(Act {
                s: item.sphere,
                idx: it,
            });
            it = item.next;
        }
        let at = fl.n.len();
        fl.n.push(FNode {
            child: [NIL; 2],
            own: [start, fl.s.len() as u32],
            floor: self.pos_floor(node),
            ceil: self.neg_ceil(node),
            axis: node.axis as u32,
        });
        for side in 0..2 {
            if node.child[side] != NIL {
                let c = self.flatten(node.child[side], fl);
                fl.n[at].child[side] = c;
            }
        }
        at as u32
    }

    #[inline]
    fn report(
        &self,
        a: u32,
        b: u32,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (ha, ia) = self.items.get_by_index(a).expect("live item");
        let (hb, ib) = self.items.get_by_index(b).expect("live item");
        f(ha, &ia.value, hb, &ib.value)
    }

    /// Appends to `buf` the entries of `buf[from..to]` that can reach child `side`
    /// of `n`: one comparison on the split axis.
    #[inline]
    fn filter_into_child(
        fl: &Flat,
        n: u32,
        side: usize,
        from: usize,
        to: usize,
        buf: &mut Vec<Act>,
    ) {
        let node = &fl.n[n as usize];
        let a = node.axis as usize;
        if side == 1 {
            refilter(buf, from, to, a, node.floor, true);
        } else {
            refilter(buf, from, to, a, node.ceil, false);
        }
    }

    /// All pairs within the subtree of `n`, plus its items against the active set
    /// `buf[active..]` (ancestors' items that reach `n`'s region).
    fn self_pairs(
        &self,
        fl: &Flat,
        n: u32,
        active: usize,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = fl.n[n as usize];
        let own = fl.own(n);
        // Each item against the active set and the node's earlier items.
        for (i, y) in own.iter().enumerate() {
            for x in buf[active..].iter().chain(&own[..i]) {
                if overlap::sphere_sphere(&x.s, &y.s) {
                    self.report(x.idx, y.idx, f)?;
                }
            }
        }
        buf.extend_from_slice(own);
        let end = buf.len();
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            Self::filter_into_child(fl, n, side, active, end, buf);
            self.self_pairs(fl, c, end, buf, f)?;
            buf.truncate(end);
        }
        if node.child[0] != NIL && node.child[1] != NIL {
            self.cross(fl, n, buf, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Every pair between the subtrees of the two children of `a`.
    fn cross(
        &self,
        fl: &Flat,
        a: u32,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let base = buf.len();
        let parent = fl.n[a as usize];
        let axis = parent.axis as usize;
        self.gather(fl, parent.child[0], axis, parent.floor, buf);
        if buf.len() > base {
            self.walk(fl, parent.child[1], base, (axis, parent.ceil), buf, f)?;
        }
        buf.truncate(base);
        ControlFlow::Continue(())
    }

    /// Appends the items of `p`'s subtree whose extent on `axis` reaches `floor`.
    ///
    /// Why this is the whole test: every sphere of the positive sibling has
    /// `min_axis >= floor` (split rule, with slack), and on the other axes both
    /// siblings share the bounds of their parent, so an item of `p` ending before
    /// `floor` overlaps none of them. Inside `p`, only a negative child of a split
    /// on the same axis lowers the upper bound of its spheres (to `m + h`), so it
    /// is skipped when that bound is below `floor`; every other child may reach.
    fn gather(&self, fl: &Flat, p: u32, axis: usize, floor: f32, buf: &mut Vec<Act>) {
        let mut stack = FixedStack::<u32>::new();
        stack.push(p);
        while let Some(n) = stack.pop() {
            let node = &fl.n[n as usize];
            let own = fl.own(n);
            let base = buf.len();
            buf.resize(base + own.len(), Act::default());
            let mut k = base;
            for x in own {
                buf[k] = *x;
                k += (x.s.center[axis] + x.s.radius >= floor) as usize;
            }
            buf.truncate(k);
            let [neg, pos] = node.child;
            if neg != NIL && (node.axis as usize != axis || node.ceil >= floor) {
                stack.push(neg);
            }
            if pos != NIL {
                stack.push(pos);
            }
        }
    }

    /// Tests the items of `n`'s subtree that reach back across the border
    /// (`c_a - r <= ceil`, the same argument as in `gather`, mirrored) against the
    /// active set `buf[active..]`.
    fn walk(
        &self,
        fl: &Flat,
        n: u32,
        active: usize,
        border: (usize, f32),
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = fl.n[n as usize];
        let end = buf.len();
        let (axis, ceil) = border;
        for y in fl.own(n) {
            if y.s.center[axis] - y.s.radius > ceil {
                continue;
            }
            for x in &buf[active..end] {
                if overlap::sphere_sphere(&x.s, &y.s) {
                    self.report(x.idx, y.idx, f)?;
                }
            }
        }
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            Self::filter_into_child(fl, n, side, active, end, buf);
            if buf.len() > end {
                self.walk(fl, c, end, border, buf, f)?;
            }
            buf.truncate(end);
        }
        ControlFlow::Continue(())
    }
}
