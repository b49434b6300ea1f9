//! Rays, segments and sphere sweeps: walk the cells along the ray (a sweep's
//! segment, widened by its radius) inside the occupied box, or scan the
//! occupied cells when the walk would be longer.
//!
//! **Sweeps** [sources: index-queries]: a sphere of radius `r` moving along a
//! segment touches an object iff its contact point lies within `r` of the
//! segment, so the walk follows the segment ([`Cast::path`]) with every
//! strip's parameter interval and cell ranges widened by `r` (plus the
//! rounding of the segment's direction): the cell holding the contact point
//! is in the strip whose interval holds the time of contact. Cells are tested
//! with [`sweep_aabb`](crate::geom::overlap::sweep_aabb) and objects with the
//! exact [`sweep_sphere`](crate::geom::overlap::sweep_sphere), through [`Cast`], so a ray and a sweep share
//! this one walk.
//!
//! The walk is a conservative DDA in strips along the dominant gridded axis `a`
//! of the direction: strip `i` holds the ray for the parameters `[ta, tb]`
//! between its two cell faces (the border strips reach to infinity: coordinates
//! are clamped), and within it the ray spans a range of cells on each other
//! axis (`b`, and `c` unless it is flat), computed from the ray's coordinates at
//! `ta` and `tb`, padded against rounding, and forced to move monotonically from
//! strip to strip. Since `|d_b|, |d_c| <= |d_a|`, a strip spans at most 2 × 2
//! cells plus padding.
//!
//! **Once-only**: with monotone ranges, the strips in which an object's key box
//! appears are consecutive; it is reported in the first one (its predecessor
//! does not meet the box, read from the key box stored in the reference), and
//! there only from the cell `(i, max(b0, lo_b), max(c0, lo_c))`.
//!
//! A ray with no motion along the gridded axes (vertical over the 2D grid)
//! stays in the cells of its origin: a key-box query over them. A hashed store
//! scans its occupied cells instead of walking when the walk would cost more
//! (a long ray over few cells, or padding that widens every strip far from the
//! origin), each object from its own lowest cell.
//!
//! The first hit walks front to back and stops once a hit precedes the start
//! of the strip just finished.

