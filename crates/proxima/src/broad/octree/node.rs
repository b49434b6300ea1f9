//! Node storage and the map from location code to node: the helpers every other
//! concern (insert, moves, queries, validation) builds on.

use super::code::{cell_box_of, point_key, LocationCode, MAX_DEPTH};
use super::LinearOctree;
use crate::arena::{Arena, Pool};
use crate::broad::Filter;
use crate::geom::{Aabb, Sphere};
use crate::prefetch::prefetch;
use crate::Handle;
use glam::Vec3;

/// "No node" in parent/child links.
pub(super) const NONE: u32 = u32::MAX;

/// The octant of a cell at depth `d` that holds depth-21 key `key` (which
/// lies in that cell), or `None` at [`MAX_DEPTH`]. O(1).
#[inline]
pub(super) fn octant_of(key: u64, d: u32) -> Option<usize> {
    (d < MAX_DEPTH).then(|| ((key >> (3 * (MAX_DEPTH - d - 1))) & 7) as usize)
}

/// Slot `s`'s bit in an octant mask (none from 64 on).
#[inline]
pub(super) fn bit(s: usize) -> u64 {
    1u64.checked_shl(s as u32).unwrap_or(0)
}

/// An object as its leaf stores it: the sphere is copied here so that scans of a
/// leaf read contiguous memory. 32 bytes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Item {
    pub sphere: Sphere,
    pub handle: Handle,
    /// Radius plus the distance the centre was clamped by (see [`Obj::ext`]).
    pub ext: f32,
}

/// An object as the arena stores it.
#[derive(Clone, Debug)]
pub(super) struct Obj<T> {
    pub sphere: Sphere,
    /// Depth-21 code of the (clamped) centre; its prefix is the leaf's code.
    pub key: u64,
    /// Extent used for loose bounds: the radius, plus the L∞ distance from the
    /// centre to the clamped placement point when the centre is outside the cube.
    pub ext: f32,
    /// Leaf node index and position in its item list.
    pub leaf: u32,
    pub slot: u32,
    /// The collision filter: read with the payload when a pair is reported,
    /// never by the walks themselves.
    pub filter: Filter,
    pub value: T,
}

/// A node. A leaf holds items and no children; an inner node holds children
/// (indices, `NONE` where an octant is empty space) and no items.
#[derive(Clone, Debug)]
pub(super) struct Node {
    pub code: LocationCode,
    pub parent: u32,
    /// Objects in the subtree.
    pub count: u32,
    /// Largest object extent in the subtree; never smaller than the truth (it may
    /// be larger until a removal or merge refits it).
    pub max_extent: f32,
    pub leaf: bool,
    pub children: [u32; 8],
    pub items: Vec<Item>,
    /// OR of the groups and of the masks of the filters of every object in
    /// the subtree, or a superset (they only grow while the node lives;
    /// `validate` checks the superset): filtered walks skip the subtree when
    /// the query's filter cannot interact with them.
    pub groups: u32,
    pub masks: u32,
}

impl Node {
    /// Starts loading the first `lines` cache lines of this leaf's items (two
    /// 32-byte items a line; an inner node has none), for a search that will
    /// scan them soon. Only a hint: no result depends on it. O(lines).
    #[inline(always)]
    pub(super) fn prefetch_items(&self, lines: usize) {
        for it in self.items.iter().step_by(2).take(lines) {
            prefetch(it);
        }
    }

