//! Removal of emptied nodes (seed `DeleteNode`) and moves (seed `Move`).

use super::node::NIL;
use super::LooseKdTree;
use crate::geom::Sphere;

impl<T> LooseKdTree<T> {
    /// Frees `n` if it holds nothing and has no children, detaching it from its
    /// parent. Returns the parent if `n` was freed.
    fn free_if_empty(&mut self, n: u32) -> Option<u32> {
        if !self.nodes[n].is_empty() {
            return None;
        }
        let p = self.nodes[n].parent;
        if p == NIL {
            self.root = NIL;
        } else {
            let side = (self.nodes[p].child[1] == n) as usize;
            self.nodes[p].child[side] = NIL;
        }
        self.nodes.free(n);
        Some(p)
    }

    /// Frees `n` and then each ancestor while they are empty (seed `Pop` loop).
    pub(super) fn prune_up(&mut self, mut n: u32) {
        while n != NIL {
            match self.free_if_empty(n) {
                Some(p) => n = p,
                None => break,
            }
        }
    }

    /// Moves item slot `idx` to `s` (already validated and covered by `span`).
    ///
    /// If the placement rule still puts `s` in the item's node (same side of every
    /// split above, `r` below every `h` above and `>= h` here or at the depth cap),
    /// only the stored sphere changes: O(1). Otherwise the item is unlinked and we
    /// climb, freeing emptied nodes, to the lowest node that still routes `s` (the
    /// root always does), and insert from there: O(climb + descent).
    pub(super) fn move_item(&mut self, idx: u32, s: Sphere) {
        let node = self
            .items
            .get_by_index(idx)
            .expect("moving a live item")
            .1
            .node;
        let n = &self.nodes[node];
        let stays = n.routes(&s) && (s.radius >= n.h || n.depth >= self.max_depth);
        self.items.get_by_index_mut(idx).expect("live").sphere = s;
        if stays {
            return;
        }
        self.unlink(idx);
        let mut cur = node;
        while !self.nodes[cur].routes(&s) {
            let parent = self.nodes[cur].parent;
            debug_assert!(parent != NIL, "the root routes every sphere");
            let _ = self.free_if_empty(cur);
            cur = parent;
        }
        let target = self.descend(cur, &s);
        self.link(target, idx);
    }
}
