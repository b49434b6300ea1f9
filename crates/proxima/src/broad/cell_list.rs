//! Shared pieces of [`UniformGrid2d`](super::UniformGrid2d) and
//! [`HashGrid`](super::HashGrid): the compact reference list of a cell, and the
//! global bounds that stand in for per-cell loose boxes.
//!
//! Cells hold only `(slot, lowest cell)` references; the spheres live in one dense
//! array indexed by slot. So an update that keeps an object's cell range writes
//! one sphere and touches no cell at all — the common case in a moving scene.

use crate::geom::{Aabb, Sphere};

/// One reference from a cell to an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellEntry<L> {
    /// The object's arena slot (`Handle::index`), also its index in the sphere array.
    pub slot: u32,
    /// Lowest cell of the object's cell range: the once-only reporting rules compare
    /// it with the cell being scanned, without touching the sphere.
    pub lo: L,
}

/// A cell's references.
#[derive(Clone, Debug)]
pub(crate) struct CellList<L> {
    pub entries: Vec<CellEntry<L>>,
}

impl<L> Default for CellList<L> {
    fn default() -> Self {
        CellList {
            entries: Vec::new(),
        }
    }
}

impl<L: Copy> CellList<L> {
    /// Adds a reference. O(1) amortized.
    #[inline]
    pub fn push(&mut self, slot: u32, lo: L) {
        self.entries.push(CellEntry { slot, lo });
    }

    /// Removes the reference to `slot`. O(len). False if there was none.
    #[inline]
    pub fn remove(&mut self, slot: u32) -> bool {
        match self.entries.iter().position(|e| e.slot == slot) {
            Some(i) => {
                self.entries.swap_remove(i);
                true
            }
            None => false,
        }
    }

    /// Sets the lowest cell stored with the reference to `slot`. False if none.
    #[inline]
    pub fn set_lo(&mut self, slot: u32, lo: L) -> bool {
        match self.entries.iter_mut().find(|e| e.slot == slot) {
            Some(e) => {
                e.lo = lo;
                true
            }
            None => false,
        }
    }

    /// Heap bytes of the reference list (capacity).
    pub fn heap_bytes(&self) -> usize {
        self.entries.capacity() * std::mem::size_of::<CellEntry<L>>()
    }
}

/// Bounds on every sphere stored since the index was created, cleared or emptied:
/// the largest radius and the union of the boxes. They only grow (shrinking would
/// need a scan), which keeps them conservative at O(1) per update.
///
/// A cell's loose box — a box containing every sphere it references — is then
/// the cell grown by twice the largest radius (a referenced sphere's footprint
/// meets the cell), clipped to the union box; border cells, which also hold the
/// clamped objects from beyond, reach out to the union box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Reach {
    pub max_radius: f32,
    pub extent: Aabb,
}

impl Default for Reach {
    fn default() -> Self {
        Reach {
            max_radius: 0.0,
            extent: Aabb::EMPTY,
        }
    }
}

impl Reach {
    /// Grows the bounds to cover `s`.
    #[inline]
    pub fn include(&mut self, s: &Sphere) {
        self.max_radius = self.max_radius.max(s.radius);
        self.extent = self.extent.union(&s.aabb());
    }

    /// True if the bounds cover `s`.
    pub fn covers(&self, s: &Sphere) -> bool {
        s.radius <= self.max_radius && self.extent.contains_aabb(&s.aabb())
    }

    /// The loose box of a cell spanning `[min, max]`; `open_lo`/`open_hi` mark the
    /// axes on which the cell is a border cell that also holds everything beyond.
    #[inline]
    pub fn loose(
        &self,
        min: glam::Vec3,
        max: glam::Vec3,
        open_lo: glam::BVec3,
        open_hi: glam::BVec3,
    ) -> Aabb {
        let r = glam::Vec3::splat(2.0 * self.max_radius);
        let lo = glam::Vec3::select(open_lo, self.extent.min, (min - r).max(self.extent.min));
        let hi = glam::Vec3::select(open_hi, self.extent.max, (max + r).min(self.extent.max));
        Aabb::new(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, BVec3, Vec3};

    #[test]
    fn references_and_reach() {
        let mut c: CellList<u8> = CellList::default();
        c.push(3, 0);
        c.push(5, 1);
        assert!(c.set_lo(5, 7));
        assert_eq!(c.entries[1].lo, 7);
        assert!(c.remove(3));
        assert!(!c.remove(3));
        assert!(!c.set_lo(3, 0));
        assert_eq!(c.entries, vec![CellEntry { slot: 5, lo: 7 }]);

        let mut r = Reach::default();
        let s = Sphere::new(vec3(5.0, 5.0, 5.0), 1.0);
        r.include(&s);
        r.include(&Sphere::new(vec3(-50.0, 5.0, 5.0), 0.5));
        assert!(r.covers(&s));
        assert!(!r.covers(&Sphere::new(Vec3::ZERO, 2.0)));
        let b = r.loose(
            Vec3::splat(4.0),
            Vec3::splat(6.0),
            BVec3::FALSE,
            BVec3::FALSE,
        );
        assert_eq!(b, Aabb::new(vec3(2.0, 4.0, 4.0), vec3(6.0, 6.0, 6.0)));
        let b = r.loose(
            Vec3::splat(4.0),
            Vec3::splat(6.0),
            BVec3::TRUE,
            BVec3::FALSE,
        );
        assert_eq!(b.min, vec3(-50.5, 4.0, 4.0));
    }
}
