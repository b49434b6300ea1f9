//! [`Store`]: how a cell grid addresses and keeps its cells — the one thing in
//! which the 2D grid (a dense array over a rectangle) and the hash grid (blocks
//! of cells in a hash map) differ. Everything else is written once, generic over
//! it, and compiled once per store (no dynamic dispatch in the loops).

use super::keys::{Key, KeyBox, Lattice};
use super::list::{CellEntry, Packed};
use std::fmt::Debug;
use std::ops::ControlFlow;

/// The entries of one cell, as the visits see them.
pub(crate) type Entries<'a, P> = &'a [CellEntry<P>];

/// Cell addressing and storage behind a [`CellGrid`](super::CellGrid).
///
/// The visits report only non-empty cells, each once, with its key; their
/// order is unspecified (the once-only rules do not depend on it).
pub(crate) trait Store: Clone + Debug {
    /// How a reference stores its object's key box.
    type Packed: Packed;
    /// A handle on one of the top-level blocks that a descent starts from.
    type Block: Copy;

    /// The gridded axes are `0..AXES`; the others are flat (one cell).
    const AXES: usize;

    /// Objects whose key box holds more cells go to the oversized list.
    const MAX_CELLS_PER_OBJECT: u64;

    /// True if the occupied cells may be far fewer than the keys of the
    /// occupied box (a hashed store): walks then weigh a scan of the occupied
    /// cells against key lookups.
    const SPARSE: bool;

    /// The lattice the keys are on.
    fn lattice(&self) -> &Lattice;

    /// Adds a reference to the cell `key` (creating the cell if needed).
    fn push(&mut self, key: Key, slot: u32, keys: Self::Packed);

    /// Removes `slot`'s reference from the cell `key` (dropping the cell if it
    /// empties and the store drops cells). False if there was none.
    fn remove(&mut self, key: Key, slot: u32) -> bool;

    /// Sets the key box stored with `slot`'s reference in the cell `key`. False
    /// if there was none.
    fn set(&mut self, key: Key, slot: u32, keys: Self::Packed) -> bool;

    /// A box containing every occupied key (possibly larger).
    fn occupied(&self) -> KeyBox;

    /// Number of cells kept (non-empty ones for a hashed store, all for a
    /// dense one).
    fn cell_count(&self) -> usize;

    /// Visits the non-empty cells with keys in `kb` (which may be huge: a store
    /// never does more than O(its cells) work for it).
    fn cells_in(
        &self,
        kb: &KeyBox,
        f: impl FnMut(Key, Entries<'_, Self::Packed>) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// Visits every non-empty cell.
    fn cells(
        &self,
        f: impl FnMut(Key, Entries<'_, Self::Packed>) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// Cuts `kb` into the store's top-level blocks and calls `f` with each
    /// part that may hold a non-empty cell.
    fn blocks_in(
        &self,
        kb: &KeyBox,
        f: impl FnMut(KeyBox, Self::Block) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// False if no cell of `region` (inside `block`) is occupied; true when
    /// unknown.
    fn any_in(&self, block: Self::Block, region: &KeyBox) -> bool;

    /// [`Store::cells_in`] for a `region` inside `block`.
    fn cells_in_block(
        &self,
        block: Self::Block,
        region: &KeyBox,
        f: impl FnMut(Key, Entries<'_, Self::Packed>) -> ControlFlow<()>,
    ) -> ControlFlow<()>;

    /// Drops every reference (the lattice stays).
    fn clear(&mut self);

    /// Heap bytes held by the cells.
    fn heap_bytes(&self) -> usize;

    /// Checks the store's own bookkeeping (not the references, which the grid
    /// checks through [`Store::cells`]).
    fn check(&self) -> Result<(), String>;
}
