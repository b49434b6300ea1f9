//! A dense uniform 3D grid over a world box, for scenes of similar-sized objects
//! spread evenly through a known volume [sources: w1]: the 3D counterpart of the
//! 2D grid [sources: grid2d, grid3d], specialised for moving spheres.
//!
//! Split by concern: [`cells`] (geometry and cell storage), `query` (range,
//! frustum and ray visits), `pairs` (half-shell pair search), `par_pairs`
//! (the same across rayon's threads), `validate`.

mod cells;
mod nearest;
mod pairs;
#[cfg(feature = "parallel")]
mod par_pairs;
mod query;
mod validate;

use crate::arena::Arena;
use crate::broad::filter::InertCount;
use crate::broad::walk::{walk_methods, Walk};
use crate::broad::{Filter, IndexKind, SceneHint, Selection, SpatialIndex};
use crate::geom::{Aabb, Sphere};
use crate::{Error, Handle, Result};
use cells::{CellStore, Geometry, NO_CELL};
use std::ops::ControlFlow;

/// Everything a [`UniformGrid3d`] is built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid3dConfig {
    /// The box the cells cover. Centres outside it are clamped to the border
    /// cells, still exactly.
    pub world: Aabb,
    /// The edge of the cubic cells: finite and `> 0`. The grid enlarges it if
    /// needed to stay within 2^21 cells, 2^12 along an axis.
    pub cell_size: f32,
}

impl Grid3dConfig {
    /// Cells `typical_radius / 0.49` wide (about twice the radius, so objects up
    /// to that radius are gridded); a radius that is not finite and positive
    /// gives a NaN cell size, which the grid rejects.
    pub fn new(world: Aabb, typical_radius: f32) -> Self {
        Grid3dConfig {
            world,
            cell_size: UniformGrid3d::<()>::cell_for_radius(typical_radius).unwrap_or(f32::NAN),
        }
    }

    /// Cells sized for the hint's `r_max` over its world box.
    pub fn for_scene(hint: &SceneHint) -> Self {
        Self::new(hint.world, hint.r_max)
    }
}

/// Where an object is stored: position `idx` of cell `cell`, or position `idx` of
/// the large list when `cell == NO_CELL`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Loc {
    cell: u32,
    idx: u32,
}

/// A dense uniform grid over a world box; each object is stored once, in the cell
/// holding its centre.
///
/// **Idea.** With cells at least twice as wide as any gridded radius, two
/// overlapping objects have centres in the same or adjacent cells. So pairs are
/// found by testing each cell against itself and its 13 "forward" neighbours (the
/// half shell: each neighbouring pair of cells once), with no duplicate to filter
/// and nothing to clip: each object is in exactly one cell.
///
/// **Layout.** Cells are a dense array indexed `x + nx·(y + ny·z)` of 16-byte
/// records: a count and up to 3 slots stored in the cell itself (more spill to
/// a side table), so that moving an object between cells touches one cache
/// line per cell. The spheres live in one array by slot, so an
/// update that keeps its cell is one sequential write when objects are updated in
/// handle order (writing into cell order instead scatters the writes: W1 at
/// 100k measured 9.7 ms of updates per frame that way, 3.4 ms this way; 1.3 ms
/// once the in-cell update inlines into the caller's loop). The pair scan
/// gathers each row of cells (fixed y, z) once into a packed structure-of-arrays
/// buffer in cell order, keeping about one xy layer of rows (see `pairs`; it is
/// allocated per pair search, about 20 bytes per sphere of a layer plus 4 per
/// cell of a layer, and not counted by `memory_bytes`), so that each neighbour
/// run of cells is contiguous and the SIMD tests stream through it.
///
/// **Outside and large objects.** Centres outside the world box are clamped to the
/// border cells (still exact: the clamp is monotone). Objects whose radius exceeds
/// `0.49 · cell` go to a large list: every query tests them directly and their
/// pairs are found by querying the grid with their sphere.
///
/// **Cell size** (see [`UniformGrid3d::new`]): about twice the typical largest
/// radius; a world that would need more than 2^21 cells, or 2^12 along an axis,
/// gets larger cells.
///
/// Costs, with `k` objects per cell: insert/remove/update O(1) (amortized);
/// pairs O(cells + Σ k·(neighbours' k) + large × query); range queries O(cells in
/// the range + objects there + large). Frusta (which have no bounding box) and
/// ranges of more than a few dozen cells descend an implicit octree of cell
/// blocks instead: blocks outside the query are skipped and blocks whose
/// centres lie inside it are reported without tests (see `query`), so a
/// frustum costs O(blocks near its boundary + objects inside), not O(cells). Memory: 16 bytes per cell, 8 per
/// object for its location, 16 for its sphere, 8 for its filter, plus the
/// payloads.
#[derive(Clone, Debug)]
pub struct UniformGrid3d<T> {
    geom: Geometry,
    store: CellStore,
    items: Arena<T>,
    /// Slot → location.
    locs: Vec<Loc>,
    /// Slot → sphere.
    spheres: Vec<Sphere>,
    /// Slot → collision filter (read for reported pairs and filtered queries
    /// only, so the scans' sphere array stays dense).
    filters: Vec<Filter>,
    /// Inert objects stored: while there are some, the pair scan leaves them
    /// out of its rows (see `pairs.rs`).
    inert: InertCount,
    /// Slots of the large objects.
    large: Vec<u32>,
    /// Union of the gridded spheres' boxes since the grid was created, cleared or
    /// emptied (only grows): rays are clipped to it.
    extent: Aabb,
}

