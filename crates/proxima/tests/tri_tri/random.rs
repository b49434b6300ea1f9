//! Randomized comparisons with fixed seeds: the library against the predicate
//! reference (every generator) and the integer Carathéodory oracle (grid
//! generators), plus order invariance.

use crate::sym::{axis_map, variants, Tri};
use crate::{carath, reference};
use glam::Vec3;
use proxima::narrow::triangles_intersect;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

/// Uniform f32 coordinates in [-1, 1].
fn uniform(r: &mut Pcg64) -> Tri {
    [(); 3].map(|_| {
        Vec3::new(
            r.gen_range(-1.0..=1.0),
            r.gen_range(-1.0..=1.0),
            r.gen_range(-1.0..=1.0),
        )
    })
}

/// Coordinates k/64 with |k| <= n: small n makes coplanar, touching and
/// degenerate configurations common.
fn grid(r: &mut Pcg64, n: i32) -> Tri {
    [(); 3].map(|_| Vec3::from_array([(); 3].map(|_| r.gen_range(-n..=n) as f32 / 64.0)))
}

/// Moves a coordinate by a few ulps.
fn nudge(r: &mut Pcg64, x: f32) -> f32 {
    let steps = r.gen_range(-2i32..=2);
    let mut y = x;
    for _ in 0..steps.abs() {
        y = if steps > 0 { next_up(y) } else { -next_up(-y) };
    }
    y
}

fn next_up(x: f32) -> f32 {
    if x == 0.0 {
        f32::from_bits(1)
    } else if x > 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        f32::from_bits(x.to_bits() - 1)
    }
}

/// B shares (up to a few ulps) a corner, an edge point or the plane of A:
/// nearly-touching configurations in general position.
fn near_touching(r: &mut Pcg64) -> (Tri, Tri) {
    let a = uniform(r);
    let mut b = uniform(r);
    match r.gen_range(0..4) {
        0 => b[0] = a[r.gen_range(0..3)],
        1 => {
            let t: f32 = r.gen_range(0.0..=1.0);
            b[0] = a[0] + (a[1] - a[0]) * t;
        }
        2 => {
            // B's corners in (roughly) A's plane.
            for p in &mut b {
                let (u, w): (f32, f32) = (r.gen_range(-1.0..2.0), r.gen_range(-1.0..2.0));
                *p = a[0] + (a[1] - a[0]) * u + (a[2] - a[0]) * w;
            }
        }
        _ => {
            b[0] = a[0];
            b[1] = a[1];
        }
    }
    for p in &mut b {
        *p = Vec3::new(nudge(r, p.x), nudge(r, p.y), nudge(r, p.z));
    }
    (a, b)
}

/// Exactly coplanar (z = 0, then an axis map) f32 triangles, one possibly a
/// scaled copy of a sub-triangle of the other.
fn coplanar(r: &mut Pcg64) -> (Tri, Tri) {
    let m = r.gen_range(0..48);
    let flat = |r: &mut Pcg64| {
        [(); 3].map(|_| Vec3::new(r.gen_range(-1.0..=1.0), r.gen_range(-1.0..=1.0), 0.0))
    };
    let (a, b) = (flat(r), flat(r));
    (a.map(|p| axis_map(p, m)), b.map(|p| axis_map(p, m)))
}

fn check(a: &Tri, b: &Tri, stats: &mut [usize; 2]) {
    let got = triangles_intersect(a, b);
    assert_eq!(got, reference::intersect(a, b), "{a:?} {b:?}");
    assert_eq!(super::prepared(a, b), got, "prepared: {a:?} {b:?}");
    stats[got as usize] += 1;
}

/// The headline comparison: >= 10^6 pairs from five generators.
#[test]
fn million_pairs_against_reference() {
    let mut r = rng(0x7121_7121);
    let mut stats = [0usize; 2];
    for i in 0..1_000_000 {
        let (a, b) = match i % 5 {
            0 => (uniform(&mut r), uniform(&mut r)),
            1 => (grid(&mut r, 2), grid(&mut r, 2)),
            2 => (grid(&mut r, 16), grid(&mut r, 16)),
            3 => near_touching(&mut r),
            _ => coplanar(&mut r),
        };
        check(&a, &b, &mut stats);
    }
    // Both answers must be common, or the comparison proves little.
    assert!(stats[0] > 100_000 && stats[1] > 100_000, "{stats:?}");
}

