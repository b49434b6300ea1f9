//! An unbounded 3D hashed grid: cells keyed by integer coordinates in a hash map,
//! created when first occupied and dropped when emptied ([sources: hash-grid], the 3D
//! counterpart of the 2D grid of [sources: grid2d]).
//!
//! Split by concern: [`keys`] (cell coordinates), `link` (cells, references, the
//! oversized list), `query` (range and frustum queries), `ray`, `pairs`,
//! `validate`.

mod keys;
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
use keys::{Key, KeyBox, Keys};
use rustc_hash::FxHashMap;
use std::ops::ControlFlow;

/// Objects whose bounding box covers more cells than this are kept in the
/// oversized list instead of the cells.
const MAX_CELLS_PER_OBJECT: u64 = 64;

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

/// Where an object is referenced from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// From every cell of the box.
    Cells(KeyBox),
    /// From the oversized list, at this position.
    Oversized(u32),
}

/// A stored object: where it is referenced from and its payload (the sphere is
/// in the dense `spheres` array).
#[derive(Clone, Debug)]
struct Item<T> {
    place: Place,
    /// Read with the payload when a pair is reported.
    filter: Filter,
    value: T,
}

/// A cell slot: its key and its references (empty when the slot is free).
#[derive(Clone, Debug)]
struct Cell {
    key: Key,
    list: CellList<Key>,
}

/// A hashed uniform grid over all of 3D space (no world box needed).
///
/// Every object is referenced from each cell its bounding box covers, by a
/// 16-byte reference (slot and lowest covered cell); the spheres live in one dense
/// array by slot, so an update that keeps the covered cells writes one sphere and
/// touches no cell or hash entry. Cells live in a flat `Vec` with a free list and are found through an
/// [`FxHashMap`] from integer coordinates (the fast non-cryptographic hasher of
/// `rustc-hash`).
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
/// cells; if it still holds more keys than there are occupied cells, the query
/// scans the occupied cells instead of looking keys up. Frustums always scan the
/// occupied cells, pruning each by its loose box. Rays walk the cells along the
/// ray within the occupied box, or scan when that walk would be longer. So no
/// query iterates over more empty cells than there are occupied ones.
///
/// **Once-only reporting with `&self`**: as in
/// [`UniformGrid2d`](crate::broad::UniformGrid2d), an object is reported only from
/// the lowest cell of the overlap of its key box with the query's, and a pair only
/// from the lowest cell both cover.
///
/// Costs, with `k` references per cell: insert/remove O(cells covered × k), update
/// O(1) while the covered cells stay the same and O(cells covered × k) otherwise, range
/// queries O(min(cells in range, occupied cells) + references met), pairs
/// O(Σ k² + oversized × query). Memory: about 60 bytes per occupied cell, 16
/// per reference, 16 per object for the sphere. Queries prune cells by a loose
/// box: the cell grown by twice the largest gridded radius, within the bounds of
/// everything stored (both only grow until `clear` or the grid empties).
#[derive(Clone, Debug)]
pub struct HashGrid<T> {
    keys: Keys,
    map: FxHashMap<Key, u32>,
    cells: Vec<Cell>,
    free_cells: Vec<u32>,
    items: Arena<Item<T>>,
    /// Slot → sphere of the live object there (hot data for pairs and queries).
    spheres: Vec<Sphere>,
    /// Slot → live handle, to report a handle from a reference.
    handles: Vec<Handle>,
    /// Growing bounds on the gridded spheres, for the cells' loose boxes.
    reach: Reach,
    /// Slots of the oversized objects.
    oversized: Vec<u32>,
    /// Total number of references.
    refs: usize,
    /// Contains every occupied key (may be larger; recomputed when stale).
    occupied: KeyBox,
    /// Cells freed since `occupied` was last recomputed.
    stale: usize,
}

