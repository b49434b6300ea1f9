//! [`SpatialIndex`]: the small, object-safe core every broad-phase index
//! implements [sources: index-trait, index-queries], and the [`RayHit`] its ray
//! and sweep queries return.

use super::{Filter, IndexKind, Nearest, Neighbor, Query};
use crate::geom::{Ray, Sphere, SphereSweep};
use crate::{Handle, Result};
use std::ops::ControlFlow;

/// A ray hit: the object and the entry parameter `t` along the ray (`0` when the
/// origin is inside the sphere). Also a sweep hit ([`SweepHit`]): the object
/// and the time of impact `t` in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The object hit.
    pub handle: Handle,
    /// Entry parameter, in units of the ray's direction (for a sweep: the time
    /// of impact, `0` at `from`, `1` at `to`).
    pub t: f32,
}

/// A sphere sweep's hit: the object touched and the time of impact `t` in
/// `[0, 1]` (`0` when touching at the start). The same type as [`RayHit`],
/// ordered the same way (smaller `t`, then smaller handle).
pub type SweepHit = RayHit;

impl RayHit {
    /// Keeps in `best` the first hit of a ray: the smaller `t`, ties broken by
    /// the smaller handle (the order every first-hit search reports). Returns
    /// whether `(t, handle)` replaced it. O(1).
    #[inline]
    pub(crate) fn offer(best: &mut Option<RayHit>, t: f32, handle: Handle) -> bool {
        let better = match best {
            None => true,
            Some(b) => (t, handle) < (b.t, b.handle),
        };
        if better {
            *best = Some(RayHit { handle, t });
        }
        better
    }
}

/// The interface every broad-phase index implements: a set of bounding spheres,
/// each with a payload `T` and a collision [`Filter`], named by [`Handle`]s.
///
/// The trait is object-safe: `Box<dyn SpatialIndex<T>>` holds any index, and
/// [`AnyIndex`](super::AnyIndex) is the enum over the six built-in ones. Callbacks
/// are `&mut dyn FnMut`; the conveniences that take closures and collect results
/// are in [`SpatialIndexExt`](super::SpatialIndexExt), implemented for every
/// index. Each index matches the [`Query`] once and runs a walk compiled for that
/// shape, so the dynamic call is per reported object, never per node.
///
/// Mutations validate their input and leave the index unchanged on error.
/// Queries take `&self` (indices are `Send + Sync`, so queries may run on many
/// threads) and stop early when the callback returns [`ControlFlow::Break`].
/// Overlap is closed everywhere: touching counts.
///
/// # Filters
///
/// Every object carries a [`Filter`] (group and mask bits; [`Filter::ALL`]
/// unless inserted with [`insert_with_filter`](SpatialIndex::insert_with_filter)
/// or changed with [`set_filter`](SpatialIndex::set_filter); moves keep it).
/// [`visit_pairs`](SpatialIndex::visit_pairs) reports only pairs whose filters
/// interact ([`Filter::interacts`]).
///
/// Every query method takes the query's filter as an explicit last argument,
/// `filter: Option<Filter>`: `None` reports every object the shape selects
/// (exactly as an unfiltered query), `Some(f)` only those whose filter
/// interacts with `f`, as if the query were one more object with filter `f`
/// (so `Some(Filter::ALL)` still leaves out objects whose group or mask is
/// zero). One argument, the same for every query, rather than a filter carried
/// inside each query value (the Box2D way rather than the Rapier one): the
/// filter is orthogonal to the shape, the k-nearest and sweep queries are not
/// [`Query`] values, and an index that prunes by filter bits inside its
/// traversal sees the filter in every method it implements. The conveniences
/// of [`SpatialIndexExt`](super::SpatialIndexExt) are unfiltered;
/// [`SpatialIndexExt::filtered`](super::SpatialIndexExt::filtered) gives the
/// same conveniences with a filter.
pub trait SpatialIndex<T>: Send + Sync {
    /// Stores `value` with bounding sphere `sphere` and [`Filter::ALL`].
    /// Errors on a non-finite centre or a negative or non-finite radius.
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle> {
        self.insert_with_filter(sphere, Filter::ALL, value)
    }

    /// Stores `value` with bounding sphere `sphere` and collision filter
    /// `filter`. Errors as [`insert`](SpatialIndex::insert).
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle>;

    /// Removes an object and returns its payload. Errors on a stale handle.
    fn remove(&mut self, handle: Handle) -> Result<T>;

    /// Moves and/or resizes an object (its filter stays).
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()>;

    /// The sphere and payload of an object.
    fn get(&self, handle: Handle) -> Result<(Sphere, &T)>;

    /// The payload of an object, mutably (the sphere changes only through
    /// `update`).
    fn get_mut(&mut self, handle: Handle) -> Result<&mut T>;

