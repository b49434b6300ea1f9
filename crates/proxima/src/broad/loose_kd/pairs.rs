//! Self-collision: every overlapping pair once, by walking the tree node against
//! node (not one query per object).
//!
//! A pair `(x, y)` with `x` at node `X` and `y` at node `Y` falls in exactly one
//! case, each handled once:
//! - `X == Y`: the items of a node against each other;
//! - `X` a proper ancestor of `Y`: during the depth-first walk each node carries
//!   the *active set*, the ancestors' items that can reach its region; it is
//!   filtered by one split-axis comparison per level and tested against the
//!   node's items;
//! - neither: `X` and `Y` lie in the two children of their lowest common ancestor
//!   `A`, which runs `cross(A⁻, A⁺)` once: the items of the negative subtree that
//!   reach the positive child's region are gathered, then carried down the
//!   positive subtree as an active set and tested only against the items there
//!   that reach back into the negative child's region. The two children's regions
//!   overlap only in the border zone `[m - h, m + h]`, so only items near it take
//!   part on either side.
//!
//! Collision filters prune the walk [sources: index-queries]: inert objects
//! (group or mask zero) are never carried nor tested, and `cross` skips the two
//! subtrees, or any subtree on either side, whose filter bits (OR of the groups,
//! OR of the masks, kept per node) cannot interact with the other side's. The
//! filter of a pair found is still checked before it is reported.
//!
//! The walks read each node's objects where they are stored: a contiguous range
//! of the tree's object array (`store.rs`), which compaction keeps in the
//! depth-first order of this walk; the carried sets are copies of the spheres, one array per
//! coordinate (structure of arrays, see [`Carried`]), with the object's position
//! in that array, so the inner loop tests one sphere against four carried ones with a
//! branch-free `f32` pre-test that vectorizes (`overlap::sphere_sphere_candidate`)
//! and runs the exact test only on the few candidates; only a reported pair goes
//! back to the object array for its handle and payload. A node's own objects are appended
//! to the carried set first, so "own against ancestors" and "own against own" are
//! the same scan. A node with many own objects (they stop where `r >= h`, so
//! they are spread over its whole box) sweeps them and the carried set on its
//! split axis instead of testing all pairs, through the same scan over windows
//! of a bucket order; the carried set is narrowed at each level except before a
//! small leaf, where the copy would cost more than the tests it saves.

use super::node::{FixedStack, NIL};
use super::LooseKdTree;
use crate::broad::Filter;
use crate::geom::{overlap, Sphere};
use crate::Handle;
use glam::{Vec3, Vec4};
use std::ops::ControlFlow;
use std::sync::{Mutex, TryLockError};

/// Below this many own objects in a node, the node's tests are all-pairs
/// through the vectorized [`Carried::scan`]; from it on they use the bucketed
/// sweep on the split axis (`LooseKdTree::sweep`, O(k) set-up for k own and
/// carried objects). W1 100k (callgrind, 2 frames): the sweep from 16 or 32 own
/// objects cut the pair search's instructions by 15%, the same for both; the
/// nodes it runs on hold ~114 objects. The earlier comparison sort with a
/// scalar sweep paid only from 256 objects (own plus carried).
const SWEEP_MIN: usize = 32;

/// Leaves with fewer objects are tested against their parent's carried set
/// without narrowing it first (see `worth_filtering`).
const LEAF_FILTER_MIN: usize = 8;

/// Spheres tested at once by the pre-test of [`Carried::scan`]: one SIMD `Vec4`.
const LANES: usize = 4;

/// A stack of carried objects in structure-of-arrays form: coordinates, radius
/// and origin (position in the object array) of entry `i` are `x[i]`, ..., `org[i]`.
/// The vectors are kept at least `len` long (entries past `len` are garbage), so
/// appending a filtered range is a branch-free write-then-advance.
#[derive(Default)]
pub(super) struct Carried {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    r: Vec<f32>,
    org: Vec<u32>,
    len: usize,
}

