//! Tests of the sweep and distance functions of `overlap` against exact
//! arithmetic written independently here (expansions straight from the end
//! points, not through `line_ball`'s formulation).

use super::*;
use crate::geom::exact::{self, Exp};
use crate::geom::Segment;
use glam::vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// A random `f32` on a coarse grid (exact ties are common) at one of several
/// magnitudes, mixed within one case.
fn coarse(rng: &mut Pcg64) -> f32 {
    let scale = [1.0f32, 1.0 / 64.0, 1e-20, 1e15, 1e30][rng.gen_range(0..5)];
    rng.gen_range(-8i32..=8) as f32 * scale
}

fn cv(rng: &mut Pcg64) -> Vec3 {
    vec3(coarse(rng), coarse(rng), coarse(rng))
}

fn ex(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn edot(a: &[Exp; 3], b: &[Exp; 3]) -> Exp {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

fn ediff(a: Vec3, b: Vec3) -> [Exp; 3] {
    let (a, b) = (ex(a), ex(b));
    [0, 1, 2].map(|i| Exp::diff(a[i], b[i]))
}

/// Exactly: does the sweep touch the sphere? From the end points: touching at
/// the start or the end, or the closest point of the open segment within
/// `r + R` (its foot strictly between the ends: `(f - c)·(t - f) < 0` and
/// `(t - c)·(t - f) > 0`, then `|(f - c) × (t - c)|² <= ρ² |t - f|²`).
fn sweep_touches_exact(sw: &SphereSweep, s: &Sphere) -> bool {
    let rho = Exp::diff(s.radius as f64, -(sw.radius as f64));
    let rho2 = rho.mul(&rho);
    let within = |p: Vec3| {
        let d = ediff(p, s.center);
        rho2.sub(&edot(&d, &d)).sign() != Ordering::Less
    };
    if within(sw.from) || within(sw.to) {
        return true;
    }
    let (fc, tc, tf) = (
        ediff(sw.from, s.center),
        ediff(sw.to, s.center),
        ediff(sw.to, sw.from),
    );
    if edot(&fc, &tf).sign() != Ordering::Less || edot(&tc, &tf).sign() != Ordering::Greater {
        return false;
    }
    let cr = [
        fc[1].mul(&tc[2]).sub(&fc[2].mul(&tc[1])),
        fc[2].mul(&tc[0]).sub(&fc[0].mul(&tc[2])),
        fc[0].mul(&tc[1]).sub(&fc[1].mul(&tc[0])),
    ];
    rho2.mul(&edot(&tf, &tf)).sub(&edot(&cr, &cr)).sign() != Ordering::Less
}

/// Hit or miss of `sweep_sphere` is exact at every magnitude (from 1e-20 to
/// 1e30, exact ties common), zero-length sweeps included; a hit's `t` is in
/// `[0, 1]`, `0` iff it touches at the start; and every box containing the
/// sphere is met by `sweep_aabb` with `t0 <= t <= t1` (index pruning is
/// consistent with the reported time).
#[test]
fn sweep_sphere_exact_and_consistent() {
    let mut rng = Pcg64::seed_from_u64(21);
    let (mut hits, mut misses, mut zero_len, mut at_start) = (0, 0, 0, 0);
    for k in 0..200_000 {
        let from = cv(&mut rng);
        let to = if k % 10 == 0 { from } else { cv(&mut rng) };
        let sw = SphereSweep::new(from, to, coarse(&mut rng).abs());
        let s = Sphere::new(cv(&mut rng), coarse(&mut rng).abs());
        let got = sweep_sphere(&sw, &s);
        assert_eq!(got.is_some(), sweep_touches_exact(&sw, &s), "{sw:?} {s:?}");
        let start = exact::within(ex(from), ex(s.center), s.radius as f64, sw.radius as f64);
        zero_len += (from == to) as u32;
        let Some(t) = got else {
            misses += 1;
            continue;
        };
        hits += 1;
        assert!((0.0..=1.0).contains(&t), "{t} {sw:?} {s:?}");
        if start {
            assert_eq!(t, 0.0);
            at_start += 1;
        }
        if from == to {
            assert!(start, "a zero-length sweep touches only at the start");
        }
        let b = outward_box(&s);
        for _ in 0..3 {
            let mut grow = || [0.0, 1.0, 1e10, 1e30][rng.gen_range(0..4)];
            let bx = Aabb::new(
                b.min - vec3(grow(), grow(), grow()),
                b.max + vec3(grow(), grow(), grow()),
            );
            let (t0, t1) = sweep_aabb(&sw, &bx).expect("box pruned a touched sphere");
            assert!(t0 <= t && t <= t1, "{t0} {t} {t1} {sw:?} {s:?}");
        }
    }
    assert!(hits > 20_000 && misses > 20_000, "{hits} {misses}");
    assert!(
        zero_len > 10_000 && at_start > 5_000,
        "{zero_len} {at_start}"
    );
}

/// Near-tangent sweeps at random orientations and magnitudes: the exact answer
/// flips within a few ulps, and the test follows it.
#[test]
fn grazing_sweeps_are_exact() {
    let mut rng = Pcg64::seed_from_u64(22);
    let mut both = [0u32; 2];
    for k in 0..50_000 {
        let scale = [1e-3f32, 1.0, 1e4, 1e20][k % 4];
        let mut u = || rng.gen_range(-1.0f32..1.0);
        let c = vec3(u(), u(), u()) * scale;
        let dir = vec3(u(), u(), u()).normalize_or(Vec3::X);
        let side = dir.any_orthonormal_vector();
        let (r, rr) = (u().abs() * scale, u().abs() * scale);
        // The segment passes at distance (r + R)(1 + tiny) from the centre.
        let off = (r + rr) * (1.0 + u() * 1e-6);
        let mid = c + side * off;
        let half = dir * scale * (0.5 + u().abs());
        let sw = SphereSweep::new(mid - half, mid + half, rr);
        let s = Sphere::new(c, r);
        let got = sweep_sphere(&sw, &s).is_some();
        assert_eq!(got, sweep_touches_exact(&sw, &s), "{sw:?} {s:?}");
        both[got as usize] += 1;
    }
    assert!(both.iter().all(|&n| n > 5_000), "{both:?}");
}

/// Tangent cases with exact answers: a sweep grazing a sphere touches it, and
/// one ulp less radius misses; at the end point too.
#[test]
fn tangent_sweeps_touch_and_one_ulp_less_misses() {
    let s = Sphere::new(vec3(0.0, 5.0, 0.0), 3.0);
    let graze = SphereSweep::new(vec3(-10.0, 0.0, 0.0), vec3(10.0, 0.0, 0.0), 2.0);
    assert_eq!(sweep_sphere(&graze, &s), Some(0.5));
    let thinner = SphereSweep {
        radius: exact::f32_down(2.0),
        ..graze
    };
    assert_eq!(sweep_sphere(&thinner, &s), None);
    // 3-4-5 at the end point: the sweep stops exactly touching.
    let s2 = Sphere::new(vec3(13.0, 4.0, 0.0), 2.0);
    let to_touch = SphereSweep::new(vec3(-10.0, 0.0, 0.0), vec3(10.0, 0.0, 0.0), 3.0);
    assert_eq!(sweep_sphere(&to_touch, &s2), Some(1.0));
    let short = SphereSweep::new(
        vec3(-10.0, 0.0, 0.0),
        vec3(exact::f32_down(10.0), 0.0, 0.0),
        3.0,
    );
    assert_eq!(sweep_sphere(&short, &s2), None);
    // Starting inside (and touching at the start) is t = 0.
    let inside = SphereSweep::new(vec3(0.0, 1.0, 0.0), vec3(0.0, -100.0, 0.0), 1.5);
    assert_eq!(sweep_sphere(&inside, &s), Some(0.0));
    let touching = SphereSweep::new(vec3(0.0, 0.0, 0.0), vec3(0.0, -100.0, 0.0), 2.0);
    assert_eq!(sweep_sphere(&touching, &s), Some(0.0));
    // Moving away from a sphere it does not touch.
    let away = SphereSweep::new(vec3(0.0, 0.0, 0.0), vec3(0.0, -100.0, 0.0), 1.0);
    assert_eq!(sweep_sphere(&away, &s), None);
    // Zero length: touches iff it overlaps.
    let rest = SphereSweep::new(vec3(0.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0), 1.0);
    assert_eq!(sweep_sphere(&rest, &s), Some(0.0));
    let rest_far = SphereSweep::new(Vec3::ZERO, Vec3::ZERO, 1.0);
    assert_eq!(sweep_sphere(&rest_far, &s), None);
    assert!(sweep_aabb(&rest, &s.aabb()).is_some());
    // Head on: first contact when the centres are r + R apart.
    let head_on = SphereSweep::new(vec3(0.0, -5.0, 0.0), vec3(0.0, 15.0, 0.0), 2.0);
    assert_eq!(sweep_sphere(&head_on, &s), Some(0.25));
}

/// The radius is the exact sum `r + R` and the direction the exact difference:
/// inputs whose `f32` sum or difference would round the wrong way are decided
/// right.
#[test]
fn sweep_does_not_round_its_inputs() {
    // r + R = 1 + 2^-30 is not an f32; the sphere is touched only through the
    // exact sum.
    let r = 1.0f32;
    let rr = 2f32.powi(-30);
    let s = Sphere::new(vec3(0.0, 1.0 + 2f32.powi(-23), 0.0), r);
    let sw = SphereSweep::new(vec3(-1.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), rr);
    assert_eq!(sweep_sphere(&sw, &s), None, "gap 2^-23 > 2^-30");
    let s_touch = Sphere::new(vec3(0.0, 1.0, 0.0), r);
    assert!(sweep_sphere(&sw, &s_touch).is_some());
    // A direction that is not an f32: from 1e-30 to 1 (to - from rounds to 1).
    // The segment ends at 1, so a sphere touching x = 1 exactly counts, and
    // one an ulp beyond does not.
    let sw = SphereSweep::new(vec3(1e-30, 0.0, 0.0), vec3(1.0, 0.0, 0.0), 0.0);
    let at_end = Sphere::new(vec3(2.0, 0.0, 0.0), 1.0);
    assert_eq!(sweep_sphere(&sw, &at_end), Some(1.0));
    let beyond = Sphere::new(vec3(2.0, 0.0, 0.0), exact::f32_down(1.0));
    assert_eq!(sweep_sphere(&sw, &beyond), None);
    let (t0, t1) = sweep_aabb(&sw, &at_end.aabb()).expect("touching box");
    assert!(t0 <= 1.0 && t1 == 1.0, "{t0} {t1}");
}

/// A radius-0 sweep is the segment query whenever `to - from` is an `f32`:
/// the same hits with bit-identical times, and the same box intervals.
#[test]
fn radius_zero_sweep_is_the_segment_query() {
    let mut rng = Pcg64::seed_from_u64(23);
    let mut hits = 0;
    for k in 0..100_000 {
        let mut g = || rng.gen_range(-64i32..=64) as f32 * [1.0, 0.25, 1024.0][k % 3];
        let (from, to) = (vec3(g(), g(), g()), vec3(g(), g(), g()));
        if from == to {
            continue;
        }
        let s = Sphere::new(vec3(g(), g(), g()), g().abs());
        let sw = SphereSweep::new(from, to, 0.0);
        let seg = Segment::new(from, to).to_ray();
        assert_eq!(sweep_sphere(&sw, &s), ray_sphere(&seg, &s), "{sw:?} {s:?}");
        let b = Aabb::new(vec3(g(), g(), g()), vec3(g(), g(), g()));
        let b = Aabb::new(b.min.min(b.max), b.min.max(b.max));
        assert_eq!(sweep_aabb(&sw, &b), ray_aabb(&seg, &b), "{sw:?} {b:?}");
        hits += sweep_sphere(&sw, &s).is_some() as u32;
    }
    assert!(hits > 5_000, "{hits}");
}

/// The times are accurate: for hits that do not start inside, the true first
/// contact (solved in `f64` where well-conditioned) is within 1e-5.
#[test]
fn sweep_times_are_accurate() {
    let mut rng = Pcg64::seed_from_u64(24);
    let mut checked = 0;
    for _ in 0..50_000 {
        let mut u = || rng.gen_range(-50.0f32..50.0);
        let sw = SphereSweep::new(vec3(u(), u(), u()), vec3(u(), u(), u()), u().abs() * 0.1);
        let s = Sphere::new(vec3(u(), u(), u()), u().abs() * 0.3);
        let Some(t) = sweep_sphere(&sw, &s) else {
            continue;
        };
        let (f, e, c) = (ex(sw.from), ex(sw.to), ex(s.center));
        let d = [0, 1, 2].map(|i| e[i] - f[i]);
        let m = [0, 1, 2].map(|i| f[i] - c[i]);
        let rho = s.radius as f64 + sw.radius as f64;
        let (a, b, cc) = (dot(d, d), dot(m, d), dot(m, m) - rho * rho);
        if cc <= 0.0 {
            assert_eq!(t, 0.0);
            continue;
        }
        let disc = b * b - a * cc;
        // Well-conditioned roots only (not grazing).
        if disc < 1e-3 * b * b {
            continue;
        }
        let want = (-b - disc.sqrt()) / a;
        assert!((t as f64 - want).abs() < 1e-5, "{t} {want} {sw:?} {s:?}");
        checked += 1;
    }
    assert!(checked > 1000, "{checked}");
}

/// Sign of `|a - c| - r - m`, from expansions written here (the reference for
/// the rounding of `point_sphere_distance`).
fn cmp_exact(p: Vec3, s: &Sphere, m: f64) -> Ordering {
    let rm = Exp::diff(s.radius as f64, -m);
    if rm.sign() == Ordering::Less {
        return Ordering::Greater;
    }
    let d = ediff(p, s.center);
    edot(&d, &d).sub(&rm.mul(&rm)).sign()
}

/// `y` is the correctly rounded `max(0, |c - p| - r)` (ties to even), checked
/// with exact comparisons against the midpoints around `y`.
fn assert_correctly_rounded(p: Vec3, s: &Sphere, y: f32) {
    assert!(y >= 0.0, "{p} {s:?} -> {y}");
    let even = y.to_bits() & 1 == 0;
    let yd = y as f64;
    if y > 0.0 {
        let lo = (yd + exact::f32_down(y) as f64) * 0.5;
        let c = cmp_exact(p, s, lo);
        assert!(
            c == Ordering::Greater || (c == Ordering::Equal && even),
            "{p} {s:?} -> {y}: below its interval"
        );
    }
    if y.is_finite() {
        let next = if y == f32::MAX {
            2f64.powi(128)
        } else {
            -exact::f32_down(-y) as f64
        };
        let hi = (yd + next) * 0.5;
        let c = cmp_exact(p, s, hi);
        assert!(
            c == Ordering::Less || (c == Ordering::Equal && even),
            "{p} {s:?} -> {y}: above its interval"
        );
    }
}

/// Correct rounding on coarse grids at every magnitude (exact ties and
/// distances on rounding boundaries are common there) and on random floats.
#[test]
fn point_sphere_distance_is_correctly_rounded() {
    let mut rng = Pcg64::seed_from_u64(25);
    let mut zeros = 0;
    for k in 0..200_000 {
        let (p, s) = if k % 2 == 0 {
            (
                cv(&mut rng),
                Sphere::new(cv(&mut rng), coarse(&mut rng).abs()),
            )
        } else {
            let scale = 10f32.powi(rng.gen_range(-30..30));
            let mut u = || rng.gen_range(-1.0f32..1.0) * scale;
            (
                vec3(u(), u(), u()),
                Sphere::new(vec3(u(), u(), u()), u().abs()),
            )
        };
        let y = point_sphere_distance(p, &s);
        assert_correctly_rounded(p, &s, y);
        zeros += (y == 0.0) as u32;
        // The centre distance is the same function with radius 0.
        let yc = point_sphere_distance(p, &Sphere::new(s.center, 0.0));
        assert_correctly_rounded(p, &Sphere::new(s.center, 0.0), yc);
        assert!(yc >= y, "centre distance below surface distance");
    }
    assert!(zeros > 10_000, "{zeros}");
}

/// The k-nearest pruning test never rejects a candidate whose correctly
/// rounded distance is at most the bound: at the distance itself, one `f32`
/// either side of it, exact rounding ties (which round down to an even
/// bound), `-0.0`, `f32::MAX` and `∞`; and it does reject clearly farther ones
/// (a test that cannot fail would pass with `false` everywhere).
#[test]
fn distance_exceeds_never_rejects_what_rounds_within() {
    let mut rng = Pcg64::seed_from_u64(27);
    let mut rejected = 0;
    let up = |y: f32| {
        if y == f32::INFINITY {
            y
        } else {
            f32::from_bits(y.to_bits() + 1)
        }
    };
    for k in 0..200_000 {
        let (p, c, r) = if k % 2 == 0 {
            (cv(&mut rng), cv(&mut rng), coarse(&mut rng).abs())
        } else {
            let scale = 10f32.powi(rng.gen_range(-30..30));
            let mut u = || rng.gen_range(-1.0f32..1.0) * scale;
            (vec3(u(), u(), u()), vec3(u(), u(), u()), u().abs())
        };
        let s2 = point_point_distance_sq(p, c);
        for r in [r, 0.0] {
            let y = point_sphere_distance(p, &Sphere::new(c, r));
            let down = if y > 0.0 { exact::f32_down(y) } else { 0.0 };
            for d in [y, up(y), down, y * 0.5, 0.0, -0.0, f32::MAX, f32::INFINITY] {
                let out = distance_exceeds(s2, r, d);
                assert!(!out || y > d, "{p} {c} r {r}: {y} rejected at bound {d}");
                rejected += out as u32;
            }
        }
        // The box form: the distance to the box's closest point.
        let b = Aabb::new(c.min(p * 0.5), c.max(p * 0.5));
        let q = vec3(p.x, -p.y, c.z);
        let yb = point_aabb_distance(q, &b);
        for d in [yb, up(yb), 0.0] {
            let out = distance_exceeds(point_aabb_distance_sq(q, &b), 0.0, d);
            assert!(!out || yb > d, "{q} {b:?}: {yb} rejected at bound {d}");
        }
    }
    assert!(rejected > 100_000, "{rejected}");
    // |p - c| - r = 1 + 2^-24 exactly, which rounds (to even) to 1: kept at 1.
    let (p, c, r) = (
        vec3(1.0 + 2f32.powi(-23), 0.0, 0.0),
        Vec3::ZERO,
        2f32.powi(-24),
    );
    assert_eq!(point_sphere_distance(p, &Sphere::new(c, r)), 1.0);
    assert!(!distance_exceeds(point_point_distance_sq(p, c), r, 1.0));
    // Far apart near f32::MAX: the squares do not overflow in f64.
    let (p, c) = (Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
    assert!(!distance_exceeds(
        point_point_distance_sq(p, c),
        0.0,
        f32::INFINITY
    ));
    assert!(distance_exceeds(point_point_distance_sq(p, c), 0.0, 1e38));
}

/// Distances exactly on a rounding boundary round to even; Pythagorean
/// distances are exact; huge ones round to `f32::MAX` or `∞` as IEEE does.
#[test]
fn distance_ties_and_extremes() {
    // |p - c| - r = 1 + 2^-24: the midpoint of 1 and 1 + 2^-23 -> 1 (even).
    let s = Sphere::new(Vec3::ZERO, 2f32.powi(-24));
    let p = vec3(1.0 + 2f32.powi(-23), 0.0, 0.0);
    assert_eq!(point_sphere_distance(p, &s), 1.0);
    // 1 + 3·2^-24, the midpoint of 1 + 2^-23 (odd) and 1 + 2^-22 -> the latter.
    let p = vec3(1.0 + 2f32.powi(-22), 0.0, 0.0);
    let s = Sphere::new(Vec3::ZERO, 2f32.powi(-24));
    assert_eq!(point_sphere_distance(p, &s), 1.0 + 2f32.powi(-22));
    // 3-4-5, 12 away, minus radius 2.
    let s = Sphere::new(vec3(1.0, 2.0, 3.0), 2.0);
    assert_eq!(point_sphere_distance(vec3(4.0, 6.0, 15.0), &s), 11.0);
    assert_eq!(point_sphere_distance(vec3(1.0, 2.0, 4.0), &s), 0.0);
    assert_eq!(point_sphere_distance(vec3(1.0, 2.0, 5.0), &s), 0.0);
    // Beyond f32::MAX: ∞ (2√3·MAX); just below the overflow threshold: MAX.
    let far = Sphere::new(Vec3::splat(-f32::MAX), 0.0);
    assert_eq!(
        point_sphere_distance(Vec3::splat(f32::MAX), &far),
        f32::INFINITY
    );
    let s = Sphere::new(vec3(-f32::MAX, 0.0, 0.0), 0.0);
    assert_eq!(point_sphere_distance(Vec3::ZERO, &s), f32::MAX);
    // A huge sphere whose surface passes 1 unit from the point.
    let s = Sphere::new(vec3(1e30, 0.0, 0.0), 1e30);
    let p = vec3(-1.0, 0.0, 0.0);
    assert_eq!(point_sphere_distance(p, &s), 1.0);
    // Subnormal distances.
    let tiny = f32::from_bits(3);
    assert_eq!(
        point_sphere_distance(vec3(tiny, 0.0, 0.0), &Sphere::new(Vec3::ZERO, 0.0)),
        tiny
    );
}

/// `point_aabb_distance` bounds every sphere inside the box from below, for
/// both metrics, and is 0 inside.
#[test]
fn box_distance_bounds_the_spheres_inside() {
    let mut rng = Pcg64::seed_from_u64(26);
    for _ in 0..100_000 {
        let s = Sphere::new(cv(&mut rng), coarse(&mut rng).abs());
        let p = cv(&mut rng);
        let b = outward_box(&s);
        let mut grow = || [0.0, 1.0, 1e10][rng.gen_range(0..3)];
        let bx = Aabb::new(
            b.min - vec3(grow(), grow(), grow()),
            b.max + vec3(grow(), grow(), grow()),
        );
        let lb = point_aabb_distance(p, &bx);
        assert!(lb <= point_sphere_distance(p, &s), "{p} {s:?} {bx:?}");
        assert!(lb <= point_sphere_distance(p, &Sphere::new(s.center, 0.0)));
        if bx.contains_point(p) {
            assert_eq!(lb, 0.0);
        }
    }
}

/// The `f32` pre-test of `sweep_sphere` never answers "miss" for a sweep the
/// exact test (independent, above) says touches: near-tangent grazes of the
/// side, of the start cap and of the end cap, at magnitudes from subnormal
/// to 1e30 (centres far from the origin, long and short sweeps, tiny and
/// zero radii, and mixed ones). It must also do its work: it rejects most
/// clear misses of moderate inputs. Its four-lane form
/// (`SweepTest::misses4`) answers each lane as it does.
#[test]
fn sweep_miss_pretest_is_conservative() {
    let mut rng = Pcg64::seed_from_u64(23);
    let (mut touched, mut rejected, mut clear, mut clear_rejected) = (0u32, 0u32, 0u32, 0u32);
    let mut compared = 0u32;
    for k in 0..300_000 {
        let mut u = || rng.gen_range(-1.0f32..1.0);
        let (scale, offset, rscale) = match k % 6 {
            0 => (1.0f32, 0.0f32, 1.0f32),
            1 => (1e-3, 1e6, 1e-3),
            2 => (1e20, 1e30, 1e20),
            3 => (1.0, 0.0, 1e-30),
            4 => (1e-38, 0.0, 1e-40),
            _ => (1e4, 1e8, 1e-6),
        };
        let base = vec3(u(), u(), u()) * offset;
        let c = base + vec3(u(), u(), u()) * scale;
        let dir = vec3(u(), u(), u()).normalize_or(Vec3::X);
        let side = dir.any_orthonormal_vector();
        let (r, rr) = match k % 5 {
            0 => (0.0, u().abs() * rscale),
            1 => (u().abs() * rscale, 0.0),
            _ => (u().abs() * rscale, u().abs() * rscale),
        };
        let rho = r + rr;
        let len = scale * [1e-6f32, 0.3, 1.0, 30.0][rng.gen_range(0..4)];
        let mut u = || rng.gen_range(-1.0f32..1.0);
        // Which part of the capsule the centre grazes: its side, the start
        // cap or the end cap; at a distance rho (1 + e), |e| from 1e-7 (where
        // only the exact test decides) to 1e-2 (where the pre-test does).
        let off = rho * (1.0 + u() * [1e-7f32, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2][k % 7 % 6]);
        let (from, to) = match k % 3 {
            0 => {
                let mid = c + side * off;
                (mid - dir * len * 0.5, mid + dir * len * 0.5)
            }
            1 => {
                let from = c + (dir * u().abs() - side * u()).normalize_or(dir) * off;
                (from, from + dir * len)
            }
            _ => {
                let to = c - (dir * u().abs() + side * u()).normalize_or(dir) * off;
                (to - dir * len, to)
            }
        };
        let sw = SphereSweep::new(from, to, rr);
        let s = Sphere::new(c, r);
        if !(sw.validate().is_ok() && s.validate().is_ok()) {
            continue;
        }
        let miss = sweep_sphere_misses(&sw, &s);
        if sweep_touches_exact(&sw, &s) {
            touched += 1;
            assert!(!miss, "pre-test rejects a touched sphere: {sw:?} {s:?}");
        }
        rejected += miss as u32;
        // A clear miss (distance about twice the radii) of moderate inputs.
        let far = SphereSweep::new(from + side * (2.0 * rho), to + side * (2.0 * rho), rr);
        // The four-lane pre-test answers each lane as the scalar one does:
        // this sphere and three moved off the capsule by 0.5, 2 and 1e3
        // radii (the last with a radius at the magnitude's scale), against
        // both sweeps. One differing lane fails.
        let quad = [
            s,
            Sphere::new(c + side * (0.5 * rho), r),
            Sphere::new(c - side * (2.0 * rho), r),
            Sphere::new(c + dir * (1e3 * rho), rscale * u().abs()),
        ];
        for sweep in [&sw, &far] {
            let lanes = SweepTest::new(sweep).misses4(quad.each_ref());
            for (j, q) in quad.iter().enumerate() {
                if q.validate().is_ok() && sweep.validate().is_ok() {
                    let scalar = sweep_sphere_misses(sweep, q);
                    assert_eq!(lanes >> j & 1 == 1, scalar, "lane {j}: {sweep:?} {q:?}");
                    compared += 1;
                }
            }
        }
        if k % 6 == 0 && rho > 1e-3 && !sweep_touches_exact(&far, &s) {
            clear += 1;
            clear_rejected += sweep_sphere_misses(&far, &s) as u32;
        }
    }
    // Both sides of the boundary, and misses near it decided by the pre-test.
    assert!(touched > 50_000 && rejected > 3_000, "{touched} {rejected}");
    assert!(compared > 1_000_000, "{compared} lanes compared");
    assert!(
        clear_rejected * 10 > clear * 9,
        "{clear_rejected} of {clear}"
    );
}

/// Exactly: is `c` below (`below`) or above the real number `o + d t`?
fn on_side(c: f64, o: f64, d: f64, t: f64, below: bool) -> bool {
    let v = Exp::of(o).add(&Exp::of(d).mul(&Exp::of(t)));
    let s = v.sub(&Exp::of(c)).sign();
    s == if below {
        Ordering::Greater
    } else {
        Ordering::Less
    } || s == Ordering::Equal
}

/// Exactly: is the ray's parameter interval inside `b` (within `[0, max_t]`)
/// empty? Some entry parameter (or 0) exceeds some exit parameter (or
/// `max_t`), compared as exact fractions `(x - o) / d`; or a zero direction
/// component lies outside its slab.
fn exactly_empty(ray: &Ray, b: &Aabb) -> bool {
    exactly_empty_grown(ray, b, [0.0; 3])
}

/// [`exactly_empty`] for `b` grown by `g[a]` on each side of axis `a`
/// (exactly: the grown sides are expansions).
#[allow(clippy::needless_range_loop)] // indexes the ray, the box and `g` by axis
fn exactly_empty_grown(ray: &Ray, b: &Aabb, g: [f64; 3]) -> bool {
    // (numerator, denominator) of each finite entry and exit parameter.
    let mut enter = vec![(Exp::of(0.0), 1.0f64)];
    let mut exit = Vec::new();
    let mut inf_entry = false;
    if ray.max_t.is_finite() {
        exit.push((Exp::of(ray.max_t as f64), 1.0f64));
    }
    for a in 0..3 {
        let (o, d) = (ray.origin[a] as f64, ray.dir[a] as f64);
        let (lo, hi) = (b.min[a] as f64, b.max[a] as f64);
        let (glo, ghi) = (
            Exp::of(lo).sub(&Exp::of(g[a])),
            Exp::of(hi).add(&Exp::of(g[a])),
        );
        if d == 0.0 {
            let below = lo.is_finite() && glo.sub(&Exp::of(o)).sign() == Ordering::Greater;
            let above = hi.is_finite() && Exp::of(o).sub(&ghi).sign() == Ordering::Greater;
            if below || above || lo == f64::INFINITY || hi == f64::NEG_INFINITY {
                return true;
            }
            continue;
        }
        let (near, far, gnear, gfar) = if d > 0.0 {
            (lo, hi, glo, ghi)
        } else {
            (hi, lo, ghi, glo)
        };
        if near.is_finite() {
            enter.push((gnear.sub(&Exp::of(o)), d));
        } else if (near - o) / d == f64::INFINITY {
            inf_entry = true; // a side at ∓∞ entered only at t = ∞
        }
        if far.is_finite() {
            exit.push((gfar.sub(&Exp::of(o)), d));
        }
    }
    // n1 / d1 > n2 / d2  <=>  (n1 d2 - n2 d1) has the sign of d1 d2.
    (inf_entry && !exit.is_empty())
        || enter.iter().any(|(n1, d1)| {
            exit.iter().any(|(n2, d2)| {
                let v = n1.mul(&Exp::of(*d2)).sub(&n2.mul(&Exp::of(*d1)));
                let want = if d1 * d2 > 0.0 {
                    Ordering::Greater
                } else {
                    Ordering::Less
                };
                v.sign() == want
            })
        })
}

/// `RayClip` (the grids' path clip) is conservative against exact
/// arithmetic on adversarial rays and boxes: coarse coordinates with exact
/// ties, magnitudes from 1e-20 to 1e30, zero direction components, boxes
/// with infinite or degenerate sides and boxes the ray only grazes. It
/// fails only when the exact interval is empty (`ray_aabb` says so, or
/// expansions do where `ray_aabb` rounds a tiny exit up to -0); its `t0`
/// rounded down is at most `ray_aabb`'s floor of the exact entry and its
/// `t1` at least the exact exit (checked with expansions), and its
/// coordinate range holds the exact coordinates at both ends.
#[test]
fn ray_clip_contains_the_exact_interval() {
    let mut rng = Pcg64::seed_from_u64(41);
    let (mut met, mut grazed) = (0, 0);
    for k in 0..200_000 {
        let o = cv(&mut rng);
        let mut d = cv(&mut rng);
        if k % 4 == 0 {
            d[rng.gen_range(0..3)] = 0.0;
        }
        if d == Vec3::ZERO {
            d = Vec3::X;
        }
        let max_t = [f32::INFINITY, 1.0, coarse(&mut rng).abs()][k % 3];
        let ray = Ray::with_max_t(o, d, max_t);
        let b = entry_box(&mut rng, o, d, k);
        let (lo, hi) = (b.min, b.max);
        let exact = ray_aabb(&ray, &b);
        let clip = RayClip::new(&ray);
        let Some((c0, c1)) = clip.clip(&b) else {
            // `ray_aabb` rounds outward, so it may meet a box the ray misses
            // by less than an `f32` step of the parameter: decide exactly.
            assert!(
                exact.is_none() || exactly_empty(&ray, &b),
                "{ray:?} {b:?}: clip misses, ray_aabb {exact:?}"
            );
            continue;
        };
        let Some((t0, t1)) = exact else { continue };
        met += 1;
        grazed += (t0 == t1) as u32;
        assert!(
            exact::round_down_f32(c0) <= t0,
            "{ray:?} {b:?}: {c0} > {t0}"
        );
        // The exact exit is min(max_t, exits): c1 is at or past one of them.
        let mut past_exit = c1 >= max_t as f64 || !c1.is_finite();
        // The exact entry is max(0, entries): c0 is at or before one of them.
        let mut before_entry = c0 <= 0.0;
        for a in 0..3 {
            let (o, d) = (o[a] as f64, d[a] as f64);
            if d == 0.0 {
                continue;
            }
            let (near, far) = if d > 0.0 {
                (lo[a], hi[a])
            } else {
                (hi[a], lo[a])
            };
            if near.is_finite() {
                // c0 <= (near - o) / d  <=>  o + d c0 on the near side of `near`.
                before_entry |= on_side(near as f64, o, d, c0, d < 0.0);
            } else if (near as f64 - o) / d == f64::INFINITY {
                before_entry = true; // entered only at t = ∞ (a side at ∓∞)
            }
            if far.is_finite() && c1.is_finite() {
                past_exit |= on_side(far as f64, o, d, c1, d > 0.0);
            }
        }
        assert!(before_entry && past_exit, "{ray:?} {b:?}: [{c0}, {c1}]");
        for a in 0..3 {
            let (plo, phi) = clip.coord_range(a, c0, c1);
            for t in [c0, c1] {
                if t.is_finite() {
                    let (o, d) = (o[a] as f64, d[a] as f64);
                    let ok_lo = plo == f64::NEG_INFINITY || on_side(plo, o, d, t, true);
                    let ok_hi = phi == f64::INFINITY || on_side(phi, o, d, t, false);
                    assert!(
                        ok_lo && ok_hi,
                        "{ray:?} {b:?} axis {a}: [{plo}, {phi}] at {t}"
                    );
                }
            }
        }
    }
    assert!(met > 20_000 && grazed > 500, "{met} {grazed}");
}

/// The selections' exact tests without the parameter agree with the tests
/// that return it, on the adversarial sweeps and rays of the other tests
/// (coarse coordinates with exact ties, every magnitude, grazes at relative
/// distances down to 1e-7) and with the independent exact reference.
#[test]
fn touch_tests_agree_with_first_contact() {
    let mut rng = Pcg64::seed_from_u64(43);
    let mut touched = 0;
    for k in 0..100_000 {
        let c = cv(&mut rng);
        let (r, rr) = (coarse(&mut rng).abs(), coarse(&mut rng).abs());
        let from = cv(&mut rng);
        let to = if k % 3 == 0 {
            // Tangent: end on the sphere's surface along an axis.
            let mut t = c;
            t[k % 3] += r + rr;
            t
        } else {
            cv(&mut rng)
        };
        let sw = SphereSweep::new(from, to, rr);
        let s = Sphere::new(c, r);
        if sw.validate().is_err() || s.validate().is_err() {
            continue;
        }
        let t = sweep_touches_sphere(&sw, &s);
        assert_eq!(t, sweep_sphere(&sw, &s).is_some(), "{sw:?} {s:?}");
        assert_eq!(t, sweep_touches_exact(&sw, &s), "{sw:?} {s:?}");
        touched += t as u32;
        let d = to - from;
        if d != Vec3::ZERO && d.is_finite() {
            let ray = Ray::with_max_t(from, d, [1.0, f32::INFINITY][k % 2]);
            assert_eq!(
                ray_touches_sphere(&ray, &s),
                ray_sphere(&ray, &s).is_some(),
                "{ray:?} {s:?}"
            );
        }
    }
    assert!(touched > 10_000, "{touched}");
}

/// `entry_ceiling` bounds `entry_floor` from above on adversarial sweeps and
/// rays (coarse coordinates with exact ties, magnitudes from 1e-20 to 1e30,
/// zero components, starts inside, grazes, overflowing directions), so the
/// skipped clamp of the contact parameter never changes it (and the skip
/// is taken for most hits).
#[test]
fn entry_ceiling_bounds_the_entry_floor() {
    let mut rng = Pcg64::seed_from_u64(47);
    let mut skipped = 0;
    for k in 0..200_000 {
        let c = cv(&mut rng);
        let (r, rr) = (coarse(&mut rng).abs(), coarse(&mut rng).abs());
        let from = cv(&mut rng);
        let mut to = match k % 4 {
            0 => {
                let mut t = c;
                t[k % 3] += r + rr;
                t
            }
            1 => from,
            _ => cv(&mut rng),
        };
        if k % 7 == 0 {
            to[k % 3] = 0.0;
        }
        if k % 1000 == 0 {
            to.x = f32::MAX;
        }
        let (sw, s) = (SphereSweep::new(from, to, rr), Sphere::new(c, r));
        if sw.validate().is_err() || s.validate().is_err() {
            continue;
        }
        let l = SweepBall { sweep: &sw, s: &s };
        let (ceil, floor) = (l.entry_ceiling(), l.entry_floor());
        assert!(ceil >= floor as f64, "{sw:?} {s:?}: {ceil} < {floor}");
        if let Some(t) = sweep_sphere(&sw, &s) {
            skipped += (t as f64 >= ceil) as u32;
        }
        let d = to - from;
        if d != Vec3::ZERO && d.is_finite() {
            let ray = Ray::with_max_t(from, d, [1.0, f32::INFINITY][k % 2]);
            let l = RayBall { ray: &ray, s: &s };
            let (ceil, floor) = (l.entry_ceiling(), l.entry_floor());
            assert!(ceil >= floor as f64, "{ray:?} {s:?}: {ceil} < {floor}");
        }
    }
    assert!(skipped > 10_000, "{skipped}");
}

/// A random box for the entry-bound test: coarse corners (ties and every
/// magnitude), sometimes infinite or degenerate sides, sometimes with a
/// corner on the cast's line at a random parameter (a graze).
fn entry_box(rng: &mut Pcg64, o: Vec3, d: Vec3, k: usize) -> Aabb {
    let (mut lo, mut hi) = (cv(rng), cv(rng));
    for a in 0..3 {
        if lo[a] > hi[a] {
            std::mem::swap(&mut lo[a], &mut hi[a]);
        }
        match rng.gen_range(0..8) {
            0 => lo[a] = f32::NEG_INFINITY,
            1 => hi[a] = f32::INFINITY,
            2 => hi[a] = lo[a],
            _ => {}
        }
    }
    if k.is_multiple_of(5) {
        let p = o + d * coarse(rng).abs();
        (lo, hi) = (p, p + cv(rng).abs());
    }
    Aabb::new(lo, hi)
}

/// `EntryBound` (the trees' first-hit pruning) is below the exact tests'
/// entry and fails only where they do, on adversarial rays, sweeps and
/// boxes (coarse coordinates with exact ties, magnitudes from 1e-20 to
/// 1e30, zero direction components, infinite and degenerate sides, grazes,
/// zero-length and overflowing sweeps): where `ray_aabb` / `sweep_aabb`
/// give `t0`, the bound (for a sweep, with the box's magnitude) is at most
/// `t0`; where the bound is `None` (with or without the magnitude), they
/// are `None` or the exact interval of the box grown exactly by the
/// sweep's growth is empty. And it
/// is not merely `0`: on ordinary inputs (one case in ten: uniform
/// coordinates in ±100) it is within 1e-5 of `t0`.
#[test]
fn entry_bound_is_below_the_exact_entry() {
    let mut rng = Pcg64::seed_from_u64(53);
    let (mut met, mut close) = (0u32, 0u32);
    let uniform = |rng: &mut Pcg64| Vec3::from(rng.gen::<[f32; 3]>().map(|x| 200.0 * x - 100.0));
    for k in 0..200_000 {
        let ordinary = k % 10 == 9;
        let o = if ordinary {
            uniform(&mut rng)
        } else {
            cv(&mut rng)
        };
        let mut d = if ordinary {
            uniform(&mut rng)
        } else {
            cv(&mut rng)
        };
        if k % 4 == 0 {
            d[rng.gen_range(0..3)] = 0.0;
        }
        let sweep = k % 2 == 1;
        let b = if ordinary {
            let (p, q) = (uniform(&mut rng), uniform(&mut rng));
            Aabb::new(p.min(q), p.max(q))
        } else {
            entry_box(&mut rng, o, d, k)
        };
        let (bound, exact, grown_ray) = if sweep {
            let to = if k % 11 == 1 { o } else { o + d };
            let r = if ordinary {
                rng.gen_range(0.0..4.0)
            } else {
                coarse(&mut rng).abs()
            };
            let sw = SphereSweep::new(o, to, r);
            if sw.validate().is_err() {
                continue;
            }
            // The ray and box `sweep_aabb` clips exactly.
            let grown = sweep_ray(&sw).map(|(ray, g)| {
                let lo = [0, 1, 2].map(|i| sum_floor(b.min[i], -g[i]));
                let hi = [0, 1, 2].map(|i| -sum_floor(-b.max[i], -g[i]));
                (ray, Aabb::new(Vec3::from(lo), Vec3::from(hi)), g)
            });
            // The box's own magnitude (finite coordinates; the sides at ±∞
            // stay there when grown).
            let m = [b.min, b.max]
                .iter()
                .flat_map(|v| v.to_array())
                .filter(|x| x.is_finite())
                .fold(0.0f32, |m, x| m.max(x.abs()));
            // With no magnitude (the selection walks' touch test) the bound
            // fails only where the exactly grown box is empty.
            if let (None, Some(_), Some((ray, _, g))) = (
                EntryBound::sweep(&sw, 0.0).enter(&b),
                sweep_aabb(&sw, &b),
                grown,
            ) {
                assert!(
                    exactly_empty_grown(&ray, &b, g),
                    "k={k} {o} {d} {b:?}: touch bound misses"
                );
            }
            (
                EntryBound::sweep(&sw, m).enter(&b),
                sweep_aabb(&sw, &b),
                grown,
            )
        } else {
            if d == Vec3::ZERO {
                d = Vec3::X;
            }
            let max_t = [f32::INFINITY, 1.0, coarse(&mut rng).abs()][k % 3];
            let ray = Ray::with_max_t(o, d, max_t);
            (
                EntryBound::ray(&ray).enter(&b),
                ray_aabb(&ray, &b),
                Some((ray, b, [0.0; 3])),
            )
        };
        match (bound, exact) {
            (Some(t), Some((t0, _))) => {
                // A sweep's bound may exceed `sweep_aabb`'s `t0` by what its
                // outward `f32` rounding of the grown box adds; it must not
                // exceed the exact entry into the box grown exactly (which
                // every touched sphere inside `b` is touched after).
                assert!(t <= t0, "k={k} {o} {d} {b:?}: bound {t} > {t0}");
                met += 1;
                if ordinary && (t0 - t).abs() <= 1e-5 * (1.0 + t0.abs()) {
                    close += 1;
                }
            }
            (None, Some(_)) => {
                let (ray, _, g) = grown_ray.expect("a sweep that prunes has a ray");
                assert!(
                    exactly_empty_grown(&ray, &b, g),
                    "k={k} {o} {d} {b:?}: bound misses, exact {exact:?}"
                );
            }
            _ => {}
        }
    }
    assert!(met > 20_000 && close > 1_000, "{met} {close}");
}

/// `EntryBound::enter_octants` (the octree's children step) equals
/// `EntryBound::enter` on each of its 8 boxes, bit for bit, for rays and
/// sweeps (with and without a magnitude) on adversarial inputs: coarse
/// coordinates with exact ties, zero direction components, infinite,
/// degenerate and inverted halves, zero-length sweeps.
#[test]
fn entry_octants_equal_entry_per_box() {
    let mut rng = Pcg64::seed_from_u64(67);
    let mut some = 0u32;
    for k in 0..50_000 {
        let o = cv(&mut rng);
        let mut d = cv(&mut rng);
        if k % 4 == 0 {
            d[rng.gen_range(0..3)] = 0.0;
        }
        let entry = if k % 2 == 0 {
            if d == Vec3::ZERO {
                d = Vec3::Y;
            }
            let max_t = [f32::INFINITY, 1.0, coarse(&mut rng).abs()][k % 3];
            EntryBound::ray(&Ray::with_max_t(o, d, max_t))
        } else {
            let to = if k % 7 == 1 { o } else { o + d };
            let sw = SphereSweep::new(o, to, coarse(&mut rng).abs());
            if sw.validate().is_err() {
                continue;
            }
            EntryBound::sweep(&sw, [0.0, coarse(&mut rng).abs()][k % 3 / 2])
        };
        // Two boxes from the adversarial generator lend each axis its halves.
        let (b0, b1) = (
            entry_box(&mut rng, o, d, k),
            entry_box(&mut rng, o, d, k + 1),
        );
        let mut halves = [0, 1, 2].map(|a| [(b0.min[a], b0.max[a]), (b1.min[a], b1.max[a])]);
        // Sides the boxes never have, which the clip must treat alike: a
        // NaN side (ignored) and `-0.0` for every zero side.
        let side = |rng: &mut Pcg64| (rng.gen_range(0..3), rng.gen_range(0..2));
        if k % 11 == 3 {
            let (a, h) = side(&mut rng);
            halves[a][h].1 = f32::NAN;
        }
        if k % 11 == 7 {
            let (a, h) = side(&mut rng);
            halves[a][h].0 = f32::NAN;
        }
        if k % 3 == 1 {
            for (l, h) in halves.iter_mut().flatten() {
                if *l == 0.0 {
                    *l = -0.0;
                }
                if *h == 0.0 {
                    *h = -0.0;
                }
            }
        }
        let got = entry.enter_octants(halves);
        for (i, g) in got.iter().enumerate() {
            // A zero entry is `+0.0` whatever order the slabs were folded in.
            assert!(g.is_sign_positive(), "case {k}: box {i} entered at {g}");
            let pick = |a: usize| halves[a][(i >> a) & 1];
            let (x, y, z) = (pick(0), pick(1), pick(2));
            let b = Aabb::new(Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1));
            let want = entry.enter(&b);
            // `+∞` for `None` and for an entry at `+∞`.
            let want = want.filter(|&t| t < f32::INFINITY);
            // The unrounded entry the octree prunes on is the clip's own,
            // bit for bit (so at most the exact entry), and its floor is
            // `enter`'s.
            let unrounded = match &entry.clip {
                Some(c) => c.clip(&b).map(|(t0, _)| t0),
                None => Some(0.0),
            }
            .filter(|&t| t < f64::INFINITY);
            assert_eq!(
                (*g < f64::INFINITY).then(|| g.to_bits()),
                unrounded.map(f64::to_bits),
                "k={k} octant {i} {b:?}"
            );
            let g = (*g < f64::INFINITY).then(|| round_down(*g));
            assert_eq!(
                g.map(f32::to_bits),
                want.map(f32::to_bits),
                "k={k} octant {i} {b:?}"
            );
            some += want.is_some() as u32;
        }
    }
    assert!(some > 20_000, "too few entered boxes: {some}");
}

/// `EntryBound::reach_octants` (the octree leaf's octant filter for first
/// hits) keeps every box of `halves` that the cast touches up to parameter
/// `t`, by the exact tests (`ray_aabb` with `max_t` lowered to `t`;
/// `sweep_aabb` of the sweep cut at `t`), for rays and sweeps (with and
/// without a magnitude), `t` from 0 to past the end and ∞. Coordinates
/// are small multiples of 1 and 1/64, so that the cut sweep's end point and
/// the boxes grown by the radius are exact in `f32` and the oracle rounds
/// nothing (not `coarse`'s magnitudes: there `ray_aabb` rounds its
/// parameters to `f32`, and says "touched" of a box entered an ulp past
/// `max_t`, which the exact clip and this filter rightly drop); the halves
/// may be infinite, degenerate or inverted. It must also drop boxes, some of them
/// reached by the whole cast but not by `t` (a filter that keeps all 8, or
/// ignores `t`, passes the first part).
#[test]
fn reach_octants_keep_every_box_touched_by_t() {
    let nice =
        |rng: &mut Pcg64| rng.gen_range(-8i32..=8) as f32 * [1.0, 1.0 / 64.0][rng.gen_range(0..2)];
    let nv = |rng: &mut Pcg64| vec3(nice(rng), nice(rng), nice(rng));
    let mut rng = Pcg64::seed_from_u64(71);
    let (mut touched, mut dropped, mut late) = (0u32, 0u32, 0u32);
    for k in 0..60_000usize {
        let o = nv(&mut rng);
        let mut d = nv(&mut rng);
        if k % 4 == 0 {
            d[rng.gen_range(0..3)] = 0.0;
        }
        if d == Vec3::ZERO {
            d = Vec3::Y;
        }
        let t = [0.0f32, 0.25, 0.5, 1.0, 3.0, f32::INFINITY][k % 6];
        let mut halves = [[(0.0f32, 0.0f32); 2]; 3];
        for h in halves.iter_mut().flatten() {
            let (a, b) = (nice(&mut rng) * 4.0, nice(&mut rng) * 4.0);
            *h = match rng.gen_range(0..10) {
                0 => (f32::NEG_INFINITY, b),
                1 => (a, f32::INFINITY),
                2 => (a, a),
                3 => (a.max(b), a.min(b)),
                _ => (a.min(b), a.max(b)),
            };
        }
        let boxes: [Aabb; 8] = std::array::from_fn(|i| {
            let pick = |a: usize| halves[a][(i >> a) & 1];
            let (x, y, z) = (pick(0), pick(1), pick(2));
            Aabb::new(vec3(x.0, y.0, z.0), vec3(x.1, y.1, z.1))
        });
        // Whether the cast touches each box by `t`, and at all.
        let (entry, hits, ever): (EntryBound, [bool; 8], [bool; 8]) = if k % 2 == 0 {
            let max_t = [f32::INFINITY, 1.0, 0.5][k % 3];
            let ray = Ray::with_max_t(o, d, max_t);
            let cut = Ray::with_max_t(o, d, max_t.min(t));
            (
                EntryBound::ray(&ray),
                boxes.map(|b| ray_aabb(&cut, &b).is_some()),
                boxes.map(|b| ray_aabb(&ray, &b).is_some()),
            )
        } else {
            let radius = nice(&mut rng).abs();
            let sw = SphereSweep::new(o, o + d, radius);
            let cut = SphereSweep::new(o, o + d * t.min(1.0), radius);
            let m = [0.0, 64.0][k % 3 / 2];
            (
                EntryBound::sweep(&sw, m),
                boxes.map(|b| sweep_aabb(&cut, &b).is_some()),
                boxes.map(|b| sweep_aabb(&sw, &b).is_some()),
            )
        };
        let reach = entry.reach_octants(halves, t);
        for (i, (&hit, &all)) in hits.iter().zip(&ever).enumerate() {
            let kept = reach >> i & 1 == 1;
            assert!(
                kept || !hit,
                "k={k} t={t} octant {i} {:?} o={o} d={d}",
                boxes[i]
            );
            touched += hit as u32;
            dropped += !kept as u32;
            // Reached by the whole cast, not by `t`, and dropped: `t` counts.
            late += (all && !kept) as u32;
        }
    }
    assert!(
        touched > 20_000 && dropped > 20_000 && late > 2_000,
        "{touched} touched, {dropped} dropped, {late} dropped for t"
    );
}
