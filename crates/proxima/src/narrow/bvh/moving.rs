//! The moving tree's volumes in one query of two posed meshes, shared by
//! collision ([`Collider`](crate::narrow::Collider)) and the distance queries
//! ([`Proximity`](crate::narrow::Proximity)): the rounding slack, and which of
//! the four sources gives the moved volumes (the pose inside the test, an exact
//! refit [sources: bvh-rotate], lazily transformed volumes, or those with exact
//! volumes near the leaves); each query then runs its own descent over the
//! chosen source ([`Descent`]).

use super::collide::RotationUpdate;
use super::mesh::Mesh;
use super::traverse::{Lazy, Local, Precomputed, VolumeSource};
use super::tree::{Bvh, Node};
use super::tri_cache::QueryCache;
use crate::narrow::bv::{slack_for, BoundingVolume};
use glam::{Affine3A, Mat3A, Vec3};

/// The rounding slack of a query of `a` moved by `pose` (whose matrix deviates
/// from a rotation by `dev`) against `b`: [`slack_for`] the largest
/// `|x| + |y| + |z|` of any point involved (moved or fixed, and their
/// differences). O(1).
#[inline]
pub(crate) fn query_slack<BV>(a: &Bvh<BV>, pose: &Affine3A, dev: f32, b: &Bvh<BV>) -> f32 {
    let t1 = Vec3::from(pose.translation).abs().element_sum();
    let scale = 2.0 * (1.8 * a.coord_bound * (1.0 + dev) + t1 + b.coord_bound);
    slack_for(scale, dev)
}

/// A [`VolumeSource`] that also bounds distances.
pub(crate) trait LowerBounds<BV>: VolumeSource<BV> {
    /// A lower bound on the distance between node `i` of the moving tree (moved)
    /// and `other` (a fixed-tree volume); `0` if they may overlap.
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32;
}

impl<BV: BoundingVolume> LowerBounds<BV> for Local<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.nodes[i].bv.distance_lower_bound(&self.motion, other)
    }
}

impl<BV: BoundingVolume> LowerBounds<BV> for Precomputed<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.0[i].distance_lower_bound_fixed(other)
    }
}

/// Volumes moved into the fixed frame (and enlarged by the slack) on first use,
/// by [`Lazy`] or [`ExactLeaves`].
trait Posed<BV> {
    /// Node `i`'s moved volume.
    fn posed(&mut self, i: usize) -> &BV;
}

/// A [`Posed`] source as a [`VolumeSource`]: its tests are those of two volumes
/// in one frame.
struct InFixedFrame<P>(P);

impl<BV: BoundingVolume, P: Posed<BV>> VolumeSource<BV> for InFixedFrame<P> {
    #[inline(always)]
    fn overlaps(&mut self, i: usize, other: &BV) -> bool {
        self.0.posed(i).overlaps_fixed(other)
    }
    #[inline(always)]
    fn size(&mut self, i: usize) -> f32 {
        self.0.posed(i).size()
    }
}

impl<BV: BoundingVolume, P: Posed<BV>> LowerBounds<BV> for InFixedFrame<P> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.0.posed(i).distance_lower_bound_fixed(other)
    }
}

impl<BV: BoundingVolume> Posed<BV> for Lazy<'_, BV> {
    #[inline(always)]
    fn posed(&mut self, i: usize) -> &BV {
        self.get(i)
    }
}

/// Subtrees of at most this many triangles get exact moved volumes in
/// [`ExactLeaves`].
const EXACT_BELOW: usize = 8;

/// The number of triangles below node `i`: its subtree covers the contiguous
/// leaf-order range from its leftmost leaf's start to its rightmost leaf's end.
/// O(depth of the subtree).
fn subtree_len<BV>(nodes: &[Node<BV>], i: usize) -> usize {
    let mut lo = i;
    while !nodes[lo].is_leaf() {
        lo += 1; // left child
    }
    let mut hi = i;
    while !nodes[hi].is_leaf() {
        hi = nodes[hi].children(hi as u32).1 as usize;
    }
    nodes[hi].triangle_range().end - nodes[lo].triangle_range().start
}

/// [`Lazy`] with exact volumes near the leaves: a leaf's volume is fitted to its
/// triangles' posed corners (`f32`, as the triangle tests see them), an internal
/// node with a small subtree (at most [`EXACT_BELOW`] triangles) merges its
/// children's, a larger one takes the conservative
/// [`BoundingVolume::transformed`] bound; all enlarged by the slack and computed
/// on first use (one node update each).
///
/// Distance queries are decided near the leaves, where the transformed bound of
/// a rotated k-DOP is loosest relative to its content (up to `√3` times its
/// size): exact volumes there cost three vertex transforms per reached leaf and
/// roughly halve the pairs a near-miss query visits.
struct ExactLeaves<'a, BV> {
    lazy: Lazy<'a, BV>,
    tris: &'a [[u32; 3]],
    vertices: &'a [Vec3],
}

