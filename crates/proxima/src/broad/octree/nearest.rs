//! k nearest neighbours [sources: index-queries]: a depth-first branch and
//! bound over the loose boxes, nearer octant first, or for large `k` a
//! best-first search over the same boxes, with the bounded candidate set of
//! `broad/nearest.rs`.

use super::node::{Item, Node, NONE};
use super::query::child_coords;
use super::{LinearOctree, DEFAULT_MAX_PER_LEAF};
use crate::broad::nearest::{KBest, Metric, Nearest, Neighbor, LINEAR_MAX_K, SEED_MAX};
use crate::broad::Filter;
use crate::geom::{overlap, Sphere};
use glam::Vec4;
use std::cell::RefCell;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// From this `k` on the search is best-first (a frontier of nodes ordered by
/// their boxes' distances) instead of depth-first: with many answers spread
/// over many leaves, the depth-first order fills the candidate set from the
/// far corners of the first subtrees and evicts them later, while best-first
/// visits leaves strictly nearest first and stops at the first node beyond the
/// bound. Below it the depth-first walk needs no frontier and is cheaper.
/// Measured (`w7 --n 100000`, two runs each): best-first at k = 10 took
/// 3.04-3.59 µs a query against 2.82-3.16 depth-first; at k = 100 the
/// candidate insertions fell 23% (callgrind) and the time ~10%.
const BEST_FIRST_MIN_K: usize = 32;

/// From this many objects on, the depth-first search prefetches a leaf's
/// items as a whole when it enters it (see `nearest_node`): 2^18 objects,
/// 8 MiB of leaf items, well past a core's L2 cache (2 MiB on the machine
/// measured), where the leaves are mostly not cached. Below it, at 100k,
/// the prefetches bought nothing and cost instructions.
const PREFETCH_LEAF_MIN_OBJECTS: usize = 1 << 18;

/// The cache lines of a default full leaf's items (two a line): what the
/// searches prefetch to have a whole leaf on its way. A constant rather than
/// read from the configuration: with the count known the prefetch loop
/// compiled to ~0.8% fewer instructions at k = 100 (callgrind,
/// `knn_leaf 100000 100 1000 48`). A tree configured with larger leaves
/// prefetches their first lines only; no result depends on it.
const LEAF_LINES: usize = DEFAULT_MAX_PER_LEAF.div_ceil(2) as usize;

/// A node waiting in the best-first search: the squared distance from the
/// query point to its box (the heap's key, smallest first), the node, its
/// cell coordinates and depth.
#[derive(Clone, Copy)]
struct Pending {
    dist_sq: f64,
    node: u32,
    c: [u32; 3],
    d: u32,
}

impl PartialEq for Pending {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

impl Eq for Pending {}

impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Pending {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the nearest first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.dist_sq.total_cmp(&self.dist_sq)
    }
}

thread_local! {
    /// The best-first frontier, kept per thread between queries so that a
    /// search allocates nothing once it has grown (a search runs no user code,
    /// so it is never re-entered; a failed borrow would use a fresh heap).
    static FRONTIER: RefCell<BinaryHeap<Pending>> = const { RefCell::new(BinaryHeap::new()) };
}

