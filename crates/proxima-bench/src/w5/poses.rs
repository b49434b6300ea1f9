//! W5 poses: FCL's rob-vs-env distribution from a pose file, and generated poses
//! for the other mesh pairs.

use proxima::glam::{Affine3A, Mat3, Quat, Vec3};
use proxima::narrow::TriMesh;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Parses a pose file [sources: pose-format] (the CLI's parser, shared through
/// `proxima_harness::poses`). Errors name the line.
pub use proxima_harness::poses::parse;

fn bounds(m: &TriMesh) -> (Vec3, f32) {
    let (lo, hi) = m.vertices().iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    );
    ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
}

/// A rotation uniform over SO(3) (Shoemake's method).
fn uniform_rotation(rng: &mut Pcg64) -> Mat3 {
    let (u1, u2, u3): (f32, f32, f32) = (rng.gen(), rng.gen(), rng.gen());
    let tau = std::f32::consts::TAU;
    let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = Quat::from_xyzw(
        s1 * (tau * u2).sin(),
        s1 * (tau * u2).cos(),
        s2 * (tau * u3).sin(),
        s2 * (tau * u3).cos(),
    )
    .normalize();
    Mat3::from_quat(q)
}

/// A point uniform in the cube of half-side `h` around `c`.
fn in_cube(rng: &mut Pcg64, c: Vec3, h: f32) -> Vec3 {
    c + Vec3::new(rng.gen(), rng.gen(), rng.gen()) * (2.0 * h) - Vec3::splat(h)
}

/// `n` poses of `a` relative to `b`: rotations uniform over SO(3) (Shoemake),
/// `a`'s centre uniform in a cube around `b`'s centre of half-side
/// `0.6 * (r_a + r_b)` (bounding radii), so that a good share of the poses touch
/// and the rest are near misses. Deterministic in `seed`.
pub fn generate(a: &TriMesh, b: &TriMesh, n: usize, seed: u64) -> Vec<Affine3A> {
    let ((ca, ra), (cb, rb)) = (bounds(a), bounds(b));
    let h = 0.6 * (ra + rb);
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let r = uniform_rotation(&mut rng);
            let c = in_cube(&mut rng, cb, h);
            // Place a's centre at c after rotating it.
            Affine3A::from_mat3_translation(r, c - r * ca)
        })
        .collect()
}

/// `n` poses of `a` "around and into" `b`, for a pair where one mesh is much
/// larger than the other (W5's SKINbody around BONERibcage): `a`'s centre
/// uniform in a cube of half-side `0.4 * max(r_a, r_b)` around `b`'s centre, so
/// that the smaller mesh lies deep inside the larger's bounds on most poses and
/// crosses its surface on many; every other pose keeps `a` near its own
/// orientation (a rotation of at most 0.5 rad about a random axis, as in a
/// scene where the two start nested), the rest rotate uniformly. Deterministic
/// in `seed`.
pub fn generate_nested(a: &TriMesh, b: &TriMesh, n: usize, seed: u64) -> Vec<Affine3A> {
    let ((ca, ra), (cb, rb)) = (bounds(a), bounds(b));
    let h = 0.4 * ra.max(rb);
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|k| {
            let r = if k % 2 == 0 {
                let axis = uniform_rotation(&mut rng) * Vec3::X;
                Mat3::from_axis_angle(axis, 0.5 * rng.gen::<f32>())
            } else {
                uniform_rotation(&mut rng)
            };
            let c = in_cube(&mut rng, cb, h);
            Affine3A::from_mat3_translation(r, c - r * ca)
        })
        .collect()
}