impl Carried {
    #[inline]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    #[inline]
    pub(super) fn truncate(&mut self, len: usize) {
        self.len = self.len.min(len);
    }

    /// Makes room for `extra` more entries.
    #[inline]
    fn reserve(&mut self, extra: usize) {
        let need = self.len + extra;
        if self.x.len() < need {
            let cap = need.max(2 * self.x.len()).max(64);
            self.x.resize(cap, 0.0);
            self.y.resize(cap, 0.0);
            self.z.resize(cap, 0.0);
            self.r.resize(cap, 0.0);
            self.org.resize(cap, 0);
        }
    }

    /// Writes `s` at the end; it is kept only if `keep` (branch-free). Needs
    /// room (see `reserve`).
    #[inline]
    fn put(&mut self, s: &Sphere, org: u32, keep: bool) {
        let k = self.len;
        self.x[k] = s.center.x;
        self.y[k] = s.center.y;
        self.z[k] = s.center.z;
        self.r[k] = s.radius;
        self.org[k] = org;
        self.len += keep as usize;
    }

    /// Appends the objects at positions `start..` of the object array whose
    /// spheres are `spheres` and for which `keep(position, sphere)` holds.
    #[inline]
    pub(super) fn push_node(
        &mut self,
        start: usize,
        spheres: &[Sphere],
        keep: impl Fn(usize, &Sphere) -> bool,
    ) {
        self.reserve(spheres.len());
        for (i, s) in spheres.iter().enumerate() {
            self.put(s, (start + i) as u32, keep(start + i, s));
        }
    }

    /// Copies entry `i` to position `k` (past `len`: see `reserve`).
    #[inline]
    fn copy_to(&mut self, i: usize, k: usize) {
        self.x[k] = self.x[i];
        self.y[k] = self.y[i];
        self.z[k] = self.z[i];
        self.r[k] = self.r[i];
        self.org[k] = self.org[i];
    }

    /// Entry `i` as a sphere.
    #[inline]
    fn sphere(&self, i: usize) -> Sphere {
        Sphere::new(Vec3::new(self.x[i], self.y[i], self.z[i]), self.r[i])
    }

    /// Position of entry `i` in the object array.
    #[inline]
    fn origin(&self, i: usize) -> usize {
        self.org[i] as usize
    }

    /// Lower (`c_a - r`) or upper (`c_a + r`) end of entry `i` on `axis`.
    #[inline]
    fn end(&self, i: usize, axis: usize, upper: bool) -> f32 {
        let c = match axis {
            0 => self.x[i],
            1 => self.y[i],
            _ => self.z[i],
        };
        if upper {
            c + self.r[i]
        } else {
            c - self.r[i]
        }
    }

    /// Appends the entries of `from..to` that reach `bound` on `axis` from below
    /// (`c_a + r >= bound`, `upper`) or stay under it (`c_a - r <= bound`).
    pub(super) fn refilter(
        &mut self,
        from: usize,
        to: usize,
        axis: usize,
        bound: f32,
        upper: bool,
    ) {
        match (axis, upper) {
            (0, true) => self.refilter_on::<0, true>(from, to, bound),
            (1, true) => self.refilter_on::<1, true>(from, to, bound),
            (_, true) => self.refilter_on::<2, true>(from, to, bound),
            (0, false) => self.refilter_on::<0, false>(from, to, bound),
            (1, false) => self.refilter_on::<1, false>(from, to, bound),
            (_, false) => self.refilter_on::<2, false>(from, to, bound),
        }
    }

