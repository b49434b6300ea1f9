//! The BVH: one flat array of small nodes, children by index (Box2D / parry style).

use super::options::BuildOptions;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::trimesh::MeshStamp;
use crate::narrow::TriMesh;
use crate::{Error, Result};

/// One node: its volume and either its triangle range (leaf) or its right child.
///
/// Nodes are stored in depth-first pre-order, so the left child of internal node `i`
/// is `i + 1` and every child has a larger index than its parent (a reverse sweep is
/// a bottom-up pass).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node<BV> {
    /// The bounding volume of every triangle below the node.
    pub bv: BV,
    /// Leaf: first position in the BVH's triangle order. Internal: right child.
    pub(crate) start: u32,
    /// Leaf: number of triangles (`>= 1`). Internal: `0`.
    pub(crate) count: u32,
}

impl<BV> Node<BV> {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count != 0
    }

    /// For an internal node at index `i`: its two children.
    #[inline]
    pub fn children(&self, i: u32) -> (u32, u32) {
        (i + 1, self.start)
    }

    /// For a leaf: the range of positions in [`Bvh::triangle_order`].
    #[inline]
    pub fn triangle_range(&self) -> std::ops::Range<usize> {
        self.start as usize..(self.start + self.count) as usize
    }
}

/// A binary bounding-volume hierarchy over the triangles of a [`TriMesh`],
/// generic over the [`BoundingVolume`]: the low-level tree that a
/// [`Mesh`](crate::narrow::Mesh) owns, for experiments with volumes and split
/// rules over one separate `TriMesh`.
///
/// The tree keeps its own copy of the triangles' vertex indices, permuted so that
/// each leaf covers a contiguous range, and reads vertex *positions* from the mesh
/// at query time: every call that takes the mesh fails with
/// [`Error::MeshMismatch`] unless it is the mesh the tree was built over (or a
/// clone), with the vertices of the last build or [`Bvh::refit`]. Built by
/// [`Bvh::build`] (top-down, binary: [sources: bvh-build]).
#[derive(Clone, Debug)]
pub struct Bvh<BV> {
    pub(crate) nodes: Vec<Node<BV>>,
    /// Vertex-index triples in leaf order.
    pub(crate) tris: Vec<[u32; 3]>,
    /// `ids[k]`: index in the mesh of `tris[k]`.
    pub(crate) ids: Vec<u32>,
    /// `subtree[i]`: the number of triangles below node `i`.
    pub(crate) subtree: Vec<u32>,
    /// The mesh (and its vertex version) the volumes were fitted to.
    pub(crate) mesh: MeshStamp,
    /// Max over vertices of `|x| + |y| + |z|` (for the rounding slack).
    pub(crate) coord_bound: f32,
    pub(crate) options: BuildOptions,
}

impl<BV: BoundingVolume> Bvh<BV> {
    /// The nodes, root first (pre-order).
    pub fn nodes(&self) -> &[Node<BV>] {
        &self.nodes
    }

    /// The root volume.
    pub fn root(&self) -> &BV {
        &self.nodes[0].bv
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Mesh triangle index at each leaf-order position.
    pub fn triangle_order(&self) -> &[u32] {
        &self.ids
    }

    /// The options the tree was built with.
    pub fn options(&self) -> BuildOptions {
        self.options
    }

    /// Depth of the tree (a single leaf has depth 1). O(nodes).
    pub fn depth(&self) -> usize {
        let mut depth = vec![0usize; self.nodes.len()];
        depth[0] = 1;
        let mut best = 1;
        for (i, n) in self.nodes.iter().enumerate() {
            if !n.is_leaf() {
                let (l, r) = n.children(i as u32);
                depth[l as usize] = depth[i] + 1;
                depth[r as usize] = depth[i] + 1;
                best = best.max(depth[i] + 1);
            }
        }
        best
    }

    /// Checks that `mesh` is the one the tree was built over, with the vertices
    /// its volumes were last fitted to. O(1).
    pub(crate) fn check_mesh(&self, mesh: &TriMesh) -> Result<()> {
        let s = mesh.stamp();
        // Geometry stamps are never reused: equal ones mean the same topology too.
        if s.geometry == self.mesh.geometry {
            return Ok(());
        }
        if s.topology != self.mesh.topology {
            return Err(Error::MeshMismatch(
                "the BVH was built over another mesh".into(),
            ));
        }
        Err(Error::MeshMismatch(
            "the mesh's vertices changed since the BVH was built or refit (refit it)".into(),
        ))
    }
}

/// The number of triangles below each node (one reverse sweep of the pre-order
/// array: children come after their parent).
pub(crate) fn subtree_sizes<BV>(nodes: &[Node<BV>]) -> Vec<u32> {
    let mut n = vec![0u32; nodes.len()];
    for i in (0..nodes.len()).rev() {
        n[i] = if nodes[i].is_leaf() {
            nodes[i].count
        } else {
            let (l, r) = nodes[i].children(i as u32);
            n[l as usize] + n[r as usize]
        };
    }
    n
}

/// Max over `vertices` of `|x| + |y| + |z|`.
pub(crate) fn coord_bound(vertices: &[glam::Vec3]) -> f32 {
    vertices
        .iter()
        .map(|v| v.abs().element_sum())
        .fold(0.0f32, f32::max)
}
