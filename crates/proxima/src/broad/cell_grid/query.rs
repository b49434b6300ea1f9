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
//! or boxes) are descended from the store's top-level blocks as an implicit
//! tree: a block is classified, and an `Intersecting` one split in two along
//! its longest axis with the planes that still cut it (plane masking), down to
//! [`LEAF_CELLS`]; empty parts of a hashed block are skipped by its occupancy
//! mask. Cost O(blocks near the query's boundary + cells inside it), never
//! more than O(occupied cells) for a hashed store.

use super::keys::{Key, KeyBox};
use super::list::{CellEntry, Packed};
use super::store::Store;
use super::CellGrid;
use crate::broad::Selection;
use crate::geom::{Aabb, Frustum, Relation, Sphere};
use crate::Handle;
use glam::Vec3;
use std::ops::ControlFlow;

/// Key boxes of at most this many cells are visited cell by cell without the
/// block descent (a small sphere or box query: classifying blocks would cost
/// more than it saves).
const FLAT_CELLS: u64 = 64;

/// Blocks of at most this many cells are not split further.
const LEAF_CELLS: u64 = 8;

/// Cells with more references than this are classified before their references
/// are tested.
const CLASSIFY_ABOVE: usize = 2;

impl<T, S: Store> CellGrid<T, S> {
    /// Reports every object `q` selects, each once: a ray walks its cells
    /// (`ray.rs`), other shapes visit the key box of their bounds (every key
    /// for a frustum), then the oversized list is tested.
    pub fn walk<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if let Some(ray) = q.as_ray() {
            self.visit_ray(ray, &mut f)?;
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
        self.store.blocks_in(&kb, |region, block| {
            self.descend(q, &kb, block, region, Frustum::ALL_PLANES, f)
        })
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
        let (centres, loose) = self.report_boxes(&region, kb);
        let (rel, mask) = q.classify_centres(&centres, &loose, mask);
        match rel {
            Relation::Outside => ControlFlow::Continue(()),
            Relation::Inside => self.store.cells_in_block(block, &region, |key, es| {
                for e in es {
                    if Self::reported_here(e.keys.lo(), kb, key) {
                        let (h, v) = self.resolve(e.slot);
                        f(h, &self.spheres[e.slot as usize], v)?;
                    }
                }
                ControlFlow::Continue(())
            }),
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
    /// planes in `mask` (the others keep every sphere of the cell). A cell with
    /// several references is classified first by its report boxes.
    #[inline]
    fn test_cell<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        key: Key,
        es: &[CellEntry<S::Packed>],
        mut mask: u8,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut rel = Relation::Intersecting;
        if es.len() > CLASSIFY_ABOVE {
            let (centres, loose) = self.report_boxes(&KeyBox::single(key), kb);
            (rel, mask) = q.classify_centres(&centres, &loose, mask);
            if rel == Relation::Outside {
                return ControlFlow::Continue(());
            }
        }
        for e in es {
            if !Self::reported_here(e.keys.lo(), kb, key) {
                continue;
            }
            let s = &self.spheres[e.slot as usize];
            if rel == Relation::Inside || q.selects_masked(s, mask) {
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
