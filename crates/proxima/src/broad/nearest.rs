//! k nearest neighbours [sources: index-queries]: the query ([`Nearest`]), its
//! answer ([`Neighbor`]), the distances ([`Metric`]), and the reference search
//! every index starts from (an expanding sphere query), which the indices with
//! a better search override: the trees' best-first searches, and the grids'
//! growing box of cells ([`grow_box`]).

use super::cell_grid::keys::KeyBox;
use super::walk::Walk;
use super::Filter;
use crate::error::check_vec3;
use crate::geom::overlap::{above as hi, below as lo};
use crate::geom::{overlap, Aabb, Sphere};
use crate::{Error, Handle, Result};
use glam::Vec3;
use std::ops::ControlFlow;

/// How [`Nearest`] measures the distance from its point to a stored sphere.
/// Both are [`overlap::point_sphere_distance`], correctly rounded to `f32`, so
/// every index reports the same value for the same object (bit for bit) and
/// breaks ties the same way (smaller handle first).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Metric {
    /// To the sphere's surface, `max(0, |c - q| - r)` (`0` inside): the
    /// default, what "the nearest object" means for objects with extent.
    #[default]
    Surface,
    /// To the sphere's centre, `|c - q|`: for point clouds (with radius-0
    /// spheres the two metrics are equal).
    Center,
}

impl Metric {
    /// The distance from `point` to `s` in this metric (correctly rounded).
    /// O(1).
    #[inline]
    pub fn distance(self, point: Vec3, s: &Sphere) -> f32 {
        match self {
            Metric::Surface => overlap::point_sphere_distance(point, s),
            Metric::Center => overlap::point_sphere_distance(point, &Sphere::new(s.center, 0.0)),
        }
    }

    /// [`Metric::distance`] if it is at most `best`'s bound, else `None`: the
    /// searches' per-candidate step. Most candidates lie beyond the current
    /// k-th best, and [`overlap::distance_exceeds`] rejects them from the
    /// squared centre distance alone (no square root, no rounding); only the
    /// others get the correctly rounded distance, so the answer is the same
    /// bit for bit. O(1).
    #[inline]
    pub(crate) fn distance_within(self, point: Vec3, s: &Sphere, best: &KBest<'_>) -> Option<f32> {
        let s2 = overlap::point_point_distance_sq(point, s.center);
        self.distance_within_given_sq(point, s, s2, best)
    }

    /// Whether `s`, whose squared centre distance from the query point is
    /// `s2` ([`overlap::point_point_distance_sq`]), surely cannot enter
    /// `best` in this metric ([`KBest::exceeds`]): the pruning half of
    /// [`Metric::distance_within`], for searches that test a whole group of
    /// candidates before computing any distance. O(1); no branch but the
    /// metric's (the same for a whole query).
    #[inline]
    pub(crate) fn excluded(self, s2: f64, s: &Sphere, best: &KBest<'_>) -> bool {
        match self {
            Metric::Surface => best.exceeds(s2, s.radius),
            Metric::Center => best.exceeds_sq(s2),
        }
    }

    /// [`Metric::distance_within`] when the caller already holds `s2 =`
    /// [`overlap::point_point_distance_sq`]`(point, s.center)`: the same
    /// value without computing it twice. O(1).
    #[inline]
    pub(crate) fn distance_within_given_sq(
        self,
        point: Vec3,
        s: &Sphere,
        s2: f64,
        best: &KBest<'_>,
    ) -> Option<f32> {
        if self.excluded(s2, s, best) {
            return None;
        }
        let distance = self.distance_given_sq(point, s, s2);
        (distance <= best.bound()).then_some(distance)
    }

    /// [`Metric::distance`] when the caller already holds `s2 =`
    /// [`overlap::point_point_distance_sq`]`(point, s.center)`: the same
    /// value, bit for bit. O(1).
    #[inline]
    pub(crate) fn distance_given_sq(self, point: Vec3, s: &Sphere, s2: f64) -> f32 {
        match self {
            Metric::Surface => overlap::point_sphere_distance_given_sq(point, s, s2),
            Metric::Center => {
                overlap::point_sphere_distance_given_sq(point, &Sphere::new(s.center, 0.0), s2)
            }
        }
    }
}

/// A k-nearest-neighbours query: the (up to) `k` stored objects nearest to
/// `point`, at most `max_distance` away, in `metric`. Build it with
/// [`Nearest::new`] and refine with [`Nearest::within`] and
/// [`Nearest::metric`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Where distances are measured from.
    pub point: Vec3,
    /// How many objects at most (`0` gives none).
    pub k: usize,
    /// Objects farther than this are left out (inclusive: an object exactly
    /// this far counts). `f32::INFINITY` (the default) for no limit.
    pub max_distance: f32,
    /// The distance used, for ranking and for `max_distance`.
    pub metric: Metric,
}

impl Nearest {
    /// The `k` objects nearest to `point` by surface distance, with no limit.
    pub const fn new(point: Vec3, k: usize) -> Self {
        Nearest {
            point,
            k,
            max_distance: f32::INFINITY,
            metric: Metric::Surface,
        }
    }

    /// The same query limited to objects at most `max_distance` away.
    pub const fn within(self, max_distance: f32) -> Self {
        Nearest {
            max_distance,
            ..self
        }
    }

    /// The same query in another metric.
    pub const fn metric(self, metric: Metric) -> Self {
        Nearest { metric, ..self }
    }

    /// Checks for a finite point and a `max_distance` that is not NaN or
    /// negative (`∞` is fine). O(1).
    pub fn validate(&self) -> Result<()> {
        check_vec3(self.point, "nearest point")?;
        if self.max_distance.is_nan() {
            return Err(Error::NonFinite {
                what: "nearest max_distance",
            });
        }
        if self.max_distance < 0.0 {
            return Err(Error::InvalidParameter(format!(
                "nearest max_distance must be >= 0, got {}",
                self.max_distance
            )));
        }
        Ok(())
    }
}

/// One answer of a [`Nearest`] query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor {
    /// The object.
    pub handle: Handle,
    /// Its distance from the query point in the query's metric.
    pub distance: f32,
}