impl<T> UniformGrid3d<T> {
    /// A grid over `world` with cells `typical_radius / 0.49` wide (about twice
    /// the radius, so objects up to that radius are gridded), enlarged to respect
    /// the caps. Errors on an invalid box or a radius that is not finite and
    /// positive.
    pub fn new(world: Aabb, typical_radius: f32) -> Result<Self> {
        let cell_size = Self::cell_for_radius(typical_radius)?;
        Self::with_config(Grid3dConfig { world, cell_size })
    }

    /// A grid as `config` says (cells enlarged if the caps require). Errors on
    /// an invalid box or a cell size that is not finite and positive.
    pub fn with_config(config: Grid3dConfig) -> Result<Self> {
        let geom = Geometry::new(&config.world, config.cell_size)?;
        Ok(UniformGrid3d {
            store: CellStore::new(geom.cell_count()),
            geom,
            items: Arena::new(),
            locs: Vec::new(),
            spheres: Vec::new(),
            filters: Vec::new(),
            inert: InertCount::default(),
            large: Vec::new(),
            extent: Aabb::EMPTY,
        })
    }

    /// `typical_radius / 0.49`, or the error for a radius that is not finite
    /// and positive.
    fn cell_for_radius(typical_radius: f32) -> Result<f32> {
        if !typical_radius.is_finite() || typical_radius <= 0.0 {
            return Err(Error::InvalidParameter(format!(
                "typical radius {typical_radius} must be finite and positive"
            )));
        }
        Ok((typical_radius / cells::GRID_FRACTION).min(f32::MAX))
    }

    /// Edge of a cell.
    pub fn cell_size(&self) -> f32 {
        self.geom.cell
    }

    /// Cells along x, y and z.
    pub fn dims(&self) -> [u32; 3] {
        self.geom.dims
    }

    /// Number of objects in the large list.
    pub fn large_count(&self) -> usize {
        self.large.len()
    }

    /// The handle and payload of a live slot (locations name live slots: checked
    /// by `validate`, so failure is a bug).
    #[inline]
    fn resolve(&self, slot: u32) -> (Handle, &T) {
        self.items
            .get_by_index(slot)
            .expect("grid3d entry names a dead slot: invariant broken")
    }

    /// Stores `slot` with sphere `s` and returns where.
    fn place(&mut self, slot: u32, s: Sphere) -> Loc {
        if s.radius <= self.geom.limit {
            self.extent = self.extent.union(&s.aabb());
            let cell = self.geom.cell_of(s.center);
            let idx = self.store.push(cell, slot);
            Loc { cell, idx }
        } else {
            self.large.push(slot);
            Loc {
                cell: NO_CELL,
                idx: self.large.len() as u32 - 1,
            }
        }
    }

    /// Moves `slot` from `loc` to wherever `s` belongs. Out of line: an update
    /// that keeps its cell (the common case) is then small enough to inline into
    /// the caller's loop.
    #[cold]
    #[inline(never)]
    fn relocate(&mut self, slot: u32, loc: Loc, s: Sphere) {
        self.unplace(loc);
        self.locs[slot as usize] = self.place(slot, s);
        self.spheres[slot as usize] = s;
    }

