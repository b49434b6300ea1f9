//! # Proxima
//!
//! Spatial queries and collision detection for dynamic 3D scenes.
//!
//! - [`geom`]: the primitive shapes (`Sphere`, `Aabb`, `Ray`, `Segment`, `Plane`,
//!   `Frustum`) and the one implementation of every closed overlap test between them.
//! - [`broad`]: six indices over bounding spheres behind the object-safe
//!   [`broad::SpatialIndex`] trait (with the conveniences of
//!   [`broad::SpatialIndexExt`]): [`broad::BruteForce`] (the oracle),
//!   [`broad::LooseKdTree`], [`broad::LinearOctree`], [`broad::UniformGrid2d`],
//!   [`broad::HashGrid`] and [`broad::UniformGrid3d`]; [`broad::AnyIndex`] holds
//!   whichever one an [`broad::IndexKind`] names at run time. Stored objects are
//!   named by [`Handle`]s.
//! - [`narrow`]: [`narrow::Mesh`], a triangle mesh that owns its trees: a k-DOP,
//!   OBB, AABB or sphere BVH for exact mesh–mesh collision down to the closed
//!   triangle–triangle test, and a 4-wide BVH for exact ray casts; the generic
//!   [`narrow::Bvh`] below it for experiments with the source's choices [sources: bvh].
//! - [`world`]: the collision world, [`world::World`]: shared mesh and ball
//!   [`world::Shape`]s at rigid poses over a broad-phase index chosen at run
//!   time, with contacts (temporal coherence, ignored pairs, filters), ray casts,
//!   sphere queries and culling [sources: world].
//! - [`io`]: OBJ, STL and PLY loaders into a [`narrow::TriMesh`], or with
//!   [`narrow::Mesh::load`] straight into a mesh with its trees.
//!
//! Math types are [`glam`]'s (`f32`), re-exported as [`proxima::glam`](glam) so that
//! users need not match versions by hand.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod arena;
pub mod broad;
mod error;
pub mod geom;
mod handle;
pub mod io;
pub mod narrow;
mod prefetch;
pub mod world;

pub use error::{Error, FileLocation, IoError, Result};
pub use glam;
pub use handle::Handle;

/// The root README's examples, compiled and run as doctests (`cargo test`).
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
