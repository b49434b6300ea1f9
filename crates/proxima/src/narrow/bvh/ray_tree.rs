//! [`RayBvh`]: a BVH laid out for ray casts only.

use super::build::BuildOptions;
use super::tree::Bvh;
use crate::geom::Aabb;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::prepare_triangle;
use crate::narrow::TriMesh;
use crate::{Error, Result};
use glam::{Vec3, Vec3A, Vec4};

/// Marks a leaf in a child link: the low bits index `RayBvh::leaves`.
pub(crate) const LEAF: u32 = 1 << 31;

/// One node of the 4-wide tree: the boxes of up to four children side by side
/// (one SIMD lane per child, structure of arrays), so one slab test checks all
/// four with vertical operations only.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayNode {
    /// `lo[axis]`: the children's min corners on `axis`.
    pub lo: [Vec4; 3],
    /// `hi[axis]`: the children's max corners on `axis`.
    pub hi: [Vec4; 3],
    /// Child links: a node index, or `LEAF | leaf index`.
    pub child: [u32; 4],
    /// Number of children in use (2 to 4; the first lanes).
    pub len: u32,
}

impl RayNode {
    const EMPTY: RayNode = RayNode {
        lo: [Vec4::ZERO; 3],
        hi: [Vec4::ZERO; 3],
        child: [0; 4],
        len: 0,
    };

    /// The box of lane `k`.
    pub fn lane(&self, k: usize) -> Aabb {
        Aabb {
            min: Vec3::new(self.lo[0][k], self.lo[1][k], self.lo[2][k]),
            max: Vec3::new(self.hi[0][k], self.hi[1][k], self.hi[2][k]),
        }
    }

    fn set_lane(&mut self, k: usize, b: &Aabb) {
        for a in 0..3 {
            self.lo[a][k] = b.min[a];
            self.hi[a][k] = b.max[a];
        }
    }

    /// The union of the lanes in use.
    fn bounds(&self) -> Aabb {
        (0..self.len as usize).fold(Aabb::EMPTY, |b, k| b.union(&self.lane(k)))
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
/// The topology is a [`Bvh`]'s (any bounding volume, any split rule), collapsed
/// to a 4-wide tree for rays: each node holds the axis-aligned boxes of up to four
/// children in SIMD lanes (128 bytes), and the triangles are copied in leaf order
/// with their corners and normal (64 bytes each), so a cast reads no index and no
/// vertex array. Casts use a precomputed inverse direction, an ordered
/// front-to-back descent pruned by the best hit, and a conservative `f32`
/// pre-test before the exact watertight [`ray_triangle`](crate::narrow::ray_triangle):
/// the answers are exactly those of [`Bvh::cast_ray`] (and of brute force).
///
/// Memory: 128 bytes per node (about `2n / (3 leaf_size)` nodes) + 80 bytes per
/// triangle. After deforming the mesh, call [`RayBvh::refit`].
#[derive(Clone, Debug)]
pub struct RayBvh {
    pub(crate) nodes: Vec<RayNode>,
    /// `[first triangle, count]` of each leaf (leaf order).
    pub(crate) leaves: Vec<[u32; 2]>,
    /// The root's box (the ray first clips against it).
    pub(crate) root: Aabb,
    /// The root's link (a node, or a leaf for a one-leaf tree).
    pub(crate) root_link: u32,
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
        let mut t = RayBvh {
            nodes: Vec::with_capacity(bvh.nodes.len() / 2 + 1),
            leaves: Vec::new(),
            root: Aabb::EMPTY,
            root_link: 0,
            tris: Vec::new(),
            corners: bvh.tris.clone(),
            ids: bvh.ids.clone(),
            n_vertices: mesh.vertices().len(),
        };
        t.root_link = t.collapse(&bvh.nodes, 0);
        t.fit(mesh.vertices());
        Ok(t)
    }

    /// Collapses the binary subtree at `old[i]` into 4-wide nodes (pre-order, so
    /// children have larger indices than parents); returns its link.
    fn collapse<BV: BoundingVolume>(&mut self, old: &[super::Node<BV>], i: u32) -> u32 {
        let n = &old[i as usize];
        if n.is_leaf() {
            self.leaves.push([n.start, n.count]);
            return LEAF | (self.leaves.len() - 1) as u32;
        }
        // Open internal children, largest volume first, until four lanes.
        let (l, r) = n.children(i);
        let mut lanes = vec![l, r];
        while lanes.len() < 4 {
            let pick = lanes
                .iter()
                .enumerate()
                .filter(|(_, &c)| !old[c as usize].is_leaf())
                .max_by(|a, b| {
                    let size = |c: u32| old[c as usize].bv.size();
                    size(*a.1).total_cmp(&size(*b.1))
                })
                .map(|(k, _)| k);
            let Some(k) = pick else { break };
            let c = lanes.remove(k);
            let (cl, cr) = old[c as usize].children(c);
            lanes.insert(k, cr);
            lanes.insert(k, cl);
        }
        let idx = self.nodes.len();
        self.nodes.push(RayNode::EMPTY);
        let mut node = RayNode::EMPTY;
        node.len = lanes.len() as u32;
        for (k, &c) in lanes.iter().enumerate() {
            node.child[k] = self.collapse(old, c);
        }
        self.nodes[idx] = node;
        idx as u32
    }

    /// Recomputes the triangles and the boxes, bottom-up.
    fn fit(&mut self, vertices: &[Vec3]) {
        self.tris.clear();
        self.tris.extend(
            self.corners
                .iter()
                .map(|c| RayTri::new(c.map(|v| vertices[v as usize]))),
        );
        let leaf_box = |tris: &[RayTri], [s, n]: [u32; 2]| {
            let mut b = Aabb::EMPTY;
            for t in &tris[s as usize..(s + n) as usize] {
                for p in t.v {
                    b.min = b.min.min(p.into());
                    b.max = b.max.max(p.into());
                }
            }
            b
        };
        for i in (0..self.nodes.len()).rev() {
            let mut n = self.nodes[i];
            for k in 0..n.len as usize {
                let c = n.child[k];
                let b = if c & LEAF != 0 {
                    leaf_box(&self.tris, self.leaves[(c & !LEAF) as usize])
                } else {
                    self.nodes[c as usize].bounds()
                };
                n.set_lane(k, &b);
            }
            self.nodes[i] = n;
        }
        self.root = if self.root_link & LEAF != 0 {
            leaf_box(&self.tris, self.leaves[(self.root_link & !LEAF) as usize])
        } else {
            self.nodes[self.root_link as usize].bounds()
        };
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

    /// The box of everything (the root's).
    pub fn bounds(&self) -> Aabb {
        self.root
    }

    /// Heap bytes used.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<RayNode>()
            + self.leaves.capacity() * 8
            + self.tris.capacity() * std::mem::size_of::<RayTri>()
            + self.corners.capacity() * 12
            + self.ids.capacity() * 4
    }
}
