//! First hit along a ray or a sphere sweep: front-to-back traversal of the
//! loose boxes, pruning every subtree the cast enters after the best hit found
//! so far.

use super::code::MAX_DEPTH;
use super::node::{Item, NONE};
use super::query::child_coords;
use super::LinearOctree;
use crate::broad::walk::{Cast, Contact};
use crate::broad::{Filter, RayHit};
use crate::geom::overlap::EntryBound;
use crate::prefetch::prefetch;

/// A subtree is skipped only when its box entry `t0` exceeds the best hit by more
/// than this relative margin: the box and sphere entry parameters are rounded
/// differently (and the loose box is checked to contain the sphere's rounded
/// box, not the exact ball), and a pruned subtree must never hold the true
/// first hit. The same bound limits the leaf octants scanned.
const PRUNE_MARGIN: f32 = 1e-4;

/// What a box or octant must be entered after to be skipped, given the best
/// hit's time `t` (see [`PRUNE_MARGIN`]).
#[inline(always)]
fn prune_bound(t: f32) -> f32 {
    t + PRUNE_MARGIN * (t.abs() + 1.0)
}

impl<T> LinearOctree<T> {
    /// The contact of a ray or sweep with the smallest `(t, handle)`; the
    /// children a cast enters ([`Cast::entry`] of their cells grown by the
    /// parent's extent: `child_halves`, all 8 from 12 slab parameters,
    /// [`EntryBound::enter_octants`], no child read before it is entered)
    /// are visited front to back in the octant order of the cast's
    /// direction ([`EntryBound::near_octant`]), each skipped if entered after
    /// the best hit so far. A leaf scans only the items of the octants of
    /// its cell that the cast's box up to that bound reaches
    /// ([`EntryBound::reach_octants`], `LinearOctree::octants`); they take
    /// the cast's four-wide pre-test ([`Contact::misses4`]) where it has one
    /// (sweeps), and those it leaves in go straight to the exact test
    /// ([`Contact::contact_after_misses4`]). The object of each better hit
    /// starts loading (`Arena::prefetch`) for the caller's lookup. No
    /// allocation (≤ 8 children listed on the stack per level). Objects
    /// whose filter does not interact with `filter` are skipped at the
    /// candidate.
    pub(super) fn first_tree<C: Cast>(&self, cast: &C, filter: Option<Filter>) -> Option<RayHit> {
        let mut best = None;
        if !self.objects.is_empty() {
            let n = &self.nodes[self.root];
            // The root's loose box holds every stored sphere's box: its
            // magnitude bounds theirs (`Cast::entry`).
            let root = self.loose_of([0; 3], 0, n.max_extent);
            let entry = cast.entry(root.min.abs().max(root.max.abs()).max_element());
            if let Some(t0) = entry.enter(&root) {
                let test = cast.test();
                self.first_node(
                    self.root, [0; 3], 0, t0 as f64, &test, &entry, filter, &mut best,
                );
            }
        }
        best
    }

