//! Range and frustum queries: visit a rectangle of cells, prune each cell by its
//! loose box, report each object from one cell only.

use super::cells::CellRect;
use super::UniformGrid2d;
use crate::broad::Selection;
use crate::geom::{Frustum, Relation, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

impl<T> UniformGrid2d<T> {
    /// Reports the objects selected by `q` among those referenced from `rect`,
    /// which must cover the XY footprint of every object `q` can select.
    ///
    /// Once-only: an object is reported only from the cell `(max(ox0, rect.x0),
    /// max(oy0, rect.y0))`, the lowest cell of the overlap of its range with
    /// `rect`. That cell is in both ranges, so the object is referenced there and
    /// the scan reaches it exactly once. The test is two comparisons against the
    /// lowest cell stored in the reference, before any geometry.
    ///
    /// Each non-empty cell is first classified against its loose box:
    /// `Outside` skips the cell, `Inside` reports its objects without the exact
    /// test (the selection contract makes both sound).
    pub(super) fn visit_rect<Q: Selection + ?Sized>(
        &self,
        q: &Q,
        rect: CellRect,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for y in rect.y0..=rect.y1 {
            for x in rect.x0..=rect.x1 {
                let cell = &self.cells[self.geom.index(x, y)];
                if cell.entries.is_empty() {
                    continue;
                }
                let (rel, _) = q.classify_box(&self.loose(x, y), Frustum::ALL_PLANES);
                if rel == Relation::Outside {
                    continue;
                }
                for e in &cell.entries {
                    if (e.lo[0] as u32).max(rect.x0) != x || (e.lo[1] as u32).max(rect.y0) != y {
                        continue;
                    }
                    let s = &self.spheres[e.slot as usize];
                    if rel == Relation::Inside || q.selects(s) {
                        let (h, v) = self.resolve(e.slot);
                        f(h, s, v)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::Grid2dConfig;
    use crate::broad::SpatialIndexExt;
    use crate::broad::{SpatialIndex, UniformGrid2d};
    use crate::geom::{Aabb, Sphere};
    use glam::{vec3, Vec3};
    use std::ops::ControlFlow;

    #[test]
    fn an_object_in_many_cells_is_reported_once() {
        let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 10.0));
        let mut g = UniformGrid2d::with_config(Grid2dConfig {
            world: w,
            cell_size: 5.0,
        })
        .unwrap();
        let big = g
            .insert(Sphere::new(vec3(50.0, 50.0, 5.0), 30.0), 0)
            .unwrap();
        let small = g
            .insert(Sphere::new(vec3(52.0, 52.0, 5.0), 1.0), 1)
            .unwrap();
        // An object far outside sits in a border cell and is still found.
        let far = g
            .insert(Sphere::new(vec3(-1e4, 50.0, 5.0), 1.0), 2)
            .unwrap();
        assert!(g.reference_count() > 100);
        for q in [
            Sphere::new(vec3(50.0, 50.0, 5.0), 40.0),
            Sphere::new(vec3(52.0, 52.0, 5.0), 0.5),
            Sphere::new(vec3(20.0, 50.0, 5.0), 3.0),
        ] {
            let mut seen = Vec::new();
            let _ = g.for_each_in(q, |h, _, _| {
                seen.push(h);
                ControlFlow::Continue(())
            });
            let n = seen.len();
            seen.sort();
            seen.dedup();
            assert_eq!(n, seen.len(), "reported twice");
            assert!(seen.contains(&big));
        }
        assert_eq!(g.within(vec3(-1e4, 50.0, 5.0), 0.0).unwrap(), vec![far]);
        // Wrong z: the grid ignores z, the exact test does not.
        assert!(!g
            .within(vec3(52.0, 52.0, 100.0), 1.0)
            .unwrap()
            .contains(&small));
        let b = Aabb::new(vec3(51.0, 51.0, 0.0), vec3(53.0, 53.0, 10.0));
        let mut hits = g.query(b).unwrap();
        hits.sort();
        assert_eq!(hits, {
            let mut v = vec![big, small];
            v.sort();
            v
        });
    }
}
