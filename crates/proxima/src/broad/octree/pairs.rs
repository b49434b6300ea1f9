//! All overlapping pairs by a simultaneous traversal of the tree with itself,
//! pruned by loose boxes (each pair of objects is met exactly once: in the leaf
//! they share, or in the one pair of sibling subtrees that separates them).
//!
//! Collision filters prune it too [sources: index-queries]: a subtree whose
//! filter bits (OR of the groups, OR of the masks) cannot interact with
//! themselves holds no pair, two subtrees whose bits cannot interact hold none
//! between them, and inert objects (group or mask zero) are skipped in the
//! leaves, through a bit set by arena slot built per search (only when some
//! object is inert, so the leaves need not store filters).

use super::node::{Node, NONE};
use super::query::child_coords;
use super::LinearOctree;
use crate::broad::Filter;
use crate::geom::{overlap, Aabb};
use crate::Handle;
use std::ops::ControlFlow;

/// A node with its cell coordinates, depth and loose box, as the pair traversal
/// carries it.
#[derive(Clone, Copy)]
struct Visit {
    i: u32,
    c: [u32; 3],
    d: u32,
    loose: Aabb,
}

/// The inert objects by arena slot, one bit each (empty when none is inert).
struct Inert(Vec<u64>);

impl Inert {
    /// Whether `h` may enter the pair search.
    #[inline]
    fn pairable(&self, h: Handle) -> bool {
        let i = h.index() as usize;
        self.0.is_empty() || self.0[i / 64] & (1 << (i % 64)) == 0
    }
}

impl<T> LinearOctree<T> {
    pub(super) fn pairs_tree<F>(&self, f: &mut F) -> ControlFlow<()>
    where
        F: FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    {
        if self.objects.len() < 2 {
            return ControlFlow::Continue(());
        }
        let mut inert = Inert(Vec::new());
        if self.inert.any() {
            inert.0 = vec![0; self.objects.slot_count().div_ceil(64)];
            for (h, o) in self.objects.iter() {
                let i = h.index() as usize;
                inert.0[i / 64] |= (o.filter.is_inert() as u64) << (i % 64);
            }
        }
        self.self_pairs(self.visit(self.root, [0; 3], 0), &inert, f)
    }

    /// The filter bits of node `i`'s subtree as one filter.
    #[inline]
    fn bits(&self, i: u32) -> Filter {
        let n = &self.nodes[i];
        Filter::new(n.groups, n.masks)
    }

    #[inline]
    fn visit(&self, i: u32, c: [u32; 3], d: u32) -> Visit {
        Visit {
            i,
            c,
            d,
            loose: self.loose_of(c, d, self.nodes[i].max_extent),
        }
    }

    #[inline]
    fn child_visits(&self, v: &Visit, out: &mut [Visit; 8]) -> usize {
        let mut n = 0;
        for (k, &ch) in self.nodes[v.i].children.iter().enumerate() {
            if ch != NONE {
                out[n] = self.visit(ch, child_coords(v.c, k), v.d + 1);
                n += 1;
            }
        }
        n
    }

    /// Pairs with both objects below `v`.
    fn self_pairs<F>(&self, v: Visit, inert: &Inert, f: &mut F) -> ControlFlow<()>
    where
        F: FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    {
        let n = &self.nodes[v.i];
        if n.count < 2 || n.groups & n.masks == 0 {
            return ControlFlow::Continue(());
        }
        if n.leaf {
            let items = &n.items;
            for (a, ia) in items.iter().enumerate() {
                if !inert.pairable(ia.handle) {
                    continue;
                }
                for ib in &items[a + 1..] {
                    if overlap::sphere_sphere(&ia.sphere, &ib.sphere) && inert.pairable(ib.handle) {
                        self.report(ia.handle, ib.handle, f)?;
                    }
                }
            }
            return ControlFlow::Continue(());
        }
        let mut kids = [v; 8];
        let m = self.child_visits(&v, &mut kids);
        for a in 0..m {
            self.self_pairs(kids[a], inert, f)?;
            for b in a + 1..m {
                self.cross_pairs(kids[a], kids[b], inert, f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Pairs with one object below `a` and one below `b` (disjoint subtrees).
    fn cross_pairs<F>(&self, a: Visit, b: Visit, inert: &Inert, f: &mut F) -> ControlFlow<()>
    where
        F: FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    {
        if !overlap::aabb_aabb(&a.loose, &b.loose) {
            return ControlFlow::Continue(());
        }
        let bb = self.bits(b.i);
        if !self.bits(a.i).may_interact(bb.group, bb.mask) {
            return ControlFlow::Continue(());
        }
        let (na, nb): (&Node, &Node) = (&self.nodes[a.i], &self.nodes[b.i]);
        match (na.leaf, nb.leaf) {
            (true, true) => {
                // Only spheres reaching the other leaf's loose box can overlap
                // anything there: filter `b` once (into a stack buffer; a huge
                // leaf at max depth falls back to no filter), then each of `a`.
                // Inert objects are left out on both sides.
                let mut buf = [0u16; 64];
                let mut m = 0;
                let filtered = nb.items.len() <= buf.len();
                if filtered {
                    for (k, ib) in nb.items.iter().enumerate() {
                        if overlap::sphere_aabb(&ib.sphere, &a.loose) && inert.pairable(ib.handle) {
                            buf[m] = k as u16;
                            m += 1;
                        }
                    }
                    if m == 0 {
                        return ControlFlow::Continue(());
                    }
                }
                for ia in &na.items {
                    if !overlap::sphere_aabb(&ia.sphere, &b.loose) || !inert.pairable(ia.handle) {
                        continue;
                    }
                    if filtered {
                        for &k in &buf[..m] {
                            let ib = &nb.items[k as usize];
                            if overlap::sphere_sphere(&ia.sphere, &ib.sphere) {
                                self.report(ia.handle, ib.handle, f)?;
                            }
                        }
                    } else {
                        for ib in &nb.items {
                            if overlap::sphere_sphere(&ia.sphere, &ib.sphere)
                                && inert.pairable(ib.handle)
                            {
                                self.report(ia.handle, ib.handle, f)?;
                            }
                        }
                    }
                }
                ControlFlow::Continue(())
            }
            // Descend the inner node; of two inner nodes, the larger (shallower) one.
            (false, true) => self.cross_children(a, b, inert, f),
            (true, false) => self.cross_children(b, a, inert, f),
            (false, false) => {
                if a.d <= b.d {
                    self.cross_children(a, b, inert, f)
                } else {
                    self.cross_children(b, a, inert, f)
                }
            }
        }
    }

    /// Crosses each child of inner node `split` with `other`.
    fn cross_children<F>(
        &self,
        split: Visit,
        other: Visit,
        inert: &Inert,
        f: &mut F,
    ) -> ControlFlow<()>
    where
        F: FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    {
        let mut kids = [split; 8];
        let m = self.child_visits(&split, &mut kids);
        for kid in &kids[..m] {
            if overlap::aabb_aabb(&kid.loose, &other.loose) {
                self.cross_pairs(*kid, other, inert, f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Reports an overlapping pair if the objects' filters interact (read
    /// from the records the payloads come from).
    #[inline]
    fn report<F>(&self, a: Handle, b: Handle, f: &mut F) -> ControlFlow<()>
    where
        F: FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    {
        let (oa, ob) = (self.obj(a), self.obj(b));
        if oa.filter.interacts(ob.filter) {
            f(a, &oa.value, b, &ob.value)
        } else {
            ControlFlow::Continue(())
        }
    }
}