impl<T> LinearOctree<T> {
    /// The `k` nearest into `out`, nearest first, ties by handle.
    ///
    /// A subtree is skipped only if the correctly rounded distance from the
    /// point to its box — its cell grown by its parent's largest extent — is
    /// surely above the candidate set's bound ([`overlap::distance_exceeds`]
    /// on [`overlap::point_aabb_distance_sq`], summed per axis):
    /// that box contains the node's loose box, hence every sphere below it
    /// (`validate` checks the loose boxes), and
    /// the rounded distances are monotone, so a pruned subtree holds nothing
    /// that could have entered and the answer is brute force's, bit for bit.
    /// Candidates are tested the same way before their exact distance
    /// (`Metric::excluded`, then the exact distance). A leaf reached while
    /// nothing is held (the first, in practice), if it holds `k` to
    /// `SEED_MAX` items, bounds the answer from its items'
    /// centre distances before it offers any (`KBest::tighten_by_centres`;
    /// unfiltered queries), so later leaves
    /// are pruned against a near-final bound and few candidates are
    /// inserted only to be evicted. The depth-first search reaches that leaf
    /// first, straight down the nearest octants (a node whose nearest child
    /// is absent orders all its children at once), and orders a node's
    /// other children only on the way back up, against its bound. Octants
    /// are searched nearest first (up to rounding, `octants_nearest_first`;
    /// each tested against the bound when its turn comes), or from
    /// `BEST_FIRST_MIN_K` answers on all pending nodes nearest first (a
    /// per-thread frontier heap). The filter is checked at each
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
        let d0 = overlap::point_aabb_distance_sq(q.point, &self.loose_of([0; 3], 0, n.max_extent));
        if q.k >= BEST_FIRST_MIN_K {
            FRONTIER.with(|f| match f.try_borrow_mut() {
                Ok(mut heap) => self.nearest_best_first(d0, q, filter, &mut best, &mut heap),
                Err(_) => self.nearest_best_first(d0, q, filter, &mut best, &mut BinaryHeap::new()),
            });
        } else {
            self.nearest_node(self.root, [0; 3], 0, d0, q, filter, &mut best);
        }
        best.finish();
    }

    /// The best-first search from the root (whose box is `d0` away): pops the
    /// nearest pending node, stops when even it lies surely beyond the bound
    /// (the bound only shrinks, and every other pending node is at least as
    /// far), offers a leaf's items, and pushes the children that may hold a
    /// candidate. The same tests as the depth-first [`Self::nearest_node`],
    /// so the same answer.
    fn nearest_best_first(
        &self,
        d0: f64,
        q: &Nearest,
        filter: Option<Filter>,
        best: &mut KBest<'_>,
        heap: &mut BinaryHeap<Pending>,
    ) {
        heap.clear();
        heap.push(Pending {
            dist_sq: d0,
            node: self.root,
            c: [0; 3],
            d: 0,
        });
        while let Some(p) = heap.pop() {
            if best.exceeds_sq(p.dist_sq) {
                break;
            }
            // The next node's items (a default leaf's, up to 48 of them: one
            // line per two) and the first items of the two after it in the
            // heap's layout (`BinaryHeap::iter`'s order: the top's children
            // there, likely popped soon; only a hint either way) on their
            // way while this one is searched; their nodes were prefetched
            // when they were pushed, below. Without these prefetches the
            // loads of a popped node and of its leaf's first item took ~60%
            // of the search's samples at 1M (`perf`, W7 spheres k = 100):
            // with them, 29.6-31.1 -> 22.3-22.6 µs a query (six
            // alternations), 0.78-0.81 of rstar's time; with the next
            // leaf's first four lines alone it was ~0.85. (Measured with
            // leaves of up to 32 and 16 lines; `LEAF_LINES` follows the
            // default.)
            if let Some(next) = heap.peek() {
                self.nodes[next.node].prefetch_items(LEAF_LINES);
            }
            for after in heap.iter().skip(1).take(2) {
                self.nodes[after.node].prefetch_items(1);
            }
            let n = &self.nodes[p.node];
            if filter.is_some_and(|f| !f.may_interact(n.groups, n.masks)) {
                continue;
            }
            if n.leaf {
                // The depth-first search's leaf step. One item at a time was
                // cheaper here while each distance waited on the offer
                // before it; with the passers' distances computed first, the
                // three loops are faster (W7 spheres k = 100: 16.7 against
                // 17.9 µs a query, medians of seven alternations; points
                // k = 100: 14.2-16.6 against 16.5-19.7).
                self.offer_leaf(n, q, filter, best);
                continue;
            }
            let (dist, mut mask, _) = self.near_children(n, p.c, p.d, q, best);
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                self.prefetch_node(n.children[k]);
                heap.push(Pending {
                    dist_sq: dist[k],
                    node: n.children[k],
                    c: child_coords(p.c, k),
                    d: p.d + 1,
                });
            }
        }
    }

    /// Offers every item of leaf `n` that may enter `best`, in three loops:
    /// the list of the items not surely beyond the bound (from their
    /// squared centre distances in `f64` in the seed leaf, else from the
    /// four-lane `f32` pre-test of either metric; no branch per item: which items pass is
    /// unpredictable, and a mispredicted branch per passer cost ~16 a
    /// query, callgrind W7 points k = 10), then the exact distances of
    /// those, and then their offers (after the seed block, below), each
    /// tested again against the bound
    /// its predecessors may have lowered (`KBest::offer_unsynced`; W7 points
    /// k = 10: median 2.27 -> 2.18 µs a query on the probe `knn_leaf`
    /// against a distance and an offer in turn, 22 alternations). A leaf
    /// reached while nothing is held (unfiltered queries) bounds the answer
    /// from the same squared distances before anything is offered
    /// (`KBest::tighten_by_centres`), and offers the `k` it bounds by first,
    /// nearest first, as one block (`KBest::seed_unsynced`: 0.35k fewer
    /// instructions a query than offering each, W7 points k = 10). Leaves
    /// over `SEED_MAX` items (only at the depth cap) go one item at a time.
    /// Both searches take this step.
    /// Always inlined: as a call from the depth-first recursion it cost 4%
    /// more instructions at k = 10 (callgrind, W7 points).
    #[inline(always)]
    fn offer_leaf(&self, n: &Node, q: &Nearest, filter: Option<Filter>, best: &mut KBest<'_>) {
        let items = &n.items;
        if items.len() > SEED_MAX {
            return self.offer_each(n, q, filter, best);
        }
        let metric = leaf_metric(n, q);
        // Indices of the items not surely beyond the bound, without a branch
        // per item.
        // Four more than a leaf's items: with the first `k` listed ahead, the
        // branch-free loop below may write one slot past the last passer,
        // and four at a time up to four.
        let mut pass = [0u8; SEED_MAX + 4];
        let mut m = 0;
        // How many of the passers lead as the seed of an empty set.
        let mut taken = 0;
        // The passers' distances, and whether they are computed yet.
        let mut dist = [0.0f32; SEED_MAX];
        let mut measured = false;
        if best.is_empty() && filter.is_none() {
            let mut s2 = [0.0f64; SEED_MAX];
            let s2 = &mut s2[..items.len()];
            for (d, it) in s2.iter_mut().zip(items) {
                *d = overlap::point_point_distance_sq(q.point, it.sphere.center);
            }
            // The k it bounds by go first, nearest first, so that they enter
            // as one block, mostly without a sort, then the others that
            // pass.
            // Against the leaf's order: 89 -> 77 mispredicts a query,
            // 12.4k -> 12.6k instructions (callgrind); probe median 2.12
            // -> 2.03 µs a query, faster in 17 of 20 alternations (W7
            // points k = 10, `knn_leaf 100000 10 50000 32`).
            let mut first = [0u8; LINEAR_MAX_K];
            taken = best.tighten_by_centres(s2, &mut first);
            pass[..taken].copy_from_slice(&first[..taken]);
            m = taken;
            let mut is_first = 0u64;
            for &i in &first[..taken] {
                is_first |= 1 << i;
            }
            for (i, (&d, it)) in s2.iter().zip(items).enumerate() {
                pass[m] = i as u8;
                m += (!metric.excluded(d, &it.sphere, best) & (is_first >> i & 1 == 0)) as usize;
            }
            // From the squared distances at hand (the loop below computes
            // them again): 10.62k -> 10.57k instructions and 63.0 -> 60.4
            // mispredicts a query (W7 points k = 10, callgrind).
            for (d, &i) in dist.iter_mut().zip(&pass[..m]) {
                let it = &items[i as usize];
                *d = metric.distance_given_sq(q.point, &it.sphere, s2[i as usize]);
            }
            measured = true;
        } else if !items.is_empty() {
            // In `f32`, four items at a time (`list_passers`): no
            // conversions, and the passers' exact test below keeps the
            // answer brute force's. Against one item at a time in `f64`
            // (W7 points k = 10, `knn_leaf 100000 10 2000 32`, callgrind):
            // 12.57k -> 11.89k instructions a query; `knn_leaf 100000 10
            // 50000 32` median 2.24 -> 2.13 µs, faster in 13 of 16
            // alternations. Spheres (the surface metric) take a threshold
            // per lane grown by its radius (`spheres_beyond_f32_4`; W7
            // spheres 100k, callgrind: k = 100 -12.5%, k = 10 -18%
            // instructions against an `f64` test per item). One copy of the
            // loop per metric, not a branch per quad.
            m = match metric {
                Metric::Center => list_passers(
                    items,
                    &mut pass,
                    &CentresBeyond {
                        point: q.point,
                        t: Vec4::splat(best.sq_threshold_f32()),
                    },
                ),
                Metric::Surface => list_passers(
                    items,
                    &mut pass,
                    &SpheresBeyond {
                        point: q.point,
                        mid: best.midpoint_up_f32(),
                    },
                ),
            };
        }
        // Outside the seed leaf (which kept every item's squared distance
        // for its selection) the few that pass compute their squared
        // distance again (cheaper than keeping every item's in `f64`,
        // measured before the `f32` pre-test: a `memset` call per leaf and
        // more mispredicts), and
        // their distances all before any is offered: no distance then waits
        // for the offer before it (each offer lowers the bound the next
        // test reads, and mispredicts where it inserts), so their square
        // roots overlap. The offers compare with the bound only; its pruning
        // thresholds are synced once after them.
        if !measured {
            for (d, &i) in dist.iter_mut().zip(&pass[..m]) {
                let it = &items[i as usize];
                let s2 = overlap::point_point_distance_sq(q.point, it.sphere.center);
                *d = metric.distance_given_sq(q.point, &it.sphere, s2);
            }
        }
        // The seed enters as a block (no filter here): in answer order
        // already but for rounding and ties, it needs no insertion each.
        if taken > 0 {
            best.seed_unsynced(
                pass[..taken]
                    .iter()
                    .zip(&dist)
                    .map(|(&i, &distance)| Neighbor {
                        handle: items[i as usize].handle,
                        distance,
                    }),
            );
        }
        for (&distance, &i) in dist[taken..].iter().zip(&pass[taken..m]) {
            let it = &items[i as usize];
            if distance <= best.bound()
                && filter.is_none_or(|f| f.interacts(self.obj(it.handle).filter))
            {
                best.offer_unsynced(Neighbor {
                    handle: it.handle,
                    distance,
                });
            }
        }
        best.sync();
    }

    /// Offers each item of leaf `n` that may enter `best`, one at a time.
    #[inline(always)]
    fn offer_each(&self, n: &Node, q: &Nearest, filter: Option<Filter>, best: &mut KBest<'_>) {
        let metric = leaf_metric(n, q);
        for it in &n.items {
            let s2 = overlap::point_point_distance_sq(q.point, it.sphere.center);
            self.offer_item(it, s2, metric, q, filter, best);
        }
    }

    /// Offers item `it` (squared centre distance `s2`, distance in `metric`)
    /// if it may enter `best` and passes the filter.
    #[inline(always)]
    fn offer_item(
        &self,
        it: &Item,
        s2: f64,
        metric: Metric,
        q: &Nearest,
        filter: Option<Filter>,
        best: &mut KBest<'_>,
    ) {
        let Some(distance) = metric.distance_within_given_sq(q.point, &it.sphere, s2, best) else {
            return;
        };
        if filter.is_none_or(|f| f.interacts(self.obj(it.handle).filter)) {
            best.offer(Neighbor {
                handle: it.handle,
                distance,
            });
        }
    }

    /// The squared per-axis gaps from the query point to the two halves of
    /// inner node `n`'s cell (at coordinates `c`, depth `d`) on each axis,
    /// grown by `n`'s extent.
    ///
    /// The children's loose boxes are their cells grown by this node's
    /// extent (never below any child's: still every sphere below each
    /// child is inside). So each axis has two intervals, the cell's low
    /// and high halves, and the 8 boxes' distances are sums of 6 terms
    /// (`overlap::axis_gap_sq`, equal to the per-box distance bit for bit):
    /// no child node is read before it is visited (callgrind, 100k points,
    /// octree: -15% instructions a query at k = 1, -8% at k = 10).
    #[inline(always)]
    fn child_gaps(
        &self,
        n: &Node,
        c: [u32; 3],
        d: u32,
        q: &Nearest,
    ) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let [x, y, z] = self.child_halves(n, c, d);
        let p = q.point;
        let gap = |v: f32, [(l0, h0), (l1, h1)]: [(f32, f32); 2]| {
            [
                overlap::axis_gap_sq(v, l0, h0),
                overlap::axis_gap_sq(v, l1, h1),
            ]
        };
        (gap(p.x, x), gap(p.y, y), gap(p.z, z))
    }

    /// The squared distances to the boxes of inner node `n`'s children (at
    /// `c`, depth `d`; by octant), the mask of the children present whose
    /// box may hold a candidate, and the nearest octant (on each axis the
    /// half with the smaller gap): the one children step of both searches.
    /// Always inlined, as `child_gaps`.
    #[inline(always)]
    fn near_children(
        &self,
        n: &Node,
        c: [u32; 3],
        d: u32,
        q: &Nearest,
        best: &KBest<'_>,
    ) -> ([f64; 8], u32, usize) {
        let (gx, gy, gz) = self.child_gaps(n, c, d, q);
        let mut dist = [0.0f64; 8];
        let mut mask = 0u32;
        for (k, &ch) in n.children.iter().enumerate() {
            dist[k] = gx[k & 1] + gy[(k >> 1) & 1] + gz[k >> 2];
            if ch != NONE && !best.exceeds_sq(dist[k]) {
                mask |= 1 << k;
            }
        }
        let near = (gx[1] < gx[0]) as usize
            | ((gy[1] < gy[0]) as usize) << 1
            | ((gz[1] < gz[0]) as usize) << 2;
        (dist, mask, near)
    }

    #[allow(clippy::too_many_arguments)]
    fn nearest_node(
        &self,
        i: u32,
        c: [u32; 3],
        d: u32,
        dist_sq: f64,
        q: &Nearest,
        filter: Option<Filter>,
        best: &mut KBest<'_>,
    ) {
        if best.exceeds_sq(dist_sq) {
            return;
        }
        let n = &self.nodes[i];
        if filter.is_some_and(|f| !f.may_interact(n.groups, n.masks)) {
            return;
        }
        if n.leaf {
            // The whole leaf on its way at once, rather than line by line
            // as the scan reaches it, where the leaves are unlikely to be
            // cached already (the first descent's leaf is the one nothing
            // prefetched before). W7 spheres 1M (three alternations):
            // k = 10 0.80-0.85 -> 0.72-0.78 of rstar's time, k = 1 0.49-0.56
            // -> 0.49-0.53 (leaves of up to 32 then, 16 lines; now
            // `LEAF_LINES`). At 100k it gained nothing and cost ~0.4k
            // instructions and ~13 mispredicts a k = 10 query (callgrind;
            // the loop's exit), hence the size test.
            if self.objects.len() >= PREFETCH_LEAF_MIN_OBJECTS {
                n.prefetch_items(LEAF_LINES);
            }
            self.offer_leaf(n, q, filter, best);
            return;
        }
        let (dist, mut mask, near) = self.near_children(n, c, d, q, best);
        if best.is_empty() && mask >> near & 1 == 1 {
            // The first descent, while nothing bounds the search: straight
            // into the nearest octant, and only then order, prefetch and
            // visit the others, against the bound its leaf set. Ordered and
            // touched now, all eight children would pass the infinite
            // bound, on every level down: 37 children ordered and touched
            // a query, 12 of them visited (callgrind, W7 points k = 10);
            // now 9. With the early return below (and the seed entering as
            // a block): 11.89k -> 10.62k instructions and 77 -> 63
            // mispredicts a query; `knn_leaf 100000 10 50000 32` median
            // 1.85 -> 1.70 µs a query, faster in 12 of 12 alternations
            // (k = 1: 0.84 -> 0.75 µs before the early return).
            let (ch, cc) = (n.children[near], child_coords(c, near));
            self.nearest_node(ch, cc, d + 1, dist[near], q, filter, best);
            mask &= !(1 << near);
            for (k, &dk) in dist.iter().enumerate() {
                mask &= !((best.exceeds_sq(dk) as u32) << k);
            }
            // Mostly so on the way back up: nothing to order.
            if mask == 0 {
                return;
            }
        }
        // The children in (nearly) nearest-first order, those pruned left
        // out without a branch each.
        let mut order = [0u8; 8];
        let mut m = 0;
        for o in octants_nearest_first(&dist, near) {
            order[m] = o;
            m += (mask >> o) as usize & 1;
        }
        // The children on their way now, so that their cache misses overlap
        // instead of following one another (`perf` put ~10% of the search's
        // samples on the first read of a node and ~15% on a leaf's first
        // item, each waiting for the one before), and the next child's first
        // items while this one is searched. Prefetches rather than the plain
        // reads they replace, which held up the instructions behind them
        // (the loop over the `m` to visit, leaves of 32: `knn_leaf 100000 10
        // 50000 32` median 0.94× the time, eight alternations, faster in
        // six; k = 1 unchanged). Now all eight, pruned or not, an absent one
        // as this node (already cached), so that the loop has no
        // data-dependent exit: `knn_leaf 100000 10 50000 48` 0.976-0.994 of
        // the time (8 of 8 alternations), mispredicts −2.2% and
        // instructions +1.9% (callgrind).
        for &ch in &n.children {
            self.prefetch_node(if ch == NONE { i } else { ch });
        }
        for (j, &o) in order[..m].iter().enumerate() {
            if let Some(&next) = order[..m].get(j + 1) {
                self.nodes[n.children[next as usize]].prefetch_items(1);
            }
            let o = o as usize;
            // The bound may have fallen since the mask was made. The order is
            // nearest first only up to rounding, so a child beyond it does
            // not prove the rest are.
            let dc = dist[o];
            if best.exceeds_sq(dc) {
                continue;
            }
            let (ch, cc) = (n.children[o], child_coords(c, o));
            self.nearest_node(ch, cc, d + 1, dc, q, filter, best);
        }
    }
}

