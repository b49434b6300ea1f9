//! The moving tree's volumes in one query of two posed meshes, shared by
//! collision ([`Collider`](crate::narrow::Collider)) and the distance queries
//! ([`Proximity`](crate::narrow::Proximity)): the rounding slack, and which of
//! the four sources gives the moved volumes (the pose inside the test, an exact
//! refit [sources: bvh-rotate], lazily transformed volumes, or those with exact
//! volumes near the leaves); each query then runs its own descent over the
//! chosen source ([`Descent`]).

use super::collide::RotationUpdate;
use super::mesh::Mesh;
use super::traverse::{ExactLeaves, Lazy, Local, Precomputed, VolumeSource};
use super::tree::Bvh;
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

impl<BV: BoundingVolume> LowerBounds<BV> for Lazy<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).distance_lower_bound_fixed(other)
    }
}

impl<BV: BoundingVolume> LowerBounds<BV> for ExactLeaves<'_, BV> {
    #[inline(always)]
    fn lower_bound(&mut self, i: usize, other: &BV) -> f32 {
        self.get(i).distance_lower_bound_fixed(other)
    }
}

/// Which moved volumes an axis-aligned tree takes under a rotated pose (each
/// query maps the user's [`RotationUpdate`] to one: [`Descent::moved`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Moved {
    /// Every node refitted to the posed vertices ([`Precomputed`]).
    Refit,
    /// The conservative [`BoundingVolume::transformed`] bound of each reached
    /// node ([`Lazy`]).
    Transformed,
    /// [`ExactLeaves`]: exact volumes for subtrees of at most `below`
    /// triangles, the transformed bound above.
    Exact {
        /// The subtree size up to which volumes are exact.
        below: u32,
    },
}

/// One query's descent over the moving tree, written once for every source of
/// its volumes (a generic method: each source is its own type, so each
/// descent is compiled per source, as if written out).
pub(crate) trait Descent<BV: BoundingVolume> {
    /// The moved volumes this query takes for `rotation` (chosen per query by
    /// instruction counts on W5). Inlined with constant answers, so that a
    /// query's code holds only the sources it may use.
    fn moved(rotation: RotationUpdate) -> Moved;

    /// Whether transformed volumes are the tight ones
    /// ([`BoundingVolume::transformed_tight`]): worth it where a better bound
    /// prunes more than it costs (distance), not for collision.
    const TIGHT: bool = false;

    /// Descends with the moving tree's volumes from `src`; the moving mesh's
    /// posed vertex `v` is `corner(v)` (`pose.transform_point3` of it, the same
    /// `f32` values whichever the source). The corner is a type parameter, not
    /// a `dyn`, so that the leaf tests inline it (W5 collision: 5% more
    /// instructions through a `&dyn Fn`).
    /// Returns whether the descent stopped early (collision's first contact).
    fn descend(self, src: &mut impl LowerBounds<BV>, corner: &impl Fn(u32) -> Vec3) -> bool;
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
    /// oriented volumes or a pose without rotation; else as
    /// [`Descent::moved`] says for `rotation`: an exact refit of every node,
    /// lazily transformed volumes, or those with exact volumes near the leaves.
    /// Returns the node updates (`Nu`) and whether the descent stopped early.
    #[inline]
    pub(crate) fn descend<D: Descent<BV>>(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        slack: f32,
        rotation: RotationUpdate,
        d: D,
    ) -> (u64, bool) {
        let (ta, va) = (a.bvh(), a.trimesh().vertices());
        let moved = |v: u32| pose.transform_point3(va[v as usize]);
        if !(BV::AXIS_ALIGNED && pose.matrix3 != Mat3A::IDENTITY) {
            let mut src = Local {
                nodes: &ta.nodes,
                motion: BV::motion(pose, slack),
            };
            return (0, d.descend(&mut src, &moved));
        }
        let MovingVolumes {
            world_vertices,
            world,
            cache,
        } = self;
        let moved_by = D::moved(rotation);
        if moved_by == Moved::Refit {
            world_vertices.clear();
            world_vertices.extend(va.iter().map(|&v| pose.transform_point3(v)));
            let nu = ta.world_volumes(world_vertices, slack, world);
            let wv: &[Vec3] = world_vertices;
            let stopped = d.descend(&mut Precomputed(world), &|v: u32| wv[v as usize]);
            return (nu, stopped);
        }
        cache.begin(ta.nodes.len(), ta.nodes[0].bv);
        let lazy = Lazy {
            nodes: &ta.nodes,
            pose: *pose,
            slack,
            cache,
            updates: 0,
            tight: D::TIGHT,
        };
        if let Moved::Exact { below } = moved_by {
            let mut src = ExactLeaves {
                lazy,
                tris: &ta.tris,
                vertices: va,
                sizes: &ta.subtree,
                below,
            };
            let stopped = d.descend(&mut src, &moved);
            (src.lazy.updates, stopped)
        } else {
            let mut src = lazy;
            let stopped = d.descend(&mut src, &moved);
            (src.updates, stopped)
        }
    }
}
