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

/// The smallest parameter `t` in `[0, T]` at which the point is (up to the
/// rounding of the returned value) within `ρ` of the centre, or `None` when it
/// never is. Hit or miss is exact (see the module); `t` is the closest-approach
/// formula in `f64` (no `b² - ac` cancellation), rounded to `f32`, then clamped
/// into `[entry_floor, T]`. Cost: ~40 flops, plus expansions for near-ties.
#[inline]
pub(super) fn first_touch<L: Line>(l: &L) -> Option<f32> {
    if l.starts_inside() {
        return Some(0.0);
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
    if !hit {
        return None;
    }
    let tc = -b / a;
    let closest = [m[0] + d[0] * tc, m[1] + d[1] * tc, m[2] + d[2] * tc];
    let h2 = (rho2 - dot(closest, closest)).max(0.0);
    let t = (tc - (h2 / a).sqrt()).max(0.0) as f32;
    Some(t.max(l.entry_floor()).min(l.t_max()))
}
