//! Cell coordinates of the 2D grid: which cells a footprint covers.
//!
//! Coordinates are clamped to the grid, so anything outside the rectangle maps to
//! the border cells. Clamping is monotone, which is all correctness needs: if two
//! footprints overlap on an axis, their clamped cell intervals overlap too.
//! Footprints are padded by a tiny relative margin so that float rounding in the
//! exact overlap tests (which may accept a pair that misses by an ulp) never meets a
//! cell range that excludes it.

use crate::geom::{Aabb, Sphere};
use crate::{Error, Result};

/// Relative padding of footprints (a few hundred ulps of the coordinate).
const REL_PAD: f32 = 1e-5;

/// Most cells along one axis (coordinates are stored as `u16`).
pub const MAX_CELLS_PER_AXIS: u32 = 1 << 16;

/// Most cells in a grid (about 48 bytes each when empty).
pub const MAX_CELLS: u64 = 1 << 24;

/// An inclusive rectangle of cells `[x0, x1] × [y0, y1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl CellRect {
    /// True if cell `(x, y)` is inside.
    #[inline]
    pub fn contains(&self, x: u32, y: u32) -> bool {
        self.x0 <= x && x <= self.x1 && self.y0 <= y && y <= self.y1
    }

    /// Number of cells.
    #[inline]
    pub fn area(&self) -> usize {
        (self.x1 - self.x0 + 1) as usize * (self.y1 - self.y0 + 1) as usize
    }

    /// The lowest cell, as stored in references.
    #[inline]
    pub fn lo(&self) -> [u16; 2] {
        [self.x0 as u16, self.y0 as u16]
    }
}

/// The grid's placement: origin, cell size and dimensions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Lower XY corner of the gridded rectangle.
    pub origin: [f32; 2],
    /// Edge of a square cell.
    pub cell: f32,
    /// `1 / cell`.
    pub inv_cell: f32,
    /// Cells along x and y.
    pub dims: [u32; 2],
    /// Absolute padding (relative to the rectangle's coordinates).
    pub pad: f32,
}

impl Geometry {
    /// Checks the parameters and lays the grid over `world`'s XY rectangle.
    pub fn new(world: &Aabb, cell: f32) -> Result<Geometry> {
        world.validate()?;
        if !cell.is_finite() || cell <= 0.0 {
            return Err(Error::InvalidParameter(format!(
                "grid cell size {cell} must be finite and positive"
            )));
        }
        let mut dims = [0u32; 2];
        for (a, d) in dims.iter_mut().enumerate() {
            // In f64: a world spanning most of the f32 range has an extent that
            // overflows f32 (3e38 - -3e38), yet a huge cell covers it.
            let n = ((world.max[a] as f64 - world.min[a] as f64) / cell as f64)
                .ceil()
                .max(1.0) as f32;
            if n.is_nan() || n > MAX_CELLS_PER_AXIS as f32 {
                return Err(Error::InvalidParameter(format!(
                    "grid would need {n} cells along an axis (at most {MAX_CELLS_PER_AXIS})"
                )));
            }
            *d = n as u32;
        }
        if dims[0] as u64 * dims[1] as u64 > MAX_CELLS {
            return Err(Error::InvalidParameter(format!(
                "grid would need {} x {} cells (at most {MAX_CELLS})",
                dims[0], dims[1]
            )));
        }
        let inv_cell = 1.0 / cell;
        if !inv_cell.is_finite() {
            return Err(Error::InvalidParameter(format!(
                "grid cell size {cell} is too small"
            )));
        }
        let mag = world.min.abs().max(world.max.abs());
        let pad = (mag.x.max(mag.y) + cell) * REL_PAD;
        Ok(Geometry {
            origin: [world.min.x, world.min.y],
            cell,
            inv_cell,
            dims,
            pad,
        })
    }

    /// Total number of cells.
    #[inline]
    pub fn cell_count(&self) -> usize {
        self.dims[0] as usize * self.dims[1] as usize
    }

