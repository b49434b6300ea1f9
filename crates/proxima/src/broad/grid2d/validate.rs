//! The grid's invariants, checked by `validate()`.

use super::UniformGrid2d;
use crate::{Error, Result};

fn fail<T>(msg: String) -> Result<T> {
    Err(Error::Invalid(format!("UniformGrid2d: {msg}")))
}

impl<T> UniformGrid2d<T> {
    /// Checks, in O(references + cells):
    /// - the arena, and the slot → handle table for every live object;
    /// - every object's stored cell range is the one its sphere gives;
    /// - every reference names a live object, sits in a cell of that object's
    ///   range, carries its lowest cell, and no cell references an object twice;
    ///   with the count check below, every object is referenced from exactly the
    ///   cells of its range;
    /// - the reference count, and the growing bounds cover every sphere (so every
    ///   cell's loose box contains the spheres it references).
    pub(super) fn check(&self) -> Result<()> {
        self.items.validate()?;
        if self.cells.len() != self.geom.cell_count() {
            return fail(format!(
                "{} cells, expected {}",
                self.cells.len(),
                self.geom.cell_count()
            ));
        }
        let mut expected = 0usize;
        for (h, item) in self.items.iter() {
            if self.handles.get(h.index() as usize) != Some(&h) {
                return fail(format!(
                    "slot {} does not map back to its handle",
                    h.index()
                ));
            }
            let Some(sphere) = self.spheres.get(h.index() as usize) else {
                return fail(format!("no sphere for slot {}", h.index()));
            };
            if !self.reach.covers(sphere) {
                return fail(format!(
                    "bounds do not cover the sphere of slot {}",
                    h.index()
                ));
            }
            let rect = self.geom.sphere_rect(sphere);
            if rect != item.rect {
                return fail(format!("stale cell range {:?} for {:?}", item.rect, h));
            }
            expected += rect.area();
        }
        if expected != self.refs {
            return fail(format!(
                "reference count {} but ranges cover {expected}",
                self.refs
            ));
        }
        let nx = self.geom.dims[0];
        let mut total = 0usize;
        // Cell in which each slot was last seen: a repeat within a cell is a duplicate.
        let mut last_cell = vec![usize::MAX; self.handles.len()];
        for (ci, cell) in self.cells.iter().enumerate() {
            let (x, y) = (ci as u32 % nx, ci as u32 / nx);
            for e in &cell.entries {
                let Some(&h) = self.handles.get(e.slot as usize) else {
                    return fail(format!(
                        "cell ({x}, {y}) references unknown slot {}",
                        e.slot
                    ));
                };
                let Ok(item) = self.items.get(h) else {
                    return fail(format!("cell ({x}, {y}) references dead slot {}", e.slot));
                };
                if !item.rect.contains(x, y) {
                    return fail(format!(
                        "cell ({x}, {y}) outside the range of slot {}",
                        e.slot
                    ));
                }
                if e.lo != item.rect.lo() {
                    return fail(format!(
                        "cell ({x}, {y}) has a stale lowest cell for slot {}",
                        e.slot
                    ));
                }
                if std::mem::replace(&mut last_cell[e.slot as usize], ci) == ci {
                    return fail(format!("cell ({x}, {y}) references slot {} twice", e.slot));
                }
            }
            total += cell.entries.len();
        }
        if total != expected {
            return fail(format!("{total} references in cells, expected {expected}"));
        }
        Ok(())
    }
}
