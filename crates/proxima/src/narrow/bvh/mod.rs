//! Bounding-volume hierarchies over triangle meshes [sources: bvh].
//!
//! - [`tree`](Bvh): the flat node array and its accessors;
//! - `build.rs`: top-down binary build, split at the mean or the median of the
//!   triangle centroids (the source's two rules, [sources: bvh-build]) or by a
//!   binned surface-area heuristic;
//! - `refit.rs`: bottom-up refit for deformed vertices, and the exact world-frame
//!   refit of a rotated tree (the source's rotation update, [sources: bvh-rotate]);
//! - `traverse.rs`: the simultaneous descent of two trees [sources: bvh-traverse];
//! - `collide.rs`: mesh–mesh collision of two posed meshes with the cost counters;
//! - `tri_cache.rs`: the per-query cache of prepared triangles;
//! - `ray.rs`: ray and segment casts; `ray_tree.rs` + `ray_cast.rs`: [`RayBvh`], the
//!   same casts on a layout made for rays only; `par.rs`: parallel batches of them (feature
//!   `parallel`);
//! - `validate.rs`: the structural invariants.

mod build;
mod collide;
#[cfg(feature = "parallel")]
mod par;
mod ray;
mod ray_cast;
mod ray_tree;
mod refit;
mod traverse;
mod tree;
mod tri_cache;
mod validate;

pub use build::{BuildOptions, SplitRule};
pub use collide::{
    check_pose, collide_all, collide_first, Collider, Contacts, CostCounters, FirstContact,
    RotationUpdate,
};
pub use ray::RayHit;
pub use ray_tree::RayBvh;
pub use tree::{Bvh, Node};
