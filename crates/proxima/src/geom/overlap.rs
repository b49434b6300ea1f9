//! The closed overlap tests, one function per shape pair, and the distances of
//! the k-nearest queries. Every index and every method on the shape types calls
//! these; nothing re-implements them.
//!
//! Closed means boundaries count: touching shapes overlap. Costs are O(1).
//!
//! | shapes | test | box test the index walks prune with |
//! |---|---|---|
//! | sphere–sphere, sphere–box | [`sphere_sphere`], [`sphere_aabb`] | [`sphere_aabb`] |
//! | ray/segment–sphere (first `t`) | [`ray_sphere`] | [`ray_aabb`] |
//! | sphere sweep–sphere (time of impact) | [`sweep_sphere`] | [`sweep_aabb`] |
//! | frustum–sphere | [`frustum_sphere`] | [`frustum_aabb`] |
//! | point–sphere distance (k nearest) | [`point_sphere_distance`] | [`point_aabb_distance`] |

use crate::geom::exact::Exp;
use crate::geom::{Aabb, Frustum, Ray, Relation, Sphere, SphereSweep};
use glam::{Vec3, Vec4};
use std::cmp::Ordering;

// The sphere tests are exact: whether `|p - q| <= r1 + r2` is decided for the
// real numbers the `f32` inputs denote, at every magnitude. A fast `f64`
// evaluation decides unless the two sides agree to 1e-12 relative; then an exact
// evaluation (error-free transformations, see `exact.rs`) decides. In `f64` no
// square of a finite `f32` overflows (x² <= 1.2e77), so there is no `inf <= inf`.
// The ray, sweep and frustum tests are exact too (hit/miss, cull/keep), by the
// same filter-then-expansion scheme (rays and sweeps share one implementation,
// `line_ball.rs`); only the returned parameters are rounded, and those
// consistently with the box tests where pruning depends on them. Distances are
// correctly rounded, so they are monotone and the same in every index.

#[inline]
fn d3(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Exactly: `|p - q| <= r1 + r2` (radii non-negative).
#[inline]
pub(crate) fn within(p: Vec3, q: Vec3, r1: f32, r2: f32) -> bool {
    // `f32` filter first: this test is the inner loop of every pair search. The
    // computed squares carry a relative error below 6·2⁻²⁴ ≈ 4e-7 (one rounding per
    // subtraction, square and sum), so a gap wider than 1e-5 of their size (plus
    // an absolute term for underflow) decides with a 25× safety factor. An overflow
    // to ∞ makes both comparisons false and falls through to `f64`.
    let d = p - q;
    let d2f = d.length_squared();
    let rsf = r1 + r2;
    let rs2f = rsf * rsf;
    let marginf = f32_margin(d2f, rs2f);
    if d2f < rs2f - marginf {
        return true;
    }
    if d2f > rs2f + marginf {
        return false;
    }
    let (a, b) = (d3(p), d3(q));
    let d2: f64 = (0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum();
    let rs = r1 as f64 + r2 as f64;
    let rs2 = rs * rs;
    // The fast path's relative error is below 1e-15 (a few roundings of 2^-53).
    let margin = 1e-12 * (d2 + rs2);
    if d2 < rs2 - margin {
        true
    } else if d2 > rs2 + margin {
        false
    } else {
        super::exact::within(a, b, r1 as f64, r2 as f64)
    }
}

/// Rounding margin of the `f32` filter of [`within`] for computed squares `d2f`
/// (distance) and `rs2f` (radius sum).
#[inline(always)]
fn f32_margin(d2f: f32, rs2f: f32) -> f32 {
    1e-5 * (d2f + rs2f) + 1e-35
}

/// Conservative pre-test for batched sphere–sphere loops, on plain coordinates
/// (structure-of-arrays callers): `false` only if [`sphere_sphere`] is `false`
/// for the spheres `(a, ar)` and `(b, br)`, so those need no exact test; `true`
/// means "run [`sphere_sphere`]". It is the rejection step of `sphere_sphere`'s
/// own `f32` filter (same operations, so the same rounding; a square is
/// unchanged by the sign of the difference), branch-free so that loops over
/// many spheres vectorize. O(1).
#[allow(clippy::too_many_arguments, clippy::neg_cmp_op_on_partial_ord)]
#[inline(always)]
pub(crate) fn sphere_sphere_candidate(
    ax: f32,
    ay: f32,
    az: f32,
    ar: f32,
    bx: f32,
    by: f32,
    bz: f32,
    br: f32,
) -> bool {
    let (dx, dy, dz) = (ax - bx, ay - by, az - bz);
    let d2f = dx * dx + dy * dy + dz * dz;
    let rsf = ar + br;
    let rs2f = rsf * rsf;
    // Written as `!(>)` so that a NaN or an overflow to ∞ stays a candidate,
    // exactly as `within` falls through to `f64` then.
    !(d2f > rs2f + f32_margin(d2f, rs2f))
}

/// [`sphere_sphere_candidate`] for four spheres at once, given lane by lane
/// (`x[j]`, `y[j]`, `z[j]`, `r[j]` for sphere `j`), against `s`: bit `j` of the
/// result is set when sphere `j` is a candidate, i.e. clear only if
/// [`sphere_sphere`] is `false` for it. The same operations as the scalar
/// pre-test in each SIMD lane, so the same rounding. O(1).
#[inline(always)]
pub(crate) fn sphere_sphere_candidates4(x: Vec4, y: Vec4, z: Vec4, r: Vec4, s: &Sphere) -> u32 {
    let dx = x - Vec4::splat(s.center.x);
    let dy = y - Vec4::splat(s.center.y);
    let dz = z - Vec4::splat(s.center.z);
    let d2f = dx * dx + dy * dy + dz * dz;
    let rsf = r + Vec4::splat(s.radius);
    let rs2f = rsf * rsf;
    let margin = Vec4::splat(1e-5) * (d2f + rs2f) + Vec4::splat(1e-35);
    // `>` is false for NaN, so NaN and ∞ lanes stay candidates, as in the scalar test.
    !d2f.cmpgt(rs2f + margin).bitmask() & 0xF
}

/// Sphere–sphere: `|c1 - c2| <= r1 + r2`, decided exactly (see the module).
#[inline]
pub fn sphere_sphere(a: &Sphere, b: &Sphere) -> bool {
    within(a.center, b.center, a.radius, b.radius)
}

/// Sphere–AABB: the distance from the centre to the box (its closest point) is at
/// most `r`, decided exactly.
#[inline]
pub fn sphere_aabb(s: &Sphere, b: &Aabb) -> bool {
    let q = s.center.clamp(b.min, b.max);
    within(s.center, q, s.radius, 0.0)
}

/// Sphere contains AABB: every point of `b` is within `s` (boundary included),
/// decided exactly. A ball is convex, so it contains the box iff it contains the
/// box's 8 corners, each tested like [`sphere_sphere`] with a point. A box with
/// an infinite or NaN coordinate is never contained. O(1) (8 point tests).
#[inline]
pub fn sphere_contains_aabb(s: &Sphere, b: &Aabb) -> bool {
    if !b.min.is_finite() || !b.max.is_finite() {
        return false;
    }
    (0..8u8).all(|i| {
        let p = Vec3::select(
            glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0),
            b.max,
            b.min,
        );
        within(p, s.center, 0.0, s.radius)
    })
}

/// AABB–AABB: the intervals overlap on all three axes.
#[inline]
pub fn aabb_aabb(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

use super::line_ball::{dot, entry_ceiling, filtered, first_touch, touches, Exact, Line, U};

/// Ray (or segment) against a sphere: a parameter `t` in `[0, ray.max_t]` at which
/// the ray is (up to rounding) entering the closed ball, or `None` when no point
/// of the ray within `[0, max_t]` is in the ball.
///
/// Hit or miss is decided **exactly** for the real numbers the `f32` inputs
/// denote, at every magnitude: with `m = o - c`, the distance `|m + t d|` is
/// convex in `t`, so the ray meets the ball iff the origin is in it (exact
/// `within`), or it approaches (`m·d < 0`) and either the closest approach lies
/// within `max_t` and `|m × d|² <= r²|d|²`, or it lies beyond and the end point is
/// in the ball (`|m + max_t d|² <= r²`). Each sign is first taken from an `f64`
/// evaluation with an error bound (cost: ~40 flops) and only for near-ties
/// from error-free expansions (`exact.rs`). The scheme is written once, for
/// rays and [`sweep_sphere`] alike (`line_ball.rs`).
///
/// The returned `t` is the closest-approach formula in `f64` (no `b² - ac`
/// cancellation), rounded to `f32`, then clamped into `[lb, max_t]` where `lb` is
/// [`ray_aabb`]'s rigorous lower bound for entering the sphere's bounding box.
/// Since `ray_aabb`'s entry bound is monotone in the box, an index box containing
/// the sphere never has an entry bound above this `t`, so front-to-back pruning
/// (`box t0 > best t`) never drops a nearer hit.
#[inline]
pub fn ray_sphere(ray: &Ray, s: &Sphere) -> Option<f32> {
    first_touch(&RayBall { ray, s })
}

/// Whether [`ray_sphere`] is `Some`, by the same exact decision but without
/// computing the parameter (which costs a box test for its entry bound): what
/// a selection needs. Cost: ~40 flops, expansions only for near-ties.
#[inline]
pub fn ray_touches_sphere(ray: &Ray, s: &Sphere) -> bool {
    touches(&RayBall { ray, s })
}

/// A ray and a stored sphere, as the shared line–ball test sees them.
struct RayBall<'a> {
    ray: &'a Ray,
    s: &'a Sphere,
}

impl Line for RayBall<'_> {
    #[inline]
    fn starts_inside(&self) -> bool {
        within(self.ray.origin, self.s.center, self.s.radius, 0.0)
    }
    #[inline]
    fn m_d(&self) -> ([f64; 3], [f64; 3]) {
        let (o, c) = (d3(self.ray.origin), d3(self.s.center));
        ([0, 1, 2].map(|i| o[i] - c[i]), d3(self.ray.dir))
    }
    #[inline]
    fn t_max(&self) -> f32 {
        self.ray.max_t
    }
    #[inline]
    fn rho2(&self) -> f64 {
        let r = self.s.radius as f64;
        r * r
    }
    /// `r²` is exact and `|d|²` rounds twice: within the 4u always allowed.
    #[inline]
    fn lhs_units(&self) -> f64 {
        0.0
    }
    /// `m × d = o × d - c × d`: the products of `f32`s are exact in `f64`, so
    /// each component rounds only three times, relative to values that do not
    /// include the huge cancelling parts of `m` (a ray from 1e20 passing 100
    /// units from a sphere still decides).
    #[inline]
    fn cross(&self, _m: [f64; 3], d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let cross = |p: [f64; 3]| {
            [
                p[1] * d[2] - p[2] * d[1],
                p[2] * d[0] - p[0] * d[2],
                p[0] * d[1] - p[1] * d[0],
            ]
        };
        let (ox, cx) = (cross(d3(self.ray.origin)), cross(d3(self.s.center)));
        let cr = [0, 1, 2].map(|k| ox[k] - cx[k]);
        let err = [0, 1, 2].map(|k| 2.0 * U * (ox[k].abs() + cx[k].abs() + cr[k].abs()));
        (cr, err)
    }
    /// `o + max_t d - c` (`max_t d` is exact: two `f32`s), two roundings per
    /// component.
    #[inline]
    fn end(&self, _m: [f64; 3], d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (o, c) = (d3(self.ray.origin), d3(self.s.center));
        let big_t = self.ray.max_t as f64;
        let e = [0, 1, 2].map(|i| o[i] + big_t * d[i]);
        let p = [0, 1, 2].map(|i| e[i] - c[i]);
        let err = [0, 1, 2].map(|i| 2.0 * U * (e[i].abs() + p[i].abs()));
        (p, err)
    }
    fn exact(&self) -> Exact {
        let (o, c) = (d3(self.ray.origin), d3(self.s.center));
        let t = self.ray.max_t;
        Exact {
            m: [0, 1, 2].map(|i| Exp::diff(o[i], c[i])),
            d: d3(self.ray.dir).map(Exp::of),
            rho: Exp::of(self.s.radius as f64),
            t: t.is_finite().then(|| Exp::of(t as f64)),
        }
    }
    /// The sphere's bounding box, rounded outward to `f32`: every index box that
    /// contains the sphere contains it.
    #[inline]
    fn entry_floor(&self) -> f32 {
        ray_aabb(self.ray, &outward_box(self.s)).map_or(0.0, |(t0, _)| t0)
    }
    #[inline]
    fn entry_ceiling(&self) -> f64 {
        let (o, d, c) = (self.ray.origin, self.ray.dir, self.s.center);
        entry_ceiling(o.into(), d.into(), c.into(), self.s.radius as f64)
    }
}

