//! The uniform 2D grid [sources: grid2d]: for flat worlds (`dz << dx,
//! dy`) with objects of similar size, project every sphere onto the XY plane and
//! reference it from every cell its footprint covers; a query visits the cells its
//! own footprint covers.
//!
//! Split by concern: [`cells`] (cell coordinates and ranges), `link` (keeping the
//! references in step with insert/remove/update), `query` (range and frustum
//! queries), `ray` (walking the cells along a ray), `pairs`, `validate`.

mod cells;
mod link;
mod pairs;
mod query;
mod ray;
mod validate;

use crate::arena::Arena;
use crate::broad::cell_list::{CellList, Reach};
use crate::broad::walk::{self, walk_methods, Walk};
use crate::broad::{Filter, IndexKind, RayHit, SceneHint, Selection, SpatialIndex};
use crate::geom::{Aabb, Ray, Sphere};
use crate::{Error, Handle, Result};
use cells::{CellRect, Geometry};
use std::ops::ControlFlow;

/// Default cap on the number of cells chosen by [`UniformGrid2d::new`].
const DEFAULT_MAX_CELLS: usize = 1 << 20;

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

/// A stored object: the cells it is referenced from and its payload (the sphere
/// is in the dense `spheres` array).
#[derive(Clone, Debug)]
struct Item<T> {
    rect: CellRect,
    /// Read with the payload when a pair is reported.
    filter: Filter,
    value: T,
}

