//! The world's broad phase: an [`AnyIndex`] over the objects' bounding spheres,
//! built lazily from the scene and rebuilt when the scene drifts far from what
//! it was built for (the rule is in [`World`](super::World)'s docs).

use super::{Object, WorldConfig};
use crate::arena::Arena;
use crate::broad::{AnyIndex, Filter, IndexKind, Query, SceneHint, SpatialIndex};
use crate::geom::{overlap, Aabb, Relation, Sphere};
use crate::{Handle, Result};
use std::ops::ControlFlow;

/// The index and what it was built for. The payload of each stored sphere is
/// the object's slot in the world's arena.
#[derive(Debug, Default)]
pub(crate) struct Broad {
    pub(crate) index: Option<AnyIndex<u32>>,
    /// Centres outside this box count as drifted (the built world box grown by
    /// half its extent on every side).
    drift_box: Option<Aabb>,
    /// Radii above this count as drifted (4× the built `r_max`).
    drift_radius: f32,
    /// Number of live objects whose sphere is drifted.
    pub(crate) drifted: usize,
    /// Number of builds so far.
    pub(crate) builds: u64,
}

/// Objects that may drift before a rebuild is due: `max(MIN_DRIFTED, n / 4)`.
const MIN_DRIFTED: usize = 8;

impl Broad {
    /// Whether a sphere counts as drifted for the current build. Before the
    /// first build nothing does; with fixed bounds, only radii count.
    pub(crate) fn is_drifted(&self, s: &Sphere, bounded: bool) -> bool {
        if self.index.is_none() {
            return false;
        }
        let outside = !bounded && self.drift_box.is_some_and(|b| !b.contains_point(s.center));
        outside || s.radius > self.drift_radius
    }

    /// Whether a build is due for `n` live objects: none yet, or too many
    /// drifted.
    pub(crate) fn due(&self, n: usize) -> bool {
        self.index.is_none() || self.drifted > MIN_DRIFTED.max(n / 4)
    }

    /// Builds a new index over every object (O(n)) and points the objects at
    /// it. On error the old index and the objects are unchanged.
    pub(crate) fn rebuild<T, BV>(
        &mut self,
        config: &WorldConfig,
        objects: &mut Arena<Object<T, BV>>,
    ) -> Result<()> {
        let spheres = objects.iter().map(|(_, o)| o.sphere);
        let mut hint = SceneHint::from_spheres(spheres, objects.len());
        if let Some(b) = config.bounds {
            hint.world = b;
        }
        let kind = config.index.unwrap_or(IndexKind::LooseKd);
        let mut index: AnyIndex<u32> = kind.build(&hint)?;
        let mut handles = Vec::with_capacity(objects.len());
        for (h, o) in objects.iter() {
            // With its filter: the index's pair search prunes by it.
            handles.push(index.insert_with_filter(o.sphere, o.filter, h.index())?);
        }
        let grow = hint.world.extent() * 0.5;
        self.drift_box = Some(Aabb::new(hint.world.min - grow, hint.world.max + grow));
        self.drift_radius = 4.0 * hint.r_max;
        self.index = Some(index);
        self.builds += 1;
        let bounded = config.bounds.is_some();
        let mut drifted = 0;
        for ((_, o), b) in objects.iter_mut().zip(handles) {
            o.broad = Some(b);
            o.drift = self.is_drifted(&o.sphere, bounded);
            drifted += o.drift as usize;
        }
        self.drifted = drifted;
        Ok(())
    }

    /// Stores a sphere with the object's filter if the index is built; its
    /// handle there.
    pub(crate) fn insert(
        &mut self,
        s: Sphere,
        filter: Filter,
        slot: u32,
    ) -> Result<Option<Handle>> {
        match &mut self.index {
            Some(i) => Ok(Some(i.insert_with_filter(s, filter, slot)?)),
            None => Ok(None),
        }
    }

    /// Gives the index's copy of an object the object's new filter.
    pub(crate) fn set_filter(&mut self, h: Handle, filter: Filter) -> Result<()> {
        if let Some(i) = &mut self.index {
            i.set_filter(h, filter)?;
        }
        Ok(())
    }

    pub(crate) fn remove(&mut self, h: Handle) -> Result<()> {
        if let Some(i) = &mut self.index {
            i.remove(h)?;
        }
        Ok(())
    }

    pub(crate) fn update(&mut self, h: Handle, s: Sphere) -> Result<()> {
        if let Some(i) = &mut self.index {
            i.update(h, s)?;
        }
        Ok(())
    }

    pub(crate) fn kind(&self) -> Option<IndexKind> {
        self.index.as_ref().map(|i| i.kind())
    }

    pub(crate) fn memory_bytes(&self) -> usize {
        self.index.as_ref().map_or(0, |i| i.memory_bytes())
    }

    /// Calls `f` with the slot of every object whose broad sphere `query`
    /// selects (closed tests, as every index answers them): through the index
    /// once built, otherwise by scanning the objects with the same tests.
    /// `query` must be valid.
    pub(crate) fn visit<T, BV>(
        &self,
        objects: &Arena<Object<T, BV>>,
        query: &Query,
        mut f: impl FnMut(u32),
    ) -> Result<()> {
        if let Some(index) = &self.index {
            return visit_index(index, query, &mut f);
        }
        query.validate()?;
        for (h, o) in objects.iter() {
            let s = &o.sphere;
            let hit = match query {
                Query::Sphere(q) => overlap::sphere_sphere(q, s),
                Query::Aabb(b) => overlap::sphere_aabb(s, b),
                Query::Ray(r) => overlap::ray_touches_sphere(r, s),
                Query::Frustum(fr) => overlap::frustum_sphere(fr, s) != Relation::Outside,
                Query::Sweep(sw) => overlap::sweep_touches_sphere(sw, s),
            };
            if hit {
                f(h.index());
            }
        }
        Ok(())
    }

    /// Calls `f` with the slots of every overlapping pair of objects whose
    /// filters interact, once each, in no particular order, through the
    /// index's pair search (its cost). The callback sits behind `dyn` for the
    /// reason given at [`visit_index`]. Panics if the index is not built (the
    /// callers build it first).
    pub(crate) fn for_each_pair(&self, f: &mut dyn FnMut(u32, u32)) {
        let index = self.index.as_ref().expect("the broad phase is built");
        let _ = index.for_each_pair(|_, &a, _, &b| {
            f(a, b);
            ControlFlow::Continue(())
        });
    }
}

/// [`Broad::visit`] through the index. Not generic, the caller's closure
/// behind `dyn`: the index walks are compiled once, in this crate, rather
/// than once per world method, payload type and bounding volume in every
/// crate that uses a [`World`](super::World) (the world tests' crate took
/// 327 s to build in CI's `cargo test`, most of it in copies of the grids'
/// walks; 44 s since: `docs/bench/ci-build-e7d3473.txt`). It costs an
/// indirect call per candidate, small beside what the world's callers do with
/// one (callgrind on the world bench scenes: +0.01% instructions).
fn visit_index(index: &AnyIndex<u32>, query: &Query, f: &mut dyn FnMut(u32)) -> Result<()> {
    let _ = index.for_each_in(*query, |_, _, &slot| {
        f(slot);
        ControlFlow::Continue(())
    })?;
    Ok(())
}