/// Sphere sweep against a stored sphere: the time `t` in `[0, 1]` at which the
/// sweep's sphere, moving from `sweep.from` to `sweep.to`, first touches the
/// closed ball `s` (`0` when they touch at the start), or `None` when it never
/// does — when the distance from `s.center` to the segment exceeds
/// `s.radius + sweep.radius`.
///
/// Touching or not is decided **exactly** for the real numbers the `f32`
/// inputs denote: the segment is taken from its end points (its direction
/// `to - from` is never rounded to `f32`) and the radius is the exact sum
/// `r + R`. The scheme is [`ray_sphere`]'s, written once (`line_ball.rs`).
/// With `radius == 0` this is the exact segment test: it equals `ray_sphere`
/// on [`Segment::to_ray`](crate::geom::Segment::to_ray) whenever `to - from` is
/// an `f32` (otherwise `to_ray` rounds the segment and this does not). A
/// zero-length sweep touches iff it starts touching.
///
/// The returned `t` is rounded (closest-approach formula in `f64`), then
/// clamped into `[lb, 1]` where `lb` is [`sweep_aabb`]'s entry bound for the
/// sphere's bounding box rounded outward: every index box containing the
/// sphere enters no later (the box test is monotone), so front-to-back pruning
/// by box entry never drops an earlier hit. Cost: ~50 flops, expansions only
/// for near-ties.
#[inline]
pub fn sweep_sphere(sweep: &SphereSweep, s: &Sphere) -> Option<f32> {
    SweepTest::new(sweep).contact(s)
}

/// Whether [`sweep_sphere`] is `Some`, by the same pre-test and exact
/// decision but without computing the time of contact (which costs a box test
/// for its entry bound): what a selection needs. Cost: ~35 `f32` flops for a
/// clear miss, ~50 flops otherwise, expansions only for near-ties.
#[inline]
pub fn sweep_touches_sphere(sweep: &SphereSweep, s: &Sphere) -> bool {
    SweepTest::new(sweep).touches(s)
}

/// A sphere sweep prepared for testing many spheres: [`sweep_sphere`] and
/// [`sweep_touches_sphere`] with the sweep's own terms of the `f32` pre-test
/// (its direction `to - from`, `|d|²` and that term's guard) computed once
/// per query instead of once per sphere. The same values as the one-shot
/// functions compute, so the same answers (they are written as this).
/// Index walks and first-hit searches test tens to hundreds of spheres per
/// sweep: this halves the cost of each clear miss.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SweepTest {
    sweep: SphereSweep,
    d: Vec3,
    dd: f32,
    /// `|d|²` lies where the pre-test's error model holds (see `misses`).
    usable: bool,
}

impl SweepTest {
    const TINY: f32 = 1.0 / 1_152_921_504_606_846_976.0; // 2^-60
    const HUGE: f32 = 1_152_921_504_606_846_976.0 * 1_099_511_627_776.0; // 2^100

    /// Prepares `sweep`. O(1).
    #[inline]
    pub(crate) fn new(sweep: &SphereSweep) -> Self {
        let d = sweep.to - sweep.from;
        let dd = d.length_squared();
        SweepTest {
            sweep: *sweep,
            d,
            dd,
            // Written so that a NaN fails it.
            usable: (Self::TINY..Self::HUGE).contains(&dd),
        }
    }

    /// [`sweep_sphere`] of the prepared sweep and `s`.
    #[inline]
    pub(crate) fn contact(&self, s: &Sphere) -> Option<f32> {
        if self.misses(s) {
            return None;
        }
        self.contact_undecided(s)
    }

    /// [`SweepTest::contact`] of a sphere whose pre-test already said
    /// "undecided" ([`SweepTest::misses`] false, or its lane of
    /// [`SweepTest::misses4`]): the exact test only. Equal to `contact` on
    /// every sphere whatever a pre-test said, since the pre-test is
    /// conservative (it says "miss" only where the exact test does).
    #[inline]
    pub(crate) fn contact_undecided(&self, s: &Sphere) -> Option<f32> {
        first_touch(&SweepBall {
            sweep: &self.sweep,
            s,
        })
    }

    /// [`sweep_touches_sphere`] of the prepared sweep and `s`.
    #[inline]
    pub(crate) fn touches(&self, s: &Sphere) -> bool {
        !self.misses(s) && self.touches_undecided(s)
    }

    /// [`SweepTest::touches`] of a sphere whose pre-test already said
    /// "undecided" (as for [`SweepTest::contact_undecided`]): the exact test
    /// only.
    #[inline]
    pub(crate) fn touches_undecided(&self, s: &Sphere) -> bool {
        touches(&SweepBall {
            sweep: &self.sweep,
            s,
        })
    }

    /// Conservative `f32` pre-test of [`sweep_sphere`]: `true` only if the sweep
    /// certainly misses `s` (then `sweep_sphere` is `None`); `false` means
    /// "undecided", and the exact test runs. Most candidates of an index walk are
    /// clear misses; this rejects them in ~35 `f32` flops instead of the `f64`
    /// filters with error bounds (~120 flops). It answers "miss" when the
    /// distance from the centre to the segment certainly exceeds `ρ = r + R`, in
    /// one of three ways: the infinite line passes farther than `ρ`
    /// (`|m × d|² > ρ²|d|²`, `m = from - c`, `d = to - from`), or the sweep moves
    /// away from the centre from the start on (`m·d >= 0`, the minimum at `t = 0`)
    /// and starts farther than `ρ`, or it still approaches at the end
    /// (`n·d < 0`, `n = to - c`, the minimum at `t = 1`) and ends farther.
    ///
    /// Why it is conservative (u = 2^-24): without underflow or overflow every
    /// `f32` operation is exact up to a factor `1 + δ`, `|δ| <= u`. `m`, `d`, `n`
    /// and `ρ` round once; `|d|²`, `|m|²`, `|n|²` are within 5u relative, `ρ²|d|²`
    /// within 9u; each component of `m × d` is within
    /// `4u (|m_i d_j| + |m_j d_i|) <= 4u |m||d|` of the exact one, so
    /// `|m × d|²` is within `20u |m|²|d|²`, and `m·d`, `n·d` within
    /// `5u |m||d| <= 3u (|m|² + |d|²)`. Every comparison below demands a gap of
    /// `2^-16 = 256u` times the sum of those magnitudes: more than 10× the
    /// bound. The guards keep the inputs where that model holds: `ρ² >= 2^-60`
    /// and `|d|² >= 2^-60` make every margin at least `2^-136`, far above the
    /// absolute error `~2^-144` that underflowing products and squares may add;
    /// `|d|² < 2^100` and `|m|²|d|² < 2^100` keep every product, square and
    /// dot product finite (a sum of margins may overflow to `∞`: undecided). A NaN or an
    /// overflow fails a guard: undecided.
    #[inline]
    pub(crate) fn misses(&self, s: &Sphere) -> bool {
        const EPS: f32 = 1.0 / 65536.0; // 2^-16
        let (sweep, d, dd) = (&self.sweep, self.d, self.dd);
        let m = sweep.from - s.center;
        let rho = s.radius + sweep.radius;
        let (rho2, mm) = (rho * rho, m.length_squared());
        let mmdd = mm * dd;
        // Written so that a NaN fails them.
        if !(self.usable && rho2 >= Self::TINY && mmdd < Self::HUGE) {
            return false;
        }
        let b = rho2 * dd;
        if m.cross(d).length_squared() > b + EPS * (mmdd + b) {
            return true; // the whole line passes farther than ρ
        }
        let far = |pp: f32| pp > rho2 + EPS * (pp + rho2);
        if m.dot(d) > EPS * (mm + dd) && far(mm) {
            return true; // receding from the start, which is outside
        }
        let n = sweep.to - s.center;
        let nn = n.length_squared();
        n.dot(d) < -EPS * (nn + dd) && far(nn) // approaching at the end, outside
    }

    /// [`SweepTest::misses`] of four spheres at once, one per SIMD lane:
    /// bit `j` is set when sphere `j` certainly misses. Each lane runs the
    /// scalar test's operations in the same order (glam's `cross` and
    /// `length_squared` written out), so it rounds the same and answers the
    /// same (test `sweep_miss_pretest_is_conservative` compares every lane);
    /// the three early returns become one mask. What it saves: the leaves'
    /// clear misses are most of the spheres a sweep's walks test (first hit
    /// and all hits).
    #[inline(always)]
    pub(crate) fn misses4(&self, s: [&Sphere; 4]) -> u32 {
        const EPS: f32 = 1.0 / 65536.0; // 2^-16
        if !self.usable {
            return 0;
        }
        let [cx, cy, cz, r] = sphere_lanes(s);
        let (f, to, d) = (self.sweep.from, self.sweep.to, self.d);
        let sp = Vec4::splat;
        let (dd, eps) = (sp(self.dd), sp(EPS));
        let (mx, my, mz) = (sp(f.x) - cx, sp(f.y) - cy, sp(f.z) - cz);
        let rho = r + sp(self.sweep.radius);
        let rho2 = rho * rho;
        let mm = mx * mx + my * my + mz * mz;
        let mmdd = mm * dd;
        let usable = rho2.cmpge(sp(Self::TINY)) & mmdd.cmplt(sp(Self::HUGE));
        let b = rho2 * dd;
        // m × d, as `Vec3::cross`.
        let (dx, dy, dz) = (sp(d.x), sp(d.y), sp(d.z));
        let (ux, uy, uz) = (my * dz - dy * mz, mz * dx - dz * mx, mx * dy - dx * my);
        let line = (ux * ux + uy * uy + uz * uz).cmpgt(b + eps * (mmdd + b));
        let far = |pp: Vec4| pp.cmpgt(rho2 + eps * (pp + rho2));
        let md = mx * dx + my * dy + mz * dz;
        let receding = md.cmpgt(eps * (mm + dd)) & far(mm);
        let (nx, ny, nz) = (sp(to.x) - cx, sp(to.y) - cy, sp(to.z) - cz);
        let nn = nx * nx + ny * ny + nz * nz;
        let nd = nx * dx + ny * dy + nz * dz;
        let approaching = nd.cmplt(-(eps * (nn + dd))) & far(nn);
        (usable & (line | receding | approaching)).bitmask()
    }
}

/// [`SweepTest::misses`] of a one-shot sweep (the tests' name for it).
#[cfg(test)]
pub(crate) fn sweep_sphere_misses(sweep: &SphereSweep, s: &Sphere) -> bool {
    SweepTest::new(sweep).misses(s)
}

/// A sphere sweep and a stored sphere, as the shared line–ball test sees them.
struct SweepBall<'a> {
    sweep: &'a SphereSweep,
    s: &'a Sphere,
}

impl Line for SweepBall<'_> {
    #[inline]
    fn starts_inside(&self) -> bool {
        within(
            self.sweep.from,
            self.s.center,
            self.s.radius,
            self.sweep.radius,
        )
    }
    #[inline]
    fn m_d(&self) -> ([f64; 3], [f64; 3]) {
        let (f, t, c) = (d3(self.sweep.from), d3(self.sweep.to), d3(self.s.center));
        (
            [0, 1, 2].map(|i| f[i] - c[i]),
            [0, 1, 2].map(|i| t[i] - f[i]),
        )
    }
    #[inline]
    fn t_max(&self) -> f32 {
        1.0
    }
    #[inline]
    fn rho2(&self) -> f64 {
        let rho = self.s.radius as f64 + self.sweep.radius as f64;
        rho * rho
    }
    /// `ρ = r + R` rounds once, `ρ²` once more (3u); each `d_i` carries u, so
    /// `|d|²` about 5u; the product one more: below 12u beyond the 4u.
    #[inline]
    fn lhs_units(&self) -> f64 {
        12.0
    }
    /// `m × d = (from - c) × (to - c)` (the `(from - c) × (from - c)` part is
    /// zero): both differences round once, each product once more and the
    /// difference of products once.
    #[inline]
    fn cross(&self, m: [f64; 3], _d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (t, c) = (d3(self.sweep.to), d3(self.s.center));
        let n = [0, 1, 2].map(|i| t[i] - c[i]);
        let mut cr = [0.0; 3];
        let mut err = [0.0; 3];
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let (p, q) = (m[i] * n[j], m[j] * n[i]);
            cr[k] = p - q;
            err[k] = 4.0 * U * (p.abs() + q.abs() + cr[k].abs());
        }
        (cr, err)
    }
    /// `to - c`, one rounding per component.
    #[inline]
    fn end(&self, _m: [f64; 3], _d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (t, c) = (d3(self.sweep.to), d3(self.s.center));
        let p = [0, 1, 2].map(|i| t[i] - c[i]);
        (p, p.map(|x| 2.0 * U * x.abs()))
    }
    fn exact(&self) -> Exact {
        let (f, t, c) = (d3(self.sweep.from), d3(self.sweep.to), d3(self.s.center));
        Exact {
            m: [0, 1, 2].map(|i| Exp::diff(f[i], c[i])),
            d: [0, 1, 2].map(|i| Exp::diff(t[i], f[i])),
            rho: Exp::diff(self.s.radius as f64, -(self.sweep.radius as f64)),
            t: Some(Exp::of(1.0)),
        }
    }
    #[inline]
    fn entry_floor(&self) -> f32 {
        sweep_aabb(self.sweep, &outward_box(self.s)).map_or(0.0, |(t0, _)| t0)
    }
    /// With [`sweep_aabb`]'s ray: `to - from` rounded from its `f64`
    /// difference (an overflow there makes the entry floor 0).
    #[inline]
    fn entry_ceiling(&self) -> f64 {
        let (f, t) = (d3(self.sweep.from), d3(self.sweep.to));
        let d = [0, 1, 2].map(|i| (t[i] - f[i]) as f32);
        if !d.iter().all(|x| x.is_finite()) {
            return 0.0;
        }
        let rho = self.s.radius as f64 + self.sweep.radius as f64;
        entry_ceiling(self.sweep.from.into(), d, self.s.center.into(), rho)
    }
}

