//! The volumes' distance lower bounds: never above the distance of the points
//! they were fitted to (under the pose, with and without the transform paths of
//! the queries), and useful (well above 0 for well separated sets).

use super::common::random_rotation;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{BoundingVolume, Kdop14, Kdop18, Kdop26, Obb};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn cloud(rng: &mut Pcg64, n: usize) -> Vec<Vec3> {
    // An anisotropic, rotated, offset cloud (so OBBs are not boxes).
    let rot = random_rotation(rng);
    let stretch = Vec3::new(
        rng.gen_range(0.1..3.0),
        rng.gen_range(0.1..3.0),
        rng.gen_range(0.0..1.0),
    );
    let c = Vec3::new(
        rng.gen_range(-5.0..5.0),
        rng.gen_range(-5.0..5.0),
        rng.gen_range(-5.0..5.0),
    );
    (0..n)
        .map(|_| {
            c + rot
                * (stretch
                    * Vec3::new(
                        rng.gen_range(-1.0..1.0),
                        rng.gen_range(-1.0..1.0),
                        rng.gen_range(-1.0..1.0),
                    ))
        })
        .collect()
}

fn min_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .flat_map(|p| b.iter().map(move |q| p.distance(*q)))
        .fold(f32::INFINITY, f32::min)
}

fn check<BV: BoundingVolume>() {
    let mut rng = Pcg64::seed_from_u64(11);
    let (mut ratio, mut separated) = (0.0f64, 0);
    for case in 0..3000 {
        let (a, b) = (cloud(&mut rng, 12), cloud(&mut rng, 12));
        let mut pose =
            Affine3A::from_rotation_translation(random_rotation(&mut rng), Vec3::splat(1.5));
        if case % 3 == 0 {
            pose.matrix3 = proxima::glam::Mat3A::IDENTITY;
        }
        let moved: Vec<Vec3> = a.iter().map(|&p| pose.transform_point3(p)).collect();
        let truth = min_distance(&moved, &b);
        let (va, vb) = (BV::from_points(&a), BV::from_points(&b));
        // f32 rounding of the points themselves: the bounds carry no slack here.
        let tol = 1e-4;
        let bounds = [
            va.distance_lower_bound(&BV::motion(&pose, 0.0), &vb),
            va.transformed(&pose).distance_lower_bound_fixed(&vb),
            BV::from_points(&moved).distance_lower_bound_fixed(&vb),
        ];
        let exact_pose = !BV::AXIS_ALIGNED || case % 3 == 0;
        for (k, lb) in bounds.into_iter().enumerate() {
            if k == 0 && !exact_pose {
                continue; // axis-aligned motion reads only the translation
            }
            assert!(lb >= 0.0, "{} case {case} bound {k}: {lb}", BV::NAME);
            assert!(
                lb <= truth + tol,
                "{} case {case} bound {k}: {lb} > {truth}",
                BV::NAME
            );
        }
        // The slack lowers the bound (never raises it).
        let slacked = va.distance_lower_bound(&BV::motion(&pose, 0.5), &vb);
        if exact_pose {
            assert!(slacked <= bounds[0], "{}", BV::NAME);
            if bounds[0] > 1.0 {
                assert!(slacked < bounds[0], "{}", BV::NAME);
            }
        }
        // Symmetric in the fixed frame.
        let (x, y) = (
            va.distance_lower_bound_fixed(&vb),
            vb.distance_lower_bound_fixed(&va),
        );
        assert!((x - y).abs() <= 1e-4, "{} {x} {y}", BV::NAME);
        if truth > 2.0 {
            separated += 1;
            ratio += (bounds[2] / truth) as f64;
        }
    }
    let mean = ratio / separated as f64;
    assert!(separated > 200, "{separated}");
    // Spheres are the loosest; every volume bounds well separated sets usefully.
    assert!(mean > 0.4, "{}: mean bound / distance {mean}", BV::NAME);
}

#[test]
fn lower_bounds_are_bounds() {
    check::<Aabb>();
    check::<Kdop14>();
    check::<Kdop18>();
    check::<Kdop26>();
    check::<Obb>();
    check::<Sphere>();
}

