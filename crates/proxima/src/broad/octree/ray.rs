//! First hit along a ray: front-to-back traversal of the loose boxes, pruning
//! every subtree the ray enters after the best hit found so far.

use super::node::NONE;
use super::query::child_coords;
use super::LinearOctree;
use crate::broad::{Filter, RayHit};
use crate::geom::{overlap, Ray};

/// A subtree is skipped only when its box entry `t0` exceeds the best hit by more
/// than this relative margin: the box and sphere entry parameters are rounded
/// differently, and a pruned subtree must never hold the true first hit.
const PRUNE_MARGIN: f32 = 1e-4;

impl<T> LinearOctree<T> {
    /// The hit with the smallest `(t, handle)`; children are visited in order of
    /// their loose boxes' entry parameter. No allocation (≤ 8 children sorted on
    /// the stack per level).
    /// Objects whose filter does not interact with `filter` are skipped at
    /// the candidate.
    pub(super) fn ray_first_tree(&self, ray: &Ray, filter: Option<Filter>) -> Option<RayHit> {
        let mut best = None;
        if !self.objects.is_empty() {
            let n = &self.nodes[self.root];
            if let Some((t0, _)) = overlap::ray_aabb(ray, &self.loose_of([0; 3], 0, n.max_extent)) {
                self.ray_node(self.root, [0; 3], 0, t0, ray, filter, &mut best);
            }
        }
        best
    }

    #[allow(clippy::too_many_arguments)]
    fn ray_node(
        &self,
        i: u32,
        c: [u32; 3],
        d: u32,
        t0: f32,
        ray: &Ray,
        filter: Option<Filter>,
        best: &mut Option<RayHit>,
    ) {
        if let Some(b) = best {
            if t0 > b.t + PRUNE_MARGIN * (b.t.abs() + 1.0) {
                return;
            }
        }
        let n = &self.nodes[i];
        if n.leaf {
            for it in &n.items {
                if let Some(t) = overlap::ray_sphere(ray, &it.sphere) {
                    if filter.map_or(true, |f| f.interacts(self.obj(it.handle).filter)) {
                        RayHit::offer(best, t, it.handle);
                    }
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
            if let Some((ct0, _)) = overlap::ray_aabb(ray, &loose) {
                order[m] = (ct0, ch, cc);
                m += 1;
            }
        }
        order[..m].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for &(ct0, ch, cc) in &order[..m] {
            self.ray_node(ch, cc, d + 1, ct0, ray, filter, best);
        }
    }
}