    /// Drops the entry at `loc`, fixing the location of the entry moved into it.
    fn unplace(&mut self, loc: Loc) {
        let moved = if loc.cell == NO_CELL {
            let i = loc.idx as usize;
            self.large.swap_remove(i);
            self.large.get(i).copied()
        } else {
            self.store.remove(loc.cell, loc.idx)
        };
        if let Some(m) = moved {
            self.locs[m as usize] = loc;
        }
    }
}

impl<T: Send + Sync> SpatialIndex<T> for UniformGrid3d<T> {
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        // Room first: a full arena must leave the grid exactly as it was.
        self.items.check_room()?;
        let slot = self.items.next_handle().index();
        let loc = self.place(slot, sphere);
        let h = self.items.insert(value)?;
        debug_assert_eq!(h.index(), slot);
        if self.locs.len() <= slot as usize {
            self.locs.resize(slot as usize + 1, loc);
            self.spheres.resize(slot as usize + 1, sphere);
            self.filters.resize(slot as usize + 1, filter);
        }
        self.locs[slot as usize] = loc;
        self.spheres[slot as usize] = sphere;
        self.filters[slot as usize] = filter;
        self.inert.add(filter);
        Ok(h)
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        let value = self.items.remove(handle)?;
        self.inert.sub(self.filters[handle.index() as usize]);
        self.unplace(self.locs[handle.index() as usize]);
        if self.items.is_empty() {
            self.extent = Aabb::EMPTY;
        }
        Ok(value)
    }

    #[inline]
    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        if !self.items.contains(handle) {
            // The arena's error for a stale handle.
            return self.items.get(handle).map(|_| ());
        }
        let slot = handle.index();
        let loc = self.locs[slot as usize];
        if loc.cell != NO_CELL && sphere.radius <= self.geom.limit {
            self.extent = self.extent.union(&sphere.aabb());
            let cell = self.geom.cell_of(sphere.center);
            if cell == loc.cell {
                // The common case in a moving scene: one sphere written, no cell
                // touched.
                self.spheres[slot as usize] = sphere;
                return Ok(());
            }
        }
        self.relocate(slot, loc, sphere);
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        let v = self.items.get(handle)?;
        Ok((self.spheres[handle.index() as usize], v))
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.items.get_mut(handle)
    }

    fn filter(&self, handle: Handle) -> Result<Filter> {
        self.items.get(handle)?;
        Ok(self.filters[handle.index() as usize])
    }

    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        self.items.get(handle)?;
        let old = std::mem::replace(&mut self.filters[handle.index() as usize], filter);
        self.inert.change(old, filter);
        Ok(())
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    fn clear(&mut self) {
        let g = self.geom;
        *self = UniformGrid3d {
            store: CellStore::new(g.cell_count()),
            geom: g,
            items: Arena::new(),
            locs: Vec::new(),
            spheres: Vec::new(),
            filters: Vec::new(),
            inert: InertCount::default(),
            large: Vec::new(),
            extent: Aabb::EMPTY,
        };
    }

    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (h, v) in self.items.iter() {
            f(h, &self.spheres[h.index() as usize], v);
        }
    }

    walk_methods!(T);

    fn validate(&self) -> Result<()> {
        self.check()
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.store.heap_bytes()
            + self.items.heap_bytes()
            + self.locs.capacity() * std::mem::size_of::<Loc>()
            + self.large.capacity() * 4
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
            + self.filters.capacity() * std::mem::size_of::<Filter>()
    }

    fn kind(&self) -> IndexKind {
        IndexKind::Grid3d
    }
}

