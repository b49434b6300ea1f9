//! The multi-reference cell grid behind [`UniformGrid2d`](super::UniformGrid2d)
//! and [`HashGrid`](super::HashGrid) ([sources: grid2d], [sources: hash-grid]):
//! every object is referenced from each cell its footprint covers, and reported
//! once by the lowest-cell rule ([sources: grid-dedup]).
//!
//! One body, [`CellGrid`], generic over its [`Store`] — how a cell is addressed
//! and kept: [`Dense`] (a 2D array over a rectangle, z flat) or [`Hashed`]
//! (blocks of 3D cells in a hash map). The front ends add their constructors and
//! accessors. Split by concern: `keys` (cell coordinates), `list` (a cell's
//! references, the growing bounds), `store` / `dense` / `hashed`, `link`
//! (keeping references and the oversized list in step), `query` (range and
//! frustum visits), `ray`, `pairs`, `validate`.

mod dense;
mod hashed;
pub(crate) mod keys;
mod link;
mod list;
mod nearest;
mod pairs;
mod query;
mod ray;
mod store;
mod validate;

#[cfg(test)]
mod tests;

pub(crate) use dense::Dense;
pub(crate) use hashed::Hashed;
pub(crate) use store::Store;

use crate::arena::Arena;
use crate::broad::filter::InertCount;
use crate::broad::Filter;
use crate::geom::Sphere;
use crate::{Handle, Result};
use keys::KeyBox;
use list::Reach;

/// Where an object is referenced from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place<P> {
    /// From every cell of its key box.
    Cells(P),
    /// From the oversized list, at this position.
    Oversized(u32),
}

/// A stored object: where it is referenced from and its payload (the sphere is
/// in the dense `spheres` array).
#[derive(Clone, Debug)]
struct Item<T, P> {
    place: Place<P>,
    value: T,
}

/// A grid of cells over the store `S`, each cell holding compact references
/// `(slot, key box)` to the objects whose footprint covers it.
///
/// The spheres live in one dense array by slot, so an update that keeps the
/// covered cells writes one sphere and touches no cell. An object covering more
/// than `S::MAX_CELLS_PER_OBJECT` cells is not gridded: it goes to the
/// **oversized list**, which every query tests directly and whose pairs are
/// found by querying the grid with its sphere. Queries prune cells by loose
/// boxes: cells grown by twice the largest gridded radius, within the bounds of
/// everything gridded (both only grow until `clear` or the grid empties).
#[derive(Clone, Debug)]
pub(crate) struct CellGrid<T, S: Store> {
    store: S,
    items: Arena<Item<T, S::Packed>>,
    /// Slot → sphere of the live object there (hot data for pairs and queries).
    /// A reference's handle and payload come from the arena slot itself (one
    /// memory access per hit, not two).
    spheres: Vec<Sphere>,
    /// Slot → collision filter of the live object there (read only for pairs
    /// that overlap and for filtered queries, so the spheres stay dense).
    filters: Vec<Filter>,
    /// Inert objects stored: while there are some, the pair search leaves
    /// them out of each cell's list (see `pairs.rs`).
    inert: InertCount,
    /// Growing bounds on the gridded spheres, for the cells' loose boxes.
    reach: Reach,
    /// Slots of the oversized objects.
    oversized: Vec<u32>,
    /// Total number of references.
    refs: usize,
}

impl<T, S: Store> CellGrid<T, S> {
    /// An empty grid over `store` (which must be empty).
    pub fn new(store: S) -> Self {
        CellGrid {
            store,
            items: Arena::new(),
            spheres: Vec::new(),
            filters: Vec::new(),
            inert: InertCount::default(),
            reach: Reach::default(),
            oversized: Vec::new(),
            refs: 0,
        }
    }

    /// The store (for the front ends' accessors).
    pub fn store(&self) -> &S {
        &self.store
    }

    /// Total number of cell references (an object covering 4 cells counts 4).
    pub fn reference_count(&self) -> usize {
        self.refs
    }

    /// Number of objects in the oversized list.
    pub fn oversized_count(&self) -> usize {
        self.oversized.len()
    }

    /// The key box of a sphere, or `None` if it covers too many cells to be
    /// gridded.
    #[inline]
    fn cells_of(&self, s: &Sphere) -> Option<KeyBox> {
        let kb = self.store.lattice().sphere_box(s, S::AXES);
        (kb.volume() <= S::MAX_CELLS_PER_OBJECT).then_some(kb)
    }

