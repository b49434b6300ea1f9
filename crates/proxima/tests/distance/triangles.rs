//! Triangle–triangle distance against the independent reference, the reference
//! against dense sampling and hand-computed answers.

use super::reference::{point_triangle, samples, segment_segment, triangle_triangle};
use proxima::glam::{DVec3, Vec3};
use proxima::narrow::{closest_point_on_triangle, triangle_distance, triangles_intersect};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// A random triangle near the origin, sometimes degenerate: a point, a segment
/// (repeated or collinear corners) or a sliver.
fn random_triangle(rng: &mut Pcg64, scale: f32) -> [Vec3; 3] {
    let mut p = || {
        v(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ) * scale
    };
    let (a, b, c) = (p(), p(), p());
    match rng.gen_range(0..10) {
        0 => [a, a, a],
        1 => [a, b, b],
        2 => [a, b, a + (b - a) * 0.375],
        3 => [a, b, a + (b - a) * 0.5 + (c - a) * 1e-4],
        _ => [a, b, c],
    }
}

/// Checks one pair against the reference: the distance within `1e-9` of the
/// scene's size, the points on their triangles and at that distance.
fn check(a: &[Vec3; 3], b: &[Vec3; 3]) -> f64 {
    let got = triangle_distance(a, b);
    let want = triangle_triangle(a, b);
    let size = a
        .iter()
        .chain(b)
        .map(|p| p.abs().max_element())
        .fold(1e-30f32, f32::max) as f64;
    let tol = 1e-9 * size;
    assert!(
        (got.distance - want).abs() <= tol,
        "{a:?} {b:?}: {} vs reference {want}",
        got.distance
    );
    assert_eq!(
        got.distance == 0.0,
        triangles_intersect(a, b),
        "{a:?} {b:?}"
    );
    let [p, q] = got.points;
    let (ta, tb) = (a.map(|x| x.as_dvec3()), b.map(|x| x.as_dvec3()));
    assert!(point_triangle(p, ta) <= tol, "{a:?} {b:?}: point off a");
    assert!(point_triangle(q, tb) <= tol, "{a:?} {b:?}: point off b");
    assert!(
        (p.distance(q) - got.distance).abs() <= tol,
        "{a:?} {b:?}: points {} apart, distance {}",
        p.distance(q),
        got.distance
    );
    // Symmetric.
    let back = triangle_distance(b, a);
    assert!((back.distance - got.distance).abs() <= tol);
    got.distance
}

#[test]
fn reference_agrees_with_dense_sampling() {
    let mut rng = Pcg64::seed_from_u64(1);
    let n = 40;
    for case in 0..40 {
        let a = random_triangle(&mut rng, 1.0);
        let mut b = random_triangle(&mut rng, 1.0);
        if case % 2 == 0 {
            // Move b away so most pairs are apart.
            let off = v(rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0), 1.5);
            b = b.map(|p| p + off);
        }
        let (ta, tb) = (a.map(|x| x.as_dvec3()), b.map(|x| x.as_dvec3()));
        let (sa, sb) = (samples(ta, n), samples(tb, n));
        let mut sampled = f64::INFINITY;
        for p in &sa {
            for q in &sb {
                sampled = sampled.min(p.distance(*q));
            }
        }
        let want = triangle_triangle(&a, &b);
        // The true distance is at most the sampled one, and at least it minus
        // the sampling steps (a sample within one step of every point).
        let step = |t: [DVec3; 3]| {
            (0..3)
                .map(|i| t[i].distance(t[(i + 1) % 3]))
                .fold(0.0, f64::max)
                / n as f64
        };
        assert!(want <= sampled + 1e-12, "case {case}: {want} > {sampled}");
        assert!(
            want >= sampled - step(ta) - step(tb) - 1e-12,
            "case {case}: {want} < {sampled}"
        );
        // Point–triangle against sampling too.
        let p = DVec3::new(rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0), 1.0);
        let near = sa
            .iter()
            .map(|s| s.distance(p))
            .fold(f64::INFINITY, f64::min);
        let pt = point_triangle(p, ta);
        assert!(pt <= near + 1e-12 && pt >= near - step(ta) - 1e-12);
    }
}

