//! The exact closed ball–triangle test: whether some point of a triangle lies
//! within `radius` of a point. The one place it is decided; the collision world's
//! sphere queries and sphere–mesh contacts call it [sources: near-objects].
//!
//! The closest point of a triangle to `p` is a corner, a point inside an edge, or
//! (for a triangle that is not degenerate) a point inside the face, so the ball
//! meets the triangle iff one of these holds:
//! 1. a corner is within `r` of `p`;
//! 2. for an edge `uv` (`u != v`): the projection of `p` on its line falls on the
//!    edge (`(p − u)·(v − u) >= 0` and `(p − v)·(u − v) >= 0`) and
//!    `|(p − u) × (v − u)|² <= r²·|v − u|²`;
//! 3. for `n = (b − a) × (c − a) != 0`: `p` projects into the closed triangle
//!    (`((y − x) × (p − x))·n >= 0` for each edge `xy`) and
//!    `((p − a)·n)² <= r²·|n|²`.
//!
//! Each is the sign of a polynomial (degree 2, 4 or 6) in the `f32` inputs, each
//! decided exactly: an `f64` evaluation that tracks a bound on its own rounding
//! error decides when the bound allows, otherwise the exact expansions of
//! `geom::exact` do. With `f32` inputs no step can overflow or underflow `f64`
//! (degree 6 in coordinates below 2^129 stays below 2^774; non-zero values stay
//! above 2^-894), so the answer is exact for every finite input.

use crate::geom::exact::Exp;
use crate::geom::overlap;
use crate::geom::{Aabb, Sphere};
use glam::Vec3;
use std::cmp::Ordering;

/// Whether the closed ball of `radius` around `center` shares a point with the
/// closed triangle `tri` (edges and corners included; a degenerate triangle is
/// its segment or point). Exact for every finite input with `radius >= 0`;
/// non-finite input gives an unspecified answer, never a panic.
///
/// Cost: a box pre-test (one exact point–box distance), then ~100 flops on the
/// `f64` filter; a few thousand when the ball (nearly) touches the triangle
/// exactly and the expansions decide.
pub fn sphere_triangle(center: Vec3, radius: f32, tri: &[Vec3; 3]) -> bool {
    let [a, b, c] = *tri;
    let ball = Sphere::new(center, radius);
    let bounds = Aabb::new(a.min(b).min(c), a.max(b).max(c));
    if !overlap::sphere_aabb(&ball, &bounds) {
        return false;
    }
    if tri
        .iter()
        .any(|&v| overlap::sphere_sphere(&ball, &Sphere::new(v, 0.0)))
    {
        return true;
    }
    if [(a, b), (b, c), (c, a)]
        .iter()
        .any(|&(u, v)| edge_within(center, radius, u, v))
    {
        return true;
    }
    face_within(center, radius, tri)
}

/// Case 2 of the module docs for the edge `uv`.
fn edge_within(p: Vec3, r: f32, u: Vec3, v: Vec3) -> bool {
    if u == v {
        // A point: case 1 covers it.
        return false;
    }
    let ahead = |x: Vec3, y: Vec3| {
        decide(
            || dot(&diff3(p, x), &diff3(y, x)),
            || dot(&diff3(p, x), &diff3(y, x)),
        )
    };
    if ahead(u, v) == Ordering::Less || ahead(v, u) == Ordering::Less {
        return false;
    }
    decide(
        || line_gap::<Tracked>(p, r, u, v),
        || line_gap::<Exp>(p, r, u, v),
    ) != Ordering::Greater
}

/// `|(p − u) × (v − u)|² − r²·|v − u|²`: negative or zero iff the line `uv` is
/// within `r` of `p`.
fn line_gap<N: Num>(p: Vec3, r: f32, u: Vec3, v: Vec3) -> N {
    let e: [N; 3] = diff3(v, u);
    let c = cross(&diff3(p, u), &e);
    let r2 = N::of(r).mul(&N::of(r));
    dot(&c, &c).sub(&r2.mul(&dot(&e, &e)))
}