    /// [`Carried::refilter`] for one axis and direction (compiled separately, so
    /// the coordinate array is fixed). Branch-free: every entry is written at the
    /// end, which advances only for kept ones (most are kept, and a branch per
    /// entry measured slower). Reads stay below `to <= len`, writes at or above
    /// `len`, so they never meet.
    fn refilter_on<const A: usize, const UPPER: bool>(
        &mut self,
        from: usize,
        to: usize,
        bound: f32,
    ) {
        let n = to - from;
        self.reserve(n);
        let len = self.len;
        // Sources below `len`, destinations from `len` on: split so that neither
        // side needs a bounds check against the other.
        let (xs, xd) = self.x.split_at_mut(len);
        let (ys, yd) = self.y.split_at_mut(len);
        let (zs, zd) = self.z.split_at_mut(len);
        let (rs, rd) = self.r.split_at_mut(len);
        let (os, od) = self.org.split_at_mut(len);
        let (xs, ys, zs, rs, os) = (
            &xs[from..to],
            &ys[from..to],
            &zs[from..to],
            &rs[from..to],
            &os[from..to],
        );
        let (xd, yd, zd, rd, od) = (
            &mut xd[..n],
            &mut yd[..n],
            &mut zd[..n],
            &mut rd[..n],
            &mut od[..n],
        );
        let mut k = 0;
        for i in 0..n {
            let c = match A {
                0 => xs[i],
                1 => ys[i],
                _ => zs[i],
            };
            let keep = if UPPER {
                c + rs[i] >= bound
            } else {
                c - rs[i] <= bound
            };
            // `k <= i < n`: the clamp only tells the compiler so.
            let w = k.min(n - 1);
            xd[w] = xs[i];
            yd[w] = ys[i];
            zd[w] = zs[i];
            rd[w] = rs[i];
            od[w] = os[i];
            k += keep as usize;
        }
        self.len = len + k;
    }

    /// Calls `hit(i)` for every entry `i` in `from..to` whose sphere overlaps `s`
    /// (closed, exact). Four entries at a time go through the SIMD `f32` pre-test
    /// (`overlap::sphere_sphere_candidates4`); only its candidates take the exact
    /// test, which decides.
    #[inline]
    fn scan(
        &self,
        from: usize,
        to: usize,
        s: &Sphere,
        mut hit: impl FnMut(usize) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (sx, sy, sz, sr) = (s.center.x, s.center.y, s.center.z, s.radius);
        // Cut once, so the chunks below need no bounds checks.
        let (xs, ys, zs, rs) = (
            &self.x[from..to],
            &self.y[from..to],
            &self.z[from..to],
            &self.r[from..to],
        );
        let quads = xs
            .chunks_exact(LANES)
            .zip(ys.chunks_exact(LANES))
            .zip(zs.chunks_exact(LANES).zip(rs.chunks_exact(LANES)));
        let mut i = from;
        for ((cx, cy), (cz, cr)) in quads {
            let mut mask = overlap::sphere_sphere_candidates4(
                Vec4::from_slice(cx),
                Vec4::from_slice(cy),
                Vec4::from_slice(cz),
                Vec4::from_slice(cr),
                s,
            );
            while mask != 0 {
                let k = i + mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if overlap::sphere_sphere(&self.sphere(k), s) {
                    hit(k)?;
                }
            }
            i += LANES;
        }
        for k in i..to {
            if overlap::sphere_sphere_candidate(
                self.x[k], self.y[k], self.z[k], self.r[k], sx, sy, sz, sr,
            ) && overlap::sphere_sphere(&self.sphere(k), s)
            {
                hit(k)?;
            }
        }
        ControlFlow::Continue(())
    }

    /// Makes this the copy of the first `len` entries of `other`.
    #[cfg(feature = "parallel")]
    pub(super) fn copy_from(&mut self, other: &Carried, len: usize) {
        self.x.clear();
        self.x.extend_from_slice(&other.x[..len]);
        self.y.clear();
        self.y.extend_from_slice(&other.y[..len]);
        self.z.clear();
        self.z.extend_from_slice(&other.z[..len]);
        self.r.clear();
        self.r.extend_from_slice(&other.r[..len]);
        self.org.clear();
        self.org.extend_from_slice(&other.org[..len]);
        self.len = len;
    }

