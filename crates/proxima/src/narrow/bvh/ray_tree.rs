//! [`RayBvh`]: a BVH laid out for ray casts only.

use super::options::BuildOptions;
use super::tree::{Bvh, Node};
use crate::geom::Aabb;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::{prepare_triangle, TriPacket};
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
    /// `b[0][axis]`: the children's min corners on `axis`; `b[1][axis]`: their
    /// max corners (one array, so a cast picks the near side by index, per ray,
    /// instead of by a select per node). Lanes past `len` hold the empty box
    /// (`+∞` min, `−∞` max): no ray enters them, so the slab test needs no lane
    /// mask.
    pub b: [[Vec4; 3]; 2],
    /// Child links: a node index, or `LEAF | leaf index`.
    pub child: [u32; 4],
    /// Number of children in use (2 to 4; the first lanes).
    pub len: u32,
}

impl RayNode {
    const EMPTY: RayNode = RayNode {
        b: [
            [Vec4::splat(f32::INFINITY); 3],
            [Vec4::splat(f32::NEG_INFINITY); 3],
        ],
        child: [0; 4],
        len: 0,
    };

    /// The box of lane `k`.
    pub fn lane(&self, k: usize) -> Aabb {
        Aabb {
            min: Vec3::new(self.b[0][0][k], self.b[0][1][k], self.b[0][2][k]),
            max: Vec3::new(self.b[1][0][k], self.b[1][1][k], self.b[1][2][k]),
        }
    }

