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
//! The walks read each node's objects where they are stored, contiguously in the
//! node (`Node::slots`); the carried sets are copies of the spheres with the
//! object's node and position, so the inner loops scan flat arrays and only a
//! reported pair goes back to the node for its handle and payload.

use super::node::{FixedStack, Slot, NIL};
use super::LooseKdTree;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
use std::ops::ControlFlow;

/// An object carried down the tree: its sphere, node and position in the node.
#[derive(Clone, Copy, Default)]
struct Act {
    s: Sphere,
    node: u32,
    pos: u32,
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
        let mut buf: Vec<Act> = Vec::with_capacity(1024);
        self.self_pairs(self.root, 0, &mut buf, &mut f)
    }

    /// Reports carried object `x` with stored object `y`.
    #[inline]
    fn report(
        &self,
        x: &Act,
        y: &Slot<T>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let xs = &self.nodes[x.node].slots[x.pos as usize];
        f(xs.handle, &xs.value, y.handle, &y.value)
    }

    /// Appends to `buf` the entries of `buf[from..to]` that can reach child `side`
    /// of `n`: one comparison on the split axis.
    #[inline]
    fn filter_into_child(&self, n: u32, side: usize, from: usize, to: usize, buf: &mut Vec<Act>) {
        let node = &self.nodes[n];
        let a = node.axis as usize;
        if side == 1 {
            refilter(buf, from, to, a, self.pos_floor(node), true);
        } else {
            refilter(buf, from, to, a, self.neg_ceil(node), false);
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
        let own = &node.slots[..];
        // Each object against the active set and the node's earlier objects.
        for (i, y) in own.iter().enumerate() {
            for x in &buf[active..] {
                if overlap::sphere_sphere(&x.s, &y.sphere) {
                    self.report(x, y, f)?;
                }
            }
            for x in &own[..i] {
                if overlap::sphere_sphere(&x.sphere, &y.sphere) {
                    f(x.handle, &x.value, y.handle, &y.value)?;
                }
            }
        }
        buf.extend(own.iter().enumerate().map(|(pos, x)| Act {
            s: x.sphere,
            node: n,
            pos: pos as u32,
        }));
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
            self.cross(n, buf, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Every pair between the subtrees of the two children of `a`.
    fn cross(
        &self,
        a: u32,
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let base = buf.len();
        let parent = &self.nodes[a];
        let axis = parent.axis as usize;
        self.gather(parent.child[0], axis, self.pos_floor(parent), buf);
        if buf.len() > base {
            let border = (axis, self.neg_ceil(parent));
            self.walk(parent.child[1], base, border, buf, f)?;
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
            let base = buf.len();
            buf.resize(base + node.slots.len(), Act::default());
            let mut k = base;
            for (pos, x) in node.slots.iter().enumerate() {
                buf[k] = Act {
                    s: x.sphere,
                    node: n,
                    pos: pos as u32,
                };
                k += (x.sphere.center[axis] + x.sphere.radius >= floor) as usize;
            }
            buf.truncate(k);
            let [neg, pos] = node.child;
            if neg != NIL && (node.axis as usize != axis || self.neg_ceil(node) >= floor) {
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
        n: u32,
        active: usize,
        border: (usize, f32),
        buf: &mut Vec<Act>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        let end = buf.len();
        let (axis, ceil) = border;
        for y in &node.slots {
            if y.sphere.center[axis] - y.sphere.radius > ceil {
                continue;
            }
            for x in &buf[active..end] {
                if overlap::sphere_sphere(&x.s, &y.sphere) {
                    self.report(x, y, f)?;
                }
            }
        }
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            self.filter_into_child(n, side, active, end, buf);
            if buf.len() > end {
                self.walk(c, end, border, buf, f)?;
            }
            buf.truncate(end);
        }
        ControlFlow::Continue(())
    }
}
