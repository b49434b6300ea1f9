//! The generic walks behind the object-safe trait (crate-private).
//!
//! Each index implements [`Walk`] with its traversals generic over the query
//! shape and the callback, so every shape gets its own compiled loop. The
//! public [`SpatialIndex`](super::SpatialIndex) methods reach them through
//! [`visit`] (one `match` on the [`Query`] per call); [`AnyIndex`](super::AnyIndex)
//! calls them directly with the caller's closure.

use super::{Query, RayHit, Selection};
use crate::geom::{overlap, Ray, Sphere};
use crate::{Handle, Result};
use std::ops::ControlFlow;

/// An index's traversals, generic over the query and the callback.
pub(crate) trait Walk<T> {
    /// Reports every object `query` selects, each once, without validating the
    /// query. Stops when `f` breaks and returns what it returned.
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// Reports every overlapping pair once. Stops when `f` breaks.
    fn walk_pairs(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// The hit with the smallest entry `t` (ties: smallest handle), without
    /// validating the ray. The default scans every hit; indices with a
    /// hierarchy override it with a front-to-back search.
    fn first_hit(&self, ray: &Ray) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        let _ = self.walk(ray, |h, s, _| {
            if let Some(t) = overlap::ray_sphere(ray, s) {
                RayHit::offer(&mut best, t, h);
            }
            ControlFlow::Continue(())
        });
        best
    }
}

/// Validates `query`, then runs the index's walk for its shape: the one match
/// per query of every [`SpatialIndex::visit`](super::SpatialIndex::visit).
#[inline]
pub(crate) fn visit<T, I: Walk<T> + ?Sized>(
    index: &I,
    query: &Query,
    f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
) -> Result<ControlFlow<()>> {
    query.validate()?;
    Ok(match query {
        Query::Sphere(s) => index.walk(s, f),
        Query::Aabb(b) => index.walk(b, f),
        Query::Ray(r) => index.walk(r, f),
        Query::Frustum(fr) => index.walk(fr, f),
    })
}

/// The query methods of [`SpatialIndex`](super::SpatialIndex) for a type that
/// implements [`Walk`]: written once, expanded inside each index's impl.
macro_rules! walk_methods {
    ($t:ty) => {
        fn visit(
            &self,
            query: &$crate::broad::Query,
            f: &mut dyn FnMut(
                $crate::Handle,
                &$crate::geom::Sphere,
                &$t,
            ) -> std::ops::ControlFlow<()>,
        ) -> $crate::Result<std::ops::ControlFlow<()>> {
            $crate::broad::walk::visit(self, query, f)
        }

        fn visit_pairs(
            &self,
            f: &mut dyn FnMut(
                $crate::Handle,
                &$t,
                $crate::Handle,
                &$t,
            ) -> std::ops::ControlFlow<()>,
        ) -> std::ops::ControlFlow<()> {
            $crate::broad::walk::Walk::walk_pairs(self, f)
        }

        fn ray_first(
            &self,
            ray: &$crate::geom::Ray,
        ) -> $crate::Result<Option<$crate::broad::RayHit>> {
            ray.validate()?;
            Ok($crate::broad::walk::Walk::first_hit(self, ray))
        }
    };
}
pub(crate) use walk_methods;
