//! Range and frustum queries: visit the cells of a key box, report each object
//! from one cell only, and prune blocks of cells by the boxes of the objects
//! they report.
//!
//! **Once-only** [sources: grid-dedup]: a query over the key box `kb` reports
//! an object only from the cell `max(lo, kb.lo)` (per axis), the lowest cell of
//! the overlap of its key box `[lo, hi]` with `kb`. That cell is in both boxes,
//! so the object is referenced there and the visit reaches it exactly once. The
//! test is a few comparisons against the key box stored in the reference,
//! before any geometry. Clipping `kb` to the occupied box does not change that
//! cell, since every key of an object is occupied.
//!
//! **Report boxes.** The objects a block of cells reports are those whose
//! lowest shared cell is in the block: on every axis where the block starts
//! above `kb.lo`, their own lowest cell is in the block, so they lie in the
//! block grown *upwards* by twice the largest radius (their centres, by once);
//! only on the axes where the block starts at `kb.lo` do they reach below it.
//! These boxes are half the size of the usual loose box on most axes, so
//! [`Selection::classify_centres`] culls (`Outside`) and accepts (`Inside`,
//! reported without exact tests) far more blocks.
//!
//! **Large key boxes** (frusta, which have no bounding box, and large spheres
//! or boxes) are descended as an implicit tree: the whole key box (clipped to
//! the occupied box) is classified and an `Intersecting` part split in two
//! along a block boundary until it lies in one of the store's blocks (a
//! hashed store's blocks not occupied are skipped by one lookup), then
//! halved along its longest axis down to [`LEAF_CELLS`], each time with the
//! planes that still cut it (plane masking); empty parts of a hashed block are
//! skipped by its occupancy mask. Cost O(parts near the query's boundary +
//! cells inside it). A hashed store whose occupied box holds many more blocks
//! than are occupied (clusters far apart) is cut into its occupied blocks
//! instead, each descended alone, so no visit costs more than O(occupied
//! cells). (W4's frustum, over a cube of 2 197 blocks all occupied, classified
//! every block when each was descended alone: 5.1 M instructions per frustum,
//! 2.9 M with the descent from the whole box; rstar 3.1 M.)

use super::keys::{Key, KeyBox};
use super::list::{CellEntry, Packed};
use super::store::{Store, Within};
use super::CellGrid;
use crate::broad::walk::Cast;
use crate::broad::Selection;
use crate::geom::{Aabb, Frustum, Relation, Sphere, SphereSweep};
use crate::Handle;
use glam::Vec3;
use std::ops::ControlFlow;

/// Key boxes of at most this many cells are visited cell by cell without the
/// block descent (a small sphere or box query: classifying blocks would cost
/// more than it saves).
const FLAT_CELLS: u64 = 64;

/// Blocks of at most this many cells are not split further.
const LEAF_CELLS: u64 = 16;

impl<T, S: Store> CellGrid<T, S> {
    /// Reports every object `q` selects, each once: a ray or a sweep walks
    /// its cells (`ray.rs`), other shapes visit the key box of their bounds (every key
    /// for a frustum), then the oversized list is tested.
    pub fn walk<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if let Some(ray) = q.as_ray() {
            self.visit_cast(ray, &mut f)?;
        } else if let Some(sweep) = q.as_sweep().filter(|s| self.sweep_walks(s)) {
            self.visit_cast(sweep, &mut f)?;
        } else {
            let lattice = self.store.lattice();
            let kb = match q.bounds() {
                Some(b) => lattice.aabb_box(&b, S::AXES),
                None => lattice.limits,
            };
            self.visit_cells(q, kb, &mut f)?;
        }
        for &slot in &self.oversized {
            let s = &self.spheres[slot as usize];
            if q.selects(s) {
                let (h, v) = self.resolve(slot);
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// True if the cells of `sweep`'s bounding box are few enough
    /// ([`FLAT_CELLS`]) that visiting them all costs less than walking the
    /// segment, which tests each cell's box against the sweep (W8-shaped
    /// sweeps 2.5 cells long on the hash grid: 12.3 k instructions by the box,
    /// 17.0 k by the walk).
    #[inline]
    pub fn sweep_is_short(&self, sweep: &SphereSweep) -> bool {
        let lattice = self.store.lattice();
        lattice.aabb_box(&sweep.aabb(), S::AXES).volume() <= FLAT_CELLS
    }

    /// True if `sweep` takes the cell walk along its segment (`ray.rs`):
    /// it is not [short](Self::sweep_is_short), and the walk can follow it
    /// ([`Cast::walk_fits`]: its padded coordinates stay finite). Other
    /// sweeps visit the cells of their bounds, exact at any magnitude.
    #[inline]
    pub fn sweep_walks(&self, sweep: &SphereSweep) -> bool {
        sweep.walk_fits(0.0) && !self.sweep_is_short(sweep)
    }

    /// True if an object with lowest key `lo` is reported from `key` by a query
    /// over `kb` (the once-only rule).
    #[inline(always)]
    pub(super) fn reported_here(lo: Key, kb: &KeyBox, key: Key) -> bool {
        (0..S::AXES).all(|a| lo[a].max(kb.lo[a]) == key[a])
    }

    /// Reports the gridded objects selected by `q` among those referenced from
    /// the cells of `kb`, which must meet the key box of every gridded object `q`
    /// selects.
    pub(super) fn visit_cells<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: KeyBox,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let kb = kb.intersect(&self.store.occupied());
        if kb.is_empty() || self.refs == 0 {
            return ControlFlow::Continue(());
        }
        if kb.volume() <= FLAT_CELLS {
            return self.store.cells_in(&kb, |key, es| {
                self.test_cell(q, &kb, key, es, Frustum::ALL_PLANES, f)
            });
        }
        if self.store.descent_is_bounded(&kb) {
            return self.descend_blocks(q, &kb, kb, Frustum::ALL_PLANES, f);
        }
        self.store.blocks_in(&kb, |region, block| {
            self.descend(q, &kb, block, region, Frustum::ALL_PLANES, f)
        })
    }

    /// The descent above the store's blocks, over the planes in `mask`: a
    /// `region` spanning several blocks is classified and an `Intersecting`
    /// one split in two along a block boundary, until it lies in one block.
    fn descend_blocks<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        region: KeyBox,
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        match self.store.within(&region) {
            Within::One(block) => return self.descend(q, kb, block, region, mask, f),
            Within::Empty => return ControlFlow::Continue(()),
            Within::Many => {}
        }
        let (rel, mask) = self.classify(q, kb, &region, mask);
        match rel {
            Relation::Outside => ControlFlow::Continue(()),
            Relation::Inside => self
                .store
                .cells_in(&region, |key, es| self.report_all(kb, key, es, f)),
            Relation::Intersecting => {
                let (low, high) = self.store.split(&region);
                self.descend_blocks(q, kb, low, mask, f)?;
                self.descend_blocks(q, kb, high, mask, f)
            }
        }
    }

