//! Generated scenes for the default run (and, later, `demo` and `bench`).
//!
//! W1 of design §5: `n` spheres with radii uniform in [0.5, 2] and centres uniform
//! in a cube of side `L = 4 * n^(1/3)`; each frame every sphere takes a small step
//! along its own slowly-wandering velocity and bounces off the walls. Deterministic
//! for a given seed, so every index sees the same frames.

use crate::indices::SceneHint;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Smallest and largest radius of W1.
pub const W1_RADII: (f32, f32) = (0.5, 2.0);
/// Largest distance a centre moves in one frame.
pub const W1_MAX_STEP: f32 = 0.25;
/// Largest random change of a velocity component per frame.
const JITTER: f32 = 0.05;

/// The W1 scene: moving spheres in a cube.
#[derive(Clone, Debug)]
pub struct W1 {
    side: f32,
    spheres: Vec<Sphere>,
    velocity: Vec<Vec3>,
    rng: Pcg64,
}

impl W1 {
    /// `n` spheres at their initial positions. O(n).
    pub fn new(n: usize, seed: u64) -> W1 {
        let mut rng = Pcg64::seed_from_u64(seed);
        let side = 4.0 * (n as f32).cbrt();
        let spheres = (0..n)
            .map(|_| {
                let c = Vec3::new(
                    rng.gen_range(0.0..=side),
                    rng.gen_range(0.0..=side),
                    rng.gen_range(0.0..=side),
                );
                Sphere::new(c, rng.gen_range(W1_RADII.0..=W1_RADII.1))
            })
            .collect();
        let velocity = (0..n)
            .map(|_| random_in_ball(&mut rng) * W1_MAX_STEP)
            .collect();
        W1 {
            side,
            spheres,
            velocity,
            rng,
        }
    }

    /// Side `L` of the cube.
    pub fn side(&self) -> f32 {
        self.side
    }

    /// The cube `[0, L]^3` holding every centre.
    pub fn world(&self) -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::splat(self.side))
    }

    /// The current spheres, object `i` at position `i`.
    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }

    /// What index constructors are told about this scene.
    pub fn hint(&self) -> SceneHint {
        SceneHint {
            world: self.world(),
            r_max: W1_RADII.1,
            r_largest: W1_RADII.1,
            max_live: self.spheres.len(),
        }
    }

    /// Advances one frame: jitter each velocity (keeping its length at most
    /// [`W1_MAX_STEP`]), move, and reflect centres and velocities at the walls.
    pub fn step(&mut self) {
        let side = self.side;
        for (s, v) in self.spheres.iter_mut().zip(&mut self.velocity) {
            let jitter = Vec3::new(
                self.rng.gen_range(-JITTER..=JITTER),
                self.rng.gen_range(-JITTER..=JITTER),
                self.rng.gen_range(-JITTER..=JITTER),
            );
            *v = (*v + jitter).clamp_length_max(W1_MAX_STEP);
            let mut c = s.center + *v;
            for a in 0..3 {
                if c[a] < 0.0 {
                    c[a] = -c[a];
                    v[a] = -v[a];
                } else if c[a] > side {
                    c[a] = 2.0 * side - c[a];
                    v[a] = -v[a];
                }
            }
            s.center = c;
        }
    }
}

/// A point uniform in the unit ball (rejection sampling).
fn random_in_ball(rng: &mut Pcg64) -> Vec3 {
    loop {
        let p = Vec3::new(
            rng.gen_range(-1.0..=1.0),
            rng.gen_range(-1.0..=1.0),
            rng.gen_range(-1.0..=1.0),
        );
        if p.length_squared() <= 1.0 {
            return p;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn w1_stays_in_its_cube_with_its_radii_and_small_steps() {
        let mut w = W1::new(500, 3);
        assert!((w.side() - 4.0 * 500f32.cbrt()).abs() < 1e-4);
        let world = w.world();
        for _ in 0..200 {
            let before: Vec<_> = w.spheres().to_vec();
            w.step();
            for (a, b) in before.iter().zip(w.spheres()) {
                assert!(world.contains_point(b.center));
                assert!(a.center.distance(b.center) <= W1_MAX_STEP + 1e-5);
                assert!((W1_RADII.0..=W1_RADII.1).contains(&b.radius));
            }
        }
    }

    #[test]
    fn w1_is_deterministic() {
        let (mut a, mut b) = (W1::new(100, 9), W1::new(100, 9));
        a.step();
        b.step();
        assert_eq!(a.spheres(), b.spheres());
        assert_ne!(W1::new(100, 10).spheres(), W1::new(100, 9).spheres());
    }
}
