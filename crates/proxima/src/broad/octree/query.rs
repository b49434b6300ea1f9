//! Queries: one top-down traversal for every [`Selection`], with loose boxes
//! ([sources: octree-cull]: classify cells against the frustum as outside / inside /
//! intersecting).

use super::node::{Item, NONE};
use super::LinearOctree;
use crate::broad::filter::Admit;
use crate::broad::Selection;
use crate::geom::{Frustum, Relation, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// Child `k`'s integer coordinates from its parent's.
#[inline]
pub(super) fn child_coords(c: [u32; 3], k: usize) -> [u32; 3] {
    [
        c[0] * 2 + (k & 1) as u32,
        c[1] * 2 + ((k >> 1) & 1) as u32,
        c[2] * 2 + ((k >> 2) & 1) as u32,
    ]
}

impl<T> LinearOctree<T> {
    /// Traverses the tree for `q`. A node's loose box is classified once: `Outside`
    /// prunes the subtree, `Inside` reports it whole without testing its spheres,
    /// `Intersecting` goes on (a leaf tests each sphere with `q.selects`; where
    /// the query has [`Selection::rejects4`], four at a time through it first,
    /// and the spheres it leaves in with `q.selects_after_rejects4`). The plane
    /// mask returned for a node is what its children are tested against, so a
    /// frustum plane that contains a parent is never tested again below it.
    /// Recursion depth ≤ 22; no allocation.
    ///
    /// `admit` is `()` for an unfiltered walk (compiled away) or the query's
    /// filter: then subtrees whose filter bits cannot interact with it are
    /// skipped, and objects are reported only if their filter interacts.
    pub(super) fn visit_tree<Q, A, F>(&self, q: &Q, admit: A, f: &mut F) -> ControlFlow<()>
    where
        Q: Selection + ?Sized,
        A: Admit,
        F: FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    {
        if self.objects.is_empty() {
            return ControlFlow::Continue(());
        }
        self.visit_node(self.root, [0; 3], 0, Frustum::ALL_PLANES, q, admit, f)
    }

    #[allow(clippy::too_many_arguments)]
    fn visit_node<Q, A, F>(
        &self,
        i: u32,
        c: [u32; 3],
        d: u32,
        mask: u8,
        q: &Q,
        admit: A,
        f: &mut F,
    ) -> ControlFlow<()>
    where
        Q: Selection + ?Sized,
        A: Admit,
        F: FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    {
        let n = &self.nodes[i];
        if !admit.node(n.groups, n.masks) {
            return ControlFlow::Continue(());
        }
        let (rel, mask) = q.classify_box(&self.loose_of(c, d, n.max_extent), mask);
        match rel {
            Relation::Outside => ControlFlow::Continue(()),
            Relation::Inside => self.report_all(i, admit, f),
            Relation::Intersecting => {
                if n.leaf {
                    let mut report = |it: &Item| {
                        let o = self.obj(it.handle);
                        if admit.object(o.filter) {
                            f(it.handle, &it.sphere, &o.value)?;
                        }
                        ControlFlow::Continue(())
                    };
                    // Four at a time through the query's SIMD pre-test where
                    // it has one (sweeps), as the first-hit search does; the
                    // spheres it leaves in take the exact test only, in the
                    // leaf's order.
                    let mut quads =
                        n.items
                            .chunks_exact(if Q::HAS_REJECTS4 { 4 } else { usize::MAX });
                    for quad in &mut quads {
                        let mut live = !q.rejects4([0, 1, 2, 3].map(|j| &quad[j].sphere)) & 0xF;
                        while live != 0 {
                            let it = &quad[live.trailing_zeros() as usize];
                            if q.selects_after_rejects4(&it.sphere) {
                                report(it)?;
                            }
                            live &= live - 1;
                        }
                    }
                    for it in quads.remainder() {
                        if q.selects(&it.sphere) {
                            report(it)?;
                        }
                    }
                } else {
                    // The children the query reaches, listed first and
                    // their nodes prefetched, so that their cache misses
                    // overlap; each next child's first items are prefetched
                    // while the one before is searched. W4 (`w4 --only
                    // LinearOctree`, four alternations): sphere and box
                    // queries ~5% faster in three; W8 all hits unchanged.
                    let mut reached = [(0u32, [0u32; 3]); 8];
                    let mut m = 0;
                    for (k, &ch) in n.children.iter().enumerate() {
                        if ch == NONE {
                            continue;
                        }
                        // Pre-test with this node's extent (never below a child's):
                        // a box containing the child's loose box, so `Outside` here
                        // is `Outside` there, decided without loading the child —
                        // on a large tree each node load is a cache miss.
                        let cc = child_coords(c, k);
                        let outer = self.loose_of(cc, d + 1, n.max_extent);
                        if q.classify_box(&outer, mask).0 == Relation::Outside {
                            continue;
                        }
                        self.prefetch_node(ch);
                        reached[m] = (ch, cc);
                        m += 1;
                    }
                    for (j, &(ch, cc)) in reached[..m].iter().enumerate() {
                        if let Some(&(next, _)) = reached[..m].get(j + 1) {
                            self.nodes[next].prefetch_items(1);
                        }
                        self.visit_node(ch, cc, d + 1, mask, q, admit, f)?;
                    }
                }
                ControlFlow::Continue(())
            }
        }
    }

    /// Reports every object below node `i` without testing (its loose box is
    /// inside the query).
    fn report_all<A, F>(&self, i: u32, admit: A, f: &mut F) -> ControlFlow<()>
    where
        A: Admit,
        F: FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    {
        let n = &self.nodes[i];
        if !admit.node(n.groups, n.masks) {
            return ControlFlow::Continue(());
        }
        if n.leaf {
            for it in &n.items {
                let o = self.obj(it.handle);
                if admit.object(o.filter) {
                    f(it.handle, &it.sphere, &o.value)?;
                }
            }
        } else {
            for &ch in &n.children {
                if ch != NONE {
                    self.report_all(ch, admit, f)?;
                }
            }
        }
        ControlFlow::Continue(())
    }
}