    fn heap_bytes(&self) -> usize {
        4 * self.x.capacity() * std::mem::size_of::<f32>()
            + self.org.capacity() * std::mem::size_of::<u32>()
    }
}

/// The pair search's buffers: the carried set and the sweep's bucket sort
/// (per entry its bucket, per bucket its first and then its end slot, per slot
/// the entry it holds).
#[derive(Default)]
pub(super) struct Buffers {
    pub(super) c: Carried,
    bucket: Vec<u32>,
    start: Vec<u32>,
    order: Vec<u32>,
}

impl Buffers {
    fn heap_bytes(&self) -> usize {
        self.c.heap_bytes()
            + (self.bucket.capacity() + self.start.capacity() + self.order.capacity())
                * std::mem::size_of::<u32>()
    }
}

/// The pair search's buffers, kept in the tree between calls so that a
/// steady-state `for_each_pair` does not allocate. Behind a mutex because the
/// search takes `&self`; a call that finds it taken (a concurrent or nested
/// search) uses fresh buffers instead. Cloning gives empty buffers.
#[derive(Default)]
pub(super) struct PairScratch(Mutex<Buffers>);

impl Clone for PairScratch {
    fn clone(&self) -> Self {
        PairScratch::default()
    }
}

impl std::fmt::Debug for PairScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PairScratch")
    }
}

impl PairScratch {
    /// Heap bytes held by the buffers (0 if they are in use).
    pub(super) fn heap_bytes(&self) -> usize {
        match self.0.try_lock() {
            Ok(b) => b.heap_bytes(),
            Err(_) => 0,
        }
    }
}

impl<T> LooseKdTree<T> {
    pub(super) fn pairs_impl(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        if self.root == NIL {
            return ControlFlow::Continue(());
        }
        let mut fresh = Buffers::default();
        let mut guard = match self.scratch.0.try_lock() {
            Ok(g) => Some(g),
            // A panic in an earlier callback left the buffers in some state; they
            // are cleared below anyway.
            Err(TryLockError::Poisoned(p)) => Some(p.into_inner()),
            Err(TryLockError::WouldBlock) => None,
        };
        let b = guard.as_deref_mut().unwrap_or(&mut fresh);
        b.c.truncate(0);
        self.self_pairs(self.root, 0, b, &mut f)
    }

    /// Whether the object at position `p` may enter the pair search: not
    /// inert, or no inert object stored at all (then no filter is read).
    #[inline]
    fn pairable(&self, p: usize) -> bool {
        !self.inert.any() || !self.store.full(p).1.is_inert()
    }

    /// The filter bits of node `n`'s subtree as one filter (OR of the groups,
    /// OR of the masks): a subtree whose bits cannot interact with another's
    /// ([`Filter::may_interact`]) holds no pair with it.
    #[inline]
    fn bits(&self, n: u32) -> Filter {
        let node = &self.nodes[n];
        Filter::new(node.groups, node.masks)
    }

    /// Reports carried entry `i` with carried entry `j`, if their filters
    /// interact.
    #[inline]
    fn report(
        &self,
        c: &Carried,
        i: usize,
        j: usize,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.report_at(c, i, c.origin(j), f)
    }

    /// Reports carried entry `i` with the object at position `y`, if their
    /// filters interact (read from the entries the report reads anyway).
    #[inline]
    fn report_at(
        &self,
        c: &Carried,
        i: usize,
        y: usize,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (xh, xf, xv) = self.store.full(c.origin(i));
        let (yh, yf, yv) = self.store.full(y);
        if xf.interacts(yf) {
            f(xh, xv, yh, yv)
        } else {
            ControlFlow::Continue(())
        }
    }