impl Neighbor {
    /// The order of a [`Nearest`] answer: smaller distance first, ties by the
    /// smaller handle. A total order (distances are never NaN).
    #[inline]
    pub fn order(a: &Neighbor, b: &Neighbor) -> std::cmp::Ordering {
        a.distance
            .total_cmp(&b.distance)
            .then(a.handle.cmp(&b.handle))
    }

    /// `Neighbor::order(a, b).is_lt()`, comparing handles only when the
    /// distances are equal as floats (then `total_cmp` still puts `-0.0`
    /// before `0.0`): the same answer, for non-NaN distances, at a fraction
    /// of the cost (`KBest`'s binary searches and heap steps). O(1).
    #[inline]
    pub(crate) fn precedes(a: &Neighbor, b: &Neighbor) -> bool {
        a.distance < b.distance || (a.distance == b.distance && Neighbor::order(a, b).is_lt())
    }
}

/// Sorts the candidates in `out` into the answer order and keeps the first
/// `k`. O(n + k log k).
pub(crate) fn finish(out: &mut Vec<Neighbor>, k: usize) {
    if out.len() > k {
        out.select_nth_unstable_by(k, Neighbor::order);
        out.truncate(k);
    }
    out.sort_unstable_by(Neighbor::order);
}

/// Where `n` goes in `h` (sorted by [`Neighbor::order`]): after every entry
/// that [precedes](Neighbor::precedes) it. A binary search on the distances
/// alone (one float comparison a step), then a step over the entries at
/// `n`'s distance that precede it: entries with equal float distances
/// (`-0.0` and `0.0` included) are contiguous in that order, and among them
/// `precedes` is `order`. The same index as
/// `h.partition_point(|e| Neighbor::precedes(e, n))` (tested), at about half
/// its cost (callgrind W7, k = 100). O(log k + ties).
#[inline]
fn insertion_point(h: &[Neighbor], n: &Neighbor) -> usize {
    let mut i = h.partition_point(|e| e.distance < n.distance);
    while i < h.len() && h[i].distance == n.distance && Neighbor::order(&h[i], n).is_lt() {
        i += 1;
    }
    i
}

/// Up to this `k`, [`KBest`] keeps its candidates sorted (an insertion costs
/// a binary search and a move of at most `k` entries, and the answer needs no
/// final sort); above it, a binary heap (O(log k) per insertion, a sort at the
/// end). Callgrind W7 at k = 100 (octree, spheres, n = 20000): the heap's
/// final sort alone cost ~21k instructions a query, the sorted buffer's
/// moves ~10k.
pub(crate) const SORTED_MAX_K: usize = 256;

/// Up to this `k`, a sorted [`KBest`] inserts by shifting from the end
/// (`O(k)` comparisons, no call); above it by a binary search and a move.
pub(crate) const LINEAR_MAX_K: usize = 32;

/// From `k = 2` up to this `k`, [`KBest::tighten_by_centres`] passes every
/// value through its insertion network, without first testing whether it
/// enters (`k = 1` takes running minima).
const BRANCH_FREE_MAX_K: usize = 4;

/// The largest group [`KBest::tighten_by_centres`] takes (the octree's first
/// leaf; a leaf only exceeds its `max_per_leaf` at the depth cap), so that
/// its selection needs no allocation.
pub(crate) const SEED_MAX: usize = 64;

// `tighten_by_centres` keeps an index in 6 bits, the octree a leaf's seed
// members in a `u64` mask.
const _: () = assert!(SEED_MAX <= 64);

/// The `k` best candidates seen so far inside the caller's output buffer: the
/// bounded candidate set of the best-first and branch-and-bound searches. For
/// `k <=` [`SORTED_MAX_K`] the buffer is kept in answer order
/// ([`Neighbor::order`]), beyond it as a max-heap (worst first). It also keeps
/// the pruning threshold of its bound ([`overlap::distance_midpoint`]), which
/// changes only when a candidate enters (or, after
/// [`KBest::offer_unsynced`] or [`KBest::seed_unsynced`], at [`KBest::sync`]),
/// so the per-candidate and per-node
/// tests ([`KBest::exceeds`], [`KBest::exceeds_sq`]) are one or two flops and
/// a comparison. No allocation once the buffer holds `k` entries.
pub(crate) struct KBest<'a> {
    held: &'a mut Vec<Neighbor>,
    k: usize,
    limit: f32,
    /// Whether `held` is sorted (small `k`) rather than a heap.
    sorted: bool,
    /// [`KBest::bound`], cached.
    bound: f32,
    /// `distance_midpoint(bound)`.
    mid: f64,
    /// `exceeds_threshold(mid, 0)`: the squared threshold of boxes and points.
    mid_sq: f64,
    /// `sq_threshold_f32(mid_sq)`: the `f32` pre-test's threshold.
    mid_sq_f32: f32,
    /// The bound `mid`, `mid_sq` and `mid_sq_f32` were computed from: equal to
    /// `bound` but after [`KBest::offer_unsynced`], whose caller syncs them
    /// later ([`KBest::sync`]).
    synced: f32,
}

/// Inserts `x` into `top` (ascending; `∞` for "none yet"), dropping the
/// largest: slot j keeps the smaller of its value and the larger of its
/// lower neighbour's and x, from the top down, without a branch (where x
/// stops is unpredictable). O(len).
#[inline(always)]
fn insert_key(top: &mut [f64], x: f64) {
    for j in (1..top.len()).rev() {
        top[j] = lo(top[j], hi(top[j - 1], x));
    }
    top[0] = lo(top[0], x);
}

/// The `K` smallest of `key(0..n)`, ascending, into `top[..K]`: the
/// insertion network of [`insert_key`] on a `K` known at compile time, so
/// that it is unrolled and its slots stay in registers. For `K` up to
/// [`BRANCH_FREE_MAX_K`] every key goes through it (it leaves the `K` as
/// they were when the key does not enter): cheaper than the test, whose
/// outcome is unpredictable while the `K` are still falling (k = 4: 36 ->
/// 31 mispredicts a query, callgrind, `knn_leaf 100000 4 4000 48`).
#[inline(always)]
fn smallest_keys<const K: usize>(
    n: usize,
    key: impl Fn(usize) -> f64,
    top: &mut [f64; LINEAR_MAX_K],
) {
    let mut t = [f64::INFINITY; K];
    for i in 0..n {
        let x = key(i);
        if K > BRANCH_FREE_MAX_K && x >= t[K - 1] {
            continue;
        }
        insert_key(&mut t, x);
    }
    top[..K].copy_from_slice(&t);
}