/// Sphere sweep against a box: a parameter interval `[t0, t1]` within `[0, 1]`
/// that contains every time at which the sweep's sphere touches the closed box
/// `b` (its centre `from + t (to - from)` within `sweep.radius` of `b`), or
/// `None` only when it never does. Conservative, never exact: the index walks
/// prune with it, and [`sweep_sphere`] is the exact test.
///
/// It is [`ray_aabb`] for the ray from `from` along `to - from` rounded to `f32`
/// (`max_t = 1`), against `b` grown on each axis by `R` plus a bound on what
/// that rounding moved the segment, everything rounded outward. So `t0` is
/// monotone in the box (a larger box never enters later) and never above the
/// time [`sweep_sphere`] returns for a sphere inside `b`. With `radius == 0`
/// and an `f32` direction it is exactly `ray_aabb` of the segment. A sweep
/// whose direction overflows `f32` (end points near `±f32::MAX` on opposite
/// sides) prunes nothing: `Some((0, 1))`. Cost: [`ray_aabb`]'s plus a few
/// exact sums.
#[inline]
pub fn sweep_aabb(sweep: &SphereSweep, b: &Aabb) -> Option<(f32, f32)> {
    let Some((ray, grow)) = sweep_ray(sweep) else {
        return Some((0.0, 1.0));
    };
    let lo = [0, 1, 2].map(|i| sum_floor(b.min[i], -grow[i]));
    let hi = [0, 1, 2].map(|i| -sum_floor(-b.max[i], -grow[i]));
    ray_aabb(&ray, &Aabb::new(Vec3::from(lo), Vec3::from(hi)))
}

/// The ray [`sweep_aabb`] clips (from `from` along `to - from` rounded to
/// `f32`, `max_t = 1`) and how much it grows a box on each axis: `R` plus a
/// bound on what the direction's rounding moved the segment (at `t = 1`),
/// rounded up; `None` when the direction overflows `f32`. Written once for
/// [`sweep_aabb`] and [`EntryBound::sweep`]. O(1).
#[inline]
fn sweep_ray(sweep: &SphereSweep) -> Option<(Ray, [f64; 3])> {
    let (from, to) = (d3(sweep.from), d3(sweep.to));
    let mut dir = [0.0f32; 3];
    let mut grow = [0.0f64; 3];
    for i in 0..3 {
        // The exact direction `s + e`, its `f32` rounding, and what the
        // rounding moves the segment by at most (at t = 1).
        let (s, e) = super::exact::two_sum_pub(to[i], -from[i]);
        let d = s as f32;
        if !d.is_finite() {
            return None;
        }
        dir[i] = d;
        let moved = (s - d as f64).abs() + e.abs();
        grow[i] = if moved == 0.0 {
            sweep.radius as f64
        } else {
            // Rounded up: at least R + moved.
            let g = sweep.radius as f64 + moved;
            g + g * (4.0 * U)
        };
    }
    Some((Ray::with_max_t(sweep.from, Vec3::from(dir), 1.0), grow))
}

/// A ray or a sphere sweep prepared for many box tests of a front-to-back
/// search: [`EntryBound::enter`] bounds [`ray_aabb`]'s (or [`sweep_aabb`]'s)
/// entry parameter from below at a fraction of its cost.
///
/// Why: those two are exact (six `f64` divisions with exact corrections, and
/// for a sweep exact sums to grow the box), and a tree's first-hit search
/// tests two child boxes per node and a chunk bound per eight objects: W8
/// (100k sweeps through W4's set, callgrind) spent 57% of the loose k-d
/// tree's instructions in them. A pruning bound needs only to be *below* the
/// exact entry of every sphere inside: this one clips with [`RayClip`] (the
/// inverse direction computed once, no division per box), for a sweep thick
/// by its growth ([`RayClip::thick`]: the box is not grown at all).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EntryBound {
    /// The prepared (thick) ray; `None` when the sweep's direction overflows
    /// `f32` (then every box is entered at 0, as [`sweep_aabb`] says).
    clip: Option<RayClip>,
}

impl EntryBound {
    /// For a ray with a finite origin and direction (validated). O(1).
    #[inline]
    pub(crate) fn ray(ray: &Ray) -> EntryBound {
        let finite = ray.origin.is_finite() && ray.dir.is_finite() && !ray.max_t.is_nan();
        EntryBound {
            clip: finite.then(|| RayClip::new(ray)),
        }
    }

    /// For a sphere sweep: the ray of [`sweep_aabb`], thick by its growth
    /// ([`RayClip::thick`]), plus `2^-22 (m + g)` on each axis, where `m`
    /// bounds the magnitude of every finite coordinate of the boxes whose
    /// `sweep_aabb` entry the bound must stay below (`∞` when unknown: then
    /// every box is entered at 0).
    ///
    /// Why the extra: `sweep_aabb` grows a box by `g` and rounds the grown
    /// sides outward to `f32`, moving each by less than `2^-23 (m + g)`; a
    /// bound for the box grown exactly by `g` can exceed its entry by that
    /// much. With the extra, the thick ray covers the rounded box of every
    /// box with coordinates up to `m`, so [`EntryBound::enter`] is at most
    /// `sweep_aabb`'s `t0` on all of them. The first-hit searches need it:
    /// [`sweep_sphere`]'s time is clamped to `sweep_aabb`'s entry of the
    /// sphere's box, and a pruned node's bound must stay below it. (A
    /// selection walk needs only "touches nothing", which `m = 0` gives.)
    /// O(1).
    #[inline]
    pub(crate) fn sweep(sweep: &SphereSweep, m: f32) -> EntryBound {
        EntryBound {
            clip: sweep_ray(sweep)
                .map(|(ray, g)| {
                    // Rounded up (the factor exceeds the sum's rounding).
                    let g = g.map(|g| widen(g + (m as f64 + g) * (1.0 / 4194304.0), true));
                    (ray, g)
                })
                .filter(|(ray, g)| ray.origin.is_finite() && g.iter().all(|x| x.is_finite()))
                .map(|(ray, g)| RayClip::thick(&ray, g)),
        }
    }

    /// A parameter at most the `t0` of [`ray_aabb`] (for a ray) or
    /// [`sweep_aabb`] (for a sweep, on boxes with coordinates up to its `m`)
    /// on `b`, and `None` only when the exact interval of `b` grown by the
    /// sweep's growth is empty (so the cast touches nothing inside `b`). A
    /// search that skips a box entered after its best contact skips only
    /// what the exact test would (and a little less). Monotone in `b` (a
    /// larger box is never entered later): the clip's roundings are.
    ///
    /// Why it is below: [`RayClip::thick`]'s interval contains the exact
    /// interval of the box grown as [`EntryBound::sweep`] says, which
    /// contains `sweep_aabb`'s rounded box; its `t0` is then at most that
    /// box's exact entry, and rounded down to `f32` at most the entry's `f32`
    /// floor, `sweep_aabb`'s (or for a ray `ray_aabb`'s) `t0`. Infinite sides
    /// stay infinite; a NaN side is ignored, as in `clip`. Cost: 6 `f64`
    /// subtractions and products, no division. (Tested against the exact
    /// tests, including adversarial magnitudes.)
    #[inline(always)]
    pub(crate) fn enter(&self, b: &Aabb) -> Option<f32> {
        let Some(clip) = &self.clip else {
            return Some(0.0);
        };
        Some(round_down(clip.clip(b)?.0))
    }

    /// The octant a cast enters first among a node's 8 children in cells
    /// without growth: bit `a` set where the direction is negative on axis
    /// `a`. Visiting octant `near ^ j` for `j = 0..8` goes front to back
    /// across the node's split planes (no octant before one it can only be
    /// reached through). O(1).
    #[inline]
    pub(crate) fn near_octant(&self) -> usize {
        self.clip.as_ref().map_or(0, |c| {
            (c.d[0] < 0.0) as usize
                | ((c.d[1] < 0.0) as usize) << 1
                | ((c.d[2] < 0.0) as usize) << 2
        })
    }

    /// [`EntryBound::enter`] of the 8 boxes made of the per-axis intervals
    /// `halves` ([`RayClip::entry_octants`]: box `k` takes
    /// `halves[a][(k >> a) & 1]` on axis `a`), before its rounding down to
    /// `f32`, and `+∞` where `enter` is `None` (or `Some(∞)`: entered at no
    /// finite parameter). `enter` of each box is this value's `f32` floor;
    /// a search that prunes a box when this exceeds an `f32` bound prunes
    /// exactly when `enter` does, except where the bound is that floor
    /// itself (then the box's exact entry is above the bound as well). Not
    /// rounded: 8 roundings a node with a branch each, ~1.5% of a W8 octree
    /// first-hit sweep's instructions and 66 -> 56 mispredicts (callgrind:
    /// the rounding's branch). No branch per box.
    #[inline(always)]
    pub(crate) fn enter_octants(&self, halves: [[(f32, f32); 2]; 3]) -> [f64; 8] {
        match &self.clip {
            Some(clip) => clip.entry_octants(halves),
            None => [0.0; 8],
        }
    }

    /// The octants among the 8 boxes of `halves` (as in
    /// [`EntryBound::enter_octants`]; bit `k` for box `k`) that the cast may
    /// enter at a parameter up to `t`: those overlapping the box that the
    /// thick ray sweeps over `[0, min(t, max_t)]`. A superset of the boxes
    /// entered by then (every point of the thick ray up to `t` is in that
    /// box, which is rounded outward by `2^-50` of its terms, more than the
    /// two roundings of `o + d t`), so a search that scans only these for a
    /// contact before `t` misses none that the slab clip would keep; coarser
    /// than [`EntryBound::enter_octants`] for a long diagonal cast, but ~40
    /// `f64` operations and 12 comparisons for all 8 boxes, no branch,
    /// instead of 12 slab parameters and eight clips. A NaN side or bound keeps the box; a `None` clip
    /// (an overflowing direction) keeps all 8. O(1).
    #[inline(always)]
    pub(crate) fn reach_octants(&self, halves: [[(f32, f32); 2]; 3], t: f32) -> u32 {
        let Some(clip) = &self.clip else {
            return 0xFF;
        };
        let t = (t as f64).min(clip.max_t);
        let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
        for a in 0..3 {
            // 0 · ∞ is NaN, which `min`/`max` drop: a zero direction stays put.
            let dt = clip.d[a] * t;
            let (back, ahead) = (dt.min(0.0), dt.max(0.0));
            lo[a] = clip.o_lo[a] + back;
            lo[a] -= (clip.o_lo[a].abs() - back) * CLIP_WIDEN;
            hi[a] = clip.o_hi[a] + ahead;
            hi[a] += (clip.o_hi[a].abs() + ahead) * CLIP_WIDEN;
        }
        octants_overlapping(lo, hi, halves)
    }
}

/// The octants among the 8 boxes of `halves` (box `k` takes
/// `halves[a][(k >> a) & 1]` on axis `a`; bit `k` of the result) that the
/// closed box `[lo, hi]` overlaps; a NaN bound or side keeps the box. No
/// branch: two comparisons per half. O(1).
#[inline(always)]
fn octants_overlapping(lo: [f64; 3], hi: [f64; 3], halves: [[(f32, f32); 2]; 3]) -> u32 {
    // The octants on the low half of each axis.
    const LOW: [u32; 3] = [0x55, 0x33, 0x0F];
    let mut keep = 0xFF;
    for a in 0..3 {
        let [(l0, h0), (l1, h1)] = halves[a];
        let low = !(lo[a] > h0 as f64 || hi[a] < l0 as f64);
        let high = !(lo[a] > h1 as f64 || hi[a] < l1 as f64);
        keep &= (LOW[a] & 0u32.wrapping_sub(low as u32))
            | (!LOW[a] & 0xFF & 0u32.wrapping_sub(high as u32));
    }
    keep
}

/// `x` where it exceeds `acc`, else `acc`: a NaN `x` is ignored (a NaN box
/// side constrains nothing). A select, not `f64::max`, so that it needs no
/// NaN fix-up and no branch: one instruction where `f64::max` (and a
/// comparison of the `u64` bits, with no SSE2 min) costs several. Also the
/// k-nearest selection's `max` of its keys (`broad/nearest.rs`: 1.70k ->
/// 1.01k instructions a query against `f64::min`/`max`, callgrind on
/// `examples/knn_leaf`, 100k points, k = 10).
#[inline(always)]
pub(crate) fn above(x: f64, acc: f64) -> f64 {
    if x > acc {
        x
    } else {
        acc
    }
}

/// `x` where it is below `acc`, else `acc`: a NaN `x` is ignored (as
/// [`above`]); the k-nearest selection's `min`.
#[inline(always)]
pub(crate) fn below(x: f64, acc: f64) -> f64 {
    if x < acc {
        x
    } else {
        acc
    }
}

/// The largest `f32` not above `x + g` (exactly; `x` passes through when it
/// is not finite).
#[inline]
pub(super) fn sum_floor(x: f32, g: f64) -> f32 {
    if !x.is_finite() {
        return x;
    }
    let (v, e) = super::exact::two_sum_pub(x as f64, g);
    // `round_down(v)` is at least one `f64` step below `v` unless `v` is an
    // `f32`; only then can the error `e` push the true value below it.
    if e < 0.0 && (v as f32) as f64 == v {
        step_down(v as f32)
    } else {
        round_down(v)
    }
}

/// The smallest `f32` box containing the ball exactly.
#[inline]
fn outward_box(s: &Sphere) -> Aabb {
    let r = s.radius as f64;
    let lo = [0, 1, 2].map(|i| sum_floor(s.center[i], -r));
    let hi = [0, 1, 2].map(|i| -sum_floor(-s.center[i], -r));
    Aabb::new(Vec3::from(lo), Vec3::from(hi))
}

