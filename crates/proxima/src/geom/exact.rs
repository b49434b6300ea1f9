//! Exact evaluation of the sphere tests' sign, for the rare inputs where `f64`
//! cannot decide: error-free transformations (Knuth's TwoSum, FMA-based
//! TwoProduct) turn `(r1 + r2)² - |p - q|²` into a sum of `f64` terms that equals
//! it exactly, and Shewchuk's Grow-Expansion sums them without error; the sign
//! of a nonoverlapping expansion is that of its largest component.
//!
//! Every input is an `f32` widened to `f64`, so no step overflows or loses bits
//! to underflow (products of two such terms stay far inside the normal range).

/// `a + b = s + e` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// `a + b = s + e` exactly, for the other `geom` modules.
#[inline]
pub(crate) fn two_sum_pub(a: f64, b: f64) -> (f64, f64) {
    two_sum(a, b)
}

/// `a * b = p + e` exactly (FMA gives the rounding error of the product).
#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Adds `b` to the nonoverlapping expansion `e` (increasing magnitude), exactly.
fn grow(e: &mut Vec<f64>, b: f64) {
    let mut q = b;
    let mut out = Vec::with_capacity(e.len() + 1);
    for &x in e.iter() {
        let (s, err) = two_sum(q, x);
        if err != 0.0 {
            out.push(err);
        }
        q = s;
    }
    out.push(q);
    *e = out;
}

/// Adds `sign * x * y` exactly.
fn add_product(e: &mut Vec<f64>, sign: f64, x: f64, y: f64) {
    let (p, err) = two_product(x, y);
    grow(e, sign * p);
    grow(e, sign * err);
}

/// Adds `sign * (u + v)²` exactly, with `u + v` an exact two-term sum.
fn add_square(e: &mut Vec<f64>, sign: f64, u: f64, v: f64) {
    add_product(e, sign, u, u);
    add_product(e, 2.0 * sign, u, v);
    add_product(e, sign, v, v);
}

/// Exactly: `|a - b| <= r1 + r2` for `f32` values given as `f64`.
pub(crate) fn within(a: [f64; 3], b: [f64; 3], r1: f64, r2: f64) -> bool {
    cmp_distance(a, b, r1, r2) != std::cmp::Ordering::Greater
}

/// Exactly: the sign of `|a - b| - (r1 + r2)`, for coordinates that are `f32`s
/// given as `f64` and `r1`, `r2` `f64`s of about the `f32` range (an `f32`, or
/// the midpoint of two neighbouring `f32`s), so that no product below overflows
/// or underflows and each is exact. A negative sum `r1 + r2` is handled too
/// (then the distance is larger).
pub(crate) fn cmp_distance(a: [f64; 3], b: [f64; 3], r1: f64, r2: f64) -> std::cmp::Ordering {
    use std::cmp::Ordering;
    let (rs, re) = two_sum(r1, r2);
    // `rs + re` is exact, so its sign is that of `rs` (`re == 0` when `rs == 0`).
    if rs < 0.0 {
        return Ordering::Greater;
    }
    // Both sides are non-negative: compare their squares.
    let mut e = Vec::with_capacity(32);
    add_square(&mut e, -1.0, rs, re);
    for i in 0..3 {
        let (ds, de) = two_sum(a[i], -b[i]);
        add_square(&mut e, 1.0, ds, de);
    }
    // The largest nonzero component carries the sign.
    match e.iter().rev().find(|&&x| x != 0.0) {
        Some(&x) if x > 0.0 => Ordering::Greater,
        Some(_) => Ordering::Less,
        None => Ordering::Equal,
    }
}

/// An exact real number as a nonoverlapping expansion: the sum of its `f64`
/// components (smallest first). Only for the rare inputs the `f64` filters of the
/// ray and frustum tests cannot decide, so it favours simplicity over speed:
/// products are O(n·m) `grow`s. Every value built here is a polynomial of degree
/// at most 4 in `f32` inputs, so no component overflows (|x| <= 1.2e154) or
/// underflows (all are multiples of 2^-596, far above 2^-1074).
#[derive(Clone, Debug, Default)]
pub(crate) struct Exp(Vec<f64>);

