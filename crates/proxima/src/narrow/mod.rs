//! Narrow phase: triangle meshes, bounding-volume hierarchies over them, and
//! mesh-vs-mesh collision down to exact triangle–triangle tests [sources: bvh, tri-tri].

pub mod bv;
mod bvh;
mod coplanar;
pub mod predicates;
mod prepared;
mod ray_triangle;
mod segment;
mod tri_tri;
mod trimesh;

pub use bv::{BoundingVolume, Kdop, Kdop14, Kdop18, Kdop26, Obb};
pub use bvh::{
    check_pose, collide_all, collide_first, BuildOptions, Bvh, Collider, Contacts, CostCounters,
    FirstContact, Node, RayBvh, RayHit, RotationUpdate, SplitRule,
};
pub use prepared::PreparedTriangle;
pub use ray_triangle::{ray_triangle, TriangleHit};
pub use segment::{segment_triangle_intersect, segments_intersect};
pub use tri_tri::triangles_intersect;
pub use trimesh::TriMesh;
