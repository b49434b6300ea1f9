//! # Proxima
//!
//! Spatial queries and collision detection for dynamic 3D scenes.
//!
//! - [`geom`]: the primitive shapes (`Sphere`, `Aabb`, `Ray`, `Segment`, `Plane`,
//!   `Frustum`) and the one implementation of every closed overlap test between them.
//! - [`broad`]: the [`broad::SpatialIndex`] trait over bounding spheres and its
//!   indices: [`broad::BruteForce`] (the oracle) and the loose k-d tree
//!   [sources: kd-tree], with more to come.
//! - [`narrow`]: triangle meshes and the exact, closed triangle–triangle test.
//! - [`io`]: OBJ, STL and PLY loaders into a [`narrow::TriMesh`].
//!
//! Math types are [`glam`]'s (`f32`), re-exported as [`proxima::glam`](glam) so that
//! users need not match versions by hand.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod arena;
pub mod broad;
mod error;
pub mod geom;
pub mod io;
pub mod narrow;

pub use error::{Error, FileLocation, Result};
pub use glam;

/// The root README's examples, compiled and run as doctests (`cargo test`).
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
