//! Cell coordinates: integer keys, inclusive boxes of keys, and the lattice that
//! maps world coordinates to keys.
//!
//! Cell `k` on axis `a` covers `[origin + k·cell, origin + (k + 1)·cell)`.
//! Coordinates are clamped to the lattice's limits (the 2D grid's rectangle, the
//! hash grid's `±LIMIT`), so the border cells reach to infinity; clamping is
//! monotone, so overlapping footprints still get overlapping key boxes. An axis
//! whose limits are equal is flat: every coordinate maps to its one cell (the
//! 2D grid's z). Footprints are padded by a tiny relative margin so that float
//! rounding in the exact overlap tests (which may accept a pair that misses by an
//! ulp) never meets a key box that excludes it.

use crate::geom::{Aabb, Sphere};
use glam::Vec3;

/// Relative padding of footprints (a few hundred ulps of the coordinate).
pub(crate) const REL_PAD: f32 = 1e-5;

/// A cell key: integer coordinates on x, y, z (0 on a flat axis).
pub(crate) type Key = [i32; 3];

/// An inclusive box of cell keys `[lo, hi]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct KeyBox {
    pub lo: Key,
    pub hi: Key,
}

impl KeyBox {
    /// Contains no key; the identity of [`KeyBox::include`].
    pub const EMPTY: KeyBox = KeyBox {
        lo: [i32::MAX; 3],
        hi: [i32::MIN; 3],
    };

    /// The box holding the one key `k`.
    #[inline]
    pub fn single(k: Key) -> KeyBox {
        KeyBox { lo: k, hi: k }
    }

    /// True if no key is inside.
    #[inline]
    pub fn is_empty(&self) -> bool {
        (0..3).any(|a| self.lo[a] > self.hi[a])
    }

    /// Number of keys along axis `a` (0 if empty there).
    #[inline]
    pub fn len(&self, a: usize) -> u64 {
        (self.hi[a] as i64 - self.lo[a] as i64 + 1).max(0) as u64
    }

    /// Number of keys (saturating).
    #[inline]
    pub fn volume(&self) -> u64 {
        self.len(0)
            .saturating_mul(self.len(1))
            .saturating_mul(self.len(2))
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

    /// Calls `f` on every key, x fastest. Only for boxes known to be small.
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

    /// The two halves of the box split at the middle of its longest axis
    /// (which must hold at least two keys).
    #[inline]
    pub fn halves(&self) -> (KeyBox, KeyBox) {
        let a = (0..3).max_by_key(|&a| self.len(a)).unwrap_or(0);
        let mid = ((self.lo[a] as i64 + self.hi[a] as i64).div_euclid(2)) as i32;
        let (mut low, mut high) = (*self, *self);
        low.hi[a] = mid;
        high.lo[a] = mid + 1;
        (low, high)
    }
}

/// Where the cells lie: origin, cell size, the clamping limits and the padding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lattice {
    /// World coordinates of the corner of cell `[0, 0, 0]`.
    pub origin: Vec3,
    /// Edge of a cell.
    pub cell: f32,
    /// `1 / cell`.
    pub inv_cell: f32,
    /// Lowest and highest cell coordinates; coordinates beyond are clamped.
    pub limits: KeyBox,
    /// Absolute padding of footprints (relative to the coordinates the lattice
    /// is meant for).
    pub pad: f32,
}

impl Lattice {
    /// Clamped cell coordinate of `v` on axis `a` (NaN and −∞ give the lowest,
    /// +∞ the highest).
    #[inline]
    pub fn coord(&self, v: f32, a: usize) -> i32 {
        let (lo, hi) = (self.limits.lo[a], self.limits.hi[a]);
        let c = (v - self.origin[a]) * self.inv_cell;
        if c >= hi as f32 {
            hi
        } else if c >= lo as f32 {
            // Floor without a libm call (no SSE4.1 in the baseline target):
            // |c| < 2^31 here, and above 2^24 every f32 is an integer.
            let t = c as i32;
            t - ((t as f32) > c) as i32
        } else {
            lo
        }
    }

    /// Padding for a coordinate of magnitude `|v|`.
    #[inline]
    pub fn pad_at(&self, v: f32) -> f32 {
        self.pad + v.abs() * REL_PAD
    }

    /// Cells covered by the padded interval `[lo, hi]` on axis `a`.
    #[inline]
    pub fn span(&self, lo: f32, hi: f32, a: usize) -> (i32, i32) {
        if lo.is_nan() || hi.is_nan() {
            // Not from a validated shape; stay conservative.
            return (self.limits.lo[a], self.limits.hi[a]);
        }
        (
            self.coord(lo - self.pad_at(lo), a),
            self.coord(hi + self.pad_at(hi), a),
        )
    }