/// For each mask of four items, the positions of its set bits packed into
/// the low bytes, in order (the rest 0).
const QUAD_PASSERS: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut bits = 0;
    while bits < 16 {
        let (mut j, mut at) = (0, 0);
        while j < 4 {
            if bits >> j & 1 == 1 {
                t[bits] |= (j as u32) << (8 * at);
                at += 1;
            }
            j += 1;
        }
        bits += 1;
    }
    t
};

/// The number of set bits of each mask of four (no `popcnt` in the
/// baseline x86-64 target).
const QUAD_COUNT: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];

/// The leaf step's four-lane pre-test: a bit per lane whose sphere surely
/// cannot enter the search's candidate set. A trait with always-inlined
/// methods rather than a closure: `list_passers` calls it at two sites, and
/// the closure was compiled out of line at the second (the last quad's:
/// a call per leaf, ~35 instructions each; callgrind, W7 points k = 10,
/// docs/bench/run19-02adaaa.txt).
trait QuadBeyond {
    /// Bit `j` set when sphere `s[j]` surely cannot enter. O(1).
    fn beyond(&self, s: [&Sphere; 4]) -> u32;
}

/// `Metric::Center` (radii ignored): the `f32` squared centre distance
/// above `t` ([`KBest::sq_threshold_f32`]).
struct CentresBeyond {
    point: glam::Vec3,
    t: Vec4,
}

