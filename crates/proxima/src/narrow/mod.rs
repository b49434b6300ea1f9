//! Narrow phase: triangle meshes, bounding-volume hierarchies over them, exact
//! mesh–mesh collision down to triangle–triangle tests [sources: bvh, tri-tri], and
//! ray casts.
//!
//! Start from [`Mesh`]: a triangle mesh that owns its collision tree and its ray
//! tree. `Mesh::load(path)` reads an OBJ, STL or PLY file; [`Mesh::collide`] gives
//! every intersecting triangle pair of two posed meshes, [`Mesh::cast_ray`] the
//! closest [`TriangleHit`]; a [`Collider`] keeps the scratch space of a loop of
//! collision queries.
//!
//! Below it, for experiments with the source's choices [sources: bvh]: [`TriMesh`] (the geometry
//! alone); [`Bvh<BV>`](Bvh) over a `TriMesh`, generic over the
//! [`BoundingVolume`] ([`Aabb`](crate::geom::Aabb), [`Kdop14`], [`Kdop18`],
//! [`Kdop26`], [`Obb`], [`Sphere`](crate::geom::Sphere)) and the [`SplitRule`];
//! [`RayBvh`], the 4-wide ray layout. And the exact primitive tests every query
//! ends in: [`triangles_intersect`] (with [`PreparedTriangle`] for repeated tests),
//! [`ray_triangle`], [`segments_intersect`], [`segment_triangle_intersect`].

mod bv;
mod bvh;
mod coplanar;
pub(crate) mod predicates;
mod prepared;
mod ray_triangle;
mod segment;
mod sphere_triangle;
mod tri_tri;
mod trimesh;

pub use bv::{BoundingVolume, Kdop, Kdop14, Kdop18, Kdop26, Obb};
// For the collision world (crate::world).
pub use bvh::{
    check_pose, BuildOptions, Bvh, Collider, Contacts, CostCounters, FirstContact, Mesh, Node,
    RayBvh, RotationUpdate, SplitRule,
};
pub(crate) use bvh::{rotation_deviation, CutRecorder};
pub use prepared::PreparedTriangle;
pub use ray_triangle::{ray_triangle, TriangleHit};
pub use segment::{segment_triangle_intersect, segments_intersect};
pub use sphere_triangle::sphere_triangle;
pub use tri_tri::triangles_intersect;
pub use trimesh::TriMesh;