/// The distance from `p` to the closed ball `s`, `max(0, |c - p| - r)`
/// (`0` inside), **correctly rounded** to `f32`: the `f32` nearest to the
/// exact real value (ties to even).
///
/// This is the one distance of the k-nearest queries (with `r = 0` for the
/// centre distance), so every index reports the same value for the same
/// object, bit for bit, and orders ties the same way. Correct rounding is what
/// makes it consistent with the index walks: it is monotone in the exact
/// distance, so a sphere inside a box is never reported nearer than
/// [`point_aabb_distance`] of that box, and a sphere query of an `f32` radius
/// `R` (exact) selects every object whose distance is `<= R`. Its value is
/// also what a reader expects: equal for equal centres and radii, `0` inside,
/// exact whenever the exact distance is an `f32`.
///
/// Cost: an `f64` evaluation (~15 flops and a square root) decides unless the
/// exact value lies within ~1e-15 relative of a rounding boundary; then exact
/// comparisons with the boundary (`exact.rs`) decide. Distances beyond
/// `f32::MAX` round to `f32::MAX` or `∞` as IEEE rounding says.
#[inline]
pub fn point_sphere_distance(p: Vec3, s: &Sphere) -> f32 {
    point_sphere_distance_given_sq(p, s, point_point_distance_sq(p, s.center))
}

/// [`point_sphere_distance`] when the caller already holds
/// `s2 = `[`point_point_distance_sq`]`(p, s.center)` (the k-nearest searches
/// compute it for their pruning test first): the same value, bit for bit,
/// without computing the squared distance twice. `s2` must be exactly that
/// function's value, as the error bound below is derived from it. O(1).
#[inline]
pub(crate) fn point_sphere_distance_given_sq(p: Vec3, s: &Sphere, s2: f64) -> f32 {
    let dist = s2.sqrt();
    let r = s.radius as f64;
    let v = dist - r;
    // Each difference rounds once, squares and sums three times, the root
    // about 1.5 more: `dist` is within 4u of `|a - c|`, and the subtraction adds
    // u of `|v|` (no underflow: nonzero differences of `f32`s are >= 2^-149).
    let err = 8.0 * U * (dist + v.abs());
    if v + err <= 0.0 {
        return 0.0;
    }
    let y = (v as f32).max(0.0);
    if v - err > rounding_below(y) && v + err < rounding_above(y) {
        return y;
    }
    distance_rounded_exactly(d3(p), d3(s.center), r, v, err)
}

/// The midpoint between the non-negative `f32` `y` and the next one up (exact
/// in `f64`; `2^128` stands for the one above `f32::MAX`): reals below it
/// round to `y` or lower.
#[inline]
fn rounding_above(y: f32) -> f64 {
    // A non-negative finite `f32`'s next one up is one bit pattern away
    // (`-0.0` is taken as `+0.0`, whose pattern is 0); from `f32::MAX` on
    // (and for `∞`, where the midpoint stays `∞`) `2^128` stands for it.
    let next = if y < f32::MAX {
        let b = if y == 0.0 { 0 } else { y.to_bits() };
        f32::from_bits(b + 1) as f64
    } else {
        2f64.powi(128)
    };
    (y as f64 + next) * 0.5
}

/// The midpoint between the non-negative `f32` `y` and the next one down;
/// `-∞` for `y = 0` (negative values clamp to 0). A positive `y`'s next one
/// down is one bit pattern away (`f32::MAX` below `∞`, whose midpoint
/// stays `∞`).
#[inline]
fn rounding_below(y: f32) -> f64 {
    if y == 0.0 {
        f64::NEG_INFINITY
    } else {
        (y as f64 + f32::from_bits(y.to_bits() - 1) as f64) * 0.5
    }
}

/// [`point_sphere_distance`] when the `f64` value `v` (within `err` of the
/// exact `x = |a - c| - r`) does not decide the rounding: a binary search over
/// the `f32`s between `v - err` and `v + err` (in bit order, which is numeric
/// order for non-negative floats) for the one `x` rounds to, each step an
/// exact comparison of `x` with a rounding midpoint (ties to even). At most
/// ~32 steps; usually 1 or 2 (the interval is a few ulps wide unless `r`
/// nearly cancels a huge `|a - c|`).
#[cold]
#[inline(never)]
fn distance_rounded_exactly(a: [f64; 3], c: [f64; 3], r: f64, v: f64, err: f64) -> f32 {
    // round(max(0, x)) <= y, for a non-negative f32 y.
    let at_most = |y: f32| {
        if y == f32::INFINITY {
            return true;
        }
        match super::exact::cmp_distance(a, c, r, rounding_above(y)) {
            Ordering::Less => true,
            Ordering::Equal => y.to_bits() & 1 == 0,
            Ordering::Greater => false,
        }
    };
    // round(x) is monotone: it lies between the roundings of x's bounds.
    let mut lo = if v - err > 0.0 {
        round_down(v - err).to_bits()
    } else {
        0 // +0.0
    };
    let mut hi = (-round_down(-(v + err))).to_bits();
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if at_most(f32::from_bits(mid)) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    f32::from_bits(lo)
}

/// The distance from `p` to the closed box `b` (`0` inside), correctly rounded
/// to `f32` like [`point_sphere_distance`] (it is that distance to the box's
/// closest point). The bound the k-nearest searches prune with: for a sphere
/// inside `b`, neither its surface distance nor its centre distance is below
/// this (correct rounding is monotone). O(1).
#[inline]
pub fn point_aabb_distance(p: Vec3, b: &Aabb) -> f32 {
    point_sphere_distance(p, &Sphere::new(p.clamp(b.min, b.max), 0.0))
}

/// `|c - p|²` evaluated in `f64`: each difference is exact unless the two
/// coordinates' exponents are more than 29 apart, and then rounds once
/// (within `u` of itself), and the squares and sums round three times: within
/// `6u` relative of the exact value (`u = 2^-53`), never overflowing or
/// underflowing for finite `f32` inputs. The cheap half of
/// [`distance_exceeds`]. O(1), no square root.
#[inline]
pub fn point_point_distance_sq(p: Vec3, c: Vec3) -> f64 {
    let (a, c) = (d3(p), d3(c));
    let diff = [0, 1, 2].map(|i| a[i] - c[i]);
    dot(diff, diff)
}

/// `|c - p|²` evaluated in `f32` (three differences, three products, two
/// sums, each rounded): a cheap pre-test beside [`point_point_distance_sq`],
/// with no conversions to `f64`. It is at most `(1 + u)^5` times the exact
/// value plus about `3·2^-150` for the products that underflow (`u = 2^-24`), or `∞`
/// only when the exact value is above `f32::MAX·(1 - 4u)`; so whenever
/// [`point_point_distance_sq`] is at most `t`, this is at most
/// [`sq_threshold_f32`]`(t)`. O(1). The searches run it four lanes at a
/// time ([`point_point_distance_sq_f32_4`]); this is its definition.
#[cfg(test)]
pub(crate) fn point_point_distance_sq_f32(p: Vec3, c: Vec3) -> f32 {
    let (x, y, z) = (c.x - p.x, c.y - p.y, c.z - p.z);
    x * x + y * y + z * z
}

/// `|c - p|²` evaluated in `f32` from `p` to four centres at once, one per
/// SIMD lane (the spheres' radii are ignored): three differences, three
/// products, two sums, each rounded, in each lane the same operations in the
/// same order as `point_point_distance_sq_f32`, hence the same value (test
/// `f32_squared_distance_stays_within_its_threshold`). So whenever
/// [`point_point_distance_sq`] is at most `t`, a lane is at most
/// [`sq_threshold_f32`]`(t)`. O(1).
#[inline(always)]
pub(crate) fn point_point_distance_sq_f32_4(p: Vec3, s: [&Sphere; 4]) -> Vec4 {
    let [cx, cy, cz, _] = sphere_lanes(s);
    distance_sq_lanes(p, [cx, cy, cz])
}

/// `|c - p|²` in `f32` to the four centres whose `x`, `y`, `z` are the
/// lanes of `c`: the one body of [`point_point_distance_sq_f32_4`] and
/// [`spheres_beyond_f32_4`]. O(1).
#[inline(always)]
fn distance_sq_lanes(p: Vec3, [cx, cy, cz]: [Vec4; 3]) -> Vec4 {
    let (x, y, z) = (
        cx - Vec4::splat(p.x),
        cy - Vec4::splat(p.y),
        cz - Vec4::splat(p.z),
    );
    x * x + y * y + z * z
}

/// The four-lane `f32` pre-test of [`distance_exceeds`] for spheres (the
/// surface metric): bit `j` set when sphere `s[j]` is surely farther than the
/// bound whose midpoint ([`distance_midpoint`]) rounded up to `f32` is `m`
/// ([`midpoint_up_f32`]): a lane's `|c - p|²` (as
/// [`point_point_distance_sq_f32_4`]) above its
/// [`sphere_sq_thresholds_f32_4`]. O(1).
///
/// Why a set bit implies `distance_exceeds(s2, r, d)`: write `A = m₆₄ + r`
/// (`m₆₄` the `f64` midpoint). The threshold is at least `A²·(1 + 2^-17) +
/// 2^-126` or `∞` (see there). The lane's distance is at most `(1 + u)^5`
/// times the exact `D = |c - p|²` plus an underflow under `2^-148` (see
/// `point_point_distance_sq_f32`), so a lane above a finite threshold has
/// `D > A²·(1 + 2^-18)`, and the `f64` `s2 ≥ D·(1 - 6·2^-53)` is above
/// `exceeds_threshold`'s `A²·(1 + 1e-12)` (rounded three times in `f64`). A
/// lane whose distance overflowed to `∞` has `D > f32::MAX·(1 - 4u)`, and a
/// finite threshold means `A²·(1 + 2^-17) ≤ f32::MAX`: the same conclusion.
/// An infinite threshold (an infinite `m`, or an overflow) sets no bit. So
/// the pre-test only ever keeps too many.
#[inline(always)]
pub(crate) fn spheres_beyond_f32_4(p: Vec3, s: [&Sphere; 4], m: f32) -> u32 {
    let [cx, cy, cz, r] = sphere_lanes(s);
    let d = distance_sq_lanes(p, [cx, cy, cz]);
    d.cmpgt(sphere_sq_thresholds_f32_4(m, r)).bitmask()
}

/// The thresholds of [`spheres_beyond_f32_4`] for radii `r` (non-negative)
/// and the rounded-up midpoint `m`: `(m + r)²` grown by `2^-16` relative and
/// by `2·f32::MIN_POSITIVE`, in `f32`. At least `A²·(1 + 2^-17) + 2^-126`
/// for `A = m₆₄ + r` (`m ≥ m₆₄`) or `∞`: the sum, the square and the
/// product each round down by at most `u = 2^-24` relative (or underflow
/// under `2^-149`), and the growth's `(1 + 2^-16)·(1 - u)^5` exceeds `1 +
/// 2^-17`. The additive term is doubled so that a host which flushes
/// subnormal results to zero (a square just under `2^-126` becoming 0) still
/// gets a threshold above `A²`. O(1).
#[inline(always)]
pub(crate) fn sphere_sq_thresholds_f32_4(m: f32, r: Vec4) -> Vec4 {
    let a = Vec4::splat(m) + r;
    a * a * Vec4::splat(1.0 + 1.0 / 65_536.0) + Vec4::splat(2.0 * f32::MIN_POSITIVE)
}

/// The `f64` midpoint `m` of [`distance_midpoint`] rounded up to `f32` (`∞`
/// past `f32::MAX`): the `m` of [`spheres_beyond_f32_4`]. O(1).
#[inline]
pub(crate) fn midpoint_up_f32(m: f64) -> f32 {
    -round_down(-m)
}

/// Four spheres as SIMD lanes: their `x`, `y`, `z` and radii, one vector
/// each (the rows `(x, y, z, r)` transposed, a few shuffles). O(1).
#[inline(always)]
fn sphere_lanes(s: [&Sphere; 4]) -> [Vec4; 4] {
    let t =
        glam::Mat4::from_cols_array_2d(&s.map(|s| [s.center.x, s.center.y, s.center.z, s.radius]))
            .transpose();
    [t.x_axis, t.y_axis, t.z_axis, t.w_axis]
}

/// The `f32` threshold for `point_point_distance_sq_f32` (and each lane of
/// [`point_point_distance_sq_f32_4`]) that keeps every
/// point whose [`point_point_distance_sq`] is at most `t` (a non-negative
/// `f64`): `t` grown by `2^-18` relative (the `f32` sum's `5u` and the `f64`
/// one's error, under `6·2^-53` even where its differences round, with room
/// to spare) and by `f32::MIN_POSITIVE` (the
/// underflow), rounded up to `f32` (`∞` past `f32::MAX`). A pre-test with it
/// only ever keeps too many, never drops one. O(1).
#[inline]
pub(crate) fn sq_threshold_f32(t: f64) -> f32 {
    let x = t * (1.0 + 1.0 / 262_144.0) + f32::MIN_POSITIVE as f64;
    let f = x as f32;
    if (f as f64) < x {
        f32::from_bits(f.to_bits() + 1)
    } else {
        f
    }
}

/// An `f32` at least the correctly rounded distance `|c - p|`, given
/// `s2 = `[`point_point_distance_sq`]`(p, c)`: `s2` is within `6u` relative
/// of `|c - p|²` and the root adds half an ulp, so `sqrt(s2)·(1 + 1e-12)` is
/// above the exact distance, and rounding it up keeps it above the correctly
/// rounded one (rounding is monotone). `∞` beyond `f32::MAX`. The k-nearest
/// searches' early bound from a first group of candidates
/// (`KBest::tighten_by_centres`). O(1).
#[inline]
pub(crate) fn distance_at_most_from_sq(s2: f64) -> f32 {
    -round_down(-(s2.sqrt() * (1.0 + 1e-12)))
}

