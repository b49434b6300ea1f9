//! [`SpatialIndex`]: the small, object-safe core every broad-phase index
//! implements [sources: index-trait], and the [`RayHit`] its ray queries return.

use super::{IndexKind, Query};
use crate::geom::{Ray, Sphere};
use crate::{Handle, Result};
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
/// each with a payload `T`, named by [`Handle`]s.
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
pub trait SpatialIndex<T>: Send + Sync {
    /// Stores `value` with bounding sphere `sphere`. Errors on a non-finite centre
    /// or a negative or non-finite radius.
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle>;

    /// Removes an object and returns its payload. Errors on a stale handle.
    fn remove(&mut self, handle: Handle) -> Result<T>;

    /// Moves and/or resizes an object.
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()>;

    /// The sphere and payload of an object.
    fn get(&self, handle: Handle) -> Result<(Sphere, &T)>;

    /// The payload of an object, mutably (the sphere changes only through
    /// `update`).
    fn get_mut(&mut self, handle: Handle) -> Result<&mut T>;

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
    /// object it selects, each once, in no particular order. Stops when `f`
    /// breaks and returns what it returned.
    fn visit(
        &self,
        query: &Query,
        f: &mut dyn FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>>;

    /// Calls `f` once for every unordered pair of stored objects that overlap
    /// (closed), in no particular order. Stops early when `f` breaks.
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// The object the ray enters first: smallest entry `t`, ties broken by the
    /// smaller handle. Errors on an invalid ray. Indices with a hierarchy search
    /// front to back and skip what lies behind the best hit so far.
    fn ray_first(&self, ray: &Ray) -> Result<Option<RayHit>>;

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
        f: &mut dyn FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        (**self).visit(query, f)
    }
    fn visit_pairs(
        &self,
        f: &mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        (**self).visit_pairs(f)
    }
    fn ray_first(&self, ray: &Ray) -> Result<Option<RayHit>> {
        (**self).ray_first(ray)
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
