//! The hash grid's store: blocks of 4 × 4 × 4 cells in a hash map, created when
//! a cell of theirs is first occupied and dropped when the last one empties.
//!
//! Neighbouring cells share a block, so a small query looks up one to a few
//! blocks instead of one hash entry per cell (each a likely cache miss), and a
//! query over many cells (a frustum) classifies whole blocks first and skips
//! the empty cells of a block by its occupancy mask. A block names its cells'
//! reference lists in a pool with a free list (freed lists keep their capacity).

use super::keys::{Key, KeyBox, Lattice};
use super::list::{CellList, Cube};
use super::store::{Entries, Store, Within};
use rustc_hash::FxHashMap;
use std::ops::ControlFlow;

/// log2 of the block edge in cells.
const SHIFT: u32 = 2;

/// Marks a cell of a block with no list.
const NONE: u32 = u32::MAX;

/// The block holding key `k`. Functions rather than a closure in each
/// generic walk: `[T; 3]::map` then compiles once per crate, not once per
/// walk and callback (5.5k copies of it in the world tests' build,
/// `docs/bench/ci-build-e7d3473.txt`).
#[inline]
fn block_of(k: Key) -> Key {
    k.map(|c| c >> SHIFT)
}

/// The first key of block `b` (a function for the same reason).
#[inline]
fn block_base(b: Key) -> Key {
    b.map(|c| c << SHIFT)
}

/// The block holding key `k`, and `k`'s bit in the block's mask (x fastest).
#[inline]
fn split(k: Key) -> (Key, u32) {
    let local = (k[0] & 3) | (k[1] & 3) << 2 | (k[2] & 3) << 4;
    (block_of(k), local as u32)
}

/// The keys of block `b`.
#[inline]
fn block_keys(b: Key) -> KeyBox {
    let lo = block_base(b);
    KeyBox {
        lo,
        hi: lo.map(|c| c + 3),
    }
}

/// The mask bits of the keys `r` inside block `b` (`r` must be inside it).
#[inline]
fn region_mask(b: Key, r: &KeyBox) -> u64 {
    let base = block_base(b);
    let lo = [0, 1, 2].map(|a| (r.lo[a] - base[a]) as u32);
    let hi = [0, 1, 2].map(|a| (r.hi[a] - base[a]) as u32);
    let row = (0xF_u64 >> (3 - (hi[0] - lo[0]))) << lo[0];
    let mut layer = 0u64;
    for y in lo[1]..=hi[1] {
        layer |= row << (4 * y);
    }
    let mut m = 0u64;
    for z in lo[2]..=hi[2] {
        m |= layer << (16 * z);
    }
    m
}

/// 4 × 4 × 4 cells.
#[derive(Clone, Debug)]
struct Block {
    /// The block's key (cell keys shifted right by [`SHIFT`]).
    key: Key,
    /// Bit `x + 4y + 16z` set iff that cell is occupied; 0 for a free block.
    mask: u64,
    /// Pool index of each occupied cell's list ([`NONE`] otherwise).
    lists: [u32; 64],
}

/// Cells in blocks found through an [`FxHashMap`] (the fast non-cryptographic
/// hasher of `rustc-hash`) from block keys.
#[derive(Clone, Debug)]
pub(crate) struct Hashed {
    lattice: Lattice,
    map: FxHashMap<Key, u32>,
    blocks: Vec<Block>,
    free_blocks: Vec<u32>,
    lists: Vec<CellList<Cube>>,
    free_lists: Vec<u32>,
    /// Number of occupied cells.
    cells: usize,
    /// Contains every occupied key (may be larger; recomputed when stale).
    occupied: KeyBox,
    /// Cells freed since `occupied` was last recomputed.
    stale: usize,
}

impl Hashed {
    /// No cells, on `lattice`.
    pub fn new(lattice: Lattice) -> Hashed {
        Hashed {
            lattice,
            map: FxHashMap::default(),
            blocks: Vec::new(),
            free_blocks: Vec::new(),
            lists: Vec::new(),
            free_lists: Vec::new(),
            cells: 0,
            occupied: KeyBox::EMPTY,
            stale: 0,
        }
    }

    /// Number of blocks holding an occupied cell.
    #[inline]
    fn live_blocks(&self) -> usize {
        self.map.len()
    }

