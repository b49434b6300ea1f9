//! The hashed grid's invariants, checked by `validate()`.

use super::{HashGrid, Place};
use crate::{Error, Result};

fn fail<T>(msg: String) -> Result<T> {
    Err(Error::Invalid(format!("HashGrid: {msg}")))
}

impl<T> HashGrid<T> {
    /// Checks, in O(references + cells):
    /// - the arena and the slot → handle table;
    /// - every object's place is the one its sphere gives (cells or oversized),
    ///   and the oversized list and the stored positions agree;
    /// - the map and the cell slots agree: each mapped slot holds its key and is
    ///   not empty, each unmapped slot is empty and on the free list exactly once;
    /// - every reference names a live gridded object, sits in a cell of its key
    ///   box, carries its lowest cell, and appears once per cell; with the count
    ///   check, every object is referenced from exactly its cells;
    /// - the growing bounds cover every gridded sphere (so loose boxes contain
    ///   their spheres); the occupied box contains every key.
    pub(super) fn check(&self) -> Result<()> {
        self.items.validate()?;
        let mut expected = 0usize;
        let mut oversized = 0usize;
        for (h, item) in self.items.iter() {
            let slot = h.index();
            if self.handles.get(slot as usize) != Some(&h) {
                return fail(format!("slot {slot} does not map back to its handle"));
            }
            let Some(sphere) = self.spheres.get(slot as usize) else {
                return fail(format!("no sphere for slot {slot}"));
            };
            match (item.place, self.cells_of(sphere)) {
                (Place::Cells(kb), Some(want)) if kb == want => {
                    if !self.reach.covers(sphere) {
                        return fail(format!("bounds do not cover the sphere of slot {slot}"));
                    }
                    expected += kb.volume() as usize
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
        let mut is_free = vec![false; self.cells.len()];
        for &c in &self.free_cells {
            match is_free.get_mut(c as usize) {
                Some(f) if !*f => *f = true,
                _ => return fail(format!("bad or repeated free cell {c}")),
            }
        }
        let mut mapped = 0usize;
        for (key, &c) in &self.map {
            let Some(cell) = self.cells.get(c as usize) else {
                return fail(format!("key {key:?} maps to missing cell {c}"));
            };
            if cell.key != *key || cell.list.entries.is_empty() || is_free[c as usize] {
                return fail(format!("key {key:?} maps to a wrong, empty or free cell"));
            }
            if !self.occupied.contains(*key) {
                return fail(format!("occupied box misses key {key:?}"));
            }
            mapped += 1;
        }
        if mapped + self.free_cells.len() != self.cells.len() {
            return fail(format!(
                "{mapped} mapped + {} free cells != {} slots",
                self.free_cells.len(),
                self.cells.len()
            ));
        }
        let mut total = 0usize;
        let mut last_cell = vec![usize::MAX; self.handles.len()];
        for (ci, cell) in self.cells.iter().enumerate() {
            if is_free[ci] && !cell.list.entries.is_empty() {
                return fail(format!("free cell {ci} holds references"));
            }
            for e in &cell.list.entries {
                let Some(&h) = self.handles.get(e.slot as usize) else {
                    return fail(format!(
                        "cell {:?} references unknown slot {}",
                        cell.key, e.slot
                    ));
                };
                let Ok(item) = self.items.get(h) else {
                    return fail(format!(
                        "cell {:?} references dead slot {}",
                        cell.key, e.slot
                    ));
                };
                let Place::Cells(kb) = item.place else {
                    return fail(format!(
                        "cell {:?} references oversized slot {}",
                        cell.key, e.slot
                    ));
                };
                if !kb.contains(cell.key) || e.lo != kb.lo {
                    return fail(format!(
                        "cell {:?} has a stray or stale reference to slot {}",
                        cell.key, e.slot
                    ));
                }
                if std::mem::replace(&mut last_cell[e.slot as usize], ci) == ci {
                    return fail(format!(
                        "cell {:?} references slot {} twice",
                        cell.key, e.slot
                    ));
                }
            }
            total += cell.list.entries.len();
        }
        if total != expected {
            return fail(format!("{total} references in cells, expected {expected}"));
        }
        Ok(())
    }
}