impl<T> HashGrid<T> {
    /// An empty grid over `keys`: the one place that lists the fields, shared by the
    /// constructors and `clear`.
    fn empty(keys: Keys) -> Self {
        HashGrid {
            keys,
            map: FxHashMap::default(),
            cells: Vec::new(),
            free_cells: Vec::new(),
            items: Arena::new(),
            spheres: Vec::new(),
            handles: Vec::new(),
            reach: Reach::default(),
            oversized: Vec::new(),
            refs: 0,
            occupied: KeyBox::EMPTY,
            stale: 0,
        }
    }

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
        let cell_size = config.cell_size;
        if !cell_size.is_finite() || cell_size <= 0.0 || !(1.0 / cell_size).is_finite() {
            return Err(Error::InvalidParameter(format!(
                "hash grid cell size {cell_size} must be finite and positive"
            )));
        }
        Ok(HashGrid::empty(Keys::new(cell_size)))
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
        self.keys.cell
    }

    /// Number of occupied cells.
    pub fn cell_count(&self) -> usize {
        self.map.len()
    }

    /// Number of objects kept in the oversized list.
    pub fn oversized_count(&self) -> usize {
        self.oversized.len()
    }

    /// Total number of cell references.
    pub fn reference_count(&self) -> usize {
        self.refs
    }

    /// Where a sphere goes: the cells of its box, or the oversized list.
    fn cells_of(&self, s: &Sphere) -> Option<KeyBox> {
        let kb = self.keys.sphere_box(s);
        (kb.volume() <= MAX_CELLS_PER_OBJECT).then_some(kb)
    }

    /// The filter of the live object at `slot`.
    #[inline]
    fn slot_filter(&self, slot: u32) -> Filter {
        self.filter_of(self.handles[slot as usize])
    }

    /// The handle and payload of a referenced slot (references name live slots:
    /// checked by `validate`, so failure is a bug).
    #[inline]
    fn resolve(&self, slot: u32) -> (Handle, &T) {
        let h = self.handles[slot as usize];
        let item = self
            .items
            .get(h)
            .expect("hash grid reference to a dead slot: invariant broken");
        (h, &item.value)
    }

    /// The loose box of cell `key`: a box containing every sphere it references.
    #[inline]
    fn loose(&self, key: Key) -> Aabb {
        let k = glam::IVec3::from(key);
        let min = k.as_vec3() * self.keys.cell;
        // `(k + 1) * cell`, not `min + cell`: with a huge cell `min` may overflow
        // to -∞, and the cell's upper side must stay finite.
        let max = (k + 1).as_vec3() * self.keys.cell;
        let open_lo = k.cmple(glam::IVec3::splat(-keys::LIMIT));
        let open_hi = k.cmpge(glam::IVec3::splat(keys::LIMIT));
        self.keys
            .padded(&self.reach.loose(min, max, open_lo, open_hi))
    }
}

impl<T: Send + Sync> SpatialIndex<T> for HashGrid<T> {
    fn insert_with_filter(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        self.items.check_room()?;
        let cells = self.cells_of(&sphere);
        let h = self.items.next_handle();
        let slot = h.index();
        let place = match cells {
            Some(kb) => {
                self.reach.include(&sphere);
                self.link(slot, kb);
                Place::Cells(kb)
            }
            None => {
                self.oversized.push(slot);
                Place::Oversized(self.oversized.len() as u32 - 1)
            }
        };
        let h2 = self.items.insert(Item {
            place,
            filter,
            value,
        })?;
        debug_assert_eq!(h, h2);
        if self.handles.len() <= slot as usize {
            self.handles.resize(slot as usize + 1, h);
            self.spheres.resize(slot as usize + 1, sphere);
        }
        self.handles[slot as usize] = h;
        self.spheres[slot as usize] = sphere;
        Ok(h)
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        let item = self.items.remove(handle)?;
        match item.place {
            Place::Cells(kb) => self.unlink(handle.index(), kb),
            Place::Oversized(i) => self.drop_oversized(i),
        }
        if self.items.is_empty() {
            self.reach = Reach::default();
        }
        Ok(item.value)
    }

    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        let old = self.items.get(handle)?.place;
        let slot = handle.index();
        let cells = self.cells_of(&sphere);
        if cells.is_some() {
            self.reach.include(&sphere);
        }
        let place = match (old, cells) {
            (Place::Cells(a), Some(b)) => {
                if a != b {
                    self.relink(slot, a, b);
                }
                Place::Cells(b)
            }
            (Place::Cells(a), None) => {
                self.unlink(slot, a);
                self.oversized.push(slot);
                Place::Oversized(self.oversized.len() as u32 - 1)
            }
            (Place::Oversized(i), Some(b)) => {
                self.drop_oversized(i);
                self.link(slot, b);
                Place::Cells(b)
            }
            (Place::Oversized(_), None) => old,
        };
        // `drop_oversized` may have moved another object, never this one's item.
        self.items.get_mut(handle)?.place = place;
        self.spheres[slot as usize] = sphere;
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
        let keys = self.keys;
        *self = HashGrid::empty(keys);
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
        // hashbrown: one (key, value) slot and one control byte per bucket, with
        // buckets ≈ capacity · 8/7.
        let bucket = std::mem::size_of::<(Key, u32)>() + 1;
        std::mem::size_of::<Self>()
            + self.map.capacity() * 8 / 7 * bucket
            + self.cells.capacity() * std::mem::size_of::<Cell>()
            + self
                .cells
                .iter()
                .map(|c| c.list.heap_bytes())
                .sum::<usize>()
            + self.free_cells.capacity() * 4
            + self.items.heap_bytes()
            + self.handles.capacity() * std::mem::size_of::<Handle>()
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
            + self.oversized.capacity() * 4
    }

    fn kind(&self) -> IndexKind {
        IndexKind::HashGrid
    }
}

