//! Narrow phase: triangle meshes, bounding-volume hierarchies over them, and
//! mesh-vs-mesh collision down to exact triangle–triangle tests (seed 003).

pub mod bv;
mod bvh;
mod ray_triangle;
mod trimesh;

pub use bv::{BoundingVolume, Kdop, Kdop14, Kdop18, Kdop26, Obb};
pub use bvh::{
    collide_all, collide_first, BuildOptions, Bvh, Collider, Contacts, CostCounters, FirstContact,
    Node, RayHit, RotationUpdate, SplitRule,
};
pub use ray_triangle::{ray_triangle, TriangleHit};
pub use trimesh::TriMesh;

// TEMPORARY until the `tri` branch lands `tri_tri.rs`: not a triangle test.
#[doc(hidden)]
pub fn triangles_intersect(_a: &[glam::Vec3; 3], _b: &[glam::Vec3; 3]) -> bool {
    unimplemented!("triangles_intersect comes from the tri branch")
}
