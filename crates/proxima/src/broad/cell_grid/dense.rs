//! The 2D grid's store: one cell per key of a rectangle, row-major in a `Vec`.

use super::keys::{Key, KeyBox, Lattice};
use super::list::{CellList, Rect};
use super::store::{Entries, Store};
use std::ops::ControlFlow;

/// A dense array of cells over the keys `lattice.limits` (z flat).
#[derive(Clone, Debug)]
pub(crate) struct Dense {
    lattice: Lattice,
    /// Cells along x.
    nx: usize,
    cells: Vec<CellList<Rect>>,
}

impl Dense {
    /// Empty cells over `lattice`, whose limits must start at `[0, 0, 0]`, be
    /// flat in z and fit `u16` keys.
    pub fn new(lattice: Lattice) -> Dense {
        let [nx, ny, _] = lattice.limits.hi.map(|h| h as usize + 1);
        debug_assert!(lattice.limits.lo == [0; 3] && lattice.limits.hi[2] == 0);
        Dense {
            lattice,
            nx,
            cells: vec![CellList::default(); nx * ny],
        }
    }

    /// Index of the cell `k` in the row-major array.
    #[inline]
    fn index(&self, k: Key) -> usize {
        k[1] as usize * self.nx + k[0] as usize
    }
}

impl Store for Dense {
    type Packed = Rect;
    type Block = ();
    const AXES: usize = 2;
    /// A footprint of 32 × 32 cells: 16 times the diameter the default cell
    /// size is chosen for.
    const MAX_CELLS_PER_OBJECT: u64 = 1024;
    const SPARSE: bool = false;

    #[inline]
    fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    #[inline]
    fn push(&mut self, key: Key, slot: u32, keys: Rect) {
        let i = self.index(key);
        self.cells[i].push(slot, keys);
    }

    #[inline]
    fn remove(&mut self, key: Key, slot: u32) -> bool {
        let i = self.index(key);
        self.cells[i].remove(slot)
    }

    #[inline]
    fn set(&mut self, key: Key, slot: u32, keys: Rect) -> bool {
        let i = self.index(key);
        self.cells[i].set(slot, keys)
    }

    #[inline]
    fn occupied(&self) -> KeyBox {
        self.lattice.limits
    }

    #[inline]
    fn cell_count(&self) -> usize {
        self.cells.len()
    }

    #[inline]
    fn cells_in(
        &self,
        kb: &KeyBox,
        mut f: impl FnMut(Key, Entries<'_, Rect>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let kb = kb.intersect(&self.lattice.limits);
        if kb.is_empty() {
            return ControlFlow::Continue(());
        }
        for y in kb.lo[1]..=kb.hi[1] {
            let first = self.index([kb.lo[0], y, 0]);
            let row = &self.cells[first..=first + (kb.hi[0] - kb.lo[0]) as usize];
            for (x, cell) in (kb.lo[0]..).zip(row) {
                if !cell.entries.is_empty() {
                    f([x, y, 0], &cell.entries)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    #[inline]
    fn cells(
        &self,
        mut f: impl FnMut(Key, Entries<'_, Rect>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (i, cell) in self.cells.iter().enumerate() {
            if !cell.entries.is_empty() {
                f(
                    [(i % self.nx) as i32, (i / self.nx) as i32, 0],
                    &cell.entries,
                )?;
            }
        }
        ControlFlow::Continue(())
    }

    #[inline]
    fn blocks_in(
        &self,
        kb: &KeyBox,
        mut f: impl FnMut(KeyBox, ()) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let kb = kb.intersect(&self.lattice.limits);
        if kb.is_empty() {
            return ControlFlow::Continue(());
        }
        f(kb, ())
    }

    #[inline]
    fn any_in(&self, _: (), region: &KeyBox) -> bool {
        // No occupancy summary: only a single cell is known empty.
        region.lo != region.hi || !self.cells[self.index(region.lo)].entries.is_empty()
    }

    #[inline]
    fn cells_in_block(
        &self,
        _: (),
        region: &KeyBox,
        f: impl FnMut(Key, Entries<'_, Rect>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.cells_in(region, f)
    }

    fn clear(&mut self) {
        for c in &mut self.cells {
            *c = CellList::default();
        }
    }

    fn heap_bytes(&self) -> usize {
        self.cells.capacity() * std::mem::size_of::<CellList<Rect>>()
            + self.cells.iter().map(|c| c.heap_bytes()).sum::<usize>()
    }

    fn check(&self) -> Result<(), String> {
        let want = self.lattice.limits.volume() as usize;
        if self.cells.len() != want {
            return Err(format!("{} cells, expected {want}", self.cells.len()));
        }
        Ok(())
    }
}