#[test]
fn grid_pairs_against_integer_oracle() {
    let mut r = rng(64);
    let mut stats = [0usize; 2];
    for i in 0..200_000 {
        let n = [1, 2, 4, 64][i % 4];
        let (a, b) = (grid(&mut r, n), grid(&mut r, n));
        let want = carath::intersect(&a, &b, 64.0).unwrap();
        assert_eq!(triangles_intersect(&a, &b), want, "{a:?} {b:?}");
        assert_eq!(reference::intersect(&a, &b), want, "reference: {a:?} {b:?}");
        assert_eq!(super::prepared(&a, &b), want, "prepared: {a:?} {b:?}");
        stats[want as usize] += 1;
    }
    assert!(stats[0] > 20_000 && stats[1] > 20_000, "{stats:?}");
}

#[test]
fn random_pairs_are_order_invariant() {
    let mut r = rng(3);
    for i in 0..3_000 {
        let (a, b) = match i % 3 {
            0 => (grid(&mut r, 2), grid(&mut r, 2)),
            1 => near_touching(&mut r),
            _ => coplanar(&mut r),
        };
        let want = triangles_intersect(&a, &b);
        for (x, y) in variants(&a, &b, i % 30 == 0) {
            assert_eq!(
                triangles_intersect(&x, &y),
                want,
                "{a:?} {b:?} as {x:?} {y:?}"
            );
        }
    }
}

#[test]
fn wide_exponent_range() {
    // Coordinates spanning many binades, where naive arithmetic loses everything.
    let mut r = rng(99);
    let mut stats = [0usize; 2];
    for _ in 0..100_000 {
        let e: i32 = r.gen_range(-60..60);
        let mut t = || {
            [(); 3].map(|_| {
                Vec3::from_array([(); 3].map(|_| {
                    let x: f32 = r.gen_range(-1.0..=1.0);
                    x * 2f32.powi(r.gen_range(e - 20..=e))
                }))
            })
        };
        let (a, b) = (t(), t());
        check(&a, &b, &mut stats);
    }
    assert!(stats[0] > 1000 && stats[1] > 1000, "{stats:?}");
}

#[test]
fn extreme_exponent_spread() {
    // Every f32 binade mixed inside one triangle, where differences are not exact
    // even in f64: the prepared test's error bound must still certify only exact
    // signs. Half the pairs share a corner, so touching answers are common.
    let mut r = rng(4242);
    let mut stats = [0usize; 2];
    for i in 0..100_000 {
        let mut p = || {
            Vec3::from_array([(); 3].map(|_| {
                let x: f32 = r.gen_range(-1.0..=1.0);
                x * 2f32.powi(r.gen_range(-126..=126))
            }))
        };
        let a = [p(), p(), p()];
        let b = if i % 2 == 0 {
            [a[0], p(), p()]
        } else {
            [p(), p(), p()]
        };
        check(&a, &b, &mut stats);
    }
    assert!(stats[0] > 1000 && stats[1] > 1000, "{stats:?}");
}

#[test]
fn segment_tests_against_integer_oracle() {
    use proxima::narrow::{segment_triangle_intersect, segments_intersect};
    let mut r = rng(5);
    for i in 0..50_000 {
        let n = [1, 2, 8][i % 3];
        let (s, t, u) = (grid(&mut r, n), grid(&mut r, n), grid(&mut r, n));
        let seg_as_tri = |p: Vec3, q: Vec3| [p, q, q];
        let want = carath::intersect(&seg_as_tri(s[0], s[1]), &t, 64.0).unwrap();
        assert_eq!(
            segment_triangle_intersect(s[0], s[1], &t),
            want,
            "{s:?} {t:?}"
        );
        let want =
            carath::intersect(&seg_as_tri(s[0], s[1]), &seg_as_tri(u[0], u[1]), 64.0).unwrap();
        assert_eq!(
            segments_intersect(s[0], s[1], u[0], u[1]),
            want,
            "{s:?} {u:?}"
        );
    }
}
