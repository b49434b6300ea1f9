//! k nearest neighbours [sources: index-queries]: a depth-first branch and
//! bound over the node regions, nearer child first, with the bounded candidate set of
//! `broad/nearest.rs`.

use super::node::{FixedStack, NIL};
use super::LooseKdTree;
use crate::broad::nearest::{KBest, Nearest, Neighbor};
use crate::broad::Filter;
use crate::geom::overlap;

impl<T> LooseKdTree<T> {
    /// The `k` nearest into `out`, nearest first, ties by handle.
    ///
    /// A node is skipped only if the correctly rounded distance from the point
    /// to its region is surely above the candidate set's bound
    /// ([`overlap::distance_exceeds`] on [`overlap::point_aabb_distance_sq`]);
    /// the region contains every sphere of the subtree, and the rounded
    /// distances are monotone, so no object of a pruned subtree could have
    /// entered: the answer is brute force's, bit for bit.
    /// Children are pushed farther first, so the nearer is searched first and
    /// the bound shrinks early. With a filter, subtrees whose filter bits
    /// cannot interact with it are skipped, and each candidate that could
    /// enter is checked. Cost: O(log n + k log k) node visits on typical scenes; no
    /// allocation once `out` holds `k` entries (the stack is fixed).
    pub(super) fn nearest_impl(
        &self,
        q: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) {
        let mut best = KBest::new(out, q.k, q.max_distance);
        if self.root == NIL || q.k == 0 {
            return;
        }
        let mut stack = FixedStack::<(u32, f64)>::new();
        let d0 = overlap::point_aabb_distance_sq(q.point, &self.region(&self.nodes[self.root]));
        if !best.exceeds_sq(d0) {
            stack.push((self.root, d0));
        }
        while let Some((n, d)) = stack.pop() {
            if best.exceeds_sq(d) {
                continue;
            }
            let node = &self.nodes[n];
            if filter.is_some_and(|f| !f.may_interact(node.groups, node.masks)) {
                continue;
            }
            for (p, s) in node.range().zip(&self.store.sphere[node.range()]) {
                if let Some(distance) = q.metric.distance_within(q.point, s, &best) {
                    let (handle, of, _) = self.store.full(p);
                    if filter.is_none_or(|f| f.interacts(of)) {
                        best.offer(Neighbor { handle, distance });
                    }
                }
            }
            let mut next = [(NIL, f64::INFINITY); 2];
            for (side, e) in next.iter_mut().enumerate() {
                let c = node.child[side];
                if c != NIL {
                    let dc = overlap::point_aabb_distance_sq(q.point, &self.region(&self.nodes[c]));
                    if !best.exceeds_sq(dc) {
                        *e = (c, dc);
                    }
                }
            }
            // Farther first, so that the nearer is popped first.
            if next[0].1 < next[1].1 {
                next.swap(0, 1);
            }
            for e in next {
                if e.0 != NIL {
                    stack.push(e);
                }
            }
        }
        best.finish();
    }
}
