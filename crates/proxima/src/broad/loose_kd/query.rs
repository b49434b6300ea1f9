//! Queries ([sources: kd-query]: `TestIntersection`, generalized to any [`Selection`]) and the
//! front-to-back first-hit ray search.

use super::node::{FixedStack, Node, NIL};
use super::store::CHUNK;
use super::LooseKdTree;
use crate::broad::filter::Admit;
use crate::broad::walk::{Cast, Contact};
use crate::broad::{Filter, RayHit, Selection};
use crate::geom::overlap::EntryBound;
use crate::geom::{Aabb, Frustum, Relation, Sphere};
use crate::Handle;
use glam::Vec3;
use std::ops::{ControlFlow, Range};

/// A pending node: index, frustum plane mask, whether its whole region is known
/// to be selected (then its subtree is reported without tests), and its box `B`
/// (derived from the parent's, equal to the node's own `bbox`, which `validate`
/// checks): carrying it means a walk reads only a node's first cache line.
#[derive(Clone, Copy)]
struct Pending {
    node: u32,
    mask: u8,
    inside: bool,
    bbox: Aabb,
}

/// Filler of the fixed stack's unused entries.
impl Default for Pending {
    fn default() -> Self {
        Pending {
            node: NIL,
            mask: 0,
            inside: false,
            bbox: Aabb::EMPTY,
        }
    }
}

impl<T> LooseKdTree<T> {
    /// Depth-first walk reporting every item `query` selects.
    ///
    /// Per child, two conservative filters, both decided from the *parent* (already
    /// in cache), so a pruned child's node is never loaded — on a large tree each
    /// node load is a cache miss, and it is what the profile of W4's queries shows:
    /// 1. the source's one comparison [sources: kd-query] on the split axis against `query.bounds()`
    ///    (descend positive only if `q_max_a >= m - h`, negative only if
    ///    `q_min_a <= m + h`, each with slack): every sphere of the positive subtree
    ///    has `c_a - r > m - h`, so a query box ending before `m - h` selects none
    ///    of them (bounds are a box every selected sphere intersects);
    /// 2. `query.classify_box` on the child's region (its box is the parent's with
    ///    one face moved, [`Node::child_bounds`](super::node::Node::child_bounds),
    ///    an invariant `validate` checks; the region contains every sphere of the
    ///    subtree), carrying the frustum plane mask down: `Outside` skips the
    ///    subtree, `Inside` reports it whole without tests (valid because the
    ///    selection promises `Inside` only when every sphere inside the box is
    ///    selected). Queries without bounds (frustums) rely on this one alone.
    ///
    /// `admit` is `()` for an unfiltered walk (compiled away) or the query's
    /// [`Filter`]: then a node whose filter bits cannot interact with it is
    /// skipped with its subtree, and each object is reported only if its own
    /// filter interacts.
    pub(super) fn visit_impl<Q: Selection + ?Sized, A: Admit>(
        &self,
        query: &Q,
        admit: A,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let bounds = query.bounds();
        let mut stack = FixedStack::<Pending>::new();
        let push = |node: u32,
                    bbox: Aabb,
                    (rel, mask): (Relation, u8),
                    stack: &mut FixedStack<Pending>|
         -> bool {
            let inside = match rel {
                Relation::Outside => return false,
                Relation::Inside => true,
                Relation::Intersecting => false,
            };
            stack.push(Pending {
                node,
                mask: if inside { 0 } else { mask },
                inside,
                bbox,
            });
            true
        };
        let root = &self.nodes[self.root];
        let _ = push(
            self.root,
            root.bbox,
            query.classify_box(&self.region(root), Frustum::ALL_PLANES),
            &mut stack,
        );
        while let Some(p) = stack.pop() {
            let node = &self.nodes[p.node];
            if !admit.node(node.groups, node.masks) {
                continue;
            }
            if p.inside {
                self.report_all(node.range(), admit, &mut f)?;
                for c in node.child {
                    if c != NIL {
                        stack.push(Pending {
                            node: c,
                            inside: true,
                            ..p
                        });
                    }
                }
                continue;
            }
            let a = node.axis as usize;
            for side in 0..2 {
                let c = node.child[side];
                if c == NIL {
                    continue;
                }
                if let Some(b) = &bounds {
                    let reach = if side == 1 {
                        b.max[a] >= self.pos_floor(node)
                    } else {
                        b.min[a] <= self.neg_ceil(node)
                    };
                    if !reach {
                        continue;
                    }
                }
                let cb = child_box(node, &p.bbox, side);
                let region = self.region_of_box(&cb);
                if push(c, cb, query.classify_box(&region, p.mask), &mut stack) {
                    // Start loading the child now, so that the load overlaps the
                    // scan of this node's objects instead of stalling the next pop.
                    std::hint::black_box(self.nodes[c].start);
                }
            }
            // The node's own objects after its children are classified: the
            // children's tests need only this node's fields, and the scan's
            // first load (the node's range of the object array) is the miss.
            self.scan(node.range(), node.loose, query, p.mask, admit, &mut f)?;
        }
        ControlFlow::Continue(())
    }