impl<BV: BoundingVolume> ExactLeaves<'_, BV> {
    fn get(&mut self, i: usize) -> &BV {
        if self.lazy.cache.is_set(i) {
            return self.lazy.get(i);
        }
        let nodes = self.lazy.nodes;
        let n = &nodes[i];
        if n.is_leaf() {
            self.lazy.updates += 1;
            let (pose, slack, tris, verts) =
                (&self.lazy.pose, self.lazy.slack, self.tris, self.vertices);
            return self.lazy.cache.get(i, || {
                let mut range = n.triangle_range();
                let corners = |k: usize| tris[k].map(|v| pose.transform_point3(verts[v as usize]));
                let mut bv = BV::from_points(&corners(range.next().unwrap_or(0)));
                for k in range {
                    bv = bv.merge(&BV::from_points(&corners(k)));
                }
                bv.inflated(slack)
            });
        }
        if subtree_len(nodes, i) > EXACT_BELOW {
            return self.lazy.get(i);
        }
        // A small subtree: the merge of the children's (exact) volumes.
        let (l, r) = n.children(i as u32);
        let left = *self.get(l as usize);
        let merged = left.merge(self.get(r as usize));
        self.lazy.updates += 1;
        self.lazy.cache.get(i, || merged)
    }
}

impl<BV: BoundingVolume> Posed<BV> for ExactLeaves<'_, BV> {
    #[inline]
    fn posed(&mut self, i: usize) -> &BV {
        self.get(i)
    }
}

/// What [`RotationUpdate::Auto`] means for a kind of query (chosen per kind by
/// instruction counts on W5; see [`RotationUpdate::Auto`] and
/// [`Proximity::rotation`](crate::narrow::Proximity::rotation)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AutoUpdate {
    /// As [`RotationUpdate::Conservative`] (collision).
    Conservative,
    /// [`RotationUpdate::Conservative`] above subtrees of at most
    /// [`EXACT_BELOW`] triangles, exact volumes of the posed triangles below
    /// (distance).
    ExactLeaves,
}

/// One query's descent over the moving tree, written once for every source of
/// its volumes (a generic method: each source is its own type, so each
/// descent is compiled per source, as if written out).
pub(crate) trait Descent<BV: BoundingVolume> {
    /// What [`RotationUpdate::Auto`] means for this query (a constant, so that
    /// a query's code holds only the sources it may use).
    const AUTO: AutoUpdate;

    /// Descends with the moving tree's volumes from `src`; the moving mesh's
    /// posed vertex `v` is `corner(v)` (`pose.transform_point3` of it, the same
    /// `f32` values whichever the source). The corner is a type parameter, not
    /// a `dyn`, so that the leaf tests inline it (W5 collision: 5% more
    /// instructions through a `&dyn Fn`).
    fn descend(self, src: &mut impl LowerBounds<BV>, corner: &impl Fn(u32) -> Vec3);
}

/// The scratch space of the moving volumes (kept by the query objects: no
/// allocation per query once warmed up).
#[derive(Clone, Debug)]
pub(crate) struct MovingVolumes<BV> {
    world_vertices: Vec<Vec3>,
    world: Vec<BV>,
    cache: QueryCache<BV>,
}

impl<BV> Default for MovingVolumes<BV> {
    fn default() -> Self {
        MovingVolumes {
            world_vertices: Vec::new(),
            world: Vec::new(),
            cache: QueryCache::default(),
        }
    }
}

impl<BV: BoundingVolume> MovingVolumes<BV> {
    /// Runs `d` over mesh `a` moved by `pose`, its volumes enlarged by `slack`
    /// and taken from: the pose inside each test ([`BoundingVolume::motion`]) for
    /// oriented volumes or a pose without rotation; else, by `rotation`
    /// (`Auto` as [`Descent::AUTO`] says), an exact refit of every node, lazily transformed
    /// volumes, or those with exact volumes near the leaves. Returns the node
    /// updates (`Nu`).
    #[inline]
    pub(crate) fn descend<D: Descent<BV>>(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        slack: f32,
        rotation: RotationUpdate,
        d: D,
    ) -> u64 {
        let (ta, va) = (a.bvh(), a.trimesh().vertices());
        let moved = |v: u32| pose.transform_point3(va[v as usize]);
        if !(BV::AXIS_ALIGNED && pose.matrix3 != Mat3A::IDENTITY) {
            let mut src = Local {
                nodes: &ta.nodes,
                motion: BV::motion(pose, slack),
            };
            d.descend(&mut src, &moved);
            return 0;
        }
        let MovingVolumes {
            world_vertices,
            world,
            cache,
        } = self;
        if rotation == RotationUpdate::Refit {
            world_vertices.clear();
            world_vertices.extend(va.iter().map(|&v| pose.transform_point3(v)));
            let nu = ta.world_volumes(world_vertices, slack, world);
            let wv: &[Vec3] = world_vertices;
            d.descend(&mut Precomputed(world), &|v: u32| wv[v as usize]);
            return nu;
        }
        cache.begin(ta.nodes.len(), ta.nodes[0].bv);
        let lazy = Lazy {
            nodes: &ta.nodes,
            pose: *pose,
            slack,
            cache,
            updates: 0,
        };
        if D::AUTO == AutoUpdate::ExactLeaves && rotation == RotationUpdate::Auto {
            let mut src = InFixedFrame(ExactLeaves {
                lazy,
                tris: &ta.tris,
                vertices: va,
            });
            d.descend(&mut src, &moved);
            src.0.lazy.updates
        } else {
            let mut src = InFixedFrame(lazy);
            d.descend(&mut src, &moved);
            src.0.updates
        }
    }
}
