//! All overlapping pairs: each cell against itself and its 13 forward neighbours,
//! then the large objects.
//!
//! The 13 forward neighbours of cell `(x, y, z)` are cell `x + 1` of its own row
//! and cells `x - 1 ..= x + 1` of four rows: `(y + 1, z)`, `(y - 1, z + 1)`,
//! `(y, z + 1)` and `(y + 1, z + 1)`. With the spheres of a row packed in cell
//! order, each of those is one contiguous run of spheres (the molecular-dynamics
//! "cell list" trick), so an object is compared with five runs of about three
//! spheres, four at a time, instead of with thirteen cells of about one.
//!
//! Inert objects (group or mask zero) are dropped from the gathered rows and
//! large inert objects skipped [sources: index-queries], so they cost the scan
//! one filter read each; the filters of the pairs found are checked per batch.

use super::cells::INLINE;
use super::UniformGrid3d;
use crate::geom::{overlap, Sphere};
use crate::Handle;
use glam::Vec4;
use std::ops::ControlFlow;

/// The four forward rows `(dy, dz)` whose cells `x - 1 ..= x + 1` neighbour cell
/// `x` of the current row (the own row's cell `x + 1` is handled apart).
const FORWARD_ROWS: [(i32, u32); 4] = [(1, 0), (-1, 1), (0, 1), (1, 1)];

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
            if !g.filters[a as usize].interacts(g.filters[b as usize]) {
                continue;
            }
            let (ha, va) = g.resolve(a);
            let (hb, vb) = g.resolve(b);
            f(ha, va, hb, vb)?;
        }
        ControlFlow::Continue(())
    }
}

/// Lane masks by count: the first `min(count, 4)` lanes.
const LANE_MASK: [u32; 5] = [0, 0b1, 0b11, 0b111, 0b1111];

/// Padding after a row's spheres, so that four lanes can always be loaded from
/// any position of the row (the lanes past its end are masked off).
const PAD: usize = 4;

/// The spheres of one row of cells (fixed y and z), packed in cell order as
/// structure of arrays: the spheres of cell `x` are positions `off[x] ..
/// off[x + 1]`.
#[derive(Default)]
struct Row {
    off: Vec<u32>,
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    r: Vec<f32>,
    slot: Vec<u32>,
    /// Cell x of each sphere.
    cx: Vec<u32>,
}

impl Row {
    /// Number of spheres (without the padding).
    #[inline]
    fn len(&self) -> usize {
        self.slot.len()
    }

    /// Sphere at position `k`.
    #[inline]
    fn sphere(&self, k: usize) -> Sphere {
        Sphere::new(glam::vec3(self.x[k], self.y[k], self.z[k]), self.r[k])
    }

    /// Removes the inert objects ([`Filter::is_inert`](crate::broad::Filter::is_inert))
    /// from the row's slots and cells, before their spheres are gathered: they
    /// interact with nothing, so the scan never meets them. Branch-free, one
    /// filter read per object of the row.
    fn drop_inert<T>(&mut self, g: &UniformGrid3d<T>) {
        let mut k = 0;
        for x in 0..self.off.len() - 1 {
            let (s, e) = (self.off[x] as usize, self.off[x + 1] as usize);
            self.off[x] = k as u32;
            for p in s..e {
                let slot = self.slot[p];
                self.slot[k] = slot;
                self.cx[k] = x as u32;
                k += !g.filters[slot as usize].is_inert() as usize;
            }
        }
        *self.off.last_mut().expect("a row has cells") = k as u32;
        self.slot.truncate(k);
        self.cx.truncate(k);
    }

    /// The candidates among positions `j .. j + 4` for sphere `a`, as bits
    /// (lanes past the row's end may be set: the caller masks them).
    #[inline(always)]
    fn candidates4(&self, a: &Sphere, j: usize) -> u32 {
        let v = |s: &[f32]| Vec4::from_slice(&s[j..j + 4]);
        overlap::sphere_sphere_candidates4(v(&self.x), v(&self.y), v(&self.z), v(&self.r), a)
    }
}

/// The rows just ahead of the pair scan, gathered into [`Row`]s.
///
/// Every forward neighbour of a cell of row `w` lies in rows `w ..= w + ny + 1`,
/// so a ring of `ny + 2` rows holds every sphere the scan compares in row `w`.
/// Each row is gathered once, a loop of independent reads of the slot-ordered
/// sphere array (so the processor overlaps the cache misses); the tests then
/// stream through the packed rows. The ring holds about one xy layer of
/// spheres (a few tens of KB for W1 at 100k) plus `nx + 1` offsets per row, so
/// it stays in the L1/L2 caches; it is allocated per pair search.
struct Ring {
    rows: Vec<Row>,
    /// Next row to gather.
    next: u32,
}

