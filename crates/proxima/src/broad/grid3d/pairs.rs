//! All overlapping pairs: each cell against itself and its 13 forward neighbours,
//! then the large objects.

use super::cells::INLINE;
use super::UniformGrid3d;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
use glam::Vec4;
use std::ops::ControlFlow;

/// The forward half of the 26 neighbours: `(dx, dy, dz)` greater than zero in
/// z-then-y-then-x order, so every pair of adjacent cells is visited once.
const HALF_SHELL: [[i32; 3]; 13] = [
    [1, 0, 0],
    [-1, 1, 0],
    [0, 1, 0],
    [1, 1, 0],
    [-1, -1, 1],
    [0, -1, 1],
    [1, -1, 1],
    [-1, 0, 1],
    [0, 0, 1],
    [1, 0, 1],
    [-1, 1, 1],
    [0, 1, 1],
    [1, 1, 1],
];

/// Candidate pairs resolved to handles and payloads per batch: resolving reads
/// the arena at random, and a tight loop of independent reads lets the processor
/// overlap the cache misses that one read per test would serialize.
const BATCH: usize = 64;

/// Overlapping pairs found but not yet reported, as slots.
struct Batch {
    pairs: [(u32, u32); BATCH],
    len: usize,
}

impl Batch {
    fn new() -> Batch {
        Batch {
            pairs: [(0, 0); BATCH],
            len: 0,
        }
    }

    /// Adds a pair, reporting the batch when full.
    #[inline]
    fn push<T>(
        &mut self,
        g: &UniformGrid3d<T>,
        a: u32,
        b: u32,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.pairs[self.len] = (a, b);
        self.len += 1;
        if self.len == BATCH {
            self.flush(g, f)
        } else {
            ControlFlow::Continue(())
        }
    }

    /// Reports every pair held.
    fn flush<T>(
        &mut self,
        g: &UniformGrid3d<T>,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let n = std::mem::replace(&mut self.len, 0);
        for &(a, b) in &self.pairs[..n] {
            let (ha, va) = g.resolve(a);
            let (hb, vb) = g.resolve(b);
            f(ha, va, hb, vb)?;
        }
        ControlFlow::Continue(())
    }
}

/// Cells gathered at a time beyond the look-ahead.
const GATHER_AHEAD: u32 = 256;

/// A cell's gathered spheres as four SIMD rows: x, y, z, radius, one lane per
/// entry (lanes past the cell's count are stale and masked off).
type Lanes = [[f32; INLINE]; 4];

/// Lane masks by count: the first `min(count, 4)` lanes.
const LANE_MASK: [u32; INLINE + 1] = [0, 0b1, 0b11, 0b111, 0b1111];

/// The spheres of the cells just ahead of the pair scan, copied into cell order.
///
/// Every forward neighbour of cell `c` lies in `c ..= c + look` (`look = nx·ny +
/// nx + 1`), so a ring of the next `look + 1` cells (plus a gathering step,
/// rounded up to a power of two) holds every sphere the scan compares at `c`.
/// Each cell's spheres are gathered once, in batches of independent reads of
/// the slot-ordered array (so the processor overlaps the cache misses); the
/// tests then read the ring. The ring is 64 bytes per cell of an xy layer: a
/// few hundred KB for W1 at 100k, so it stays in the L2 cache.
struct Window {
    mask: usize,
    look: u32,
    next: u32,
    lanes: Vec<Lanes>,
    /// (slot, cell · INLINE + lane) of the spheres to gather next.
    todo: Vec<(u32, u32)>,
}

impl Window {
    fn new<T>(g: &UniformGrid3d<T>, c0: u32) -> Window {
        let [nx, ny, _] = g.geom.dims;
        let cells = g.geom.cell_count() as u32;
        let look = (nx * ny + nx + 1).min(cells - 1);
        let size = (look as usize + 1 + GATHER_AHEAD as usize).next_power_of_two();
        Window {
            mask: size - 1,
            look,
            next: c0,
            lanes: vec![[[0.0; INLINE]; 4]; size],
            todo: Vec::with_capacity(GATHER_AHEAD as usize * INLINE),
        }
    }

