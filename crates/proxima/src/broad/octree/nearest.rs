//! k nearest neighbours [sources: index-queries]: a depth-first branch and
//! bound over the loose boxes, nearer octant first, with the bounded heap of
//! `broad/nearest.rs`.

use super::node::NONE;
use super::query::child_coords;
use super::LinearOctree;
use crate::broad::nearest::{KBest, Nearest, Neighbor};
use crate::broad::Filter;
use crate::geom::overlap;

impl<T> LinearOctree<T> {
    /// The `k` nearest into `out`, nearest first, ties by handle.
    ///
    /// A subtree is entered only if the distance from the point to its loose
    /// box ([`overlap::point_aabb_distance`], correctly rounded) is at most the
    /// heap's bound: the loose box contains every sphere below it (`validate`
    /// checks it) and both distances are correctly rounded, hence monotone, so
    /// a pruned subtree holds nothing that could have entered and the answer
    /// is brute force's, bit for bit. Octants are searched nearest first (at
    /// most 8 sorted on the stack per level). The filter is checked at each
    /// candidate that could enter. No allocation once `out` holds `k` entries.
    pub(super) fn nearest_tree(
        &self,
        q: &Nearest,
        filter: Option<Filter>,
        out: &mut Vec<Neighbor>,
    ) {
        let mut best = KBest::new(out, q.k, q.max_distance);
        if self.objects.is_empty() || q.k == 0 {
            return;
        }
        let n = &self.nodes[self.root];
        let d0 = overlap::point_aabb_distance(q.point, &self.loose_of([0; 3], 0, n.max_extent));
        self.nearest_node(self.root, [0; 3], 0, d0, q, filter, &mut best);
        best.finish();
    }

    #[allow(clippy::too_many_arguments)]
    fn nearest_node(
        &self,
        i: u32,
        c: [u32; 3],
        d: u32,
        dist: f32,
        q: &Nearest,
        filter: Option<Filter>,
        best: &mut KBest<'_>,
    ) {
        if dist > best.bound() {
            return;
        }
        let n = &self.nodes[i];
        if filter.is_some_and(|f| !f.may_interact(n.groups, n.masks)) {
            return;
        }
        if n.leaf {
            for it in &n.items {
                let distance = q.metric.distance(q.point, &it.sphere);
                if distance <= best.bound()
                    && filter.map_or(true, |f| f.interacts(self.obj(it.handle).filter))
                {
                    best.offer(Neighbor {
                        handle: it.handle,
                        distance,
                    });
                }
            }
            return;
        }
        let mut order = [(0.0f32, 0u32, [0u32; 3]); 8];
        let mut m = 0;
        for (k, &ch) in n.children.iter().enumerate() {
            if ch == NONE {
                continue;
            }
            let cc = child_coords(c, k);
            let loose = self.loose_of(cc, d + 1, self.nodes[ch].max_extent);
            let dc = overlap::point_aabb_distance(q.point, &loose);
            if dc <= best.bound() {
                order[m] = (dc, ch, cc);
                m += 1;
            }
        }
        order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for &(dc, ch, cc) in &order[..m] {
            self.nearest_node(ch, cc, d + 1, dc, q, filter, best);
        }
    }
}