/// [`point_point_distance_sq`] from `p` to the closest point of the closed
/// box `b` (`0` inside). O(1).
#[inline]
pub fn point_aabb_distance_sq(p: Vec3, b: &Aabb) -> f64 {
    point_point_distance_sq(p, p.clamp(b.min, b.max))
}

/// One axis's term of [`point_aabb_distance_sq`]: the squared gap from `p` to
/// the closed interval `[lo, hi]` (`0` inside), in `f64`. Summed over x, y, z
/// in that order, the terms equal [`point_aabb_distance_sq`] bit for bit (the
/// same clamp, difference and products): searches that test many boxes
/// sharing their intervals (an octree node's 8 children take one of 2 halves
/// per axis) compute 6 terms instead of 8 boxes. O(1).
#[inline]
pub fn axis_gap_sq(p: f32, lo: f32, hi: f32) -> f64 {
    let d = p as f64 - p.max(lo).min(hi) as f64;
    d * d
}

/// Whether the correctly rounded distance `max(0, sqrt(s2) - r)` (as
/// [`point_sphere_distance`] and [`point_aabb_distance`] compute it, `s2`
/// from [`point_point_distance_sq`] or [`point_aabb_distance_sq`]) is surely
/// greater than the `f32` `d`: the k-nearest searches' pruning test, which
/// skips the square root and the rounding for the many candidates beyond the
/// current k-th best. Conservative: `false` may still mean "greater" (within
/// 1e-12 relative of the boundary, or `d` infinite), `true` never errs.
///
/// Why: the rounded distance exceeds `d` iff the exact one exceeds the
/// midpoint `m` between `d` and the next `f32` up (at `m` exactly, ties to
/// even may round down, so only `> m` counts), i.e. iff `|c - p| > m + r`,
/// i.e. `|c - p|² > (m + r)²` (both sides non-negative as `m > 0`). `s2` is
/// within `6u` of `|c - p|²` and `(m + r)²` is evaluated within `3u`; a margin
/// of 1e-12 relative covers both. O(1): a few flops, no square root.
#[inline]
pub fn distance_exceeds(s2: f64, r: f32, d: f32) -> bool {
    s2 > exceeds_threshold(distance_midpoint(d), r)
}

/// The midpoint `m` of [`distance_exceeds`] for the bound `d`: halfway between
/// `d` (`-0.0` taken as `0`) and the next `f32` up, `∞` when `d` is infinite
/// or `f32::MAX` (nothing surely exceeds those). The searches keep it beside
/// their bound, which changes far less often than it is tested. O(1).
#[inline]
pub(crate) fn distance_midpoint(d: f32) -> f64 {
    if d == f32::INFINITY {
        return f64::INFINITY;
    }
    // -0.0 (a limit of -0.0) is 0; `d + 1 ulp` overflows to ∞ at f32::MAX.
    let d = if d > 0.0 { d } else { 0.0 };
    (d as f64 + f32::from_bits(d.to_bits() + 1) as f64) * 0.5
}

/// The squared distance above which [`distance_exceeds`] holds for a sphere
/// of radius `r` and the midpoint `m` ([`distance_midpoint`]): `(m + r)²`
/// with the 1e-12 relative margin; `∞` for an infinite `m`. O(1).
#[inline]
pub(crate) fn exceeds_threshold(m: f64, r: f32) -> f64 {
    let t = m + r as f64;
    t * t * (1.0 + 1e-12)
}

/// A ray prepared for many conservative box clips ([`RayClip::clip`]): its
/// origin, direction and `1 / direction` in `f64`, computed once.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayClip {
    /// Origin.
    pub o: [f64; 3],
    /// Direction.
    pub d: [f64; 3],
    /// `1 / d` (rounded; unused where `d` is 0).
    inv: [f64; 3],
    /// Largest parameter.
    max_t: f64,
    /// The origin the boxes' low sides are measured from: `o`, or for a
    /// thick ray ([`RayClip::thick`]) at least `o + g` (rounded up).
    o_hi: [f64; 3],
    /// The origin the boxes' high sides are measured from: `o`, or at most
    /// `o - g` (rounded down).
    o_lo: [f64; 3],
}

/// Relative widening of [`RayClip`]'s `f64` results: 2^-50 = 8u, with u =
/// 2^-53 the unit roundoff of `f64`.
const CLIP_WIDEN: f64 = 1.0 / 1_125_899_906_842_624.0;

/// `x` moved away from 0 (`up`) or towards −∞ (`!up`) by [`CLIP_WIDEN`]
/// relative, as a product (exact at ±∞ and 0, no `∞ - ∞`).
#[inline]
fn widen(x: f64, up: bool) -> f64 {
    if (x > 0.0) == up {
        x * (1.0 + CLIP_WIDEN)
    } else {
        x * (1.0 - CLIP_WIDEN)
    }
}

impl RayClip {
    /// Prepares `ray` (finite origin, finite direction).
    #[inline]
    pub(crate) fn new(ray: &Ray) -> RayClip {
        let o = [0, 1, 2].map(|a| ray.origin[a] as f64);
        let d = [0, 1, 2].map(|a| ray.dir[a] as f64);
        RayClip {
            o,
            d,
            inv: d.map(|x| 1.0 / x),
            max_t: ray.max_t as f64,
            o_hi: o,
            o_lo: o,
        }
    }

    /// Prepares `ray` (finite origin, finite direction) to clip boxes grown
    /// by `g[a] >= 0` on each side of axis `a` without growing them: growing
    /// the low side of a slab by `g` moves its parameter `(lo - g - o) / d`
    /// exactly as moving the origin to `o + g` does, so the low sides are
    /// measured from `o_hi >= o + g` and the high sides from `o_lo <= o - g`
    /// (each rounded outward once here, per ray). [`RayClip::clip`]'s
    /// analysis holds unchanged: each slab parameter is still one `f64`
    /// subtraction of two exact `f64`s, a reciprocal and a product; and the
    /// outward origins only move the low sides' parameters down and the high
    /// sides' up for a positive `d` (for a negative `d` the low side is the
    /// exit and moves up, the high side the entry and moves down), so the
    /// interval still contains the grown box's exact one. A zero component
    /// is decided by `o_hi < lo` or `o_lo > hi`, exact comparisons that
    /// imply `o` is outside the grown slab.
    #[inline]
    pub(crate) fn thick(ray: &Ray, g: [f64; 3]) -> RayClip {
        let c = RayClip::new(ray);
        // Rounded outward: a sum of two finite `f64`s below 2^200 is within a
        // relative 2^-53 of the exact one, and the factor moves it by more
        // than that, up for `o + g` and down for `o - g` (a sum that rounds
        // to 0 is exact).
        RayClip {
            o_hi: [0, 1, 2].map(|a| widen(c.o[a] + g[a], true)),
            o_lo: [0, 1, 2].map(|a| widen(c.o[a] - g[a], false)),
            ..c
        }
    }

    /// An `f64` interval `[t0, t1]` containing the exact parameter interval
    /// of the ray inside the closed box `b`, clipped to `[0, max_t]`; `None`
    /// only when that exact interval is empty. Conservative, not tight: a
    /// cheap stand-in for [`ray_aabb`] where an outward bound suffices (the
    /// grids' path clipping), with no division and no exact arithmetic.
    ///
    /// Why it contains the exact interval: `f32` inputs in `f64` never
    /// overflow or underflow in `(x - o) · (1 / d)` (magnitudes within
    /// 2^±300), so each of its three roundings is a factor `1 + δ`,
    /// `|δ| <= u = 2^-53`: the computed slab parameter is within `3.1u` of the
    /// exact one, relative. The largest entry is moved down and the smallest
    /// exit up by 2^-50 = `8u` relative (a product, rounding once more): at
    /// least `6.9u`, more than that error. Max and min are exact, 0 and
    /// `max_t` are exact bounds, and a zero direction component is decided by
    /// exact comparisons (no `0 · ∞`). Infinite box sides give infinite
    /// parameters of the right sign; a NaN side is ignored (conservative).
    /// Cost: 6 subtractions and 6 multiplications.
    #[inline(always)]
    pub(crate) fn clip(&self, b: &Aabb) -> Option<(f64, f64)> {
        let (mn, mx) = (b.min.to_array(), b.max.to_array());
        self.finish([
            self.slab(0, mn[0], mx[0])?,
            self.slab(1, mn[1], mx[1])?,
            self.slab(2, mn[2], mx[2])?,
        ])
    }

    /// The entries of [`RayClip::clip`] of the 8 boxes whose side on axis
    /// `a` is one of the two intervals `halves[a]`: box `k` takes
    /// `halves[a][(k >> a) & 1]`, as an octree's children take their cells'
    /// halves. Box `k`'s `t0` from `clip`, bit for bit (the same slab
    /// parameters; folded y and z first, then x, which gives the same
    /// largest entry and smallest exit, and [`RayClip::widen_interval`]
    /// makes a zero entry `+0.0` whatever the order), or `+∞` where `clip`
    /// is `None` (or its `t0` is `+∞`), for 12 slab parameters instead of
    /// 48 and no branch per box (an `Option` per box mispredicted ~10
    /// times a W8 octree first-hit sweep, callgrind): what an octree's cast
    /// search needs per inner node.
    #[inline(always)]
    pub(crate) fn entry_octants(&self, halves: [[(f32, f32); 2]; 3]) -> [f64; 8] {
        // Written out: as `[0, 1, 2].map(..)` this compiled to an
        // out-of-line `array::try_map` call per node; with the `[T; 8]::map`
        // that rounded the entries then, 11% of a W8 octree first-hit
        // sweep's instructions (callgrind; docs/bench/run19-02adaaa.txt).
        let axis = |a: usize| {
            let [(l0, h0), (l1, h1)] = halves[a];
            let [(e0, x0), (e1, x1)] =
                [self.slab_or_empty(a, l0, h0), self.slab_or_empty(a, l1, h1)];
            ([e0, e1], [x0, x1])
        };
        let ((xe, xx), (ye, yx), (ze, zx)) = (axis(0), axis(1), axis(2));
        // Boxes `2j` and `2j + 1` share their y and z slabs: those are
        // folded once per pair, then each of the pair's x slabs, with
        // selects and no branch (`widened`'s fold in another order: the
        // same largest entry and smallest exit, NaNs ignored either way,
        // and a zero entry's sign made `+` by `widen_interval`). Against a
        // fold per box with an `Option` per slab (callgrind, W8 octree
        // first hits as in `LinearOctree::first_node`'s notes): 9.1k ->
        // 8.3k instructions and 48 -> 34 mispredicted branches a sweep.
        let mut out = [0.0; 8];
        for j in 0..4 {
            let near_yz = above(ze[j >> 1], above(ye[j & 1], f64::NEG_INFINITY));
            let far_yz = below(zx[j >> 1], below(yx[j & 1], f64::INFINITY));
            for h in 0..2 {
                let (t0, t1) = self.widen_interval(above(xe[h], near_yz), below(xx[h], far_yz));
                out[2 * j + h] = if t0 <= t1 { t0 } else { f64::INFINITY };
            }
        }
        out
    }

    /// [`RayClip::slab`] with `None` (a zero direction component, the
    /// origin outside the slab) as the empty interval `(+∞, −∞)`, which
    /// every clip then finds empty. (`+∞` folds into the entry and `−∞`
    /// into the exit like any other value.)
    #[inline(always)]
    fn slab_or_empty(&self, a: usize, lo: f32, hi: f32) -> (f64, f64) {
        self.slab(a, lo, hi)
            .unwrap_or((f64::INFINITY, f64::NEG_INFINITY))
    }

    /// One axis of [`RayClip::clip`]: the slab `[lo, hi]`'s entry and exit
    /// parameters (unwidened), `None` when a zero direction component leaves
    /// the origin outside it, and `(-∞, ∞)` (no constraint) when it is inside.
    #[inline(always)]
    fn slab(&self, a: usize, lo: f32, hi: f32) -> Option<(f64, f64)> {
        let (lo, hi) = (lo as f64, hi as f64);
        let d = self.d[a];
        if d == 0.0 {
            if self.o_hi[a] < lo || self.o_lo[a] > hi {
                return None;
            }
            return Some((f64::NEG_INFINITY, f64::INFINITY));
        }
        let (tl, th) = (
            (lo - self.o_hi[a]) * self.inv[a],
            (hi - self.o_lo[a]) * self.inv[a],
        );
        Some(if d > 0.0 { (tl, th) } else { (th, tl) })
    }

    /// The last step of [`RayClip::clip`]: the largest entry and smallest
    /// exit of the three slabs, widened and clipped to `[0, max_t]`.
    #[inline(always)]
    fn finish(&self, slabs: [(f64, f64); 3]) -> Option<(f64, f64)> {
        let (t0, t1) = self.widened(slabs);
        (t0 <= t1).then_some((t0, t1))
    }

    /// [`RayClip::finish`]'s interval before the emptiness test: the three
    /// slabs folded in axis order, then [`RayClip::widen_interval`] (which
    /// [`RayClip::entry_octants`] shares).
    #[inline(always)]
    fn widened(&self, slabs: [(f64, f64); 3]) -> (f64, f64) {
        let mut near = f64::NEG_INFINITY;
        let mut far = f64::INFINITY;
        for (enter, exit) in slabs {
            near = above(enter, near);
            far = below(exit, far);
        }
        self.widen_interval(near, far)
    }

