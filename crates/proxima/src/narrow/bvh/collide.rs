//! Collision of two posed meshes ([`Mesh::collide`], [`Collider`]): simultaneous
//! traversal of their BVHs down to exact triangle–triangle tests, with the cost
//! counters of [sources: bvh-cost].

use super::mesh::Mesh;
use super::traverse::{traverse, ExactLeaves, Lazy, Local, Precomputed, Terminal};
use super::tri_cache::{QueryCache, TriangleCache};
use crate::narrow::bv::{slack_for, BoundingVolume};
use crate::narrow::PreparedTriangle;
use crate::{Error, Result};
use glam::{Affine3A, Mat3A, Vec3};

/// A caller's triangle predicate ([`Collider::all_pairs_with`]).
type TriangleTest<'f> = dyn Fn(&[Vec3; 3], &[Vec3; 3]) -> bool + 'f;

/// Largest accepted deviation of `RᵀR` from the identity (per entry).
const MAX_POSE_DEVIATION: f32 = 1e-3;

/// How axis-aligned volumes (AABB, k-DOPs) follow a rotated pose. Oriented volumes
/// (OBB, sphere) ignore this: their test takes the pose directly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RotationUpdate {
    /// Currently [`RotationUpdate::Conservative`] for every query. Chosen from the
    /// W5 benchmark (`proxima-bench w5 --rotation ...`): since triangle pairs are
    /// tested through [`PreparedTriangle`](crate::narrow::PreparedTriangle), the
    /// extra pair tests of the looser volumes cost less than refitting every node
    /// (rob vs env, k-DOP18 all pairs: 34 µs mean conservative vs 40–43 µs refit;
    /// teapot and hand-vs-forearm, ~2,000-node trees: ~1 µs vs 47 µs median).
    #[default]
    Auto,
    /// The source's method [sources: bvh-rotate]: transform the moving mesh's
    /// vertices and recompute every node's volume bottom-up (exact; `Nu` = number of nodes).
    Refit,
    /// Bound each visited node's rotated volume from its own AABB part
    /// ([`BoundingVolume::transformed`]), lazily: looser volumes, but only the nodes
    /// the traversal reaches are updated (`Nu` = visited nodes of the moving tree).
    Conservative,
}

/// The cost counters of [sources: bvh-cost]: `T = Nv*Cv + Np*Cp + Nu*Cu`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CostCounters {
    /// Bounding-volume pair tests (`Nv`).
    pub nv: u64,
    /// Triangle pair tests (`Np`).
    pub np: u64,
    /// Node volume updates for the pose (`Nu`).
    pub nu: u64,
}

/// Every intersecting triangle pair of a query.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Contacts {
    /// `(triangle of the first mesh, triangle of the second)`, each pair once, in
    /// traversal order.
    pub pairs: Vec<(u32, u32)>,
    /// Cost counters of the query.
    pub counters: CostCounters,
}

/// The result of a first-contact query.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstContact {
    /// An intersecting triangle pair, if any (the first the traversal met).
    pub pair: Option<(u32, u32)>,
    /// Cost counters of the query.
    pub counters: CostCounters,
}

/// Reusable scratch space and settings for mesh–mesh queries (no allocation per
/// query once warmed up): the form of [`Mesh::collide`] for a loop of queries.
/// One collider serves any meshes, one query at a time.
#[derive(Clone, Debug)]
pub struct Collider<BV> {
    /// How axis-aligned volumes follow rotations.
    pub rotation: RotationUpdate,
    world_vertices: Vec<Vec3>,
    world: Vec<BV>,
    cache: QueryCache<BV>,
    stack: Vec<(u32, u32)>,
    /// Prepared triangles of the moving mesh (world frame) and of the fixed one.
    tris_a: TriangleCache,
    tris_b: TriangleCache,
}

impl<BV: BoundingVolume> Default for Collider<BV> {
    /// A collider with [`RotationUpdate::Auto`].
    fn default() -> Self {
        Collider::new(RotationUpdate::Auto)
    }
}

impl<BV: BoundingVolume> Mesh<BV> {
    /// Every intersecting triangle pair of this mesh moved by `pose` and `other`
    /// (at the identity): [`Collider::all_pairs`] with a new collider
    /// ([`RotationUpdate::Auto`]), whose scratch space is allocated for this one
    /// query; keep a [`Collider`] for repeated queries.
    pub fn collide(&self, pose: &Affine3A, other: &Mesh<BV>) -> Result<Contacts> {
        Collider::new(RotationUpdate::Auto).all_pairs(self, pose, other)
    }

    /// Whether this mesh moved by `pose` and `other` intersect, with an early exit:
    /// [`Collider::first_contact`] with a new collider (see [`Mesh::collide`]).
    pub fn collide_first(&self, pose: &Affine3A, other: &Mesh<BV>) -> Result<FirstContact> {
        Collider::new(RotationUpdate::Auto).first_contact(self, pose, other)
    }
}