    /// Calls `f` with this leaf's items (at depth `d`) that lie in the
    /// octants of `reach` (bit `k` for octant `k` of its cell; `octants` are
    /// its masks, `LinearOctree::octants`), four at a time for a four-lane pre-test, and a
    /// mask of the lanes that hold them: a last group of fewer is padded
    /// with its first item, those lanes off. With all 8 octants (or at
    /// [`MAX_DEPTH`], where there are none) the items go in slot order in
    /// chunks; otherwise the slots come off the octants' masks four at a
    /// time without a branch each, then the slots from 64 on, which no mask
    /// holds. (A loop that stopped at the mask's last bit mispredicted its
    /// exit once a group: W8 first hits 77 -> 64 mispredicts a sweep in an
    /// intermediate build, callgrind.) O(items visited).
    #[inline(always)]
    pub(super) fn for_each_quad(
        &self,
        octants: &[u64; 8],
        d: u32,
        reach: u32,
        mut f: impl FnMut([&Item; 4], u32),
    ) {
        let items = &self.items;
        let rest = if reach & 0xFF == 0xFF || d >= MAX_DEPTH {
            &items[..]
        } else {
            let mut live = 0;
            for (k, m) in octants.iter().enumerate() {
                live |= m & 0u64.wrapping_sub(((reach >> k) & 1) as u64);
            }
            while live != 0 {
                let first = live.trailing_zeros() as usize;
                let mut quad = [first; 4];
                let mut valid = 0u32;
                for (j, q) in quad.iter_mut().enumerate() {
                    let some = live != 0;
                    *q = if some {
                        live.trailing_zeros() as usize
                    } else {
                        first
                    };
                    valid |= (some as u32) << j;
                    live &= live.wrapping_sub(1);
                }
                f(
                    [
                        &items[quad[0]],
                        &items[quad[1]],
                        &items[quad[2]],
                        &items[quad[3]],
                    ],
                    valid,
                );
            }
            items.get(64..).unwrap_or(&[])
        };
        let mut quads = rest.chunks_exact(4);
        for q in &mut quads {
            f([&q[0], &q[1], &q[2], &q[3]], 0xF);
        }
        let r = quads.remainder();
        if let Some(first) = r.first() {
            let at = |j: usize| r.get(j).unwrap_or(first);
            f([at(0), at(1), at(2), at(3)], (1 << r.len()) - 1);
        }
    }
}

impl<T> LinearOctree<T> {
    /// Starts loading node `i` (not `NONE`) for a search that will visit it
    /// soon: the lines of its item list and its children, what a visit reads
    /// first (the compiler chooses the layout, so two fields of an 88-byte
    /// node rather than its address). Only a hint. O(1).
    #[inline(always)]
    pub(super) fn prefetch_node(&self, i: u32) {
        let n = &self.nodes[i];
        prefetch(&n.items);
        prefetch(&n.children);
    }

    /// Allocates a leaf for `code` (child of `parent`) and registers it in the map.
    pub(super) fn new_node(&mut self, code: LocationCode, parent: u32) -> u32 {
        let items = self.spare.pop().unwrap_or_default();
        let i = self.nodes.alloc(Node {
            code,
            parent,
            count: 0,
            max_extent: 0.0,
            leaf: true,
            children: [NONE; 8],
            items,
            groups: 0,
            masks: 0,
        });
        // A freed node's slot comes back with its masks cleared.
        let at = i as usize;
        if self.octants.len() <= at {
            self.octants.resize(at + 1, [0; 8]);
        }
        self.octants[at] = [0; 8];
        self.map.insert(code.raw(), i);
        self.per_depth[code.depth() as usize] += 1;
        if parent != NONE {
            self.nodes[parent].children[code.child_index() as usize] = i;
        }
        i
    }

    /// Unregisters and frees node `i` (not its children), keeping its item list's
    /// memory for reuse, and unlinks it from its parent.
    pub(super) fn free_node(&mut self, i: u32) {
        let node = &mut self.nodes[i];
        let mut items = std::mem::take(&mut node.items);
        let (code, parent) = (node.code, node.parent);
        items.clear();
        if items.capacity() > 0 {
            self.spare.push(items);
        }
        self.map.remove(&code.raw());
        self.per_depth[code.depth() as usize] -= 1;
        if parent != NONE {
            let slot = &mut self.nodes[parent].children[code.child_index() as usize];
            if *slot == i {
                *slot = NONE;
            }
        }
        self.nodes.free(i);
    }

    /// The box of the cell at depth `d` with integer coordinates `c`.
    #[inline]
    pub(super) fn cell_of(&self, c: [u32; 3], d: u32) -> Aabb {
        cell_box_of(self.cube.min, Vec3::splat(self.cell_size[d as usize]), c)
    }

    /// The loose box of a node: its cell grown by its largest extent and the
    /// rounding slack. Every sphere stored below lies inside it.
    #[inline]
    pub(super) fn loose_of(&self, c: [u32; 3], d: u32, max_extent: f32) -> Aabb {
        self.cell_of(c, d).grown(max_extent + self.slack)
    }

