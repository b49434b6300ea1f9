//! Moves [sources: octree-move, octree-depths]: an object whose centre leaves its leaf goes to the
//! neighbouring leaf found through the face-neighbour code and the map, also when
//! that neighbour sits at another depth; a long jump finds its leaf from the code
//! of the new centre.

use super::code::{Face, LocationCode, MAX_DEPTH};
use super::node::{bit, octant_of, Item};
use super::LinearOctree;
use crate::geom::Sphere;
use crate::Handle;

impl<T> LinearOctree<T> {
    /// Moves/resizes live object `h` to the validated sphere `sphere`.
    pub(super) fn move_obj(&mut self, h: Handle, sphere: Sphere) {
        let (key, ext) = self.placement(&sphere);
        let o = self.obj_mut(h);
        let (s, slot, old_ext, old_key) = (o.leaf, o.slot, o.ext, o.key);
        o.sphere = sphere;
        o.key = key;
        o.ext = ext;
        let s_code = self.nodes[s].code;
        let d = s_code.depth();
        let cell = LocationCode::from_raw_unchecked(key >> (3 * (MAX_DEPTH - d)));

        if cell == s_code {
            // Same leaf: only the stored sphere and the bounds change.
            self.counters.same_leaf_moves += 1;
            let n = &mut self.nodes[s];
            let item = &mut n.items[slot as usize];
            item.sphere = sphere;
            item.ext = ext;
            // The centre may have crossed into another octant of the leaf.
            if octant_of(key, d) != octant_of(old_key, d) {
                self.unmark_slots(s, bit(slot as usize));
                self.mark_octant(s, slot, key);
            }
            if ext > old_ext {
                self.grow_extent(s, ext);
            } else if ext < old_ext && old_ext >= self.nodes[s].max_extent {
                self.refit_extent(s);
            }
            return;
        }

        let target = match s_code.offset_to(cell) {
            Some(off) => {
                // Adjacent cell at the leaf's depth: walk to it with O(1) face
                // steps (one per axis crossed), then resolve it in the map.
                let mut n = s_code;
                for (axis, &o) in off.iter().enumerate() {
                    if o != 0 {
                        n = n
                            .face_neighbor(Face::new(axis, o > 0))
                            .expect("the centre's cell is inside the world");
                    }
                }
                debug_assert_eq!(n, cell);
                if off.iter().filter(|&&o| o != 0).count() == 1 {
                    self.counters.face_moves += 1;
                } else {
                    self.counters.edge_corner_moves += 1;
                }
                self.resolve_neighbor(n, key)
            }
            None => {
                self.counters.jump_moves += 1;
                let start = self.locate(key);
                self.descend_to_leaf(start, key)
            }
        };
        self.relocate(h, s, slot, target, sphere, ext, old_ext);
    }

    /// The leaf containing `key` given `n`, a same-depth neighbour cell of the
    /// object's old leaf that contains `key` [sources: octree-depths]: if `n` is a node, go
    /// down toward the centre (smaller neighbours); if not, go up to the first
    /// existing ancestor (a larger neighbour, or an inner node whose octant toward
    /// the centre is empty space and gets a new leaf).
    ///
    /// The source guesses whether to search up or down first from the node's depth
    /// relative to the tree's depth; here one map lookup of `n` decides it (a node:
    /// same depth or down; absent: up), so no guess is needed.
    pub(super) fn resolve_neighbor(&mut self, n: LocationCode, key: u64) -> u32 {
        if let Some(&i) = self.map.get(&n.raw()) {
            if !self.nodes[i].leaf {
                self.counters.neighbor_down += 1;
            } else {
                self.counters.neighbor_same_depth += 1;
            }
            return self.descend_to_leaf(i, key);
        }
        self.counters.neighbor_up += 1;
        let mut c = n;
        loop {
            c = c.parent().expect("the root is always in the map");
            if let Some(&i) = self.map.get(&c.raw()) {
                return self.descend_to_leaf(i, key);
            }
        }
    }

    /// Moves the item at `slot` of leaf `s` into leaf `t` (≠ `s`). Counts change
    /// only below the two leaves' common ancestor; the target is filled before the
    /// source is thinned, so a move never merges a node the object stays under.
    #[allow(clippy::too_many_arguments)]
    fn relocate(
        &mut self,
        h: Handle,
        s: u32,
        slot: u32,
        t: u32,
        sphere: Sphere,
        ext: f32,
        old_ext: f32,
    ) {
        debug_assert_ne!(s, t);
        let lca_code = self.nodes[s].code.common_ancestor(self.nodes[t].code);
        let mut lca = t;
        while self.nodes[lca].code != lca_code {
            lca = self.nodes[lca].parent;
        }
        self.take_item(s, slot);
        self.push_item(
            t,
            Item {
                sphere,
                handle: h,
                ext,
            },
        );
        self.add_count(t, lca, 1);
        self.grow_extent(t, ext);
        self.shrink_chain(s, lca, old_ext);
        debug_assert!(self.nodes[t].leaf && self.obj(h).leaf == t);
        self.split_if_full(t);
    }
}
