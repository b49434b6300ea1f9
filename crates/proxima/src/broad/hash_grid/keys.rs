//! Integer cell coordinates of the hashed grid and boxes of them.
//!
//! Cell `k` on an axis covers `[k * cell, (k + 1) * cell)`. Coordinates are clamped
//! to `±LIMIT`, so the grid is a (huge) finite one whose border cells reach to
//! infinity; clamping is monotone, so overlapping footprints still get overlapping
//! key boxes. Footprints are padded by a tiny relative margin so that rounding in
//! the exact tests never meets a key box that excludes an accepted pair.

use crate::geom::{Aabb, Sphere};

/// Largest cell coordinate magnitude (exact in `f32`).
pub const LIMIT: i32 = 1 << 30;

/// Relative padding of footprints.
const REL_PAD: f32 = 1e-5;

/// A cell key.
pub type Key = [i32; 3];

/// An inclusive box of cell keys `[lo, hi]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeyBox {
    pub lo: Key,
    pub hi: Key,
}

impl KeyBox {
    /// Contains no key; the identity of [`KeyBox::include`].
    pub const EMPTY: KeyBox = KeyBox {
        lo: [i32::MAX; 3],
        hi: [i32::MIN; 3],
    };

    /// Every key.
    pub const ALL: KeyBox = KeyBox {
        lo: [-LIMIT; 3],
        hi: [LIMIT; 3],
    };

    /// True if no key is inside.
    #[inline]
    pub fn is_empty(&self) -> bool {
        (0..3).any(|a| self.lo[a] > self.hi[a])
    }

    /// Number of keys (saturating).
    #[inline]
    pub fn volume(&self) -> u64 {
        if self.is_empty() {
            return 0;
        }
        (0..3).fold(1u64, |v, a| {
            v.saturating_mul((self.hi[a] as i64 - self.lo[a] as i64 + 1) as u64)
        })
    }

    /// True if `k` is inside.
    #[inline]
    pub fn contains(&self, k: Key) -> bool {
        (0..3).all(|a| self.lo[a] <= k[a] && k[a] <= self.hi[a])
    }

    /// The keys in both.
    #[inline]
    pub fn intersect(&self, o: &KeyBox) -> KeyBox {
        KeyBox {
            lo: [0, 1, 2].map(|a| self.lo[a].max(o.lo[a])),
            hi: [0, 1, 2].map(|a| self.hi[a].min(o.hi[a])),
        }
    }

    /// Grows the box to contain `k`.
    #[inline]
    pub fn include(&mut self, k: Key) {
        self.lo = [0, 1, 2].map(|a| self.lo[a].min(k[a]));
        self.hi = [0, 1, 2].map(|a| self.hi[a].max(k[a]));
    }

    /// Calls `f` on every key, x fastest. Only for small boxes.
    #[inline]
    pub fn for_each(&self, mut f: impl FnMut(Key)) {
        if self.is_empty() {
            return;
        }
        for z in self.lo[2]..=self.hi[2] {
            for y in self.lo[1]..=self.hi[1] {
                for x in self.lo[0]..=self.hi[0] {
                    f([x, y, z]);
                }
            }
        }
    }
}

/// Cell size and the coordinate functions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keys {
    pub cell: f32,
    pub inv_cell: f32,
    pub pad: f32,
}

impl Keys {
    /// For a validated, positive, finite cell size with a finite inverse.
    pub fn new(cell: f32) -> Keys {
        Keys {
            cell,
            inv_cell: 1.0 / cell,
            pad: cell * REL_PAD,
        }
    }

    /// Clamped cell coordinate of `v` (NaN gives `-LIMIT`).
    #[inline]
    pub fn coord(&self, v: f32) -> i32 {
        let c = (v * self.inv_cell).floor();
        if c >= LIMIT as f32 {
            LIMIT
        } else if c >= -LIMIT as f32 {
            c as i32
        } else {
            -LIMIT
        }
    }

    /// Padding for a coordinate of magnitude `|v|`.
    #[inline]
    pub fn pad_at(&self, v: f32) -> f32 {
        self.pad + v.abs() * REL_PAD
    }