    /// `q` against the objects that the cells `region` report for a query
    /// over `kb`, over the planes in `mask`.
    #[inline]
    fn classify<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        region: &KeyBox,
        mask: u8,
    ) -> (Relation, u8) {
        let (centres, loose) = self.report_boxes(region, kb);
        q.classify_centres(&centres, &loose, mask)
    }

    /// Reports every reference of cell `key` that a query over `kb` reports
    /// there, without testing it (the cell is inside the query).
    #[inline]
    fn report_all(
        &self,
        kb: &KeyBox,
        key: Key,
        es: &[CellEntry<S::Packed>],
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for e in es {
            if Self::reported_here(e.keys.lo(), kb, key) {
                let (h, v) = self.resolve(e.slot);
                f(h, &self.spheres[e.slot as usize], v)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// One block of the descent (see the module docs), over the planes in `mask`.
    fn descend<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        block: S::Block,
        region: KeyBox,
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if !self.store.any_in(block, &region) {
            return ControlFlow::Continue(());
        }
        let (rel, mask) = self.classify(q, kb, &region, mask);
        match rel {
            Relation::Outside => ControlFlow::Continue(()),
            Relation::Inside => self
                .store
                .cells_in_block(block, &region, |key, es| self.report_all(kb, key, es, f)),
            Relation::Intersecting if region.volume() <= LEAF_CELLS => {
                self.store.cells_in_block(block, &region, |key, es| {
                    self.test_cell(q, kb, key, es, mask, f)
                })
            }
            Relation::Intersecting => {
                let (low, high) = region.halves();
                self.descend(q, kb, block, low, mask, f)?;
                self.descend(q, kb, block, high, mask, f)
            }
        }
    }

    /// The references of cell `key` reported here, tested against `q` over the
    /// planes in `mask` (the others keep every sphere of the cell). Cells are
    /// not classified first: with the few references of a cell that costs
    /// more than the tests it saves (W4 callgrind: 45% more instructions per
    /// small sphere query on the hash grid, 12% on the 2D grid).
    #[inline]
    fn test_cell<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        key: Key,
        es: &[CellEntry<S::Packed>],
        mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for e in es {
            if !Self::reported_here(e.keys.lo(), kb, key) {
                continue;
            }
            let s = &self.spheres[e.slot as usize];
            if q.selects_masked(s, mask) {
                let (h, v) = self.resolve(e.slot);
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Boxes around the centres and around the spheres of the objects that the
    /// cells `region` report for a query over `kb` (see the module docs),
    /// padded for rounding.
    #[inline]
    pub(super) fn report_boxes(&self, region: &KeyBox, kb: &KeyBox) -> (Aabb, Aabb) {
        (
            self.report_box(region, kb, 1.0),
            self.report_box(region, kb, 2.0),
        )
    }

    /// The cells `region` grown by `radii` times the largest gridded radius
    /// upwards, and downwards only on the axes where `region` starts at or
    /// below `kb.lo` (see the module docs); clipped to the bounds of every
    /// gridded sphere, padded for rounding. With `radii = 2` it contains every
    /// sphere the cells report for a query over `kb`; with 1, their centres.
    #[inline]
    pub(super) fn report_box(&self, region: &KeyBox, kb: &KeyBox, radii: f32) -> Aabb {
        let lattice = self.store.lattice();
        let from_below = glam::IVec3::from(region.lo).cmple(kb.lo.into());
        let below = Vec3::select(from_below, Vec3::splat(radii), Vec3::ZERO);
        let b = self.reach.around(
            lattice.cells_box(region),
            (below, Vec3::splat(radii)),
            lattice.open_sides(region),
        );
        lattice.padded(&b)
    }
}
