//! Keeping cells, references and the oversized list in step with the objects.

use super::keys::{Key, KeyBox};
use super::{Cell, HashGrid, Place};
use crate::broad::cell_list::CellList;

impl<T> HashGrid<T> {
    /// The cell slot of `key`, created (reusing a freed slot) if absent.
    fn cell_mut(&mut self, key: Key) -> &mut CellList<Key> {
        let slot = match self.map.get(&key) {
            Some(&s) => s,
            None => {
                let s = match self.free_cells.pop() {
                    Some(s) => {
                        // The freed slot keeps its (empty) list's capacity.
                        self.cells[s as usize].key = key;
                        s
                    }
                    None => {
                        self.cells.push(Cell {
                            key,
                            list: CellList::default(),
                        });
                        self.cells.len() as u32 - 1
                    }
                };
                self.map.insert(key, s);
                self.occupied.include(key);
                s
            }
        };
        &mut self.cells[slot as usize].list
    }

    /// Removes `slot`'s reference from the cell `key`, freeing the cell if it
    /// empties. Returns false if there was none.
    fn remove_ref(&mut self, key: Key, slot: u32) -> bool {
        let Some(&c) = self.map.get(&key) else {
            return false;
        };
        let list = &mut self.cells[c as usize].list;
        if !list.remove(slot) {
            return false;
        }
        if list.entries.is_empty() {
            self.map.remove(&key);
            self.free_cells.push(c);
            self.stale += 1;
            // Recompute the occupied box once as many cells were freed as are left:
            // amortized O(1) per freed cell.
            if self.stale > self.map.len() {
                let mut b = KeyBox::EMPTY;
                for k in self.map.keys() {
                    b.include(*k);
                }
                self.occupied = b;
                self.stale = 0;
            }
        }
        true
    }

    /// References `slot` from every cell of `kb`.
    pub(super) fn link(&mut self, slot: u32, kb: KeyBox) {
        kb.for_each(|k| self.cell_mut(k).push(slot, kb.lo));
        self.refs += kb.volume() as usize;
    }

    /// Drops `slot`'s references from every cell of `kb`.
    pub(super) fn unlink(&mut self, slot: u32, kb: KeyBox) {
        kb.for_each(|k| {
            let found = self.remove_ref(k, slot);
            debug_assert!(found, "missing hash grid reference");
        });
        self.refs -= kb.volume() as usize;
    }

    /// Moves `slot` from the cells of `old` to those of a different `new`: drops
    /// the references that leave, adds those that arrive, updates the lowest cell
    /// stored in those that stay.
    pub(super) fn relink(&mut self, slot: u32, old: KeyBox, new: KeyBox) {
        old.for_each(|k| {
            let found = if new.contains(k) {
                self.cell_mut(k).set_lo(slot, new.lo)
            } else {
                self.remove_ref(k, slot)
            };
            debug_assert!(found, "missing hash grid reference");
        });
        new.for_each(|k| {
            if !old.contains(k) {
                self.cell_mut(k).push(slot, new.lo);
            }
        });
        self.refs = self.refs - old.volume() as usize + new.volume() as usize;
    }

    /// Removes entry `i` of the oversized list, fixing the position stored by the
    /// object moved into its place.
    pub(super) fn drop_oversized(&mut self, i: u32) {
        self.oversized.swap_remove(i as usize);
        if let Some(&moved) = self.oversized.get(i as usize) {
            let h = self.handles[moved as usize];
            if let Ok(item) = self.items.get_mut(h) {
                item.place = Place::Oversized(i);
            }
        }
    }
}