    /// The collision filter of an object. Errors on a stale handle.
    fn filter(&self, handle: Handle) -> Result<Filter>;

    /// Replaces the collision filter of an object. Errors on a stale handle.
    /// O(1).
    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()>;

    /// Number of stored objects.
    fn len(&self) -> usize;

    /// True when nothing is stored.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Removes everything and releases the structure's memory; all handles go
    /// stale.
    fn clear(&mut self);

    /// Calls `f` for every stored object, in no particular order. O(n).
    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T));

    /// Checks the query's numbers ([`Query::validate`]), then reports every
    /// object it selects whose filter interacts with `filter` (every one for
    /// `None`), each once, in no particular order. Stops when `f` breaks and
    /// returns what it returned.
    fn visit(
        &self,
        query: &Query,
        filter: Option<Filter>,
        f: &mut dyn FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>>;

    /// Calls `f` once for every unordered pair of stored objects that overlap
    /// (closed) and whose filters interact, in no particular order. Stops early
    /// when `f` breaks.
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// The object the ray enters first among those `filter` admits: smallest
    /// entry `t`, ties broken by the smaller handle. Errors on an invalid ray.
    /// Indices with a hierarchy search front to back and skip what lies behind
    /// the best hit so far.
    fn ray_first(&self, ray: &Ray, filter: Option<Filter>) -> Result<Option<RayHit>>;

    /// The object a moving sphere touches first among those `filter` admits,
    /// with its time of impact `t` in `[0, 1]` (`0` if touching at the start):
    /// smallest `t` ([`overlap::sweep_sphere`](crate::geom::overlap::sweep_sphere),
    /// the same value in every index), ties broken by the smaller handle.
    /// Errors on an invalid sweep. Cost: at most that of the
    /// [`Query::Sweep`] walk.
    fn sweep_first(&self, sweep: &SphereSweep, filter: Option<Filter>) -> Result<Option<SweepHit>>;

    /// The k nearest objects ([`Nearest`]) among those `filter` admits, into
    /// `out` (cleared first), nearest first: the `min(k, admitted)` objects
    /// with the smallest distance in the query's metric, at most
    /// `max_distance` away, ties broken by the smaller handle. The distances
    /// are [`Metric::distance`](super::Metric::distance), correctly rounded,
    /// so every index gives the same answer bit for bit. Errors (leaving `out`
    /// empty) on a non-finite point or a NaN or negative `max_distance`.
    /// Allocates nothing once `out` has grown to the candidates' count.
    fn nearest_into(
        &self,
        query: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) -> Result<()>;

    /// Checks the structure's invariants (tests call it after every operation).
    fn validate(&self) -> Result<()>;

    /// Heap and inline bytes held by the index, payloads included.
    fn memory_bytes(&self) -> usize;

    /// Which of the built-in indices this is (a wrapper reports the index it
    /// wraps).
    fn kind(&self) -> IndexKind;
}

/// A boxed index is an index (so `Box<dyn SpatialIndex<T>>` goes wherever an
/// index does); every call forwards through the box.
impl<T, I: SpatialIndex<T> + ?Sized> SpatialIndex<T> for Box<I> {
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle> {
        (**self).insert(sphere, value)
    }
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        (**self).insert_with_filter(sphere, filter, value)
    }
    fn remove(&mut self, handle: Handle) -> Result<T> {
        (**self).remove(handle)
    }
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        (**self).update(handle, sphere)
    }
    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        (**self).get(handle)
    }
    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        (**self).get_mut(handle)
    }
    fn filter(&self, handle: Handle) -> Result<Filter> {
        (**self).filter(handle)
    }
    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        (**self).set_filter(handle, filter)
    }
    fn len(&self) -> usize {
        (**self).len()
    }
    fn is_empty(&self) -> bool {
        (**self).is_empty()
    }
    fn clear(&mut self) {
        (**self).clear()
    }
    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        (**self).for_each(f)
    }
    fn visit(
        &self,
        query: &Query,
        filter: Option<Filter>,
        f: &mut dyn FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        (**self).visit(query, filter, f)
    }
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        (**self).visit_pairs(f)
    }
    fn ray_first(&self, ray: &Ray, filter: Option<Filter>) -> Result<Option<RayHit>> {
        (**self).ray_first(ray, filter)
    }
    fn sweep_first(&self, sweep: &SphereSweep, filter: Option<Filter>) -> Result<Option<SweepHit>> {
        (**self).sweep_first(sweep, filter)
    }
    fn nearest_into(
        &self,
        query: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) -> Result<()> {
        (**self).nearest_into(query, filter, out)
    }
    fn validate(&self) -> Result<()> {
        (**self).validate()
    }
    fn memory_bytes(&self) -> usize {
        (**self).memory_bytes()
    }
    fn kind(&self) -> IndexKind {
        (**self).kind()
    }
}
