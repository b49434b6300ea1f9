//! The generic walks behind the object-safe trait (crate-private).
//!
//! Each index implements [`Walk`] with its traversals generic over the query
//! shape and the callback, so every shape gets its own compiled loop. The
//! public [`SpatialIndex`](super::SpatialIndex) methods reach them through
//! [`visit`] (one `match` on the [`Query`] per call) and [`walk_methods`];
//! [`AnyIndex`](super::AnyIndex) calls them directly with the caller's closure.
//!
//! The searches that are not a plain selection (first ray hit, first sweep
//! hit, k nearest) and the query filter have correct default implementations
//! here, written once on top of [`Walk::walk`]; an index overrides them with
//! its own traversal (front-to-back, best-first, pruning by filter bits).

use super::nearest::{self, Nearest, Neighbor};
use super::selection::Prepared;
use super::{Filter, Query, RayHit, Selection};
use crate::geom::overlap::{EntryBound, SweepTest};
use crate::geom::{overlap, Ray, Sphere, SphereSweep};
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

    /// Reports every overlapping pair whose stored filters interact, once.
    /// Stops when `f` breaks.
    fn walk_pairs(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// The filter stored with the live object `h` (callers pass handles the
    /// walks reported, so a stale one is a bug).
    fn filter_of(&self, h: Handle) -> Filter;

    /// Number of stored objects.
    fn object_count(&self) -> usize;

    /// [`Walk::walk`] reporting only objects whose filter interacts with
    /// `filter` (all of them for `None`). The default tests each selected
    /// object's filter ([`Walk::filter_of`]); an index may prune inside its
    /// traversal instead.
    #[inline]
    fn walk_filtered<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        filter: Option<Filter>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        match filter {
            None => self.walk(query, f),
            Some(q) => self.walk(query, |h, s, v| {
                if q.interacts(self.filter_of(h)) {
                    f(h, s, v)
                } else {
                    ControlFlow::Continue(())
                }
            }),
        }
    }

    /// The hit with the smallest entry `t` (ties: smallest handle) among the
    /// objects `filter` admits, without validating the ray. The default scans
    /// every hit; indices with a hierarchy override it with a front-to-back
    /// search.
    fn first_hit(&self, ray: &Ray, filter: Option<Filter>) -> Option<RayHit> {
        scan_first(self, ray, filter)
    }

    /// The object the sweep touches first: smallest time of impact
    /// ([`overlap::sweep_sphere`]), ties by the smaller handle, among the
    /// objects `filter` admits; without validating the sweep. The default scans
    /// every touched object (the index's walk for [`Query::Sweep`]); indices
    /// with a hierarchy search front to back, pruning by
    /// [`overlap::sweep_aabb`]'s entry bound.
    fn first_sweep_hit(&self, sweep: &SphereSweep, filter: Option<Filter>) -> Option<RayHit> {
        scan_first(self, sweep, filter)
    }

    /// The answer of a k-nearest query into `out` (cleared first), nearest
    /// first, without validating the query. The default is the expanding
    /// sphere search of `nearest.rs`; indices override it with best-first or
    /// ring searches.
    fn knn_into(&self, query: &Nearest, filter: Option<Filter>, out: &mut Vec<Neighbor>) {
        nearest::expanding(self, query, filter, out)
    }
}

/// A ray or a sphere sweep, as the first-hit searches see it: a selection
/// with a parameter of first contact. Written once here so that every index
/// answers `ray_first` and `sweep_first` with one search each.
pub(crate) trait Cast: Selection {
    /// The cast's sphere tests, prepared once per query.
    type Test: Contact;
    /// Prepares the sphere tests: what a search does once before testing
    /// many spheres. O(1).
    fn test(&self) -> Self::Test;
    /// The cast prepared for its search's box tests, over stored spheres
    /// whose bounding boxes have coordinates of magnitude at most `m`
    /// ([`EntryBound::sweep`]; `0` for a walk that needs only touch tests):
    /// [`EntryBound::enter`] is a lower bound on [`Cast::contact`] of every
    /// sphere inside a box (below [`overlap::ray_aabb`]'s or
    /// [`overlap::sweep_aabb`]'s entry of the sphere's box, to which
    /// `contact` is clamped, by monotonicity), and `None` only when the cast
    /// touches nothing inside it; so front-to-back searches may skip a box
    /// entered after the best contact so far.
    fn entry(&self, m: f32) -> EntryBound;
    /// The line the cast's centre follows, as a ray whose parameter is the
    /// cast's, and how far from that line the cast reaches: `0` for a ray; a
    /// sweep's radius plus the rounding of its direction `to - from` (which
    /// the ray rounds but the exact tests do not). The grids' segment walks
    /// follow it, widened by the reach, conservatively.
    fn path(&self) -> (Ray, f32);

