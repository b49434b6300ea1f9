//! [`SpatialIndexExt`]: the conveniences over the core trait (closures instead of
//! `&mut dyn`, collected results), written once for every index.

use super::{Query, RayHit, SpatialIndex};
use crate::geom::{overlap, Ray, Sphere};
use crate::{Handle, Result};
use glam::Vec3;
use std::ops::ControlFlow;

/// Conveniences implemented for every [`SpatialIndex`] (including
/// `dyn SpatialIndex<T>`), each a thin layer over one core method. Bring it into
/// scope with the trait: `use proxima::broad::{SpatialIndex, SpatialIndexExt}`.
///
/// Results that collect handles are in no particular order unless said.
/// [`AnyIndex`](super::AnyIndex) has inherent versions of the callback and pair
/// methods with the same meaning that skip the dynamic call per object.
pub trait SpatialIndexExt<T>: SpatialIndex<T> {
    /// Handles of the objects `query` selects (a [`Sphere`], an
    /// [`Aabb`](crate::geom::Aabb), a [`Ray`], a
    /// [`Frustum`](crate::geom::Frustum) or a [`Query`]). Errors on an invalid
    /// query. Cost: the index's query plus the result vector.
    fn query(&self, query: impl Into<Query>) -> Result<Vec<Handle>> {
        let mut out = Vec::new();
        let _ = self.visit(&query.into(), &mut |h, _, _| {
            out.push(h);
            ControlFlow::Continue(())
        })?;
        Ok(out)
    }

    /// Handles of the objects within `radius` of `center` (whose spheres overlap
    /// the ball; the point-radius query of [sources: index-trait]).
    fn within(&self, center: Vec3, radius: f32) -> Result<Vec<Handle>> {
        self.query(Sphere::new(center, radius))
    }

    /// [`SpatialIndex::visit`] with a closure.
    fn for_each_in(
        &self,
        query: impl Into<Query>,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        self.visit(&query.into(), &mut f)
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
        let mut hits = Vec::new();
        let _ = self.visit(&Query::Ray(*ray), &mut |h, s, _| {
            // The index selected it, so the exact test hits.
            if let Some(t) = overlap::ray_sphere(ray, s) {
                hits.push(RayHit { handle: h, t });
            }
            ControlFlow::Continue(())
        })?;
        hits.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.handle.cmp(&b.handle)));
        Ok(hits)
    }

    /// Every overlapping pair once, as `(a, b)` with `a < b`, in no particular
    /// order.
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

    /// Number of overlapping pairs.
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