    /// The last step of [`RayClip::widened`]: the largest entry `near`
    /// moved down and the smallest exit `far` up, then clipped to `[0,
    /// max_t]`. The entry is `+0.0` where it clamps, never `-0.0`, so
    /// that folds in any order give the same bits.
    #[inline(always)]
    fn widen_interval(&self, near: f64, far: f64) -> (f64, f64) {
        // `widen(near, false).max(0.0)` and `widen(far, true)` without the
        // sign test: a negative `near` clamps to 0 either way, and a
        // negative `far` leaves the interval empty either way (`t0 >= 0`),
        // so the answers are the same; ~6% of a W8 octree first-hit
        // sweep's instructions were in those sign tests (16 a node).
        // `+0.0` for a zero or negative entry, whatever the fold order
        // left (`-0.0 > +0.0` is false): `entry_octants` folds in another
        // order than `clip` and must give the same bits.
        let t0 = near * (1.0 - CLIP_WIDEN);
        let t0 = if t0 > 0.0 { t0 } else { 0.0 };
        // `f64::min`, not a select: as a select, the selection walk's box
        // test (`EntryBound::enter`) lost its early exits and ran 54% more
        // instructions (W8 octree all hits, callgrind), 4% slower.
        let t1 = (far * (1.0 + CLIP_WIDEN)).min(self.max_t);
        (t0, t1)
    }

    /// An `f64` interval containing the exact coordinate on axis `a` of the
    /// ray at every parameter of `[t0, t1]` (finite or not): the end points
    /// `o + d t` (two roundings each, within `2.01u (|o| + |d t|)`) moved out
    /// by `2^-50 (|o| + |d t|)`. A zero component is exactly `o`.
    #[inline]
    pub(crate) fn coord_range(&self, a: usize, t0: f64, t1: f64) -> (f64, f64) {
        let (o, d) = (self.o[a], self.d[a]);
        if d == 0.0 {
            return (o, o);
        }
        let at = |t: f64| {
            let dt = d * t;
            (o + dt, (o.abs() + dt.abs()) * CLIP_WIDEN)
        };
        let ((p0, e0), (p1, e1)) = (at(t0), at(t1));
        let (lo, hi) = if p0 <= p1 {
            (p0 - e0, p1 + e1)
        } else {
            (p1 - e1, p0 + e0)
        };
        // ∞ - ∞ (an infinite end) is NaN: that end is unbounded.
        (
            if lo.is_nan() { f64::NEG_INFINITY } else { lo },
            if hi.is_nan() { f64::INFINITY } else { hi },
        )
    }
}

/// Ray (or segment) against a box: the interval `[t0, t1]` of `f32`s that
/// rounds the exact parameter interval of the ray inside the closed box outward
/// (`t0` the largest `f32` not above the exact entry, `t1` the smallest not below
/// the exact exit), clipped to `[0, ray.max_t]`; `None` only when the exact
/// interval is empty.
///
/// So the test never rejects a box the ray meets, at any magnitude, and `t0` is
/// monotone in the box (a larger box never gets a larger `t0`), which makes
/// front-to-back pruning consistent with [`ray_sphere`]. Each slab's parameters
/// `(lo - o) / d` come from `exact::quotient_floor_f32`: an `f64` division whose
/// exact residual (one FMA) shows when it is exact, an exact adjustment only when
/// it lies within 2^-50 of an `f32` boundary. A zero direction component is
/// handled explicitly (inside the slab for all `t` or none), so no `0 * ∞` NaN
/// arises. Cost: 6 divisions and 6 FMAs in the common case.
#[inline]
pub fn ray_aabb(ray: &Ray, b: &Aabb) -> Option<(f32, f32)> {
    let mut t0 = 0.0f32;
    let mut t1 = ray.max_t;
    for axis in 0..3 {
        let o = ray.origin[axis] as f64;
        let d = ray.dir[axis] as f64;
        let (lo, hi) = (b.min[axis] as f64, b.max[axis] as f64);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        // The entry side rounds down, the exit side up (`⌈q⌉ = -⌊-q⌋`).
        let floor = |x: f64, o: f64| {
            if x.is_finite() {
                super::exact::quotient_floor_f32(x, o, d)
            } else {
                // An infinite side (loose bounds of huge objects): exact ±∞.
                ((x - o) / d) as f32
            }
        };
        let (near, far) = if d > 0.0 { (lo, hi) } else { (hi, lo) };
        let enter = floor(near, o);
        let exit = -floor(-far, -o);
        // `max`/`min` ignore a NaN operand (a NaN box), which keeps the test
        // conservative.
        t0 = t0.max(enter);
        t1 = t1.min(exit);
        if t0 > t1 {
            return None;
        }
    }
    Some((t0, t1))
}

use super::exact::{f32_down as step_down, round_down_f32 as round_down};

/// The exact sign of `t[0] + t[1] + t[2] + t[3]` for `f64` terms that are exact
/// products of `f32`s (or `f32`s), or `None` when it is undefined (a NaN, or
/// infinities of both signs). Infinite terms (boxes with infinite sides) decide
/// by their sign. `f64` filter first: the terms are exact, the sum rounds three
/// times (error <= 3 · 2^-53 of the sum of magnitudes).
#[inline]
fn sum4_sign(t: [f64; 4]) -> Option<Ordering> {
    let v = t[0] + t[1] + t[2] + t[3];
    if v.is_finite() {
        let perm: f64 = t.iter().map(|x| x.abs()).sum();
        return Some(filtered(v, perm).unwrap_or_else(|| sum_exact(&t)));
    }
    if v.is_nan() {
        return None;
    }
    Some(if v > 0.0 {
        Ordering::Greater
    } else {
        Ordering::Less
    })
}

/// The exact sign of a sum of `f64`s.
#[cold]
#[inline(never)]
fn sum_exact(t: &[f64]) -> Ordering {
    t.iter()
        .fold(Exp::default(), |e, &x| e.add(&Exp::of(x)))
        .sign()
}

/// The exact signs of `D + r|n|` and `D - r|n|` for a plane `(n, dd)` and a
/// sphere `(c, r)`, where `D = n·c + dd`; `None` for a NaN. `f64` filter first
/// (the products are exact, `√(n·n)` is correctly rounded: the error is below
/// 4u of `Σ|n_i c_i| + |dd| + r|n|`), expansions for near-ties. The inner sign
/// is only computed when `inner` is set (and the outer one is not negative).
#[inline]
fn plane_sphere_signs(
    n: [f64; 3],
    dd: f64,
    c: [f64; 3],
    r: f64,
    inner: bool,
) -> (Option<Ordering>, Option<Ordering>) {
    let terms = [n[0] * c[0], n[1] * c[1], n[2] * c[2], dd];
    let dv = terms[0] + terms[1] + terms[2] + terms[3];
    let n2 = dot(n, n);
    let rn = r * n2.sqrt();
    if (dv + rn).is_nan() {
        return (None, None);
    }
    let perm = terms[0].abs() + terms[1].abs() + terms[2].abs() + terms[3].abs() + rn;
    let outer = filtered(dv + rn, perm)
        .unwrap_or_else(|| plane_sphere_exact(terms, n, r, n2, Ordering::Greater));
    if !inner || outer == Ordering::Less {
        return (Some(outer), None);
    }
    let inside = filtered(dv - rn, perm)
        .unwrap_or_else(|| plane_sphere_exact(terms, n, r, n2, Ordering::Less));
    (Some(outer), Some(inside))
}

/// The exact sign of `Σ terms + rn_sign · r|n|` (`terms` exact products).
#[cold]
#[inline(never)]
fn plane_sphere_exact(terms: [f64; 4], n: [f64; 3], r: f64, n2: f64, sign: Ordering) -> Ordering {
    let de = terms
        .iter()
        .fold(Exp::default(), |e, &x| e.add(&Exp::of(x)));
    let ds = de.sign();
    let rn_sign = if r == 0.0 || n2 == 0.0 {
        Ordering::Equal
    } else {
        sign
    };
    if ds == rn_sign || rn_sign == Ordering::Equal {
        return ds;
    }
    if ds == Ordering::Equal {
        return rn_sign;
    }
    // Opposite signs: the larger magnitude wins; compare D² with r²|n|².
    let r = Exp::of(r);
    let nn = n
        .iter()
        .fold(Exp::default(), |e, &x| e.add(&Exp::of(x).mul(&Exp::of(x))));
    match de.mul(&de).sub(&r.mul(&r).mul(&nn)).sign() {
        Ordering::Greater => ds,
        Ordering::Less => rn_sign,
        Ordering::Equal => Ordering::Equal,
    }
}

/// Frustum–sphere, per plane: `Outside` if the sphere is entirely on the outer
/// side of some plane (`n·c + d < -r |n|`; `|n| = 1` for normalized planes),
/// `Inside` if it is at least `r |n|` inside every plane (`n·c + d >= r |n|`),
/// else `Intersecting`. A sphere exactly touching a plane from outside is not
/// culled. Decided **exactly** for the `f32` inputs (f64 filter, expansions for
/// near-ties), so it agrees with [`frustum_aabb`] on every box containing the
/// sphere at any magnitude. A NaN (only from a NaN plane) never culls.
#[inline]
pub fn frustum_sphere(f: &Frustum, s: &Sphere) -> Relation {
    frustum_sphere_masked(f, s, Frustum::ALL_PLANES)
}

/// [`frustum_sphere`] over the planes whose bit is set in `mask` only (bit `i`
/// = plane `i`): the planes a hierarchy's plane masking has shown to contain
/// the sphere need no test. Exact like [`frustum_sphere`]; with a full mask it
/// is [`frustum_sphere`]. O(planes in `mask`).
#[inline]
pub(crate) fn frustum_sphere_masked(f: &Frustum, s: &Sphere, mask: u8) -> Relation {
    let mut rel = Relation::Inside;
    let c = d3(s.center);
    let r = s.radius as f64;
    for (i, p) in f.planes.iter().enumerate() {
        if mask & (1 << i) == 0 {
            continue;
        }
        let (n, dd) = (d3(p.normal), p.d as f64);
        // The radius in the plane's units is `r |n|`: `r` for the unit normals of
        // `from_view_projection`; 0 for a zero normal (a degenerate matrix: the
        // plane is everywhere inside or everywhere outside), consistent with
        // `frustum_aabb`, whose box extent also scales with |n|.
        match plane_sphere_signs(n, dd, c, r, rel == Relation::Inside) {
            (Some(Ordering::Less), _) => return Relation::Outside,
            (_, Some(Ordering::Greater | Ordering::Equal)) => {}
            // Not provably at least `r|n|` inside (or a NaN, which never culls).
            _ => rel = Relation::Intersecting,
        }
    }
    rel
}

/// Frustum–AABB over the planes whose bit is set in `mask` (bit `i` = plane `i`).
///
/// Returns the relation and the mask of planes that still cut the box: planes that
/// contain the box entirely are dropped, so a child of this box needs to be tested
/// only against the returned mask (plane masking). `Inside` when the returned mask
/// is empty. A box that merely touches a plane from outside is not culled.
///
/// Exact: a plane culls the box iff `n·p + d < 0` at the box corner farthest
/// along `n` (the "p-vertex"), and contains it iff `n·p + d >= 0` at the nearest
/// corner; both sums of four exact `f64` products, signed by an `f64` filter or
/// an expansion. Boxes with infinite sides (loose bounds of huge objects) are
/// handled by the infinite terms' sign; a NaN or `∞ - ∞` neither culls nor
/// proves a plane contains the box.
#[inline]
pub fn frustum_aabb(f: &Frustum, b: &Aabb, mask: u8) -> (Relation, u8) {
    frustum_aabb_centres(f, b, b, mask)
}

/// Frustum test of a block of spheres known by two boxes: every sphere has its
/// centre in `centres` and lies inside `loose`. Per plane in `mask`: `loose`
/// wholly outside the plane culls the block (`Outside`); `centres` wholly
/// inside it drops the plane from the returned mask (a sphere whose centre is
/// inside a plane is not culled by it, see [`frustum_sphere`]). `Inside` when
/// the returned mask is empty: every sphere of the block is kept by
/// [`frustum_sphere`]. With `centres == loose` this is [`frustum_aabb`]. Exact,
/// by the same corner sums as [`frustum_aabb`]. O(planes in `mask`).
#[inline]
pub(crate) fn frustum_aabb_centres(
    f: &Frustum,
    centres: &Aabb,
    loose: &Aabb,
    mask: u8,
) -> (Relation, u8) {
    let (lo, hi) = (d3(loose.min), d3(loose.max));
    let (clo, chi) = (d3(centres.min), d3(centres.max));
    let mut out_mask = 0u8;
    for (i, p) in f.planes.iter().enumerate() {
        let bit = 1u8 << i;
        if mask & bit == 0 {
            continue;
        }
        let n = d3(p.normal);
        // A zero normal component contributes 0 whatever the box (no 0 · ∞).
        let term = |k: usize, v: f64| if n[k] == 0.0 { 0.0 } else { n[k] * v };
        let far = [0, 1, 2].map(|k| term(k, if n[k] > 0.0 { hi[k] } else { lo[k] }));
        let near = [0, 1, 2].map(|k| term(k, if n[k] < 0.0 { chi[k] } else { clo[k] }));
        let dd = p.d as f64;
        if sum4_sign([far[0], far[1], far[2], dd]) == Some(Ordering::Less) {
            return (Relation::Outside, 0);
        }
        if !matches!(
            sum4_sign([near[0], near[1], near[2], dd]),
            Some(Ordering::Greater | Ordering::Equal)
        ) {
            out_mask |= bit;
        }
    }
    if out_mask == 0 {
        (Relation::Inside, 0)
    } else {
        (Relation::Intersecting, out_mask)
    }
}