impl<T> Walk<T> for HashGrid<T> {
    fn walk<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if let Some(ray) = query.as_ray() {
            self.visit_ray(ray, &mut f)?;
        } else {
            let kb = match query.bounds() {
                Some(b) => self.keys.aabb_box(&b),
                None => KeyBox::ALL,
            };
            self.visit_cells(query, kb, &mut f)?;
        }
        for &slot in &self.oversized {
            let s = &self.spheres[slot as usize];
            if query.selects(s) {
                let (h, v) = self.resolve(slot);
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
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
    use crate::broad::HashGridConfig;
    use crate::broad::SpatialIndexExt;
    use glam::{vec3, Vec3};

    #[test]
    fn constructor_checks() {
        assert_eq!(HashGrid::<()>::new(2.0).unwrap().cell_size(), 4.0);
        assert!(HashGrid::<()>::new(0.0).is_err());
        assert!(HashGrid::<()>::new(-1.0).is_err());
        assert!(HashGrid::<()>::new(f32::NAN).is_err());
        assert!(HashGrid::<()>::with_config(HashGridConfig {
            cell_size: f32::INFINITY
        })
        .is_err());
        assert!(HashGrid::<()>::with_config(HashGridConfig { cell_size: 1e-45 }).is_err());
    }

    #[test]
    fn objects_move_between_cells_and_the_oversized_list() {
        let mut g = HashGrid::with_config(HashGridConfig { cell_size: 4.0 }).unwrap();
        let h = g
            .insert(Sphere::new(vec3(2.0, 2.0, 2.0), 1.0), 'a')
            .unwrap();
        assert_eq!((g.cell_count(), g.reference_count()), (1, 1));
        g.update(h, Sphere::new(vec3(2.5, 1.5, 2.0), 1.2)).unwrap();
        assert_eq!((g.cell_count(), g.reference_count()), (1, 1));
        g.update(h, Sphere::new(vec3(4.0, 4.0, 4.0), 1.0)).unwrap();
        assert_eq!((g.cell_count(), g.reference_count()), (8, 8));
        g.validate().unwrap();
        g.update(h, Sphere::new(Vec3::ZERO, 100.0)).unwrap();
        assert_eq!((g.cell_count(), g.oversized_count()), (0, 1));
        let h2 = g.insert(Sphere::new(Vec3::ONE, 1e3), 'b').unwrap();
        g.update(h, Sphere::new(Vec3::ZERO, 200.0)).unwrap();
        g.validate().unwrap();
        g.update(h, Sphere::new(vec3(1e4 + 2.0, 2.0, 2.0), 0.5))
            .unwrap();
        assert_eq!((g.cell_count(), g.oversized_count()), (1, 1));
        g.validate().unwrap();
        assert_eq!(g.pairs().len(), 0);
        assert_eq!(g.remove(h2), Ok('b'));
        assert_eq!(g.remove(h), Ok('a'));
        assert_eq!((g.cell_count(), g.oversized_count()), (0, 0));
        g.validate().unwrap();
        assert!(g.remove(h).is_err());
    }
}