    /// The pool index of the list of cell `k`, if occupied.
    #[inline]
    fn list_of(&self, k: Key) -> Option<u32> {
        let (b, bit) = split(k);
        let &bi = self.map.get(&b)?;
        let i = self.blocks[bi as usize].lists[bit as usize];
        (i != NONE).then_some(i)
    }

    /// Visits the occupied cells of block `bi` whose bits are in `bits`.
    #[inline]
    fn visit_bits(
        &self,
        bi: u32,
        bits: u64,
        f: &mut impl FnMut(Key, Entries<'_, Cube>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let block = &self.blocks[bi as usize];
        let base = block_base(block.key);
        let mut bits = bits & block.mask;
        while bits != 0 {
            let l = bits.trailing_zeros() as i32;
            bits &= bits - 1;
            let key = [
                base[0] | (l & 3),
                base[1] | (l >> 2 & 3),
                base[2] | (l >> 4),
            ];
            let list = &self.lists[block.lists[l as usize] as usize];
            f(key, &list.entries)?;
        }
        ControlFlow::Continue(())
    }

    /// Calls `f` with every live block meeting `kb` and the part of `kb` inside
    /// it: by looking the blocks of `kb` up when they are no more than the live
    /// blocks, else by scanning the live blocks.
    #[inline]
    fn each_block(
        &self,
        kb: &KeyBox,
        mut f: impl FnMut(KeyBox, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let kb = kb.intersect(&self.occupied);
        if kb.is_empty() {
            return ControlFlow::Continue(());
        }
        let bk = KeyBox {
            lo: block_of(kb.lo),
            hi: block_of(kb.hi),
        };
        if bk.volume() <= self.live_blocks() as u64 {
            for z in bk.lo[2]..=bk.hi[2] {
                for y in bk.lo[1]..=bk.hi[1] {
                    for x in bk.lo[0]..=bk.hi[0] {
                        if let Some(&bi) = self.map.get(&[x, y, z]) {
                            f(block_keys([x, y, z]).intersect(&kb), bi)?;
                        }
                    }
                }
            }
        } else {
            for (bi, block) in self.blocks.iter().enumerate() {
                if block.mask != 0 {
                    let part = block_keys(block.key).intersect(&kb);
                    if !part.is_empty() {
                        f(part, bi as u32)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Recomputes the occupied box from the blocks' masks.
    fn recompute_occupied(&mut self) {
        let mut b = KeyBox::EMPTY;
        for block in &self.blocks {
            let base = block_base(block.key);
            let mut bits = block.mask;
            while bits != 0 {
                let l = bits.trailing_zeros() as i32;
                bits &= bits - 1;
                b.include([
                    base[0] | (l & 3),
                    base[1] | (l >> 2 & 3),
                    base[2] | (l >> 4),
                ]);
            }
        }
        self.occupied = b;
        self.stale = 0;
    }
}

impl Store for Hashed {
    type Packed = Cube;
    type Block = u32;
    const AXES: usize = 3;
    /// 4 × 4 × 4 cells: 8 times the volume of the 2 × 2 × 2 cells a typical
    /// object covers.
    const MAX_CELLS_PER_OBJECT: u64 = 64;
    const SPARSE: bool = true;

    #[inline]
    fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    fn push(&mut self, key: Key, slot: u32, keys: Cube) {
        let (b, bit) = split(key);
        let bi = match self.map.get(&b) {
            Some(&bi) => bi,
            None => {
                let bi = match self.free_blocks.pop() {
                    Some(bi) => {
                        self.blocks[bi as usize].key = b;
                        bi
                    }
                    None => {
                        self.blocks.push(Block {
                            key: b,
                            mask: 0,
                            lists: [NONE; 64],
                        });
                        self.blocks.len() as u32 - 1
                    }
                };
                self.map.insert(b, bi);
                bi
            }
        };
        let mut li = self.blocks[bi as usize].lists[bit as usize];
        if li == NONE {
            li = match self.free_lists.pop() {
                Some(li) => li,
                None => {
                    self.lists.push(CellList::default());
                    self.lists.len() as u32 - 1
                }
            };
            let block = &mut self.blocks[bi as usize];
            block.lists[bit as usize] = li;
            block.mask |= 1 << bit;
            self.cells += 1;
            self.occupied.include(key);
        }
        self.lists[li as usize].push(slot, keys);
    }

    fn remove(&mut self, key: Key, slot: u32) -> bool {
        let (b, bit) = split(key);
        let Some(&bi) = self.map.get(&b) else {
            return false;
        };
        let li = self.blocks[bi as usize].lists[bit as usize];
        if li == NONE || !self.lists[li as usize].remove(slot) {
            return false;
        }
        if self.lists[li as usize].entries.is_empty() {
            self.free_lists.push(li);
            let block = &mut self.blocks[bi as usize];
            block.lists[bit as usize] = NONE;
            block.mask &= !(1 << bit);
            if block.mask == 0 {
                self.map.remove(&b);
                self.free_blocks.push(bi);
            }
            self.cells -= 1;
            self.stale += 1;
            // Recompute the occupied box once as many cells were freed as are
            // left: amortized O(1) per freed cell.
            if self.stale > self.cells {
                self.recompute_occupied();
            }
        }
        true
    }

    #[inline]
    fn set(&mut self, key: Key, slot: u32, keys: Cube) -> bool {
        match self.list_of(key) {
            Some(li) => self.lists[li as usize].set(slot, keys),
            None => false,
        }
    }

    #[inline]
    fn occupied(&self) -> KeyBox {
        self.occupied
    }

    #[inline]
    fn cell_count(&self) -> usize {
        self.cells
    }

    #[inline]
    fn cells_in(
        &self,
        kb: &KeyBox,
        mut f: impl FnMut(Key, Entries<'_, Cube>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.each_block(kb, |part, bi| {
            let b = self.blocks[bi as usize].key;
            self.visit_bits(bi, region_mask(b, &part), &mut f)
        })
    }

    #[inline]
    fn cells(
        &self,
        mut f: impl FnMut(Key, Entries<'_, Cube>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for bi in 0..self.blocks.len() as u32 {
            self.visit_bits(bi, u64::MAX, &mut f)?;
        }
        ControlFlow::Continue(())
    }

    #[inline]
    fn blocks_in(
        &self,
        kb: &KeyBox,
        f: impl FnMut(KeyBox, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.each_block(kb, f)
    }

    #[inline]
    fn within(&self, region: &KeyBox) -> Within<u32> {
        let (lo, hi) = (block_of(region.lo), block_of(region.hi));
        if lo != hi {
            return Within::Many;
        }
        match self.map.get(&lo) {
            Some(&bi) => Within::One(bi),
            None => Within::Empty,
        }
    }

    #[inline]
    fn split(&self, region: &KeyBox) -> (KeyBox, KeyBox) {
        let (lo, hi) = (block_of(region.lo), block_of(region.hi));
        let a = (0..3).max_by_key(|&a| hi[a] - lo[a]).unwrap_or(0);
        // The first block of the upper half; `< 2^28` in magnitude, so the
        // shift stays within the keys' range.
        let first = (lo[a] + hi[a]).div_euclid(2) + 1;
        let (mut low, mut high) = (*region, *region);
        low.hi[a] = (first << SHIFT) - 1;
        high.lo[a] = first << SHIFT;
        (low, high)
    }

    /// At most 8 blocks of the key box per occupied block: the descent then
    /// classifies O(occupied blocks) parts.
    #[inline]
    fn descent_is_bounded(&self, kb: &KeyBox) -> bool {
        let blocks = KeyBox {
            lo: block_of(kb.lo),
            hi: block_of(kb.hi),
        };
        blocks.volume() <= 8 * self.live_blocks() as u64 + 8
    }

    #[inline]
    fn any_in(&self, bi: u32, region: &KeyBox) -> bool {
        let block = &self.blocks[bi as usize];
        block.mask & region_mask(block.key, region) != 0
    }

    #[inline]
    fn cells_in_block(
        &self,
        bi: u32,
        region: &KeyBox,
        mut f: impl FnMut(Key, Entries<'_, Cube>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let b = self.blocks[bi as usize].key;
        self.visit_bits(bi, region_mask(b, region), &mut f)
    }

    fn clear(&mut self) {
        *self = Hashed::new(self.lattice);
    }

    fn heap_bytes(&self) -> usize {
        // hashbrown: one (key, value) slot and one control byte per bucket, with
        // buckets ≈ capacity · 8/7.
        let bucket = std::mem::size_of::<(Key, u32)>() + 1;
        self.map.capacity() * 8 / 7 * bucket
            + self.blocks.capacity() * std::mem::size_of::<Block>()
            + self.free_blocks.capacity() * 4
            + self.lists.capacity() * std::mem::size_of::<CellList<Cube>>()
            + self.lists.iter().map(|c| c.heap_bytes()).sum::<usize>()
            + self.free_lists.capacity() * 4
    }

    /// The map and the blocks agree (each mapped block holds its key and is not
    /// empty; each unmapped one is empty and free exactly once); every list is
    /// named by exactly one occupied cell or free exactly once, and only free
    /// lists are empty; the cell count and the occupied box are right.
    fn check(&self) -> Result<(), String> {
        let mut block_free = vec![false; self.blocks.len()];
        for &b in &self.free_blocks {
            match block_free.get_mut(b as usize) {
                Some(f) if !*f => *f = true,
                _ => return Err(format!("bad or repeated free block {b}")),
            }
        }
        for (key, &b) in &self.map {
            let Some(block) = self.blocks.get(b as usize) else {
                return Err(format!("block key {key:?} maps to missing block {b}"));
            };
            if block.key != *key || block.mask == 0 || block_free[b as usize] {
                return Err(format!(
                    "block key {key:?} maps to a wrong, empty or free block"
                ));
            }
        }
        if self.map.len() + self.free_blocks.len() != self.blocks.len() {
            return Err(format!(
                "{} mapped + {} free blocks != {}",
                self.map.len(),
                self.free_blocks.len(),
                self.blocks.len()
            ));
        }
        let mut list_used = vec![false; self.lists.len()];
        for &l in &self.free_lists {
            match list_used.get_mut(l as usize) {
                Some(u) if !*u && self.lists[l as usize].entries.is_empty() => *u = true,
                _ => return Err(format!("bad, repeated or non-empty free list {l}")),
            }
        }
        let mut cells = 0usize;
        for (b, block) in self.blocks.iter().enumerate() {
            for bit in 0..64 {
                let li = block.lists[bit];
                let occupied = block.mask >> bit & 1 == 1;
                if occupied != (li != NONE) {
                    return Err(format!("block {b}: mask and lists disagree at {bit}"));
                }
                if !occupied {
                    continue;
                }
                match list_used.get_mut(li as usize) {
                    Some(u) if !*u && !self.lists[li as usize].entries.is_empty() => *u = true,
                    _ => return Err(format!("block {b}: bad, shared or empty list {li}")),
                }
                let base = block_base(block.key);
                let l = bit as i32;
                let key = [
                    base[0] | (l & 3),
                    base[1] | (l >> 2 & 3),
                    base[2] | (l >> 4),
                ];
                if !self.occupied.contains(key) {
                    return Err(format!("occupied box misses key {key:?}"));
                }
                cells += 1;
            }
        }
        if list_used.iter().any(|u| !u) {
            return Err("a list is neither used nor free".into());
        }
        if cells != self.cells {
            return Err(format!("{cells} occupied cells, counted {}", self.cells));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_split_into_blocks_and_bits() {
        assert_eq!(split([0, 0, 0]), ([0, 0, 0], 0));
        assert_eq!(split([5, -1, -4]), ([1, -1, -1], 1 | 3 << 2));
        let lim = 1 << 30;
        let (b, bit) = split([-lim, lim, 3]);
        assert_eq!(b, [-(1 << 28), 1 << 28, 0]);
        assert!(block_keys(b).contains([-lim, lim, 3]));
        assert_eq!(bit, 3 << 4);
        // Every key of a block maps back to it, each to its own bit.
        let bk = block_keys([-1, 2, 0]);
        let mut seen = 0u64;
        bk.for_each(|k| {
            let (b, bit) = split(k);
            assert_eq!(b, [-1, 2, 0]);
            assert_eq!(seen >> bit & 1, 0);
            seen |= 1 << bit;
        });
        assert_eq!(seen, u64::MAX);
        assert_eq!(region_mask([-1, 2, 0], &bk), u64::MAX);
        // A sub-box's mask has exactly its keys' bits.
        let r = KeyBox {
            lo: [-3, 9, 1],
            hi: [-2, 10, 3],
        };
        let mut want = 0u64;
        r.for_each(|k| want |= 1 << split(k).1);
        assert_eq!(region_mask([-1, 2, 0], &r), want);
        assert_eq!(want.count_ones(), 12);
    }
}