impl Ring {
    fn new<T>(g: &UniformGrid3d<T>, w0: u32) -> Ring {
        let [nx, ny, _] = g.geom.dims.map(|d| d as usize);
        // Room for twice an average row up front: growing ny + 2 rows of seven
        // vectors a step at a time costs thousands of reallocations per search
        // in a wide flat world (W2).
        let gridded = g.items.len() - g.large.len();
        let per_row = 2 * gridded / g.row_count() as usize + INLINE + PAD;
        let row = || Row {
            off: Vec::with_capacity(nx + 1),
            x: Vec::with_capacity(per_row),
            y: Vec::with_capacity(per_row),
            z: Vec::with_capacity(per_row),
            r: Vec::with_capacity(per_row),
            slot: Vec::with_capacity(per_row),
            cx: Vec::with_capacity(per_row),
        };
        Ring {
            rows: (0..ny + 2).map(|_| row()).collect(),
            next: w0,
        }
    }

    /// Makes sure rows up to `last` are gathered.
    fn advance<T>(&mut self, g: &UniformGrid3d<T>, last: u32) {
        let nx = g.geom.dims[0];
        while self.next <= last {
            let w = self.next;
            let k = w as usize % self.rows.len();
            let row = &mut self.rows[k];
            // First the slots in cell order: each cell's inline slots copied
            // whole, whatever its count (the surplus is overwritten by the next
            // cell), so that the loop does not branch on the counts...
            let c0 = (w * nx) as usize;
            let cells = &g.store.cells[c0..c0 + nx as usize];
            let total: usize = cells.iter().map(|c| c.count as usize).sum();
            row.off.clear();
            row.slot.clear();
            row.slot.resize(total + INLINE, 0);
            row.cx.clear();
            row.cx.resize(total + INLINE, 0);
            let mut p = 0;
            for (x, cell) in cells.iter().enumerate() {
                let n = cell.count;
                row.off.push(p as u32);
                row.slot[p..p + INLINE].copy_from_slice(&cell.slots);
                row.cx[p..p + INLINE].fill(x as u32);
                if n as usize > INLINE {
                    // A spilled cell (rare in even scenes): the rest of it.
                    let more = g.store.parts((c0 + x) as u32)[1];
                    let end = p + INLINE + more.len();
                    row.slot[p + INLINE..end].copy_from_slice(more);
                    row.cx[p + INLINE..end].fill(x as u32);
                }
                p += n as usize;
            }
            row.off.push(p as u32);
            row.slot.truncate(total);
            row.cx.truncate(total);
            if g.inert.any() {
                row.drop_inert(g);
            }
            // ... then a tight loop of independent reads of their spheres, so
            // that many cache misses are in flight at once.
            let n = row.slot.len() + PAD;
            for v in [&mut row.x, &mut row.y, &mut row.z, &mut row.r] {
                v.clear();
                v.resize(n, 0.0);
            }
            let lanes = row
                .x
                .iter_mut()
                .zip(&mut row.y)
                .zip(&mut row.z)
                .zip(&mut row.r);
            for (&slot, (((x, y), z), r)) in row.slot.iter().zip(lanes) {
                let s = &g.spheres[slot as usize];
                (*x, *y, *z, *r) = (s.center.x, s.center.y, s.center.z, s.radius);
            }
            self.next += 1;
        }
    }

    /// The gathered row `w`.
    #[inline]
    fn row(&self, w: u32) -> &Row {
        &self.rows[w as usize % self.rows.len()]
    }
}

impl<T> UniformGrid3d<T> {
    /// Number of rows of cells (`ny · nz`): the units [`Self::pair_rows`]
    /// splits on.
    pub(super) fn row_count(&self) -> u32 {
        self.geom.dims[1] * self.geom.dims[2]
    }