    /// Whether to narrow the carried set before visiting node `c`. The filter only
    /// saves work (a superset of the objects that can reach `c` gives the same
    /// pairs): it costs a copy per carried object, and for a leaf with few objects
    /// that is more than the sphere tests it saves, so such a leaf is tested
    /// against its parent's set as it is.
    #[inline]
    pub(super) fn worth_filtering(&self, c: u32) -> bool {
        let node = &self.nodes[c];
        node.child != [NIL, NIL] || node.len as usize >= LEAF_FILTER_MIN
    }

    /// Prepares the carried set `c[active..end]` (objects that reach `n`'s region)
    /// for a visit of child `side` of `n`, returning where the child's active set
    /// starts: either the same range, or a narrowed copy appended at `end`.
    #[inline]
    pub(super) fn narrow(
        &self,
        n: u32,
        side: usize,
        active: usize,
        end: usize,
        c: &mut Carried,
    ) -> usize {
        let ch = self.nodes[n].child[side];
        if self.worth_filtering(ch) {
            self.filter_into_child(n, side, active, end, c);
            end
        } else {
            active
        }
    }

    /// Appends to the carried set the entries of `from..to` that can reach child
    /// `side` of `n`: one comparison on the split axis.
    #[inline]
    pub(super) fn filter_into_child(
        &self,
        n: u32,
        side: usize,
        from: usize,
        to: usize,
        c: &mut Carried,
    ) {
        let node = &self.nodes[n];
        let a = node.axis as usize;
        if side == 1 {
            c.refilter(from, to, a, self.pos_floor(node), true);
        } else {
            c.refilter(from, to, a, self.neg_ceil(node), false);
        }
    }

    /// The pairs of node `n`'s own objects with each other and with the active set
    /// `b.c[active..]`; appends the own objects to the carried set (they are the
    /// entries from the returned index on).
    pub(super) fn own_pairs(
        &self,
        n: u32,
        active: usize,
        b: &mut Buffers,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        let start = node.start as usize;
        let own = &self.store.sphere[node.range()];
        let base = b.c.len();
        if !self.inert.any() {
            // Every object takes part: the own objects are read in place (one
            // sphere load each; the loop below rebuilds them from the carried
            // set, which cost W1 100k 5% more instructions).
            b.c.push_node(start, own, |_, _| true);
            if own.len() >= SWEEP_MIN {
                return self.sweep(active, base, node.axis as usize, b, f);
            }
            let c = &b.c;
            for (i, y) in own.iter().enumerate() {
                c.scan(active, base + i, y, |k| self.report_at(c, k, start + i, f))?;
            }
            return ControlFlow::Continue(());
        }
        // Inert objects stay out: neither carried down nor tested here.
        b.c.push_node(start, own, |p, _| self.pairable(p));
        let end = b.c.len();
        if end - base >= SWEEP_MIN {
            self.sweep(active, base, node.axis as usize, b, f)?;
        } else {
            let c = &b.c;
            for k in base..end {
                let p = c.origin(k);
                c.scan(active, k, &c.sphere(k), |j| self.report_at(c, j, p, f))?;
            }
        }
        ControlFlow::Continue(())
    }

    /// All pairs within the subtree of `n`, plus its items against the active set
    /// `b.c[active..]` (ancestors' items that reach `n`'s region).
    pub(super) fn self_pairs(
        &self,
        n: u32,
        active: usize,
        b: &mut Buffers,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.own_pairs(n, active, b, f)?;
        let node = &self.nodes[n];
        let end = b.c.len();
        for side in 0..2 {
            let c = node.child[side];
            if c == NIL {
                continue;
            }
            let child_active = self.narrow(n, side, active, end, &mut b.c);
            self.self_pairs(c, child_active, b, f)?;
            b.c.truncate(end);
        }
        if node.child[0] != NIL && node.child[1] != NIL {
            self.cross(n, b, f)?;
        }
        ControlFlow::Continue(())
    }