    #[allow(clippy::too_many_arguments)]
    fn first_node<X: Contact>(
        &self,
        i: u32,
        c: [u32; 3],
        d: u32,
        t0: f64,
        test: &X,
        entry: &EntryBound,
        filter: Option<Filter>,
        best: &mut Option<RayHit>,
    ) {
        if let Some(b) = best {
            // `t0` unrounded (`EntryBound::enter_octants`): above an `f32`
            // bound, the box's exact entry is too.
            if t0 > prune_bound(b.t) as f64 {
                return;
            }
        }
        let n = &self.nodes[i];
        if filter.is_some_and(|f| !f.may_interact(n.groups, n.masks)) {
            return;
        }
        if n.leaf {
            let offer = |t: Option<f32>, it: &Item, best: &mut Option<RayHit>| {
                if let Some(t) = t {
                    if filter.is_none_or(|f| f.interacts(self.obj(it.handle).filter))
                        && RayHit::offer(best, t, it.handle)
                    {
                        // The caller will most likely look the answer up:
                        // its object starts loading while the search goes
                        // on (W8 first hits with the lookup 1.115-1.128 ->
                        // 0.970-0.979 µs a sweep, without it 0.880-0.884
                        // -> 0.923-0.924: two alternations; a prefetch of
                        // the final answer only, after the search: no gain).
                        self.objects.prefetch(it.handle);
                    }
                }
            };
            // Only the items of the octants of the leaf's cell (the boxes a
            // split would give; `LinearOctree::octants`) that the cast's box
            // up to the best hit so far reaches, and those no mask holds
            // (W8 first hits, callgrind as below: 10.6k -> 9.7k
            // instructions, 66 -> 45 L1 data misses and 72 -> 65
            // mispredicted branches a sweep).
            let reach = if d < MAX_DEPTH {
                let limit = best.map_or(f32::INFINITY, |b| prune_bound(b.t));
                entry.reach_octants(self.child_halves(n, c, d), limit)
            } else {
                0xFF
            };
            // Four at a time through the cast's SIMD pre-test where it has
            // one: the clear misses are most of a sweep's candidates
            // (callgrind, `w8 --n 100000 --queries 5000 --reps 1 --check 0
            // --only LinearOctree`: 16.2k -> 12.5k instructions a first-hit
            // sweep, before the octant masks).
            n.for_each_quad(&self.octants[i as usize], d, reach, |q, valid| {
                if X::HAS_MISSES4 {
                    let spheres = [&q[0].sphere, &q[1].sphere, &q[2].sphere, &q[3].sphere];
                    let mut lanes = !test.misses4(spheres) & valid;
                    while lanes != 0 {
                        // Its lane ran the pre-test already (conservative,
                        // so the exact test alone gives `contact`'s answer).
                        let it = q[lanes.trailing_zeros() as usize];
                        offer(test.contact_after_misses4(&it.sphere), it, best);
                        lanes &= lanes - 1;
                    }
                } else {
                    let mut lanes = valid;
                    while lanes != 0 {
                        let it = q[lanes.trailing_zeros() as usize];
                        offer(test.contact(&it.sphere), it, best);
                        lanes &= lanes - 1;
                    }
                }
            });
            return;
        }
        // The children's boxes from this node's extent: 12 slab parameters
        // for all 8, and no child node read before it is entered.
        let enters = entry.enter_octants(self.child_halves(n, c, d));
        // Front to back across the split planes by the direction's signs,
        // not sorted by entry: the loose boxes overlap by the extent only,
        // so the order is nearly the entry order, and the children entered
        // are listed without a branch each. Against the sorted entries
        // (callgrind, W8 as above): 12.5k -> 11.6k instructions and 92 ->
        // 74 mispredicted branches a first-hit sweep. Any order finds the
        // same hit; each child is tested against it on entry.
        let near = entry.near_octant();
        let mut order = [(0.0f64, 0usize); 8];
        let mut m = 0;
        for j in 0..8 {
            let k = near ^ j;
            order[m] = (enters[k], k);
            m += (n.children[k] != NONE && enters[k] < f64::INFINITY) as usize;
        }
        // Every child entered starts loading now, with its octant
        // masks: the first read of a child node and of a leaf's masks were
        // the search's two largest stalls (perf: 9% and 4% of its samples
        // on one load each). W8 first hits 1.083-1.115 -> 1.026-1.056 µs
        // (two alternations); prefetching all 8 children before the clips
        // instead: no better.
        for &(_, k) in &order[..m] {
            let ch = n.children[k];
            self.prefetch_node(ch);
            prefetch(&self.octants[ch as usize]);
        }
        for &(ct0, k) in &order[..m] {
            let ch = n.children[k];
            self.first_node(
                ch,
                child_coords(c, k),
                d + 1,
                ct0,
                test,
                entry,
                filter,
                best,
            );
        }
    }
}
