//! The one implementation of "does a moving point come within `ρ` of a centre,
//! and when first": the point `P(t) = o + t·d`, `t` in `[0, T]`, against the
//! closed ball of radius `ρ` around `c`, decided **exactly** for the real
//! numbers the inputs denote.
//!
//! Two shapes use it, each describing its numbers through [`Line`]:
//! - a ray ([`overlap::ray_sphere`](super::overlap::ray_sphere)): `o` and `d`
//!   are the ray's `f32` origin and direction, `T = max_t`, `ρ = r`;
//! - a sphere sweep ([`overlap::sweep_sphere`](super::overlap::sweep_sphere)):
//!   `o = from`, `d = to - from`, `T = 1`, `ρ = r + R`, where the direction and
//!   the radius are exact differences and sums of `f32`s that need not be
//!   `f32`s themselves (the sweep is given by its end points, so nothing is
//!   rounded before the test).
//!
//! The scheme: with `m = o - c`, the distance `|m + t d|` is convex in `t`, so
//! the point comes within `ρ` iff it starts there, or it approaches
//! (`m·d < 0`) and either the closest approach `t* = -m·d / |d|²` lies within
//! `T` and `|m × d|² <= ρ²|d|²`, or it lies beyond and the end is within `ρ`
//! (`|m + T d|² <= ρ²`). Each sign is first taken from an `f64` evaluation
//! with an error bound and, only for near-ties, from exact expansions
//! (`exact.rs`).

use super::exact::Exp;
use std::cmp::Ordering;

/// The unit roundoff of `f64`, 2^-53.
pub(super) const U: f64 = f64::EPSILON / 2.0;

/// Relative error bound for the `f64` filters of the sign tests: every filtered
/// quantity is a polynomial of degree <= 4 in `f32` inputs (or in exact
/// differences and sums of them, each rounded once), evaluated with a handful of
/// roundings of 2^-53 each, whose error is below ~16 · 2^-53 of its permanent
/// (the same polynomial on absolute values). 1e-14 is 9× that.
pub(super) const FILTER: f64 = 1e-14;

/// The sign of a value computed in `f64` as `v` with permanent `perm`, if the
/// filter decides it; `None` sends the caller to the exact evaluation.
#[inline]
pub(super) fn filtered(v: f64, perm: f64) -> Option<Ordering> {
    let margin = FILTER * perm;
    if v > margin {
        Some(Ordering::Greater)
    } else if v < -margin {
        Some(Ordering::Less)
    } else {
        None
    }
}

#[inline]
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The sign of `lhs - |v|²`, if an `f64` evaluation decides it: `lhs` within
/// `lhs_units` · u of its value, each `v[k]` within `err[k]` of its value. An
/// a-posteriori bound (from the computed `v`, not from the inputs' magnitudes),
/// so a long ray passing near a small sphere (huge inputs, modest cross product)
/// still decides in `f64`; the bound is doubled to cover its own rounding.
#[inline]
fn square_gap(lhs: f64, lhs_units: f64, v: [f64; 3], err: [f64; 3]) -> Option<Ordering> {
    let vv = dot(v, v);
    let mut bound = lhs_units * U * lhs + 4.0 * U * (lhs + vv);
    for k in 0..3 {
        bound += (2.0 * v[k].abs() + err[k]) * err[k];
    }
    filtered(lhs - vv, 2.0 * bound / FILTER)
}

/// What [`first_touch`] needs to know about a moving point and a ball: `f64`
/// approximations with error bounds for the filters, exact values for the
/// near-ties, and the box test's bound on the entry parameter.
pub(super) trait Line {
    /// Exactly: `|o - c| <= ρ`.
    fn starts_inside(&self) -> bool;
    /// `m = o - c` and `d`, each component within `u` of its magnitude.
    fn m_d(&self) -> ([f64; 3], [f64; 3]);
    /// `T`, the largest parameter (may be `∞`).
    fn t_max(&self) -> f32;
    /// `ρ²`, computed in `f64`.
    fn rho2(&self) -> f64;
    /// Relative error bound, in units of `u`, of `ρ²·|d|²` computed as
    /// `rho2() * dot(d, d)` (and of `rho2()` itself), beyond the 4u that
    /// [`square_gap`] always allows.
    fn lhs_units(&self) -> f64;
    /// `m × d` with an absolute error bound per component (computed from the
    /// inputs as accurately as the shape allows).
    fn cross(&self, m: [f64; 3], d: [f64; 3]) -> ([f64; 3], [f64; 3]);
    /// `m + T d` (finite `T`) with an absolute error bound per component.
    fn end(&self, m: [f64; 3], d: [f64; 3]) -> ([f64; 3], [f64; 3]);
    /// The exact quantities, for near-ties.
    fn exact(&self) -> Exact;
    /// A lower bound on the returned parameter: the entry bound of the shape's
    /// box test ([`ray_aabb`](super::overlap::ray_aabb),
    /// [`sweep_aabb`](super::overlap::sweep_aabb)) for the smallest `f32` box
    /// containing the ball, so that every index box containing it enters no
    /// later than the returned parameter (front-to-back pruning stays
    /// consistent).
    fn entry_floor(&self) -> f32;
    /// A cheap upper bound on [`Line::entry_floor`] ([`entry_ceiling`]):
    /// when the rounded parameter is at least this, clamping it by the entry
    /// floor cannot change it, and the box test is skipped.
    fn entry_ceiling(&self) -> f64;
}

