//! Keeping cell references in step with the stored objects.

use super::cells::CellRect;
use super::UniformGrid2d;

impl<T> UniformGrid2d<T> {
    /// References `slot` from every cell of `rect`.
    pub(super) fn link(&mut self, slot: u32, rect: CellRect) {
        let lo = rect.lo();
        for y in rect.y0..=rect.y1 {
            for x in rect.x0..=rect.x1 {
                let i = self.geom.index(x, y);
                self.cells[i].push(slot, lo);
            }
        }
        self.refs += rect.area();
    }

    /// Drops the references to `slot` from every cell of `rect`.
    pub(super) fn unlink(&mut self, slot: u32, rect: CellRect) {
        for y in rect.y0..=rect.y1 {
            for x in rect.x0..=rect.x1 {
                let i = self.geom.index(x, y);
                let found = self.cells[i].remove(slot);
                debug_assert!(found, "missing grid reference");
            }
        }
        self.refs -= rect.area();
    }

    /// Moves `slot` from the cells of `old` to those of a different `new`: drops
    /// the references that leave, adds those that arrive, and updates the lowest
    /// cell stored in those that stay.
    pub(super) fn relink(&mut self, slot: u32, old: CellRect, new: CellRect) {
        let lo = new.lo();
        for y in old.y0..=old.y1 {
            for x in old.x0..=old.x1 {
                let i = self.geom.index(x, y);
                let found = if new.contains(x, y) {
                    self.cells[i].set_lo(slot, lo)
                } else {
                    self.cells[i].remove(slot)
                };
                debug_assert!(found, "missing grid reference");
            }
        }
        for y in new.y0..=new.y1 {
            for x in new.x0..=new.x1 {
                if !old.contains(x, y) {
                    let i = self.geom.index(x, y);
                    self.cells[i].push(slot, lo);
                }
            }
        }
        self.refs = self.refs - old.area() + new.area();
    }
}
