//! Read-only walk over the nodes, for pictures, debugging and tools.

use super::node::NIL;
use super::LooseKdTree;
use crate::geom::Aabb;

/// One node of a [`LooseKdTree`], as seen by [`LooseKdTree::for_each_node`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KdNodeView {
    /// Depth (root = 0).
    pub depth: usize,
    /// The node's (loose) box `B`: the world box narrowed by one face per split
    /// above, each face pushed outward by that split's border half-width.
    pub bbox: Aabb,
    /// Where the centres of the spheres routed through this node lie, clipped to
    /// the world box: the node's share of a partition of the world (the children's
    /// cells tile their parent's cell without overlap, unlike their boxes). Empty
    /// (`min > max` on some axis) only for a subtree holding nothing but spheres
    /// centred outside the world box.
    pub cell: Aabb,
    /// Split axis (0 = x, 1 = y, 2 = z): the longest axis of `bbox`.
    pub axis: usize,
    /// Split coordinate `m` on `axis` (the centre of `bbox`).
    pub mid: f32,
    /// Border half-width `h`: the children overlap in `[mid - h, mid + h]`.
    pub half_width: f32,
    /// Objects attached to this node itself (not below it).
    pub items: usize,
    /// Which children exist: `[negative, positive]`.
    pub children: [bool; 2],
}

impl<T> LooseKdTree<T> {
    /// Calls `f` for every live node, parents before their children (depth-first,
    /// negative child first). O(nodes); allocates one stack of at most the depth.
    ///
    /// This is how the figures of the tree [sources: figures] (node boxes and their shared
    /// border zones) can be drawn; it changes nothing.
    pub fn for_each_node(&self, mut f: impl FnMut(&KdNodeView)) {
        if self.root == NIL {
            return;
        }
        let mut stack = vec![self.root];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            let cell = Aabb::new(
                node.cell.min.max(self.world.min),
                node.cell.max.min(self.world.max),
            );
            f(&KdNodeView {
                depth: node.depth as usize,
                bbox: node.bbox,
                cell,
                axis: node.axis as usize,
                mid: node.m,
                half_width: node.h,
                items: node.len as usize,
                children: [node.child[0] != NIL, node.child[1] != NIL],
            });
            // Positive pushed first so the negative child is visited first.
            stack.extend(node.child.into_iter().rev().filter(|&c| c != NIL));
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::LooseKdConfig;
    use crate::broad::{LooseKdTree, SpatialIndex};
    use crate::geom::{Aabb, Sphere};
    use glam::Vec3;

    #[test]
    fn visitor_sees_every_node_and_item_once_with_tiling_cells() {
        let world = Aabb::new(Vec3::ZERO, Vec3::splat(64.0));
        let mut t = LooseKdTree::with_config(LooseKdConfig {
            density: 0.25,
            ..LooseKdConfig::new(world, 2.0)
        })
        .unwrap();
        let mut seed = 7u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        for i in 0..500u32 {
            let c = Vec3::new(next(), next(), next()) * 64.0;
            t.insert(Sphere::new(c, 0.1 + 2.5 * next()), i).unwrap();
        }
        let mut nodes = 0;
        let mut items = 0;
        let mut leaf_volume = 0.0f64;
        t.for_each_node(|v| {
            nodes += 1;
            items += v.items;
            assert!(v.bbox.contains_aabb(&v.cell) || v.cell.extent().min_element() <= 0.0);
            assert!(v.half_width > 0.0 && v.axis < 3);
            if v.children == [false, false] {
                let e = v.cell.extent().max(Vec3::ZERO);
                leaf_volume += (e.x * e.y * e.z) as f64;
            }
        });
        let s = t.stats();
        assert_eq!(nodes, s.nodes);
        assert_eq!(items, t.len());
        // Leaf cells never overlap, so their volumes add up to at most the world's.
        assert!(leaf_volume <= 64f64.powi(3) * 1.000_01, "{leaf_volume}");
    }
}