    /// Calls `f` once per overlapping pair of gridded objects whose first object
    /// (in the half-shell order) lies in a row of cells `[w0, w1)` (row `w` =
    /// `y + ny·z`).
    ///
    /// Gridded radii are at most `0.49 · cell`, so overlapping centres are less
    /// than a cell apart and lie in the same or adjacent cells (clamping keeps
    /// that true for centres outside the world). Each cell is tested against
    /// itself (pairs `i < j`) and its forward neighbours, so every pair of cells
    /// — and every pair of objects — is met exactly once. Each object is tested
    /// against four spheres at a time with a SIMD prefilter
    /// ([`overlap::sphere_sphere_candidates4`]); what it keeps is decided by
    /// [`overlap::sphere_sphere`]. Cost O(cells in the rows and one layer beyond
    /// + Σ k·k'), streaming through the cell arrays in memory order.
    pub(super) fn pair_rows(
        &self,
        w0: u32,
        w1: u32,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let w1 = w1.min(self.row_count());
        if w0 >= w1 {
            return ControlFlow::Continue(());
        }
        let [nx, ny, nz] = self.geom.dims;
        let last_row = self.row_count() - 1;
        let mut ring = Ring::new(self, w0);
        let mut batch = Batch::new();
        for w in w0..w1 {
            let (y, z) = (w % ny, w / ny);
            ring.advance(self, (w + ny + 1).min(last_row));
            let own = ring.row(w);
            if own.len() == 0 {
                continue;
            }
            // The own row, then the forward rows inside the grid.
            let mut rows: [&Row; 5] = [own; 5];
            let mut nr = 1;
            for (dy, dz) in FORWARD_ROWS {
                let yy = y as i32 + dy;
                if yy >= 0 && (yy as u32) < ny && z + dz < nz {
                    rows[nr] = ring.row(yy as u32 + ny * (z + dz));
                    nr += 1;
                }
            }
            let nx = nx as usize;
            for i in 0..own.len() {
                let a = own.sphere(i);
                let sa = own.slot[i];
                let x = own.cx[i] as usize;
                let (lo, hi) = (x.saturating_sub(1), (x + 2).min(nx));
                // The runs: the later spheres of this cell and all of cell
                // x + 1, then cells x - 1 ..= x + 1 of each forward row. Their
                // first four lanes are tested whatever the run's length (short
                // and random: branching on it would mispredict); the rest of a
                // longer run after.
                for (ri, row) in rows[..nr].iter().enumerate() {
                    let s = if ri == 0 { i + 1 } else { row.off[lo] as usize };
                    let e = row.off[hi] as usize;
                    let bits = row.candidates4(&a, s) & LANE_MASK[(e - s).min(4)];
                    if bits != 0 {
                        self.report(sa, &a, row, s, bits, &mut batch, f)?;
                    }
                    if e - s > 4 {
                        self.run(sa, &a, row, s + 4, e, &mut batch, f)?;
                    }
                }
            }
        }
        batch.flush(self, f)
    }

