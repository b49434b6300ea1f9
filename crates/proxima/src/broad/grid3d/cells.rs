//! The dense grid's geometry (which cell a centre falls in, which cells a box
//! reaches) and its cell storage (a few spheres inline per cell, the rest spilled).
//!
//! Coordinates are clamped to the grid, so every centre outside the world box lands
//! in a border cell. Clamping and flooring are monotone and the dimensions are
//! capped (see [`MAX_CELLS_PER_AXIS`]), so two centres at most `2 · limit` apart
//! (the largest gridded pair distance) get cell coordinates at most one apart: the
//! rounding of `(x - origin) / cell` is far below the 2 % of a cell kept free by
//! [`GRID_FRACTION`].

use crate::geom::Aabb;
use crate::{Error, Result};
use rustc_hash::FxHashMap;

/// An object is gridded when its radius is at most this fraction of a cell, so
/// overlapping gridded objects have centres in neighbouring cells; larger ones go
/// to the large list. Just under ½ leaves a margin for rounding.
pub const GRID_FRACTION: f32 = 0.49;

/// Most cells along one axis (keeps the rounding of cell coordinates below 1e-3
/// of a cell near the grid).
pub const MAX_CELLS_PER_AXIS: u32 = 1 << 12;

/// Most cells in a grid (16 bytes each).
pub const MAX_CELLS: u64 = 1 << 21;

/// Slots stored inline in a cell (with the count, 16 bytes: a quarter of a
/// cache line); more spill to a side table.
pub const INLINE: usize = 3;

/// Marks "no cell" (a large object's location).
pub const NO_CELL: u32 = u32::MAX;

/// The grid's placement: origin, cell size and dimensions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Lower corner of the gridded box.
    pub origin: glam::Vec3,
    /// Edge of a cubic cell.
    pub cell: f32,
    /// `1 / cell`.
    pub inv_cell: f32,
    /// Cells along x, y, z.
    pub dims: [u32; 3],
    /// Largest radius of a gridded object: `GRID_FRACTION · cell`.
    pub limit: f32,
}

impl Geometry {
    /// Lays a grid of cells of edge `cell` (or larger, to respect the caps) over
    /// `world`. Errors on an invalid box or a cell size that is not finite and
    /// positive.
    pub fn new(world: &Aabb, cell: f32) -> Result<Geometry> {
        world.validate()?;
        if !cell.is_finite() || cell <= 0.0 || !(1.0 / cell).is_finite() {
            return Err(Error::InvalidParameter(format!(
                "grid cell size {cell} must be finite and positive"
            )));
        }
        // A world spanning most of the f32 range has an extent that overflows
        // f32: clamp it. The grid then ends before the world does, and centres
        // beyond it go to the border cells like any centre outside the world.
        let e = (world.max.as_dvec3() - world.min.as_dvec3())
            .min(glam::DVec3::splat(f32::MAX as f64))
            .as_vec3();
        let mut cell = cell;
        // Enlarge the cells until both caps hold (a few iterations at most).
        let dims = loop {
            let d = [0, 1, 2].map(|a| ((e[a] / cell).ceil() as f64).max(1.0));
            if d.iter().all(|&n| n <= MAX_CELLS_PER_AXIS as f64)
                && d[0] * d[1] * d[2] <= MAX_CELLS as f64
            {
                break d.map(|n| n as u32);
            }
            cell *= 1.25;
        };
        Ok(Geometry {
            origin: world.min,
            cell,
            inv_cell: 1.0 / cell,
            dims,
            limit: GRID_FRACTION * cell,
        })
    }

    /// Number of cells.
    #[inline]
    pub fn cell_count(&self) -> usize {
        self.dims.iter().map(|&d| d as usize).product()
    }

    /// Clamped cell coordinate of `v` on axis `a` (monotone in `v`).
    #[inline]
    pub fn coord(&self, v: f32, a: usize) -> u32 {
        let t = (v - self.origin[a]) * self.inv_cell;
        // `as` truncates (= floors for t ≥ 0) and saturates; no libm call.
        if t > 0.0 {
            (t as u32).min(self.dims[a] - 1)
        } else {
            0
        }
    }

    /// Index of the cell holding centre `p`.
    #[inline]
    pub fn cell_of(&self, p: glam::Vec3) -> u32 {
        self.index([self.coord(p.x, 0), self.coord(p.y, 1), self.coord(p.z, 2)])
    }