/// Case 3 of the module docs.
fn face_within(p: Vec3, r: f32, tri: &[Vec3; 3]) -> bool {
    let [a, b, c] = *tri;
    // A degenerate triangle has no face: its edges and corners are all of it.
    let normal_zero = (0..3).all(|i| {
        decide(
            || cross::<Tracked>(&diff3(b, a), &diff3(c, a))[i],
            || cross::<Exp>(&diff3(b, a), &diff3(c, a))[i].clone(),
        ) == Ordering::Equal
    });
    if normal_zero {
        return false;
    }
    let inside = [(a, b), (b, c), (c, a)].iter().all(|&(x, y)| {
        decide(
            || edge_side::<Tracked>(p, x, y, tri),
            || edge_side::<Exp>(p, x, y, tri),
        ) != Ordering::Less
    });
    inside
        && decide(
            || plane_gap::<Tracked>(p, r, tri),
            || plane_gap::<Exp>(p, r, tri),
        ) != Ordering::Greater
}

/// `((y − x) × (p − x))·n` with `n` the triangle's normal: non-negative iff `p`
/// projects onto the inner side of the edge `xy` (or onto its line).
fn edge_side<N: Num>(p: Vec3, x: Vec3, y: Vec3, tri: &[Vec3; 3]) -> N {
    let [a, b, c] = *tri;
    let n = cross(&diff3(b, a), &diff3(c, a));
    dot(&cross(&diff3(y, x), &diff3(p, x)), &n)
}

/// `((p − a)·n)² − r²·|n|²`: negative or zero iff the triangle's plane is within
/// `r` of `p`.
fn plane_gap<N: Num>(p: Vec3, r: f32, tri: &[Vec3; 3]) -> N {
    let [a, b, c] = *tri;
    let n: [N; 3] = cross(&diff3(b, a), &diff3(c, a));
    let h = dot(&diff3(p, a), &n);
    let r2 = N::of(r).mul(&N::of(r));
    h.mul(&h).sub(&r2.mul(&dot(&n, &n)))
}

/// The sign of a polynomial: the filtered `f64` value when its error bound
/// decides, else the exact one.
#[inline]
fn decide(fast: impl FnOnce() -> Tracked, exact: impl FnOnce() -> Exp) -> Ordering {
    fast().sign().unwrap_or_else(|| exact().sign())
}

/// The arithmetic the predicates are written in, once for the filter and once
/// for the exact fallback.
trait Num: Clone {
    /// The exact value of an `f32`.
    fn of(x: f32) -> Self;
    /// `x − y` for two `f32`s.
    fn diff(x: f32, y: f32) -> Self;
    fn add(&self, o: &Self) -> Self;
    fn sub(&self, o: &Self) -> Self;
    fn mul(&self, o: &Self) -> Self;
}

impl Num for Exp {
    fn of(x: f32) -> Self {
        Exp::of(x as f64)
    }
    fn diff(x: f32, y: f32) -> Self {
        Exp::diff(x as f64, y as f64)
    }
    fn add(&self, o: &Self) -> Self {
        Exp::add(self, o)
    }
    fn sub(&self, o: &Self) -> Self {
        Exp::sub(self, o)
    }
    fn mul(&self, o: &Self) -> Self {
        Exp::mul(self, o)
    }
}

/// An `f64` value with a bound on its rounding error: `|value − exact| <=
/// k·ε·mag` with `ε = 2^-53` (Higham's `γ_k`, `k` the roundings on the longest
/// path; `mag` is the same expression evaluated on absolute values, the
/// "permanent"). No product of `f32`-derived values of degree <= 6 overflows or
/// underflows `f64`, the only way the bound could fail.
#[derive(Clone, Copy, Debug)]
struct Tracked {
    value: f64,
    mag: f64,
    k: u32,
}

impl Tracked {
    /// The sign if the error bound certifies it. Twice the bound (and `2^-52`
    /// for `2^-53`) absorbs the rounding of `mag` itself and `γ_k`'s `1/(1 − kε)`.
    fn sign(&self) -> Option<Ordering> {
        if self.mag == 0.0 {
            // Every term is exactly zero (no product underflows).
            return Some(Ordering::Equal);
        }
        let bound = 2.0 * self.k as f64 * f64::EPSILON * self.mag;
        if self.value > bound {
            Some(Ordering::Greater)
        } else if self.value < -bound {
            Some(Ordering::Less)
        } else {
            None
        }
    }
}