/// 2^-50 = 8u: the relative widening of [`entry_ceiling`].
const CEIL_WIDEN: f64 = 1.0 / 1_125_899_906_842_624.0;

/// An upper bound on the exact parameter at which the ray from `o` along `d`
/// (the `f32` ray of the shape's box test) enters the exact box of the ball
/// of radius `rho` around `c` (`max(0, largest near-slab parameter)`); so
/// an upper bound on the box test's entry bound of any box containing that
/// box (its slabs are wider on every axis, so each near parameter is no
/// larger, and the box test rounds down and clamps at 0; a missed box gives
/// 0). An axis with `d = 0` has no near parameter.
///
/// Why it is one (u = 2^-53): `c - o ∓ ρ` in `f64` (the `f32` inputs, `ρ`
/// within `u ρ`) is within `4.1u M` of its value, `M = |c| + |o| + ρ`; it is
/// moved by `8u M` towards making the quotient larger (adding that rounds
/// once more, `1.01u M`), then divided by `d` (`u` relative) and the
/// largest quotient (or 0) multiplied by `1 + 8u`. No `f32` input
/// overflows or underflows these `f64` operations. Cost: 3 divisions.
#[inline]
pub(super) fn entry_ceiling(o: [f32; 3], d: [f32; 3], c: [f32; 3], rho: f64) -> f64 {
    let mut t = 0.0f64;
    for i in 0..3 {
        let di = d[i] as f64;
        if di == 0.0 {
            continue;
        }
        let co = c[i] as f64 - o[i] as f64;
        let slack = (c[i].abs() as f64 + o[i].abs() as f64 + rho) * CEIL_WIDEN;
        // The near face is `c - ρ` moving up, `c + ρ` moving down.
        let q = if di > 0.0 {
            (co - rho + slack) / di
        } else {
            (co + rho - slack) / di
        };
        if q > t {
            t = q;
        }
    }
    t * (1.0 + CEIL_WIDEN)
}

/// The exact `m`, `d`, `ρ` and `T` of a [`Line`], and the signs its filters may
/// leave undecided.
pub(super) struct Exact {
    pub m: [Exp; 3],
    pub d: [Exp; 3],
    pub rho: Exp,
    /// `None` for `T = ∞`.
    pub t: Option<Exp>,
}

