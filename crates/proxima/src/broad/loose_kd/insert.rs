//! Insertion ([sources: kd-insert]: `RecursivePush`, iterative): the placement rule, lazy node
//! creation, and the O(1) placement and swap-removal of objects in a node's range
//! of the object array (`store.rs`), including the compaction of that array.

use super::node::{all_space, Node, NIL};
use super::store::room_for;
use super::{Loc, LooseKdTree};
use crate::arena::Pool;
use crate::broad::Filter;
use crate::geom::Sphere;
use crate::Handle;

/// Compaction starts once the dead positions exceed this many plus half the
/// live objects, or the nodes out of order this many plus an eighth of all
/// nodes: tiny trees rarely bother, big ones keep at most ~1.5 dead or spare
/// positions per object and mostly depth-first order.
const COMPACT_SLACK: usize = 64;

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
        self.store.disorder += 1;
        c
    }

    /// Places an object in `node`'s range and records its location. O(1)
    /// amortized: a full range first moves to the end of the array with twice
    /// the room (the old range becomes dead).
    pub(super) fn put(
        &mut self,
        node: u32,
        sphere: Sphere,
        handle: Handle,
        filter: Filter,
        value: T,
    ) {
        let (start, len, cap) = {
            let n = &self.nodes[node];
            (n.start, n.len, n.cap)
        };
        let start = if len < cap {
            start
        } else {
            let new_cap = (2 * cap).max(2);
            let at = self.store.grow(new_cap as usize);
            for i in 0..len as usize {
                let (from, to) = (start as usize + i, at as usize + i);
                self.store.set(to, self.store.sphere[from]);
                self.store.entry[to] = self.store.entry[from].take();
            }
            self.store.dead += cap as usize;
            self.store.disorder += 1;
            let n = &mut self.nodes[node];
            n.start = at;
            n.loose = false;
            n.cap = new_cap;
            at
        };
        let p = (start + len) as usize;
        self.store.set(p, sphere);
        self.store.entry[p] = Some((handle, filter, value));
        self.inert.add(filter);
        self.nodes[node].len = len + 1;
        self.widen_filters(node, filter);
        *self
            .items
            .get_by_index_mut(handle.index())
            .expect("placing a live item") = Loc { node, pos: len };
    }

    /// ORs `filter` into the filter bits of `node` and its ancestors, stopping
    /// where they already hold it. O(depth), usually O(1).
    pub(super) fn widen_filters(&mut self, mut node: u32, filter: Filter) {
        while node != NIL {
            let n = &mut self.nodes[node];
            let (g, m) = (n.groups | filter.group, n.masks | filter.mask);
            if (g, m) == (n.groups, n.masks) {
                break;
            }
            (n.groups, n.masks) = (g, m);
            node = n.parent;
        }
    }

    /// Takes the object at `loc` out of its node ([sources: kd-remove]: `DeleteItem`) by moving the
    /// node's last object into the hole, whose location is updated. O(1). The
    /// taken object's own location is stale until it is placed again.
    pub(super) fn take(&mut self, loc: Loc) -> (Sphere, Handle, Filter, T) {
        let n = &mut self.nodes[loc.node];
        n.len -= 1;
        let (p, last) = ((n.start + loc.pos) as usize, (n.start + n.len) as usize);
        let sphere = self.store.sphere[p];
        let (handle, filter, value) = self.store.entry[p].take().expect("live position");
        self.inert.sub(filter);
        if p != last {
            self.store.set(p, self.store.sphere[last]);
            let moved = self.store.entry[last].take();
            let idx = moved.as_ref().expect("live position").0.index();
            self.store.entry[p] = moved;
            self.items
                .get_by_index_mut(idx)
                .expect("moved item is live")
                .pos = loc.pos;
        }
        (sphere, handle, filter, value)
    }

    /// Compacts the object array if its dead positions have outgrown the live
    /// objects or too many nodes are out of depth-first order (see
    /// `COMPACT_SLACK`). The costs are geometric in the size, so building a tree
    /// by insertion compacts O(log n) times, O(n) in total.
    pub(super) fn maybe_compact(&mut self) {
        if self.store.dead > COMPACT_SLACK + self.items.len() / 2
            || self.store.disorder > COMPACT_SLACK + self.nodes.len() / 8
        {
            self.compact();
        }
    }

    /// Rebuilds the node pool and the object array in depth-first order (node,
    /// then its negative subtree, then its positive one: the order of the pair
    /// walk), each range with some spare room (`room_for`). O(objects + nodes).
    pub(super) fn compact(&mut self) {
        let mut nodes = Pool::default();
        // Same capacity as before: a steady state compacts without reallocating.
        let mut store = self.store.empty_like();
        if self.root != NIL {
            // (old index, new parent index, side under that parent)
            let mut stack = vec![(self.root, NIL, 0usize)];
            while let Some((old, parent, side)) = stack.pop() {
                let mut node = self.nodes[old];
                let at = store.grow(room_for(node.len) as usize);
                for i in 0..node.len as usize {
                    let from = node.start as usize + i;
                    store.set(at as usize + i, self.store.sphere[from]);
                    store.entry[at as usize + i] = self.store.entry[from].take();
                }
                node.start = at;
                node.cap = room_for(node.len);
                node.loose = false;
                node.parent = parent;
                let children = node.child;
                node.child = [NIL, NIL];
                let new = nodes.alloc(node);
                if parent == NIL {
                    self.root = new;
                } else {
                    let p: &mut Node = &mut nodes[parent];
                    p.child[side] = new;
                }
                for i in 0..node.len as usize {
                    let (h, _, _) = store.entry[at as usize + i].as_ref().expect("live");
                    self.items
                        .get_by_index_mut(h.index())
                        .expect("live item")
                        .node = new;
                }
                // Positive pushed first so the negative subtree comes out first.
                for s in [1, 0] {
                    if children[s] != NIL {
                        stack.push((children[s], new, s));
                    }
                }
            }
        }
        self.nodes = nodes;
        self.store = store;
    }
}
