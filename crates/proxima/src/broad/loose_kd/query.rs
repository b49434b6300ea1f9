//! Queries (seed `TestIntersection`, generalized to any [`Selection`]) and the
//! front-to-back first-hit ray search.

use super::node::{FixedStack, NIL};
use super::LooseKdTree;
use crate::arena::Handle;
use crate::broad::{RayHit, Selection};
use crate::geom::{overlap, Frustum, Ray, Relation, Sphere};
use std::ops::ControlFlow;

/// A pending node: index, frustum plane mask, and whether its whole region is
/// known to be selected (then its subtree is reported without tests).
#[derive(Clone, Copy, Default)]
struct Pending {
    node: u32,
    mask: u8,
    inside: bool,
}

/// A subtree known to be wholly selected.
#[inline]
fn p_inside(node: u32) -> Pending {
    Pending {
        node,
        mask: 0,
        inside: true,
    }
}

impl<T> LooseKdTree<T> {
    /// Depth-first walk reporting every item `query` selects.
    ///
    /// Per child, two conservative filters, both decided from the *parent* (already
    /// in cache), so a pruned child's node is never loaded — on a large tree each
    /// node load is a cache miss, and it is what the profile of W4's queries shows:
    /// 1. the seed's one comparison on the split axis against `query.bounds()`
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
    pub(super) fn visit_impl<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let bounds = query.bounds();
        let mut stack = FixedStack::<Pending>::new();
        let push =
            |node: u32, (rel, mask): (Relation, u8), stack: &mut FixedStack<Pending>| match rel {
                Relation::Outside => {}
                Relation::Inside => stack.push(Pending {
                    node,
                    mask: 0,
                    inside: true,
                }),
                Relation::Intersecting => stack.push(Pending {
                    node,
                    mask,
                    inside: false,
                }),
            };
        let root = &self.nodes[self.root];
        push(
            self.root,
            query.classify_box(&self.region(root), Frustum::ALL_PLANES),
            &mut stack,
        );
        while let Some(p) = stack.pop() {
            let node = &self.nodes[p.node];
            if p.inside {
                for (q, s) in node.range().zip(&self.store.sphere[node.range()]) {
                    let (h, v) = self.store.at(q);
                    f(h, s, v)?;
                }
                for c in node.child {
                    if c != NIL {
                        stack.push(p_inside(c));
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
                // The child's box, from the parent: one face moved to `m ∓ h`.
                let mut cb = node.bbox;
                if side == 1 {
                    cb.min[a] = node.m - node.h;
                } else {
                    cb.max[a] = node.m + node.h;
                }
                push(
                    c,
                    query.classify_box(&self.region_of_box(&cb), p.mask),
                    &mut stack,
                );
            }
            // The node's own objects after its children are classified: the
            // children's tests need only this node's fields, and the scan's
            // first load (the node's range of the object array) is the miss.
            for (q, s) in node.range().zip(&self.store.sphere[node.range()]) {
                if query.selects(s) {
                    let (h, v) = self.store.at(q);
                    f(h, s, v)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Smallest entry `t` (ties: smallest handle) by a front-to-back walk: the
    /// ray's `max_t` shrinks to the best hit so far, children are visited nearer
    /// entry first, and a subtree whose region (which contains all its spheres) the
    /// shortened ray does not reach is skipped. `t` values come from the same
    /// `overlap::ray_sphere` on the unshortened ray, as in the default scan, so the
    /// answer is identical: a pruned box has `ray_aabb`'s entry bound above the
    /// best `t`, and that bound is at most the `t` of every sphere inside.
    pub(super) fn ray_first_impl(&self, ray: &Ray) -> Option<RayHit> {
        if self.root == NIL {
            return None;
        }
        let mut r = *ray;
        let mut best: Option<RayHit> = None;
        let mut stack = FixedStack::<(u32, f32)>::new();
        if let Some((t0, _)) = overlap::ray_aabb(&r, &self.region(&self.nodes[self.root])) {
            stack.push((self.root, t0));
        }
        while let Some((n, t_enter)) = stack.pop() {
            if t_enter > r.max_t {
                continue;
            }
            let node = &self.nodes[n];
            for (q, s) in node.range().zip(&self.store.sphere[node.range()]) {
                // The full ray: its `t` is what brute force reports (`ray_sphere`
                // clamps into `[.., max_t]`); the shortened `r` only prunes boxes.
                if let Some(t) = overlap::ray_sphere(ray, s).filter(|&t| t <= r.max_t) {
                    let h = self.store.at(q).0;
                    let better = match best {
                        None => true,
                        Some(b) => (t, h) < (b.t, b.handle),
                    };
                    if better {
                        best = Some(RayHit { handle: h, t });
                        r.max_t = t;
                    }
                }
            }
            let mut entries = [(NIL, f32::INFINITY); 2];
            for (side, e) in entries.iter_mut().enumerate() {
                let c = node.child[side];
                if c != NIL {
                    if let Some((t0, _)) = overlap::ray_aabb(&r, &self.region(&self.nodes[c])) {
                        *e = (c, t0);
                    }
                }
            }
            // Push the farther first so the nearer is popped first.
            if entries[0].1 < entries[1].1 {
                entries.swap(0, 1);
            }
            for e in entries {
                if e.0 != NIL {
                    stack.push(e);
                }
            }
        }
        best
    }
}
