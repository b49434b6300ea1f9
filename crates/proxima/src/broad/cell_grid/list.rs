//! What a cell holds: a compact list of references, each naming an object's slot
//! and its whole key box; and the global bounds that stand in for per-cell loose
//! boxes.
//!
//! Cells hold only `(slot, key box)` references; the spheres live in one dense
//! array indexed by slot. So an update that keeps an object's key box writes one
//! sphere and touches no cell at all — the common case in a moving scene. The
//! key box travels with every reference so that the once-only rules (lowest
//! cell, and for rays the strip an object was first met in) read it without
//! touching the sphere.

use super::keys::{Key, KeyBox};
use crate::geom::{Aabb, Sphere};
use std::fmt::Debug;

/// An object's key box as a reference stores it: compact, and decoded to the
/// same [`KeyBox`] it was packed from.
pub(crate) trait Packed: Copy + Eq + Debug {
    /// Packs a key box of a gridded object (within the store's per-object cell cap).
    fn pack(kb: &KeyBox) -> Self;
    /// The lowest key.
    fn lo(&self) -> Key;
    /// The highest key.
    fn hi(&self) -> Key;
}

/// The 2D grid's key box: cells fit `u16` (at most 2^16 along an axis) and z is
/// always 0. 8 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rect {
    lo: [u16; 2],
    hi: [u16; 2],
}

impl Packed for Rect {
    #[inline]
    fn pack(kb: &KeyBox) -> Self {
        Rect {
            lo: [kb.lo[0] as u16, kb.lo[1] as u16],
            hi: [kb.hi[0] as u16, kb.hi[1] as u16],
        }
    }
    #[inline]
    fn lo(&self) -> Key {
        [self.lo[0] as i32, self.lo[1] as i32, 0]
    }
    #[inline]
    fn hi(&self) -> Key {
        [self.hi[0] as i32, self.hi[1] as i32, 0]
    }
}

/// The hash grid's key box: the lowest key and the extent per axis (a gridded
/// object covers at most 64 cells, so at most 64 along any axis). 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Cube {
    lo: [i32; 3],
    ext: [u8; 3],
}

impl Packed for Cube {
    #[inline]
    fn pack(kb: &KeyBox) -> Self {
        Cube {
            lo: kb.lo,
            ext: [0, 1, 2].map(|a| (kb.hi[a] as i64 - kb.lo[a] as i64) as u8),
        }
    }
    #[inline]
    fn lo(&self) -> Key {
        self.lo
    }
    #[inline]
    fn hi(&self) -> Key {
        [0, 1, 2].map(|a| self.lo[a] + self.ext[a] as i32)
    }
}

/// One reference from a cell to an object.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellEntry<P> {
    /// The object's arena slot (`Handle::index`), also its index in the sphere array.
    pub slot: u32,
    /// The object's key box: the once-only rules compare its lowest cell with
    /// the cell being scanned, without touching the sphere.
    pub keys: P,
}

/// A cell's references.
#[derive(Clone, Debug)]
pub(crate) struct CellList<P> {
    pub entries: Vec<CellEntry<P>>,
}

impl<P> Default for CellList<P> {
    fn default() -> Self {
        CellList {
            entries: Vec::new(),
        }
    }
}

impl<P: Copy> CellList<P> {
    /// Adds a reference. O(1) amortized.
    #[inline]
    pub fn push(&mut self, slot: u32, keys: P) {
        self.entries.push(CellEntry { slot, keys });
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

    /// Sets the key box stored with the reference to `slot`. False if none.
    #[inline]
    pub fn set(&mut self, slot: u32, keys: P) -> bool {
        match self.entries.iter_mut().find(|e| e.slot == slot) {
            Some(e) => {
                e.keys = keys;
                true
            }
            None => false,
        }
    }

    /// Heap bytes of the reference list (capacity).
    pub fn heap_bytes(&self) -> usize {
        self.entries.capacity() * std::mem::size_of::<CellEntry<P>>()
    }
}

/// Bounds on every gridded sphere stored since the index was created, cleared or
/// emptied: the largest radius and the union of the boxes. They only grow
/// (shrinking would need a scan), which keeps them conservative at O(1) per
/// update.
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

    /// A box around the spheres of a block of cells spanning `[min, max]`:
    /// grown by `below` times the largest radius downwards and `above` times
    /// upwards, clipped to the union box; on the axes marked in `open_lo` /
    /// `open_hi` the block is a border one that also holds everything beyond,
    /// and reaches out to the union box.
    #[inline]
    pub fn around(
        &self,
        (min, max): (glam::Vec3, glam::Vec3),
        (below, above): (glam::Vec3, glam::Vec3),
        (open_lo, open_hi): (glam::BVec3, glam::BVec3),
    ) -> Aabb {
        let r = self.max_radius;
        let lo = (min - below * r).max(self.extent.min);
        let hi = (max + above * r).min(self.extent.max);
        let lo = glam::Vec3::select(open_lo, self.extent.min, lo);
        let hi = glam::Vec3::select(open_hi, self.extent.max, hi);
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
        assert!(c.set(5, 7));
        assert_eq!(c.entries[1].keys, 7);
        assert!(c.remove(3));
        assert!(!c.remove(3));
        assert!(!c.set(3, 0));
        assert_eq!(c.entries, vec![CellEntry { slot: 5, keys: 7 }]);

        let mut r = Reach::default();
        let s = Sphere::new(vec3(5.0, 5.0, 5.0), 1.0);
        r.include(&s);
        r.include(&Sphere::new(vec3(-50.0, 5.0, 5.0), 0.5));
        assert!(r.covers(&s));
        assert!(!r.covers(&Sphere::new(Vec3::ZERO, 2.0)));
        let cell = (Vec3::splat(4.0), Vec3::splat(6.0));
        let twice = (Vec3::splat(2.0), Vec3::splat(2.0));
        let b = r.around(cell, twice, (BVec3::FALSE, BVec3::FALSE));
        assert_eq!(b, Aabb::new(vec3(2.0, 4.0, 4.0), vec3(6.0, 6.0, 6.0)));
        let b = r.around(cell, twice, (BVec3::TRUE, BVec3::FALSE));
        assert_eq!(b.min, vec3(-50.5, 4.0, 4.0));
        // Upwards only: the block's own lower side.
        let b = r.around(cell, (Vec3::ZERO, twice.1), (BVec3::FALSE, BVec3::FALSE));
        assert_eq!(b, Aabb::new(vec3(4.0, 4.0, 4.0), vec3(6.0, 6.0, 6.0)));
    }

    #[test]
    fn packed_key_boxes_round_trip() {
        let kb = KeyBox {
            lo: [3, 65535, 0],
            hi: [70, 65535, 0],
        };
        let r = Rect::pack(&kb);
        assert_eq!((r.lo(), r.hi()), (kb.lo, kb.hi));
        let kb = KeyBox {
            lo: [-(1 << 30), 5, -7],
            hi: [-(1 << 30) + 63, 5, 0],
        };
        let c = Cube::pack(&kb);
        assert_eq!((c.lo(), c.hi()), (kb.lo, kb.hi));
    }
}