impl<'a> KBest<'a> {
    /// An empty set in `out` (cleared) for the `k` best within `limit`.
    pub(crate) fn new(out: &'a mut Vec<Neighbor>, k: usize, limit: f32) -> Self {
        out.clear();
        let mut best = KBest {
            held: out,
            k,
            limit,
            sorted: k <= SORTED_MAX_K,
            bound: f32::NAN,
            mid: 0.0,
            mid_sq: 0.0,
            mid_sq_f32: 0.0,
            synced: f32::NAN,
        };
        best.set_bound(limit);
        best
    }

    /// Whether no candidate is held yet. O(1).
    #[inline]
    pub(crate) fn is_empty(&self) -> bool {
        self.held.is_empty()
    }

    /// The largest distance a candidate may have and still enter: the limit
    /// until `k` are held, then the worst held distance (a candidate at exactly
    /// that distance may still enter with a smaller handle, so searches prune
    /// only what lies strictly beyond it).
    #[inline]
    pub(crate) fn bound(&self) -> f32 {
        self.bound
    }

    /// [`overlap::distance_exceeds`]`(s2, r, self.bound())` from the cached
    /// midpoint: whether a sphere of radius `r` whose centre lies `sqrt(s2)`
    /// away (squared, [`overlap::point_point_distance_sq`]) surely cannot
    /// enter. O(1).
    #[inline]
    pub(crate) fn exceeds(&self, s2: f64, r: f32) -> bool {
        s2 > overlap::exceeds_threshold(self.mid, r)
    }

    /// [`KBest::exceeds`] for a point or a box (`r = 0`, `s2` from
    /// [`overlap::point_aabb_distance_sq`]): one comparison. O(1).
    #[inline]
    pub(crate) fn exceeds_sq(&self, s2: f64) -> bool {
        s2 > self.mid_sq
    }

    /// The `f32` pre-test's threshold: a point whose `f32` squared distance
    /// (`overlap::point_point_distance_sq_f32_4`, one lane) is above it
    /// surely cannot enter as a centre (`Metric::Center`, or a zero radius):
    /// then [`KBest::exceeds_sq`] holds for its `f64` squared distance too
    /// ([`overlap::sq_threshold_f32`]). At or below it, the `f64` test
    /// decides. O(1).
    #[inline]
    pub(crate) fn sq_threshold_f32(&self) -> f32 {
        self.mid_sq_f32
    }

    /// The bound's midpoint rounded up to `f32`, for the spheres' four-lane
    /// pre-test ([`overlap::spheres_beyond_f32_4`]): a sphere it sets a bit
    /// for surely cannot enter in [`Metric::Surface`] ([`KBest::exceeds`]
    /// holds for it). Computed on each call (a few instructions), not kept
    /// beside the others: [`KBest::sync`] runs after every offer in some
    /// searches. O(1).
    #[inline]
    pub(crate) fn midpoint_up_f32(&self) -> f32 {
        overlap::midpoint_up_f32(self.mid)
    }

    fn set_bound(&mut self, bound: f32) {
        self.bound = bound;
        self.sync();
    }

    /// Brings the pruning thresholds of [`KBest::exceeds`],
    /// [`KBest::exceeds_sq`] and [`KBest::sq_threshold_f32`] to the current
    /// bound, after offers made with [`KBest::offer_unsynced`]. O(1).
    #[inline]
    pub(crate) fn sync(&mut self) {
        // Bit equality: a bound of -0.0 and 0.0 give the same midpoint anyway.
        if self.bound.to_bits() != self.synced.to_bits() {
            self.synced = self.bound;
            self.mid = overlap::distance_midpoint(self.bound);
            self.mid_sq = overlap::exceeds_threshold(self.mid, 0.0);
            self.mid_sq_f32 = overlap::sq_threshold_f32(self.mid_sq);
        }
    }

