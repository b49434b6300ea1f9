//! Rays and segments: walk the cells along the ray inside the occupied box, or
//! scan the occupied cells when the walk would be longer.
//!
//! The walk is the 2D grid's conservative DDA (see `grid2d/ray.rs`) in 3D: strips
//! along the dominant axis `a` of the direction; in strip `i` the ray spans a
//! rectangle of cells on the two other axes, computed from its coordinates at the
//! strip's entry and exit parameters, padded against rounding, and forced to move
//! monotonically from strip to strip. Since `|d_b|, |d_c| <= |d_a|` a strip spans
//! at most 2 × 2 cells plus padding.
//!
//! Once-only: with monotone rectangles, the strips in which an object's key box
//! appears are consecutive; it is reported in the first one (its predecessor does
//! not meet the box), and there only from the cell `(i, max(b0, ob0), max(c0,
//! oc0))`.

use super::keys::{KeyBox, LIMIT};
use super::HashGrid;
use crate::broad::cell_list::CellEntry;
use crate::broad::RayHit;
use crate::geom::{overlap, Ray, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// Relative padding of the ray's coordinates (rounding of `o + d t`).
const RAY_PAD: f32 = 1e-5;

/// Strip walks longer than this many lookups per occupied cell scan instead.
const LOOKUPS_PER_STRIP: u64 = 4;

enum Step<'a> {
    /// A candidate reference, once per object.
    Candidate(&'a CellEntry<[i32; 3]>),
    /// Every object the ray meets below `t_done` has been reported.
    StripDone { t_done: f32 },
}

/// True if the inclusive ranges `[a0, a1]` and `[b0, b1]` meet (empty ranges,
/// `a0 > a1`, meet nothing).
#[inline]
fn meet(a0: i32, a1: i32, b0: i32, b1: i32) -> bool {
    a0.max(b0) <= a1.min(b1)
}

impl<T> HashGrid<T> {
    fn walk_ray(
        &self,
        ray: &Ray,
        mut step: impl FnMut(Step<'_>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let occ = self.occupied;
        if occ.is_empty() {
            return ControlFlow::Continue(());
        }
        let k = &self.keys;
        let (o, d) = (ray.origin, ray.dir);
        let extra = o.abs().max_element() * RAY_PAD;
        let touches =
            |key: [i32; 3]| overlap::ray_aabb(ray, &self.loose(key).grown(extra)).is_some();
        let ad = d.abs();
        let a = if ad.x >= ad.y && ad.x >= ad.z {
            0
        } else if ad.y >= ad.z {
            1
        } else {
            2
        };
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);

        let forward = d[a] > 0.0;
        let line_t = |line: i32| (line as f32 * k.cell - o[a]) / d[a];
        let io = k.coord(o[a]);
        let start = if d[a] == 0.0 {
            None // zero direction: not a valid ray; scan
        } else if forward {
            if io > occ.hi[a] {
                return ControlFlow::Continue(());
            }
            Some(if io < occ.lo[a] {
                (occ.lo[a], line_t(occ.lo[a]).max(0.0))
            } else {
                (io, 0.0)
            })
        } else {
            if io < occ.lo[a] {
                return ControlFlow::Continue(());
            }
            Some(if io > occ.hi[a] {
                (occ.hi[a], line_t(occ.hi[a] + 1).max(0.0))
            } else {
                (io, 0.0)
            })
        };
        // Length of the walk, against the cost of scanning every occupied cell.
        // The last strip: the cell of the ray's end, padded in the direction of
        // travel (far from the origin `o + d t` rounds by up to its magnitude times
        // epsilon, and so do the strips' `t`s, which can then all round to `max_t`:
        // the walk must stop at this cell, not wait for a `t` beyond `max_t`).
        let end = if ray.max_t.is_finite() {
            let v = ray.at(ray.max_t)[a];
            let pad = (o[a].abs() + (d[a] * ray.max_t).abs()) * RAY_PAD;
            if forward {
                k.coord(v + pad)
            } else {
                k.coord(v - pad)
            }
        } else if forward {
            LIMIT
        } else {
            -LIMIT
        };
        let end = end.clamp(occ.lo[a], occ.hi[a]);
        let walk = start.map(|(i, _)| (end as i64 - i as i64).unsigned_abs() + 1);
        // The ray's coordinate on `axis` at t, padded; f32::min/max skip the NaN
        // of ∞ − ∞ at an infinite end.
        let at = |axis: usize, t: f32| {
            let v = if d[axis] == 0.0 {
                o[axis]
            } else {
                o[axis] + d[axis] * t
            };
            let pad = (o[axis].abs() + (d[axis] * t).abs()) * RAY_PAD;
            (v - pad, v + pad)
        };
        // One strip: its end line, its parameter interval's end `tb` and its raw
        // (unclipped, monotone) cell ranges on b and c.
        let strip = |i: i32, ta: f32, prev: Option<(i32, [(i32, i32); 2])>| {
            let end_line = if forward {
                (i < LIMIT).then_some(i + 1)
            } else {
                (i > -LIMIT).then_some(i)
            };
            let tb = end_line
                .map_or(f32::INFINITY, line_t)
                .min(ray.max_t)
                .max(ta);
            let mut ranges = [(0, 0); 2];
            for (j, axis) in [b, c].into_iter().enumerate() {
                let (l0, h0) = at(axis, ta);
                let (l1, h1) = at(axis, tb);
                let (mut r0, mut r1) = k.span(l0.min(l1), h0.max(h1));
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
            (end_line, tb, ranges)
        };
        let clipped_area = |ranges: [(i32, i32); 2]| {
            let [(b0, b1), (c0, c1)] = ranges;
            let (rb0, rb1) = (b0.max(occ.lo[b]), b1.min(occ.hi[b]));
            let (rc0, rc1) = (c0.max(occ.lo[c]), c1.min(occ.hi[c]));
            ((rb1 as i64 - rb0 as i64 + 1).max(0) * (rc1 as i64 - rc0 as i64 + 1).max(0)) as u64
        };
        let cells = self.map.len() as u64;
        // Dry run of the walk (arithmetic only): its cost is at most one lookup per
        // key of each strip, or one pass over the map for a strip wider than that.
        // Far from the origin the padding can make every strip as wide as the
        // occupied box; then scanning once is cheaper than walking (a fuzzed ray
        // took 89 s walking).
        let walk_cost_ok = |mut i: i32, mut ta: f32| {
            let budget = LOOKUPS_PER_STRIP.saturating_mul(cells) + 64;
            let mut cost = 0u64;
            let mut prev = None;
            loop {
                let (end_line, tb, ranges) = strip(i, ta, prev);
                cost = cost.saturating_add(clipped_area(ranges).min(cells));
                if cost > budget {
                    return false;
                }
                prev = Some((i, ranges));
                let Some(next_line) = end_line else {
                    return true;
                };
                if (tb >= ray.max_t && line_t(next_line) > ray.max_t) || i == end {
                    return true;
                }
                i = if forward { i + 1 } else { i - 1 };
                if i < occ.lo[a] || i > occ.hi[a] {
                    return true;
                }
                ta = tb;
            }
        };
        let Some((mut i, mut ta)) = start.filter(|&(i, ta)| {
            walk.unwrap_or(u64::MAX).saturating_mul(LOOKUPS_PER_STRIP) <= cells
                && (ta > ray.max_t || walk_cost_ok(i, ta))
        }) else {
            // Scan: each object from its own lowest cell.
            for cell in &self.cells {
                if cell.list.entries.is_empty() || !touches(cell.key) {
                    continue;
                }
                for e in &cell.list.entries {
                    if e.lo == cell.key {
                        step(Step::Candidate(e))?;
                    }
                }
            }
            return ControlFlow::Continue(());
        };
        if ta > ray.max_t {
            return ControlFlow::Continue(());
        }

        // Raw (unclipped, monotone) ranges on b and c of the previous strip.
        let mut prev: Option<(i32, [(i32, i32); 2])> = None;
        loop {
            let (end_line, tb, ranges) = strip(i, ta, prev);
            let [(b0, b1), (c0, c1)] = ranges;
            let (rb0, rb1) = (b0.max(occ.lo[b]), b1.min(occ.hi[b]));
            let (rc0, rc1) = (c0.max(occ.lo[c]), c1.min(occ.hi[c]));
            let mut cell = |key: [i32; 3], slot: u32| -> ControlFlow<()> {
                let list = &self.cells[slot as usize].list;
                if !touches(key) {
                    return ControlFlow::Continue(());
                }
                let (rb, rc) = (key[b], key[c]);
                for e in &list.entries {
                    let ob: KeyBox = k.sphere_box(&self.spheres[e.slot as usize]);
                    if rb != b0.max(ob.lo[b]) || rc != c0.max(ob.lo[c]) {
                        continue;
                    }
                    if let Some((pi, p)) = prev {
                        if ob.lo[a] <= pi
                            && pi <= ob.hi[a]
                            && meet(p[0].0, p[0].1, ob.lo[b], ob.hi[b])
                            && meet(p[1].0, p[1].1, ob.lo[c], ob.hi[c])
                        {
                            continue; // met in the previous strip
                        }
                    }
                    step(Step::Candidate(e))?;
                }
                ControlFlow::Continue(())
            };
            // A strip wider than the number of occupied cells (huge padding far from
            // the origin, or a widely spread scene) is served from the map instead
            // of key by key, so one strip never costs more than one pass over it.
            let area = (rb1 as i64 - rb0 as i64 + 1).max(0) * (rc1 as i64 - rc0 as i64 + 1).max(0);
            if area == 0 {
                // An empty range on one axis: nothing to visit (the other axis's
                // range may still be huge, so do not loop over it).
            } else if area as u64 > self.map.len() as u64 {
                for (key, &slot) in &self.map {
                    if key[a] == i && (rb0..=rb1).contains(&key[b]) && (rc0..=rc1).contains(&key[c])
                    {
                        cell(*key, slot)?;
                    }
                }
            } else {
                for rc in rc0..=rc1 {
                    for rb in rb0..=rb1 {
                        let mut key = [0; 3];
                        key[a] = i;
                        key[b] = rb;
                        key[c] = rc;
                        if let Some(&slot) = self.map.get(&key) {
                            cell(key, slot)?;
                        }
                    }
                }
            }
            prev = Some((i, ranges));
            step(Step::StripDone { t_done: ta })?;
            let Some(next_line) = end_line else { break };
            if tb >= ray.max_t && line_t(next_line) > ray.max_t {
                break;
            }
            if i == end {
                break;
            }
            i = if forward { i + 1 } else { i - 1 };
            if i < occ.lo[a] || i > occ.hi[a] {
                break;
            }
            ta = tb;
        }
        ControlFlow::Continue(())
    }

    /// Every gridded object the ray touches, each once (the caller adds the
    /// oversized ones).
    pub(super) fn visit_ray(
        &self,
        ray: &Ray,
        f: &mut impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        self.walk_ray(ray, |s| match s {
            Step::Candidate(e) => {
                let s = &self.spheres[e.slot as usize];
                if overlap::ray_sphere(ray, s).is_some() {
                    let (h, v) = self.resolve(e.slot);
                    f(h, s, v)
                } else {
                    ControlFlow::Continue(())
                }
            }
            Step::StripDone { .. } => ControlFlow::Continue(()),
        })
    }

    /// The first hit (smallest `t`, ties by handle): the oversized objects first,
    /// then the walk, stopping once a hit precedes the strip just finished.
    pub(super) fn ray_first_cells(&self, ray: &Ray) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        for &slot in &self.oversized {
            if let Some(t) = overlap::ray_sphere(ray, &self.spheres[slot as usize]) {
                RayHit::offer(&mut best, t, self.handles[slot as usize]);
            }
        }
        let _ = self.walk_ray(ray, |s| match s {
            Step::Candidate(e) => {
                if let Some(t) = overlap::ray_sphere(ray, &self.spheres[e.slot as usize]) {
                    RayHit::offer(&mut best, t, self.handles[e.slot as usize]);
                }
                ControlFlow::Continue(())
            }
            Step::StripDone { t_done } => {
                if best.is_some_and(|b| b.t < t_done) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            }
        });
        best
    }
}

#[cfg(test)]
mod tests {
    use crate::broad::HashGridConfig;
    use crate::broad::{BruteForce, HashGrid, SpatialIndex};
    use crate::geom::{Ray, Segment, Sphere};
    use glam::{vec3, Vec3};

    fn sample() -> (HashGrid<u32>, BruteForce<u32>) {
        let mut g = HashGrid::with_config(HashGridConfig { cell_size: 3.0 }).unwrap();
        let mut b = BruteForce::new();
        let mut k = 0u32;
        let mut add = |s: Sphere| {
            g.insert(s, k).unwrap();
            b.insert(s, k).unwrap();
            k += 1;
        };
        for x in (0..=60).step_by(7) {
            for y in (0..=60).step_by(9) {
                for z in (0..=30).step_by(6) {
                    add(Sphere::new(
                        vec3(x as f32, y as f32, z as f32),
                        0.5 + ((x + y + z) % 4) as f32 * 0.5,
                    ));
                }
            }
        }
        add(Sphere::new(vec3(-1e4, 30.0, 15.0), 1.0));
        add(Sphere::new(vec3(30.0, 30.0, 15.0), 80.0)); // oversized
        add(Sphere::new(vec3(2e4, 2e4, -2e4), 0.0));
        (g, b)
    }

    fn check(g: &HashGrid<u32>, b: &BruteForce<u32>, r: &Ray) {
        crate::broad::test_util::check_ray(g, b, r);
    }

    #[test]
    fn rays_match_the_oracle_in_every_direction() {
        let (g, b) = sample();
        let origins = [
            vec3(30.0, 30.0, 15.0),
            vec3(-20.0, 10.0, 5.0),
            vec3(6.0, 9.0, 12.0), // on cell faces
            vec3(-3e4, 30.0, 15.0),
            vec3(1e6, -1e6, 1e6),
        ];
        for o in origins {
            for k in 0..64 {
                let (t, p) = (k as f32 * 0.7, k as f32 * 0.31);
                let d = vec3(t.cos() * p.sin(), t.sin() * p.sin(), p.cos());
                for max_t in [f32::INFINITY, 50.0, 2.0, 0.0] {
                    check(&g, &b, &Ray::with_max_t(o, d, max_t));
                }
            }
            for d in [
                Vec3::X,
                -Vec3::Y,
                Vec3::Z,
                -Vec3::Z,
                vec3(1.0, 1.0, 1.0),
                vec3(0.0, 1.0, -1.0),
            ] {
                check(&g, &b, &Ray::new(o, d));
                check(&g, &b, &Ray::new(o, d * 1e-3));
            }
        }
        // Towards the far point, and a segment across everything.
        let o = vec3(30.0, 30.0, 15.0);
        check(&g, &b, &Ray::new(o, vec3(2e4, 2e4, -2e4) - o));
        check(
            &g,
            &b,
            &Segment::new(vec3(-5.0, -5.0, -5.0), vec3(65.0, 65.0, 35.0)).to_ray(),
        );
    }

    #[test]
    fn vertical_rays() {
        let (g, b) = sample();
        for (x, y) in [(7.0, 9.0), (3.0, 3.0), (-1e4, 30.0), (0.0, 0.0)] {
            for dz in [1.0, -1.0] {
                check(&g, &b, &Ray::new(vec3(x, y, -100.0), vec3(0.0, 0.0, dz)));
                check(&g, &b, &Ray::new(vec3(x, y, 100.0), vec3(0.0, 0.0, dz)));
            }
        }
    }
}
