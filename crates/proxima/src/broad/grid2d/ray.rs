//! Rays and segments: walk the cells along the ray's XY projection.
//!
//! The walk goes strip by strip along the dominant XY axis `a` of the direction
//! (columns when `|dx| >= |dy|`, else rows). Strip `i` holds the ray for the
//! parameters `[ta, tb]` between its two grid lines (the border strips reach to
//! infinity: coordinates are clamped), and within it the ray spans the cells
//! `[r0, r1]` on the other axis `b`, computed from the ray's `b` coordinate at
//! `ta` and `tb` and padded against rounding. Since `|d_b| <= |d_a|`, a strip spans
//! at most two cells plus padding: this is a conservative 2D DDA.
//!
//! Once-only: `[r0, r1]` is forced to move monotonically from strip to strip, so
//! the strips in which a given object (a cell rectangle) appears are consecutive.
//! An object is reported in the first of them — the one whose predecessor does not
//! contain it — and there only from the row `max(r0, ob0)`. Both checks use the
//! object's cell range recomputed from its sphere, with no allocation.
//!
//! A ray with zero XY direction (vertical) stays in one column of cells: it is a
//! rectangle query over the cells of its (padded) XY point.

use super::UniformGrid2d;
use crate::broad::cell_list::CellEntry;
use crate::broad::RayHit;
use crate::geom::{overlap, Aabb, Ray, Sphere};
use crate::Handle;
use std::ops::ControlFlow;

/// Relative padding of the ray's `b` coordinate (rounding of `o + d t`).
const RAY_PAD: f32 = 1e-5;

/// What the walk reports to its consumer.
enum Step<'a> {
    /// A candidate reference, once per object.
    Candidate(&'a CellEntry<[u16; 2]>),
    /// A strip is finished; every object the ray meets at a parameter below
    /// `t_done` has been reported.
    StripDone { t_done: f32 },
}

