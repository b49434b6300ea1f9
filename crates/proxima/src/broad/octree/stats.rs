//! Counters and structure statistics, and the memory estimate.

use super::node::Item;
use super::LinearOctree;
use std::mem::size_of;

/// Event counters kept by the tree (reset by `clear`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Counters {
    pub splits: u64,
    pub merges: u64,
    pub same_leaf_moves: u64,
    pub face_moves: u64,
    pub edge_corner_moves: u64,
    pub jump_moves: u64,
    pub neighbor_same_depth: u64,
    pub neighbor_up: u64,
    pub neighbor_down: u64,
}

/// What [`LinearOctree::stats`] reports: the shape of the tree now and what its
/// updates have done since it was created or cleared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OctreeStats {
    /// Stored objects.
    pub objects: usize,
    /// Nodes (inner and leaves), i.e. entries of the code → node map.
    pub nodes: usize,
    /// Leaves.
    pub leaves: usize,
    /// Depth of the deepest node.
    pub depth: u32,
    /// Leaf splits so far.
    pub splits: u64,
    /// Subtree merges so far.
    pub merges: u64,
    /// Moves whose centre stayed in its leaf (no lookup at all).
    pub same_leaf_moves: u64,
    /// Moves into the cell across one face, found with one
    /// [`face_neighbor`](super::LocationCode::face_neighbor) step and the map.
    pub face_moves: u64,
    /// Moves into a cell across an edge or a corner (two or three face steps).
    pub edge_corner_moves: u64,
    /// Moves farther than one cell: leaf found from the new centre's code by a
    /// search over depths.
    pub jump_moves: u64,
    /// Neighbour moves whose neighbour code was a node at the leaf's own depth
    /// (a leaf there, or the start of a descent).
    pub neighbor_same_depth: u64,
    /// Neighbour moves whose neighbour code was not in the map: resolved by going
    /// up to a larger cell.
    pub neighbor_up: u64,
    /// Neighbour moves whose neighbour code was an inner node: resolved by going
    /// down toward the centre to a smaller leaf.
    pub neighbor_down: u64,
}

impl<T> LinearOctree<T> {
    /// Structure statistics and update counters. O(nodes).
    pub fn stats(&self) -> OctreeStats {
        let c = self.counters;
        let mut leaves = 0;
        for &i in self.map.values() {
            leaves += self.nodes[i].leaf as usize;
        }
        OctreeStats {
            objects: self.objects.len(),
            nodes: self.map.len(),
            leaves,
            depth: (0..self.per_depth.len())
                .rev()
                .find(|&d| self.per_depth[d] > 0)
                .unwrap_or(0) as u32,
            splits: c.splits,
            merges: c.merges,
            same_leaf_moves: c.same_leaf_moves,
            face_moves: c.face_moves,
            edge_corner_moves: c.edge_corner_moves,
            jump_moves: c.jump_moves,
            neighbor_same_depth: c.neighbor_same_depth,
            neighbor_up: c.neighbor_up,
            neighbor_down: c.neighbor_down,
        }
    }

    /// Bytes held: the struct, the object arena, the node pool, the hash map's
    /// table (buckets of key + value plus one control byte each, as hashbrown
    /// lays it out), every leaf's item list, the leaves' octant masks and the
    /// spare lists (capacities).
    pub(super) fn memory(&self) -> usize {
        let map_buckets = if self.map.capacity() == 0 {
            0
        } else {
            (self.map.capacity() * 8 / 7).next_power_of_two()
        };
        let map_bytes = map_buckets * (size_of::<(u64, u32)>() + 1) + 16;
        let items: usize = self
            .map
            .values()
            .map(|&i| self.nodes[i].items.capacity() * size_of::<Item>())
            .sum();
        let spare: usize = self.spare.capacity() * size_of::<Vec<Item>>()
            + self
                .spare
                .iter()
                .map(|v| v.capacity() * size_of::<Item>())
                .sum::<usize>();
        size_of::<Self>()
            + self.objects.heap_bytes()
            + self.nodes.heap_bytes()
            + self.octants.capacity() * size_of::<[u64; 8]>()
            + map_bytes
            + items
            + spare
    }
}