impl QuadBeyond for CentresBeyond {
    #[inline(always)]
    fn beyond(&self, s: [&Sphere; 4]) -> u32 {
        overlap::point_point_distance_sq_f32_4(self.point, s)
            .cmpgt(self.t)
            .bitmask()
    }
}

/// Spheres (`Metric::Surface`): [`overlap::spheres_beyond_f32_4`] at the
/// bound's midpoint rounded up ([`KBest::midpoint_up_f32`]).
struct SpheresBeyond {
    point: glam::Vec3,
    mid: f32,
}

impl QuadBeyond for SpheresBeyond {
    #[inline(always)]
    fn beyond(&self, s: [&Sphere; 4]) -> u32 {
        overlap::spheres_beyond_f32_4(self.point, s, self.mid)
    }
}

/// Lists in `pass` the indices of the items of a non-empty leaf that
/// `beyond` (four spheres at a time, a bit per lane surely beyond the
/// search's bound) does not rule out, and returns how many. The positions
/// are written four bytes at once from a table (`QUAD_PASSERS`), and the
/// last 0-3 items go as one more quad with its other lanes masked off: no
/// branch per item and no loop whose length varies by leaf (its exit
/// mispredicted about once a leaf). O(items).
#[inline(always)]
fn list_passers(items: &[Item], pass: &mut [u8; SEED_MAX + 4], beyond: &impl QuadBeyond) -> usize {
    // A function, not a closure: the closure was compiled as a call
    // (callgrind, W7 points k = 10: +2.6% instructions a query).
    #[inline(always)]
    fn quad(pass: &mut [u8], m: usize, from: usize, beyond: u32, live: u32) -> usize {
        let bits = (!beyond & live) as usize;
        let at = QUAD_PASSERS[bits] + from as u32 * 0x0101_0101;
        pass[m..m + 4].copy_from_slice(&at.to_le_bytes());
        m + QUAD_COUNT[bits] as usize
    }
    debug_assert!(!items.is_empty() && items.len() <= SEED_MAX);
    let mut m = 0;
    let mut quads = items.chunks_exact(4);
    let mut from = 0;
    for c in &mut quads {
        m = quad(
            pass,
            m,
            from,
            beyond.beyond([&c[0].sphere, &c[1].sphere, &c[2].sphere, &c[3].sphere]),
            0xF,
        );
        from += 4;
    }
    let last = items.len() - 1;
    // Written out: `[0, 1, 2, 3].map(..)` compiled to an out-of-line
    // `array::try_map` call per leaf (callgrind, W7 points k = 10: ~260
    // instructions a query; docs/bench/run19-02adaaa.txt).
    let at = |j: usize| &items[(from + j).min(last)].sphere;
    let rest = [at(0), at(1), at(2), at(3)];
    quad(
        pass,
        m,
        from,
        beyond.beyond(rest),
        (1 << quads.remainder().len()) - 1,
    )
}

