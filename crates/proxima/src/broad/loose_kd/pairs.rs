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
//! reported pair goes back to the node for its handle and payload. A node whose
//! own and carried objects are many (typically a node high in the tree holding
//! big spheres spread over its box) sweeps them on its split axis instead of
//! testing all pairs; the carried set is narrowed at each level except before a
//! small leaf, where the copy would cost more than the tests it saves.

use super::node::{FixedStack, Slot, NIL};
use super::LooseKdTree;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
use std::ops::ControlFlow;
use std::sync::{Mutex, TryLockError};

/// An object carried down the tree: its sphere, node and position in the node.
#[derive(Clone, Copy, Default)]
struct Act {
    s: Sphere,
    node: u32,
    pos: u32,
}

/// Below this many objects in a node (own plus carried), the node's tests are
/// all-pairs; from it on they use a sweep on the split axis.
const SWEEP_MIN: usize = 48;

/// Leaves with fewer objects are tested against their parent's carried set
/// without narrowing it first (see `worth_filtering`).
const LEAF_FILTER_MIN: usize = 8;

/// Scratch of the sweep: the spheres (carried first, then own) and their sort
/// keys (lower end on the sweep axis, index into `sp`).
#[derive(Default)]
struct Sweep {
    sp: Vec<Sphere>,
    keys: Vec<(f32, u32)>,
}

/// The pair search's buffers, kept in the tree between calls so that a
/// steady-state `for_each_pair` does not allocate. Behind a mutex because the
/// search takes `&self`; a call that finds it taken (a concurrent or nested
/// search) uses fresh buffers instead. Cloning gives empty buffers.
#[derive(Default)]
pub(super) struct PairScratch(Mutex<Buffers>);

#[derive(Default)]
struct Buffers {
    buf: Vec<Act>,
    sw: Sweep,
}

impl Clone for PairScratch {
    fn clone(&self) -> Self {
        PairScratch::default()
    }
}

impl std::fmt::Debug for PairScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PairScratch")
    }
}

impl PairScratch {
    /// Heap bytes held by the buffers (0 if they are in use).
    pub(super) fn heap_bytes(&self) -> usize {
        match self.0.try_lock() {
            Ok(b) => {
                b.buf.capacity() * std::mem::size_of::<Act>()
                    + b.sw.sp.capacity() * std::mem::size_of::<Sphere>()
                    + b.sw.keys.capacity() * std::mem::size_of::<(f32, u32)>()
            }
            Err(_) => 0,
        }
    }
}

/// Appends to `buf` the entries of `buf[from..to]` that reach `bound` on `axis`
/// from below (`c_a + r >= bound`, `upper`) or stay under it (`c_a - r <= bound`).
#[inline]
fn refilter(buf: &mut Vec<Act>, from: usize, to: usize, axis: usize, bound: f32, upper: bool) {
    match (axis, upper) {
        (0, true) => refilter_on::<0, true>(buf, from, to, bound),
        (1, true) => refilter_on::<1, true>(buf, from, to, bound),
        (_, true) => refilter_on::<2, true>(buf, from, to, bound),
        (0, false) => refilter_on::<0, false>(buf, from, to, bound),
        (1, false) => refilter_on::<1, false>(buf, from, to, bound),
        (_, false) => refilter_on::<2, false>(buf, from, to, bound),
    }
}

/// [`refilter`] for one axis and direction (compiled separately, so the
/// coordinate is a field access, not an index). Branch-free: the range is copied
/// to the end in one block, then compacted in place (every entry is written, the
/// end advances only for kept ones).
fn refilter_on<const A: usize, const UPPER: bool>(
    buf: &mut Vec<Act>,
    from: usize,
    to: usize,
    bound: f32,
) {
    let base = buf.len();
    buf.extend_from_within(from..to);
    let tail = &mut buf[base..];
    let mut k = 0;
    for i in 0..tail.len() {
        let x = tail[i];
        let c = match A {
            0 => x.s.center.x,
            1 => x.s.center.y,
            _ => x.s.center.z,
        };
        let keep = if UPPER {
            c + x.s.radius >= bound
        } else {
            c - x.s.radius <= bound
        };
        tail[k] = x;
        k += keep as usize;
    }
    buf.truncate(base + k);
}

