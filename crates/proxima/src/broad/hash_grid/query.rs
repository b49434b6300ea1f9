//! Range and frustum queries over the occupied cells.

use super::keys::{Key, KeyBox};
use super::HashGrid;
use crate::broad::cell_list::CellList;
use crate::broad::Selection;
use crate::geom::{Frustum, Relation, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

impl<T> HashGrid<T> {
    /// Reports the gridded objects selected by `q` among those referenced from the
    /// cells of `kb`, which must cover the key box of every object `q` selects.
    ///
    /// `kb` is first clipped to the occupied box. If it still holds no more keys
    /// than there are occupied cells, each key is looked up; otherwise the occupied
    /// cells are scanned and those outside `kb` skipped. Either way the cost is at
    /// most O(occupied cells), whatever the query's extent.
    ///
    /// Once-only: an object is reported only from the cell `max(lo, kb.lo)` (per
    /// axis), the lowest cell of the overlap of its key box with `kb`; clipping to
    /// the occupied box does not change it, since every key of an object is
    /// occupied.
    pub(super) fn visit_cells<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: KeyBox,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let kb = kb.intersect(&self.occupied);
        if kb.is_empty() {
            return ControlFlow::Continue(());
        }
        if kb.volume() <= self.map.len() as u64 {
            let mut flow = ControlFlow::Continue(());
            kb.for_each(|key| {
                if flow.is_continue() {
                    if let Some(&c) = self.map.get(&key) {
                        flow = self.scan_cell(q, &kb, key, &self.cells[c as usize].list, f);
                    }
                }
            });
            flow
        } else {
            for cell in &self.cells {
                if !cell.list.entries.is_empty() && kb.contains(cell.key) {
                    self.scan_cell(q, &kb, cell.key, &cell.list, f)?;
                }
            }
            ControlFlow::Continue(())
        }
    }

    /// One cell of a query: prune by the loose box, then report the
    /// references whose lowest shared cell with `kb` is this one.
    #[inline]
    fn scan_cell<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        kb: &KeyBox,
        key: Key,
        list: &CellList<Key>,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (rel, _) = q.classify_box(&self.loose(key), Frustum::ALL_PLANES);
        if rel == Relation::Outside {
            return ControlFlow::Continue(());
        }
        for e in &list.entries {
            if (0..3).any(|a| e.lo[a].max(kb.lo[a]) != key[a]) {
                continue;
            }
            let s = &self.spheres[e.slot as usize];
            if rel == Relation::Inside || q.selects(s) {
                let (h, v) = self.resolve(e.slot);
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::HashGridConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{BruteForce, HashGrid, SpatialIndex};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use std::ops::ControlFlow;

    /// Sorted payloads of the objects `q` selects (duplicates kept).
    fn values(i: &impl SpatialIndex<u32>, q: &Sphere) -> Vec<u32> {
        let mut v = Vec::new();
        let _ = i.for_each_in(*q, |_, _, x| {
            v.push(*x);
            ControlFlow::Continue(())
        });
        v.sort_unstable();
        v
    }

    #[test]
    fn huge_and_unbounded_queries_are_exact_and_once() {
        let mut g = HashGrid::with_config(HashGridConfig { cell_size: 2.0 }).unwrap();
        let mut b = BruteForce::new();
        let mut k = 0;
        for i in 0..20 {
            for j in 0..20 {
                let s = Sphere::new(
                    vec3(i as f32 * 3.0, j as f32 * 2.5, (i * j % 7) as f32),
                    1.5,
                );
                g.insert(s, k).unwrap();
                b.insert(s, k).unwrap();
                k += 1;
            }
        }
        for s in [
            Sphere::new(vec3(1e4, -1e4, 3e4), 1.0),
            Sphere::new(vec3(-3e38, 0.0, 0.0), 1.0),
            Sphere::new(Vec3::splat(20.0), 500.0), // oversized
        ] {
            g.insert(s, k).unwrap();
            b.insert(s, k).unwrap();
            k += 1;
        }
        g.validate().unwrap();
        for q in [
            Sphere::new(Vec3::ZERO, 1e6),
            Sphere::new(Vec3::ZERO, 3e38),
            Sphere::new(vec3(30.0, 25.0, 3.0), 4.0),
            Sphere::new(vec3(1e4, -1e4, 3e4), 0.0),
        ] {
            let got = values(&g, &q);
            let mut d = got.clone();
            d.dedup();
            assert_eq!(got.len(), d.len(), "reported twice");
            assert_eq!(got, values(&b, &q), "{q:?}");
        }
        let bx = Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38));
        assert_eq!(g.query(bx).unwrap().len(), b.len());
    }
}
