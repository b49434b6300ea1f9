//! Removal of emptied nodes (`DeleteNode`) and moves (`Move`) [sources: kd-remove, kd-move].

use super::node::NIL;
use super::{Loc, LooseKdTree};
use crate::geom::Sphere;

impl<T> LooseKdTree<T> {
    /// Frees `n` if it holds nothing and has no children, detaching it from its
    /// parent. Returns the parent if `n` was freed.
    fn free_if_empty(&mut self, n: u32) -> Option<u32> {
        if !self.nodes[n].is_empty() {
            return None;
        }
        let p = self.nodes[n].parent;
        // Its (empty) range is dead until the next compaction.
        self.store.dead += self.nodes[n].cap as usize;
        if p == NIL {
            self.root = NIL;
        } else {
            let side = (self.nodes[p].child[1] == n) as usize;
            self.nodes[p].child[side] = NIL;
        }
        self.nodes.free(n);
        Some(p)
    }

    /// Frees `n` and then each ancestor while they are empty ([sources: kd-remove]: the `Pop` loop).
    pub(super) fn prune_up(&mut self, mut n: u32) {
        while n != NIL {
            match self.free_if_empty(n) {
                Some(p) => n = p,
                None => break,
            }
        }
    }

    /// Moves the object at `loc` to `s` (already validated and covered by `span`).
    ///
    /// If the placement rule still puts `s` in the object's node (same side of every
    /// split above, `r` below every `h` above and `>= h` here or at the depth cap),
    /// only the stored sphere changes: O(1). Otherwise the object is taken out of
    /// the node and we climb, freeing emptied nodes, to the lowest node that still
    /// routes `s` (the root always does), and insert from there: O(climb + descent).
    pub(super) fn move_item(&mut self, loc: Loc, s: Sphere) {
        let max_depth = self.max_depth;
        let n = &self.nodes[loc.node];
        if n.routes(&s) && (s.radius >= n.h || n.depth >= max_depth) {
            let p = (n.start + loc.pos) as usize;
            if !n.loose {
                self.nodes[loc.node].loose = true;
            }
            self.store.sphere[p] = s;
            return;
        }
        let (_, handle, filter, value) = self.take(loc);
        let mut cur = loc.node;
        while !self.nodes[cur].routes(&s) {
            let parent = self.nodes[cur].parent;
            debug_assert!(parent != NIL, "the root routes every sphere");
            let _ = self.free_if_empty(cur);
            cur = parent;
        }
        let target = self.descend(cur, &s);
        self.put(target, s, handle, filter, value);
        self.maybe_compact();
    }
}
