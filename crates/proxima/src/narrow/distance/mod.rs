//! Distance and proximity queries on triangle meshes (issue #15, parts 1–3): how
//! far apart two posed meshes are and where, whether they are within a margin,
//! which triangle pairs are; the nearest surface point to a point, whether a
//! point is inside a closed mesh, ball–mesh distance and overlap.
//!
//! - `triangle.rs`, `segment.rs`: closest points of triangles, segments and
//!   points in `f64` ([`triangle_distance`], [`closest_point_on_triangle`]);
//! - `traverse.rs`: best-first and depth-first descents with a cut, over the
//!   moving tree's volumes from the same sources as collision (the pose in the
//!   test, a refit, a lazy transform, exact near the leaves: `narrow/bvh/moving.rs`,
//!   shared with [`Collider`](crate::narrow::Collider), with its rounding slack);
//! - `query.rs`: [`Proximity`], the reusable query object, and the mesh–mesh
//!   queries; `point.rs`: point and ball queries; `inside.rs`: the inside test.
//!
//! Sources: the descent is the simultaneous BVH traversal of seed 003 with its
//! cost counters, ordered best-first by a lower bound as in PQP (Larsen,
//! Gottschalk, Lin, Manocha, "Fast distance queries with rectangular swept
//! sphere volumes", 2000), whose triangle distance (`TriDist`) also gives the
//! early exit of ours; the inside test perturbs its ray symbolically (Edelsbrunner
//! and Mücke's simulation of simplicity) over the exact predicates of
//! [`predicates`](crate::narrow::predicates).
//!
//! Precision: the first mesh's vertices are posed in `f32` as in
//! [`Collider`](crate::narrow::Collider), and every distance is then computed
//! in `f64` from those `f32` points (widened exactly): results are within a
//! few units of `f64` rounding of the exact distances of the posed `f32`
//! triangles, except for triangles thinner than `1e-8` of their size, which are
//! measured as the union of their edges (off by at most `1e-8` of their size).
//! Contact (distance exactly `0`) is decided by the exact triangle test. The
//! volumes' bounds are computed in `f32` and lowered by the rounding slack of
//! collision, so they never cut a pair they should keep.

mod inside;
mod point;
mod query;
mod segment;
mod traverse;
mod triangle;

pub use point::ClosestPoint;
pub use query::{mesh_distance, meshes_within, MeshDistance, NearPair, NearPairs, Proximity};
pub use triangle::{closest_point_on_triangle, triangle_distance, TriangleDistance};