/// Squared distance between two points (helper for callers that need it; in `f32`,
/// so it overflows to infinity beyond about 1.8e19).
#[inline]
pub fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    (a - b).length_squared()
}

#[cfg(test)]
mod tests {

    /// The rounding boundaries from bit patterns equal the midpoints with the
    /// neighbouring `f32`s (from `exact::f32_down` and `f64` arithmetic) at
    /// every edge: `±0`, the smallest subnormal, the subnormal/normal seam,
    /// powers of two, `f32::MAX` (whose next one up is `2^128`) and `∞`, and
    /// on 10,000 random bit patterns.
    #[test]
    fn rounding_boundaries_are_the_midpoints_with_the_neighbours() {
        let up = |y: f32| {
            if y == f32::MAX || y == f32::INFINITY {
                2f64.powi(128)
            } else {
                -step_down(-y) as f64
            }
        };
        let check = |y: f32| {
            let yd = if y == 0.0 { 0.0 } else { y as f64 };
            let above = if y == f32::INFINITY {
                f64::INFINITY
            } else {
                (yd + up(y)) * 0.5
            };
            assert_eq!(rounding_above(y), above, "above {y:e}");
            let below = if y == 0.0 {
                f64::NEG_INFINITY
            } else {
                (yd + step_down(y) as f64) * 0.5
            };
            assert_eq!(rounding_below(y), below, "below {y:e}");
            if y != f32::INFINITY {
                assert!(rounding_below(y) < yd && yd < rounding_above(y), "{y:e}");
            }
        };
        let tiny = f32::from_bits(1);
        for y in [
            0.0,
            -0.0,
            tiny,
            f32::from_bits(2),
            f32::MIN_POSITIVE,
            step_down(f32::MIN_POSITIVE),
            0.5,
            1.0,
            step_down(1.0),
            3.0,
            f32::MAX,
            step_down(f32::MAX),
            f32::INFINITY,
        ] {
            check(y);
        }
        assert_eq!(rounding_above(0.0), tiny as f64 / 2.0);
        assert_eq!(rounding_above(-0.0), tiny as f64 / 2.0);
        assert_eq!(rounding_above(1.0), 1.0 + 2f64.powi(-24));
        assert_eq!(rounding_below(1.0), 1.0 - 2f64.powi(-25));
        assert_eq!(
            rounding_above(f32::MAX),
            (f32::MAX as f64 + 2f64.powi(128)) * 0.5
        );
        let mut st = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..10_000 {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            let y = f32::from_bits((st >> 33) as u32 % f32::INFINITY.to_bits());
            check(y);
        }
    }

    /// The `f32` pre-test keeps every point the `f64` test keeps, at the
    /// hardest threshold (the point's own `f64` squared distance), at every
    /// magnitude from subnormal differences to sums that overflow `f32`;
    /// and its threshold is tight (not `∞` unless it must be).
    #[test]
    fn f32_squared_distance_stays_within_its_threshold() {
        let mut st = 0xD1B5_4A32_D192_ED03u64;
        let mut next = || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            st
        };
        let tiny = f32::from_bits(1);
        let mut kept_finite = 0;
        for k in 0..200_000 {
            let r = next();
            let unit = |b: u64| (b >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
            let scale = [1e-44f32, 1e-38, 1e-20, 1.0, 1e19, 1e37, f32::MAX][k % 7];
            let p = Vec3::new(unit(r), unit(r << 8), unit(r << 16)) * scale;
            let r2 = next();
            let c = match k % 5 {
                // A neighbour a few ulps away on each axis.
                0 => Vec3::new(
                    f32::from_bits(p.x.to_bits() ^ (r2 as u32 & 7)),
                    f32::from_bits(p.y.to_bits() ^ ((r2 >> 8) as u32 & 7)),
                    f32::from_bits(p.z.to_bits() ^ ((r2 >> 16) as u32 & 7)),
                ),
                1 => p + Vec3::splat(tiny),
                _ => Vec3::new(unit(r2), unit(r2 << 8), unit(r2 << 16)) * scale,
            };
            if !(p.is_finite() && c.is_finite()) {
                continue;
            }
            let t = point_point_distance_sq(p, c);
            let f = point_point_distance_sq_f32(p, c);
            // The four-lane form, lane by lane, bit for bit.
            let quad = [c, -c, c * 0.5, p].map(|c| Sphere::new(c, 0.0));
            let lanes = point_point_distance_sq_f32_4(p, quad.each_ref()).to_array();
            for (l, s) in lanes.iter().zip(&quad) {
                let one = point_point_distance_sq_f32(p, s.center);
                assert_eq!(l.to_bits(), one.to_bits(), "{p:?} {:?}", s.center);
            }
            let th = sq_threshold_f32(t);
            assert!(f <= th, "{p:?} {c:?}: {f:e} > {th:e} (t {t:e})");
            let tight = t * (1.0 + 2f64.powi(-17)) + 2f64.powi(-125);
            if tight < f32::MAX as f64 {
                assert!((th as f64) <= tight, "{t:e}: threshold {th:e} is loose");
                kept_finite += 1;
            }
        }
        assert!(kept_finite > 100_000, "{kept_finite}");
        assert_eq!(sq_threshold_f32(f64::INFINITY), f32::INFINITY);
        assert_eq!(sq_threshold_f32(1e300), f32::INFINITY);
    }

    /// The spheres' four-lane pre-test never rules out a sphere whose
    /// correctly rounded surface distance is at most the bound (nor one
    /// `distance_exceeds` keeps), at every scale and at the rounding
    /// boundary itself (the bound set to the sphere's own distance and the
    /// `f32`s around it), with distances and radii that overflow `f32`;
    /// it does rule out the spheres well beyond it, so it prunes; and its
    /// thresholds meet their stated lower bound at every scale.
    #[test]
    fn spheres_f32_pre_test_keeps_every_sphere_within_the_bound() {
        let mut st = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            st
        };
        let unit = |b: u64| (b >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
        let (mut pruned, mut far) = (0, 0);
        for k in 0..100_000 {
            let scale = [1e-40f32, 1e-20, 1e-3, 1.0, 1e3, 1e18, 1e20, 1e36][k % 8];
            let v = |b: u64| Vec3::new(unit(b), unit(b << 8), unit(b << 16)) * scale;
            let p = v(next());
            let spheres = [0, 1, 2, 3].map(|j| {
                let c = if j == 3 && k % 3 == 0 { p } else { v(next()) };
                let r = match j {
                    0 => 0.0,
                    1 => unit(next()).abs() * scale,
                    // Now and then a radius near `f32::MAX` (its threshold
                    // overflows).
                    _ if k % 11 == 0 => f32::MAX * unit(next()).abs(),
                    _ => unit(next()).abs() * scale * 4.0,
                };
                Sphere::new(c, r)
            });
            if spheres.iter().any(|s| !s.center.is_finite()) || !p.is_finite() {
                continue;
            }
            // The bound: one lane's own distance, an ulp around it, or a
            // fraction of it (then the spheres beyond it should go).
            let lane = (next() % 4) as usize;
            let own = point_sphere_distance(p, &spheres[lane]);
            let d = match k % 5 {
                0 => own,
                1 => own.next_down().max(0.0),
                2 => own.next_up(),
                3 => own * 0.5,
                _ => f32::INFINITY,
            };
            let m = midpoint_up_f32(distance_midpoint(d));
            let bits = spheres_beyond_f32_4(p, spheres.each_ref(), m);
            for (j, s) in spheres.iter().enumerate() {
                let set = bits >> j & 1 == 1;
                let exact = point_sphere_distance(p, s);
                let s2 = point_point_distance_sq(p, s.center);
                if exact <= d || !distance_exceeds(s2, s.radius, d) {
                    assert!(!set, "{p:?} {s:?} d {d:e}: ruled out at {exact:e}");
                }
                // Well beyond, at scales whose squares are normal `f32`s
                // (below they underflow, above they overflow, and the
                // pre-test keeps them): the pre-test prunes.
                let margin = (d as f64 + s.radius as f64) * 1e-3 + 1e-30;
                let normal = (1e-10..1e19).contains(&scale) && s.radius < 1e19;
                if normal && exact as f64 > d as f64 + margin {
                    far += 1;
                    pruned += set as u32;
                }
            }
        }
        assert!(
            far > 10_000 && pruned == far,
            "{pruned} of {far} far spheres pruned"
        );
        // The thresholds themselves, against their bound in `f64`: at least
        // `(m + r)²·(1 + 2^-17) + 2^-126`, or `∞`, over every scale of `m`
        // and `r` (subnormal to overflowing).
        for k in 0..200_000 {
            let (b1, b2) = (next(), next());
            let m = f32::from_bits((b1 as u32) & 0x7F7F_FFFF);
            let r = Vec4::from_array([0, 16, 32, 48].map(|sh| {
                let bits = (b2 >> sh) as u32 & 0x7F7F_FFFF;
                if k % 3 == 0 {
                    // Subnormal or tiny.
                    f32::from_bits(bits & 0x00FF_FFFF)
                } else {
                    f32::from_bits(bits)
                }
            }));
            let t = sphere_sq_thresholds_f32_4(m, r).to_array();
            for (t, r) in t.iter().zip(r.to_array()) {
                let a = m as f64 + r as f64;
                let low = a * a * (1.0 + 2f64.powi(-17)) + 2f64.powi(-126);
                assert!(
                    *t == f32::INFINITY || *t as f64 >= low,
                    "m {m:e} r {r:e}: {t:e}"
                );
            }
        }
        let one = Sphere::new(Vec3::ONE, 1.0);
        assert_eq!(
            spheres_beyond_f32_4(Vec3::ZERO, [&one; 4], f32::INFINITY),
            0
        );
        assert_eq!(midpoint_up_f32(f64::INFINITY), f32::INFINITY);
        assert_eq!(midpoint_up_f32(1e300), f32::INFINITY);
        assert_eq!(midpoint_up_f32(1.5), 1.5);
    }

    #[test]
    fn axis_gaps_sum_to_the_box_distance_bit_for_bit() {
        let mut st = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            (st >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        for k in 0..20_000 {
            let scale = [1e-30f32, 1e-3, 1.0, 1e3, 1e18][k % 5];
            let v = |n: &mut dyn FnMut() -> f32| Vec3::new(n(), n(), n()) * scale;
            let (a, b, p) = (v(&mut next), v(&mut next), v(&mut next));
            // Some points inside, on a face or a corner.
            let p = match k % 7 {
                0 => a.min(b),
                1 => Vec3::new(a.x.min(b.x), p.y, p.z),
                _ => p,
            };
            let bx = Aabb::new(a.min(b), a.max(b));
            let sum = axis_gap_sq(p.x, bx.min.x, bx.max.x)
                + axis_gap_sq(p.y, bx.min.y, bx.max.y)
                + axis_gap_sq(p.z, bx.min.z, bx.max.z);
            let whole = point_aabb_distance_sq(p, &bx);
            assert_eq!(sum.to_bits(), whole.to_bits(), "{p:?} {bx:?}");
        }
    }

    #[test]
    fn candidates4_agree_with_the_scalar_pre_test_and_never_drop_an_overlap() {
        // Near-tangent, overlapping, far, huge and tiny spheres.
        let mut st = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            (st >> 40) as f32 / (1u64 << 24) as f32
        };
        for k in 0..20_000 {
            let scale = [1e-3f32, 1.0, 1e3, 1e30][k % 4];
            let s = Sphere::new(Vec3::new(next(), next(), next()) * scale, next() * scale);
            let mut lanes = [Sphere::default(); 4];
            for l in &mut lanes {
                let dir = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize_or(Vec3::X);
                let r = next() * scale;
                // Around tangency: distance = (r + s.r) * (1 +- small).
                let t = (r + s.radius) * (1.0 + (next() - 0.5) * 1e-5);
                *l = Sphere::new(s.center + dir * t, r);
            }
            let v = |f: fn(&Sphere) -> f32| Vec4::from_array(lanes.map(|l| f(&l)));
            let mask = sphere_sphere_candidates4(
                v(|l| l.center.x),
                v(|l| l.center.y),
                v(|l| l.center.z),
                v(|l| l.radius),
                &s,
            );
            for (j, l) in lanes.iter().enumerate() {
                let c = l.center;
                let scalar = sphere_sphere_candidate(
                    c.x, c.y, c.z, l.radius, s.center.x, s.center.y, s.center.z, s.radius,
                );
                assert_eq!(mask >> j & 1 == 1, scalar, "{l:?} vs {s:?}");
                if sphere_sphere(l, &s) {
                    assert!(scalar, "overlap rejected: {l:?} vs {s:?}");
                }
            }
        }
    }

    use super::*;
    use glam::{vec3, Mat4};

