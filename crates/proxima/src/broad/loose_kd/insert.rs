//! Insertion (seed `RecursivePush`, iterative): the placement rule, lazy node
//! creation, and the O(1) intrusive item list of each node.

use super::node::{all_space, Node, NIL};
use super::LooseKdTree;
use crate::geom::Sphere;

impl<T> LooseKdTree<T> {
    /// The root, created over the world box if the tree is empty.
    pub(super) fn ensure_root(&mut self) -> u32 {
        if self.root == NIL {
            let n = Node::new(
                self.world,
                all_space(),
                f32::INFINITY,
                NIL,
                0,
                self.r_max,
                self.density,
            );
            self.root = self.nodes.alloc(n);
        }
        self.root
    }

    /// Applies the placement rule from `start` (a node that routes `s`) down: stop
    /// where `r >= h` or at the depth cap, else go to the child on the centre's side
    /// (`c_a > m` → positive), creating it if missing. Returns the node.
    pub(super) fn descend(&mut self, start: u32, s: &Sphere) -> u32 {
        let mut n = start;
        loop {
            let node = &self.nodes[n];
            if s.radius >= node.h || node.depth >= self.max_depth {
                return n;
            }
            let side = (s.center[node.axis as usize] > node.m) as usize;
            let c = node.child[side];
            n = if c != NIL { c } else { self.new_child(n, side) };
        }
    }

    fn new_child(&mut self, parent: u32, side: usize) -> u32 {
        let p = &self.nodes[parent];
        let (bbox, cell) = p.child_bounds(side);
        let node = Node::new(
            bbox,
            cell,
            p.h,
            parent,
            p.depth + 1,
            self.r_max,
            self.density,
        );
        let c = self.nodes.alloc(node);
        self.nodes[parent].child[side] = c;
        c
    }

    /// Pushes item slot `idx` at the front of `node`'s list. O(1).
    pub(super) fn link(&mut self, node: u32, idx: u32) {
        let head = self.nodes[node].first;
        {
            let it = self
                .items
                .get_by_index_mut(idx)
                .expect("linking a live item");
            it.node = node;
            it.prev = NIL;
            it.next = head;
        }
        if head != NIL {
            self.items.get_by_index_mut(head).expect("list head").prev = idx;
        }
        let n = &mut self.nodes[node];
        n.first = idx;
        n.count += 1;
    }

    /// Takes item slot `idx` out of its node's list (seed `DeleteItem`) and returns
    /// that node. O(1). The item keeps its stale `node` until relinked.
    pub(super) fn unlink(&mut self, idx: u32) -> u32 {
        let (node, prev, next) = {
            let it = self
                .items
                .get_by_index(idx)
                .expect("unlinking a live item")
                .1;
            (it.node, it.prev, it.next)
        };
        if prev != NIL {
            self.items.get_by_index_mut(prev).expect("prev").next = next;
        } else {
            self.nodes[node].first = next;
        }
        if next != NIL {
            self.items.get_by_index_mut(next).expect("next").prev = prev;
        }
        self.nodes[node].count -= 1;
        node
    }
}