    /// The pairs among the carried entries `active..` except those between two
    /// entries below `own` (carried objects were paired higher up), by a sweep on
    /// `axis`: the entries are ordered by the bucket of their lower end on
    /// `axis` (a counting sort, one bucket per entry over the range of the lower
    /// ends) and copied in that order to the end of the carried set; each is then
    /// tested, four at a time through [`Carried::scan`], only against the
    /// following ones up to the end of the bucket where it ends. A node's own
    /// objects are spread over its whole box (they stop there because `r >= h`,
    /// wherever their centre is), so most of them are far apart on the node's
    /// longest axis, the one it splits: W1 100k keeps ~114 objects in each node of
    /// depth 9, and all-pairs tested each against ~57 of its own. O(k) for k
    /// entries, plus the tests in the windows.
    ///
    /// Why no pair is missed: overlapping spheres (closed, as `overlap`
    /// computes it in `f32`) have centres at most `r_a + r_b` apart on every axis,
    /// so the later one's lower end is at most the earlier one's upper end (`eps`
    /// absorbs the rounding of the interval ends); the bucket map is
    /// non-decreasing, so the later one's bucket is at most the bucket of that
    /// upper end, and the earlier one's window reaches it. Each pair is tested
    /// once, from the entry that comes first in the new order; a window that
    /// runs past the overlapping entries (by a bucket, or up to three lanes)
    /// only tests pairs that do not overlap.
    fn sweep(
        &self,
        active: usize,
        own: usize,
        axis: usize,
        b: &mut Buffers,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let c = &mut b.c;
        let end = c.len();
        let m = end - active;
        let (mut lo_min, mut lo_max) = (f32::INFINITY, f32::NEG_INFINITY);
        for i in active..end {
            let lo = c.end(i, axis, false);
            lo_min = lo_min.min(lo);
            lo_max = lo_max.max(lo);
        }
        // One bucket per entry over [lo_min, lo_max]. The map is non-decreasing
        // in `x` (a rounded difference, a positive factor, a saturating cast and
        // a clamp); a degenerate range puts everything in bucket 0.
        let scale = m as f32 / (lo_max - lo_min);
        let scale = if scale.is_finite() { scale } else { 0.0 };
        let bucket_of = |x: f32| (((x - lo_min) * scale) as usize).min(m - 1);
        b.bucket.clear();
        b.start.clear();
        b.start.resize(m + 1, 0);
        for i in active..end {
            let k = bucket_of(c.end(i, axis, false));
            b.bucket.push(k as u32);
            b.start[k + 1] += 1;
        }
        for k in 0..m {
            b.start[k + 1] += b.start[k];
        }
        // Scatter: afterwards `start[k]` is the end of bucket `k`.
        b.order.clear();
        b.order.resize(m, 0);
        c.reserve(m);
        for (i, &k) in (active..end).zip(&b.bucket) {
            let slot = &mut b.start[k as usize];
            b.order[*slot as usize] = i as u32;
            c.copy_to(i, end + *slot as usize);
            *slot += 1;
        }
        c.len = end + m;
        let (c, order, bucket_end) = (&b.c, &b.order[..], &b.start[..]);
        let mut result = ControlFlow::Continue(());
        for (slot, &i) in order.iter().enumerate() {
            let carried = (i as usize) < own;
            let at = end + slot;
            let hi = c.end(at, axis, true) + self.eps;
            let stop = end + bucket_end[bucket_of(hi)] as usize;
            let s = c.sphere(at);
            result = c.scan(at + 1, stop, &s, |j| {
                if carried && (order[j - end] as usize) < own {
                    return ControlFlow::Continue(());
                }
                self.report(c, at, j, f)
            });
            if result.is_break() {
                break;
            }
        }
        b.c.truncate(end);
        result
    }

