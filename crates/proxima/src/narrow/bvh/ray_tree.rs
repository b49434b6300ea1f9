//! [`RayBvh`]: a BVH laid out for ray casts only.

use super::build::BuildOptions;
use super::tree::Bvh;
use crate::geom::Aabb;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::prepare_triangle;
use crate::narrow::TriMesh;
use crate::{Error, Result};
use glam::{Vec3, Vec3A, Vec4};

/// One node, 32 bytes: the box, with the links in the spare fourth lanes (as
/// `f32::from_bits`), so one 64-byte line holds both children of a node.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayNode {
    /// Min corner; `w`: first child (internal) or first triangle (leaf).
    pub lo: Vec4,
    /// Max corner; `w`: 0 (internal) or triangle count (leaf).
    pub hi: Vec4,
}

impl RayNode {
    fn new(b: &Aabb, link: u32, count: u32) -> RayNode {
        RayNode {
            lo: b.min.extend(f32::from_bits(link)),
            hi: b.max.extend(f32::from_bits(count)),
        }
    }

    /// First child (internal) or first triangle (leaf).
    #[inline(always)]
    pub fn link(&self) -> u32 {
        self.lo.w.to_bits()
    }

    /// Triangle count; 0 for an internal node.
    #[inline(always)]
    pub fn count(&self) -> u32 {
        self.hi.w.to_bits()
    }

    #[inline(always)]
    pub fn aabb(&self) -> Aabb {
        Aabb {
            min: self.lo.truncate(),
            max: self.hi.truncate(),
        }
    }
}

/// One triangle in leaf order, 64 bytes: its corners and, for the `f32` pre-test,
/// its normal `(v0 − v1) × (v2 − v0)` with the edges' L1 bound in `w`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayTri {
    pub v: [Vec3A; 3],
    pub ng: Vec4,
}

impl RayTri {
    fn new(t: [Vec3; 3]) -> RayTri {
        let v = t.map(Vec3A::from);
        let (_, _, ng, l1) = prepare_triangle(&v);
        RayTri {
            v,
            ng: ng.extend(l1),
        }
    }
}

/// A bounding-volume hierarchy specialized for ray and segment casts against one
/// triangle mesh.
///
/// The topology is a [`Bvh`]'s (any bounding volume, any split rule), re-laid out
/// for rays: axis-aligned boxes only, the two children of a node side by side
/// (32-byte nodes, one cache line per pair), and the triangles copied in leaf order
/// with their corners and normal (64 bytes each), so a cast reads no index and no
/// vertex array. Casts use a precomputed inverse direction, an ordered
/// front-to-back descent pruned by the best hit, and a conservative `f32`
/// pre-test before the exact watertight [`ray_triangle`](crate::narrow::ray_triangle):
/// the answers are exactly those of [`Bvh::cast_ray`] (and of brute force).
///
/// Memory: 32 bytes per node (about `2n / leaf_size` nodes) + 80 bytes per
/// triangle. After deforming the mesh, call [`RayBvh::refit`].
#[derive(Clone, Debug)]
pub struct RayBvh {
    pub(crate) nodes: Vec<RayNode>,
    pub(crate) tris: Vec<RayTri>,
    /// Vertex-index triples in leaf order (for refit).
    pub(crate) corners: Vec<[u32; 3]>,
    /// `ids[k]`: mesh index of leaf-order triangle `k`.
    pub(crate) ids: Vec<u32>,
    pub(crate) n_vertices: usize,
}

impl RayBvh {
    /// Builds a [`Bvh<Aabb>`] with `options` (SAH with 4 triangles per leaf is a
    /// good choice for rays) and re-lays it out for rays. O(n log n).
    ///
    /// Fails on `leaf_size == 0`.
    pub fn build(mesh: &TriMesh, options: BuildOptions) -> Result<RayBvh> {
        RayBvh::from_bvh(&Bvh::<Aabb>::build(mesh, options)?, mesh)
    }

    /// The ray layout of `bvh`'s topology over `mesh` (boxes recomputed from the
    /// vertices, whatever `bvh`'s volume). O(n).
    ///
    /// Fails if `mesh` has a different vertex count from the one `bvh` was built on.
    pub fn from_bvh<BV: BoundingVolume>(bvh: &Bvh<BV>, mesh: &TriMesh) -> Result<RayBvh> {
        bvh.check_vertices(mesh.vertices().len())?;
        let old = &bvh.nodes;
        let placeholder = RayNode::new(&Aabb::EMPTY, 0, 0);
        let mut nodes = vec![placeholder; old.len()];
        let mut next = 1u32;
        // (old index, new index); children pairs are allocated when their parent is
        // visited, so every child has a larger index than its parent.
        let mut stack = vec![(0u32, 0u32)];
        while let Some((oi, ni)) = stack.pop() {
            let n = &old[oi as usize];
            if n.is_leaf() {
                nodes[ni as usize] = RayNode::new(&Aabb::EMPTY, n.start, n.count);
            } else {
                let (l, r) = n.children(oi);
                nodes[ni as usize] = RayNode::new(&Aabb::EMPTY, next, 0);
                stack.push((r, next + 1));
                stack.push((l, next));
                next += 2;
            }
        }
        let mut t = RayBvh {
            nodes,
            tris: Vec::new(),
            corners: bvh.tris.clone(),
            ids: bvh.ids.clone(),
            n_vertices: mesh.vertices().len(),
        };
        t.fit(mesh.vertices());
        Ok(t)
    }

    /// Recomputes the triangles and the boxes, bottom-up.
    fn fit(&mut self, vertices: &[Vec3]) {
        self.tris.clear();
        self.tris.extend(
            self.corners
                .iter()
                .map(|c| RayTri::new(c.map(|v| vertices[v as usize]))),
        );
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            let count = n.count();
            let mut b = Aabb::EMPTY;
            if count > 0 {
                let s = n.link() as usize;
                for t in &self.tris[s..s + count as usize] {
                    for p in t.v {
                        b.min = b.min.min(p.into());
                        b.max = b.max.max(p.into());
                    }
                }
            } else {
                let c = n.link() as usize;
                b = self.nodes[c].aabb().union(&self.nodes[c + 1].aabb());
            }
            self.nodes[i] = RayNode::new(&b, n.link(), count);
        }
    }

    /// Refits to new vertex positions (same count, e.g. a deformed mesh), keeping
    /// the topology. O(n). Fails, changing nothing, on a count mismatch or a
    /// non-finite vertex.
    pub fn refit(&mut self, vertices: &[Vec3]) -> Result<()> {
        if vertices.len() != self.n_vertices {
            return Err(Error::InvalidMesh(format!(
                "ray BVH was built over {} vertices, got {}",
                self.n_vertices,
                vertices.len()
            )));
        }
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidMesh(format!("vertex {i} is not finite")));
        }
        self.fit(vertices);
        Ok(())
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Mesh triangle index at each leaf-order position.
    pub fn triangle_order(&self) -> &[u32] {
        &self.ids
    }

    /// The box of every node, root first (for inspection and tests).
    pub fn boxes(&self) -> impl Iterator<Item = Aabb> + '_ {
        self.nodes.iter().map(RayNode::aabb)
    }

    /// Heap bytes used.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<RayNode>()
            + self.tris.capacity() * std::mem::size_of::<RayTri>()
            + self.corners.capacity() * 12
            + self.ids.capacity() * 4
    }
}