impl<T> UniformGrid2d<T> {
    /// Walks the cells along `ray`, feeding `step` the candidates whose cells'
    /// loose boxes the ray touches (each object at most once) and the strip ends.
    fn walk_ray(
        &self,
        ray: &Ray,
        mut step: impl FnMut(Step<'_>) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let g = &self.geom;
        let (o, d) = (ray.origin, ray.dir);
        // The slab test's rounding grows with the origin's magnitude: pad the loose
        // boxes by as much so the box test never rejects a sphere the exact test hits.
        let extra = o.abs().max_element() * RAY_PAD;
        let touches =
            |x: u32, y: u32| overlap::ray_aabb(ray, &self.loose(x, y).grown(extra)).is_some();
        let (a, b) = if d.x.abs() >= d.y.abs() {
            (0, 1)
        } else {
            (1, 0)
        };
        if d[a] == 0.0 {
            // Vertical: the rectangle of cells around the XY point.
            let rect = g.aabb_rect(&Aabb::new(o, o));
            for y in rect.y0..=rect.y1 {
                for x in rect.x0..=rect.x1 {
                    let cell = &self.cells[g.index(x, y)];
                    if cell.entries.is_empty() || !touches(x, y) {
                        continue;
                    }
                    for e in &cell.entries {
                        if (e.lo[0] as u32).max(rect.x0) == x && (e.lo[1] as u32).max(rect.y0) == y
                        {
                            step(Step::Candidate(e))?;
                        }
                    }
                }
            }
            return ControlFlow::Continue(());
        }

        let last = g.dims[a] - 1;
        let forward = d[a] > 0.0;
        let line_t = |line: u32| (g.origin[a] + line as f32 * g.cell - o[a]) / d[a];
        // The ray's b coordinate at t, padded by the rounding of o + d t; f32::min/max
        // skip the NaN of ∞ − ∞ at an infinite end.
        let b_at = |t: f32| {
            let v = if d[b] == 0.0 { o[b] } else { o[b] + d[b] * t };
            let pad = (o[b].abs() + (d[b] * t).abs()) * RAY_PAD;
            (v - pad, v + pad)
        };
        let mut i = g.coord(o[a], a);
        let mut ta = 0.0f32;
        let mut prev: Option<(u32, u32, u32)> = None;
        loop {
            let end_line = if forward {
                (i < last).then_some(i + 1)
            } else {
                (i > 0).then_some(i)
            };
            let tb = end_line
                .map_or(f32::INFINITY, line_t)
                .min(ray.max_t)
                .max(ta);
            let (lo_a, hi_a) = b_at(ta);
            let (lo_b, hi_b) = b_at(tb);
            let (mut r0, mut r1) = g.span(lo_a.min(lo_b), hi_a.max(hi_b), b);
            // Monotone rows from strip to strip (the pads cover any ulp lost here),
            // which makes each object's strips consecutive.
            if let Some((_, p0, p1)) = prev {
                if d[b] > 0.0 {
                    r0 = r0.max(p0);
                    r1 = r1.max(p1);
                } else if d[b] < 0.0 {
                    r0 = r0.min(p0);
                    r1 = r1.min(p1);
                }
            }
            for r in r0..=r1 {
                let (x, y) = if a == 0 { (i, r) } else { (r, i) };
                let cell = &self.cells[g.index(x, y)];
                if cell.entries.is_empty() || !touches(x, y) {
                    continue;
                }
                for e in &cell.entries {
                    let or = g.sphere_rect(&self.spheres[e.slot as usize]);
                    let (oa0, oa1, ob0, ob1) = if a == 0 {
                        (or.x0, or.x1, or.y0, or.y1)
                    } else {
                        (or.y0, or.y1, or.x0, or.x1)
                    };
                    if r != r0.max(ob0) {
                        continue;
                    }
                    if let Some((pi, p0, p1)) = prev {
                        if oa0 <= pi && pi <= oa1 && p0 <= ob1 && ob0 <= p1 {
                            continue; // already met in the previous strip
                        }
                    }
                    step(Step::Candidate(e))?;
                }
            }
            prev = Some((i, r0, r1));
            // Everything whose hit point lies before this strip's start was met in
            // earlier strips (a whole strip of margin absorbs rounding).
            step(Step::StripDone { t_done: ta })?;
            let Some(next_line) = end_line else { break };
            if tb >= ray.max_t && line_t(next_line) > ray.max_t {
                break;
            }
            i = if forward { i + 1 } else { i - 1 };
            ta = tb;
        }
        ControlFlow::Continue(())
    }

    /// Every object the ray touches, each once.
    pub(super) fn visit_ray(
        &self,
        ray: &Ray,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
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

    /// The first hit (smallest `t`, ties by handle), walking front to back and
    /// stopping once a hit precedes the start of the strip just finished.
    pub(super) fn ray_first_cells(&self, ray: &Ray) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        let _ = self.walk_ray(ray, |s| match s {
            Step::Candidate(e) => {
                if let Some(t) = overlap::ray_sphere(ray, &self.spheres[e.slot as usize]) {
                    RayHit::offer(&mut best, t, self.handles[e.slot as usize]);
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

#[cfg(test)]
mod tests {
    use crate::broad::Grid2dConfig;
    use crate::broad::{BruteForce, SpatialIndex, UniformGrid2d};
    use crate::geom::{Aabb, Ray, Segment, Sphere};
    use glam::{vec3, Vec3};

    fn sample() -> (UniformGrid2d<u32>, BruteForce<u32>) {
        let w = Aabb::new(Vec3::ZERO, vec3(100.0, 100.0, 10.0));
        let mut g = UniformGrid2d::with_config(Grid2dConfig {
            world: w,
            cell_size: 7.0,
        })
        .unwrap();
        let mut b = BruteForce::new();
        let mut k = 0u32;
        for x in (0..=100).step_by(9) {
            for y in (0..=100).step_by(11) {
                let s = Sphere::new(
                    vec3(x as f32, y as f32, (x % 7) as f32),
                    1.0 + (y % 3) as f32,
                );
                g.insert(s, k).unwrap();
                b.insert(s, k).unwrap();
                k += 1;
            }
        }
        // Outside the rectangle, and one huge.
        for s in [
            Sphere::new(vec3(-1e4, 50.0, 5.0), 1.0),
            Sphere::new(vec3(150.0, -30.0, 5.0), 2.0),
            Sphere::new(vec3(50.0, 50.0, 5.0), 60.0),
        ] {
            g.insert(s, k).unwrap();
            b.insert(s, k).unwrap();
            k += 1;
        }
        (g, b)
    }

    fn check(g: &UniformGrid2d<u32>, b: &BruteForce<u32>, r: &Ray) {
        crate::broad::test_util::check_ray(g, b, r);
    }

    #[test]
    fn vertical_rays() {
        let (g, b) = sample();
        for (x, y) in [
            (9.0, 11.0),
            (50.0, 50.0),
            (-1e4, 50.0),
            (7.0, 7.0),
            (500.0, 500.0),
        ] {
            for dz in [1.0, -1.0, 1e-3] {
                for max_t in [f32::INFINITY, 3.0, 0.0] {
                    check(
                        &g,
                        &b,
                        &Ray::with_max_t(vec3(x, y, 5.0), vec3(0.0, 0.0, dz), max_t),
                    );
                }
            }
        }
    }

    #[test]
    fn rays_in_every_direction_match_the_oracle() {
        let (g, b) = sample();
        let origins = [
            vec3(50.0, 50.0, 5.0),
            vec3(-30.0, 20.0, 5.0),
            vec3(130.0, 140.0, 2.0),
            vec3(7.0, 14.0, 5.0), // on grid lines
            vec3(-2e4, 50.0, 5.0),
        ];
        for o in origins {
            for k in 0..48 {
                let ang = k as f32 * std::f32::consts::TAU / 48.0;
                let d = vec3(ang.cos(), ang.sin(), 0.01 * (k % 5) as f32 - 0.02);
                for max_t in [f32::INFINITY, 40.0, 1.0] {
                    check(&g, &b, &Ray::with_max_t(o, d, max_t));
                }
            }
            // Axis-aligned directions, including along a grid line.
            for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, vec3(1.0, 1.0, 0.0)] {
                check(&g, &b, &Ray::new(o, d));
            }
        }
        let s = Segment::new(vec3(-5.0, -5.0, 5.0), vec3(105.0, 95.0, 5.0));
        check(&g, &b, &s.to_ray());
    }
}
