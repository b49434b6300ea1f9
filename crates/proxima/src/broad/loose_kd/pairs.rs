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
//!   positive subtree as an active set. The two children's regions overlap only in
//!   the border zone `[m - h, m + h]`, so only items near it take part.
//!
//! The active sets live in one scratch `Vec` used as a stack of segments (one
//! allocation per call, none per node or item).

use super::node::{FixedStack, NIL};
use super::LooseKdTree;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
use std::ops::ControlFlow;

/// An item carried down the tree: its sphere and arena slot.
#[derive(Clone, Copy)]
struct Act {
    s: Sphere,
    idx: u32,
}

impl<T> LooseKdTree<T> {
    pub(super) fn pairs_impl(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let mut buf: Vec<Act> = Vec::with_capacity(1024);
        self.self_pairs(self.root, 0, &mut buf, &mut f)
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
    /// of `n`: one comparison on the split axis (see `pos_floor`/`neg_ceil`).
    #[inline]
    fn filter_into_child(&self, n: u32, side: usize, from: usize, to: usize, buf: &mut Vec<Act>) {
        let node = &self.nodes[n];
        let a = node.axis as usize;
        if side == 1 {
            let lo = self.pos_floor(node);
            for i in from..to {
                let x = buf[i];
                if x.s.center[a] + x.s.radius >= lo {
                    buf.push(x);
                }
            }
        } else {
            let hi = self.neg_ceil(node);
            for i in from..to {
                let x = buf[i];
                if x.s.center[a] - x.s.radius <= hi {
                    buf.push(x);
                }
            }
        }
    }

    /// All pairs within the subtree of `n`, plus its items against the active set
    /// `buf[active..]` (ancestors' items that reach `n`'s region).
    fn self_pairs(
        &self,
        n: u32,
        active: usize,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        // Each item against the active set and the node's earlier items, then it
        // joins the set (so each same-node pair is tested once).
        let mut it = node.first;
        while it != NIL {
            let item = self.items.get_by_index(it).expect("listed item").1;
            for x in &buf[active..] {
                if overlap::sphere_sphere(&x.s, &item.sphere) {
                    self.report(x.idx, it, f)?;
                }
            }
            buf.push(Act {
                s: item.sphere,
                idx: it,
            });
            it = item.next;
        }
        let end = buf.len();
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            self.filter_into_child(n, side, active, end, buf);
            self.self_pairs(c, end, buf, f)?;
            buf.truncate(end);
        }
        if node.child[0] != NIL && node.child[1] != NIL {
            self.cross(n, node.child[0], node.child[1], buf, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Every pair between the subtrees of `p` (negative child of `a`) and `q`
    /// (positive child of `a`).
    fn cross(
        &self,
        a: u32,
        p: u32,
        q: u32,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let base = buf.len();
        let parent = &self.nodes[a];
        self.gather(p, parent.axis as usize, self.pos_floor(parent), buf);
        if buf.len() > base {
            self.walk(q, base, buf, f)?;
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
    fn gather(&self, p: u32, axis: usize, floor: f32, buf: &mut Vec<Act>) {
        let mut stack = FixedStack::<u32>::new();
        stack.push(p);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            let mut it = node.first;
            while it != NIL {
                let item = self.items.get_by_index(it).expect("listed item").1;
                if item.sphere.center[axis] + item.sphere.radius >= floor {
                    buf.push(Act {
                        s: item.sphere,
                        idx: it,
                    });
                }
                it = item.next;
            }
            let [neg, pos] = node.child;
            if neg != NIL && (node.axis as usize != axis || self.neg_ceil(node) >= floor) {
                stack.push(neg);
            }
            if pos != NIL {
                stack.push(pos);
            }
        }
    }

    /// Tests the items of `n`'s subtree against the active set `buf[active..]`.
    fn walk(
        &self,
        n: u32,
        active: usize,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        let end = buf.len();
        let mut it = node.first;
        while it != NIL {
            let item = self.items.get_by_index(it).expect("listed item").1;
            for x in &buf[active..end] {
                if overlap::sphere_sphere(&x.s, &item.sphere) {
                    self.report(x.idx, it, f)?;
                }
            }
            it = item.next;
        }
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            self.filter_into_child(n, side, active, end, buf);
            if buf.len() > end {
                self.walk(c, end, buf, f)?;
            }
            buf.truncate(end);
        }
        ControlFlow::Continue(())
    }
}