impl Num for Tracked {
    fn of(x: f32) -> Self {
        Tracked {
            value: x as f64,
            mag: (x as f64).abs(),
            k: 0,
        }
    }
    fn diff(x: f32, y: f32) -> Self {
        let value = x as f64 - y as f64;
        Tracked {
            value,
            mag: value.abs(),
            k: 1,
        }
    }
    fn add(&self, o: &Self) -> Self {
        Tracked {
            value: self.value + o.value,
            mag: self.mag + o.mag,
            k: self.k.max(o.k) + 1,
        }
    }
    fn sub(&self, o: &Self) -> Self {
        Tracked {
            value: self.value - o.value,
            mag: self.mag + o.mag,
            k: self.k.max(o.k) + 1,
        }
    }
    fn mul(&self, o: &Self) -> Self {
        Tracked {
            value: self.value * o.value,
            mag: self.mag * o.mag,
            k: self.k + o.k + 1,
        }
    }
}

fn diff3<N: Num>(x: Vec3, y: Vec3) -> [N; 3] {
    [N::diff(x.x, y.x), N::diff(x.y, y.y), N::diff(x.z, y.z)]
}

fn dot<N: Num>(a: &[N; 3], b: &[N; 3]) -> N {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

fn cross<N: Num>(a: &[N; 3], b: &[N; 3]) -> [N; 3] {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// Exact reference in rationals: the squared distance from `p` to the triangle
    /// as an exact fraction, by minimizing over the closed triangle with the
    /// classic region analysis done in big rationals. Independent of the code
    /// under test (which never computes a distance).
    mod reference {
        use super::super::Exp;
        use std::cmp::Ordering;

        /// `num / den` with `den > 0`, both exact.
        #[derive(Clone, Debug)]
        pub struct Frac {
            pub num: Exp,
            pub den: Exp,
        }

        fn e(x: f32) -> Exp {
            Exp::of(x as f64)
        }

        fn sub3(a: [f32; 3], b: [f32; 3]) -> [Exp; 3] {
            [0, 1, 2].map(|i| Exp::diff(a[i] as f64, b[i] as f64))
        }

        fn dot(a: &[Exp; 3], b: &[Exp; 3]) -> Exp {
            a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
        }

        fn cmp(a: &Frac, b: &Frac) -> Ordering {
            a.num.mul(&b.den).sub(&b.num.mul(&a.den)).sign()
        }

        /// Squared distance from `p` to the segment `uv`, exactly.
        fn seg(p: [f32; 3], u: [f32; 3], v: [f32; 3]) -> Frac {
            let w = sub3(p, u);
            let d = sub3(v, u);
            let dd = dot(&d, &d);
            let wd = dot(&w, &d);
            let ww = dot(&w, &w);
            if dd.sign() == Ordering::Equal || wd.sign() != Ordering::Greater {
                return Frac {
                    num: ww,
                    den: Exp::of(1.0),
                };
            }
            if wd.sub(&dd).sign() != Ordering::Less {
                let w2 = sub3(p, v);
                return Frac {
                    num: dot(&w2, &w2),
                    den: Exp::of(1.0),
                };
            }
            // |w|² − (w·d)²/|d|²
            Frac {
                num: ww.mul(&dd).sub(&wd.mul(&wd)),
                den: dd,
            }
        }

        /// Whether the squared distance from `p` to the triangle is `<= r²`.
        pub fn within(p: [f32; 3], r: f32, t: [[f32; 3]; 3]) -> bool {
            let r2 = Frac {
                num: e(r).mul(&e(r)),
                den: Exp::of(1.0),
            };
            let mut best = seg(p, t[0], t[1]);
            for (u, v) in [(t[1], t[2]), (t[2], t[0])] {
                let s = seg(p, u, v);
                if cmp(&s, &best) == Ordering::Less {
                    best = s;
                }
            }
            // The face: barycentric coordinates of the projection, all exact.
            let e1 = sub3(t[1], t[0]);
            let e2 = sub3(t[2], t[0]);
            let w = sub3(p, t[0]);
            let (a, b, c) = (dot(&e1, &e1), dot(&e1, &e2), dot(&e2, &e2));
            let (d, f) = (dot(&w, &e1), dot(&w, &e2));
            let den = a.mul(&c).sub(&b.mul(&b)); // |e1 × e2|² >= 0
            if den.sign() == Ordering::Greater {
                let s = c.mul(&d).sub(&b.mul(&f)); // s·den
                let tt = a.mul(&f).sub(&b.mul(&d)); // t·den
                let inside = s.sign() != Ordering::Less
                    && tt.sign() != Ordering::Less
                    && den.sub(&s).sub(&tt).sign() != Ordering::Less;
                if inside {
                    // |w|² − (s·d + t·f)/den ... = (|w|²·den − s·d − t·f) / den
                    let ww = dot(&w, &w);
                    let face = Frac {
                        num: ww.mul(&den).sub(&s.mul(&d)).sub(&tt.mul(&f)),
                        den: den.clone(),
                    };
                    if cmp(&face, &best) == Ordering::Less {
                        best = face;
                    }
                }
            }
            cmp(&best, &r2) != Ordering::Greater
        }
    }

    fn arr(v: Vec3) -> [f32; 3] {
        v.to_array()
    }

    fn check(p: Vec3, r: f32, t: [Vec3; 3]) -> bool {
        let want = reference::within(arr(p), r, t.map(arr));
        let got = sphere_triangle(p, r, &t);
        assert_eq!(got, want, "p {p:?} r {r} t {t:?}");
        // Order of the corners does not matter.
        assert_eq!(sphere_triangle(p, r, &[t[1], t[2], t[0]]), want);
        assert_eq!(sphere_triangle(p, r, &[t[2], t[1], t[0]]), want);
        got
    }

    #[test]
    fn agrees_with_exact_distance_on_random_and_touching_inputs() {
        let mut rng = Pcg64::seed_from_u64(7);
        let mut seen = [0usize; 2];
        for i in 0..20_000 {
            let mut v = || {
                Vec3::new(
                    rng.gen_range(-2.0..2.0),
                    rng.gen_range(-2.0..2.0),
                    rng.gen_range(-2.0..2.0),
                )
            };
            let t = [v(), v(), v()];
            let p = v();
            let r = rng.gen_range(0.0f32..1.5);
            seen[check(p, r, t) as usize] += 1;
            // Degenerate triangles: a segment, a point, collinear corners.
            let seg = [t[0], t[1], t[0].lerp(t[1], 0.25)];
            check(p, r, seg);
            check(p, r, [t[0], t[0], t[0]]);
            check(p, r, [t[0], t[1], t[1]]);
            // Touching: the radius is the f32 distance to a point on the triangle,
            // and the ulps around it.
            let (u, w) = (rng.gen::<f32>(), rng.gen::<f32>());
            let (u, w) = if u + w > 1.0 {
                (1.0 - u, 1.0 - w)
            } else {
                (u, w)
            };
            let on = t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * w;
            let site = match i % 4 {
                0 => on,
                1 => t[i % 3],
                2 => t[0].lerp(t[1], u),
                _ => on + (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero() * 0.3,
            };
            let d = (site - p).length();
            for k in [-2i32, -1, 0, 1, 2] {
                let rr = f32::from_bits((d.to_bits() as i32 + k).max(0) as u32);
                check(p, rr, t);
            }
            // A point on the triangle itself, radius 0.
            check(site, 0.0, t);
        }
        assert!(seen.iter().all(|&n| n > 2000), "{seen:?}");
    }

    #[test]
    fn exact_at_touching_integer_configurations() {
        let t = [
            Vec3::ZERO,
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ];
        // Above the face at height 1: touching at r = 1, not at the ulp below.
        let p = Vec3::new(1.0, 1.0, 1.0);
        assert!(check(p, 1.0, t));
        assert!(!check(p, f32::from_bits(1.0f32.to_bits() - 1), t));
        // Beside the hypotenuse: distance sqrt(2) from (2, 2, 0) at (3, 3, 0).
        let q = Vec3::new(3.0, 3.0, 0.0);
        let d = 2f32.sqrt();
        let below = (d as f64) < 2f64.sqrt();
        assert_eq!(check(q, d, t), !below);
        assert!(check(q, f32::from_bits(d.to_bits() + 1), t));
        // A corner: exactly at distance 5 from (0, 0, 0).
        assert!(check(Vec3::new(-3.0, -4.0, 0.0), 5.0, t));
        assert!(!check(Vec3::new(-3.0, -4.0, 0.0), 4.999_999_5, t));
        // Huge and tiny magnitudes.
        let big = [t[0] * 1e30, t[1] * 1e30, t[2] * 1e30];
        assert!(check(p * 1e30, 1e30, big));
        let tiny = [t[0] * 1e-38, t[1] * 1e-38, t[2] * 1e-38];
        assert!(check(p * 1e-38, 1e-38, tiny));
        assert!(!check(p * 1e-38, 0.99e-38, tiny));
    }
}