    /// Whether the grids' segment walks can follow this cast's path
    /// ([`Cast::path`]) over a region whose coordinates (plus the grid's own
    /// padding) are at most `m` in magnitude: the path's origin, its length
    /// up to `t = 1`, its reach and `m` add up to less than 2^-4 of
    /// `f32::MAX`, so that every padded coordinate and bound of the walk
    /// stays finite. A sweep or region near `f32::MAX` (ops proptest: a sweep
    /// from x = 3.4e38 to -2.1e36 padded to infinity and missed a hit; a
    /// radius near `f32::MAX` made the clip meet `∞ - ∞`) fails it, and so
    /// does a NaN; the grids then visit the cells of the cast's bounds
    /// instead, exact at any magnitude. The one guard of both grids' walks.
    #[inline]
    fn walk_fits(&self, m: f32) -> bool {
        const SAFE: f32 = f32::MAX / 16.0;
        let (ray, r) = self.path();
        let len = ray.dir.abs().max_element() * ray.max_t.min(1.0);
        ray.origin.abs().max_element() + len + r + m < SAFE
    }
}

/// A cast's exact sphere tests, with whatever depends on the cast alone
/// computed once ([`Cast::test`]): a sweep's pre-test terms
/// ([`SweepTest`]); a ray needs nothing.
pub(crate) trait Contact {
    /// The parameter at which the cast first touches the closed sphere `s`,
    /// or `None` ([`overlap::ray_sphere`], [`overlap::sweep_sphere`]).
    fn contact(&self, s: &Sphere) -> Option<f32>;
    /// Whether [`Contact::contact`] is `Some`, without computing it
    /// ([`overlap::ray_touches_sphere`], [`overlap::sweep_touches_sphere`]).
    fn touches(&self, s: &Sphere) -> bool;
    /// Whether [`Contact::misses4`] is a real pre-test (else leaf scans
    /// take the spheres one at a time).
    const HAS_MISSES4: bool = false;
    /// A mask of four spheres (bit `j` for `s[j]`) that [`Contact::contact`]
    /// certainly finds `None` for, by a SIMD pre-test; 0 where a cast has
    /// none. The octree's leaf scans call it first: its first-hit search,
    /// and its selection walk through [`Selection::rejects4`](super::Selection::rejects4).
    #[inline(always)]
    fn misses4(&self, _s: [&Sphere; 4]) -> u32 {
        0
    }
    /// [`Contact::contact`] of a sphere that [`Contact::misses4`] left in:
    /// a cast whose scalar test starts with the same pre-test skips it.
    #[inline(always)]
    fn contact_after_misses4(&self, s: &Sphere) -> Option<f32> {
        self.contact(s)
    }
    /// [`Contact::touches`] of a sphere that [`Contact::misses4`] left in,
    /// as [`Contact::contact_after_misses4`].
    #[inline(always)]
    fn touches_after_misses4(&self, s: &Sphere) -> bool {
        self.touches(s)
    }
}

impl Contact for Ray {
    #[inline]
    fn contact(&self, s: &Sphere) -> Option<f32> {
        overlap::ray_sphere(self, s)
    }
    #[inline]
    fn touches(&self, s: &Sphere) -> bool {
        overlap::ray_touches_sphere(self, s)
    }
}

impl Contact for SweepTest {
    #[inline]
    fn contact(&self, s: &Sphere) -> Option<f32> {
        SweepTest::contact(self, s)
    }
    #[inline]
    fn touches(&self, s: &Sphere) -> bool {
        SweepTest::touches(self, s)
    }
    const HAS_MISSES4: bool = true;
    #[inline(always)]
    fn misses4(&self, s: [&Sphere; 4]) -> u32 {
        SweepTest::misses4(self, s)
    }
    #[inline(always)]
    fn contact_after_misses4(&self, s: &Sphere) -> Option<f32> {
        self.contact_undecided(s)
    }
    #[inline(always)]
    fn touches_after_misses4(&self, s: &Sphere) -> bool {
        self.touches_undecided(s)
    }
}