fn edot(a: &[Exp; 3], b: &[Exp; 3]) -> Exp {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

impl Exact {
    /// Sign of `m · d`.
    pub fn m_dot_d(&self) -> Ordering {
        edot(&self.m, &self.d).sign()
    }

    /// Sign of `T |d|² + m · d` (`T` finite).
    pub fn end_minus_closest(&self) -> Ordering {
        let t = self.t.as_ref().expect("finite T");
        t.mul(&edot(&self.d, &self.d))
            .add(&edot(&self.m, &self.d))
            .sign()
    }

    /// Sign of `ρ² |d|² - |m × d|²`.
    pub fn line_gap(&self) -> Ordering {
        let (m, d) = (&self.m, &self.d);
        let cr = [
            m[1].mul(&d[2]).sub(&m[2].mul(&d[1])),
            m[2].mul(&d[0]).sub(&m[0].mul(&d[2])),
            m[0].mul(&d[1]).sub(&m[1].mul(&d[0])),
        ];
        let r2 = self.rho.mul(&self.rho);
        r2.mul(&edot(d, d)).sub(&edot(&cr, &cr)).sign()
    }

    /// Sign of `ρ² - |m + T d|²` (`T` finite).
    pub fn end_gap(&self) -> Ordering {
        let t = self.t.as_ref().expect("finite T");
        let p = [0, 1, 2].map(|i| self.m[i].add(&t.mul(&self.d[i])));
        self.rho.mul(&self.rho).sub(&edot(&p, &p)).sign()
    }

    /// Whether the point comes within `ρ` for some `t` in `[0, T]`, from exact
    /// signs only (the reference the filters of [`first_touch`] must agree with;
    /// `starts_inside` is the shape's exact start test).
    #[cfg(test)]
    pub fn touches(&self, starts_inside: bool) -> bool {
        if starts_inside {
            return true;
        }
        if self.m_dot_d() != Ordering::Less {
            return false;
        }
        if self.t.is_none() || self.end_minus_closest() != Ordering::Less {
            self.line_gap() != Ordering::Less
        } else {
            self.end_gap() != Ordering::Less
        }
    }
}

/// Whether the moving point comes within `ρ` ([`first_touch`]'s exact
/// decision, without the parameter: the selections need only this, and
/// skipping the parameter saves the entry bound's box test).
#[inline]
pub(super) fn touches<L: Line>(l: &L) -> bool {
    touch(l).is_some()
}

/// How [`touch`] found the point to come within `ρ`.
enum Touch {
    /// At `t = 0`.
    Inside,
    /// Later, approaching: `m`, `d`, `b = m·d` and `a = |d|²` in `f64`.
    Approach {
        m: [f64; 3],
        d: [f64; 3],
        b: f64,
        a: f64,
    },
}

/// The exact decision shared by [`first_touch`] and [`touches`]: `None`
/// when the point never comes within `ρ` in `[0, T]`.
#[inline]
fn touch<L: Line>(l: &L) -> Option<Touch> {
    if l.starts_inside() {
        return Some(Touch::Inside);
    }
    let (m, d) = l.m_d();
    let (b, b_perm) = (dot(m, d), dot(m.map(f64::abs), d.map(f64::abs)));
    let approaching = filtered(b, b_perm).unwrap_or_else(|| l.exact().m_dot_d());
    if approaching != Ordering::Less {
        // Outside and not approaching: the distance only grows with t.
        return None;
    }
    let a = dot(d, d);
    let big_t = l.t_max() as f64;
    // Closest approach `t* = -b / a` within `T`: sign of `T·a + b`.
    let closest_within = big_t.is_infinite()
        || filtered(big_t * a + b, big_t * a + b_perm)
            .unwrap_or_else(|| l.exact().end_minus_closest())
            != Ordering::Less;
    let rho2 = l.rho2();
    let units = l.lhs_units();
    let hit = if closest_within {
        let (cr, err) = l.cross(m, d);
        square_gap(rho2 * a, units, cr, err).unwrap_or_else(|| l.exact().line_gap())
            != Ordering::Less
    } else {
        let (p, err) = l.end(m, d);
        square_gap(rho2, units, p, err).unwrap_or_else(|| l.exact().end_gap()) != Ordering::Less
    };
    hit.then_some(Touch::Approach { m, d, b, a })
}

/// The smallest parameter `t` in `[0, T]` at which the point is (up to the
/// rounding of the returned value) within `ρ` of the centre, or `None` when it
/// never is. Hit or miss is exact (see the module); `t` is the closest-approach
/// formula in `f64` (no `b² - ac` cancellation), rounded to `f32`, then clamped
/// into `[entry_floor, T]`. Cost: ~40 flops, plus expansions for near-ties.
#[inline]
pub(super) fn first_touch<L: Line>(l: &L) -> Option<f32> {
    let (m, d, b, a) = match touch(l)? {
        Touch::Inside => return Some(0.0),
        Touch::Approach { m, d, b, a } => (m, d, b, a),
    };
    let rho2 = l.rho2();
    let tc = -b / a;
    let closest = [m[0] + d[0] * tc, m[1] + d[1] * tc, m[2] + d[2] * tc];
    let h2 = (rho2 - dot(closest, closest)).max(0.0);
    let t = (tc - (h2 / a).sqrt()).max(0.0) as f32;
    // `t >= ceiling >= floor`: the clamp would keep `t`; skip its box test.
    let t = if t as f64 >= l.entry_ceiling() {
        t
    } else {
        t.max(l.entry_floor())
    };
    Some(t.min(l.t_max()))
}
