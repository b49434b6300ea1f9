//! Insertion and removal, with the split of full leaves and the merge of thinned
//! subtrees [sources: octree-split, octree-merge].

use super::code::MAX_DEPTH;
use super::node::{Item, Obj, NONE};
use super::LinearOctree;
use crate::broad::Filter;
use crate::geom::Sphere;
use crate::Handle;
use crate::Result;

impl<T> LinearOctree<T> {
    /// Inserts an already validated sphere: locate the leaf from the centre's code,
    /// append, update counts and extents up the chain, split if over capacity.
    pub(super) fn insert_valid(
        &mut self,
        sphere: Sphere,
        filter: Filter,
        value: T,
    ) -> Result<Handle> {
        let (key, ext) = self.placement(&sphere);
        let handle = self.objects.insert(Obj {
            sphere,
            key,
            ext,
            leaf: NONE,
            slot: 0,
            filter,
            value,
        })?;
        self.inert.add(filter);
        let start = self.locate(key);
        let leaf = self.descend_to_leaf(start, key);
        self.push_item(
            leaf,
            Item {
                sphere,
                handle,
                ext,
            },
        );
        self.add_count(leaf, NONE, 1);
        self.grow_extent(leaf, ext);
        self.split_if_full(leaf);
        Ok(handle)
    }

    /// Removes object `h` and returns its payload.
    pub(super) fn remove_obj(&mut self, h: Handle) -> Result<T> {
        let o = self.objects.get(h)?;
        let (leaf, slot) = (o.leaf, o.slot);
        let item = self.take_item(leaf, slot);
        let obj = self.objects.remove(h)?;
        self.inert.sub(obj.filter);
        self.shrink_chain(leaf, NONE, item.ext);
        Ok(obj.value)
    }

    /// Splits leaf `i` while it holds more than `max_per_leaf` objects and depth
    /// allows: its items go to the octants of their centres (only non-empty
    /// octants become nodes), and children still over capacity split in turn.
    pub(super) fn split_if_full(&mut self, i: u32) {
        let n = &self.nodes[i];
        let d = n.code.depth();
        if !n.leaf
            || n.items.len() <= self.config.max_per_leaf as usize
            || d >= self.config.max_depth
        {
            return;
        }
        self.counters.splits += 1;
        let mut items = std::mem::take(&mut self.nodes[i].items);
        self.nodes[i].leaf = false;
        self.octants[i as usize] = [0; 8];
        let shift = 3 * (MAX_DEPTH - d - 1);
        for it in items.drain(..) {
            let key = self.obj(it.handle).key;
            let k = ((key >> shift) & 7) as usize;
            let mut c = self.nodes[i].children[k];
            if c == NONE {
                c = self.new_node(super::LocationCode::from_raw_unchecked(key >> shift), i);
            }
            self.push_item(c, it);
            let cn = &mut self.nodes[c];
            cn.count += 1;
            cn.max_extent = cn.max_extent.max(it.ext);
        }
        self.spare.push(items);
        for k in 0..8 {
            let c = self.nodes[i].children[k];
            if c != NONE {
                self.split_if_full(c);
            }
        }
    }

    /// After one object left leaf `s`: decrements the counts from `s` up to, not
    /// including, `stop`; merges the highest node of that stretch whose count fell
    /// below `merge_below`; deletes nodes left empty; and shrinks the extent bounds
    /// when the object that left (extent `ext`) may have been the largest.
    ///
    /// Nodes at and above `stop` keep their counts (a move's common ancestor), so
    /// they can neither merge nor empty here.
    pub(super) fn shrink_chain(&mut self, s: u32, stop: u32, ext: f32) {
        let mut merge = NONE;
        let mut n = s;
        while n != stop && n != NONE {
            let node = &mut self.nodes[n];
            node.count -= 1;
            if !node.leaf && node.count < self.config.merge_below {
                merge = n; // counts grow upward: the last one found is the highest
            }
            n = node.parent;
        }
        let mut bottom = s;
        let mut changed = false;
        if merge != NONE {
            self.collapse(merge);
            bottom = merge;
            changed = true;
        }
        // Delete emptied nodes upward (the root stays, as an empty leaf).
        while self.nodes[bottom].count == 0 {
            if bottom == self.root {
                // Only reachable with merging disabled: every child was deleted.
                let root = &mut self.nodes[bottom];
                debug_assert!(root.children.iter().all(|&c| c == NONE));
                root.leaf = true;
                break;
            }
            let parent = self.nodes[bottom].parent;
            self.free_subtree(bottom);
            bottom = parent;
            changed = true;
        }
        if changed || ext >= self.nodes[bottom].max_extent {
            self.refit_extent(bottom);
        }
    }

    /// Turns inner node `x` back into a leaf holding every object of its subtree
    /// (the source's merge of a parent that no longer meets the split criterion).
    pub(super) fn collapse(&mut self, x: u32) {
        self.counters.merges += 1;
        let mut items = self.spare.pop().unwrap_or_default();
        for k in 0..8 {
            let c = self.nodes[x].children[k];
            if c != NONE {
                self.gather(c, &mut items);
            }
        }
        for (slot, it) in items.iter().enumerate() {
            let o = self.obj_mut(it.handle);
            o.leaf = x;
            o.slot = slot as u32;
        }
        let node = &mut self.nodes[x];
        node.leaf = true;
        node.children = [NONE; 8];
        node.max_extent = items.iter().fold(0.0f32, |m, it| m.max(it.ext));
        let old = std::mem::replace(&mut node.items, items);
        debug_assert!(old.is_empty());
        if old.capacity() > 0 {
            self.spare.push(old);
        }
        self.remark_octants(x);
    }

    /// Moves every item below node `i` into `out` and frees the nodes.
    fn gather(&mut self, i: u32, out: &mut Vec<Item>) {
        if self.nodes[i].leaf {
            out.extend_from_slice(&self.nodes[i].items);
        } else {
            for k in 0..8 {
                let c = self.nodes[i].children[k];
                if c != NONE {
                    self.gather(c, out);
                }
            }
        }
        self.free_node(i);
    }

    /// Frees node `i` and everything below it (their items must be gone).
    fn free_subtree(&mut self, i: u32) {
        for k in 0..8 {
            let c = self.nodes[i].children[k];
            if c != NONE {
                self.free_subtree(c);
            }
        }
        debug_assert!(self.nodes[i].items.is_empty());
        self.free_node(i);
    }
}
