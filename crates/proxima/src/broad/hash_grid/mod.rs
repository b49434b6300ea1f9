//! An unbounded 3D hashed grid: cells keyed by integer coordinates in a hash map,
//! created when first occupied and dropped when emptied ([sources: hash-grid], the 3D
//! counterpart of the 2D grid of [sources: grid2d]).
//!
//! A thin front end: the grid itself is the shared
//! [`CellGrid`](super::cell_grid) over blocks of cells in a hash map; this module
//! picks the cell size.

#[cfg(test)]
mod tests;

use crate::broad::cell_grid::keys::{KeyBox, Lattice, REL_PAD};
use crate::broad::cell_grid::{cell_grid_index, CellGrid, Hashed, Store};
use crate::broad::{IndexKind, SceneHint};
use crate::{Error, Result};

/// Largest cell coordinate magnitude (exact in `f32`); coordinates beyond are
/// clamped, so the border cells reach to infinity.
const LIMIT: i32 = 1 << 30;

/// Everything a [`HashGrid`] is built from (it needs no world box).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HashGridConfig {
    /// The edge of the cubic cells: finite and `> 0`, with a finite inverse.
    pub cell_size: f32,
}

impl HashGridConfig {
    /// Cells twice `typical_radius` wide (a radius that is not finite and
    /// positive gives a NaN cell size, which the grid rejects).
    pub fn new(typical_radius: f32) -> Self {
        HashGridConfig {
            cell_size: HashGrid::<()>::cell_for_radius(typical_radius).unwrap_or(f32::NAN),
        }
    }

    /// Cells twice the hint's `r_max` wide.
    pub fn for_scene(hint: &SceneHint) -> Self {
        Self::new(hint.r_max)
    }
}

/// A hashed uniform grid over all of 3D space (no world box needed).
///
/// Every object is referenced from each cell its bounding box covers, by a
/// 20-byte reference (slot and covered cells); the spheres live in one dense
/// array by slot, so an update that keeps the covered cells writes one sphere and
/// touches no cell or hash entry. Cells are grouped in blocks of 4 × 4 × 4, found
/// through an [`FxHashMap`](rustc_hash::FxHashMap) from block coordinates (the
/// fast non-cryptographic hasher of `rustc-hash`): neighbouring cells share a
/// block, so a small query looks up one to a few blocks, and a block with an
/// occupancy mask lets large queries skip its empty cells.
///
/// **Cell size** (see [`HashGrid::new`]): cells about the diameter of a typical
/// object keep both the references per object (≤ 8) and the objects per cell low.
/// Smaller cells multiply references and update cost; larger cells put more
/// objects in each cell and pair tests grow with their square.
///
/// **Oversized objects.** An object whose bounding box covers more than 64 cells
/// is not gridded: it goes to a list that every query tests directly, and pairs
/// involving it are found by querying the grid with its sphere. This keeps
/// memory bounded for huge spheres at the price of O(oversized) per query.
///
/// **Unbounded queries.** A query's key box is clipped to the box of occupied
/// cells, and its blocks are looked up only if they are no more than the
/// occupied blocks; otherwise the occupied blocks are scanned. Large key boxes
/// and frustums (which have no bounding box) descend from the blocks, culling
/// and accepting whole blocks and halves of blocks by the boxes of the objects
/// they report. Rays walk the cells along the ray within the occupied box, or
/// scan when that walk would be longer. So no query does more work than there
/// are occupied cells.
///
/// **Once-only reporting with `&self`**: as in
/// [`UniformGrid2d`](crate::broad::UniformGrid2d), an object is reported only from
/// the lowest cell of the overlap of its key box with the query's, and a pair only
/// from the lowest cell both cover.
///
/// Costs, with `k` references per cell: insert/remove O(cells covered × k), update
/// O(1) while the covered cells stay the same and O(cells covered × k) otherwise, range
/// queries O(min(blocks in range, occupied blocks) + cells in range + references met),
/// frustums O(occupied blocks + cells near the frustum's boundary + references
/// inside), pairs O(Σ k² + oversized × query). Memory: about 280 bytes per
/// occupied block and 24 per occupied cell, 20 per reference, 16 per object for
/// the sphere.
#[derive(Clone, Debug)]
pub struct HashGrid<T> {
    grid: CellGrid<T, Hashed>,
}

impl<T> HashGrid<T> {
    /// A grid whose cells are twice `typical_radius` wide (a typical object then
    /// covers at most 2 × 2 × 2 cells). Errors unless the radius is finite and
    /// positive.
    pub fn new(typical_radius: f32) -> Result<Self> {
        let cell_size = Self::cell_for_radius(typical_radius)?;
        Self::with_config(HashGridConfig { cell_size })
    }

    /// A grid as `config` says. Errors unless the cell size is finite and
    /// positive with a finite inverse.
    pub fn with_config(config: HashGridConfig) -> Result<Self> {
        let cell = config.cell_size;
        if !cell.is_finite() || cell <= 0.0 || !(1.0 / cell).is_finite() {
            return Err(Error::InvalidParameter(format!(
                "hash grid cell size {cell} must be finite and positive"
            )));
        }
        Ok(HashGrid {
            grid: CellGrid::new(Hashed::new(lattice(cell))),
        })
    }

    /// Twice `typical_radius`, or the error for a radius that is not finite and
    /// positive.
    fn cell_for_radius(typical_radius: f32) -> Result<f32> {
        if !typical_radius.is_finite() || typical_radius <= 0.0 {
            return Err(Error::InvalidParameter(format!(
                "typical radius {typical_radius} must be finite and positive"
            )));
        }
        // `2 r` overflows above f32::MAX / 2: the largest cell then.
        Ok((2.0 * typical_radius).min(f32::MAX))
    }

    /// Edge of a cell.
    pub fn cell_size(&self) -> f32 {
        self.grid.store().lattice().cell
    }

    /// Number of occupied cells.
    pub fn cell_count(&self) -> usize {
        self.grid.store().cell_count()
    }

    /// Number of objects kept in the oversized list.
    pub fn oversized_count(&self) -> usize {
        self.grid.oversized_count()
    }

    /// Total number of cell references.
    pub fn reference_count(&self) -> usize {
        self.grid.reference_count()
    }
}

/// Cells of edge `cell` (validated: finite, positive, finite inverse) on all of
/// space, cell `0` starting at the origin.
fn lattice(cell: f32) -> Lattice {
    Lattice {
        origin: glam::Vec3::ZERO,
        cell,
        inv_cell: 1.0 / cell,
        limits: KeyBox {
            lo: [-LIMIT; 3],
            hi: [LIMIT; 3],
        },
        pad: cell * REL_PAD,
    }
}

cell_grid_index!(HashGrid, IndexKind::HashGrid);