    /// Every pair between the subtrees of the two children of `a`. Uses the
    /// carried set above its current end as scratch.
    pub(super) fn cross(
        &self,
        a: u32,
        b: &mut Buffers,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let base = b.c.len();
        let parent = &self.nodes[a];
        let axis = parent.axis as usize;
        let [neg, pos] = parent.child;
        // Each side is pruned by the other's filter bits: none at all when the
        // two subtrees' bits cannot interact.
        let (neg_bits, pos_bits) = (self.bits(neg), self.bits(pos));
        if !neg_bits.may_interact(pos_bits.group, pos_bits.mask) {
            return ControlFlow::Continue(());
        }
        self.gather(neg, axis, self.pos_floor(parent), pos_bits, &mut b.c);
        if b.c.len() > base {
            let border = (axis, self.neg_ceil(parent));
            self.walk(pos, base, border, neg_bits, &mut b.c, f)?;
        }
        b.c.truncate(base);
        ControlFlow::Continue(())
    }

    /// Appends the items of `p`'s subtree whose extent on `axis` reaches `floor`.
    ///
    /// Why this is the whole test: every sphere of the positive sibling has
    /// `min_axis >= floor` (split rule, with slack), and on the other axes both
    /// siblings share the bounds of their parent, so an item of `p` ending before
    /// `floor` overlaps none of them. Inside `p`, only a negative child of a split
    /// on the same axis lowers the upper bound of its spheres (to `m + h`), so it
    /// is skipped when that bound is below `floor`; every other child may reach.
    /// Subtrees whose filter bits cannot interact with `other` (the bits of
    /// the sibling they are gathered for) are skipped, and inert objects.
    fn gather(&self, p: u32, axis: usize, floor: f32, other: Filter, c: &mut Carried) {
        let mut stack = FixedStack::<u32>::new();
        stack.push(p);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if !other.may_interact(node.groups, node.masks) {
                continue;
            }
            c.push_node(
                node.start as usize,
                &self.store.sphere[node.range()],
                |p, s| (s.center[axis] + s.radius >= floor) & self.pairable(p),
            );
            let [neg, pos] = node.child;
            if neg != NIL && (node.axis as usize != axis || self.neg_ceil(node) >= floor) {
                stack.push(neg);
            }
            if pos != NIL {
                stack.push(pos);
            }
        }
    }

    /// Tests the items of `n`'s subtree that reach back across the border
    /// (`c_a - r <= ceil`, the same argument as in `gather`, mirrored) against the
    /// active set `c[active..]`, skipping inert items and the subtrees whose
    /// filter bits cannot interact with `other` (those of the gathered side).
    fn walk(
        &self,
        n: u32,
        active: usize,
        border: (usize, f32),
        other: Filter,
        c: &mut Carried,
        f: &mut impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let node = &self.nodes[n];
        if !other.may_interact(node.groups, node.masks) {
            return ControlFlow::Continue(());
        }
        let end = c.len();
        let (axis, ceil) = border;
        for (p, y) in node.range().zip(&self.store.sphere[node.range()]) {
            if y.center[axis] - y.radius > ceil || !self.pairable(p) {
                continue;
            }
            let cs = &*c;
            cs.scan(active, end, y, |k| self.report_at(cs, k, p, f))?;
        }
        let same_axis = node.axis as usize == axis;
        for side in 0..2 {
            let ch = node.child[side];
            // Checked here too, before the carried set is narrowed for it.
            if ch == NIL || !other.may_interact(self.nodes[ch].groups, self.nodes[ch].masks) {
                continue;
            }
            if same_axis {
                // A split on the border's own axis: every carried item ends below
                // the border's ceiling, so narrowing it to the negative child drops
                // nothing, and the positive child's items all start above its floor,
                // so if that floor is past the ceiling none reaches back (the
                // argument of `gather`, mirrored). Either way no copy is needed.
                if side == 0 {
                    self.walk(ch, active, border, other, c, f)?;
                    continue;
                }
                if self.pos_floor(node) > ceil {
                    continue;
                }
            }
            let child_active = self.narrow(n, side, active, end, c);
            if c.len() > child_active {
                self.walk(ch, child_active, border, other, c, f)?;
            }
            c.truncate(end);
        }
        ControlFlow::Continue(())
    }
}