    /// The handle and payload of a referenced slot. References always name live
    /// slots (checked by `validate`), so failure is a bug.
    #[inline]
    fn resolve(&self, slot: u32) -> (Handle, &T) {
        let (h, item) = self
            .items
            .get_by_index(slot)
            .expect("grid reference to a dead slot: invariant broken");
        (h, &item.value)
    }

    /// The handle of a referenced slot.
    #[inline]
    fn handle(&self, slot: u32) -> Handle {
        self.resolve(slot).0
    }

    /// Stores an object with its filter. O(cells covered × references per
    /// cell).
    pub fn insert(&mut self, sphere: Sphere, filter: Filter, value: T) -> Result<Handle> {
        sphere.validate()?;
        self.items.check_room()?;
        let h = self.items.next_handle();
        let slot = h.index();
        let place = self.place(slot, None, &sphere);
        let h2 = self.items.insert(Item { place, value })?;
        debug_assert_eq!(h, h2);
        if self.spheres.len() <= slot as usize {
            self.spheres.resize(slot as usize + 1, sphere);
            self.filters.resize(slot as usize + 1, filter);
        }
        self.spheres[slot as usize] = sphere;
        self.filters[slot as usize] = filter;
        self.inert.add(filter);
        Ok(h)
    }

    /// Removes an object. O(cells covered × references per cell).
    pub fn remove(&mut self, handle: Handle) -> Result<T> {
        let item = self.items.remove(handle)?;
        self.inert.sub(self.filters[handle.index() as usize]);
        self.unplace(handle.index(), item.place);
        if self.items.is_empty() {
            self.reach = Reach::default();
        }
        Ok(item.value)
    }

    /// Moves an object. O(1) while its key box stays the same, else
    /// O(cells covered × references per cell).
    pub fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        let old = self.items.get(handle)?.place;
        let slot = handle.index();
        let place = self.place(slot, Some(old), &sphere);
        // `unplace` may have moved another object's oversized position, never
        // this one's item.
        self.items.get_mut(handle)?.place = place;
        self.spheres[slot as usize] = sphere;
        Ok(())
    }

    /// The sphere and payload of a live handle.
    pub fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        let item = self.items.get(handle)?;
        Ok((self.spheres[handle.index() as usize], &item.value))
    }

    /// The filter of a live handle.
    pub fn filter(&self, handle: Handle) -> Result<Filter> {
        self.items.get(handle)?;
        Ok(self.filters[handle.index() as usize])
    }

    /// Replaces the filter of a live handle. O(1).
    pub fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        self.items.get(handle)?;
        let old = std::mem::replace(&mut self.filters[handle.index() as usize], filter);
        self.inert.change(old, filter);
        Ok(())
    }

    /// The filter of a live slot (callers pass reported handles' slots).
    #[inline]
    pub fn slot_filter(&self, slot: u32) -> Filter {
        self.filters[slot as usize]
    }

    /// The payload of a live handle, mutably.
    pub fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.items.get_mut(handle).map(|i| &mut i.value)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Drops every object; the cells' layout stays.
    pub fn clear(&mut self) {
        self.store.clear();
        self.items.clear();
        self.spheres = Vec::new();
        self.filters = Vec::new();
        self.inert = InertCount::default();
        self.reach = Reach::default();
        self.oversized = Vec::new();
        self.refs = 0;
    }

    /// Calls `f` on every object.
    pub fn for_each(&self, f: &mut dyn FnMut(Handle, &Sphere, &T)) {
        for (h, i) in self.items.iter() {
            f(h, &self.spheres[h.index() as usize], &i.value);
        }
    }

    /// Bytes held, the struct itself included.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.store.heap_bytes()
            + self.items.heap_bytes()
            + self.spheres.capacity() * std::mem::size_of::<Sphere>()
            + self.filters.capacity() * std::mem::size_of::<Filter>()
            + self.oversized.capacity() * 4
    }
}