    /// Makes sure the cells up to `c + look` are gathered, gathering
    /// [`GATHER_AHEAD`] more at a time.
    #[inline]
    fn advance<T>(&mut self, g: &UniformGrid3d<T>, c: u32) {
        if self.next > c + self.look {
            return;
        }
        let end = (c + self.look + GATHER_AHEAD).min(g.geom.cell_count() as u32 - 1);
        // First the (slot, lane) list, then the loads: a branch-free loop of
        // independent loads.
        self.todo.clear();
        for k in self.next..=end {
            let n = (g.store.counts[k as usize] as usize).min(INLINE);
            let base = (k as usize & self.mask) * INLINE;
            for (i, &slot) in g.store.slots[k as usize][..n].iter().enumerate() {
                self.todo.push((slot, (base + i) as u32));
            }
        }
        for &(slot, at) in &self.todo {
            let s = &g.spheres[slot as usize];
            let (cell, i) = (at as usize / INLINE, at as usize % INLINE);
            let dst = &mut self.lanes[cell];
            dst[0][i] = s.center.x;
            dst[1][i] = s.center.y;
            dst[2][i] = s.center.z;
            dst[3][i] = s.radius;
        }
        self.next = end + 1;
    }

    /// The gathered lanes of cell `c`.
    #[inline]
    fn cell(&self, c: u32) -> &Lanes {
        &self.lanes[c as usize & self.mask]
    }
}

/// The prefilter of `a` against a cell's four lanes (plain arrays, so that the
/// gather stores by lane without a dynamic `Vec4` index).
#[inline(always)]
fn maybe4(a: &Sphere, l: &Lanes) -> u32 {
    let [x, y, z, r] = l.map(Vec4::from_array);
    overlap::sphere_sphere_candidates4(x, y, z, r, a)
}

/// Sphere of lane `i`.
#[inline]
fn lane(l: &Lanes, i: usize) -> Sphere {
    Sphere::new(glam::vec3(l[0][i], l[1][i], l[2][i]), l[3][i])
}

impl<T> UniformGrid3d<T> {
    /// Calls `f` once per overlapping pair of gridded objects whose first object
    /// (in the half-shell order) lies in a cell of `[c0, c1)`.
    ///
    /// Gridded radii are at most `0.49 · cell`, so overlapping centres are less
    /// than a cell apart and lie in the same or adjacent cells (clamping keeps
    /// that true for centres outside the world). Each cell is tested against
    /// itself (pairs `i < j`) and its forward neighbours, so every pair of cells
    /// — and every pair of objects — is met exactly once. Each object is tested
    /// against a whole neighbour cell at once with a SIMD prefilter
    /// ([`overlap::sphere_sphere_candidates4`]); what it keeps is decided by
    /// [`overlap::sphere_sphere`]. Cost O(cells in range + look-ahead + Σ k·k'),
    /// streaming through the cell arrays in memory order.
    pub(super) fn visit_pairs(
        &self,
        c0: u32,
        c1: u32,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if c0 >= c1 {
            return ControlFlow::Continue(());
        }
        let [nx, ny, nz] = self.geom.dims;
        let counts = &self.store.counts;
        let offsets = HALF_SHELL.map(|d| d[0] + nx as i32 * (d[1] + ny as i32 * d[2]));
        let mut win = Window::new(self, c0);
        let mut batch = Batch::new();
        let mut own: Vec<(u32, Sphere)> = Vec::new();
        let mut nbrs = [(0u32, 0u32); 13];
        let [mut x, mut y, mut z] = self.geom.coords(c0);
        for c in c0..c1 {
            let n = counts[c as usize] as usize;
            if n != 0 {
                win.advance(self, c);
                // The non-empty forward neighbours inside the grid, compacted
                // without branches (a third of the cells are empty in W1, at
                // random: branching on it would mispredict).
                let mut k = 0;
                if x >= 1 && x + 1 < nx && y >= 1 && y + 1 < ny && z + 1 < nz {
                    for off in offsets {
                        let q = (c as i32 + off) as u32;
                        let m = counts[q as usize];
                        nbrs[k] = (q, m);
                        k += (m != 0) as usize;
                    }
                } else {
                    for (d, off) in HALF_SHELL.iter().zip(offsets) {
                        let (qx, qy, qz) = (x as i32 + d[0], y as i32 + d[1], z as i32 + d[2]);
                        let inside = qx >= 0
                            && qx < nx as i32
                            && qy >= 0
                            && qy < ny as i32
                            && qz < nz as i32;
                        let q = if inside { (c as i32 + off) as u32 } else { c };
                        let m = counts[q as usize];
                        nbrs[k] = (q, m);
                        k += (inside && m != 0) as usize;
                    }
                }
                let l = win.cell(c);
                let slots = &self.store.slots[c as usize];
                if n <= INLINE {
                    for i in 0..n {
                        let a = lane(l, i);
                        // Later lanes of this cell, then the neighbours.
                        let later = LANE_MASK[n] & !LANE_MASK[i + 1];
                        let bits = maybe4(&a, l) & later;
                        self.report_lanes(slots[i], &a, bits, l, slots, &mut batch, f)?;
                        self.against(slots[i], &a, &nbrs[..k], &win, &mut batch, f)?;
                    }
                } else {
                    // A spilled cell (rare in even scenes): all of its entries.
                    own.clear();
                    own.extend(slots.iter().enumerate().map(|(i, &s)| (s, lane(l, i))));
                    for &s in self.store.parts(c)[1] {
                        own.push((s, self.spheres[s as usize]));
                    }
                    for i in 0..n {
                        for j in i + 1..n {
                            if overlap::sphere_sphere(&own[i].1, &own[j].1) {
                                batch.push(self, own[i].0, own[j].0, f)?;
                            }
                        }
                        self.against(own[i].0, &own[i].1, &nbrs[..k], &win, &mut batch, f)?;
                    }
                }
            }
            x += 1;
            if x == nx {
                x = 0;
                y += 1;
                if y == ny {
                    y = 0;
                    z += 1;
                }
            }
        }
        batch.flush(self, f)
    }