    /// Loose boxes of the children of inner node `n` (at `c`, depth `d`)
    /// without reading them: their cells grown by `n`'s extent (never below
    /// a child's, so every sphere below each child is still inside). Per
    /// axis `a`, the low and high halves of `n`'s cell so grown; child `k`
    /// spans `halves[a][(k >> a) & 1]` (the octant order of
    /// `query::child_coords`). The same `f32` sides as [`Self::loose_of`]
    /// with `n`'s extent computes for each child.
    ///
    /// Written out per axis rather than as nested `array::map`s: those
    /// compiled to a call that was not inlined, ~10% of a k-nearest query's
    /// samples (`perf record`, W7 points, k = 10).
    #[inline(always)]
    pub(super) fn child_halves(&self, n: &Node, c: [u32; 3], d: u32) -> [[(f32, f32); 2]; 3] {
        let (size, grow) = (self.cell_size[d as usize + 1], n.max_extent + self.slack);
        let min = self.cube.min;
        [
            halves_on_axis(min.x, c[0], size, grow),
            halves_on_axis(min.y, c[1], size, grow),
            halves_on_axis(min.z, c[2], size, grow),
        ]
    }

    /// Placement of a sphere: the depth-21 key of its clamped centre and its extent.
    #[inline]
    pub(super) fn placement(&self, s: &Sphere) -> (u64, f32) {
        let key = point_key(self.cube.min, self.cube.max, self.scale, s.center);
        let clamped = s.center.clamp(self.cube.min, self.cube.max);
        let off = (s.center - clamped).abs().max_element();
        // The factor absorbs the rounding of `off` and of `radius + off`.
        let ext = if off > 0.0 {
            (s.radius + off) * (1.0 + 16.0 * f32::EPSILON)
        } else {
            s.radius
        };
        (key, ext)
    }