    /// Index of the cell at coordinates `c` (x fastest).
    #[inline]
    pub fn index(&self, c: [u32; 3]) -> u32 {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Coordinates of cell index `i`.
    #[cfg(test)]
    pub fn coords(&self, i: u32) -> [u32; 3] {
        let [nx, ny, _] = self.dims;
        [i % nx, (i / nx) % ny, i / (nx * ny)]
    }

    /// Padding added to query boxes: the largest gridded radius plus the
    /// rounding [`Geometry::margin`].
    #[inline]
    pub fn reach(&self, v: f32) -> f32 {
        self.limit + self.margin(v)
    }

    /// Margin for the rounding of cell coordinates near `v` (2 % of a cell and a
    /// relative term for far coordinates): a centre mapped to a cell lies within
    /// this of the cell's slab.
    #[inline]
    pub fn margin(&self, v: f32) -> f32 {
        0.02 * self.cell + v.abs() * 1e-5
    }

    /// Cells `[lo, hi]` (inclusive, clamped) that can hold the centre of a
    /// gridded sphere meeting the box `b` (which may be infinite).
    #[inline]
    pub fn range(&self, b: &Aabb) -> ([u32; 3], [u32; 3]) {
        let lo = [0, 1, 2].map(|a| {
            let v = b.min[a];
            if v.is_nan() {
                0
            } else {
                self.coord(v - self.reach(v), a)
            }
        });
        let hi = [0, 1, 2].map(|a| {
            let v = b.max[a];
            if v.is_nan() {
                self.dims[a] - 1
            } else {
                self.coord(v + self.reach(v), a)
            }
        });
        (lo, hi)
    }

    /// The slab of centres that map to coordinate `k` on axis `a`: the cell's
    /// interval, reaching to infinity on the border cells.
    #[inline]
    pub fn slab(&self, k: u32, a: usize) -> (f32, f32) {
        let lo = if k == 0 {
            f32::NEG_INFINITY
        } else {
            self.origin[a] + k as f32 * self.cell
        };
        let hi = if k + 1 >= self.dims[a] {
            f32::INFINITY
        } else {
            self.origin[a] + (k + 1) as f32 * self.cell
        };
        (lo, hi)
    }

    /// A box containing every gridded sphere whose centre is in cell `c`.
    #[inline]
    pub fn loose(&self, c: [u32; 3]) -> Aabb {
        self.loose_block(c, c)
    }

    /// A box containing the centre of every gridded sphere in one of the cells
    /// `[lo, hi]` (inclusive): the block's slabs widened by the margin.
    #[inline]
    pub fn centre_block(&self, lo: [u32; 3], hi: [u32; 3]) -> Aabb {
        let mut min = glam::Vec3::ZERO;
        let mut max = glam::Vec3::ZERO;
        for a in 0..3 {
            let l = self.slab(lo[a], a).0;
            let h = self.slab(hi[a], a).1;
            min[a] = l - self.margin(l);
            max[a] = h + self.margin(h);
        }
        Aabb::new(min, max)
    }

    /// A box containing every gridded sphere whose centre is in one of the
    /// cells `[lo, hi]` (inclusive): the block's slabs widened by the reach.
    #[inline]
    pub fn loose_block(&self, lo: [u32; 3], hi: [u32; 3]) -> Aabb {
        let mut min = glam::Vec3::ZERO;
        let mut max = glam::Vec3::ZERO;
        for a in 0..3 {
            let l = self.slab(lo[a], a).0;
            let h = self.slab(hi[a], a).1;
            min[a] = l - self.reach(l);
            max[a] = h + self.reach(h);
        }
        Aabb::new(min, max)
    }
}

/// One cell: its number of entries and the first [`INLINE`] of their slots.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cell {
    pub count: u32,
    pub slots: [u32; INLINE],
}

/// Every cell's objects by slot: one 16-byte record per cell (the count and up
/// to [`INLINE`] slots, so that moving an object between cells touches one
/// cache line per cell, and an empty neighbour costs one read), any further
/// slots in a side table. Positions `0..count` name a cell's entries; removal
/// swaps the last entry into the hole. The spheres themselves live in one array
/// by slot, so an update that keeps its cell writes where the caller's updates
/// already stream (see the pair search for how they are read back).
#[derive(Clone, Debug)]
pub struct CellStore {
    pub cells: Vec<Cell>,
    pub spill: FxHashMap<u32, Vec<u32>>,
}

impl CellStore {
    /// `n` empty cells.
    pub fn new(n: usize) -> CellStore {
        CellStore {
            cells: vec![Cell::default(); n],
            spill: FxHashMap::default(),
        }
    }

    /// Number of entries of cell `c`.
    #[inline]
    pub fn count(&self, c: u32) -> u32 {
        self.cells[c as usize].count
    }