    fn set_lane(&mut self, k: usize, b: &Aabb) {
        for a in 0..3 {
            self.b[0][a][k] = b.min[a];
            self.b[1][a][k] = b.max[a];
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
/// with their corners and normal (64 bytes each) and, four at a time, with the
/// pre-test's data in SIMD lanes (208 bytes per four), so a cast reads no index
/// and no vertex array. Casts use a precomputed inverse direction (one copy of
/// the descent per direction octant, whose slab sides are then fixed), an ordered
/// front-to-back descent pruned by the best hit, and a conservative `f32`
/// pre-test of four triangles at once before the exact watertight
/// [`ray_triangle`](crate::narrow::ray_triangle) on the survivors, nearest
/// first: the answers are exactly those of [`Bvh::cast_ray`] (and of brute force).
///
/// Memory: 128 bytes per node + about 135 bytes per triangle (at most
/// `leaf_size` triangles per leaf). After deforming the mesh, call
/// [`RayBvh::refit`]. A [`Mesh`](crate::narrow::Mesh) owns one, built on its
/// first cast; this type alone serves experiments with its layout.
#[derive(Clone, Debug)]
pub struct RayBvh {
    pub(crate) nodes: Vec<RayNode>,
    /// `[first triangle, count, first packet]` of each leaf (leaf order).
    pub(crate) leaves: Vec<[u32; 3]>,
    /// The pre-test data of each leaf's triangles, four per packet (the last
    /// packet of a leaf padded), leaf after leaf.
    pub(crate) packets: Vec<TriPacket>,
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
    /// Builds a [`Bvh<Aabb>`] down to one triangle per leaf with `options.split`,
    /// then re-lays it out for rays: a subtree of at most `options.leaf_size`
    /// triangles becomes one leaf where the surface-area cost model says testing
    /// its triangles is cheaper than descending (`Plan::sah` in the source), and the
    /// 4-wide nodes pull up the grandchildren of largest surface area. O(n log n).
    ///
    /// Fails with [`Error::InvalidParameter`] on `leaf_size == 0`.
    pub fn build(mesh: &TriMesh, options: BuildOptions) -> Result<RayBvh> {
        options.check()?;
        Ok(RayBvh::build_valid(mesh, options))
    }

    /// [`RayBvh::build`] with options already checked.
    pub(crate) fn build_valid(mesh: &TriMesh, options: BuildOptions) -> RayBvh {
        let bvh = Bvh::<Aabb>::build_valid(mesh, binary(options));
        RayBvh::with_plan(&bvh, mesh, &Plan::sah(&bvh, mesh, options.leaf_size))
    }

    /// [`RayBvh::build`] of `mesh`, the mesh `bvh` was built over, reusing `bvh`
    /// when it is the binary tree that build starts from (built with `options`'
    /// split rule and leaf size 1; the topology does not depend on the volume),
    /// so that only the O(n) layout remains: the same tree, unless `mesh` was
    /// deformed since, in which case it keeps the topology of the first vertices
    /// (as [`Bvh::refit`] does: as exact, maybe less tight).
    pub(crate) fn build_reusing<BV: BoundingVolume>(
        bvh: &Bvh<BV>,
        mesh: &TriMesh,
        options: BuildOptions,
    ) -> RayBvh {
        if bvh.options == binary(options) {
            RayBvh::with_plan(bvh, mesh, &Plan::sah(bvh, mesh, options.leaf_size))
        } else {
            RayBvh::build_valid(mesh, options)
        }
    }

    /// The ray layout of `bvh`'s topology over `mesh` (boxes recomputed from the
    /// vertices, whatever `bvh`'s volume): the same leaves. O(n).
    ///
    /// Fails with [`Error::MeshMismatch`] if `mesh` is not the one `bvh` was built
    /// (or last refit) over.
    pub fn from_bvh<BV: BoundingVolume>(bvh: &Bvh<BV>, mesh: &TriMesh) -> Result<RayBvh> {
        bvh.check_mesh(mesh)?;
        Ok(RayBvh::with_plan(bvh, mesh, &Plan::same(bvh)))
    }

    /// The tree of `plan` over `bvh`, the tree of `mesh`.
    fn with_plan<BV: BoundingVolume>(bvh: &Bvh<BV>, mesh: &TriMesh, plan: &Plan) -> RayBvh {
        let mut t = RayBvh {
            nodes: Vec::with_capacity(bvh.nodes.len() / 2 + 1),
            leaves: Vec::new(),
            packets: Vec::new(),
            root: Aabb::EMPTY,
            root_link: 0,
            tris: Vec::new(),
            corners: bvh.tris.clone(),
            ids: bvh.ids.clone(),
            n_vertices: mesh.vertices().len(),
        };
        t.root_link = t.collapse(&bvh.nodes, plan, 0);
        t.fit(mesh.vertices());
        t
    }

    /// Collapses the binary subtree at `old[i]` into 4-wide nodes (pre-order, so
    /// children have larger indices than parents), with the leaves of `plan`;
    /// returns its link.
    fn collapse<BV>(&mut self, old: &[Node<BV>], plan: &Plan, i: u32) -> u32 {
        if plan.leaf[i as usize] {
            let [s, n] = plan.range[i as usize];
            self.leaves.push([s, n, 0]);
            return LEAF | (self.leaves.len() - 1) as u32;
        }
        // Open internal children, largest first, until four lanes.
        let (l, r) = old[i as usize].children(i);
        let mut lanes = vec![l, r];
        while lanes.len() < 4 {
            let pick = lanes
                .iter()
                .enumerate()
                .filter(|(_, &c)| !plan.leaf[c as usize])
                .max_by(|a, b| plan.key[*a.1 as usize].total_cmp(&plan.key[*b.1 as usize]))
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
            node.child[k] = self.collapse(old, plan, c);
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
        self.packets.clear();
        for leaf in &mut self.leaves {
            leaf[2] = self.packets.len() as u32;
            let tris = &self.tris[leaf[0] as usize..(leaf[0] + leaf[1]) as usize];
            for chunk in tris.chunks(4) {
                // On the stack: `fit` runs on every refit of a deforming mesh.
                let mut v = [[Vec3A::ZERO; 3]; 4];
                for (d, t) in v.iter_mut().zip(chunk) {
                    *d = t.v;
                }
                self.packets.push(TriPacket::new(&v[..chunk.len()]));
            }
        }
        let leaf_box = |tris: &[RayTri], [s, n, _]: [u32; 3]| {
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
            + self.leaves.capacity() * 12
            + self.packets.capacity() * std::mem::size_of::<TriPacket>()
            + self.tris.capacity() * std::mem::size_of::<RayTri>()
            + self.corners.capacity() * 12
            + self.ids.capacity() * 4
    }
}

/// The binary tree a ray tree is planned from: `options` down to single triangles.
fn binary(options: BuildOptions) -> BuildOptions {
    BuildOptions {
        leaf_size: 1,
        ..options
    }
}

/// Relative cost of one packet pre-test (four triangles) in the surface-area
/// model of [`Plan::sah`] (the unit).
const COST_PACKET: f32 = 1.0;
/// Cost of a binary node: a 4-wide node tests about two binary levels at once,
/// for a bit less than a packet pre-test, so about half of it.
const COST_NODE: f32 = 0.4;
/// Fixed cost of visiting a leaf (its range, the candidate pass).
const COST_LEAF: f32 = 0.25;

/// How a binary tree becomes a ray tree: which binary nodes become leaves (with
/// their triangle range), and which internal children a 4-wide node opens first.
struct Plan {
    leaf: Vec<bool>,
    /// `[first triangle, count]` of each node's subtree (leaf order).
    range: Vec<[u32; 2]>,
    /// Opening priority of internal nodes (larger first).
    key: Vec<f32>,
}

impl Plan {
    /// `bvh`'s own leaves, children opened by [`BoundingVolume::size`].
    fn same<BV: BoundingVolume>(bvh: &Bvh<BV>) -> Plan {
        let n = &bvh.nodes;
        Plan {
            leaf: n.iter().map(|n| n.is_leaf()).collect(),
            range: n.iter().map(|n| [n.start, n.count]).collect(),
            key: n.iter().map(|n| n.bv.size()).collect(),
        }
    }

    /// The leaves the surface-area heuristic chooses (Goldsmith & Salmon, MacDonald
    /// & Booth): bottom-up, a subtree of at most `max_leaf` triangles becomes a leaf
    /// when `area · (COST_LEAF + COST_PACKET · ⌈count / 4⌉)` is no more than the cost
    /// of keeping it, `area · COST_NODE` plus its children's costs (the chance of a
    /// random ray hitting a box is proportional to its area). Children are opened by
    /// surface area. The areas are those of the nodes' boxes over `mesh`'s
    /// vertices, whatever `bvh`'s volume (for a `Bvh<Aabb>`, its own volumes).
    /// O(nodes).
    fn sah<BV: BoundingVolume>(bvh: &Bvh<BV>, mesh: &TriMesh, max_leaf: usize) -> Plan {
        let n = &bvh.nodes;
        let area = |b: &Aabb| {
            let e = b.extent();
            e.x * e.y + e.y * e.z + e.z * e.x
        };
        // The boxes bottom-up (children have larger indices): leaves from their
        // corners, parents as unions, as a `Bvh<Aabb>` fits them.
        let v = mesh.vertices();
        let mut boxes = vec![Aabb::EMPTY; n.len()];
        for i in (0..n.len()).rev() {
            boxes[i] = if n[i].is_leaf() {
                let mut b = Aabb::EMPTY;
                for t in &bvh.tris[n[i].triangle_range()] {
                    for &k in t {
                        b.min = b.min.min(v[k as usize]);
                        b.max = b.max.max(v[k as usize]);
                    }
                }
                b
            } else {
                let (l, r) = n[i].children(i as u32);
                boxes[l as usize].union(&boxes[r as usize])
            };
        }
        let mut p = Plan {
            leaf: vec![false; n.len()],
            range: vec![[0, 0]; n.len()],
            key: boxes.iter().map(area).collect(),
        };
        let mut cost = vec![0.0f32; n.len()];
        // Children have larger indices: a reverse sweep is bottom-up.
        for i in (0..n.len()).rev() {
            let a = p.key[i];
            if n[i].is_leaf() {
                p.leaf[i] = true;
                p.range[i] = [n[i].start, n[i].count];
                cost[i] = a * (COST_LEAF + COST_PACKET * n[i].count.div_ceil(4) as f32);
                continue;
            }
            let (l, r) = n[i].children(i as u32);
            let (l, r) = (l as usize, r as usize);
            // Pre-order: the left subtree's triangles come first.
            let count = p.range[l][1] + p.range[r][1];
            p.range[i] = [p.range[l][0], count];
            let keep = a * COST_NODE + cost[l] + cost[r];
            let merged = a * (COST_LEAF + COST_PACKET * count.div_ceil(4) as f32);
            if count as usize <= max_leaf && merged <= keep {
                p.leaf[i] = true;
                cost[i] = merged;
            } else {
                cost[i] = keep;
            }
        }
        p
    }
}
