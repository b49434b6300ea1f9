//! Broad phase: indices over bounding spheres behind one trait, [`SpatialIndex`].
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
//! Every index stores a [`Sphere`] and a user payload `T` per object and returns a
//! generational [`Handle`]. Queries take `&self` (indices are `Send + Sync`, so
//! queries may run on many threads) and report through a callback that can stop
//! early by returning [`ControlFlow::Break`].

mod brute;
mod cell_list;
mod grid2d;
mod grid3d;
mod hash_grid;
pub mod loose_kd;
pub mod octree;
#[cfg(feature = "parallel")]
mod parallel;
mod selection;
#[cfg(test)]
mod test_util;

pub use crate::arena::Handle;
pub use brute::BruteForce;
pub use grid2d::UniformGrid2d;
pub use grid3d::UniformGrid3d;
pub use hash_grid::HashGrid;
pub use loose_kd::LooseKdTree;
pub use octree::{LinearOctree, OctreeConfig};
#[cfg(feature = "parallel")]
pub use parallel::{par_query_counts, par_visit_batch, ParallelPairs};
pub use selection::Selection;

use crate::geom::{overlap, Aabb, Frustum, Ray, Segment, Sphere};
use crate::Result;
use std::ops::ControlFlow;

/// A ray hit: the object and the entry parameter `t` along the ray (`0` when the
/// origin is inside the sphere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The object hit.
    pub handle: Handle,
    /// Entry parameter, in units of the ray's direction.
    pub t: f32,
}

/// The interface every broad-phase index implements [sources: index-trait].
///
/// Mutations validate their input and leave the index unchanged on error. Queries
/// come in three forms: the generic [`SpatialIndex::query`] with any [`Selection`],
/// one named method per shape with a callback, and collecting conveniences that
/// return a `Vec`. Overlap is closed everywhere: touching counts.
pub trait SpatialIndex<T>: Send + Sync {
    /// Stores `value` with bounding sphere `sphere`. Errors on a non-finite centre or
    /// a negative or non-finite radius.
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle>;

    /// Removes an object and returns its payload. Errors on a stale handle.
    fn remove(&mut self, handle: Handle) -> Result<T>;

    /// Moves and/or resizes an object.
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()>;

    /// The sphere and payload of an object.
    fn get(&self, handle: Handle) -> Result<(Sphere, &T)>;

    /// The payload of an object, mutably (the sphere changes only through `update`).
    fn get_mut(&mut self, handle: Handle) -> Result<&mut T>;

    /// Number of stored objects.
    fn len(&self) -> usize;

    /// True when nothing is stored.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Removes everything and releases the structure's memory; all handles go stale.
    fn clear(&mut self);

    /// Calls `f` for every stored object, in no particular order.
    fn for_each(&self, f: impl FnMut(Handle, &Sphere, &T));

    /// Reports every object selected by `query`, without validating the query (use
    /// [`SpatialIndex::query`] for that). Stops when `f` breaks and returns what it
    /// returned.
    fn visit<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// Calls `f` once for every unordered pair of stored objects that overlap
    /// (closed). Stops early when `f` breaks.
    fn for_each_pair(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// The hit with the smallest entry `t` (ties: smallest handle), without
    /// validating the ray. The default scans all hits; indices override it with a
    /// front-to-back search.
    fn ray_first_unchecked(&self, ray: &Ray) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        let _ = self.visit(ray, |h, s, _| {
            if let Some(t) = overlap::ray_sphere(ray, s) {
                let better = match best {
                    None => true,
                    Some(b) => (t, h) < (b.t, b.handle),
                };
                if better {
                    best = Some(RayHit { handle: h, t });
                }
            }
            ControlFlow::Continue(())
        });
        best
    }

    /// Checks the structure's invariants (tests call it after every operation).
    fn validate(&self) -> Result<()>;

    /// Heap and inline bytes held by the index, payloads included.
    fn memory_bytes(&self) -> usize;

    // ---- validated queries -------------------------------------------------------

    /// Reports every object selected by `query` after checking the query's numbers.
    fn query<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        query.validate()?;
        Ok(self.visit(query, f))
    }

    /// Objects overlapping the sphere `s` (also the point-radius query: objects within
    /// `s.radius` of `s.center`).
    fn query_sphere(
        &self,
        s: &Sphere,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.query(s, f)
    }

    /// Objects overlapping the box `b`.
    fn query_aabb(
        &self,
        b: &Aabb,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.query(b, f)
    }

    /// Objects not entirely outside any plane of the frustum.
    fn query_frustum(
        &self,
        fr: &Frustum,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.query(fr, f)
    }

    /// Handles of the objects within `radius` of `center`.
    fn within(&self, center: glam::Vec3, radius: f32) -> Result<Vec<Handle>> {
        self.sphere_hits(&Sphere::new(center, radius))
    }

    /// Handles of the objects overlapping `s`.
    fn sphere_hits(&self, s: &Sphere) -> Result<Vec<Handle>> {
        collect(self, s)
    }

    /// Handles of the objects overlapping `b`.
    fn aabb_hits(&self, b: &Aabb) -> Result<Vec<Handle>> {
        collect(self, b)
    }

    /// Handles of the objects kept by frustum culling.
    fn frustum_hits(&self, fr: &Frustum) -> Result<Vec<Handle>> {
        collect(self, fr)
    }

    /// Every object hit by the ray, ordered by entry `t` (ties by handle).
    fn ray_hits(&self, ray: &Ray) -> Result<Vec<RayHit>> {
        ray.validate()?;
        let mut hits = Vec::new();
        let _ = self.visit(ray, |h, s, _| {
            if let Some(t) = overlap::ray_sphere(ray, s) {
                hits.push(RayHit { handle: h, t });
            }
            ControlFlow::Continue(())
        });
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.handle.cmp(&b.handle)));
        Ok(hits)
    }

    /// The object the ray enters first, if any.
    fn ray_first(&self, ray: &Ray) -> Result<Option<RayHit>> {
        ray.validate()?;
        Ok(self.ray_first_unchecked(ray))
    }

    /// Every object the segment touches, ordered by entry `t` in `[0, 1]`.
    fn segment_hits(&self, seg: &Segment) -> Result<Vec<RayHit>> {
        self.ray_hits(&seg.to_ray())
    }

    /// The object the segment enters first, if any.
    fn segment_first(&self, seg: &Segment) -> Result<Option<RayHit>> {
        self.ray_first(&seg.to_ray())
    }

    /// Every overlapping pair, each once, as `(a, b)` with `a < b`.
    fn pairs(&self) -> Vec<(Handle, Handle)> {
        let mut out = Vec::new();
        let _ = self.for_each_pair(|a, _, b, _| {
            out.push(if a < b { (a, b) } else { (b, a) });
            ControlFlow::Continue(())
        });
        out
    }
}

fn collect<T, I: SpatialIndex<T> + ?Sized, Q: Selection + ?Sized>(
    index: &I,
    q: &Q,
) -> Result<Vec<Handle>> {
    let mut out = Vec::new();
    let _ = index.query(q, |h, _, _| {
        out.push(h);
        ControlFlow::Continue(())
    })?;
    Ok(out)
}