    /// Index of cell `(x, y)` in the row-major cell array.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.dims[0] as usize + x as usize
    }

    /// Clamped cell coordinate of `v` on axis `a` (NaN and −∞ give 0, +∞ the last).
    #[inline]
    pub fn coord(&self, v: f32, a: usize) -> u32 {
        let c = ((v - self.origin[a]) * self.inv_cell).floor();
        let last = self.dims[a] - 1;
        if c >= last as f32 {
            last
        } else if c >= 0.0 {
            c as u32
        } else {
            0
        }
    }

    /// Padding for a coordinate of magnitude `|v|`.
    #[inline]
    pub fn pad_at(&self, v: f32) -> f32 {
        self.pad + v.abs() * REL_PAD
    }

    /// Cells covered by the padded interval `[lo, hi]` on axis `a`.
    #[inline]
    pub fn span(&self, lo: f32, hi: f32, a: usize) -> (u32, u32) {
        let c0 = self.coord(lo - self.pad_at(lo), a);
        let c1 = self.coord(hi + self.pad_at(hi), a);
        if lo.is_nan() || hi.is_nan() {
            // Not from a validated shape; stay conservative.
            (0, self.dims[a] - 1)
        } else {
            (c0, c1)
        }
    }

    /// Cells covered by the XY footprint (bounding square) of `s`.
    #[inline]
    ///
    /// Padded relative to `|centre| + radius` as well: far from the origin the
    /// rounding of `c ± r` (and of the exact test's `f64` arithmetic) is relative to
    /// the centre's magnitude, not to the bound's (a ball at y = -3e38 of radius
    /// 3e38 has `c + r = 0` but the exact test may accept y = 11.5).
    pub fn sphere_rect(&self, s: &Sphere) -> CellRect {
        // Two products, not `(|c| + r) · REL_PAD`: that sum overflows to ∞ for a ball
        // at -f32::MAX of radius 1e31, and an infinite pad referenced it from every
        // cell, outside the loose boxes the ray walk's once-only rule relies on.
        let e = |c: f32| c.abs() * REL_PAD + s.radius * REL_PAD;
        let (cx, cy) = (s.center.x, s.center.y);
        let (x0, x1) = self.span(cx - s.radius - e(cx), cx + s.radius + e(cx), 0);
        let (y0, y1) = self.span(cy - s.radius - e(cy), cy + s.radius + e(cy), 1);
        CellRect { x0, y0, x1, y1 }
    }

    /// Cells covered by the XY projection of `b` (which may be infinite).
    #[inline]
    pub fn aabb_rect(&self, b: &Aabb) -> CellRect {
        let (x0, x1) = self.span(b.min.x, b.max.x, 0);
        let (y0, y1) = self.span(b.min.y, b.max.y, 1);
        CellRect { x0, y0, x1, y1 }
    }

    /// A cell's loose box grown by the padding, for the conservative box tests of
    /// queries (the exact tests on spheres may accept a touch that a box test
    /// computed with other roundings would reject).
    #[inline]
    pub fn padded(&self, b: &Aabb) -> Aabb {
        // 3× the relative pad: a footprint is padded twice (`sphere_rect`, then
        // `span`), so an object may be referenced from a cell that far from it.
        let m = b.min.abs().max(b.max.abs()).max_element();
        b.grown(self.pad + m * (3.0 * REL_PAD))
    }

    /// Every cell.
    #[inline]
    pub fn full_rect(&self) -> CellRect {
        CellRect {
            x0: 0,
            y0: 0,
            x1: self.dims[0] - 1,
            y1: self.dims[1] - 1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Vec3};

    fn geom() -> Geometry {
        Geometry::new(&Aabb::new(Vec3::ZERO, vec3(100.0, 50.0, 1.0)), 10.0).unwrap()
    }

    #[test]
    fn dimensions_and_bad_parameters() {
        let g = geom();
        assert_eq!(g.dims, [10, 5]);
        let w = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert!(Geometry::new(&w, 0.0).is_err());
        assert!(Geometry::new(&w, -1.0).is_err());
        assert!(Geometry::new(&w, f32::NAN).is_err());
        assert!(Geometry::new(&w, 1e-9).is_err(), "too many cells");
        assert!(Geometry::new(&Aabb::new(Vec3::ONE, Vec3::ZERO), 1.0).is_err());
        // A degenerate rectangle still has one cell.
        let flat = Geometry::new(&Aabb::new(Vec3::ZERO, Vec3::ZERO), 1.0).unwrap();
        assert_eq!(flat.dims, [1, 1]);
    }

    #[test]
    fn sphere_ranges_are_clamped_and_padded() {
        let g = geom();
        let r = g.sphere_rect(&Sphere::new(vec3(15.0, 15.0, 0.0), 1.0));
        assert_eq!(
            r,
            CellRect {
                x0: 1,
                y0: 1,
                x1: 1,
                y1: 1
            }
        );
        // Touching a cell border from inside reaches across it (padding).
        let r = g.sphere_rect(&Sphere::new(vec3(15.0, 15.0, 0.0), 5.0));
        assert_eq!(
            r,
            CellRect {
                x0: 0,
                y0: 0,
                x1: 2,
                y1: 2
            }
        );
        // Far outside: the border cells.
        let r = g.sphere_rect(&Sphere::new(vec3(-1e4, 1e4, 0.0), 1.0));
        assert_eq!(
            r,
            CellRect {
                x0: 0,
                y0: 4,
                x1: 0,
                y1: 4
            }
        );
        // Huge: everything.
        let r = g.sphere_rect(&Sphere::new(vec3(50.0, 25.0, 0.0), 1e30));
        assert_eq!(r, g.full_rect());
        assert_eq!(r.area(), 50);
        // Infinite and NaN query bounds stay conservative.
        let inf = Aabb::new(Vec3::splat(f32::NEG_INFINITY), Vec3::splat(f32::INFINITY));
        assert_eq!(g.aabb_rect(&inf), g.full_rect());
        let nan = Aabb::new(Vec3::splat(f32::NAN), Vec3::splat(f32::NAN));
        assert_eq!(g.aabb_rect(&nan), g.full_rect());
    }

    #[test]
    fn coordinates_are_monotone() {
        let g = geom();
        let mut last = 0;
        let mut x = -20.0f32;
        while x < 120.0 {
            let c = g.coord(x, 0);
            assert!(c >= last);
            last = c;
            x += 0.37;
        }
        assert_eq!(last, 9);
    }
}