impl Cast for Ray {
    type Test = Ray;
    #[inline]
    fn test(&self) -> Ray {
        *self
    }
    #[inline]
    fn entry(&self, _m: f32) -> EntryBound {
        EntryBound::ray(self)
    }
    #[inline]
    fn path(&self) -> (Ray, f32) {
        (*self, 0.0)
    }
}

impl Cast for SphereSweep {
    type Test = SweepTest;
    #[inline]
    fn test(&self) -> SweepTest {
        SweepTest::new(self)
    }
    #[inline]
    fn entry(&self, m: f32) -> EntryBound {
        EntryBound::sweep(self, m)
    }
    /// From `from` along `to - from` up to `t = 1`, reaching the radius plus
    /// 2^-22 of the end points' magnitude (more than the rounding of
    /// `to - from`, and of `from + (to - from) t`, at any `t` in `[0, 1]`).
    #[inline]
    fn path(&self) -> (Ray, f32) {
        let ray = Ray::with_max_t(self.from, self.to - self.from, 1.0);
        let m = self.from.abs().max(self.to.abs()).max_element();
        (ray, self.radius + m * (1.0 / 4194304.0))
    }
}

/// The first contact of a ray or sweep by a scan of everything the index's
/// walk selects (the default of [`Walk::first_hit`] and
/// [`Walk::first_sweep_hit`], also the fallback of overrides that do not
/// handle a query filter).
pub(crate) fn scan_first<T, I: Walk<T> + ?Sized, C: Cast>(
    index: &I,
    cast: &C,
    filter: Option<Filter>,
) -> Option<RayHit> {
    let mut best: Option<RayHit> = None;
    let test = cast.test();
    let _ = index.walk_filtered(cast, filter, |h, s, _| {
        if let Some(t) = test.contact(s) {
            RayHit::offer(&mut best, t, h);
        }
        ControlFlow::Continue(())
    });
    best
}

/// Validates `query`, then runs the index's walk for its shape: the one match
/// per query of every [`SpatialIndex::visit`](super::SpatialIndex::visit).
#[inline]
pub(crate) fn visit<T, I: Walk<T> + ?Sized>(
    index: &I,
    query: &Query,
    filter: Option<Filter>,
    f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
) -> Result<ControlFlow<()>> {
    query.validate()?;
    Ok(match query {
        Query::Sphere(s) => index.walk_filtered(s, filter, f),
        Query::Aabb(b) => index.walk_filtered(b, filter, f),
        // Casts are prepared once per walk: the box tests of their many
        // nodes and chunks need no division (W8 hits, callgrind: the exact
        // box tests were ~half of the trees' instructions).
        Query::Ray(r) => index.walk_filtered(&Prepared::new(r), filter, f),
        Query::Frustum(fr) => index.walk_filtered(fr, filter, f),
        Query::Sweep(sw) => index.walk_filtered(&Prepared::new(sw), filter, f),
    })
}

/// The query methods of [`SpatialIndex`](super::SpatialIndex) for a type that
/// implements [`Walk`]: written once, expanded inside each index's impl.
macro_rules! walk_methods {
    ($t:ty) => {
        fn visit(
            &self,
            query: &$crate::broad::Query,
            filter: Option<$crate::broad::Filter>,
            f: &mut dyn FnMut(
                $crate::Handle,
                &$crate::geom::Sphere,
                &$t,
            ) -> std::ops::ControlFlow<()>,
        ) -> $crate::Result<std::ops::ControlFlow<()>> {
            $crate::broad::walk::visit(self, query, filter, f)
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
            filter: Option<$crate::broad::Filter>,
        ) -> $crate::Result<Option<$crate::broad::RayHit>> {
            ray.validate()?;
            Ok($crate::broad::walk::Walk::first_hit(self, ray, filter))
        }

        fn sweep_first(
            &self,
            sweep: &$crate::geom::SphereSweep,
            filter: Option<$crate::broad::Filter>,
        ) -> $crate::Result<Option<$crate::broad::SweepHit>> {
            sweep.validate()?;
            Ok($crate::broad::walk::Walk::first_sweep_hit(
                self, sweep, filter,
            ))
        }

        fn nearest_into(
            &self,
            query: &$crate::broad::Nearest,
            filter: Option<$crate::broad::Filter>,
            out: &mut Vec<$crate::broad::Neighbor>,
        ) -> $crate::Result<()> {
            out.clear();
            query.validate()?;
            $crate::broad::walk::Walk::knn_into(self, query, filter, out);
            Ok(())
        }
    };
}
pub(crate) use walk_methods;
