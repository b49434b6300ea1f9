//! All overlapping pairs: each cell against itself and its 13 forward neighbours,
//! then the large objects.

use super::cells::INLINE;
use super::UniformGrid3d;
use crate::arena::Handle;
use crate::geom::{overlap, Sphere};
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

/// A cell's gathered spheres, structure of arrays: rows x, y, z, radius, one
/// lane per entry (lanes past the cell's count are stale).
type Lanes = [[f32; INLINE]; 4];

/// The spheres of the cells just ahead of the pair scan, copied into cell order.
///
/// Every forward neighbour of cell `c` lies in `c ..= c + look` (`look = nx·ny +
/// nx + 1`), so a ring of the next `look + 1` cells (rounded up to a power of
/// two) holds every sphere the scan compares at `c`. Each cell's spheres are
/// gathered once, by independent reads of the slot-ordered array that the
/// processor overlaps; the tests then read the ring contiguously. The ring is 64
/// bytes per cell of an xy layer: a few hundred KB for W1 at 100k (L2-resident).
struct Window {
    mask: usize,
    look: u32,
    next: u32,
    lanes: Vec<Lanes>,
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
        }
    }

    /// Makes sure the cells up to `c + look` are gathered, gathering
    /// [`GATHER_AHEAD`] more at a time: a tight loop of independent loads keeps
    /// many cache misses in flight, where one gather between tests keeps few.
    #[inline]
    fn advance<T>(&mut self, g: &UniformGrid3d<T>, c: u32) {
        if self.next > c + self.look {
            return;
        }
        let end = (c + self.look + GATHER_AHEAD).min(g.geom.cell_count() as u32 - 1);
        while self.next <= end {
            let k = self.next as usize;
            let n = (g.store.counts[k] as usize).min(INLINE);
            let dst = &mut self.lanes[k & self.mask];
            for (i, &slot) in g.store.slots[k][..n].iter().enumerate() {
                let s = &g.spheres[slot as usize];
                dst[0][i] = s.center.x;
                dst[1][i] = s.center.y;
                dst[2][i] = s.center.z;
                dst[3][i] = s.radius;
            }
            self.next += 1;
        }
    }

    /// The gathered lanes of cell `c`.
    #[inline]
    fn cell(&self, c: u32) -> &Lanes {
        &self.lanes[c as usize & self.mask]
    }
}

/// Sphere of lane `i`.
#[inline]
fn lane(l: &Lanes, i: usize) -> Sphere {
    Sphere::new(glam::vec3(l[0][i], l[1][i], l[2][i]), l[3][i])
}

/// The spheres of a cell's forward neighbours, appended lane-wise
/// (structure of arrays) so that one object is tested against all of them four
/// at a time. Always `len + 8` lanes long, so a 4-lane read from any lane below
/// `len` stays in bounds (the lanes past `len` are stale and masked off).
struct Candidates {
    lanes: [Vec<f32>; 4],
    slots: Vec<u32>,
    len: usize,
}

