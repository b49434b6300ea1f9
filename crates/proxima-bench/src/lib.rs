//! # proxima-bench
//!
//! Proxima's performance record for the broad phase: the standard workloads
//! [sources: workloads] (W1 dynamic spheres, W2 flat world, W3 clustered, W9 mixed
//! sizes), run through every Proxima index and the peer crates side by side, with
//! the pair count of every frame checked equal across all of them.
//!
//! - the deterministic scene generators and their motion model are
//!   `proxima_harness::workloads` (shared with `proxima demo`);
//! - [`structure`]: the object-safe [`structure::Structure`] interface and the
//!   adapter over the library's `AnyIndex<u32>`;
//! - [`parry`]: the parry3d BVH adapter;
//! - [`registry`]: the list of structures (every `IndexKind`, then the peers);
//! - [`w5`]: the mesh-vs-mesh workload W5 and its peer [`parry_mesh`];
//! - [`w5_distance`]: W5's poses through the distance queries (issue #15);
//! - [`w6`]: rays vs one mesh (its own runner, table and agreement check), with
//!   its peers (obvhs, bvh, parry3d's `TriMesh`) beside it, as W4's are;
//! - [`w7`]: k nearest neighbours on W4's set (points and spheres) beside
//!   kiddo, rstar and parry3d; [`w8`]: sphere sweeps through it beside
//!   parry3d's shape cast; [`query_args`]: their shared options and timing;
//! - [`world`]: the collision world's scenes (tumble, arms, deep
//!   interpenetration, churn) as world traces, on Proxima's world and on FCL's
//!   through the `fcl_world` harness in the same run;
//! - [`run`]: timing and the pair-count ledger; [`report`]: tables and JSON;
//! - [`chart`]: an SVG bar chart of any workload's `--json` output.
//!
//! Peers are dependencies of this crate only; the library stays light.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod chart;
pub mod parry;
pub mod parry_mesh;
pub mod query_args;
pub mod registry;
pub mod report;
pub mod run;
pub mod structure;
pub mod w4;
pub mod w5;
pub mod w5_distance;
pub mod w6;
pub mod w7;
pub mod w8;
pub mod world;