    /// The slots of cell `c`: the inline part and the spilled part.
    #[inline]
    pub fn parts(&self, c: u32) -> [&[u32]; 2] {
        let cell = &self.cells[c as usize];
        let n = cell.count as usize;
        let inline = &cell.slots[..n.min(INLINE)];
        if n > INLINE {
            [inline, &self.spill[&c][..]]
        } else {
            [inline, &[]]
        }
    }

    /// The slot at position `i` of cell `c`.
    #[inline]
    pub fn slot(&self, c: u32, i: u32) -> u32 {
        let i = i as usize;
        if i < INLINE {
            self.cells[c as usize].slots[i]
        } else {
            self.spill[&c][i - INLINE]
        }
    }

    /// Writes the slot at position `i` of cell `c`.
    #[inline]
    fn set_slot(&mut self, c: u32, i: u32, slot: u32) {
        let i = i as usize;
        if i < INLINE {
            self.cells[c as usize].slots[i] = slot;
        } else if let Some(sp) = self.spill.get_mut(&c) {
            sp[i - INLINE] = slot;
        }
    }

    /// Appends `slot` to cell `c` and returns its position. O(1) amortized.
    #[inline]
    pub fn push(&mut self, c: u32, slot: u32) -> u32 {
        let cell = &mut self.cells[c as usize];
        let n = cell.count;
        cell.count = n + 1;
        if (n as usize) < INLINE {
            cell.slots[n as usize] = slot;
        } else {
            self.spill.entry(c).or_default().push(slot);
        }
        n
    }

    /// Removes the entry at position `i` of cell `c` by moving the last entry
    /// into its place; returns the slot that moved to `i`, if any. O(1).
    #[inline]
    pub fn remove(&mut self, c: u32, i: u32) -> Option<u32> {
        let last = self.cells[c as usize].count - 1;
        let moved = (i != last).then(|| {
            let slot = self.slot(c, last);
            self.set_slot(c, i, slot);
            slot
        });
        if last as usize >= INLINE {
            let sp = self.spill.get_mut(&c).expect("spilled cell without spill");
            sp.pop();
            if sp.is_empty() {
                self.spill.remove(&c);
            }
        }
        self.cells[c as usize].count = last;
        moved
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        self.cells.capacity() * std::mem::size_of::<Cell>()
            + self.spill.capacity() * (std::mem::size_of::<(u32, Vec<u32>)>() + 1)
            + self.spill.values().map(|s| s.capacity() * 4).sum::<usize>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{vec3, Vec3};

    #[test]
    fn geometry_clamps_and_caps() {
        let g = Geometry::new(&Aabb::new(Vec3::ZERO, Vec3::splat(10.0)), 2.0).unwrap();
        assert_eq!(g.dims, [5, 5, 5]);
        assert_eq!(g.coord(-3.0, 0), 0);
        assert_eq!(g.coord(3.9, 1), 1);
        assert_eq!(g.coord(1e30, 2), 4);
        assert_eq!(g.coords(g.cell_of(vec3(9.0, 0.5, 4.5))), [4, 0, 2]);
        assert_eq!(g.slab(0, 0), (f32::NEG_INFINITY, 2.0));
        assert_eq!(g.slab(4, 0), (8.0, f32::INFINITY));
        let big = Geometry::new(&Aabb::new(Vec3::ZERO, vec3(1e6, 1.0, 1.0)), 1.0).unwrap();
        assert!(big.dims[0] <= MAX_CELLS_PER_AXIS && big.cell > 1.0);
        assert!(Geometry::new(&Aabb::new(Vec3::ZERO, Vec3::ONE), 0.0).is_err());
        assert!(Geometry::new(&Aabb::new(Vec3::ZERO, Vec3::ONE), f32::NAN).is_err());
    }

    #[test]
    fn store_spills_and_swaps() {
        let mut st = CellStore::new(2);
        for k in 0..6 {
            assert_eq!(st.push(1, k), k);
        }
        assert_eq!(st.parts(1)[1], &[3, 4, 5]);
        // Removing an inline entry pulls the last spilled one in.
        assert_eq!(st.remove(1, 0), Some(5));
        assert_eq!(st.slot(1, 0), 5);
        assert_eq!(st.remove(1, 4), None);
        assert_eq!(st.remove(1, 3), None);
        assert!(st.spill.is_empty());
        assert_eq!(st.parts(1)[0], &[5, 1, 2]);
        assert_eq!((st.count(0), st.count(1)), (0, 3));
    }
}