    /// Tests object `sa` (sphere `a`) against every entry of the cells `nbrs`.
    #[inline(always)]
    fn against(
        &self,
        sa: u32,
        a: &Sphere,
        nbrs: &[(u32, u32)],
        win: &Window,
        batch: &mut Batch,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for &(q, m) in nbrs {
            let m = m as usize;
            let l = win.cell(q);
            let bits = maybe4(a, l) & LANE_MASK[m.min(INLINE)];
            if bits != 0 {
                self.report_lanes(sa, a, bits, l, &self.store.slots[q as usize], batch, f)?;
            }
            if m > INLINE {
                for &s in self.store.parts(q)[1] {
                    if overlap::sphere_sphere(a, &self.spheres[s as usize]) {
                        batch.push(self, sa, s, f)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Decides the lanes `bits` kept by the prefilter exactly and reports the
    /// overlapping ones.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn report_lanes(
        &self,
        sa: u32,
        a: &Sphere,
        mut bits: u32,
        l: &Lanes,
        slots: &[u32; INLINE],
        batch: &mut Batch,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        while bits != 0 {
            let j = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if overlap::sphere_sphere(a, &lane(l, j)) {
                batch.push(self, sa, slots[j], f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Pairs of large object `i`: with the large objects after it, then with every
    /// gridded object (a grid query with its sphere). Cost O(large + query).
    pub(super) fn large_pairs(
        &self,
        i: usize,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (ha, va) = self.resolve(self.large[i]);
        let sa = &self.spheres[self.large[i] as usize];
        for &b in &self.large[i + 1..] {
            if overlap::sphere_sphere(sa, &self.spheres[b as usize]) {
                let (hb, vb) = self.resolve(b);
                f(ha, va, hb, vb)?;
            }
        }
        let (lo, hi) = self.geom.range(&sa.aabb());
        self.visit_range(sa, lo, hi, &mut |hb, _, vb| f(ha, va, hb, vb))
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::{BruteForce, SpatialIndex, UniformGrid3d};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    #[test]
    fn pairs_match_brute_force_in_a_crowded_scene() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(20.0));
        let mut g = UniformGrid3d::with_cell_size(w, 4.0).unwrap();
        let mut b = BruteForce::new();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        for i in 0..600u32 {
            // Crowded (spilled cells), some outside the world, a few large.
            let c = vec3(
                rng.gen_range(-5.0..25.0),
                rng.gen_range(-5.0..25.0),
                rng.gen_range(-5.0..25.0),
            );
            let r = if i % 50 == 0 {
                6.0
            } else {
                rng.gen_range(0.1..1.96)
            };
            let s = Sphere::new(c, r);
            g.insert(s, i).unwrap();
            b.insert(s, i).unwrap();
        }
        g.validate().unwrap();
        assert!(g.large_count() > 0 && !g.store.spill.is_empty());
        let ids = |p: Vec<(crate::arena::Handle, crate::arena::Handle)>, i: &dyn Fn(_) -> u32| {
            let mut v: Vec<_> = p
                .into_iter()
                .map(|(x, y)| (i(x).min(i(y)), i(x).max(i(y))))
                .collect();
            v.sort_unstable();
            v
        };
        let pg = ids(g.pairs(), &|h| *g.get(h).unwrap().1);
        let pb = ids(b.pairs(), &|h| *b.get(h).unwrap().1);
        assert!(pb.len() > 500);
        assert_eq!(pg, pb);
    }
}