    /// Cells covered by the padded interval `[lo, hi]`.
    #[inline]
    pub fn span(&self, lo: f32, hi: f32) -> (i32, i32) {
        if lo.is_nan() || hi.is_nan() {
            return (-LIMIT, LIMIT);
        }
        (
            self.coord(lo - self.pad_at(lo)),
            self.coord(hi + self.pad_at(hi)),
        )
    }

    /// Cells covered by the padded box `b` (which may be infinite).
    #[inline]
    pub fn aabb_box(&self, b: &Aabb) -> KeyBox {
        let s = [0, 1, 2].map(|a| self.span(b.min[a], b.max[a]));
        KeyBox {
            lo: s.map(|x| x.0),
            hi: s.map(|x| x.1),
        }
    }

    /// Cells covered by the bounding box of `s`.
    #[inline]
    ///
    /// Padded relative to `|centre| + radius` too (see the 2D grid's `sphere_rect`).
    pub fn sphere_box(&self, s: &Sphere) -> KeyBox {
        // Two products: the sum `|c| + r` may overflow to ∞ (see the 2D grid).
        let e = s.center.abs() * REL_PAD + glam::Vec3::splat(s.radius * REL_PAD);
        let r = glam::Vec3::splat(s.radius);
        self.aabb_box(&Aabb::new(s.center - r - e, s.center + r + e))
    }

    /// A cell's loose box grown by the padding (see the 2D grid for why).
    ///
    /// An object's key box reaches `2 (|c| + r) REL_PAD + pad` beyond its sphere
    /// (`sphere_box` pads once, `span` again), so its lowest cell, from which
    /// queries report it, may be that far from it: the growth must cover both
    /// (3× the relative pad; a 2.6e24 cell and an object at 1e30 lost a pair).
    #[inline]
    pub fn padded(&self, b: &Aabb) -> Aabb {
        let m = b.min.abs().max(b.max.abs()).max_element();
        b.grown(self.pad + m * (3.0 * REL_PAD))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Vec3};

    #[test]
    fn key_boxes() {
        let k = Keys::new(4.0);
        assert_eq!(k.coord(-0.5), -1);
        assert_eq!(k.coord(7.9), 1);
        assert_eq!(k.coord(f32::NAN), -LIMIT);
        assert_eq!(k.coord(1e30), LIMIT);
        assert_eq!(k.coord(-1e30), -LIMIT);
        let b = k.sphere_box(&Sphere::new(vec3(6.0, 6.0, -6.0), 1.0));
        assert_eq!(
            b,
            KeyBox {
                lo: [1, 1, -2],
                hi: [1, 1, -2]
            }
        );
        assert_eq!(b.volume(), 1);
        // Touching a cell face from inside reaches across it (padding).
        let b = k.sphere_box(&Sphere::new(vec3(6.0, 6.0, 6.0), 2.0));
        assert_eq!(
            b,
            KeyBox {
                lo: [0, 0, 0],
                hi: [2, 2, 2]
            }
        );
        assert_eq!(b.volume(), 27);
        let mut n = 0;
        b.for_each(|key| {
            assert!(b.contains(key));
            n += 1;
        });
        assert_eq!(n, 27);
        let huge = k.sphere_box(&Sphere::new(Vec3::ZERO, 1e35));
        assert_eq!(huge, KeyBox::ALL);
        assert_eq!(huge.volume(), u64::MAX);
        assert!(KeyBox::EMPTY.is_empty());
        assert_eq!(KeyBox::EMPTY.volume(), 0);
        let mut e = KeyBox::EMPTY;
        e.include([3, -4, 5]);
        e.include([1, 2, 3]);
        assert_eq!(
            e,
            KeyBox {
                lo: [1, -4, 3],
                hi: [3, 2, 5]
            }
        );
        assert!(e
            .intersect(&KeyBox {
                lo: [4; 3],
                hi: [9; 3]
            })
            .is_empty());
        let nan = Aabb::new(Vec3::splat(f32::NAN), Vec3::ZERO);
        assert_eq!(k.aabb_box(&nan), KeyBox::ALL);
    }
}