#[test]
fn reference_on_hand_computed_cases() {
    let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // Skew segments along x at z = 0 and along y at z = 2: distance 2.
    assert_eq!(
        segment_segment(d(-1., 0., 0.), d(1., 0., 0.), d(0., -1., 2.), d(0., 1., 2.)),
        2.0
    );
    // Parallel, offset: 3-4-5.
    assert_eq!(
        segment_segment(d(0., 0., 0.), d(1., 0., 0.), d(5., 3., 0.), d(9., 3., 0.)),
        5.0
    );
    // Point above the interior, beside an edge, beyond a corner.
    let t = [d(0., 0., 0.), d(4., 0., 0.), d(0., 4., 0.)];
    assert_eq!(point_triangle(d(1., 1., 7.), t), 7.0);
    assert_eq!(point_triangle(d(2., -3., 4.), t), 5.0);
    assert_eq!(point_triangle(d(-3., -4., 0.), t), 5.0);
    // Parallel triangles one apart; crossing; sharing a corner.
    let a = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
    assert_eq!(triangle_triangle(&a, &a.map(|p| p + Vec3::Z)), 1.0);
    assert_eq!(triangle_distance(&a, &a.map(|p| p + Vec3::Z)).distance, 1.0);
    let pierce = [v(0.2, 0.2, -1.), v(0.2, 0.2, 1.), v(0.3, 0.25, 1.)];
    assert_eq!(triangle_triangle(&a, &pierce), 0.0);
    let shared = [v(1., 0., 0.), v(3., 0., 1.), v(2., 1., 5.)];
    assert_eq!(triangle_distance(&a, &shared).distance, 0.0);
}

#[test]
fn triangle_distance_matches_the_reference_on_random_pairs() {
    let mut rng = Pcg64::seed_from_u64(2);
    let (mut apart, mut touching) = (0, 0);
    for case in 0..20_000 {
        let scale = [1e-3f32, 1.0, 1e3][case % 3];
        let a = random_triangle(&mut rng, scale);
        let b = match case % 7 {
            // Near a: small random offsets of a's corners.
            0 => a.map(|p| {
                p + v(
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                ) * scale
            }),
            // Parallel: a moved along its normal, shifted in its plane.
            1 => {
                let n = (a[1] - a[0]).cross(a[2] - a[0]).normalize_or(Vec3::Z);
                let s = (a[1] - a[0]) * rng.gen_range(-1.0..1.0);
                a.map(|p| p + n * rng.gen_range(0.0..0.3) * scale + s)
            }
            // Sharing a corner or an edge.
            2 => [a[0], random_triangle(&mut rng, scale)[1], a[1]],
            3 => [
                a[2],
                random_triangle(&mut rng, scale)[0],
                a[2] + v(0.1, 0.2, 0.3) * scale,
            ],
            _ => {
                let off = v(
                    rng.gen_range(-2.0..2.0),
                    rng.gen_range(-2.0..2.0),
                    rng.gen_range(-2.0..2.0),
                ) * scale;
                random_triangle(&mut rng, scale).map(|p| p + off)
            }
        };
        if check(&a, &b) > 0.0 {
            apart += 1;
        } else {
            touching += 1;
        }
    }
    assert!(apart > 10_000 && touching > 2_000, "{apart} {touching}");
}

#[test]
fn touching_and_coplanar_pairs_are_exactly_zero() {
    // Coplanar overlapping, coplanar edge-to-edge, corner on a face, and the same
    // pairs moved one step apart.
    let a = [v(0., 0., 0.), v(2., 0., 0.), v(0., 2., 0.)];
    let cases = [
        [v(0.5, 0.5, 0.), v(3., 0.5, 0.), v(0.5, 3., 0.)],
        [v(2., 0., 0.), v(0., 2., 0.), v(2., 2., 0.)],
        [v(0.5, 0.5, 0.), v(1., 1., 1.), v(0., 1., 2.)],
        [v(1., 1., 0.), v(1., 1., 0.), v(1., 1., 0.)],
        [v(-1., 1., 0.), v(3., 1., 0.), v(3., 1., 0.)],
    ];
    for b in cases {
        assert_eq!(check(&a, &b), 0.0, "{b:?}");
        let up = b.map(|p| p + Vec3::Z * 0.25);
        assert_eq!(check(&a, &up), 0.25, "{b:?}");
    }
    // Parallel faces, offset: 0.5 apart through their overlapping region.
    let b = a.map(|p| p + v(0.3, 0.3, 0.5));
    assert_eq!(check(&a, &b), 0.5);
}

#[test]
fn closest_point_on_triangle_matches_the_reference() {
    let mut rng = Pcg64::seed_from_u64(3);
    for _ in 0..20_000 {
        let t = random_triangle(&mut rng, 1.0);
        let p = v(
            rng.gen_range(-2.0..2.0),
            rng.gen_range(-2.0..2.0),
            rng.gen_range(-2.0..2.0),
        );
        let q = closest_point_on_triangle(p, &t);
        let td = t.map(|x| x.as_dvec3());
        let want = point_triangle(p.as_dvec3(), td);
        assert!((q.distance(p.as_dvec3()) - want).abs() <= 1e-9, "{t:?} {p}");
        assert!(
            point_triangle(q, td) <= 1e-9,
            "{t:?} {p}: point off the triangle"
        );
    }
}