    /// Deepest existing node on the chain of cells containing `key`: a binary
    /// search over depths (the nodes on a chain exist from the root down to some
    /// depth, so "exists" is monotone), bounded by the deepest populated level.
    /// ≈ log2(depth) map lookups.
    pub(super) fn locate(&self, key: u64) -> u32 {
        let mut lo = 0u32; // the root always exists
        let mut hi = (0..=MAX_DEPTH)
            .rev()
            .find(|&d| self.per_depth[d as usize] > 0)
            .unwrap_or(0);
        let mut found = self.root;
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            match self.map.get(&(key >> (3 * (MAX_DEPTH - mid)))) {
                Some(&i) => {
                    lo = mid;
                    found = i;
                }
                None => hi = mid - 1,
            }
        }
        // `found` is always the node at depth `lo`.
        found
    }

    /// Goes down from node `i` toward `key` to the leaf containing it, creating the
    /// leaf where the path enters empty space.
    pub(super) fn descend_to_leaf(&mut self, mut i: u32, key: u64) -> u32 {
        loop {
            let n = &self.nodes[i];
            if n.leaf {
                return i;
            }
            let d = n.code.depth() + 1;
            let child_code = key >> (3 * (MAX_DEPTH - d));
            let c = n.children[(child_code & 7) as usize];
            if c == NONE {
                return self.new_node(LocationCode::from_raw_unchecked(child_code), i);
            }
            i = c;
        }
    }

    /// Puts the item at the end of leaf `leaf`'s list and records where it is.
    #[inline]
    pub(super) fn push_item(&mut self, leaf: u32, item: Item) {
        let items = &mut self.nodes[leaf].items;
        let slot = items.len() as u32;
        items.push(item);
        let o = self.obj_mut(item.handle);
        o.leaf = leaf;
        o.slot = slot;
        let (filter, key) = (o.filter, o.key);
        self.mark_octant(leaf, slot, key);
        self.widen_filters(leaf, filter);
    }

    /// Sets slot `slot`'s bit in the octant mask of leaf `leaf` that holds
    /// `key` (see `LinearOctree::octants`; nothing at [`MAX_DEPTH`] or from slot
    /// 64 on). The slot's bit must be clear in every mask. O(1).
    #[inline]
    pub(super) fn mark_octant(&mut self, leaf: u32, slot: u32, key: u64) {
        if let Some(k) = octant_of(key, self.nodes[leaf].code.depth()) {
            self.octants[leaf as usize][k] |= bit(slot as usize);
        }
    }

    /// Clears the slots of `slots` from every octant mask of leaf `leaf`.
    /// O(1).
    #[inline]
    pub(super) fn unmark_slots(&mut self, leaf: u32, slots: u64) {
        for m in &mut self.octants[leaf as usize] {
            *m &= !slots;
        }
    }

    /// Rebuilds leaf `leaf`'s octant masks from its items' keys. O(items).
    pub(super) fn remark_octants(&mut self, leaf: u32) {
        let n = &self.nodes[leaf];
        let d = n.code.depth();
        let mut octants = [0u64; 8];
        for (slot, it) in n.items.iter().take(64).enumerate() {
            if let Some(k) = octant_of(self.obj(it.handle).key, d) {
                octants[k] |= bit(slot);
            }
        }
        self.octants[leaf as usize] = octants;
    }

    /// ORs `filter` into the filter bits of `from` and its ancestors, stopping
    /// where they already hold it. O(depth), usually O(1).
    #[inline]
    pub(super) fn widen_filters(&mut self, mut from: u32, filter: Filter) {
        while from != NONE {
            let n = &mut self.nodes[from];
            let (g, m) = (n.groups | filter.group, n.masks | filter.mask);
            if (g, m) == (n.groups, n.masks) {
                return;
            }
            (n.groups, n.masks) = (g, m);
            from = n.parent;
        }
    }

    /// Removes the item at `slot` of `leaf` (swap-remove, fixing the moved item's
    /// slot) and returns it.
    #[inline]
    pub(super) fn take_item(&mut self, leaf: u32, slot: u32) -> Item {
        let n = &mut self.nodes[leaf];
        let last = n.items.len() - 1;
        let item = n.items.swap_remove(slot as usize);
        // The slot and the last one leave their masks; the item moved from
        // the last slot (if any) is marked at its new one.
        let moved = n.items.get(slot as usize).map(|m| m.handle);
        self.unmark_slots(leaf, bit(slot as usize) | bit(last));
        if let Some(moved) = moved {
            let o = self.obj_mut(moved);
            o.slot = slot;
            let key = o.key;
            self.mark_octant(leaf, slot, key);
        }
        item
    }

    #[inline]
    pub(super) fn obj_mut(&mut self, h: Handle) -> &mut Obj<T> {
        self.objects
            .get_mut(h)
            .expect("octree item names a live object")
    }

    #[inline]
    pub(super) fn obj(&self, h: Handle) -> &Obj<T> {
        self.objects
            .get(h)
            .expect("octree item names a live object")
    }

    /// Adds `delta` to the counts from `from` up to, not including, `stop` (`NONE`:
    /// through the root).
    #[inline]
    pub(super) fn add_count(&mut self, mut from: u32, stop: u32, delta: i32) {
        while from != stop && from != NONE {
            let n = &mut self.nodes[from];
            n.count = n.count.wrapping_add_signed(delta);
            from = n.parent;
        }
    }

    /// Raises `max_extent` from `from` upward to at least `ext`; stops at the first
    /// node already that large (its ancestors are too).
    #[inline]
    pub(super) fn grow_extent(&mut self, mut from: u32, ext: f32) {
        while from != NONE {
            let n = &mut self.nodes[from];
            if n.max_extent >= ext {
                return;
            }
            n.max_extent = ext;
            from = n.parent;
        }
    }

    /// Shrinks `max_extent` to the truth at node `from` (from its items or its
    /// children) and propagates upward while it changes. This is the only place the
    /// bounds shrink besides splits and merges: removals and moves call it when the
    /// object leaving a leaf may have been its largest.
    pub(super) fn refit_extent(&mut self, mut from: u32) {
        while from != NONE {
            let n = &self.nodes[from];
            let new = if n.leaf {
                n.items.iter().fold(0.0f32, |m, it| m.max(it.ext))
            } else {
                n.children
                    .iter()
                    .filter(|&&c| c != NONE)
                    .fold(0.0f32, |m, &c| m.max(self.nodes[c].max_extent))
            };
            if new == n.max_extent {
                return;
            }
            let parent = n.parent;
            self.nodes[from].max_extent = new;
            from = parent;
        }
    }

    /// Empties the tree (handles go stale, memory is released).
    pub(super) fn clear_all(&mut self) {
        self.objects = Arena::new();
        self.nodes = Pool::default();
        self.octants = Vec::new();
        self.map = Default::default();
        self.spare = Vec::new();
        self.per_depth = [0; MAX_DEPTH as usize + 1];
        self.counters = Default::default();
        self.inert = Default::default();
        self.root = self.new_node(LocationCode::ROOT, NONE);
    }
}

/// One axis of [`LinearOctree::child_halves`]: the low and high halves of a
/// cell at integer coordinate `c` (children at `2c` and `2c + 1`, of side
/// `size`, from the cube's `min`), each grown by `grow`.
#[inline(always)]
fn halves_on_axis(min: f32, c: u32, size: f32, grow: f32) -> [(f32, f32); 2] {
    let lo = min + (c * 2) as f32 * size;
    let hi = min + (c * 2 + 1) as f32 * size;
    [
        (lo - grow, (lo + size) + grow),
        (hi - grow, (hi + size) + grow),
    ]
}
