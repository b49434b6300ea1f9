//! The uniform 2D grid [sources: grid2d]: for flat worlds (`dz << dx,
//! dy`) with objects of similar size, project every sphere onto the XY plane and
//! reference it from every cell its footprint covers; a query visits the cells its
//! own footprint covers.
//!
//! A thin front end: the grid itself is the shared
//! [`CellGrid`](super::cell_grid) over a dense array of cells (z flat); this
//! module lays the cells over the world's rectangle and picks the cell size.

#[cfg(test)]
mod tests;

use crate::broad::cell_grid::keys::{KeyBox, Lattice, REL_PAD};
use crate::broad::cell_grid::{cell_grid_index, CellGrid, Dense, Store};
use crate::broad::{IndexKind, SceneHint};
use crate::geom::Aabb;
use crate::{Error, Result};

/// Default cap on the number of cells chosen by [`UniformGrid2d::new`].
const DEFAULT_MAX_CELLS: usize = 1 << 20;

/// Most cells along one axis (references store cell coordinates as `u16`).
const MAX_CELLS_PER_AXIS: u32 = 1 << 16;

/// Most cells in a grid (24 bytes each when empty).
const MAX_CELLS: u64 = 1 << 24;

/// Everything a [`UniformGrid2d`] is built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid2dConfig {
    /// The box whose XY rectangle the cells cover (z is not gridded). Objects
    /// outside it are referenced from the border cells, still exactly.
    pub world: Aabb,
    /// The edge of the square cells: finite and `> 0`, at most 2^16 cells along
    /// an axis and 2^24 in all.
    pub cell_size: f32,
}

impl Grid2dConfig {
    /// Cells of [`UniformGrid2d::default_cell_size`] for objects of radius up to
    /// about `typical_radius` (a negative or non-finite radius gives a NaN cell
    /// size, which the grid rejects).
    pub fn new(world: Aabb, typical_radius: f32) -> Self {
        Grid2dConfig {
            world,
            cell_size: UniformGrid2d::<()>::cell_for_radius(&world, typical_radius)
                .unwrap_or(f32::NAN),
        }
    }

    /// Cells sized for the hint's `r_max` over its world box.
    pub fn for_scene(hint: &SceneHint) -> Self {
        Self::new(hint.world, hint.r_max)
    }
}

/// A uniform grid of square cells over a rectangle of the XY plane ([sources: grid2d]: "2D
/// grid on the XY plane" for worlds with `dz << dx, dy`).
///
/// Every object is referenced from each cell its XY footprint (the bounding square
/// of its circle) covers. A cell holds a compact list of 12-byte references (slot
/// and covered cells); the spheres live in one dense array by slot, so an
/// update that keeps the covered cells writes one sphere and touches no cell.
/// The z coordinate is not gridded: the exact shared overlap tests decide.
/// Queries prune blocks of cells by the boxes of the objects they report: the
/// cells grown by twice the largest radius stored (upwards only, mostly), within
/// the bounds of everything stored (both only grow until `clear` or the grid
/// empties).
///
/// **Outside the rectangle.** Coordinates are clamped, so objects (and queries)
/// beyond the rectangle are referenced from the border cells. Answers stay exact;
/// only speed suffers if many objects sit far outside (they crowd the border
/// cells).
///
/// **Oversized objects.** An object whose footprint covers more than 1024 cells
/// (32 × 32) is not gridded: it goes to a list that every query tests directly,
/// and its pairs are found by querying the grid with its sphere.
///
/// **Once-only reporting with `&self`.** The source marks each visited object with
/// the current frame number [sources: grid-dedup] so that an object seen in several cells is tested
/// once; that needs mutation during a query. Instead, a query whose cells form a
/// rectangle reports an object only from the *lowest* cell of the overlap between
/// the object's cell range and the query's, i.e. the cell `(max(ox0, qx0),
/// max(oy0, qy0))`, which both cover exactly once. A pair is reported only from
/// the lowest cell both objects cover. Rays use the same idea along their walk.
/// No allocation, no shared state: queries may run in parallel.
///
/// **Not for deep worlds.** Each cell is a column through all of z. In a world
/// as deep as it is wide (W4's cube) a ray or a frustum tests every object in
/// the columns it crosses, however far in z; there use [`HashGrid`](super::HashGrid)
/// or [`UniformGrid3d`](super::UniformGrid3d).
///
/// Costs, with `k` references per cell: insert/remove O(cells covered × k);
/// update O(1) while the covered cells stay the same, else O(cells covered × k);
/// range queries O(cells covered + references in them); rays O(cells along the
/// ray's XY projection); frustums O(blocks of cells near the frustum's
/// boundary, plus the cells inside it); pairs O(Σ k²). Memory: 24 bytes per cell, 12 per
/// reference, 16 per object for the sphere. Objects much larger than a cell are
/// referenced from many cells: the grid suits similar sizes.
#[derive(Clone, Debug)]
pub struct UniformGrid2d<T> {
    grid: CellGrid<T, Dense>,
}