    /// Tests object `sa` (sphere `a`) against positions `lo .. hi` of `row`.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        sa: u32,
        a: &Sphere,
        row: &Row,
        lo: usize,
        hi: usize,
        batch: &mut Batch,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let mut j = lo;
        while j < hi {
            let bits = row.candidates4(a, j) & LANE_MASK[(hi - j).min(4)];
            self.report(sa, a, row, j, bits, batch, f)?;
            j += 4;
        }
        ControlFlow::Continue(())
    }

    /// Decides exactly the lanes `bits` of positions `j .. j + 4` of `row` that
    /// the prefilter kept, and reports the overlapping ones.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn report(
        &self,
        sa: u32,
        a: &Sphere,
        row: &Row,
        j: usize,
        mut bits: u32,
        batch: &mut Batch,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        while bits != 0 {
            let k = j + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if overlap::sphere_sphere(a, &row.sphere(k)) {
                batch.push(self, sa, row.slot[k], f)?;
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
        let fa = self.filters[self.large[i] as usize];
        if fa.is_inert() {
            return ControlFlow::Continue(());
        }
        let (ha, va) = self.resolve(self.large[i]);
        let sa = &self.spheres[self.large[i] as usize];
        for &b in &self.large[i + 1..] {
            if fa.interacts(self.filters[b as usize])
                && overlap::sphere_sphere(sa, &self.spheres[b as usize])
            {
                let (hb, vb) = self.resolve(b);
                f(ha, va, hb, vb)?;
            }
        }
        let (lo, hi) = self.geom.range(&sa.aabb());
        self.visit_range(sa, lo, hi, &mut |hb, _, vb| {
            if fa.interacts(self.filters[hb.index() as usize]) {
                f(ha, va, hb, vb)
            } else {
                ControlFlow::Continue(())
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::Grid3dConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{BruteForce, SpatialIndex, UniformGrid3d};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    #[test]
    fn pairs_match_brute_force_in_a_crowded_scene() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(20.0));
        let mut g = UniformGrid3d::with_config(Grid3dConfig {
            world: w,
            cell_size: 4.0,
        })
        .unwrap();
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
        let ids = |p: Vec<(crate::Handle, crate::Handle)>, i: &dyn Fn(_) -> u32| {
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

#[cfg(test)]
mod row_scan_tests {
    use crate::broad::{BruteForce, Grid3dConfig, SpatialIndex, SpatialIndexExt, UniformGrid3d};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    /// Pairs as sorted payload ids, each pair once (a duplicate would show).
    fn ids<I: SpatialIndex<u32>>(i: &I) -> Vec<(u32, u32)> {
        let mut v: Vec<_> = i
            .pairs()
            .into_iter()
            .map(|(x, y)| {
                let (a, b) = (*i.get(x).unwrap().1, *i.get(y).unwrap().1);
                (a.min(b), a.max(b))
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// The row scan against brute force over many frames of moves, in grids of
    /// every shape the scan special-cases: one cell, one row (ny = nz = 1), one
    /// layer (nz = 1), thin in y, and a cube. Each scene mixes crowded cells
    /// (runs longer than four and eight lanes, spilled cells), centres leaving
    /// the world (clamped to border cells), radii near the gridding limit,
    /// objects growing into and shrinking out of the large list, removals and
    /// re-insertions.
    #[test]
    fn row_scan_matches_brute_force_while_objects_move() {
        let shapes = [
            vec3(3.0, 3.0, 3.0),
            vec3(40.0, 3.0, 3.0),
            vec3(40.0, 40.0, 3.0),
            vec3(30.0, 5.0, 30.0),
            vec3(24.0, 24.0, 24.0),
        ];
        let mut rng = rand_pcg::Pcg64::seed_from_u64(2024);
        for (si, &ext) in shapes.iter().enumerate() {
            let world = Aabb::new(Vec3::ZERO, ext);
            let mut g = UniformGrid3d::with_config(Grid3dConfig {
                world,
                cell_size: 4.0,
            })
            .unwrap();
            let mut b = BruteForce::new();
            let mut live = Vec::new();
            let draw = |rng: &mut rand_pcg::Pcg64, crowd: bool| {
                // Some centres bunched into one corner cell (crowded runs),
                // the rest anywhere in and around the world.
                let c = if crowd {
                    vec3(
                        rng.gen_range(0.0..3.9),
                        rng.gen_range(0.0..3.0f32.min(ext.y)),
                        rng.gen_range(0.0..3.0f32.min(ext.z)),
                    )
                } else {
                    vec3(
                        rng.gen_range(-6.0..ext.x + 6.0),
                        rng.gen_range(-6.0..ext.y + 6.0),
                        rng.gen_range(-6.0..ext.z + 6.0),
                    )
                };
                let r = match rng.gen_range(0..20) {
                    0 => 5.0,
                    1 => 1.96,
                    _ => rng.gen_range(0.1..1.9),
                };
                Sphere::new(c, r)
            };
            for id in 0..400u32 {
                let s = draw(&mut rng, id % 4 == 0);
                live.push((g.insert(s, id).unwrap(), b.insert(s, id).unwrap(), s));
            }
            let mut next = 400u32;
            for frame in 0..12 {
                for entry in live.iter_mut() {
                    let (hg, hb, s) = *entry;
                    let roll = rng.gen_range(0..100);
                    if roll < 3 {
                        // Remove and insert another.
                        assert_eq!(g.remove(hg).unwrap(), b.remove(hb).unwrap());
                        let s = draw(&mut rng, roll == 0);
                        *entry = (g.insert(s, next).unwrap(), b.insert(s, next).unwrap(), s);
                        next += 1;
                        continue;
                    }
                    let step = vec3(
                        rng.gen_range(-1.5..1.5),
                        rng.gen_range(-1.5..1.5),
                        rng.gen_range(-1.5..1.5),
                    );
                    let r = match roll {
                        3 => 6.0,
                        4 => rng.gen_range(0.1..1.96),
                        _ => s.radius,
                    };
                    let s = Sphere::new(s.center + step, r);
                    g.update(hg, s).unwrap();
                    b.update(hb, s).unwrap();
                    entry.2 = s;
                }
                g.validate().unwrap();
                let (pg, pb) = (ids(&g), ids(&b));
                assert!(pg.windows(2).all(|w| w[0] != w[1]), "duplicate pair");
                if pg != pb {
                    let missing: Vec<_> = pb.iter().filter(|p| !pg.contains(p)).take(5).collect();
                    let extra: Vec<_> = pg.iter().filter(|p| !pb.contains(p)).take(5).collect();
                    panic!("shape {si}, frame {frame}: missing {missing:?}, extra {extra:?}");
                }
                assert!(pb.len() > 50, "shape {si}: too few pairs to test");
            }
            assert!(!g.store.spill.is_empty(), "shape {si}: no crowded cell");
        }
    }
}