#[test]
fn touching_volumes_bound_zero() {
    let a = [Vec3::ZERO, Vec3::ONE];
    let b = [Vec3::ONE, Vec3::splat(2.0)];
    fn zero<BV: BoundingVolume>(a: &[Vec3], b: &[Vec3]) {
        let (x, y) = (BV::from_points(a), BV::from_points(b));
        // Touching at (1, 1, 1): 0 up to the rounding of the fits.
        assert!(x.distance_lower_bound_fixed(&y) <= 1e-6, "{}", BV::NAME);
        let apart = Affine3A::from_translation(Vec3::new(3.0, 0.0, 0.0));
        let lb = x.distance_lower_bound(&BV::motion(&apart, 0.0), &y);
        // The moved points are √6 from b's: a positive bound below that.
        assert!(lb > 0.4 && lb <= 6f32.sqrt() + 1e-5, "{} {lb}", BV::NAME);
    }
    zero::<Aabb>(&a, &b);
    zero::<Kdop14>(&a, &b);
    zero::<Kdop18>(&a, &b);
    zero::<Kdop26>(&a, &b);
    zero::<Obb>(&a, &b);
    zero::<Sphere>(&a, &b);
}

#[test]
fn lower_bounds_hold_at_huge_scales() {
    // Regression: beyond √f32::MAX ≈ 1.8e19 the f32 squares of the bounds
    // overflowed, giving infinite "lower bounds" (cutting every pair of a
    // distance query); and a sphere's fit an infinite radius. Clouds scaled
    // up to 1e37: every bound is finite, at most the true (f64) distance, and
    // still useful.
    fn min_distance64(a: &[Vec3], b: &[Vec3]) -> f64 {
        a.iter()
            .flat_map(|p| b.iter().map(move |q| p.as_dvec3().distance(q.as_dvec3())))
            .fold(f64::INFINITY, f64::min)
    }
    fn check<BV: BoundingVolume>(scale: f32) {
        let mut rng = Pcg64::seed_from_u64(12);
        let (mut ratio, mut separated) = (0.0f64, 0);
        for case in 0..400 {
            let a: Vec<Vec3> = cloud(&mut rng, 12).iter().map(|&p| p * scale).collect();
            let b: Vec<Vec3> = cloud(&mut rng, 12).iter().map(|&p| p * scale).collect();
            let mut pose = Affine3A::from_rotation_translation(
                random_rotation(&mut rng),
                Vec3::splat(1.5 * scale),
            );
            if case % 3 == 0 {
                pose.matrix3 = proxima::glam::Mat3A::IDENTITY;
            }
            let moved: Vec<Vec3> = a.iter().map(|&p| pose.transform_point3(p)).collect();
            let truth = min_distance64(&moved, &b);
            let (va, vb) = (BV::from_points(&a), BV::from_points(&b));
            let bounds = [
                va.distance_lower_bound(&BV::motion(&pose, 0.0), &vb),
                va.transformed(&pose).distance_lower_bound_fixed(&vb),
                BV::from_points(&moved).distance_lower_bound_fixed(&vb),
            ];
            let exact_pose = !BV::AXIS_ALIGNED || case % 3 == 0;
            // f32 rounding of the fits and transforms, relative to the scale.
            let tol = 1e-4 * scale as f64;
            for (k, lb) in bounds.into_iter().enumerate() {
                if k == 0 && !exact_pose {
                    continue;
                }
                let ctx = format!("{} scale {scale} case {case} bound {k}", BV::NAME);
                assert!(lb >= 0.0 && lb.is_finite(), "{ctx}: {lb}");
                assert!(lb as f64 <= truth + tol, "{ctx}: {lb} > {truth}");
            }
            if truth > 2.0 * scale as f64 {
                separated += 1;
                ratio += bounds[2] as f64 / truth;
            }
        }
        assert!(separated > 20, "{separated}");
        let mean = ratio / separated as f64;
        assert!(
            mean > 0.4,
            "{} scale {scale}: mean bound / distance {mean}",
            BV::NAME
        );
    }
    for scale in [1e20f32, 1e30, 1e37] {
        check::<Aabb>(scale);
        check::<Kdop14>(scale);
        check::<Kdop18>(scale);
        check::<Kdop26>(scale);
        check::<Obb>(scale);
        check::<Sphere>(scale);
    }
}