/// Checks that `pose` is a rigid motion as the collision queries need it: finite,
/// and a matrix that is a rotation up to `1e-3` per entry of `RᵀR - I`, with a
/// positive determinant. O(1).
pub fn check_pose(pose: &Affine3A) -> Result<()> {
    pose_deviation(pose).map(|_| ())
}

/// Checks a pose and returns the deviation of its matrix from a rotation.
pub(crate) fn pose_deviation(pose: &Affine3A) -> Result<f32> {
    let dev = rotation_deviation(pose)?;
    let m = pose.matrix3;
    if dev.is_nan() || dev > MAX_POSE_DEVIATION || m.determinant() <= 0.0 {
        return Err(Error::InvalidPose(format!(
            "matrix is not a rotation (|RᵀR - I| = {dev}, det = {})",
            m.determinant()
        )));
    }
    Ok(dev)
}

/// The largest entry of `|RᵀR - I|` of a finite pose, with no limit (the
/// collision world composes two checked poses, whose product may deviate up to
/// about twice [`check_pose`]'s limit; the rounding slack grows with it).
/// Fails only on a non-finite pose.
pub(crate) fn rotation_deviation(pose: &Affine3A) -> Result<f32> {
    if !pose.matrix3.is_finite() || !pose.translation.is_finite() {
        return Err(Error::InvalidPose("pose is not finite".into()));
    }
    let m = pose.matrix3;
    let d = m.transpose() * m - Mat3A::IDENTITY;
    Ok(d.x_axis
        .abs()
        .max(d.y_axis.abs())
        .max(d.z_axis.abs())
        .max_element())
}

impl<BV: BoundingVolume> Collider<BV> {
    /// An empty collider.
    pub fn new(rotation: RotationUpdate) -> Self {
        Collider {
            rotation,
            world_vertices: Vec::new(),
            world: Vec::new(),
            cache: QueryCache::default(),
            stack: Vec::new(),
            tris_a: TriangleCache::default(),
            tris_b: TriangleCache::default(),
        }
    }

    /// Every pair `(i, j)` such that triangle `i` of mesh `a`, its vertices moved by
    /// `pose` (`pose.transform_point3`), intersects triangle `j` of mesh `b`
    /// according to [`triangles_intersect`](crate::narrow::triangles_intersect).
    /// Each pair appears once. The test runs as
    /// [`PreparedTriangle::intersects`](crate::narrow::PreparedTriangle::intersects)
    /// (same answers), each reached triangle prepared once per query.
    ///
    /// Cost: the traversal visits only pairs of overlapping volumes; with a rotated
    /// pose and axis-aligned volumes, the [`RotationUpdate`] adds `O(n_a)` (refit)
    /// or one update per visited node (conservative). A pure translation moves k-DOPs
    /// by shifting their intervals, at no update cost.
    ///
    /// Fails with [`Error::InvalidPose`] on a pose that is not a rigid motion
    /// ([`check_pose`]).
    pub fn all_pairs(&mut self, a: &Mesh<BV>, pose: &Affine3A, b: &Mesh<BV>) -> Result<Contacts> {
        let mut pairs = Vec::new();
        let counters = self.run(a, pose, b, false, &mut pairs, None)?;
        Ok(Contacts { pairs, counters })
    }

    /// [`Collider::all_pairs`] with another triangle predicate in place of
    /// [`triangles_intersect`](crate::narrow::triangles_intersect) (for example a
    /// test with a tolerance). The culling is only valid for predicates that imply
    /// the triangles share a point (up to rounding), since that is what the bounding
    /// volumes guarantee.
    pub fn all_pairs_with(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        b: &Mesh<BV>,
        triangle_test: impl Fn(&[Vec3; 3], &[Vec3; 3]) -> bool,
    ) -> Result<Contacts> {
        let mut pairs = Vec::new();
        let counters = self.run(a, pose, b, false, &mut pairs, Some(&triangle_test))?;
        Ok(Contacts { pairs, counters })
    }

    /// Like [`Collider::all_pairs`] but stops at the first intersecting pair.
    pub fn first_contact(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        b: &Mesh<BV>,
    ) -> Result<FirstContact> {
        let mut pairs = Vec::new();
        let counters = self.run(a, pose, b, true, &mut pairs, None)?;
        Ok(FirstContact {
            pair: pairs.first().copied(),
            counters,
        })
    }

    fn run(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        b: &Mesh<BV>,
        first: bool,
        out: &mut Vec<(u32, u32)>,
        custom: Option<&TriangleTest>,
    ) -> Result<CostCounters> {
        let dev = pose_deviation(pose)?;
        Ok(self
            .run_from(a, pose, dev, b, first, out, custom, &[(0, 0)], &mut ())
            .0)
    }