/// A uniform grid of square cells over a rectangle of the XY plane ([sources: grid2d]: "2D
/// grid on the XY plane" for worlds with `dz << dx, dy`).
///
/// Every object is referenced from each cell its XY footprint (the bounding square
/// of its circle) covers. A cell holds a compact list of 8-byte references (slot
/// and lowest covered cell); the spheres live in one dense array by slot, so an
/// update that keeps the covered cells writes one sphere and touches no cell.
/// The z coordinate is not gridded: the exact shared overlap tests decide.
/// Queries prune cells by a loose box: the cell grown by twice the largest radius
/// stored, within the bounds of everything stored (both only grow until `clear`
/// or the grid empties; see the docs of `Reach` in the source).
///
/// **Outside the rectangle.** Coordinates are clamped, so objects (and queries)
/// beyond the rectangle are referenced from the border cells. Answers stay exact;
/// only speed suffers if many objects sit far outside (they crowd the border
/// cells).
///
/// **Once-only reporting with `&self`.** The source marks each visited object with
/// the current frame number [sources: grid-dedup] so that an object seen in several cells is tested
/// once; that needs mutation during a query. Instead, a query whose cells form a
/// rectangle reports an object only from the *lowest* cell of the overlap between
/// the object's cell range and the query's, i.e. the cell `(max(ox0, qx0),
/// max(oy0, qy0))`, which both cover exactly once. A pair is reported only from
/// the lowest cell both objects cover. Rays use the same idea along their walk
/// (see `ray.rs`). No allocation, no shared state: queries may run in parallel.
///
/// Costs, with `k` references per cell: insert/remove O(cells covered × k);
/// update O(1) while the covered cells stay the same, else O(cells covered × k);
/// range queries O(cells covered + references in
/// them); rays O(cells along the ray's XY projection); frustums O(all cells);
/// pairs O(Σ k²). Memory: 24 bytes per cell, 8 per reference, 16 per object for the sphere. Objects much
/// larger than a cell are referenced from many cells: the grid suits similar sizes.
#[derive(Clone, Debug)]
pub struct UniformGrid2d<T> {
    geom: Geometry,
    cells: Vec<CellList<[u16; 2]>>,
    items: Arena<Item<T>>,
    /// Slot → sphere of the live object there (hot data for pairs and queries).
    spheres: Vec<Sphere>,
    /// Slot → live handle, to report a handle from a reference.
    handles: Vec<Handle>,
    /// Total number of references (for validation).
    refs: usize,
    /// Growing bounds on the stored spheres, for the cells' loose boxes.
    reach: Reach,
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
        let geom = Geometry::new(&config.world, config.cell_size)?;
        Ok(UniformGrid2d {
            cells: vec![CellList::default(); geom.cell_count()],
            geom,
            items: Arena::new(),
            spheres: Vec::new(),
            handles: Vec::new(),
            refs: 0,
            reach: Reach::default(),
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
        let min_for_axis = side / (cells::MAX_CELLS_PER_AXIS as f64 - 1.0);
        let cell = cell.max(min_for_cap * 1.001).max(min_for_axis * 1.001);
        (cell as f32).min(f32::MAX)
    }

    /// Edge of a cell.
    pub fn cell_size(&self) -> f32 {
        self.geom.cell
    }

    /// Cells along x and y.
    pub fn dims(&self) -> [u32; 2] {
        self.geom.dims
    }

    /// Total number of cell references (an object covering 4 cells counts 4).
    pub fn reference_count(&self) -> usize {
        self.refs
    }

    /// The filter of the live object at `slot`.
    #[inline]
    fn slot_filter(&self, slot: u32) -> Filter {
        self.filter_of(self.handles[slot as usize])
    }

    /// The handle and payload of a referenced slot. References always name live
    /// slots (checked by `validate`), so failure is a bug.
    #[inline]
    fn resolve(&self, slot: u32) -> (Handle, &T) {
        let h = self.handles[slot as usize];
        let item = self
            .items
            .get(h)
            .expect("grid reference to a dead slot: invariant broken");
        (h, &item.value)
    }

    /// The loose box of cell `(x, y)`: a box containing every sphere it references.
    #[inline]
    fn loose(&self, x: u32, y: u32) -> Aabb {
        let g = &self.geom;
        let min = glam::vec3(
            g.origin[0] + x as f32 * g.cell,
            g.origin[1] + y as f32 * g.cell,
            0.0,
        );
        let max = min + glam::vec3(g.cell, g.cell, 0.0);
        let open_lo = glam::BVec3::new(x == 0, y == 0, true);
        let open_hi = glam::BVec3::new(x == g.dims[0] - 1, y == g.dims[1] - 1, true);
        g.padded(&self.reach.loose(min, max, open_lo, open_hi))
    }
}

impl<T: Send + Sync> SpatialIndex<T> for UniformGrid2d<T> {
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        let rect = self.geom.sphere_rect(&sphere);
        let h = self.items.insert(Item {
            rect,
            filter,
            value,
        })?;
        let slot = h.index() as usize;
        if self.handles.len() <= slot {
            self.handles.resize(slot + 1, h);
            self.spheres.resize(slot + 1, sphere);
        }
        self.handles[slot] = h;
        self.spheres[slot] = sphere;
        self.reach.include(&sphere);
        self.link(h.index(), rect);
        Ok(h)
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        let item = self.items.remove(handle)?;
        self.unlink(handle.index(), item.rect);
        if self.items.is_empty() {
            self.reach = Reach::default();
        }
        Ok(item.value)
    }

    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        let item = self.items.get_mut(handle)?;
        let old = item.rect;
        let new = self.geom.sphere_rect(&sphere);
        item.rect = new;
        self.spheres[handle.index() as usize] = sphere;
        self.reach.include(&sphere);
        if old != new {
            self.relink(handle.index(), old, new);
        }
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        let item = self.items.get(handle)?;
        Ok((self.spheres[handle.index() as usize], &item.value))
    }

    fn filter(&self, handle: Handle) -> Result<Filter> {
        self.items.get(handle).map(|i| i.filter)
    }

    fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        self.items.get_mut(handle)?.filter = filter;
        Ok(())
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.items.get_mut(handle).map(|i| &mut i.value)
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    fn clear(&mut self) {
        self.items.clear();
        self.handles = Vec::new();
        self.spheres = Vec::new();
        for c in &mut self.cells {
            *c = CellList::default();
        }
        self.refs = 0;
        self.reach = Reach::default();
    }

    fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (h, i) in self.items.iter() {
            f(h, &self.spheres[h.index() as usize], &i.value);
        }
    }

    walk_methods!(T);

    fn validate(&self) -> Result<()> {
        self.check()
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.items.heap_bytes()
            + self.handles.capacity() * std::mem::size_of::<Handle>()
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
            + self.cells.capacity() * std::mem::size_of::<CellList<[u16; 2]>>()
            + self.cells.iter().map(|c| c.heap_bytes()).sum::<usize>()
    }

    fn kind(&self) -> IndexKind {
        IndexKind::Grid2d
    }
}

