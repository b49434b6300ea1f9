//! Narrow phase: triangle meshes, bounding-volume hierarchies over them, and
//! mesh-vs-mesh collision down to exact triangle–triangle tests (seed 003).

mod trimesh;

pub use trimesh::TriMesh;