    /// The query of [`Collider::all_pairs`] (or, with `first`, of
    /// [`Collider::first_contact`]) for a pose already checked, whose matrix
    /// deviates from a rotation by `dev` (any finite amount: the rounding slack
    /// grows with it), starting from the node pairs `start` (the roots, or a cut
    /// an earlier traversal reported to its `cut`: the same triangle pairs are
    /// found, possibly in another order) and reporting where it ends to `cut`.
    /// Appends the intersecting triangle pairs to `out`; returns the counters and
    /// whether it stopped early (then `cut` saw only part of the cut).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run_from(
        &mut self,
        a: &Mesh<BV>,
        pose: &Affine3A,
        dev: f32,
        b: &Mesh<BV>,
        first: bool,
        out: &mut Vec<(u32, u32)>,
        custom: Option<&TriangleTest>,
        start: &[(u32, u32)],
        cut: &mut impl Terminal,
    ) -> (CostCounters, bool) {
        // A mesh's tree always matches its geometry: nothing else to check.
        let (ta, ma) = (a.bvh(), a.trimesh());
        let (tb, mb) = (b.bvh(), b.trimesh());
        let t1 = glam::Vec3::from(pose.translation).abs().element_sum();
        let scale = 2.0 * (1.8 * ta.coord_bound * (1.0 + dev) + t1 + tb.coord_bound);
        let slack = slack_for(scale, dev);
        let (va, vb) = (ma.vertices(), mb.vertices());
        let mut c = CostCounters::default();
        let Collider {
            rotation,
            world_vertices,
            world,
            cache,
            stack,
            tris_a,
            tris_b,
        } = self;
        tris_a.begin(ta.tris.len(), Default::default());
        tris_b.begin(tb.tris.len(), Default::default());
        let rotated = pose.matrix3 != Mat3A::IDENTITY;
        let mut np = 0u64;
        // Leaf pair: every triangle pair, the first mesh's corners from `corner`.
        // Each triangle is prepared (corners moved, box, plane) once per query.
        let mut leaf = |corner: &dyn Fn(u32) -> Vec3, la: usize, lb: usize| -> bool {
            for k in ta.nodes[la].triangle_range() {
                let pa = tris_a.get(k, || PreparedTriangle::new(ta.tris[k].map(corner)));
                for m in tb.nodes[lb].triangle_range() {
                    let pb = tris_b.get(m, || {
                        PreparedTriangle::new(tb.tris[m].map(|v| vb[v as usize]))
                    });
                    np += 1;
                    let hit = match custom {
                        None => pa.intersects(pb),
                        Some(test) => test(pa.corners(), pb.corners()),
                    };
                    if hit {
                        out.push((ta.ids[k], tb.ids[m]));
                        if first {
                            return true;
                        }
                    }
                }
            }
            false
        };
        let moved = |v: u32| pose.transform_point3(va[v as usize]);
        // The descent, ordered deepest overlap first for a first contact.
        macro_rules! go {
            ($src:expr, $corner:expr) => {
                if first {
                    traverse::<BV, true>(ta, $src, tb, start, stack, &mut c.nv, cut, |x, y| {
                        leaf($corner, x, y)
                    })
                } else {
                    traverse::<BV, false>(ta, $src, tb, start, stack, &mut c.nv, cut, |x, y| {
                        leaf($corner, x, y)
                    })
                }
            };
        }
        let stopped = if BV::AXIS_ALIGNED && rotated {
            let update = match *rotation {
                RotationUpdate::Auto => RotationUpdate::Conservative,
                r => r,
            };
            match update {
                RotationUpdate::Refit => {
                    world_vertices.clear();
                    world_vertices.extend(va.iter().map(|&v| pose.transform_point3(v)));
                    c.nu = ta.world_volumes(world_vertices, slack, world);
                    let wv: &[Vec3] = world_vertices;
                    let corner = |v: u32| wv[v as usize];
                    go!(&mut Precomputed(world), &corner)
                }
                _ => {
                    cache.begin(ta.nodes.len(), ta.nodes[0].bv);
                    let mut src = ExactLeaves {
                        lazy: Lazy {
                            nodes: &ta.nodes,
                            pose: *pose,
                            slack,
                            cache,
                            updates: 0,
                        },
                        tris: &ta.tris,
                        vertices: va,
                        sizes: &ta.subtree,
                    };
                    let stopped = go!(&mut src, &moved);
                    c.nu = src.lazy.updates;
                    stopped
                }
            }
        } else {
            let mut src = Local {
                nodes: &ta.nodes,
                motion: BV::motion(pose, slack),
            };
            go!(&mut src, &moved)
        };
        c.np = np;
        (c, stopped)
    }
}