/// The [`SpatialIndex`](crate::broad::SpatialIndex) and
/// [`Walk`](crate::broad::walk::Walk) impls of a front end `$name<T>` whose
/// field `grid` is a [`CellGrid`]: written once, expanded in each front end.
macro_rules! cell_grid_index {
    ($name:ident, $kind:expr) => {
        impl<T: Send + Sync> $crate::broad::SpatialIndex<T> for $name<T> {
            fn insert_with_filter(
                &mut self,
                sphere: $crate::geom::Sphere,
                filter: $crate::broad::Filter,
                value: T,
            ) -> $crate::Result<$crate::Handle> {
                self.grid.insert(sphere, filter, value)
            }
            fn filter(&self, handle: $crate::Handle) -> $crate::Result<$crate::broad::Filter> {
                self.grid.filter(handle)
            }
            fn set_filter(
                &mut self,
                handle: $crate::Handle,
                filter: $crate::broad::Filter,
            ) -> $crate::Result<()> {
                self.grid.set_filter(handle, filter)
            }
            fn remove(&mut self, handle: $crate::Handle) -> $crate::Result<T> {
                self.grid.remove(handle)
            }
            fn update(
                &mut self,
                handle: $crate::Handle,
                sphere: $crate::geom::Sphere,
            ) -> $crate::Result<()> {
                self.grid.update(handle, sphere)
            }
            fn get(&self, handle: $crate::Handle) -> $crate::Result<($crate::geom::Sphere, &T)> {
                self.grid.get(handle)
            }
            fn get_mut(&mut self, handle: $crate::Handle) -> $crate::Result<&mut T> {
                self.grid.get_mut(handle)
            }
            fn len(&self) -> usize {
                self.grid.len()
            }
            fn clear(&mut self) {
                self.grid.clear()
            }
            fn for_each(&self, f: &mut dyn FnMut($crate::Handle, &$crate::geom::Sphere, &T)) {
                self.grid.for_each(f)
            }
            $crate::broad::walk::walk_methods!(T);
            fn validate(&self) -> $crate::Result<()> {
                self.grid.check(stringify!($name))
            }
            fn memory_bytes(&self) -> usize {
                self.grid.memory_bytes()
            }
            fn kind(&self) -> $crate::broad::IndexKind {
                $kind
            }
        }

        impl<T> $crate::broad::walk::Walk<T> for $name<T> {
            #[inline]
            fn walk<Q: $crate::broad::Selection + ?Sized>(
                &self,
                query: &Q,
                f: impl FnMut(
                    $crate::Handle,
                    &$crate::geom::Sphere,
                    &T,
                ) -> std::ops::ControlFlow<()>,
            ) -> std::ops::ControlFlow<()> {
                self.grid.walk(query, f)
            }
            #[inline]
            fn walk_pairs(
                &self,
                f: impl FnMut($crate::Handle, &T, $crate::Handle, &T) -> std::ops::ControlFlow<()>,
            ) -> std::ops::ControlFlow<()> {
                self.grid.pairs(f)
            }
            #[inline]
            fn filter_of(&self, h: $crate::Handle) -> $crate::broad::Filter {
                self.grid.slot_filter(h.index())
            }
            #[inline]
            fn object_count(&self) -> usize {
                self.grid.len()
            }
            /// The cell walk along the ray, filtered at each candidate.
            #[inline]
            fn first_hit(
                &self,
                ray: &$crate::geom::Ray,
                filter: Option<$crate::broad::Filter>,
            ) -> Option<$crate::broad::RayHit> {
                self.grid.first_hit(ray, filter)
            }
            /// The cell walk along the sweep's segment, widened by its radius;
            /// a scan of the cells of its box when they are few or the sweep's
            /// coordinates are near `f32::MAX` (`sweep_walks`).
            #[inline]
            fn first_sweep_hit(
                &self,
                sweep: &$crate::geom::SphereSweep,
                filter: Option<$crate::broad::Filter>,
            ) -> Option<$crate::broad::RayHit> {
                if self.grid.sweep_walks(sweep) {
                    self.grid.first_hit(sweep, filter)
                } else {
                    $crate::broad::walk::scan_first(self, sweep, filter)
                }
            }
            /// The growing box of cells (`cell_grid/nearest.rs`).
            #[inline]
            fn knn_into(
                &self,
                query: &$crate::broad::Nearest,
                filter: Option<$crate::broad::Filter>,
                out: &mut Vec<$crate::broad::Neighbor>,
            ) {
                if $crate::broad::nearest::may_overflow(query.point, &self.grid.knn_extent()) {
                    return $crate::broad::nearest::expanding(self, query, filter, out);
                }
                self.grid.nearest(query, filter, out)
            }
        }
    };
}
pub(crate) use cell_grid_index;