    /// Lowers the limit from a first group of objects before the search
    /// offers them: `s2` holds the squared centre distances
    /// ([`overlap::point_point_distance_sq`]) of objects that are in the set
    /// and pass the query's filter. If there are at least `k` of them, `k`
    /// of them (the `k` smallest; for `k <=` [`LINEAR_MAX_K`] up to 64 ulps)
    /// give, by [`overlap::distance_at_most_from_sq`] of the largest, a
    /// distance `D` at or below which at least `k` objects lie in either
    /// metric (a surface distance never exceeds the centre distance), so the
    /// answer's `k`-th distance is at most `D` and nothing beyond `D` can
    /// enter. The searches then offer only about `k` candidates from the
    /// first leaf instead of every one that beats a still loose bound
    /// (octree, 100k points, k = 10: 17.1 insertions a query instead of
    /// 24.6, callgrind on `examples/knn_leaf`). Groups of more than
    /// [`SEED_MAX`] change nothing. O(len · k) for `k <=` [`LINEAR_MAX_K`],
    /// else O(len) (the octree's only: a leaf of at least `k` items, which
    /// for `k > 48` takes a `max_per_leaf` above the default or the depth
    /// cap).
    ///
    /// When `k <=` [`LINEAR_MAX_K`] and `k <= s2.len() <=` [`SEED_MAX`], it
    /// also writes into `first[..k]` the indices (in `s2`) of the `k` values
    /// it bounds by, by centre distance up to 64 ulps (ties by index), and
    /// returns `k`; otherwise it returns 0 and leaves `first` alone. In that
    /// order they are mostly in answer order already, so
    /// [`KBest::seed_unsynced`] takes them as one block and rarely sorts
    /// (offered one by one in the leaf's order, each insertion had
    /// mispredicted ~1.7 times, callgrind, W7 points k = 10).
    pub(crate) fn tighten_by_centres(
        &mut self,
        s2: &[f64],
        first: &mut [u8; LINEAR_MAX_K],
    ) -> usize {
        if self.k == 0 || s2.len() < self.k || s2.len() > SEED_MAX {
            return 0;
        }
        let mut taken = 0;
        // Each value carries its index in its 6 lowest bits (`SEED_MAX` =
        // 64; non-negative finite values order as their bits, so the keys
        // order by the value, to 64 ulps, then the index), and the bound is
        // the largest exact value of the `k` taken: `k` values lie at or
        // below it. The bits are also raised by one exponent step, which
        // keeps their order and keeps a 0 (a point on the query) out of the
        // subnormals: a host with denormals-are-zero on (a fast-math
        // extension in the same Python process) would compare those keys
        // equal, and the min/max could then take one index twice.
        let key = |i: usize| f64::from_bits((s2[i].to_bits() & !63 | i as u64) + (1 << 52));
        let kth = if self.k == 1 {
            // The smallest key, in four running minima: one was a chain of
            // dependent `min`s, ~4 cycles a value (`perf`: the Python batch
            // at k = 1 spent ~9% of its time here). The last 1-4 values go
            // as a four with the last one repeated (a repeated key changes
            // no minimum), so the loop's length is the leaf's quads.
            let n = s2.len();
            let mut m = [f64::INFINITY; 4];
            let mut from = 0;
            while from + 4 < n {
                for (j, mj) in m.iter_mut().enumerate() {
                    *mj = lo(*mj, key(from + j));
                }
                from += 4;
            }
            for (j, mj) in m.iter_mut().enumerate() {
                *mj = lo(*mj, key((from + j).min(n - 1)));
            }
            let x = lo(lo(m[0], m[1]), lo(m[2], m[3]));
            first[0] = (x.to_bits() & 63) as u8;
            taken = 1;
            s2[first[0] as usize]
        } else if self.k <= LINEAR_MAX_K {
            // The k smallest kept sorted (`∞` for "none yet"): cheaper than
            // the library's selection on a leaf's few dozen values
            // (callgrind: ~750 instructions a call there). An entering value
            // moves in by a min/max per slot, without a branch: where it
            // stops is unpredictable, and the shifting loop it replaces
            // mispredicted ~18 times a query (callgrind, W7 points k = 10).
            let mut top = [f64::INFINITY; LINEAR_MAX_K];
            let k = self.k;
            let n = s2.len();
            // Up to 16, one copy per `k`, whose `k` smallest stay in
            // registers: held in memory, the network's two-lane loads of
            // neighbouring slots straddled the stores of the value before
            // (store-to-load forwarding failed: `perf` put a quarter of the
            // function's time on one such load, Python batch at k = 10).
            // `knn_leaf 100000 K 50000 48` (30000 queries for k = 4, 16, 20
            // and 32): k = 10 and 16 -7%, k = 4 equal; copies up to 32
            // gained ~3% at k = 20 and nothing at 32.
            macro_rules! by_k {
                ($($c:literal)*) => {
                    match k {
                        $($c => smallest_keys::<$c>(n, key, &mut top),)*
                        _ => {
                            for i in 0..n {
                                let x = key(i);
                                if x < top[k - 1] {
                                    insert_key(&mut top[..k], x);
                                }
                            }
                        }
                    }
                };
            }
            by_k!(2 3 4 5 6 7 8 9 10 11 12 13 14 15 16);
            let mut kth = 0.0f64;
            for (f, t) in first.iter_mut().zip(&top[..k]) {
                *f = (t.to_bits() & 63) as u8;
                kth = hi(kth, s2[*f as usize]);
            }
            taken = k;
            kth
        } else {
            // Non-negative and never NaN: their bits order them. A copy, so
            // that the caller's values keep their order.
            let mut bits = [0u64; SEED_MAX];
            for (b, x) in bits.iter_mut().zip(s2) {
                *b = x.to_bits();
            }
            f64::from_bits(*bits[..s2.len()].select_nth_unstable(self.k - 1).1)
        };
        let d = overlap::distance_at_most_from_sq(kth);
        if d < self.limit {
            self.limit = d;
            if self.held.len() < self.k {
                self.set_bound(d);
            }
        }
        taken
    }

    /// Offers a candidate: kept if fewer than `k` are held or it precedes the
    /// worst held one. O(log k) comparisons, plus a move of up to `k` entries
    /// when sorted.
    #[inline]
    pub(crate) fn offer(&mut self, n: Neighbor) {
        self.offer_unsynced(n);
        self.sync();
    }

    /// [`KBest::offer_unsynced`] of each of `group` in turn, into a set that
    /// holds nothing yet, for a group that mostly comes in answer order
    /// already: the `k` a search bounded by ([`KBest::tighten_by_centres`],
    /// nearest first up to 64 ulps of their squared distances). Those
    /// within the limit are appended, sorted only if their distances are
    /// not strictly rising (ties by handle, signed zeros, or two distances
    /// the 64 ulps swapped), and cut to the first `k`: the same set as
    /// offering them one by one (in the same order when sorted, `k <=`
    /// [`SORTED_MAX_K`]; as a heap above it, the same answer after
    /// [`KBest::finish`]), without the insertion step of each. A group
    /// longer than `k` may grow the buffer past `k` entries for a moment
    /// (the searches pass exactly `k`). O(len) in order, else O(len log
    /// len). Sound on any group of distinct candidates, in any order (tested
    /// against offers).
    pub(crate) fn seed_unsynced(&mut self, group: impl IntoIterator<Item = Neighbor>) {
        debug_assert!(self.held.is_empty());
        if self.k == 0 {
            return;
        }
        for n in group {
            if n.distance <= self.limit {
                self.held.push(n);
            }
        }
        let h = &mut *self.held;
        // Strictly rising distances are in answer order; anything else
        // (ties, mostly) is sorted. No branch per entry.
        let mut rising = true;
        for w in h.windows(2) {
            rising &= w[0].distance < w[1].distance;
        }
        if !rising {
            h.sort_unstable_by(Neighbor::order);
        }
        if h.len() > self.k {
            h.truncate(self.k);
        }
        if !self.sorted {
            // The heap representation keeps its worst first.
            h.reverse();
        }
        if h.len() == self.k {
            self.bound = if self.sorted {
                h[self.k - 1].distance
            } else {
                h[0].distance
            };
        }
    }