use super::keys::{Key, KeyBox, REL_PAD};
use super::list::{CellEntry, Packed};
use super::store::Store;
use super::CellGrid;
use crate::broad::walk::{Cast, Contact};
use crate::broad::{Filter, RayHit};
use crate::geom::{Aabb, Ray, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// Relative padding of the ray's coordinates (rounding of `o + d t`).
const RAY_PAD: f32 = 1e-5;

/// Strip walks longer than this many lookups per occupied cell scan instead.
const LOOKUPS_PER_STRIP: u64 = 4;

/// What the walk reports to its consumer.
enum Step<'a, P> {
    /// A candidate reference, once per object.
    Candidate(&'a CellEntry<P>),
    /// A strip is finished; every object the ray meets at a parameter below
    /// `t_done` has been reported.
    StripDone { t_done: f32 },
}

/// True if the inclusive ranges `[a0, a1]` and `[b0, b1]` meet (empty ranges,
/// `a0 > a1`, meet nothing).
#[inline]
fn meet((a0, a1): (i32, i32), b0: i32, b1: i32) -> bool {
    a0.max(b0) <= a1.min(b1)
}

/// A strip's raw (unclipped, monotone) cell ranges on the axes `b` and `c`.
type Ranges = [(i32, i32); 2];

impl<T, S: Store> CellGrid<T, S> {
    /// Walks the cells along `cast`'s path (widened by its reach, see
    /// [`Cast::path`]), feeding `step` the candidates whose cells' report
    /// boxes the cast touches (each object at most once) and the strip ends.
    fn walk_ray<C: Cast>(
        &self,
        cast: &C,
        mut step: impl FnMut(Step<'_, S::Packed>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let occ = self.store.occupied();
        if occ.is_empty() || self.refs == 0 {
            return ControlFlow::Continue(());
        }
        let lat = self.store.lattice();
        let lim = lat.limits;
        let (ray, r) = cast.path();
        let (o, d) = (ray.origin, ray.dir);
        // The slab test's rounding grows with the origin's magnitude: pad the
        // boxes by as much so the box test never rejects a sphere the exact test
        // hits.
        let extra = o.abs().max_element() * RAY_PAD;
        // How far beyond the path's padded coordinates a sweep reaches (with
        // the rounding of adding it); 0 for a ray.
        let slack = if r > 0.0 {
            r + (o.abs().max_element() + r) * RAY_PAD
        } else {
            0.0
        };
        // Does the cast touch the spheres reported from `key` by a visit whose
        // ranges start at `from`?
        // Touch tests only (`is_some`): no magnitude needed.
        let entry = cast.entry(0.0);
        let touches = |key: Key, from: Key| {
            let b = self.report_box(&KeyBox::single(key), &KeyBox::single(from), 2.0);
            entry.enter(&b.grown(extra)).is_some()
        };
        let ad = d.abs();
        let (a, b, c) = if S::AXES == 2 {
            if ad.x >= ad.y {
                (0, 1, 2)
            } else {
                (1, 0, 2)
            }
        } else if ad.x >= ad.y && ad.x >= ad.z {
            (0, 1, 2)
        } else if ad.y >= ad.z {
            (1, 2, 0)
        } else {
            (2, 0, 1)
        };
        if d[a] == 0.0 {
            // Vertical over the 2D grid, a zero direction or a sweep of no
            // length: the cells within reach of the origin's point.
            let near = Aabb::new(o - slack, o + slack);
            let kb = lat.aabb_box(&near, S::AXES).intersect(&occ);
            return self.store.cells_in(&kb, |key, es| {
                if !touches(key, kb.lo) {
                    return ControlFlow::Continue(());
                }
                for e in es {
                    if Self::reported_here(e.keys.lo(), &kb, key) {
                        step(Step::Candidate(e))?;
                    }
                }
                ControlFlow::Continue(())
            });
        }

        let forward = d[a] > 0.0;
        // The parameter at which the path's coordinate on `a` is `off` past
        // the cell line `line`.
        let line_t =
            |line: i32, off: f32| (lat.origin[a] + line as f32 * lat.cell + off - o[a]) / d[a];
        // Strip `i`'s parameter interval: where the path is within reach of
        // the cells `i` along `a` (the border strips reach to infinity).
        let enter_t = |i: i32| match forward {
            true if i > lim.lo[a] => line_t(i, -slack),
            false if i < lim.hi[a] => line_t(i + 1, slack),
            _ => f32::NEG_INFINITY,
        };
        let exit_t = |i: i32| match forward {
            true if i < lim.hi[a] => line_t(i + 1, slack),
            false if i > lim.lo[a] => line_t(i, -slack),
            _ => f32::INFINITY,
        };
        // The path's coordinate on `axis` at t, padded and widened by the
        // reach; f32::min/max skip the NaN of ∞ − ∞ at an infinite end.
        let at = |axis: usize, t: f32| {
            let v = if d[axis] == 0.0 {
                o[axis]
            } else {
                o[axis] + d[axis] * t
            };
            let pad = (o[axis].abs() + (d[axis] * t).abs()) * RAY_PAD + slack;
            (v - pad, v + pad)
        };
        let (o0, o1) = if r > 0.0 { at(a, 0.0) } else { (o[a], o[a]) };
        // The strip holding the path at t = 0. `coord` rounds `v - origin`
        // (ops proptest: y = -8.7e-20 in a grid from -16 rounded to 16, the
        // cell above the origin's, whose strip the ray entered only at
        // t = 5e5): step back while the strip starts after t = 0, at most
        // twice, then take the first strip (conservative).
        let early = |s: i32| {
            let inner = if forward {
                s > lim.lo[a]
            } else {
                s < lim.hi[a]
            };
            inner && enter_t(s) > 0.0
        };
        let back = |mut s: i32| {
            for _ in 0..2 {
                if !early(s) {
                    return s;
                }
                s = if forward { s - 1 } else { s + 1 };
            }
            match (early(s), forward) {
                (false, _) => s,
                (true, true) => lim.lo[a],
                (true, false) => lim.hi[a],
            }
        };
        let start = if forward {
            let s = back(lat.coord(o0, a));
            if s > occ.hi[a] {
                return ControlFlow::Continue(());
            }
            s.max(occ.lo[a])
        } else {
            let s = back(lat.coord(o1, a));
            if s < occ.lo[a] {
                return ControlFlow::Continue(());
            }
            s.min(occ.hi[a])
        };
        if enter_t(start) > ray.max_t {
            return ControlFlow::Continue(());
        }
        // The last strip: the cell of the path's end, padded in the direction
        // of travel (far from the origin `o + d t` rounds by up to its
        // magnitude times epsilon, and so do the strips' `t`s, which can then
        // all round to `max_t`: the walk must stop at this cell, not wait for a
        // `t` beyond `max_t`).
        let end = if ray.max_t.is_finite() {
            let (v0, v1) = at(a, ray.max_t);
            if forward {
                lat.coord(v1, a)
            } else {
                lat.coord(v0, a)
            }
        } else if forward {
            lim.hi[a]
        } else {
            lim.lo[a]
        };
        let end = end.clamp(occ.lo[a], occ.hi[a]);
        // One strip: whether a strip follows, its parameter interval
        // `[ta, tb]` and its raw ranges on b and c (a flat c stays at its one
        // cell).
        let strip = |i: i32, prev: Option<(i32, Ranges)>| {
            let more = if forward {
                i < lim.hi[a]
            } else {
                i > lim.lo[a]
            };
            let ta = enter_t(i).max(0.0).min(ray.max_t);
            let tb = exit_t(i).min(ray.max_t).max(ta);
            let mut ranges = [(lim.lo[b], lim.hi[b]), (lim.lo[c], lim.hi[c])];
            for (j, axis) in [b, c].into_iter().enumerate() {
                if axis >= S::AXES {
                    continue;
                }
                let (l0, h0) = at(axis, ta);
                let (l1, h1) = at(axis, tb);
                let (mut r0, mut r1) = lat.span(l0.min(l1), h0.max(h1), axis);
                if let Some((_, p)) = prev {
                    if d[axis] > 0.0 {
                        r0 = r0.max(p[j].0);
                        r1 = r1.max(p[j].1);
                    } else if d[axis] < 0.0 {
                        r0 = r0.min(p[j].0);
                        r1 = r1.min(p[j].1);
                    }
                }
                ranges[j] = (r0, r1);
            }
            (more, ta, tb, ranges)
        };
        let next = |i: i32| if forward { i + 1 } else { i - 1 };
        // The walk is over once the next strip starts beyond the path's end.
        let last = |i: i32, more: bool| !more || i == end || enter_t(next(i)) > ray.max_t;
        if S::SPARSE && !self.walk_is_cheap(&ray, (a, b, c), (start, end), slack, &strip, &last) {
            // Scan: each object from its own lowest cell.
            return self.store.cells(|key, es| {
                if !touches(key, lim.lo) {
                    return ControlFlow::Continue(());
                }
                for e in es {
                    if e.keys.lo() == key {
                        step(Step::Candidate(e))?;
                    }
                }
                ControlFlow::Continue(())
            });
        }

        let mut i = start;
        let mut prev: Option<(i32, Ranges)> = None;
        loop {
            let (more, ta, _, ranges) = strip(i, prev);
            let [(b0, b1), (c0, c1)] = ranges;
            let mut from = [0; 3];
            (from[a], from[b], from[c]) = (i, b0, c0);
            let mut cells = KeyBox::single(from);
            (cells.hi[b], cells.hi[c]) = (b1, c1);
            self.store.cells_in(&cells, |key, es| {
                if !touches(key, from) {
                    return ControlFlow::Continue(());
                }
                for e in es {
                    let (lo, hi) = (e.keys.lo(), e.keys.hi());
                    if key[b] != b0.max(lo[b]) || key[c] != c0.max(lo[c]) {
                        continue;
                    }
                    if let Some((pi, p)) = prev {
                        if lo[a] <= pi
                            && pi <= hi[a]
                            && meet(p[0], lo[b], hi[b])
                            && meet(p[1], lo[c], hi[c])
                        {
                            continue; // met in the previous strip
                        }
                    }
                    step(Step::Candidate(e))?;
                }
                ControlFlow::Continue(())
            })?;
            prev = Some((i, ranges));
            // Everything whose contact lies before this strip's start was met
            // in earlier strips (a whole strip of margin absorbs rounding).
            step(Step::StripDone { t_done: ta })?;
            if last(i, more) {
                break;
            }
            i = next(i);
            if i < occ.lo[a] || i > occ.hi[a] {
                break;
            }
        }
        ControlFlow::Continue(())
    }

    /// Whether walking the strips `start ..= end` (along `a`) costs no more
    /// than a few lookups per occupied cell; else the caller scans. Far from
    /// the origin the padding can make every strip as wide as the occupied
    /// box (a fuzzed ray took 89 s walking), and so can a sweep's reach: when
    /// the padding and reach may exceed half a cell somewhere along the walk,
    /// a dry run of it (arithmetic only) adds up the strips' clipped areas.
    fn walk_is_cheap(
        &self,
        ray: &Ray,
        (a, b, c): (usize, usize, usize),
        (start, end): (i32, i32),
        slack: f32,
        strip: &impl Fn(i32, Option<(i32, Ranges)>) -> (bool, f32, f32, Ranges),
        last: &impl Fn(i32, bool) -> bool,
    ) -> bool {
        let cells = self.store.cell_count() as u64;
        let walk = (end as i64 - start as i64).unsigned_abs() + 1;
        if walk.saturating_mul(LOOKUPS_PER_STRIP) > cells {
            return false;
        }
        let lat = self.store.lattice();
        // The largest parameter of the walk, and the padding there.
        let (_, _, t_end, _) = strip(end, None);
        let mag = (ray.origin.abs() + ray.dir.abs() * t_end).max_element();
        if 2.0 * (mag * (RAY_PAD + 1.1 * REL_PAD) + lat.pad + slack) < lat.cell {
            // At most 4 cells per axis in each strip.
            return true;
        }
        let occ = self.store.occupied();
        let area = |ranges: Ranges| {
            let [(b0, b1), (c0, c1)] = ranges;
            let (rb0, rb1) = (b0.max(occ.lo[b]), b1.min(occ.hi[b]));
            let (rc0, rc1) = (c0.max(occ.lo[c]), c1.min(occ.hi[c]));
            ((rb1 as i64 - rb0 as i64 + 1).max(0) * (rc1 as i64 - rc0 as i64 + 1).max(0)) as u64
        };
        let budget = LOOKUPS_PER_STRIP.saturating_mul(cells) + 64;
        let forward = ray.dir[a] > 0.0;
        let mut i = start;
        let mut cost = 0u64;
        let mut prev = None;
        loop {
            let (more, _, _, ranges) = strip(i, prev);
            cost = cost.saturating_add(area(ranges).min(cells));
            if cost > budget {
                return false;
            }
            prev = Some((i, ranges));
            if last(i, more) {
                return true;
            }
            i = if forward { i + 1 } else { i - 1 };
            if i < occ.lo[a] || i > occ.hi[a] {
                return true;
            }
        }
    }

    /// Every gridded object the ray or sweep touches, each once (the caller
    /// adds the oversized ones).
    pub(super) fn visit_cast<C: Cast>(
        &self,
        cast: &C,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.walk_ray(cast, |s| match s {
            Step::Candidate(e) => {
                let s = &self.spheres[e.slot as usize];
                if cast.selects(s) {
                    let (h, v) = self.resolve(e.slot);
                    f(h, s, v)
                } else {
                    ControlFlow::Continue(())
                }
            }
            Step::StripDone { .. } => ControlFlow::Continue(()),
        })
    }

    /// The first contact of a ray or sweep (smallest `t`, ties by handle)
    /// among the objects `filter` admits: the oversized objects first, then
    /// the walk, stopping once a contact precedes the strip just finished.
    pub fn first_hit<C: Cast>(&self, cast: &C, filter: Option<Filter>) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        let admits = |slot: u32| filter.is_none_or(|f| f.interacts(self.filters[slot as usize]));
        let test = cast.test();
        for &slot in &self.oversized {
            if let Some(t) = test.contact(&self.spheres[slot as usize]) {
                if admits(slot) {
                    RayHit::offer(&mut best, t, self.handle(slot));
                }
            }
        }
        let _ = self.walk_ray(cast, |s| match s {
            Step::Candidate(e) => {
                if let Some(t) = test.contact(&self.spheres[e.slot as usize]) {
                    if admits(e.slot) {
                        RayHit::offer(&mut best, t, self.handle(e.slot));
                    }
                }
                ControlFlow::Continue(())
            }
            Step::StripDone { t_done } => match best {
                Some(b) if b.t < t_done => ControlFlow::Break(()),
                _ => ControlFlow::Continue(()),
            },
        });
        best
    }
}
