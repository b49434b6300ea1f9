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

impl<T> UniformGrid3d<T> {
    /// Calls `f` once per overlapping pair of gridded objects whose first object
    /// (in the half-shell order) lies in a cell of `[c0, c1)`.
    ///
    /// Gridded radii are at most `0.49 · cell`, so overlapping centres are less
    /// than a cell apart and lie in the same or adjacent cells (clamping keeps
    /// that true for centres outside the world). Each cell is tested against
    /// itself (pairs `i < j`) and its forward neighbours, so every pair of cells
    /// — and every pair of objects — is met exactly once. Cost O(cells in range
    /// + Σ k·k'), streaming through the cell arrays in memory order.
    pub(super) fn visit_pairs(
        &self,
        c0: u32,
        c1: u32,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let [nx, ny, nz] = self.geom.dims;
        let counts = &self.store.counts;
        let mut report = |a: u32, b: u32| {
            let (ha, va) = self.resolve(a);
            let (hb, vb) = self.resolve(b);
            f(ha, va, hb, vb)
        };
        let [mut x, mut y, mut z] = self.geom.coords(c0);
        for c in c0..c1 {
            if counts[c as usize] != 0 {
                self.cell_self_pairs(c, &mut report)?;
                for d in HALF_SHELL {
                    let (qx, qy, qz) = (x as i32 + d[0], y as i32 + d[1], z as i32 + d[2]);
                    if qx < 0 || qx >= nx as i32 || qy < 0 || qy >= ny as i32 || qz >= nz as i32 {
                        continue;
                    }
                    let n = (qz as u32 * ny + qy as u32) * nx + qx as u32;
                    if counts[n as usize] != 0 {
                        self.cell_cross_pairs(c, n, &mut report)?;
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
        ControlFlow::Continue(())
    }

    /// Pairs within cell `c`.
    #[inline]
    fn cell_self_pairs(
        &self,
        c: u32,
        report: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let n = self.store.counts[c as usize] as usize;
        if n < 2 {
            return ControlFlow::Continue(());
        }
        if n <= INLINE {
            let sl = &self.store.slots[c as usize][..n];
            let sp = &self.store.spheres[c as usize][..n];
            for i in 0..n {
                for j in i + 1..n {
                    if overlap::sphere_sphere(&sp[i], &sp[j]) {
                        report(sl[i], sl[j])?;
                    }
                }
            }
            return ControlFlow::Continue(());
        }
        // A spilled cell: gather its entries first (rare in even scenes).
        let mut all: Vec<(u32, Sphere)> = Vec::with_capacity(n);
        for (sl, sp) in self.store.parts(c) {
            all.extend(sl.iter().copied().zip(sp.iter().copied()));
        }
        for i in 0..n {
            for j in i + 1..n {
                if overlap::sphere_sphere(&all[i].1, &all[j].1) {
                    report(all[i].0, all[j].0)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Pairs between cells `a` and `b` (both non-empty).
    #[inline]
    fn cell_cross_pairs(
        &self,
        a: u32,
        b: u32,
        report: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (na, nb) = (
            self.store.counts[a as usize] as usize,
            self.store.counts[b as usize] as usize,
        );
        if na <= INLINE && nb <= INLINE {
            let (sla, spa) = (
                &self.store.slots[a as usize][..na],
                &self.store.spheres[a as usize][..na],
            );
            let (slb, spb) = (
                &self.store.slots[b as usize][..nb],
                &self.store.spheres[b as usize][..nb],
            );
            for i in 0..na {
                for j in 0..nb {
                    if overlap::sphere_sphere(&spa[i], &spb[j]) {
                        report(sla[i], slb[j])?;
                    }
                }
            }
            return ControlFlow::Continue(());
        }
        for (sla, spa) in self.store.parts(a) {
            for (slb, spb) in self.store.parts(b) {
                for i in 0..sla.len() {
                    for j in 0..slb.len() {
                        if overlap::sphere_sphere(&spa[i], &spb[j]) {
                            report(sla[i], slb[j])?;
                        }
                    }
                }
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
        let sa = &self.large_spheres[i];
        for (&b, sb) in self.large[i + 1..].iter().zip(&self.large_spheres[i + 1..]) {
            if overlap::sphere_sphere(sa, sb) {
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