impl<T> Walk<T> for UniformGrid3d<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if let Some(ray) = query.as_ray().filter(|r| self.walkable(*r)) {
            self.visit_cast(ray, &mut f)?;
        } else if let Some(sweep) = query.as_sweep().filter(|s| self.walkable(*s)) {
            self.visit_cast(sweep, &mut f)?;
        } else if let Some(b) = query.bounds() {
            let (lo, hi) = self.geom.range(&b);
            self.visit_range(query, lo, hi, &mut f)?;
        } else {
            let hi = self.geom.dims.map(|d| d - 1);
            self.visit_range(query, [0; 3], hi, &mut f)?;
        }
        for &slot in &self.large {
            let s = &self.spheres[slot as usize];
            if query.selects(s) {
                let (h, v) = self.resolve(slot);
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    fn filter_of(&self, h: Handle) -> Filter {
        self.filters[h.index() as usize]
    }

    fn object_count(&self) -> usize {
        self.items.len()
    }

    /// Front to back along the path's dominant axis (`grid3d/query.rs`).
    fn first_hit(
        &self,
        ray: &crate::geom::Ray,
        filter: Option<Filter>,
    ) -> Option<crate::broad::RayHit> {
        // A cast the dense walk cannot clip (see `walkable`): the generic scan.
        if !self.walkable(ray) {
            return crate::broad::walk::scan_first(self, ray, filter);
        }
        self.first_cast(ray, filter)
    }

    /// Front to back along the segment's dominant axis (`grid3d/query.rs`).
    fn first_sweep_hit(
        &self,
        sweep: &crate::geom::SphereSweep,
        filter: Option<Filter>,
    ) -> Option<crate::broad::RayHit> {
        // A cast the dense walk cannot clip (see `walkable`): the generic scan.
        if !self.walkable(sweep) {
            return crate::broad::walk::scan_first(self, sweep, filter);
        }
        self.first_cast(sweep, filter)
    }

    /// The growing box of cells (`grid3d/nearest.rs`).
    fn knn_into(
        &self,
        query: &crate::broad::Nearest,
        filter: Option<Filter>,
        out: &mut Vec<crate::broad::Neighbor>,
    ) {
        if crate::broad::nearest::may_overflow(query.point, &self.extent) {
            return crate::broad::nearest::expanding(self, query, filter, out);
        }
        self.nearest_impl(query, filter, out)
    }

    fn walk_pairs(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.pair_rows(0, self.row_count(), &mut f)?;
        for i in 0..self.large.len() {
            self.large_pairs(i, &mut f)?;
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::Grid3dConfig;
    use crate::broad::SpatialIndexExt;
    use glam::{vec3, Vec3};

    #[test]
    fn constructor_checks() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(100.0));
        let g = UniformGrid3d::<()>::new(w, 2.0).unwrap();
        assert!((g.cell_size() - 2.0 / 0.49).abs() < 1e-5);
        assert_eq!(g.dims(), [25, 25, 25]);
        assert!(UniformGrid3d::<()>::new(w, 0.0).is_err());
        assert!(UniformGrid3d::<()>::new(w, f32::NAN).is_err());
        assert!(UniformGrid3d::<()>::with_config(Grid3dConfig {
            world: w,
            cell_size: -1.0
        })
        .is_err());
        let bad = Aabb::new(Vec3::ONE, Vec3::ZERO);
        assert!(UniformGrid3d::<()>::new(bad, 1.0).is_err());
    }

    #[test]
    fn objects_move_between_cells_and_the_large_list() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(40.0));
        let mut g = UniformGrid3d::with_config(Grid3dConfig {
            world: w,
            cell_size: 4.0,
        })
        .unwrap();
        let a = g
            .insert(Sphere::new(vec3(2.0, 2.0, 2.0), 1.0), 'a')
            .unwrap();
        let b = g
            .insert(Sphere::new(vec3(3.9, 2.0, 2.0), 1.0), 'b')
            .unwrap();
        assert_eq!(g.pairs().len(), 1);
        g.update(a, Sphere::new(vec3(2.5, 2.0, 2.0), 1.0)).unwrap();
        g.update(a, Sphere::new(vec3(-50.0, 2.0, 2.0), 1.0))
            .unwrap();
        g.validate().unwrap();
        assert_eq!(g.pairs().len(), 0);
        g.update(a, Sphere::new(vec3(5.0, 2.0, 2.0), 30.0)).unwrap();
        assert_eq!(g.large_count(), 1);
        assert_eq!(g.pairs().len(), 1);
        g.validate().unwrap();
        g.update(a, Sphere::new(vec3(4.5, 3.0, 2.0), 1.0)).unwrap();
        assert_eq!(g.large_count(), 0);
        assert_eq!(g.pairs(), vec![(a.min(b), a.max(b))]);
        assert_eq!(g.remove(a), Ok('a'));
        assert!(g.update(a, Sphere::new(Vec3::ZERO, 1.0)).is_err());
        assert!(g.update(b, Sphere::new(Vec3::ZERO, f32::NAN)).is_err());
        g.validate().unwrap();
        assert_eq!(g.get(b).unwrap().0, Sphere::new(vec3(3.9, 2.0, 2.0), 1.0));
    }
}