impl<T> UniformGrid2d<T> {
    /// A grid over `world`'s XY rectangle with the default cell size for objects of
    /// radius up to about `typical_radius` (see [`UniformGrid2d::default_cell_size`]).
    /// Errors on an invalid box or a negative or non-finite radius.
    pub fn new(world: Aabb, typical_radius: f32) -> Result<Self> {
        world.validate()?;
        let cell_size = Self::cell_for_radius(&world, typical_radius)?;
        Self::with_config(Grid2dConfig { world, cell_size })
    }

    /// A grid as `config` says. Errors on an invalid box, or a cell size that is
    /// not finite and positive or makes more than 2^16 cells along an axis or
    /// 2^24 in all.
    pub fn with_config(config: Grid2dConfig) -> Result<Self> {
        let lattice = lattice(&config.world, config.cell_size)?;
        Ok(UniformGrid2d {
            grid: CellGrid::new(Dense::new(lattice)),
        })
    }

    /// [`UniformGrid2d::default_cell_size`], or the error for a radius that is
    /// negative or not finite.
    fn cell_for_radius(world: &Aabb, typical_radius: f32) -> Result<f32> {
        if !typical_radius.is_finite() || typical_radius < 0.0 {
            return Err(Error::InvalidParameter(format!(
                "typical radius {typical_radius} must be finite and not negative"
            )));
        }
        Ok(Self::default_cell_size(world, typical_radius))
    }

    /// The default cell edge: twice `typical_radius` (a typical footprint then
    /// covers at most 2 × 2 cells, so each object has few references while each cell
    /// holds few objects), enlarged if the rectangle would need more than 2^20
    /// cells. A zero radius gives 1/256 of the longer side.
    pub fn default_cell_size(world: &Aabb, typical_radius: f32) -> f32 {
        // In f64 and clamped to f32::MAX: a world spanning most of the f32 range
        // has an extent that overflows f32, and `2 r` can too.
        let ex = world.max.x as f64 - world.min.x as f64;
        let ey = world.max.y as f64 - world.min.y as f64;
        let side = ex.max(ey);
        let mut cell = 2.0 * typical_radius as f64;
        if cell.is_nan() || cell <= 0.0 {
            cell = if side > 0.0 { side / 256.0 } else { 1.0 };
        }
        let min_for_cap = ((ex * ey) / DEFAULT_MAX_CELLS as f64).sqrt();
        // Also keep each axis within its limit.
        let min_for_axis = side / (MAX_CELLS_PER_AXIS as f64 - 1.0);
        let cell = cell.max(min_for_cap * 1.001).max(min_for_axis * 1.001);
        (cell as f32).min(f32::MAX)
    }

    /// Edge of a cell.
    pub fn cell_size(&self) -> f32 {
        self.grid.store().lattice().cell
    }

    /// Cells along x and y.
    pub fn dims(&self) -> [u32; 2] {
        let hi = self.grid.store().lattice().limits.hi;
        [hi[0] as u32 + 1, hi[1] as u32 + 1]
    }

    /// Total number of cell references (an object covering 4 cells counts 4).
    pub fn reference_count(&self) -> usize {
        self.grid.reference_count()
    }

    /// Number of objects kept in the oversized list.
    pub fn oversized_count(&self) -> usize {
        self.grid.oversized_count()
    }
}

/// Checks the parameters and lays cells of edge `cell` over `world`'s XY
/// rectangle (z flat).
fn lattice(world: &Aabb, cell: f32) -> Result<Lattice> {
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
    Ok(Lattice {
        origin: world.min,
        cell,
        inv_cell,
        limits: KeyBox {
            lo: [0; 3],
            hi: [dims[0] as i32 - 1, dims[1] as i32 - 1, 0],
        },
        pad: (mag.x.max(mag.y) + cell) * REL_PAD,
    })
}

cell_grid_index!(UniformGrid2d, IndexKind::Grid2d);
