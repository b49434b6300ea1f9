//! The grid's invariants, checked by `validate()`.

use super::list::Packed;
use super::store::Store;
use super::{CellGrid, Place};
use crate::{Error, Result};

impl<T, S: Store> CellGrid<T, S> {
    /// Checks, in O(references + cells), naming the front end `name` in errors:
    /// - the arena, and a sphere for every live object;
    /// - every object's place is the one its sphere gives (the cells of its key
    ///   box, or the oversized list at the position it stores);
    /// - the store's own bookkeeping;
    /// - every reference names a live gridded object, sits in a cell of that
    ///   object's key box, carries its key box, and appears once per cell; with
    ///   the count check, every object is referenced from exactly its cells;
    /// - the growing bounds cover every gridded sphere (so the report boxes
    ///   contain the spheres they stand for); the occupied box contains every
    ///   referencing cell.
    pub fn check(&self, name: &str) -> Result<()> {
        let fail = |msg: String| Err(Error::Invalid(format!("{name}: {msg}")));
        self.items.validate()?;
        if let Err(msg) = self.store.check() {
            return fail(msg);
        }
        let mut expected = 0usize;
        let mut oversized = 0usize;
        for (h, item) in self.items.iter() {
            let slot = h.index();
            let Some(sphere) = self.spheres.get(slot as usize) else {
                return fail(format!("no sphere for slot {slot}"));
            };
            match (item.place, self.cells_of(sphere)) {
                (Place::Cells(p), Some(kb)) if p == S::Packed::pack(&kb) => {
                    if !self.reach.covers(sphere) {
                        return fail(format!("bounds do not cover the sphere of slot {slot}"));
                    }
                    expected += kb.volume() as usize;
                }
                (Place::Oversized(i), None) => {
                    if self.oversized.get(i as usize) != Some(&slot) {
                        return fail(format!("oversized position {i} of slot {slot} is wrong"));
                    }
                    oversized += 1;
                }
                (p, _) => return fail(format!("stale place {p:?} for slot {slot}")),
            }
        }
        if oversized != self.oversized.len() {
            return fail(format!(
                "{} oversized entries for {oversized} oversized objects",
                self.oversized.len()
            ));
        }
        if expected != self.refs {
            return fail(format!(
                "reference count {} but key boxes cover {expected}",
                self.refs
            ));
        }
        let occupied = self.store.occupied();
        let mut total = 0usize;
        // The cell in which each slot was last seen: a repeat within a cell is a
        // duplicate (cells are visited one at a time).
        let mut last_cell = vec![None; self.spheres.len()];
        let mut bad = None;
        let _ = self.store.cells(|key, es| {
            if !occupied.contains(key) {
                bad = Some(format!("occupied box misses cell {key:?}"));
                return std::ops::ControlFlow::Break(());
            }
            for e in es {
                let item = self.items.get_by_index(e.slot).map(|(_, item)| item);
                let problem = match item {
                    None => Some("an unknown or dead"),
                    Some(item) => match item.place {
                        Place::Oversized(_) => Some("an oversized"),
                        Place::Cells(p) if p != e.keys => Some("a stale key box for"),
                        Place::Cells(p) => {
                            let lo = p.lo();
                            let hi = p.hi();
                            if (0..3).any(|a| key[a] < lo[a] || key[a] > hi[a]) {
                                Some("a stray reference to")
                            } else if last_cell[e.slot as usize].replace(key) == Some(key) {
                                Some("a repeated reference to")
                            } else {
                                None
                            }
                        }
                    },
                };
                if let Some(what) = problem {
                    bad = Some(format!("cell {key:?} holds {what} slot {}", e.slot));
                    return std::ops::ControlFlow::Break(());
                }
            }
            total += es.len();
            std::ops::ControlFlow::Continue(())
        });
        if let Some(msg) = bad {
            return fail(msg);
        }
        if total != expected {
            return fail(format!("{total} references in cells, expected {expected}"));
        }
        (self.inert).check(
            self.items
                .iter()
                .map(|(h, _)| self.filters[h.index() as usize]),
        )
    }
}