impl<T> LooseKdTree<T> {
    pub(super) fn pairs_impl(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let mut fresh = Buffers::default();
        let mut guard = match self.scratch.0.try_lock() {
            Ok(g) => Some(g),
            // A panic in an earlier callback left the buffers in some state; they
            // are cleared below anyway.
            Err(TryLockError::Poisoned(p)) => Some(p.into_inner()),
            Err(TryLockError::WouldBlock) => None,
        };
        let b = guard.as_deref_mut().unwrap_or(&mut fresh);
        b.buf.clear();
        self.self_pairs(self.root, 0, &mut b.buf, &mut b.sw, &mut f)
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

    /// Whether to narrow the carried set before visiting node `c`. The filter only
    /// saves work (a superset of the objects that can reach `c` gives the same
    /// pairs): it costs a copy per carried object, and for a leaf with few objects
    /// that is more than the sphere tests it saves, so such a leaf is tested
    /// against its parent's set as it is.
    #[inline]
    fn worth_filtering(&self, c: u32) -> bool {
        let node = &self.nodes[c];
        node.child != [NIL, NIL] || node.slots.len() >= LEAF_FILTER_MIN
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
        sw: &mut Sweep,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        let own = &node.slots[..];
        if own.len() > 1 && buf.len() - active + own.len() >= SWEEP_MIN {
            self.sweep(&buf[active..], own, node.axis as usize, sw, f)?;
        } else {
            self.brute(&buf[active..], own, f)?;
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
            if self.worth_filtering(c) {
                self.filter_into_child(n, side, active, end, buf);
                self.self_pairs(c, end, buf, sw, f)?;
            } else {
                self.self_pairs(c, active, buf, sw, f)?;
            }
            buf.truncate(end);
        }
        if node.child[0] != NIL && node.child[1] != NIL {
            self.cross(n, buf, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Every overlapping pair among `own` and between `act` and `own`, by testing
    /// all of them: for nodes with few objects.
    fn brute(
        &self,
        act: &[Act],
        own: &[Slot<T>],
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (i, y) in own.iter().enumerate() {
            for x in act {
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
        ControlFlow::Continue(())
    }

    /// The same pairs as [`Self::brute`], by a sweep on `axis`: the objects are
    /// sorted by their lower end on `axis`, and each is tested only against the
    /// following ones that start before it ends. The big objects of a node high
    /// in the tree are spread over its whole box, so most of them are far apart
    /// and the sweep skips them; sorting costs O(k log k) for k objects.
    ///
    /// Why no pair is missed: overlapping spheres (closed, as `overlap`
    /// computes it in `f32`) have centres at most `r_a + r_b` apart on every axis,
    /// so their intervals on `axis` meet; `eps` absorbs the rounding of the
    /// interval ends.
    fn sweep(
        &self,
        act: &[Act],
        own: &[Slot<T>],
        axis: usize,
        sw: &mut Sweep,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let na = act.len() as u32;
        sw.sp.clear();
        sw.sp.extend(act.iter().map(|x| x.s));
        sw.sp.extend(own.iter().map(|x| x.sphere));
        sw.keys.clear();
        let sp = &sw.sp;
        sw.keys.extend(
            sp.iter()
                .enumerate()
                .map(|(i, s)| (s.center[axis] - s.radius, i as u32)),
        );
        sw.keys.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let slot = |i: u32| -> &Slot<T> {
            if i < na {
                let x = &act[i as usize];
                &self.nodes[x.node].slots[x.pos as usize]
            } else {
                &own[(i - na) as usize]
            }
        };
        let keys = &sw.keys[..];
        for (k, &(_, i)) in keys.iter().enumerate() {
            let si = &sp[i as usize];
            let hi = si.center[axis] + si.radius + self.eps;
            for &(lo, j) in &keys[k + 1..] {
                if lo > hi {
                    break;
                }
                // Two carried objects were paired higher up.
                if (i < na && j < na) || !overlap::sphere_sphere(si, &sp[j as usize]) {
                    continue;
                }
                let (a, b) = (slot(i), slot(j));
                f(a.handle, &a.value, b.handle, &b.value)?;
            }
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
        let same_axis = node.axis as usize == axis;
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            if same_axis {
                // A split on the border's own axis: every carried item ends below
                // the border's ceiling, so narrowing it to the negative child drops
                // nothing, and the positive child's items all start above its floor,
                // so if that floor is past the ceiling none reaches back (the
                // argument of `gather`, mirrored). Either way no copy is needed.
                if side == 0 {
                    self.walk(c, active, border, buf, f)?;
                    continue;
                }
                if self.pos_floor(node) > ceil {
                    continue;
                }
            }
            if self.worth_filtering(c) {
                self.filter_into_child(n, side, active, end, buf);
                if buf.len() > end {
                    self.walk(c, end, border, buf, f)?;
                }
            } else {
                self.walk(c, active, border, buf, f)?;
            }
            buf.truncate(end);
        }
        ControlFlow::Continue(())
    }
}
