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
    let mut e = Vec::with_capacity(32);
    let (rs, re) = two_sum(r1, r2);
    add_square(&mut e, 1.0, rs, re);
    for i in 0..3 {
        let (ds, de) = two_sum(a[i], -b[i]);
        add_square(&mut e, -1.0, ds, de);
    }
    // The largest nonzero component carries the sign.
    e.iter()
        .rev()
        .find(|&&x| x != 0.0)
        .map_or(true, |&x| x > 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

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