    /// The 4-lane prefilter never clears a lane that overlaps, at any magnitude,
    /// and clears most of those far apart.
    #[test]
    fn candidates4_never_rejects_an_overlap_at_any_magnitude() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mut cleared = 0;
        for k in 0..20_000 {
            let scale = [1e-20f32, 1e-3, 1.0, 1e3, 1e18, 1e30][k % 6];
            let mut v = || rng.gen_range(-4.0f32..4.0) * scale;
            let a = Sphere::new(vec3(v(), v(), v()), v().abs());
            let lanes: Vec<Sphere> = (0..4)
                .map(|_| Sphere::new(vec3(v(), v(), v()), v().abs()))
                .collect();
            let col = |f: fn(&Sphere) -> f32| Vec4::from_array([0, 1, 2, 3].map(|i| f(&lanes[i])));
            let bits = sphere_sphere_candidates4(
                col(|s| s.center.x),
                col(|s| s.center.y),
                col(|s| s.center.z),
                col(|s| s.radius),
                &a,
            );
            for (i, l) in lanes.iter().enumerate() {
                if bits & (1 << i) == 0 {
                    assert!(!sphere_sphere(&a, l), "{a:?} {l:?}");
                    cleared += 1;
                }
            }
        }
        assert!(cleared > 20_000, "{cleared}");
        // Touching spheres on a coarse grid (exact ties) are kept.
        let a = Sphere::new(Vec3::ZERO, 1.0);
        let bits = sphere_sphere_candidates4(
            Vec4::new(2.0, 0.0, 3.0, 1.0),
            Vec4::ZERO,
            Vec4::ZERO,
            Vec4::ONE,
            &a,
        );
        assert_eq!(bits, 0b1011);
    }

    /// The `f32` filter of `within` never decides differently from the exact
    /// predicate: on a coarse grid exact ties are common, and magnitudes up to
    /// 1e30 overflow `f32` squares.
    #[test]
    fn f32_filter_agrees_with_exact_predicate() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut ties = 0;
        for k in 0..400_000 {
            let scale = [1.0f32, 1.0 / 64.0, 1e-20, 1e15, 1e30][k % 5];
            let mut g = || rng.gen_range(-8i32..=8) as f32 * scale;
            let p = glam::vec3(g(), g(), g());
            let q = glam::vec3(g(), g(), g());
            let (r1, r2) = (g().abs(), g().abs());
            let d = |v: glam::Vec3| [v.x as f64, v.y as f64, v.z as f64];
            let exact = crate::geom::exact::within(d(p), d(q), r1 as f64, r2 as f64);
            assert_eq!(within(p, q, r1, r2), exact, "{p} {q} {r1} {r2}");
            let (dd, rs) = ((p - q).length_squared(), (r1 + r2) * (r1 + r2));
            ties += (scale == 1.0 && dd == rs) as u32;
        }
        assert!(ties > 100, "the grid must produce exact ties ({ties})");
    }

    /// A random `f32` on a coarse grid (exact ties are common) at one of several
    /// magnitudes, mixed within one case.
    fn coarse(rng: &mut rand_pcg::Pcg64) -> f32 {
        use rand::Rng;
        let scale = [1.0f32, 1.0 / 64.0, 1e-20, 1e15, 1e30][rng.gen_range(0..5)];
        rng.gen_range(-8i32..=8) as f32 * scale
    }

    /// Hit or miss of `ray_sphere` decided from exact signs only (the reference
    /// for its `f64` filters).
    fn ray_sphere_exact_ref(ray: &Ray, s: &Sphere) -> bool {
        let d = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let inside = crate::geom::exact::within(d(ray.origin), d(s.center), s.radius as f64, 0.0);
        RayBall { ray, s }.exact().touches(inside)
    }

    /// `ray_sphere`'s filters never decide differently from the exact signs, and
    /// every box containing a hit sphere is met by `ray_aabb` with an entry bound
    /// not above the sphere's `t` (so index pruning is consistent), at every
    /// magnitude from 1e-20 to 1e30.
    #[test]
    fn ray_tests_exact_and_consistent() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(12);
        let (mut hits, mut exact_ties) = (0, 0);
        for _ in 0..200_000 {
            let mut v = || vec3(coarse(&mut rng), coarse(&mut rng), coarse(&mut rng));
            let (o, c, dir) = (v(), v(), v());
            if dir == Vec3::ZERO {
                continue;
            }
            let r = coarse(&mut rng).abs();
            let max_t = [f32::INFINITY, 1.0, 0.5, 3.0][rng.gen_range(0..4)];
            let ray = Ray::with_max_t(o, dir, max_t);
            let s = Sphere::new(c, r);
            let got = ray_sphere(&ray, &s);
            assert_eq!(
                got.is_some(),
                ray_sphere_exact_ref(&ray, &s),
                "{ray:?} {s:?}"
            );
            let Some(t) = got else { continue };
            hits += 1;
            assert!((0.0..=max_t).contains(&t), "{t} {ray:?} {s:?}");
            let b = outward_box(&s);
            exact_ties += (b.min == c - Vec3::splat(r)) as u32;
            for _ in 0..4 {
                let mut grow = || [0.0, 1.0, 1e10, 1e30][rng.gen_range(0..4)];
                let lo = b.min - vec3(grow(), grow(), grow());
                let hi = b.max + vec3(grow(), grow(), grow());
                let (t0, t1) = ray_aabb(&ray, &Aabb::new(lo, hi)).expect("box pruned a hit");
                assert!(t0 <= t && t <= t1, "{t0} {t} {t1} {ray:?} {s:?}");
            }
        }
        assert!(hits > 10_000 && exact_ties > 1_000, "{hits} {exact_ties}");
    }

    /// The far segment of `fuzz/found/index_ops-far-segment`'s kind: its numbers
    /// dwarf its distance to the sphere by 1e16; the exact test still tells a
    /// touching sphere from one a single `f32` step smaller.
    #[test]
    fn ray_sphere_far_segment_exact() {
        let seg = crate::geom::Segment::new(vec3(1e20, 0.0, 0.0), vec3(-32.0, 0.0, 0.0));
        let ray = seg.to_ray();
        let touching = Sphere::new(vec3(0.0, 8000.0, 0.0), 8000.0);
        let t = ray_sphere(&ray, &touching).expect("touching counts");
        assert!((t - 1.0).abs() < 1e-6, "{t}");
        let smaller = Sphere::new(vec3(0.0, 8000.0, 0.0), step_down(8000.0));
        assert_eq!(ray_sphere(&ray, &smaller), None);
    }

    /// Frustum tests, exactly: the `f64` filter agrees with exact signs, and
    /// a box's classification never contradicts a sphere inside it (box outside
    /// ⇒ sphere outside; box inside ⇒ sphere kept), for random (also non-unit
    /// and zero) plane normals at every magnitude.
    #[test]
    fn frustum_tests_exact_and_consistent() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(13);
        let mut outs = [0; 3];
        for _ in 0..100_000 {
            let mut v = || vec3(coarse(&mut rng), coarse(&mut rng), coarse(&mut rng));
            let planes = [(); 6].map(|_| crate::geom::Plane::new(v(), v().x));
            let f = Frustum::from_planes(planes);
            let s = Sphere::new(v(), v().x.abs());
            let rel = frustum_sphere(&f, &s);
            // Exact reference: per plane, signs of n·c + d ± r|n|.
            let mut want = Relation::Inside;
            for p in &f.planes {
                let (n, dd, c) = (d3(p.normal), p.d as f64, d3(s.center));
                let outer = exact_plane_sign(n, dd, c, s.radius as f64, 1.0);
                if outer == Ordering::Less {
                    want = Relation::Outside;
                    break;
                }
                if exact_plane_sign(n, dd, c, s.radius as f64, -1.0) == Ordering::Less {
                    want = Relation::Intersecting;
                }
            }
            assert_eq!(rel, want, "{f:?} {s:?}");
            outs[rel as usize] += 1;
            let b = outward_box(&s);
            let mut grow = || [0.0, 1.0, 1e30][rng.gen_range(0..3)];
            let bx = Aabb::new(
                b.min - vec3(grow(), grow(), grow()),
                b.max + vec3(grow(), grow(), grow()),
            );
            match frustum_aabb(&f, &bx, Frustum::ALL_PLANES).0 {
                Relation::Outside => assert_eq!(rel, Relation::Outside, "{f:?} {s:?} {bx:?}"),
                Relation::Inside => assert_ne!(rel, Relation::Outside, "{f:?} {s:?} {bx:?}"),
                Relation::Intersecting => {}
            }
        }
        assert!(outs.iter().all(|&n| n > 300), "{outs:?}");
    }

    /// Sign of `n·c + d + sign·r|n|` from expansions only.
    fn exact_plane_sign(n: [f64; 3], dd: f64, c: [f64; 3], r: f64, sign: f64) -> Ordering {
        let de = (0..3).fold(Exp::of(dd), |e, i| e.add(&Exp::of(n[i] * c[i])));
        let rn2 = (0..3).fold(Exp::default(), |e, i| {
            e.add(&Exp::of(r * n[i]).mul(&Exp::of(r * n[i])))
        });
        let rn_sign = if rn2.sign() == Ordering::Equal {
            Ordering::Equal
        } else if sign > 0.0 {
            Ordering::Greater
        } else {
            Ordering::Less
        };
        let ds = de.sign();
        if ds == rn_sign || rn_sign == Ordering::Equal {
            return ds;
        }
        if ds == Ordering::Equal {
            return rn_sign;
        }
        match de.mul(&de).sub(&rn2).sign() {
            Ordering::Greater => ds,
            Ordering::Less => rn_sign,
            Ordering::Equal => Ordering::Equal,
        }
    }

    #[test]
    fn touching_counts() {
        let a = Sphere::new(Vec3::ZERO, 1.0);
        let b = Sphere::new(vec3(2.0, 0.0, 0.0), 1.0);
        assert!(sphere_sphere(&a, &b));
        let bx = Aabb::new(vec3(1.0, -1.0, -1.0), vec3(3.0, 1.0, 1.0));
        assert!(sphere_aabb(&a, &bx));
        let bx2 = Aabb::new(vec3(3.0, -1.0, -1.0), vec3(4.0, 1.0, 1.0));
        assert!(aabb_aabb(&bx, &bx2));
        assert!(!sphere_aabb(&a, &bx2));
    }

    #[test]
    fn ray_sphere_cases() {
        let s = Sphere::new(vec3(5.0, 0.0, 0.0), 1.0);
        let r = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(ray_sphere(&r, &s), Some(4.0));
        let r2 = Ray::new(Vec3::ZERO, -Vec3::X);
        assert_eq!(ray_sphere(&r2, &s), None);
        let short = Ray::with_max_t(Vec3::ZERO, Vec3::X, 3.9);
        assert_eq!(ray_sphere(&short, &s), None);
        let exact = Ray::with_max_t(Vec3::ZERO, Vec3::X, 4.0);
        assert_eq!(ray_sphere(&exact, &s), Some(4.0));
        let inside = Ray::new(vec3(5.5, 0.0, 0.0), Vec3::Y);
        assert_eq!(ray_sphere(&inside, &s), Some(0.0));
        // Tangent ray touches.
        let tangent = Ray::new(vec3(0.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray_sphere(&tangent, &s), Some(5.0));
        // Unnormalized direction: t is in units of dir.
        let scaled = Ray::new(Vec3::ZERO, vec3(2.0, 0.0, 0.0));
        assert_eq!(ray_sphere(&scaled, &s), Some(2.0));
    }

    #[test]
    fn ray_aabb_cases() {
        let b = Aabb::new(vec3(1.0, -1.0, -1.0), vec3(2.0, 1.0, 1.0));
        assert_eq!(
            ray_aabb(&Ray::new(Vec3::ZERO, Vec3::X), &b),
            Some((1.0, 2.0))
        );
        // Axis-parallel ray on the box face: touching counts, no NaN.
        let on_face = Ray::new(vec3(0.0, 1.0, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&on_face, &b), Some((1.0, 2.0)));
        let above = Ray::new(vec3(0.0, 1.5, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&above, &b), None);
        let behind = Ray::new(vec3(3.0, 0.0, 0.0), Vec3::X);
        assert_eq!(ray_aabb(&behind, &b), None);
        let short = Ray::with_max_t(Vec3::ZERO, Vec3::X, 0.5);
        assert_eq!(ray_aabb(&short, &b), None);
    }

    #[test]
    fn frustum_from_perspective() {
        let proj = Mat4::perspective_rh(1.0, 1.0, 1.0, 100.0);
        let view = Mat4::look_at_rh(Vec3::ZERO, -Vec3::Z, Vec3::Y);
        let f = Frustum::from_view_projection(proj * view).unwrap();
        let inside = Sphere::new(vec3(0.0, 0.0, -10.0), 1.0);
        assert_eq!(f.classify_sphere(&inside), Relation::Inside);
        let behind = Sphere::new(vec3(0.0, 0.0, 10.0), 1.0);
        assert_eq!(f.classify_sphere(&behind), Relation::Outside);
        let across_near = Sphere::new(vec3(0.0, 0.0, -1.0), 0.5);
        assert_eq!(f.classify_sphere(&across_near), Relation::Intersecting);
        let far = Sphere::new(vec3(0.0, 0.0, -102.0), 1.0);
        assert_eq!(f.classify_sphere(&far), Relation::Outside);
        let b = Aabb::new(vec3(-1.0, -1.0, -11.0), vec3(1.0, 1.0, -9.0));
        assert_eq!(f.classify_aabb(&b, Frustum::ALL_PLANES).0, Relation::Inside);
        let b2 = Aabb::new(vec3(-0.1, -0.1, -5.0), vec3(0.1, 0.1, 5.0));
        let (rel, mask) = f.classify_aabb(&b2, Frustum::ALL_PLANES);
        assert_eq!(rel, Relation::Intersecting);
        assert_ne!(mask & (1 << 4), 0, "near plane still cuts");
        assert!(Frustum::from_view_projection(Mat4::NAN).is_err());
    }
}

#[cfg(test)]
#[path = "query_tests.rs"]
mod query_tests;
