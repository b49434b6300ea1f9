//! # proxima-bench
//!
//! Proxima's performance record for the broad phase: the standard workloads of
//! design §5 (W1 dynamic spheres, W2 flat world, W3 clustered), run through every
//! Proxima index and the peer crates side by side, with the pair count of every
//! frame checked equal across all of them.
//!
//! - [`workloads`]: the deterministic scene generators;
//! - [`structure`]: the object-safe [`structure::Structure`] interface and the
//!   adapter over any `SpatialIndex<u32>`;
//! - [`parry`]: the parry3d BVH adapter;
//! - [`registry`]: the list of structures (one line per index);
//! - [`run`]: timing and the pair-count ledger; [`report`]: tables and JSON.
//!
//! Peers are dependencies of this crate only; the library stays light.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod parry;
pub mod registry;
pub mod report;
pub mod run;
pub mod structure;
pub mod w4;
pub mod workloads;