    /// [`KBest::offer`] that updates [`KBest::bound`] but leaves the pruning
    /// thresholds at an earlier bound until [`KBest::sync`]: for a group of
    /// offers in a row, which need only the bound. Until then the
    /// `exceeds*` tests are still sound, only looser (the bound never
    /// rises, and the thresholds grow with it), so a search that tests with
    /// them before syncing prunes less but never wrongly.
    #[inline]
    pub(crate) fn offer_unsynced(&mut self, n: Neighbor) {
        if n.distance > self.limit || self.k == 0 {
            return;
        }
        let (h, k) = (&mut *self.held, self.k);
        if self.sorted {
            if k <= LINEAR_MAX_K {
                // Shift the entries `n` precedes up by one from the end: for
                // small `k` about as many instructions as a binary search and
                // `Vec::insert`'s memmove call (~150 an offer at k = 10,
                // callgrind), but no call, and faster in time (the probe
                // `knn_leaf`, 100k points, k = 10, one run each: 3.0 -> 2.2 µs
                // a query together with the reused squared distance). The
                // same position: the entries `n` precedes are exactly those
                // after `insertion_point`. A full set drops its last entry by
                // writing over it; the shift runs on a plain slice, whose
                // length stays in a register (through the `Vec` it was
                // re-read each step: 135 -> 111 instructions an offer).
                let s: &mut [Neighbor] = if h.len() == k {
                    if !Neighbor::precedes(&n, &h[k - 1]) {
                        return;
                    }
                    h
                } else {
                    h.push(n);
                    h
                };
                let mut i = s.len() - 1;
                while i > 0 && Neighbor::precedes(&n, &s[i - 1]) {
                    s[i] = s[i - 1];
                    i -= 1;
                }
                s[i] = n;
            } else {
                if h.len() == k {
                    if !Neighbor::precedes(&n, &h[k - 1]) {
                        return;
                    }
                    h.pop();
                }
                let i = insertion_point(h, &n);
                h.insert(i, n);
            }
            if h.len() == k {
                let worst = h[k - 1].distance;
                self.bound = worst;
            }
            return;
        }
        if h.len() < k {
            h.push(n);
            let mut i = h.len() - 1;
            while i > 0 {
                let p = (i - 1) / 2;
                if Neighbor::precedes(&h[p], &h[i]) {
                    h.swap(p, i);
                    i = p;
                } else {
                    break;
                }
            }
        } else if Neighbor::precedes(&n, &h[0]) {
            h[0] = n;
            let mut i = 0;
            loop {
                let (l, r) = (2 * i + 1, 2 * i + 2);
                let mut m = i;
                if l < h.len() && Neighbor::precedes(&h[m], &h[l]) {
                    m = l;
                }
                if r < h.len() && Neighbor::precedes(&h[m], &h[r]) {
                    m = r;
                }
                if m == i {
                    break;
                }
                h.swap(i, m);
                i = m;
            }
        } else {
            return;
        }
        if h.len() == k {
            let worst = h[0].distance;
            self.bound = worst;
        }
    }

    /// Puts the held candidates in answer order: nothing to do when sorted,
    /// else O(k log k).
    pub(crate) fn finish(self) {
        if !self.sorted {
            self.held.sort_unstable_by(Neighbor::order);
        }
    }
}

/// Radius of the first sphere query: small, so that a dense neighbourhood
/// costs few candidates; it grows geometrically from there.
const FIRST_RADIUS: f32 = 1.0 / 1024.0;

/// Beyond this radius the search stops growing and scans every object (the
/// sphere's `f32` radius must stay finite, and queries this wide select most
/// of an index anyway).
const SCAN_RADIUS: f32 = 1e30;

/// A box containing every finite sphere's centre: a sphere query for it
/// selects every stored object.
const EVERYTHING: Aabb = Aabb {
    min: Vec3::splat(-f32::MAX),
    max: Vec3::splat(f32::MAX),
};

/// The reference k-nearest search, correct for every index: sphere queries of
/// growing radius `r` around the point until one proves that the `k` nearest
/// are among what it selected, then a sort of those candidates.
///
/// Why it is exact: the query selects, exactly, every object whose surface
/// distance is at most `next_up(r)`; distances are correctly rounded, hence
/// monotone, so an object whose (rounded) distance is at most `r` in either
/// metric is selected (its exact distance is below `r`'s upper rounding
/// midpoint, less than `next_up(r)`, and the surface distance is at most the
/// centre distance). The search stops when (a) at least `k` candidates are at
/// most `r` away: the `k`-th smallest distance `D` is then at most `r`, so
/// every object at most `D` away is a candidate and ties at `D` are all seen;
/// (b) `r >= max_distance`: every object within the limit is a candidate;
/// (c) the query selected every object; or (d) `r` passed [`SCAN_RADIUS`],
/// when one scan of everything decides. The filter is applied to candidates.
///
/// Cost: O(rounds × sphere query) with `r` growing 2–8× per round from
/// [`FIRST_RADIUS`], plus a selection over the candidates; `out` is the only
/// buffer (no allocation once it has grown).
pub(crate) fn expanding<T, I: Walk<T> + ?Sized>(
    index: &I,
    q: &Nearest,
    filter: Option<Filter>,
    out: &mut Vec<Neighbor>,
) {
    out.clear();
    let n = index.object_count();
    if q.k == 0 || n == 0 {
        return;
    }
    let keep = |h: Handle| filter.is_none_or(|f| f.interacts(index.filter_of(h)));
    let mut r = FIRST_RADIUS.min(q.max_distance);
    loop {
        if r > SCAN_RADIUS {
            out.clear();
            let _ = index.walk(&EVERYTHING, |h, s, _| {
                if keep(h) {
                    let distance = q.metric.distance(q.point, s);
                    if distance <= q.max_distance {
                        out.push(Neighbor {
                            handle: h,
                            distance,
                        });
                    }
                }
                ControlFlow::Continue(())
            });
            break;
        }
        out.clear();
        let (mut seen, mut close) = (0usize, 0usize);
        let reach = Sphere::new(q.point, r.next_up());
        let _ = index.walk(&reach, |h, s, _| {
            seen += 1;
            if keep(h) {
                let distance = q.metric.distance(q.point, s);
                if distance <= q.max_distance {
                    out.push(Neighbor {
                        handle: h,
                        distance,
                    });
                    close += (distance <= r) as usize;
                }
            }
            ControlFlow::Continue(())
        });
        if close >= q.k || r >= q.max_distance || seen >= n {
            break;
        }
        r = (r * if close == 0 { 8.0 } else { 2.0 }).min(q.max_distance.max(r));
        // A limit just above `r` may be reached exactly: the next round ends.
    }
    finish(out, q.k);
}

