//! The W5 peer: parry3d 0.31's `TriMesh` against another `TriMesh`.
//!
//! What parry 0.31 offers for two triangle meshes (read from its source,
//! `query/default_query_dispatcher.rs` and `query/intersection_test/`):
//! - `query::intersection_test(pos1, &mesh1, pos2, &mesh2)` is supported: both are
//!   composite shapes, so the dispatcher runs `intersection_test_composite_shape_shape`:
//!   for each leaf of mesh 1's BVH whose AABB meets the AABB of the whole mesh 2
//!   (in mesh 1's frame), it recurses into `intersection_test(triangle, mesh2)`,
//!   which walks mesh 2's BVH with the triangle's AABB and tests each candidate
//!   triangle pair with GJK (`intersection_test_support_map_support_map`). It
//!   stops at the first intersecting pair: a boolean, our first-contact query.
//!   It is a nested one-tree-at-a-time query, not a simultaneous descent.
//! - No all-pairs query between two meshes (contact manifolds aside, which compute
//!   contact points with a prediction distance). The BVH does offer a simultaneous
//!   traversal, `Bvh::leaf_pairs(&other, check)`; [`ParryMeshes::all_pairs`] drives
//!   it with a check that moves mesh 1's node AABB by the pose
//!   (`Aabb::transform_by`), and tests each leaf pair with the same GJK test.
//!
//! Triangle pairs are decided by GJK in `f32` with a tolerance, so touching and
//! nearly touching pairs may be answered either way; and parry's pose is a unit
//! quaternion made from our rotation matrix, which moves the first mesh by a few
//! `f32` ulps relative to ours. The W5 run counts disagreements and checks every
//! one against Proxima's exact test.

use parry3d::bounding_volume::BoundingVolume as _;
use parry3d::math::{Matrix, Pose, Rotation, Vector};
use parry3d::partitioning::BvhNode;
use parry3d::shape::TriMesh as PTriMesh;
use proxima::glam::Affine3A;
use proxima::narrow::TriMesh;

/// Both meshes as parry `TriMesh`es (each with its own BVH, built by `TriMesh::new`).
pub struct ParryMeshes {
    a: PTriMesh,
    b: PTriMesh,
}

/// Our mesh as a parry `TriMesh` (vertex copy, then parry's own BVH build;
/// default flags: no vertex merging, no degenerate removal). Shared by the W5
/// and W6 peers.
pub fn convert(m: &TriMesh) -> Result<PTriMesh, String> {
    let v = m
        .vertices()
        .iter()
        .map(|p| Vector::new(p.x, p.y, p.z))
        .collect();
    PTriMesh::new(v, m.triangles().to_vec()).map_err(|e| format!("parry TriMesh: {e:?}"))
}

/// Our pose (rotation matrix and translation) as a parry pose (unit quaternion).
pub fn pose(p: &Affine3A) -> Pose {
    let m = Matrix::from_cols_array(&p.matrix3.to_cols_array());
    let t = p.translation;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_mat3(&m).normalize(),
    )
}

impl ParryMeshes {
    /// Builds both parry meshes (vertex copy and BVH build).
    pub fn build(a: &TriMesh, b: &TriMesh) -> Result<Self, String> {
        Ok(ParryMeshes {
            a: convert(a)?,
            b: convert(b)?,
        })
    }

    /// `parry3d::query::intersection_test` of mesh `a` at `pose` with mesh `b` at
    /// the identity.
    pub fn intersects(&self, pose: &Pose) -> Result<bool, String> {
        parry3d::query::intersection_test(pose, &self.a, &Pose::IDENTITY, &self.b)
            .map(|r| r.intersecting)
            .map_err(|_| "parry: TriMesh vs TriMesh unsupported".to_string())
    }

    /// Every triangle pair `(i in a, j in b)` that parry's GJK test finds
    /// intersecting, over the leaf pairs of a simultaneous traversal of both BVHs.
    pub fn all_pairs(&self, pose: &Pose) -> Vec<(u32, u32)> {
        let check =
            |n1: &BvhNode, n2: &BvhNode| n1.aabb().transform_by(pose).intersects(&n2.aabb());
        let mut out = Vec::new();
        for (i, j) in self.a.bvh().leaf_pairs(self.b.bvh(), check) {
            let (ta, tb) = (self.a.triangle(i), self.b.triangle(j));
            if parry3d::query::intersection_test(pose, &ta, &Pose::IDENTITY, &tb)
                .is_ok_and(|r| r.intersecting)
            {
                out.push((i, j));
            }
        }
        out
    }

    /// parry's distance between triangle `i` of `a` at `pose` and triangle `j` of
    /// `b` (0 when it considers them intersecting).
    pub fn triangle_distance(&self, pose: &Pose, i: u32, j: u32) -> f32 {
        let (ta, tb) = (self.a.triangle(i), self.b.triangle(j));
        parry3d::query::distance(pose, &ta, &Pose::IDENTITY, &tb).map_or(f32::NAN, |d| d.distance)
    }
}
