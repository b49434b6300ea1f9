//! Broad phase: indices over bounding spheres behind one object-safe trait,
//! [`SpatialIndex`].
//!
//! | index | idea | source |
//! |---|---|---|
//! | [`BruteForce`] | scan everything; the oracle | — |
//! | [`LinearOctree`] | sparse octree named by location codes in a hash map; O(1) face-neighbour codes, moves via neighbours, split/merge with hysteresis, loose bounds by max extent | [sources: octree] |
//! | [`LooseKdTree`] | binary tree with overlapping children (shared border zone); each sphere in exactly one node | [sources: kd-tree] (`SPHERE_SET_TREE`) |
//! | [`HashGrid`] | unbounded 3D hashed grid; huge objects in an oversized list | [sources: hash-grid] |
//! | [`UniformGrid3d`] | dense uniform 3D grid over a world box; each object once, in its centre's cell; half-shell pair search; large objects in a list | [sources: grid3d] |
//! | [`UniformGrid2d`] | uniform grid on the XY plane for flat worlds; objects referenced from every covered cell | [sources: grid2d] |
//!
//! Every index stores a [`Sphere`](crate::geom::Sphere) and a user payload `T`
//! per object and returns a generational [`Handle`](crate::Handle). Queries take
//! `&self` (indices are `Send + Sync`, so queries may run on many threads) and
//! report through a callback that can stop early by returning
//! [`ControlFlow::Break`](std::ops::ControlFlow::Break).
//!
//! **The API in three layers.** [`SpatialIndex`] is the small core (mutations,
//! [`visit`](SpatialIndex::visit) with a [`Query`], pairs, the first ray hit,
//! validation, memory); [`SpatialIndexExt`] adds closures and collected results
//! (`query`, `within`, `ray_hits`, `pairs`, ...) to every index;
//! [`AnyIndex`] holds whichever index an [`IndexKind`] names, chosen at run time.
//!
//! **Constructors** have one shape. `X::new(..)` takes only what the index must
//! know about the scene (nothing for [`BruteForce`], a typical radius for
//! [`HashGrid`], the world box and a typical radius for the others, the world
//! box alone for [`LinearOctree`]) and uses default tuning;
//! `X::with_config(XConfig)` takes everything, with public fields:
//! `XConfig::new(..)` (same arguments as `X::new`) holds the defaults and
//! `XConfig::for_scene(&SceneHint)` derives them from a [`SceneHint`]. Bad
//! parameters are [`Error::InvalidParameter`](crate::Error::InvalidParameter)
//! (or the world box's own error), never a panic.

mod any;
mod brute;
mod cell_grid;
mod ext;
pub(crate) mod filter;
mod grid2d;
mod grid3d;
mod hash_grid;
mod hint;
mod index;
mod kind;
mod loose_kd;
mod nearest;
mod octree;
#[cfg(feature = "parallel")]
mod parallel;
mod query;
mod selection;
#[cfg(test)]
mod test_util;
pub(crate) mod walk;

pub use any::AnyIndex;
pub use brute::BruteForce;
pub use ext::{Filtered, SpatialIndexExt};
pub use filter::Filter;
pub use grid2d::{Grid2dConfig, UniformGrid2d};
pub use grid3d::{Grid3dConfig, UniformGrid3d};
pub use hash_grid::{HashGrid, HashGridConfig};
pub use hint::SceneHint;
pub use index::{RayHit, SpatialIndex, SweepHit};
pub use kind::IndexKind;
pub use loose_kd::{KdNodeView, KdStats, LooseKdConfig, LooseKdTree, Placement};
pub use nearest::{Metric, Nearest, Neighbor};
pub use octree::{morton_order, Face, LinearOctree, LocationCode, OctreeConfig, OctreeStats};
#[cfg(feature = "parallel")]
pub use parallel::{par_nearest, par_query_counts, par_visit_batch, NearestBatch, ParallelPairs};
pub use query::Query;
// Not part of the API: the index walks' view of a query, public only so that the
// benchmark's peers can test their nodes with exactly the indices' tests. Sealed.
#[doc(hidden)]
pub use selection::Selection;