/// Whether some distance from `point` to a sphere inside `extent` may round
/// to infinity (a point near `f32::MAX`). The grids' [`grow_box`] takes an
/// infinite face bound for "no more cells", so such queries go to
/// [`expanding`] instead, which ends in one scan of everything (ops proptest:
/// a 2D grid answered nothing where brute force found an object at distance
/// inf).
pub(crate) fn may_overflow(point: Vec3, extent: &crate::geom::Aabb) -> bool {
    let p = point.as_dvec3();
    let far = (p - extent.min.as_dvec3())
        .abs()
        .max((p - extent.max.as_dvec3()).abs());
    // NaN (an infinite coordinate) counts as overflowing too.
    let len = far.length();
    len.is_nan() || len >= f32::MAX as f64 * 0.5
}

/// The grids' k-nearest search [sources: index-queries]: a box of cells
/// growing one face at a time around the query's cell, nearest face first.
///
/// `start` is the query point's cell, already clamped into `cells`, the box
/// of cells that may hold anything (so a query far outside the grid starts
/// at the grid's edge, not at its own far-away cell). `visit(best, slab,
/// seen)` offers every object referenced from the cells of `slab` that was
/// not referenced from any cell of `seen` (empty at first; `seen ∪ slab` is
/// again a box), and may break to say that it offered everything (a store
/// that gave up growing and scanned). `face(a, upper, k)` is the squared
/// distance ([`overlap::point_aabb_distance_sq`]) to a box holding every object
/// whose cells all lie beyond the face of axis `a` starting at key `k` (above
/// it if `upper`, else below); `f64::INFINITY` when nothing can lie there.
/// Squared `f64` bounds tested with [`overlap::distance_exceeds`] cost no
/// square root and never the exact rounding (a face's distance is often an
/// exact `f32` rounding tie, which the correctly rounded distance resolves
/// slowly).
///
/// The box grows across the face with the smallest bound, one layer of cells
/// at a time, and the search stops when that bound surely exceeds the candidate set's
/// [`KBest::bound`] after rounding (strictly: an object at exactly the bound
/// may still enter with a smaller handle) or every face reached the edge of
/// `cells`. An object never seen has all its cells beyond one face, so its distance is at least
/// that face's bound: the answer is brute force's. Growing the nearest face
/// rather than whole rings (Chebyshev shells) costs the same in an even scene
/// and far less for a query outside it, whose k nearest lie in the grid's
/// near layer: rings would sweep the whole grid to prove it. Each face's
/// bound changes only when it moves, so a step costs one bound and one slab.
pub(crate) fn grow_box(
    best: &mut KBest<'_>,
    start: KeyBox,
    cells: KeyBox,
    axes: usize,
    face: impl Fn(usize, bool, i32) -> f64,
    mut visit: impl FnMut(&mut KBest<'_>, &KeyBox, &KeyBox) -> ControlFlow<()>,
) {
    if cells.is_empty() {
        return;
    }
    let mut seen = start;
    if visit(best, &start, &KeyBox::EMPTY).is_break() {
        return;
    }
    let bound_of = |seen: &KeyBox, a: usize, upper: bool| {
        if upper && seen.hi[a] < cells.hi[a] {
            face(a, true, seen.hi[a] + 1)
        } else if !upper && seen.lo[a] > cells.lo[a] {
            face(a, false, seen.lo[a] - 1)
        } else {
            f64::INFINITY
        }
    };
    let mut bounds = [[f64::INFINITY; 2]; 3];
    for (a, b) in bounds.iter_mut().enumerate().take(axes) {
        *b = [bound_of(&seen, a, false), bound_of(&seen, a, true)];
    }
    loop {
        let mut next = (f64::INFINITY, 0, 0);
        for (a, b) in bounds.iter().enumerate().take(axes) {
            for (side, &d) in b.iter().enumerate() {
                if d < next.0 {
                    next = (d, a, side);
                }
            }
        }
        let (d, a, side) = next;
        if d == f64::INFINITY || best.exceeds_sq(d) {
            return;
        }
        let mut slab = seen;
        if side == 1 {
            slab.hi[a] += 1;
            slab.lo[a] = slab.hi[a];
        } else {
            slab.lo[a] -= 1;
            slab.hi[a] = slab.lo[a];
        }
        if visit(best, &slab, &seen).is_break() {
            return;
        }
        if side == 1 {
            seen.hi[a] = slab.hi[a];
        } else {
            seen.lo[a] = slab.lo[a];
        }
        bounds[a][side] = bound_of(&seen, a, side == 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::seq::SliceRandom;
    use rand::{Rng, SeedableRng};

    fn neighbor(index: u32, distance: f32) -> Neighbor {
        Neighbor {
            handle: Handle {
                tag: 7,
                index,
                generation: index % 3,
            },
            distance,
        }
    }

    /// `KBest` in both representations (sorted up to `SORTED_MAX_K`, heap
    /// beyond) against a full sort, on long random sequences dense in exact
    /// ties, duplicates (same handle and distance) and one-ulp near-ties,
    /// for `k` on both sides of the switch, with and without a limit, offered
    /// synced or not (`offer_unsynced`); its bound is the k-th's after every
    /// offer, its pruning tests never prune what `overlap::distance_exceeds`
    /// on that bound keeps, and after `sync` they agree with it.
    #[test]
    fn kbest_matches_a_full_sort_on_both_sides_of_the_switch() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(14);
        let s = SORTED_MAX_K;
        let base = [
            0.0f32,
            1.0,
            1.0 + f32::EPSILON,
            2.0,
            2.0 - f32::EPSILON / 2.0,
        ];
        let l = LINEAR_MAX_K;
        for k in [
            0,
            1,
            2,
            3,
            10,
            16,
            17,
            l,
            l + 1,
            100,
            s - 1,
            s,
            s + 1,
            s + 40,
        ] {
            for limit in [f32::INFINITY, 1.0 + f32::EPSILON, 0.0] {
                let mut out = vec![neighbor(999, 5.0)]; // cleared by `new`
                let mut best = KBest::new(&mut out, k, limit);
                let mut all = Vec::new();
                for step in 0..3 * s {
                    // Few handles and distances: many exact ties and repeats.
                    let d = if rng.gen_bool(0.6) {
                        base[rng.gen_range(0..base.len())]
                    } else {
                        rng.gen_range(0.0f32..3.0)
                    };
                    let n = neighbor(rng.gen_range(0..64), d);
                    if rng.gen_bool(0.5) {
                        best.offer(n);
                    } else {
                        best.offer_unsynced(n);
                    }
                    if d <= limit {
                        all.push(n);
                    }
                    if step % 97 == 0 || step + 1 == 3 * s {
                        let b = best.bound();
                        // Not yet synced: the tests prune only what the
                        // bound prunes.
                        for s2 in [0.0, 1.0, 1.0 + 1e-9, 4.0, 4.0 * (1.0 + 1e-7), 9.0] {
                            let r = 0.25;
                            assert!(!best.exceeds_sq(s2) || overlap::distance_exceeds(s2, 0.0, b));
                            assert!(!best.exceeds(s2, r) || overlap::distance_exceeds(s2, r, b));
                            assert!(
                                s2 as f32 <= best.sq_threshold_f32()
                                    || overlap::sq_threshold_f32(overlap::exceeds_threshold(
                                        overlap::distance_midpoint(b),
                                        0.0
                                    )) < s2 as f32
                            );
                        }
                        best.sync();
                        let mut want = all.clone();
                        want.sort_unstable_by(Neighbor::order);
                        // k = 0 holds nothing: the bound stays the limit.
                        let want_bound = match k.checked_sub(1).and_then(|i| want.get(i)) {
                            Some(worst) => worst.distance,
                            None => limit,
                        };
                        assert_eq!(b.to_bits(), want_bound.to_bits(), "k={k} step {step}");
                        for s2 in [0.0, 1.0, 1.0 + 1e-9, 4.0, 4.0 * (1.0 + 1e-7), 9.0] {
                            let r = 0.25;
                            assert_eq!(best.exceeds_sq(s2), overlap::distance_exceeds(s2, 0.0, b));
                            assert_eq!(best.exceeds(s2, r), overlap::distance_exceeds(s2, r, b));
                        }
                    }
                }
                best.finish();
                all.sort_unstable_by(Neighbor::order);
                all.truncate(k);
                assert_eq!(out, all, "k={k} limit {limit}");
            }
        }
    }

    /// `seed_unsynced` leaves the set exactly as offering its group one by
    /// one does (entries, their order or heap layout's answer, bound, and
    /// what later offers do), on groups of distinct handles dense in tied
    /// and one-ulp-apart distances, in order, nearly in order and shuffled,
    /// shorter and longer than `k`, with and without a limit, for `k` on
    /// both sides of the sorted/heap switch.
    #[test]
    fn seed_unsynced_is_offering_one_by_one() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(15);
        let ds = [-0.0f32, 0.0, 1.0, 1.0 + f32::EPSILON, 2.0, 3.0];
        for round in 0..6000 {
            let k = [1, 2, 5, 10, LINEAR_MAX_K, 40, SORTED_MAX_K + 3][round % 7];
            // Independent of the group's order below (round % 3).
            let limit = [f32::INFINITY, 1.0 + f32::EPSILON, 0.0][round / 7 % 3];
            // Half the heap rounds fill the set (a wrong heap layout shows
            // only then).
            let len = if k > SORTED_MAX_K && rng.gen_bool(0.5) {
                rng.gen_range(k..=k + 4)
            } else {
                rng.gen_range(0..=k + 4)
            };
            let mut handles: Vec<u32> = (0..600).collect();
            handles.shuffle(&mut rng);
            let mut group: Vec<Neighbor> = handles[..len]
                .iter()
                .map(|&i| {
                    let d = if rng.gen_bool(0.5) {
                        ds[rng.gen_range(0..ds.len())]
                    } else {
                        rng.gen_range(0.0f32..3.0)
                    };
                    neighbor(i, d)
                })
                .collect();
            match round % 3 {
                0 => group.sort_unstable_by(Neighbor::order),
                1 => {
                    group.sort_unstable_by(|a, b| a.distance.total_cmp(&b.distance));
                    if len > 1 {
                        let i = rng.gen_range(0..len - 1);
                        group.swap(i, i + 1);
                    }
                }
                _ => {}
            }
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let mut seeded = KBest::new(&mut a, k, limit);
            let mut offered = KBest::new(&mut b, k, limit);
            seeded.seed_unsynced(group.iter().copied());
            for &n in &group {
                offered.offer_unsynced(n);
            }
            assert_eq!(
                seeded.bound().to_bits(),
                offered.bound().to_bits(),
                "round {round}"
            );
            // Later offers see the same set.
            for _ in 0..4 {
                let n = neighbor(rng.gen_range(600..660), ds[rng.gen_range(0..ds.len())]);
                seeded.offer(n);
                offered.offer(n);
                assert_eq!(seeded.bound().to_bits(), offered.bound().to_bits());
            }
            seeded.finish();
            offered.finish();
            assert_eq!(a, b, "round {round}: k {k}, limit {limit}, {group:?}");
        }
    }

    /// `precedes` is `order(..).is_lt()` on every pair of a set dense in
    /// equal distances, signed zeros, subnormals and infinities.
    #[test]
    fn precedes_is_the_answer_order() {
        let ds = [
            -0.0f32,
            0.0,
            f32::from_bits(1),
            f32::MIN_POSITIVE,
            1.0,
            1.0 + f32::EPSILON,
            f32::MAX,
            f32::INFINITY,
        ];
        let all: Vec<Neighbor> = ds
            .iter()
            .flat_map(|&d| (0..6).map(move |i| neighbor(i, d)))
            .collect();
        for a in &all {
            for b in &all {
                assert_eq!(
                    Neighbor::precedes(a, b),
                    Neighbor::order(a, b).is_lt(),
                    "{a:?} {b:?}"
                );
            }
        }
    }

    /// `insertion_point` is the binary search on `precedes` it replaces, on
    /// sorted buffers of every length up to 40 drawn from few distances
    /// (long runs of equal distances, `-0.0` beside `0.0`, subnormals, `∞`)
    /// and few handles (duplicates), for candidates inside and outside them.
    #[test]
    fn insertion_point_is_the_precedes_search() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(41);
        let ds = [
            -0.0f32,
            0.0,
            f32::from_bits(1),
            1.0,
            1.0 + f32::EPSILON,
            f32::INFINITY,
        ];
        let pick = |rng: &mut rand_pcg::Pcg64| {
            neighbor(rng.gen_range(0..8), ds[rng.gen_range(0..ds.len())])
        };
        for _ in 0..4000 {
            let len = rng.gen_range(0..=40);
            let mut h: Vec<Neighbor> = (0..len).map(|_| pick(&mut rng)).collect();
            h.sort_unstable_by(Neighbor::order);
            for _ in 0..8 {
                let n = pick(&mut rng);
                assert_eq!(
                    insertion_point(&h, &n),
                    h.partition_point(|e| Neighbor::precedes(e, &n)),
                    "{n:?} into {h:?}"
                );
            }
        }
    }

    /// `tighten_by_centres` never cuts the answer: on random groups of
    /// points at every magnitude (and coarse grids dense in exact ties and
    /// duplicates), with `k` on both sides of its linear selection, the
    /// limit it sets is at least the `k`-th smallest correctly rounded
    /// centre distance of the group (so at least `k` objects stay within
    /// it in either metric), and within 1e-6 of it, so it does prune (a
    /// limit of `∞` everywhere would pass the first check). With fewer
    /// than `k` values, or a lower limit already, it changes nothing.
    #[test]
    fn tighten_by_centres_keeps_k_within_the_limit() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(43);
        let mut tight = 0;
        for round in 0..20_000 {
            let scale = 10f32.powi(rng.gen_range(-30..30));
            let coarse = round % 3 == 0;
            let u = |rng: &mut rand_pcg::Pcg64| {
                if coarse {
                    rng.gen_range(-4i32..=4) as f32 * 0.5 * scale
                } else {
                    rng.gen_range(-1.0f32..1.0) * scale
                }
            };
            let p = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng));
            let n = rng.gen_range(0..=SEED_MAX);
            let centres: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)))
                .collect();
            let mut exact: Vec<f32> = centres
                .iter()
                .map(|&c| overlap::point_sphere_distance(p, &Sphere::new(c, 0.0)))
                .collect();
            exact.sort_unstable_by(f32::total_cmp);
            let k = [
                1,
                2,
                3,
                4,
                5,
                10,
                16,
                17,
                LINEAR_MAX_K,
                LINEAR_MAX_K + 1,
                40,
            ][round % 11];
            let limit = if round % 13 == 0 { 0.0 } else { f32::INFINITY };
            let s2: Vec<f64> = centres
                .iter()
                .map(|&c| overlap::point_point_distance_sq(p, c))
                .collect();
            let mut out = Vec::new();
            let mut best = KBest::new(&mut out, k, limit);
            let mut first = [0u8; LINEAR_MAX_K];
            let taken = best.tighten_by_centres(&s2, &mut first);
            let got = best.bound();
            // The first `k`: distinct, nearest first and none farther than
            // an item left out, both up to the 64 ulps of the index bits.
            let expect = if k <= LINEAR_MAX_K && (k..=SEED_MAX).contains(&s2.len()) {
                k
            } else {
                0
            };
            assert_eq!(taken, expect, "k {k}, {n} values");
            let coarse_bits = |i: u8| s2[i as usize].to_bits() >> 6;
            let first = &first[..taken];
            for (j, &i) in first.iter().enumerate() {
                assert!(!first[..j].contains(&i), "index {i} twice");
                if j > 0 {
                    assert!(coarse_bits(first[j - 1]) <= coarse_bits(i), "out of order");
                }
            }
            if let Some(&last) = first.last() {
                for u in (0..s2.len() as u8).filter(|u| !first.contains(u)) {
                    assert!(
                        coarse_bits(u) >= coarse_bits(last),
                        "{u} left out but nearer"
                    );
                }
            }
            match exact.get(k - 1) {
                Some(&kth) if kth < limit => {
                    assert!(
                        got >= kth,
                        "k {k}: limit {got} below the k-th distance {kth}"
                    );
                    assert!(got as f64 <= kth as f64 * (1.0 + 1e-6), "{got} vs {kth}");
                    tight += (got < f32::INFINITY) as u32;
                }
                _ => assert_eq!(got.to_bits(), limit.to_bits(), "k {k}, {n} values"),
            }
        }
        assert!(tight > 8_000, "{tight}");
    }

    /// The cached midpoint at the bounds the searches meet: `-0.0` is `0`
    /// (anything farther than half the smallest subnormal exceeds it), and
    /// nothing exceeds `f32::MAX` or `∞` (the next `f32` up overflows).
    #[test]
    fn distance_midpoint_at_the_edges() {
        assert_eq!(
            overlap::distance_midpoint(-0.0),
            overlap::distance_midpoint(0.0)
        );
        assert!(overlap::distance_exceeds(1e-90, 0.0, -0.0));
        assert!(!overlap::distance_exceeds(1e-92, 0.0, -0.0));
        assert_eq!(overlap::distance_midpoint(f32::INFINITY), f64::INFINITY);
        assert!(!overlap::distance_exceeds(1e76, 0.0, f32::INFINITY));
        assert_eq!(overlap::distance_midpoint(f32::MAX), f64::INFINITY);
        assert!(!overlap::distance_exceeds(f64::MAX, 0.0, f32::MAX));
    }
}
