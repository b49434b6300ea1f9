//! k nearest neighbours [sources: index-queries]: the growing box of cells of
//! `broad/nearest.rs` ([`grow_box`]) over the dense cells, and the large list
//! scanned.
//!
//! Each gridded object is in one cell (its centre's), so a slab's objects are
//! simply those of its cells. **Face bounds:** a centre in a cell beyond the
//! line `k` lies beyond it less the rounding margin, so its sphere lies beyond
//! it less the reach (largest gridded radius plus margin), and inside the
//! union box of the gridded spheres: its distance is at least the point's
//! distance to that part of the union box. Rows of a slab whose spheres are
//! all farther than the candidate set's bound are skipped whole.

use super::UniformGrid3d;
use crate::broad::cell_grid::keys::KeyBox;
use crate::broad::nearest::{grow_box, KBest, Nearest, Neighbor};
use crate::broad::Filter;
use crate::geom::overlap;
use std::ops::ControlFlow;

impl<T> UniformGrid3d<T> {
    /// The `k` nearest among the objects `filter` admits into `out`, nearest
    /// first, ties by handle (see the module docs). Cost: the large list, plus
    /// the cells of the smallest box around the point's cell that holds the
    /// answer, plus the distances of their objects; no allocation once `out`
    /// holds `k` entries.
    pub(super) fn nearest_impl(
        &self,
        q: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) {
        let mut best = KBest::new(out, q.k, q.max_distance);
        if q.k == 0 || self.items.is_empty() {
            return;
        }
        let offer = |best: &mut KBest<'_>, slot: u32| {
            let s = &self.spheres[slot as usize];
            let Some(distance) = q.metric.distance_within(q.point, s, best) else {
                return;
            };
            if filter.is_none_or(|f| f.interacts(self.filters[slot as usize])) {
                best.offer(Neighbor {
                    handle: self.resolve(slot).0,
                    distance,
                });
            }
        };
        for &slot in &self.large {
            offer(&mut best, slot);
        }
        let ext = self.extent;
        if !ext.min.cmpgt(ext.max).any() {
            let g = &self.geom;
            let (lo, hi) = g.range(&ext);
            let cells = KeyBox {
                lo: lo.map(|k| k as i32),
                hi: hi.map(|k| k as i32),
            };
            let p = q.point;
            let start = KeyBox::single([0, 1, 2].map(|a| g.coord(p[a], a) as i32));
            let start =
                KeyBox::single([0, 1, 2].map(|a| start.lo[a].clamp(lo[a] as i32, hi[a] as i32)));
            // The union box grown by the margin: the spheres' boxes were
            // rounded to nearest.
            let m = ext.min.abs().max(ext.max.abs()).max_element();
            let ext = ext.grown(g.margin(m));
            let face = |a: usize, upper: bool, k: i32| {
                let mut h = ext;
                if upper {
                    let v = g.slab(k as u32, a).0;
                    h.min[a] = h.min[a].max(v - g.reach(v));
                } else {
                    let v = g.slab(k as u32, a).1;
                    h.max[a] = h.max[a].min(v + g.reach(v));
                }
                if h.min[a] > h.max[a] {
                    f64::INFINITY
                } else {
                    overlap::point_aabb_distance_sq(p, &h)
                }
            };
            grow_box(&mut best, start, cells, 3, face, |best, slab, _| {
                for z in slab.lo[2]..=slab.hi[2] {
                    for y in slab.lo[1]..=slab.hi[1] {
                        let (x0, x1) = (slab.lo[0] as u32, slab.hi[0] as u32);
                        let (y, z) = (y as u32, z as u32);
                        if x1 > x0 {
                            let row = g.loose_block([x0, y, z], [x1, y, z]);
                            let d2 = overlap::point_aabb_distance_sq(p, &row);
                            if best.exceeds_sq(d2) {
                                continue;
                            }
                        }
                        let first = g.index([x0, y, z]);
                        for c in first..=first + (x1 - x0) {
                            for part in self.store.parts(c) {
                                for &slot in part {
                                    offer(best, slot);
                                }
                            }
                        }
                    }
                }
                ControlFlow::Continue(())
            });
        }
        best.finish();
    }
}
