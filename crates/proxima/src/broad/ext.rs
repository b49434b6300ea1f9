//! [`SpatialIndexExt`]: the conveniences over the core trait (closures instead of
//! `&mut dyn`, collected results), written once for every index, and
//! [`Filtered`], the same conveniences with a query filter.

use super::{Filter, Nearest, Neighbor, Query, RayHit, SpatialIndex, SweepHit};
use crate::geom::{overlap, Ray, Sphere, SphereSweep};
use crate::{Handle, Result};
use glam::Vec3;
use std::marker::PhantomData;
use std::ops::ControlFlow;

/// Conveniences implemented for every [`SpatialIndex`] (including
/// `dyn SpatialIndex<T>`), each a thin layer over one core method. Bring it into
/// scope with the trait: `use proxima::broad::{SpatialIndex, SpatialIndexExt}`.
///
/// They are unfiltered (every object the query selects); the same methods with
/// a query filter are on [`SpatialIndexExt::filtered`]'s view. Results that
/// collect handles are in no particular order unless said.
/// [`AnyIndex`](super::AnyIndex) has inherent versions of the callback and pair
/// methods with the same meaning that skip the dynamic call per object.
pub trait SpatialIndexExt<T>: SpatialIndex<T> {
    /// Handles of the objects `query` selects (a [`Sphere`], an
    /// [`Aabb`](crate::geom::Aabb), a [`Ray`], a
    /// [`Frustum`](crate::geom::Frustum), a [`SphereSweep`] or a [`Query`]).
    /// Errors on an invalid query. Cost: the index's query plus the result
    /// vector.
    fn query(&self, query: impl Into<Query>) -> Result<Vec<Handle>> {
        collect(self, &query.into(), None)
    }

    /// Handles of the objects within `radius` of `center` (whose spheres overlap
    /// the ball; the point-radius query of [sources: index-trait]).
    fn within(&self, center: Vec3, radius: f32) -> Result<Vec<Handle>> {
        self.query(Sphere::new(center, radius))
    }

    /// [`SpatialIndex::visit`] (unfiltered) with a closure.
    fn for_each_in(
        &self,
        query: impl Into<Query>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.visit(&query.into(), None, &mut f)
    }

    /// [`SpatialIndex::visit_pairs`] with a closure.
    fn for_each_pair(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.visit_pairs(&mut f)
    }

    /// Every object the ray touches with its entry `t`, sorted by `t`, ties by
    /// handle. For a segment, pass [`Segment::to_ray`](crate::geom::Segment::to_ray)
    /// (then `t` is in `[0, 1]`). Errors on an invalid ray.
    fn ray_hits(&self, ray: &Ray) -> Result<Vec<RayHit>> {
        ray_hits(self, ray, None)
    }

    /// Every object the moving sphere touches with its time of impact
    /// ([`overlap::sweep_sphere`]), sorted by `t`, ties by handle; the first is
    /// [`SpatialIndex::sweep_first`]'s. Errors on an invalid sweep. Cost: the
    /// [`Query::Sweep`] walk plus a sort of the hits.
    fn sweep_hits(&self, sweep: &SphereSweep) -> Result<Vec<SweepHit>> {
        sweep_hits(self, sweep, None)
    }

    /// The `k` objects nearest to `point` by distance to their surface
    /// (`max(0, |c - point| - r)`, correctly rounded), nearest first, ties by
    /// handle; fewer when fewer are stored. Errors on a non-finite point. For
    /// the centre distance, a distance limit or no allocation per query, use
    /// [`SpatialIndex::nearest_into`] with a [`Nearest`].
    fn nearest(&self, point: Vec3, k: usize) -> Result<Vec<Neighbor>> {
        nearest(self, &Nearest::new(point, k), None)
    }

    /// [`nearest`](SpatialIndexExt::nearest) among the objects at most
    /// `max_distance` from `point` (inclusive). Errors also on a NaN or
    /// negative `max_distance`.
    fn nearest_within(&self, point: Vec3, k: usize, max_distance: f32) -> Result<Vec<Neighbor>> {
        nearest(self, &Nearest::new(point, k).within(max_distance), None)
    }

    /// The queries above restricted to objects whose filter interacts with
    /// `filter` (see [`SpatialIndex`]'s section on filters): a view that
    /// passes `Some(filter)` to every core query. O(1), borrows the index.
    fn filtered(&self, filter: Filter) -> Filtered<'_, T, Self> {
        Filtered {
            index: self,
            filter,
            _payload: PhantomData,
        }
    }

    /// Every overlapping pair whose filters interact, once, as `(a, b)` with
    /// `a < b`, in no particular order.
    fn pairs(&self) -> Vec<(Handle, Handle)> {
        let mut out = Vec::new();
        let _ = self.visit_pairs(&mut |a, _, b, _| {
            out.push(if a < b { (a, b) } else { (b, a) });
            ControlFlow::Continue(())
        });
        out
    }

    /// Moves/resizes each `(handle, sphere)` in turn (a frame's motion), as
    /// [`SpatialIndex::update`] would one by one. Stops at the first error:
    /// that object and the later ones are unchanged, the earlier ones moved.
    fn update_many(&mut self, moves: impl IntoIterator<Item = (Handle, Sphere)>) -> Result<()> {
        moves.into_iter().try_for_each(|(h, s)| self.update(h, s))
    }

    /// Number of overlapping pairs whose filters interact.
    fn count_pairs(&self) -> u64 {
        let mut n = 0;
        let _ = self.visit_pairs(&mut |_, _, _, _| {
            n += 1;
            ControlFlow::Continue(())
        });
        n
    }
}