/// The metric to measure leaf `n`'s items in: the query's, or
/// [`Metric::Center`] when every item's radius is zero (the leaf's largest
/// extent bounds them, `validate` checks it), where the two metrics agree
/// bit for bit (a zero radius is what `Metric::Center` measures with) and
/// the centre test spares a sum and two products per item (the threshold of
/// `KBest::exceeds` grown by the radius): point clouds stored with the
/// default metric.
#[inline(always)]
fn leaf_metric(n: &Node, q: &Nearest) -> Metric {
    if n.max_extent == 0.0 {
        Metric::Center
    } else {
        q.metric
    }
}

/// The 8 octants nearest first, given their boxes' squared distances `dist`
/// and the nearest octant `near`, from four comparisons instead of a sort.
///
/// A box's distance is a sum of one term per axis, and moving away from
/// `near` on an axis adds that axis's extra gap. With the axes ordered by
/// their extra gaps `a <= b <= c` (measured as the distances of `near`'s
/// three neighbours), the order of the sums is fixed but for one pair:
/// `near`, then across `a`, across `b`, across `a` and `b` or across `c`
/// (whichever is nearer), the other, then across `a` and `c`, `b` and `c`,
/// all three. The computed sums round, so this is nearest first only up to
/// an ulp: the search tests every child against its bound rather than
/// stopping at the first beyond it. The insertion sort it replaces
/// mispredicted ~21 branches a query (callgrind, W7 points, k = 10).
#[inline(always)]
fn octants_nearest_first(dist: &[f64; 8], near: usize) -> [u8; 8] {
    let ascending = |x: (f64, usize), y: (f64, usize)| if y.0 < x.0 { (y, x) } else { (x, y) };
    let (a, b) = ascending((dist[near ^ 1], 1), (dist[near ^ 2], 2));
    let (b, c) = ascending(b, (dist[near ^ 4], 4));
    let (a, b) = ascending(a, b);
    let (a, b, c) = (a.1, b.1, c.1);
    let (x, y) = if dist[near ^ c] < dist[near ^ a ^ b] {
        (c, a | b)
    } else {
        (a | b, c)
    };
    [0, a, b, x, y, a | c, b | c, 7].map(|o| (near ^ o) as u8)
}