    /// Reports every object at positions `range`, without tests.
    #[inline(always)]
    fn report_all<A: Admit>(
        &self,
        range: Range<usize>,
        admit: A,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (q, s) in range.clone().zip(&self.store.sphere[range]) {
            self.report_admitted(q, s, admit, f)?;
        }
        ControlFlow::Continue(())
    }

    /// Reports the object at position `q` if `admit` admits its filter.
    #[inline(always)]
    fn report_admitted<A: Admit>(
        &self,
        q: usize,
        s: &Sphere,
        admit: A,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (h, of, v) = self.store.full(q);
        if admit.object(of) {
            f(h, s, v)
        } else {
            ControlFlow::Continue(())
        }
    }

    /// Reports the objects at positions `range` (one node's) that `query`
    /// selects, chunk by chunk ([`Self::chunks`]): a chunk whose bound the
    /// query classifies `Outside` is skipped unread, one it classifies
    /// `Inside` is reported without tests, the others (and the parts without
    /// a bound) are tested sphere by sphere. `mask` is the node's frustum
    /// plane mask: the masked-off planes contain the node's region, hence its
    /// objects, even where a chunk's bound also covers a neighbouring range.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn scan<Q: Selection + ?Sized, A: Admit>(
        &self,
        range: Range<usize>,
        loose: bool,
        query: &Q,
        mask: u8,
        admit: A,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (part, bound) in self.chunks(range, loose) {
            match bound.map(|b| query.classify_box(&b, mask).0) {
                Some(Relation::Outside) => {}
                Some(Relation::Inside) => self.report_all(part, admit, f)?,
                _ => self.test_each(part, query, admit, f)?,
            }
        }
        ControlFlow::Continue(())
    }

    /// The positions `range` (one node's) cut at chunk borders, each part
    /// with its chunk's bound (`store.rs`, plus the slack `eps`) when that
    /// bound is worth a box test: not for parts of up to two objects (a
    /// chunk test costs about as much as two sphere tests), nor for the
    /// objects of a `loose` node (its bounds may miss moved objects). The
    /// one chunk loop of the selection scan and the first-hit search.
    #[inline(always)]
    fn chunks(
        &self,
        range: Range<usize>,
        loose: bool,
    ) -> impl Iterator<Item = (Range<usize>, Option<Aabb>)> + '_ {
        let e = Vec3::splat(self.eps);
        let mut p = range.start;
        std::iter::from_fn(move || {
            if p >= range.end {
                return None;
            }
            let end = ((p / CHUNK + 1) * CHUNK).min(range.end);
            let bound = (!loose && end - p > 2).then(|| {
                let c = &self.store.chunk[p / CHUNK];
                Aabb::new(c.min - e, c.max + e)
            });
            let part = p..end;
            p = end;
            Some((part, bound))
        })
    }

    /// Reports the objects at positions `range` that `query` selects, testing
    /// each one.
    #[inline(always)]
    fn test_each<Q: Selection + ?Sized, A: Admit>(
        &self,
        range: Range<usize>,
        query: &Q,
        admit: A,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (q, s) in range.clone().zip(&self.store.sphere[range]) {
            if query.selects(s) {
                self.report_admitted(q, s, admit, f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Smallest contact `t` of a ray or sweep (ties: smallest handle) by a
    /// front-to-back walk: children are visited nearer entry first, and a
    /// subtree whose region (which contains all its spheres) the cast enters
    /// after the best contact so far is skipped; within a node, so is each
    /// chunk of eight objects whose bound (`store.rs`, plus `eps`) it enters
    /// after it. `t` values come from the same [`Cast::contact`] as in the
    /// default scan, so the answer is identical: a pruned box has an entry
    /// bound ([`EntryBound::enter`]) above the best `t`, and that bound is at
    /// most the `t` of every sphere inside (`contact` is clamped to the exact
    /// entry of the sphere's box, which is at least the bound). Children's
    /// boxes are derived from the parent's (as in [`Self::visit_impl`]), so a
    /// pruned child is never loaded. Objects whose filter does not interact
    /// with `filter` are skipped at the candidate, and subtrees whose filter
    /// bits cannot interact with it are skipped whole.
    ///
    /// Measured (W8, 100k sweeps, callgrind): with the exact box tests of
    /// `ray_aabb`/`sweep_aabb` and no chunk bounds, 57% of the instructions
    /// were box tests.
    pub(super) fn first_impl<C: Cast>(&self, cast: &C, filter: Option<Filter>) -> Option<RayHit> {
        if self.root == NIL {
            return None;
        }
        let root = &self.nodes[self.root];
        // The root's region holds every stored sphere's box: its magnitude
        // bounds theirs (`Cast::entry`).
        let region = self.region(root);
        let entry = cast.entry(region.min.abs().max(region.max.abs()).max_element());
        let test = cast.test();
        let mut best: Option<RayHit> = None;
        let beyond = |best: &Option<RayHit>, t: f32| best.is_some_and(|b| t > b.t);
        let mut stack = FixedStack::<CastPending>::new();
        if let Some(t) = entry.enter(&region) {
            stack.push(CastPending {
                node: self.root,
                t,
                bbox: root.bbox,
            });
        }
        while let Some(p) = stack.pop() {
            if beyond(&best, p.t) {
                continue;
            }
            let node = &self.nodes[p.node];
            if filter.is_some_and(|f| !f.may_interact(node.groups, node.masks)) {
                continue;
            }
            let mut next = [CastPending::default(); 2];
            for (side, e) in next.iter_mut().enumerate() {
                let c = node.child[side];
                if c == NIL {
                    continue;
                }
                let cb = child_box(node, &p.bbox, side);
                if let Some(t) = entry.enter(&self.region_of_box(&cb)) {
                    *e = CastPending {
                        node: c,
                        t,
                        bbox: cb,
                    };
                }
            }
            self.first_in_node(node.range(), node.loose, &test, &entry, filter, &mut best);
            // Push the farther first so the nearer is popped first.
            if next[0].t < next[1].t {
                next.swap(0, 1);
            }
            for e in next {
                if e.node != NIL && !beyond(&best, e.t) {
                    stack.push(e);
                }
            }
        }
        best
    }

    /// Offers the contacts of the objects at positions `range` (one node's)
    /// to `best`, chunk by chunk: a chunk whose bound the cast enters after
    /// `best` (or never) is skipped unread; parts without a bound
    /// ([`Self::chunks`]) are tested one by one.
    #[inline(always)]
    fn first_in_node<X: Contact>(
        &self,
        range: Range<usize>,
        loose: bool,
        test: &X,
        entry: &EntryBound,
        filter: Option<Filter>,
        best: &mut Option<RayHit>,
    ) {
        for (part, bound) in self.chunks(range, loose) {
            if let Some(b) = bound {
                match entry.enter(&b) {
                    Some(t) if !best.is_some_and(|b| t > b.t) => {}
                    _ => continue,
                }
            }
            for (q, s) in part.clone().zip(&self.store.sphere[part]) {
                if let Some(t) = test.contact(s).filter(|&t| !best.is_some_and(|b| t > b.t)) {
                    let (h, of, _) = self.store.full(q);
                    if filter.is_some_and(|f| !f.interacts(of)) {
                        continue;
                    }
                    RayHit::offer(best, t, h);
                }
            }
        }
    }
}

/// The box of `node`'s child on `side`, from the node's box `bbox` (carried
/// by the walk): one face moved to `m ∓ h` on the split axis (the boxes
/// `validate` checks), so a walk reads no child before it visits it.
#[inline(always)]
fn child_box(node: &Node, bbox: &Aabb, side: usize) -> Aabb {
    let (a, mut cb) = (node.axis as usize, *bbox);
    if side == 1 {
        cb.min[a] = node.m - node.h;
    } else {
        cb.max[a] = node.m + node.h;
    }
    cb
}

/// A node waiting in the first-hit search: its index, a lower bound on the
/// cast's entry into its region, and its box `B` (derived from the parent's).
#[derive(Clone, Copy)]
struct CastPending {
    node: u32,
    t: f32,
    bbox: Aabb,
}

/// Filler of the fixed stack's unused entries (and of an absent child: no
/// node, never entered).
impl Default for CastPending {
    fn default() -> Self {
        CastPending {
            node: NIL,
            t: f32::INFINITY,
            bbox: Aabb::EMPTY,
        }
    }
}