impl<T> Walk<T> for UniformGrid2d<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if let Some(ray) = query.as_ray() {
            return self.visit_ray(ray, f);
        }
        let rect = match query.bounds() {
            Some(b) => self.geom.aabb_rect(&b),
            None => self.geom.full_rect(),
        };
        self.visit_rect(query, rect, f)
    }

    fn walk_pairs(
        &self,
        f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.pair_cells(f)
    }

    fn filter_of(&self, h: Handle) -> Filter {
        self.items.get(h).expect("a live handle").filter
    }

    fn object_count(&self) -> usize {
        self.items.len()
    }

    /// The cell walk along the ray; with a query filter, the filtered scan of
    /// every hit (the cell walk does not filter yet).
    fn first_hit(&self, ray: &Ray, filter: Option<Filter>) -> Option<RayHit> {
        match filter {
            None => self.ray_first_cells(ray),
            Some(_) => walk::scan_first(self, ray, filter),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::Grid2dConfig;
    use glam::{vec3, Vec3};

    #[test]
    fn constructor_checks_and_defaults() {
        let w = Aabb::new(Vec3::ZERO, vec3(1000.0, 1000.0, 10.0));
        let g: UniformGrid2d<()> = UniformGrid2d::new(w, 2.0).unwrap();
        assert_eq!(g.cell_size(), 4.0);
        assert_eq!(g.dims(), [250, 250]);
        // A tiny radius over a large world is capped at about DEFAULT_MAX_CELLS cells.
        let g: UniformGrid2d<()> = UniformGrid2d::new(w, 1e-3).unwrap();
        assert!(g.dims()[0] as usize * g.dims()[1] as usize <= DEFAULT_MAX_CELLS);
        let g: UniformGrid2d<()> = UniformGrid2d::new(w, 0.0).unwrap();
        assert_eq!(g.dims(), [256, 256]);
        assert!(UniformGrid2d::<()>::new(w, -1.0).is_err());
        assert!(UniformGrid2d::<()>::new(w, f32::INFINITY).is_err());
        assert!(UniformGrid2d::<()>::with_config(Grid2dConfig {
            world: w,
            cell_size: 0.0
        })
        .is_err());
        let bad = Aabb::new(Vec3::ONE, Vec3::ZERO);
        assert!(UniformGrid2d::<()>::new(bad, 1.0).is_err());
    }

    #[test]
    fn update_within_the_same_cells_touches_no_cell() {
        let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 1.0));
        let mut g = UniformGrid2d::with_config(Grid2dConfig {
            world: w,
            cell_size: 10.0,
        })
        .unwrap();
        let h = g
            .insert(Sphere::new(vec3(15.0, 15.0, 0.0), 1.0), 'a')
            .unwrap();
        assert_eq!(g.reference_count(), 1);
        g.update(h, Sphere::new(vec3(16.0, 14.0, 0.5), 2.0))
            .unwrap();
        assert_eq!(g.reference_count(), 1);
        g.validate().unwrap();
        // Across a border: now 2 cells.
        g.update(h, Sphere::new(vec3(19.5, 14.0, 0.5), 2.0))
            .unwrap();
        assert_eq!(g.reference_count(), 2);
        g.validate().unwrap();
        assert_eq!(g.remove(h), Ok('a'));
        assert_eq!(g.reference_count(), 0);
        g.validate().unwrap();
        assert!(g.update(h, Sphere::new(Vec3::ZERO, 1.0)).is_err());
    }
}
