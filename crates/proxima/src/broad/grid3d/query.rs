//! Range, frustum and ray queries: visit a set of cells that must hold the centre
//! of every selected gridded object, each cell once (so each object once).

use super::UniformGrid3d;
use crate::arena::Handle;
use crate::broad::Selection;
use crate::geom::{overlap, Aabb, Frustum, Ray, Relation, Sphere};
use std::ops::ControlFlow;

impl<T> UniformGrid3d<T> {
    /// Reports the gridded objects selected by `q` in the cells `[lo, hi]`
    /// (inclusive). Cells holding several objects are first classified by their
    /// loose box: `Outside` skips them, `Inside` reports without exact tests.
    pub(super) fn visit_range<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        lo: [u32; 3],
        hi: [u32; 3],
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                self.visit_row(q, [lo[0], y, z], hi[0], f)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// The cells `start.x ..= x1` of one row.
    fn visit_row<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        start: [u32; 3],
        x1: u32,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let first = self.geom.index(start);
        for (x, c) in (start[0]..=x1).zip(first..) {
            let n = self.store.count(c);
            if n == 0 {
                continue;
            }
            let mut rel = Relation::Intersecting;
            if n > 2 {
                let b = self.geom.loose([x, start[1], start[2]]);
                rel = q.classify_box(&b, Frustum::ALL_PLANES).0;
                if rel == Relation::Outside {
                    continue;
                }
            }
            for part in self.store.parts(c) {
                for &slot in part {
                    let s = &self.spheres[slot as usize];
                    if rel == Relation::Inside || q.selects(s) {
                        let (h, v) = self.resolve(slot);
                        f(h, s, v)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Reports the gridded objects hit by `ray`.
    ///
    /// The ray is clipped to the bounds of every gridded sphere; then, slab by
    /// slab along z and row by row along y, the part of the ray within reach
    /// (largest gridded radius plus a margin) of that slab and row gives the range
    /// of x cells to visit. Every cell whose centre slab the ray passes within
    /// reach of is visited once; cost O(z slabs + rows + cells near the ray).
    pub(super) fn visit_ray(
        &self,
        ray: &Ray,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.extent.min.cmpgt(self.extent.max).any() {
            return ControlFlow::Continue(());
        }
        let g = &self.geom;
        let m = self
            .extent
            .min
            .abs()
            .max(self.extent.max.abs())
            .max_element();
        let ext = self.extent.grown(g.reach(m) - g.limit);
        // The ray's interval within `b`, and the range of its coordinate on axis
        // `a` there, widened by the reach.
        let span = |b: &Aabb, a: usize| -> Option<(f32, f32, Aabb)> {
            let (t0, t1) = overlap::ray_aabb(ray, b)?;
            let p0 = ray.origin[a] as f64 + ray.dir[a] as f64 * t0 as f64;
            let p1 = ray.origin[a] as f64 + ray.dir[a] as f64 * t1 as f64;
            let (lo, hi) = (p0.min(p1) as f32, p0.max(p1) as f32);
            Some((lo - g.reach(lo), hi + g.reach(hi), *b))
        };
        // Restricts `b` on axis `a` to the reach of slab `k`.
        let restrict = |b: &Aabb, a: usize, k: u32| -> Aabb {
            let (lo, hi) = g.slab(k, a);
            let mut r = *b;
            r.min[a] = r.min[a].max(lo - g.reach(lo));
            r.max[a] = r.max[a].min(hi + g.reach(hi));
            r
        };
        let Some((z0, z1, _)) = span(&ext, 2) else {
            return ControlFlow::Continue(());
        };
        for k in g.coord(z0, 2)..=g.coord(z1, 2) {
            let Some((y0, y1, bk)) = span(&restrict(&ext, 2, k), 1) else {
                continue;
            };
            for j in g.coord(y0, 1)..=g.coord(y1, 1) {
                let Some((x0, x1, _)) = span(&restrict(&bk, 1, j), 0) else {
                    continue;
                };
                self.visit_row(ray, [g.coord(x0, 0), j, k], g.coord(x1, 0), f)?;
            }
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::test_util::check_ray;
    use crate::broad::{BruteForce, SpatialIndex, UniformGrid3d};
    use crate::geom::{Aabb, Ray, Sphere};
    use glam::{vec3, Vec3};
    use rand::{Rng, SeedableRng};

    #[test]
    fn rays_and_ranges_match_brute_force() {
        let w = Aabb::new(Vec3::ZERO, Vec3::splat(30.0));
        let mut g = UniformGrid3d::with_cell_size(w, 3.0).unwrap();
        let mut b = BruteForce::new();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for i in 0..400u32 {
            let c = vec3(
                rng.gen_range(-10.0..40.0),
                rng.gen_range(-10.0..40.0),
                rng.gen_range(-10.0..40.0),
            );
            let r = if i % 40 == 0 {
                5.0
            } else {
                rng.gen_range(0.0..1.47)
            };
            g.insert(Sphere::new(c, r), i).unwrap();
            b.insert(Sphere::new(c, r), i).unwrap();
        }
        for _ in 0..300 {
            let o = vec3(
                rng.gen_range(-20.0..50.0),
                rng.gen_range(-20.0..50.0),
                rng.gen_range(-20.0..50.0),
            );
            let mut d = vec3(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            if rng.gen_bool(0.3) {
                d[rng.gen_range(0..3)] = 0.0;
            }
            if d == Vec3::ZERO {
                d = Vec3::X;
            }
            let t = if rng.gen_bool(0.5) {
                f32::INFINITY
            } else {
                rng.gen_range(0.0..60.0)
            };
            check_ray(&g, &b, &Ray::with_max_t(o, d, t));
            let q = Sphere::new(o, rng.gen_range(0.0..8.0));
            let mut hg = g.sphere_hits(&q).unwrap();
            let mut hb: Vec<u32> = b
                .sphere_hits(&q)
                .unwrap()
                .iter()
                .map(|h| *b.get(*h).unwrap().1)
                .collect();
            let mut ig: Vec<u32> = hg.drain(..).map(|h| *g.get(h).unwrap().1).collect();
            ig.sort_unstable();
            hb.sort_unstable();
            assert_eq!(ig, hb);
        }
    }
}
