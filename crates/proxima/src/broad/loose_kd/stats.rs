//! Shape statistics and per-object placement, for tuning, tests and tools.

use super::node::NIL;
use super::LooseKdTree;
use crate::geom::Aabb;
use crate::Handle;
use crate::Result;

/// Shape of a [`LooseKdTree`] (see [`LooseKdTree::stats`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KdStats {
    /// Live nodes.
    pub nodes: usize,
    /// Nodes without children.
    pub leaves: usize,
    /// Depth of the deepest node (root = 0; 0 also for an empty tree).
    pub max_depth: usize,
    /// `items_per_depth[k]`: objects attached to nodes at depth `k`.
    pub items_per_depth: Vec<usize>,
    /// Largest number of objects attached to one node.
    pub max_items_per_node: usize,
}

/// Where one object sits (see [`LooseKdTree::placement`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Depth of its node (root = 0).
    pub depth: usize,
    /// The node's box `B`.
    pub node_box: Aabb,
    /// The node's split axis (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// The node's split centre `m`.
    pub mid: f32,
    /// The node's border half-width `h`.
    pub half_width: f32,
}

impl<T> LooseKdTree<T> {
    /// Node count, leaves, depth and the distribution of objects over depths.
    /// O(nodes).
    pub fn stats(&self) -> KdStats {
        let mut s = KdStats::default();
        if self.root == NIL {
            return s;
        }
        let mut stack = vec![self.root];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            let d = node.depth as usize;
            s.nodes += 1;
            s.max_depth = s.max_depth.max(d);
            if s.items_per_depth.len() <= d {
                s.items_per_depth.resize(d + 1, 0);
            }
            s.items_per_depth[d] += node.len as usize;
            s.max_items_per_node = s.max_items_per_node.max(node.len as usize);
            if node.child == [NIL, NIL] {
                s.leaves += 1;
            }
            stack.extend(node.child.into_iter().filter(|&c| c != NIL));
        }
        s
    }

    /// The node an object is attached to. O(1). Errors on a stale handle.
    pub fn placement(&self, handle: Handle) -> Result<Placement> {
        let loc = self.items.get(handle)?;
        let n = &self.nodes[loc.node];
        Ok(Placement {
            depth: n.depth as usize,
            node_box: n.bbox,
            axis: n.axis as usize,
            mid: n.m,
            half_width: n.h,
        })
    }
}
