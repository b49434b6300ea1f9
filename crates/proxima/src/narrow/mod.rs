//! Narrow phase: triangle meshes, bounding-volume hierarchies over them, and
//! mesh-vs-mesh collision down to exact triangle–triangle tests (seed 003).

mod coplanar;
pub mod predicates;
mod segment;
mod tri_tri;
mod trimesh;

pub use segment::{segment_triangle_intersect, segments_intersect};
pub use tri_tri::triangles_intersect;
pub use trimesh::TriMesh;