    /// Cells covered by the padded box `b` (which may be infinite) on the first
    /// `axes` axes; the others are flat.
    #[inline]
    pub fn aabb_box(&self, b: &Aabb, axes: usize) -> KeyBox {
        let mut kb = KeyBox {
            lo: self.limits.lo,
            hi: self.limits.hi,
        };
        for a in 0..axes {
            (kb.lo[a], kb.hi[a]) = self.span(b.min[a], b.max[a], a);
        }
        kb
    }

    /// Cells covered by the bounding box of `s` on the first `axes` axes.
    ///
    /// Padded relative to `|centre| + radius` as well: far from the origin the
    /// rounding of `c ± r` (and of the exact tests' `f64` arithmetic) is relative
    /// to the centre's magnitude, not to the bound's (a ball at y = -3e38 of
    /// radius 3e38 has `c + r = 0` but the exact test may accept y = 11.5).
    #[inline]
    pub fn sphere_box(&self, s: &Sphere, axes: usize) -> KeyBox {
        // Two products, not `(|c| + r) · REL_PAD`: that sum overflows to ∞ for a
        // ball at -f32::MAX of radius 1e31, and an infinite pad referenced it from
        // every cell, outside the loose boxes the ray walk's once-only rule
        // relies on.
        let e = s.center.abs() * REL_PAD + Vec3::splat(s.radius * REL_PAD);
        let r = Vec3::splat(s.radius);
        self.aabb_box(&Aabb::new(s.center - r - e, s.center + r + e), axes)
    }

    /// The world box of the cells `kb`: `min` of its lowest cell to `max` of its
    /// highest (`(k + 1)·cell`, not `min + cell`: with a huge cell `min` may
    /// overflow to -∞ and the upper side must stay finite).
    #[inline]
    pub fn cells_box(&self, kb: &KeyBox) -> (Vec3, Vec3) {
        let lo = glam::IVec3::from(kb.lo).as_vec3();
        let hi = (glam::IVec3::from(kb.hi) + 1).as_vec3();
        (self.origin + lo * self.cell, self.origin + hi * self.cell)
    }

    /// Per axis: does `kb` reach the lowest (`.0`) or highest (`.1`) cell, which
    /// also holds everything clamped onto it from beyond.
    #[inline]
    pub fn open_sides(&self, kb: &KeyBox) -> (glam::BVec3, glam::BVec3) {
        let lo = glam::IVec3::from(kb.lo).cmple(self.limits.lo.into());
        let hi = glam::IVec3::from(kb.hi).cmpge(self.limits.hi.into());
        (lo, hi)
    }

    /// A box grown by the padding, for the conservative box tests of queries
    /// (the exact tests on spheres may accept a touch that a box test computed
    /// with other roundings would reject).
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

    /// A lattice with cells of 4 and limits ±2^30 (the hash grid's).
    fn hashed() -> Lattice {
        Lattice {
            origin: Vec3::ZERO,
            cell: 4.0,
            inv_cell: 0.25,
            limits: KeyBox {
                lo: [-(1 << 30); 3],
                hi: [1 << 30; 3],
            },
            pad: 4.0 * REL_PAD,
        }
    }

    #[test]
    fn inline_floor_matches_floor() {
        let h = hashed();
        let lim = (1u32 << 30) as f32;
        // Magnitudes from 1e-3 to 4.3e9 (beyond the limit), both signs.
        let mut v = 1e-3f32;
        while v < 4.3e9 {
            for w in [v, v + 0.1, v - 0.1, -v, -v - 0.1] {
                let want = (w * 0.25).floor().clamp(-lim, lim);
                assert_eq!(h.coord(w, 1), want as i32, "{w}");
            }
            v *= 1.37;
        }
        for w in [-4.0f32, -3.999, -0.5, -0.0, 0.0, 3.999, 4.0, 1e30, -1e30] {
            let want = (w * 0.25).floor().clamp(-lim, lim);
            assert_eq!(h.coord(w, 0), want as i32, "{w}");
        }
    }

    #[test]
    fn halves_split_the_longest_axis() {
        let b = KeyBox {
            lo: [1, -4, 3],
            hi: [3, 2, 5],
        };
        let (l, h) = b.halves();
        assert_eq!((l.hi[1], h.lo[1]), (-1, 0));
        assert_eq!(l.volume() + h.volume(), b.volume());
        let lim = 1 << 30;
        let (l, h) = KeyBox {
            lo: [-lim; 3],
            hi: [lim, -lim, -lim],
        }
        .halves();
        assert_eq!((l.hi[0], h.lo[0]), (0, 1));
        assert_eq!(KeyBox::single([5, 6, 7]).volume(), 1);
    }
}
