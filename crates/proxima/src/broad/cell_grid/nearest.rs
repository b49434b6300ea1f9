//! k nearest neighbours [sources: index-queries]: the growing box of cells of
//! `broad/nearest.rs` ([`grow_box`]) over the referenced cells, each object
//! offered once, and the oversized list scanned.
//!
//! **Once-only.** Each step adds a slab of cells to the box `seen` already
//! visited. An object not met yet has a key box disjoint from `seen`; it is
//! offered from the lowest cell of its key box within the slab, so once.
//!
//! **Face bounds.** An object whose cells all lie above the cell line `k` on
//! axis `a` lies above that line less the lattice's padding (its key box was
//! computed from its padded bounds, rounded monotonically), and inside the
//! union box of the gridded spheres (the 2D grid's columns get their z range
//! from it): its distance is at least the point's distance to that part of
//! the union box.
//!
//! **Hash grid.** The slabs are looked up block by block (a block holds 4 × 4
//! × 4 cells); when the cells looked up exceed a few times the occupied ones
//! (clusters far apart, a query between them), the search stops growing and
//! scans the occupied cells once instead, each unseen object from its own
//! lowest cell, so no query costs more than O(occupied cells).

use super::keys::KeyBox;
use super::list::Packed;
use super::store::Store;
use super::CellGrid;
use crate::broad::nearest::{grow_box, KBest, Nearest, Neighbor};
use crate::broad::Filter;
use crate::geom::overlap;
use std::ops::ControlFlow;

/// A sparse store scans its occupied cells once the slabs looked up hold more
/// than this many cells per occupied cell.
const LOOKUPS_PER_CELL: u64 = 4;

impl<T, S: Store> CellGrid<T, S> {
    /// The box of every gridded sphere (what [`may_overflow`](crate::broad::nearest::may_overflow) checks).
    pub(crate) fn knn_extent(&self) -> crate::geom::Aabb {
        self.reach.extent
    }

    /// The `k` nearest among the objects `filter` admits into `out`, nearest
    /// first, ties by handle (see the module docs). Cost: the oversized list,
    /// plus the cells of the smallest box around the point's cell that holds
    /// the answer (about `k` objects' cells in an even scene), plus the
    /// distances of the objects referenced there; no allocation once `out`
    /// holds `k` entries.
    pub fn nearest(&self, q: &Nearest, filter: Option<Filter>, out: &mut Vec<Neighbor>) {
        let mut best = KBest::new(out, q.k, q.max_distance);
        if q.k == 0 || self.items.is_empty() {
            return;
        }
        let offer = |best: &mut KBest<'_>, slot: u32| {
            let s = &self.spheres[slot as usize];
            let Some(distance) = q.metric.distance_within(q.point, s, best) else {
                return;
            };
            if filter.is_none_or(|f| f.interacts(self.filters[slot as usize])) {
                best.offer(Neighbor {
                    handle: self.handle(slot),
                    distance,
                });
            }
        };
        for &slot in &self.oversized {
            offer(&mut best, slot);
        }
        let ext = self.reach.extent;
        let lat = self.store.lattice();
        let cells = self
            .store
            .occupied()
            .intersect(&lat.aabb_box(&lat.padded(&ext), S::AXES));
        if self.refs > 0 && !ext.min.cmpgt(ext.max).any() && !cells.is_empty() {
            let mut start = KeyBox::single(lat.limits.lo);
            for a in 0..S::AXES {
                start.lo[a] = lat.coord(q.point[a], a).clamp(cells.lo[a], cells.hi[a]);
            }
            start.hi = start.lo;
            let face = |a: usize, upper: bool, k: i32| {
                let mut h = ext;
                if upper {
                    h.min[a] = h.min[a].max(lat.origin[a] + k as f32 * lat.cell);
                } else {
                    h.max[a] = h.max[a].min(lat.origin[a] + (k + 1) as f32 * lat.cell);
                }
                let h = lat.padded(&h);
                if h.min[a] > h.max[a] {
                    f64::INFINITY
                } else {
                    overlap::point_aabb_distance_sq(q.point, &h)
                }
            };
            let budget = LOOKUPS_PER_CELL * self.store.cell_count() as u64 + 64;
            let mut looked = 0u64;
            grow_box(
                &mut best,
                start,
                cells,
                S::AXES,
                face,
                |best, slab, seen| {
                    looked = looked.saturating_add(slab.volume());
                    if S::SPARSE && looked > budget {
                        let _ = self.store.cells(|key, es| {
                            for e in es {
                                let kb = KeyBox {
                                    lo: e.keys.lo(),
                                    hi: e.keys.hi(),
                                };
                                if kb.lo == key && kb.intersect(seen).is_empty() {
                                    offer(best, e.slot);
                                }
                            }
                            ControlFlow::Continue(())
                        });
                        return ControlFlow::Break(());
                    }
                    self.store.cells_in(slab, |key, es| {
                        for e in es {
                            let lo = e.keys.lo();
                            if !Self::reported_here(lo, slab, key) {
                                continue;
                            }
                            let kb = KeyBox {
                                lo,
                                hi: e.keys.hi(),
                            };
                            if kb.intersect(seen).is_empty() {
                                offer(best, e.slot);
                            }
                        }
                        ControlFlow::Continue(())
                    })
                },
            );
        }
        best.finish();
    }
}
