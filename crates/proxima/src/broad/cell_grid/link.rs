//! Keeping the cell references and the oversized list in step with the objects.

use super::keys::KeyBox;
use super::list::Packed;
use super::store::Store;
use super::{CellGrid, Place};
use crate::geom::Sphere;

/// The key box a reference stores.
#[inline]
fn unpack<P: Packed>(p: &P) -> KeyBox {
    KeyBox {
        lo: p.lo(),
        hi: p.hi(),
    }
}

impl<T, S: Store> CellGrid<T, S> {
    /// Puts `slot` where `sphere` belongs — the cells of its key box, or the
    /// oversized list if that covers too many cells — coming from `old` (`None`
    /// for a new object), and returns the new place. Cells that stay keep their
    /// references (with the new key box); nothing moves when the key box stays.
    pub(super) fn place(
        &mut self,
        slot: u32,
        old: Option<Place<S::Packed>>,
        sphere: &Sphere,
    ) -> Place<S::Packed> {
        let cells = self.cells_of(sphere);
        if cells.is_some() {
            self.reach.include(sphere);
        }
        match (old, cells) {
            (Some(Place::Cells(a)), Some(b)) => {
                let packed = S::Packed::pack(&b);
                if a != packed {
                    self.relink(slot, &unpack(&a), &b, packed);
                }
                Place::Cells(packed)
            }
            (old, Some(b)) => {
                if let Some(Place::Oversized(i)) = old {
                    self.drop_oversized(i);
                }
                let packed = S::Packed::pack(&b);
                b.for_each(|k| self.store.push(k, slot, packed));
                self.refs += b.volume() as usize;
                Place::Cells(packed)
            }
            (Some(o @ Place::Oversized(_)), None) => o,
            (old, None) => {
                if let Some(Place::Cells(a)) = old {
                    self.unlink(slot, &unpack(&a));
                }
                self.oversized.push(slot);
                Place::Oversized(self.oversized.len() as u32 - 1)
            }
        }
    }

    /// Takes `slot` out of the `place` it was in.
    pub(super) fn unplace(&mut self, slot: u32, place: Place<S::Packed>) {
        match place {
            Place::Cells(p) => self.unlink(slot, &unpack(&p)),
            Place::Oversized(i) => self.drop_oversized(i),
        }
    }

    /// Drops `slot`'s references from every cell of `kb`.
    fn unlink(&mut self, slot: u32, kb: &KeyBox) {
        kb.for_each(|k| {
            let found = self.store.remove(k, slot);
            debug_assert!(found, "missing grid reference");
        });
        self.refs -= kb.volume() as usize;
    }

    /// Moves `slot` from the cells of `old` to those of a different `new`:
    /// drops the references that leave, adds those that arrive, and stores the
    /// new key box in those that stay.
    fn relink(&mut self, slot: u32, old: &KeyBox, new: &KeyBox, packed: S::Packed) {
        old.for_each(|k| {
            let found = if new.contains(k) {
                self.store.set(k, slot, packed)
            } else {
                self.store.remove(k, slot)
            };
            debug_assert!(found, "missing grid reference");
        });
        new.for_each(|k| {
            if !old.contains(k) {
                self.store.push(k, slot, packed);
            }
        });
        self.refs = self.refs - old.volume() as usize + new.volume() as usize;
    }

    /// Removes entry `i` of the oversized list, fixing the position stored by the
    /// object moved into its place.
    fn drop_oversized(&mut self, i: u32) {
        self.oversized.swap_remove(i as usize);
        if let Some(&moved) = self.oversized.get(i as usize) {
            let h = self.handles[moved as usize];
            if let Ok(item) = self.items.get_mut(h) {
                item.place = Place::Oversized(i);
            }
        }
    }
}
