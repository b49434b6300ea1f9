//! All overlapping pairs: within each occupied cell, then the oversized objects.

use super::keys::KeyBox;
use super::HashGrid;
use crate::broad::walk::Walk;
use crate::geom::{overlap, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// `overlap::sphere_sphere_candidate` on two stored spheres.
#[inline(always)]
fn candidate(a: &Sphere, b: &Sphere) -> bool {
    let (p, q) = (a.center, b.center);
    overlap::sphere_sphere_candidate(p.x, p.y, p.z, a.radius, q.x, q.y, q.z, b.radius)
}

impl<T> HashGrid<T> {
    /// Calls `f` once per overlapping pair.
    ///
    /// Gridded pairs: two overlapping objects share a cell; the pair is reported
    /// only from the lowest cell both cover (`max` of their lowest cells per axis),
    /// checked after the `f32` pre-filter and before the exact test, so that each
    /// pair gets the exact test once however many cells it shares (see
    /// `UniformGrid2d`'s pair search for why this order). Pairs with an oversized object: each
    /// oversized object against the others after it in the list, then a grid query
    /// with its sphere (each gridded object once, by the query's own rule). Cost
    /// O(Σ k² + oversized² + oversized × query).
    pub(super) fn pair_cells(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for cell in &self.cells {
            let es = &cell.list.entries[..];
            if es.len() < 2 {
                continue;
            }
            let key = cell.key;
            for (i, ea) in es.iter().enumerate() {
                let sa = &self.spheres[ea.slot as usize];
                for eb in &es[i + 1..] {
                    let sb = &self.spheres[eb.slot as usize];
                    if candidate(sa, sb)
                        && ea.lo[0].max(eb.lo[0]) == key[0]
                        && ea.lo[1].max(eb.lo[1]) == key[1]
                        && ea.lo[2].max(eb.lo[2]) == key[2]
                        && overlap::sphere_sphere(sa, sb)
                        && self
                            .slot_filter(ea.slot)
                            .interacts(self.slot_filter(eb.slot))
                    {
                        let (ha, va) = self.resolve(ea.slot);
                        let (hb, vb) = self.resolve(eb.slot);
                        f(ha, va, hb, vb)?;
                    }
                }
            }
        }
        for (i, &a) in self.oversized.iter().enumerate() {
            let (ha, va) = self.resolve(a);
            let sa = &self.spheres[a as usize];
            let fa = self.slot_filter(a);
            for &b in &self.oversized[i + 1..] {
                if fa.interacts(self.slot_filter(b))
                    && overlap::sphere_sphere(sa, &self.spheres[b as usize])
                {
                    let (hb, vb) = self.resolve(b);
                    f(ha, va, hb, vb)?;
                }
            }
            let kb: KeyBox = self.keys.sphere_box(sa);
            self.visit_cells(sa, kb, &mut |hb, _, vb| {
                if fa.interacts(self.filter_of(hb)) {
                    f(ha, va, hb, vb)
                } else {
                    ControlFlow::Continue(())
                }
            })?;
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::HashGridConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{HashGrid, SpatialIndex};
    use crate::geom::Sphere;
    use glam::{vec3, Vec3};

    #[test]
    fn pairs_are_reported_once() {
        let mut g = HashGrid::with_config(HashGridConfig { cell_size: 1.0 }).unwrap();
        // Two spheres sharing 3 x 3 x 3 cells (most of their 27 and 64).
        let a = g.insert(Sphere::new(Vec3::splat(5.0), 1.2), 0).unwrap();
        let b = g.insert(Sphere::new(Vec3::splat(5.5), 1.4), 1).unwrap();
        // Oversized, overlapping both and each other.
        let c = g.insert(Sphere::new(Vec3::ZERO, 9.0), 2).unwrap();
        let d = g.insert(Sphere::new(vec3(1.0, 0.0, 0.0), 20.0), 3).unwrap();
        // Far away, alone.
        let e = g.insert(Sphere::new(vec3(1e5, 0.0, 0.0), 0.5), 4).unwrap();
        assert_eq!(g.oversized_count(), 2);
        let mut p = g.pairs();
        p.sort();
        let mut want: Vec<_> = [(a, b), (a, c), (b, c), (a, d), (b, d), (c, d)]
            .into_iter()
            .map(|(x, y)| (x.min(y), x.max(y)))
            .collect();
        want.sort();
        assert_eq!(p, want);
        let _ = e;
    }
}
