//! The grid's invariants, checked by `validate()`.

use super::cells::{INLINE, NO_CELL};
use super::{Loc, UniformGrid3d};
use crate::{Error, Result};

fn fail<T>(msg: String) -> Result<T> {
    Err(Error::Invalid(format!("UniformGrid3d: {msg}")))
}

impl<T> UniformGrid3d<T> {
    /// Checks, in O(cells + objects):
    /// - the arena; every live object's location names an entry holding its slot;
    /// - gridded objects sit in the cell of their centre with a radius within the
    ///   limit, large ones exceed it; the growing bounds cover every gridded sphere;
    /// - the counts add up to the number of objects, and the spill table holds
    ///   exactly the entries beyond the inline ones.
    pub(super) fn check(&self) -> Result<()> {
        self.items.validate()?;
        let n = self.geom.cell_count();
        if self.store.cells.len() != n {
            return fail(format!("cell arrays do not have {n} cells"));
        }
        for (h, _) in self.items.iter() {
            let slot = h.index();
            if self.spheres.len() <= slot as usize {
                return fail(format!("no sphere for slot {slot}"));
            }
            let Some(&loc) = self.locs.get(slot as usize) else {
                return fail(format!("no location for slot {slot}"));
            };
            let Loc { cell, idx } = loc;
            if cell == NO_CELL {
                if self.large.get(idx as usize) != Some(&slot) {
                    return fail(format!("large entry {idx} is not slot {slot}"));
                }
                if self.spheres[slot as usize].radius <= self.geom.limit {
                    return fail(format!("slot {slot} is large but small enough to grid"));
                }
                continue;
            }
            if cell as usize >= n || idx >= self.store.count(cell) {
                return fail(format!("slot {slot} has an invalid location {loc:?}"));
            }
            if self.store.slot(cell, idx) != slot {
                return fail(format!("entry {loc:?} is not slot {slot}"));
            }
            let s = &self.spheres[slot as usize];
            if self.geom.cell_of(s.center) != cell {
                return fail(format!("slot {slot} is not in the cell of its centre"));
            }
            if s.radius > self.geom.limit {
                return fail(format!("slot {slot} is too large to be gridded"));
            }
            if !self.extent.contains_aabb(&s.aabb()) {
                return fail(format!("bounds do not cover slot {slot}"));
            }
        }
        let gridded: usize = self.store.cells.iter().map(|c| c.count as usize).sum();
        if gridded + self.large.len() != self.items.len() {
            return fail(format!(
                "{gridded} gridded + {} large objects, {} stored",
                self.large.len(),
                self.items.len()
            ));
        }
        for (&c, sp) in &self.store.spill {
            let count = self.store.cells.get(c as usize).map_or(0, |c| c.count) as usize;
            if sp.is_empty() || count != INLINE + sp.len() {
                return fail(format!("spill of cell {c} does not match its count"));
            }
        }
        let spilled = self
            .store
            .cells
            .iter()
            .filter(|c| c.count as usize > INLINE)
            .count();
        if spilled != self.store.spill.len() {
            return fail(format!("{spilled} cells need a spill table entry"));
        }
        (self.inert).check(
            self.items
                .iter()
                .map(|(h, _)| self.filters[h.index() as usize]),
        )
    }
}