impl Candidates {
    fn new() -> Candidates {
        let n = 13 * INLINE + 8;
        Candidates {
            lanes: [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            slots: vec![0; n],
            len: 0,
        }
    }

    #[inline]
    fn reserve(&mut self, extra: usize) {
        let want = self.len + extra + 8;
        if want > self.slots.len() {
            for l in &mut self.lanes {
                l.resize(want, 0.0);
            }
            self.slots.resize(want, 0);
        }
    }

    /// Appends the first `n` of a cell's inline lanes (copying all four keeps
    /// it branch-free).
    #[inline]
    fn push_lanes(&mut self, l: &Lanes, slots: &[u32; INLINE], n: usize) {
        let at = self.len;
        for (dst, src) in self.lanes.iter_mut().zip(l) {
            dst[at..at + INLINE].copy_from_slice(src);
        }
        self.slots[at..at + INLINE].copy_from_slice(slots);
        self.len += n;
    }

    /// Appends one sphere.
    fn push(&mut self, slot: u32, s: &Sphere) {
        self.reserve(1);
        let at = self.len;
        for (a, v) in [s.center.x, s.center.y, s.center.z, s.radius].into_iter().enumerate() {
            self.lanes[a][at] = v;
        }
        self.slots[at] = slot;
        self.len += 1;
    }

    /// Reports every candidate overlapping `a` (slot `sa`).
    #[inline]
    fn test<T>(
        &self,
        g: &UniformGrid3d<T>,
        sa: u32,
        a: &Sphere,
        batch: &mut Batch,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let [xs, ys, zs, rs] = &self.lanes;
        let mut i = 0;
        while i < self.len {
            let four = |v: &Vec<f32>| -> [f32; 4] { v[i..i + 4].try_into().expect("4 lanes") };
            let valid = if self.len - i >= 4 {
                0b1111
            } else {
                (1u32 << (self.len - i)) - 1
            };
            let mut bits =
                overlap::sphere_sphere_maybe4(a, &four(xs), &four(ys), &four(zs), &four(rs))
                    & valid;
            while bits != 0 {
                let j = i + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let b = Sphere::new(glam::vec3(xs[j], ys[j], zs[j]), rs[j]);
                if overlap::sphere_sphere(a, &b) {
                    batch.push(g, sa, self.slots[j], f)?;
                }
            }
            i += 4;
        }
        ControlFlow::Continue(())
    }
}

impl<T> UniformGrid3d<T> {
    /// Calls `f` once per overlapping pair of gridded objects whose first object
    /// (in the half-shell order) lies in a cell of `[c0, c1)`.
    ///
    /// Gridded radii are at most `0.49 · cell`, so overlapping centres are less
    /// than a cell apart and lie in the same or adjacent cells (clamping keeps
    /// that true for centres outside the world). Each cell is tested against
    /// itself (pairs `i < j`) and its forward neighbours, so every pair of cells
    /// — and every pair of objects — is met exactly once. The neighbours'
    /// spheres are collected lane-wise and each object of the cell is tested
    /// against them four at a time with a branch-free prefilter
    /// ([`overlap::sphere_sphere_maybe4`]); what it keeps is decided by
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
        let mut cand = Candidates::new();
        let mut batch = Batch::new();
        let mut own: Vec<(u32, Sphere)> = Vec::new();
        let [mut x, mut y, mut z] = self.geom.coords(c0);
        for c in c0..c1 {
            let n = counts[c as usize] as usize;
            if n != 0 {
                win.advance(self, c);
                // This cell's objects.
                own.clear();
                let l = win.cell(c);
                let slots = &self.store.slots[c as usize];
                for i in 0..n.min(INLINE) {
                    own.push((slots[i], lane(l, i)));
                }
                if n > INLINE {
                    for &s in self.store.parts(c)[1] {
                        own.push((s, self.spheres[s as usize]));
                    }
                }
                for i in 0..n {
                    for j in i + 1..n {
                        if overlap::sphere_sphere(&own[i].1, &own[j].1) {
                            batch.push(self, own[i].0, own[j].0, f)?;
                        }
                    }
                }
                // The forward neighbours' objects.
                cand.len = 0;
                let interior = x >= 1 && x + 1 < nx && y + 1 < ny && y >= 1 && z + 1 < nz;
                for (d, off) in HALF_SHELL.iter().zip(offsets) {
                    if !interior {
                        let (qx, qy, qz) = (x as i32 + d[0], y as i32 + d[1], z as i32 + d[2]);
                        if qx < 0
                            || qx >= nx as i32
                            || qy < 0
                            || qy >= ny as i32
                            || qz >= nz as i32
                        {
                            continue;
                        }
                    }
                    let q = (c as i32 + off) as u32;
                    let m = counts[q as usize] as usize;
                    cand.reserve(INLINE);
                    cand.push_lanes(win.cell(q), &self.store.slots[q as usize], m.min(INLINE));
                    if m > INLINE {
                        for &s in self.store.parts(q)[1] {
                            cand.push(s, &self.spheres[s as usize]);
                        }
                    }
                }
                for (sa, a) in &own {
                    cand.test(self, *sa, a, &mut batch, f)?;
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