impl Exp {
    /// The exact value `x`.
    pub(crate) fn of(x: f64) -> Exp {
        Exp(vec![x])
    }

    /// `a - b`, exactly.
    pub(crate) fn diff(a: f64, b: f64) -> Exp {
        let (s, e) = two_sum(a, -b);
        Exp(vec![e, s])
    }

    /// `self + other`, exactly.
    pub(crate) fn add(&self, other: &Exp) -> Exp {
        let mut e = self.0.clone();
        for &x in &other.0 {
            grow(&mut e, x);
        }
        Exp(e)
    }

    /// `self - other`, exactly.
    pub(crate) fn sub(&self, other: &Exp) -> Exp {
        self.add(&other.neg())
    }

    /// `-self`.
    pub(crate) fn neg(&self) -> Exp {
        Exp(self.0.iter().map(|x| -x).collect())
    }

    /// `self * other`, exactly.
    pub(crate) fn mul(&self, other: &Exp) -> Exp {
        let mut e = Vec::with_capacity(2 * self.0.len() * other.0.len());
        for &x in &self.0 {
            for &y in &other.0 {
                add_product(&mut e, 1.0, x, y);
            }
        }
        Exp(e)
    }

    /// The sign of the exact value: that of the largest nonzero component.
    pub(crate) fn sign(&self) -> std::cmp::Ordering {
        match self.0.iter().rev().find(|&&x| x != 0.0) {
            Some(&x) if x > 0.0 => std::cmp::Ordering::Greater,
            Some(_) => std::cmp::Ordering::Less,
            None => std::cmp::Ordering::Equal,
        }
    }
}

/// The largest `f32` not above `(x - o) / d`, exactly, for `f64`-widened `f32`
/// inputs (`d != 0`, all finite). A monotone function of the exact quotient, so
/// of `x`: a larger box never gets a larger entry parameter.
///
/// Cost: one division and one FMA when the `f64` quotient is exact or far from
/// an `f32` boundary (almost always); otherwise up to two exact sign tests of
/// `x - o - y d` (three `f64` terms, `y d` exact since `y` and `d` are `f32`s).
/// The `f64` quotient is within 2^-51 relative of the exact one (one rounding of
/// the difference, one of the division; no such quotient leaves the normal range).
#[inline]
pub(crate) fn quotient_floor_f32(x: f64, o: f64, d: f64) -> f32 {
    // Fast path: the rounded quotient `q` is within 2^-51 |q| of the exact one, so
    // if it is farther than 2^-50 |q| from its nearest `f32` `y` (the difference
    // is exact), the floor is `y` or the `f32` below. Out of the `f32` range `y`
    // is ±∞ and the gap infinite: the floor is `f32::MAX` or -∞.
    let q = (x - o) / d;
    let y = q as f32;
    let gap = q - y as f64;
    let eps = q.abs() * (1.0 / (1u64 << 50) as f64);
    if gap > eps {
        return y;
    }
    if gap < -eps {
        return f32_down(y);
    }
    quotient_floor_slow(x, o, d)
}

/// [`quotient_floor_f32`] for a quotient at (or within rounding of) an `f32`.
#[cold]
#[inline(never)]
fn quotient_floor_slow(x: f64, o: f64, d: f64) -> f32 {
    let (s, e) = two_sum(x, -o);
    let q = s / d;
    // (x - o) - q d = (s - q d) + e; `s - q d` is exact (FMA); the sum's sign is.
    let rho = (-q).mul_add(d, s) + e;
    let y = round_down_f32(q);
    if rho == 0.0 {
        return y; // exact quotient
    }
    // Near an `f32` boundary: adjust `y` by exact comparisons with the quotient.
    // `below(y)`: y <= (x - o) / d, i.e. sign(x - o - y d) agrees with sign(d).
    let below = |y: f32| {
        let p = y as f64 * d; // exact: a product of two `f32`s
        let mut ex = Exp::of(e);
        ex = ex.add(&Exp::diff(s, p));
        let sg = ex.sign();
        sg == std::cmp::Ordering::Equal || (sg == std::cmp::Ordering::Greater) == (d > 0.0)
    };
    // Beyond the `f32` range the floor is -∞ or `f32::MAX`; `below` needs finite y.
    let mut y = y.max(-f32::MAX);
    while y.is_finite() && !below(y) {
        y = f32_down(y);
    }
    loop {
        let up = -f32_down(-y);
        if up.is_finite() && below(up) {
            y = up;
        } else {
            return y;
        }
    }
}

