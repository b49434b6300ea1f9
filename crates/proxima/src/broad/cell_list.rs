//! The contents of one grid cell, shared by [`UniformGrid2d`](super::UniformGrid2d)
//! and [`HashGrid`](super::HashGrid): a compact list of references plus a loose box.
//!
//! Each reference carries a copy of the object's sphere and the lowest cell of the
//! object's cell range, so the hot loops (pairs, range queries) read one contiguous
//! array and never chase a pointer until they report.

use crate::geom::{Aabb, Sphere};

/// One reference from a cell to an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CellEntry<L> {
    /// Copy of the object's sphere (kept equal to the stored one by `update`).
    pub sphere: Sphere,
    /// The object's arena slot (`Handle::index`).
    pub slot: u32,
    /// Lowest cell of the object's cell range: the once-only reporting rules compare
    /// it with the cell being scanned.
    pub lo: L,
}

/// A cell: its references and a loose box that contains the AABB of every
/// referenced sphere.
///
/// The loose box grows when a reference is added or its sphere moves, and is
/// recomputed exactly when a reference leaves (that scan is needed anyway to find
/// it). So it is always conservative, tight after removals, and reset to
/// [`Aabb::EMPTY`] when the cell empties.
#[derive(Clone, Debug)]
pub(crate) struct CellList<L> {
    pub entries: Vec<CellEntry<L>>,
    pub loose: Aabb,
}

impl<L> Default for CellList<L> {
    fn default() -> Self {
        CellList {
            entries: Vec::new(),
            loose: Aabb::EMPTY,
        }
    }
}

impl<L: Copy> CellList<L> {
    /// Adds a reference. O(1) amortized.
    #[inline]
    pub fn push(&mut self, sphere: Sphere, slot: u32, lo: L) {
        self.entries.push(CellEntry { sphere, slot, lo });
        self.loose = self.loose.union(&sphere.aabb());
    }

    /// Removes the reference to `slot` and recomputes the loose box. O(len).
    /// Returns false if the cell did not reference `slot`.
    pub fn remove(&mut self, slot: u32) -> bool {
        let Some(i) = self.entries.iter().position(|e| e.slot == slot) else {
            return false;
        };
        self.entries.swap_remove(i);
        self.loose = self
            .entries
            .iter()
            .fold(Aabb::EMPTY, |b, e| b.union(&e.sphere.aabb()));
        true
    }

    /// Replaces the sphere (and lowest cell) of the reference to `slot`; the loose
    /// box grows to cover the new sphere. O(position of the reference).
    #[inline]
    pub fn overwrite(&mut self, slot: u32, sphere: Sphere, lo: L) -> bool {
        let Some(e) = self.entries.iter_mut().find(|e| e.slot == slot) else {
            return false;
        };
        e.sphere = sphere;
        e.lo = lo;
        self.loose = self.loose.union(&sphere.aabb());
        true
    }

    /// Heap bytes of the reference list (capacity).
    pub fn heap_bytes(&self) -> usize {
        self.entries.capacity() * std::mem::size_of::<CellEntry<L>>()
    }

    /// True if the loose box contains the AABB of every referenced sphere.
    pub fn loose_is_valid(&self) -> bool {
        if self.entries.is_empty() {
            return self.loose == Aabb::EMPTY;
        }
        self.entries
            .iter()
            .all(|e| self.loose.contains_aabb(&e.sphere.aabb()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Vec3};

    #[test]
    fn loose_box_grows_and_shrinks() {
        let mut c: CellList<u8> = CellList::default();
        c.push(Sphere::new(Vec3::ZERO, 1.0), 0, 0);
        c.push(Sphere::new(vec3(5.0, 0.0, 0.0), 1.0), 1, 0);
        assert_eq!(c.loose.max.x, 6.0);
        assert!(c.overwrite(1, Sphere::new(vec3(9.0, 0.0, 0.0), 1.0), 0));
        assert_eq!(c.loose.max.x, 10.0);
        assert!(c.loose_is_valid());
        assert!(c.remove(1));
        assert_eq!(c.loose, Sphere::new(Vec3::ZERO, 1.0).aabb());
        assert!(!c.remove(1));
        assert!(!c.overwrite(1, Sphere::default(), 0));
        assert!(c.remove(0));
        assert_eq!(c.loose, Aabb::EMPTY);
        assert!(c.loose_is_valid());
    }
}
