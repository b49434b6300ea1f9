//! Bounding-volume hierarchies over triangle meshes [sources: bvh], and [`Mesh`], the
//! mesh that owns them.
//!
//! - `mesh.rs`: [`Mesh`], geometry + collision tree + lazy ray tree + bounds;
//! - `options.rs`: [`BuildOptions`] and [`SplitRule`];
//! - `tree.rs`: [`Bvh`], the flat node array and its accessors;
//! - `build.rs`: top-down binary build, split at the mean or the median of the
//!   triangle centroids (the source's two rules, [sources: bvh-build]) or by a
//!   binned surface-area heuristic;
//! - `refit.rs`: bottom-up refit for deformed vertices, and the exact world-frame
//!   refit of a rotated tree (the source's rotation update, [sources: bvh-rotate]);
//! - `traverse.rs`: the simultaneous descent of two trees [sources: bvh-traverse];
//! - `collide.rs`: mesh–mesh collision of two posed meshes with the cost counters
//!   ([`Mesh::collide`], [`Collider`]);
//! - `tri_cache.rs`: the per-query cache of prepared triangles;
//! - `ray.rs`: ray and segment casts on a [`Bvh`]; `ray_tree.rs` + `ray_cast.rs`:
//!   [`RayBvh`], the same casts on a layout made for rays only; `stack.rs`: their
//!   traversal stack; `par.rs`: parallel batches of casts (feature `parallel`);
//! - `sphere_query.rs`: the triangles within a ball ([`Mesh::triangles_in_sphere`]);
//! - `validate.rs`: the structural invariants.

mod build;
mod collide;
mod mesh;
mod options;
#[cfg(feature = "parallel")]
mod par;
mod ray;
mod ray_cast;
mod ray_tree;
mod refit;
mod sphere_query;
mod stack;
mod traverse;
mod tree;
mod tri_cache;
mod validate;

pub use collide::{check_pose, Collider, Contacts, CostCounters, FirstContact, RotationUpdate};
// For the collision world: relative poses of two checked poses, and traversal cuts.
pub(crate) use collide::rotation_deviation;
pub use mesh::Mesh;
pub use options::{BuildOptions, SplitRule};
pub use ray_tree::RayBvh;
pub(crate) use traverse::CutRecorder;
pub use tree::{Bvh, Node};
