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

impl<T> LooseKdTree<T> {
    /// Depth-first walk reporting every item `query` selects.
    ///
    /// Per child, two conservative filters:
    /// 1. the seed's one comparison on the split axis against `query.bounds()`
    ///    (descend positive only if `q_max_a >= m - h`, negative only if
    ///    `q_min_a <= m + h`, each with slack): every sphere of the positive subtree
    ///    has `c_a - r > m - h`, so a query box ending before `m - h` selects none
    ///    of them (bounds are a box every selected sphere intersects);
    /// 2. `query.classify_box` on the child's region (`region`, which contains every
    ///    sphere of the subtree), carrying the frustum plane mask down: `Outside`
    ///    skips the subtree, `Inside` reports it whole without tests (valid because
    ///    the selection promises `Inside` only when every sphere inside the box is
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
        let classify = |n: u32, mask: u8, stack: &mut FixedStack<Pending>| {
            let (rel, mask) = query.classify_box(&self.region(&self.nodes[n]), mask);
            match rel {
                Relation::Outside => {}
                Relation::Inside => stack.push(Pending {
                    node: n,
                    mask: 0,
                    inside: true,
                }),
                Relation::Intersecting => stack.push(Pending {
                    node: n,
                    mask,
                    inside: false,
                }),
            }
        };
        classify(self.root, Frustum::ALL_PLANES, &mut stack);
        while let Some(p) = stack.pop() {
            let node = &self.nodes[p.node];
            for (q, s) in node.range().zip(&self.store.sphere[node.range()]) {
                if p.inside || query.selects(s) {
                    let (h, v) = self.store.at(q);
                    f(h, s, v)?;
                }
            }
            let a = node.axis as usize;
            for side in 0..2 {
                let c = node.child[side];
                if c == NIL {
                    continue;
                }
                if p.inside {
                    stack.push(Pending {
                        node: c,
                        mask: 0,
                        inside: true,
                    });
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
                classify(c, p.mask, &mut stack);
            }
        }
        ControlFlow::Continue(())
    }

    /// Smallest entry `t` (ties: smallest handle) by a front-to-back walk: the
    /// ray's `max_t` shrinks to the best hit so far, children are visited nearer
    /// entry first, and a subtree whose region (which contains all its spheres) the
    /// shortened ray does not reach is skipped. `t` values come from the same
    /// `overlap::ray_sphere` as the default scan, and `max_t` does not change the `t`
    /// it returns, only whether it is returned, so the answer is identical.
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
                if let Some(t) = overlap::ray_sphere(&r, s) {
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
