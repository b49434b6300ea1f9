//! Insertion (seed `RecursivePush`, iterative): the placement rule, lazy node
//! creation, and the O(1) placement and swap-removal of objects in a node.

use super::node::{all_space, Node, Slot, NIL};
use super::{Loc, LooseKdTree};
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
                self.spare.pop().unwrap_or_default(),
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
        let slots = self.spare.pop().unwrap_or_default();
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
            slots,
        );
        let c = self.nodes.alloc(node);
        self.nodes[parent].child[side] = c;
        c
    }

    /// Appends `slot` to `node`'s objects and records its location. O(1)
    /// amortized (no allocation once the node's vector has grown).
    pub(super) fn put_slot(&mut self, node: u32, slot: Slot<T>) {
        let slots = &mut self.nodes[node].slots;
        let pos = slots.len() as u32;
        let idx = slot.handle.index();
        slots.push(slot);
        *self
            .items
            .get_by_index_mut(idx)
            .expect("placing a live item") = Loc { node, pos };
    }

    /// Takes the object at `loc` out of its node (seed `DeleteItem`) by moving the
    /// node's last object into the hole, whose location is updated. O(1). The
    /// taken object's own location is stale until it is placed again.
    pub(super) fn take_slot(&mut self, loc: Loc) -> Slot<T> {
        let slots = &mut self.nodes[loc.node].slots;
        let slot = slots.swap_remove(loc.pos as usize);
        if let Some(moved) = slots.get(loc.pos as usize) {
            let idx = moved.handle.index();
            self.items
                .get_by_index_mut(idx)
                .expect("moved item is live")
                .pos = loc.pos;
        }
        slot
    }
}
