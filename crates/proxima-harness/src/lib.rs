//! # proxima-harness
//!
//! What Proxima's command-line tool, benchmarks, fuzz targets and tests share,
//! written once (it was compiled into several crates as path includes, or copied).
//! Not published: the library is `proxima`; this crate drives and checks it.
//!
//! | module | what | used by |
//! |---|---|---|
//! | [`workloads`] | the standard scenes W1–W3 and W9 [sources: workloads], one motion model | bench, `proxima demo` |
//! | [`indices`] | the indices by command-line name, brute force first | CLI, CLI tests |
//! | [`lex`] | line splitting, field and number parsing, `line N:` errors | [`trace`]; the world trace |
//! | [`trace`] | the scene trace of `proxima replay` [sources: trace-format] | CLI, `replay` fuzz target |
//! | [`replay`] | a trace run on an index, answers compared with brute force | CLI, `replay` fuzz target |
//! | [`ops`] | operation sequences decoded from bytes, every index against brute force | `tests/ops`, `index_ops` fuzz target |
//! | [`poses`] | the pose-file format (12 numbers a line) | `proxima collide`, `proxima render`, W5 bench |
//! | [`oracle`] | long random sequences on one index against brute force; [`oracle::make_index`] | `tests/oracle`, `tests/loose_kd*.rs`, `tests/extreme.rs` |
//! | [`tri_tri`] | the exact triangle–triangle reference | `tests/tri_tri`, `tri_tri` fuzz target |
//! | [`world_trace`] | the world trace of `proxima world` [sources: world-trace] | CLI, demo, `world` fuzz target |
//! | [`world_replay`] | a world trace run on a `World` with any index and BV; answers compared | CLI, demo, `world` fuzz target |
//! | [`world_oracle`] | the brute-force world (every object pair, every triangle pair) | CLI `--check`, demo, `world` fuzz target |
//!
//! Everything checks by panicking (`assert!`) or by returning a one-line error
//! a command prints: the callers are tests, fuzz targets and tools.
//! New trace lines of issue #14 slot into [`trace`] as described there.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod indices;
pub mod lex;
pub mod ops;
pub mod oracle;
pub mod poses;
pub mod replay;
pub mod trace;
pub mod tri_tri;
pub mod workloads;
pub mod world_oracle;
pub mod world_replay;
pub mod world_trace;