impl<T, I: SpatialIndex<T> + ?Sized> SpatialIndexExt<T> for I {}

/// An index seen through a query filter: the conveniences of
/// [`SpatialIndexExt`] and the core queries, each reporting only the objects
/// whose [`Filter`] interacts with this one. Made by
/// [`SpatialIndexExt::filtered`].
pub struct Filtered<'a, T, I: ?Sized> {
    index: &'a I,
    filter: Filter,
    _payload: PhantomData<fn(&T)>,
}

impl<T, I: SpatialIndex<T> + ?Sized> Filtered<'_, T, I> {
    /// The query filter.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// [`SpatialIndexExt::query`], filtered.
    pub fn query(&self, query: impl Into<Query>) -> Result<Vec<Handle>> {
        collect(self.index, &query.into(), Some(self.filter))
    }

    /// [`SpatialIndexExt::within`], filtered.
    pub fn within(&self, center: Vec3, radius: f32) -> Result<Vec<Handle>> {
        self.query(Sphere::new(center, radius))
    }

    /// [`SpatialIndexExt::for_each_in`], filtered.
    pub fn for_each_in(
        &self,
        query: impl Into<Query>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.index.visit(&query.into(), Some(self.filter), &mut f)
    }

    /// [`SpatialIndexExt::ray_hits`], filtered.
    pub fn ray_hits(&self, ray: &Ray) -> Result<Vec<RayHit>> {
        ray_hits(self.index, ray, Some(self.filter))
    }

    /// [`SpatialIndex::ray_first`], filtered.
    pub fn ray_first(&self, ray: &Ray) -> Result<Option<RayHit>> {
        self.index.ray_first(ray, Some(self.filter))
    }

    /// [`SpatialIndexExt::sweep_hits`], filtered.
    pub fn sweep_hits(&self, sweep: &SphereSweep) -> Result<Vec<SweepHit>> {
        sweep_hits(self.index, sweep, Some(self.filter))
    }

    /// [`SpatialIndex::sweep_first`], filtered.
    pub fn sweep_first(&self, sweep: &SphereSweep) -> Result<Option<SweepHit>> {
        self.index.sweep_first(sweep, Some(self.filter))
    }

    /// [`SpatialIndexExt::nearest`], filtered.
    pub fn nearest(&self, point: Vec3, k: usize) -> Result<Vec<Neighbor>> {
        nearest(self.index, &Nearest::new(point, k), Some(self.filter))
    }

    /// [`SpatialIndexExt::nearest_within`], filtered.
    pub fn nearest_within(
        &self,
        point: Vec3,
        k: usize,
        max_distance: f32,
    ) -> Result<Vec<Neighbor>> {
        let q = Nearest::new(point, k).within(max_distance);
        nearest(self.index, &q, Some(self.filter))
    }

    /// [`SpatialIndex::nearest_into`], filtered.
    pub fn nearest_into(&self, query: &Nearest, out: &mut Vec<Neighbor>) -> Result<()> {
        self.index.nearest_into(query, Some(self.filter), out)
    }
}

/// Handles of the objects `query` and `filter` select.
fn collect<T, I: SpatialIndex<T> + ?Sized>(
    index: &I,
    query: &Query,
    filter: Option<Filter>,
) -> Result<Vec<Handle>> {
    let mut out = Vec::new();
    let _ = index.visit(query, filter, &mut |h, _, _| {
        out.push(h);
        ControlFlow::Continue(())
    })?;
    Ok(out)
}

/// Every hit of `ray` among the objects `filter` admits, sorted by (t, handle).
fn ray_hits<T, I: SpatialIndex<T> + ?Sized>(
    index: &I,
    ray: &Ray,
    filter: Option<Filter>,
) -> Result<Vec<RayHit>> {
    let mut hits = Vec::new();
    let _ = index.visit(&Query::Ray(*ray), filter, &mut |h, s, _| {
        // The index selected it, so the exact test hits.
        if let Some(t) = overlap::ray_sphere(ray, s) {
            hits.push(RayHit { handle: h, t });
        }
        ControlFlow::Continue(())
    })?;
    sort_hits(&mut hits);
    Ok(hits)
}

/// Every object `sweep` touches among those `filter` admits, sorted by
/// (t, handle).
fn sweep_hits<T, I: SpatialIndex<T> + ?Sized>(
    index: &I,
    sweep: &SphereSweep,
    filter: Option<Filter>,
) -> Result<Vec<SweepHit>> {
    let mut hits = Vec::new();
    // The sweep's own terms once, not once per hit.
    let test = overlap::SweepTest::new(sweep);
    let _ = index.visit(&Query::Sweep(*sweep), filter, &mut |h, s, _| {
        if let Some(t) = test.contact(s) {
            hits.push(RayHit { handle: h, t });
        }
        ControlFlow::Continue(())
    })?;
    sort_hits(&mut hits);
    Ok(hits)
}

/// The first-hit order: smaller `t`, then smaller handle.
fn sort_hits(hits: &mut [RayHit]) {
    hits.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.handle.cmp(&b.handle)));
}

/// The answer of `query` in a new vector.
fn nearest<T, I: SpatialIndex<T> + ?Sized>(
    index: &I,
    query: &Nearest,
    filter: Option<Filter>,
) -> Result<Vec<Neighbor>> {
    let mut out = Vec::new();
    index.nearest_into(query, filter, &mut out)?;
    Ok(out)
}