/// The largest `f32` not above `x` (`-∞`/`+∞` beyond the range).
#[inline]
pub(crate) fn round_down_f32(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) > x {
        f32_down(y)
    } else {
        y
    }
}

/// The next `f32` toward −∞ (`f32::next_down`: NaN and −∞ stay, ±0 gives
/// the negative smallest subnormal). The name predates the MSRV that has it.
#[inline]
pub(crate) fn f32_down(y: f32) -> f32 {
    y.next_down()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansions_are_exact() {
        use std::cmp::Ordering::*;
        // (2^100 + 1)² - 2^200 - 2^101 = 1, far below f64's resolution at 2^200.
        let p = |k: i32| 2f64.powi(k);
        let a = Exp::diff(p(100), -1.0);
        let sq = a.mul(&a);
        let rest = sq.sub(&Exp::of(p(200))).sub(&Exp::of(p(101)));
        let one = rest.sub(&Exp::of(1.0));
        assert_eq!(rest.sign(), Greater);
        assert_eq!(one.sign(), Equal, "{one:?}");
        assert_eq!(one.sub(&Exp::of(1e-300)).sign(), Less);
    }

    #[test]
    fn quotient_floor_is_exact() {
        use rand::{Rng, SeedableRng};
        use std::cmp::Ordering::*;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mut slow = 0;
        for k in 0..200_000 {
            let mut g = || {
                if k % 2 == 0 {
                    // Small integers: exact and near-boundary quotients abound.
                    rng.gen_range(-64i32..=64) as f32 as f64
                } else {
                    let m: f32 = rng.gen_range(-1.0..1.0);
                    (m * 10f32.powi(rng.gen_range(-30..30))) as f64
                }
            };
            let (x, o, d) = (g(), g(), g());
            if d == 0.0 {
                continue;
            }
            let y = quotient_floor_f32(x, o, d);
            if ((x - o) / d).abs() >= f32::MAX as f64 {
                assert!(y == f32::NEG_INFINITY || y == f32::MAX || y == -f32::MAX);
                continue;
            }
            // y d <= x - o < next(y) d (for d > 0; reversed for d < 0), exactly.
            let num = Exp::diff(x, o);
            let gap = |y: f32| num.sub(&Exp::of(y as f64).mul(&Exp::of(d))).sign();
            let want_le = if d > 0.0 {
                [Greater, Equal]
            } else {
                [Less, Equal]
            };
            assert!(want_le.contains(&gap(y)), "{x} {o} {d} -> {y}");
            let up = -f32_down(-y);
            assert!(!want_le.contains(&gap(up)), "{x} {o} {d} -> {y}");
            slow += ((x - o) / d != y as f64) as u32;
        }
        assert!(slow > 1000);
        assert_eq!(quotient_floor_f32(2.0, 0.0, 2.0), 1.0);
        assert_eq!(quotient_floor_f32(1.0, 0.0, 3.0), 0.3333333);
    }

    #[test]
    fn decides_what_f64_cannot() {
        let big = 1e30f32 as f64;
        // (1e30 + 5, 5, 5) is outside the ball of radius 1e30 at the origin by ~5.
        assert!(!within([big + 0.0, 0.0, 0.0], [-5.0, 5.0, 5.0], big, 0.0));
        assert!(within([big, 0.0, 0.0], [0.0, 0.0, 0.0], big, 0.0));
        assert!(within([big, 0.0, 0.0], [4.0, 0.0, 0.0], big, 0.0));
        assert!(!within(
            [big, 0.0, 0.0],
            [-1e-30f32 as f64, 0.0, 0.0],
            big,
            0.0
        ));
        assert!(within([0.0; 3], [0.0; 3], 0.0, 0.0));
        let m = f32::MAX as f64;
        assert!(within([m, 0.0, 0.0], [-m, 0.0, 0.0], m, m));
        assert!(!within([m, 1e-45f32 as f64, 0.0], [-m, 0.0, 0.0], m, m));
    }
}
