//! Generated scenes for `proxima demo` [sources: w1, w2, w3].
//!
//! `n` spheres with radii uniform in [0.5, 2]; each frame every sphere takes a
//! small step along its own slowly-wandering velocity and bounces off the walls of
//! the world box. Where the centres start depends on the [`SceneKind`]:
//! - `uniform` (W1): uniform in a cube of side `L = 4 * n^(1/3)`;
//! - `flat` (W2): uniform in a 1000 × 1000 × 10 box (the 2D grid's case);
//! - `clustered` (W3): W1's cube, centres drawn from [`CLUSTERS`] Gaussian
//!   clusters of standard deviation `L / 12` (clamped into the cube).
//!
//! Deterministic for a given kind, size and seed, so every index sees the same
//! frames.

use crate::indices::SceneHint;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt;
use std::str::FromStr;

/// Smallest and largest radius of W1–W3.
pub const W1_RADII: (f32, f32) = (0.5, 2.0);
/// Largest distance a centre moves in one frame.
pub const W1_MAX_STEP: f32 = 0.25;
/// Largest random change of a velocity component per frame.
const JITTER: f32 = 0.05;
/// Number of clusters of the `clustered` scene.
pub const CLUSTERS: usize = 8;
/// Size of the `flat` world.
pub const FLAT_WORLD: Vec3 = Vec3::new(1000.0, 1000.0, 10.0);

/// Where the centres of a generated scene lie [sources: workloads].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneKind {
    /// W1: uniform in a cube.
    Uniform,
    /// W2: uniform in a flat 1000 × 1000 × 10 box.
    Flat,
    /// W3: a few tight Gaussian clusters in W1's cube.
    Clustered,
}

impl SceneKind {
    /// Every kind, in the order of [sources: workloads].
    pub const ALL: [SceneKind; 3] = [SceneKind::Uniform, SceneKind::Flat, SceneKind::Clustered];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Uniform => "uniform",
            SceneKind::Flat => "flat",
            SceneKind::Clustered => "clustered",
        }
    }

    /// One line describing the scene, for the demo's header.
    pub fn describe(self, n: usize, world: &Aabb) -> String {
        let e = world.extent();
        match self {
            SceneKind::Uniform => format!(
                "W1 uniform: {n} spheres, radii in [0.5, 2], cube side {:.1}",
                e.x
            ),
            SceneKind::Flat => format!(
                "W2 flat: {n} spheres, radii in [0.5, 2], box {:.0} x {:.0} x {:.0}",
                e.x, e.y, e.z
            ),
            SceneKind::Clustered => format!(
                "W3 clustered: {n} spheres, radii in [0.5, 2], {CLUSTERS} Gaussian clusters \
                 (sd {:.1}) in a cube of side {:.1}",
                e.x / 12.0,
                e.x
            ),
        }
    }
}

impl fmt::Display for SceneKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SceneKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        SceneKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| format!("unknown scene '{s}' (known: uniform, flat, clustered)"))
    }
}

/// A generated scene: moving spheres in a box.
#[derive(Clone, Debug)]
pub struct Scene {
    kind: SceneKind,
    world: Aabb,
    spheres: Vec<Sphere>,
    velocity: Vec<Vec3>,
    rng: Pcg64,
}

impl Scene {
    /// `n` spheres of scene `kind` at their initial positions. O(n).
    pub fn new(kind: SceneKind, n: usize, seed: u64) -> Scene {
        let mut rng = Pcg64::seed_from_u64(seed);
        let side = 4.0 * (n.max(1) as f32).cbrt();
        let world = match kind {
            SceneKind::Flat => Aabb::new(Vec3::ZERO, FLAT_WORLD),
            _ => Aabb::new(Vec3::ZERO, Vec3::splat(side)),
        };
        let size = world.extent();
        let clusters: Vec<Vec3> = (0..CLUSTERS)
            .map(|_| {
                Vec3::new(
                    rng.gen_range(0.2..=0.8),
                    rng.gen_range(0.2..=0.8),
                    rng.gen_range(0.2..=0.8),
                ) * size
            })
            .collect();
        let spheres = (0..n)
            .map(|_| {
                let c = match kind {
                    SceneKind::Clustered => {
                        let k = rng.gen_range(0..CLUSTERS);
                        let g =
                            Vec3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng));
                        (clusters[k] + g * (side / 12.0)).clamp(world.min, world.max)
                    }
                    _ => Vec3::new(
                        rng.gen_range(0.0..=size.x),
                        rng.gen_range(0.0..=size.y),
                        rng.gen_range(0.0..=size.z),
                    ),
                };
                Sphere::new(c, rng.gen_range(W1_RADII.0..=W1_RADII.1))
            })
            .collect();
        let velocity = (0..n)
            .map(|_| random_in_ball(&mut rng) * W1_MAX_STEP)
            .collect();
        Scene {
            kind,
            world,
            spheres,
            velocity,
            rng,
        }
    }

    /// The kind of scene.
    pub fn kind(&self) -> SceneKind {
        self.kind
    }

    /// The box holding every centre.
    pub fn world(&self) -> Aabb {
        self.world
    }

    /// The current spheres, object `i` at position `i`.
    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }

    /// What index constructors are told about this scene.
    pub fn hint(&self) -> SceneHint {
        SceneHint {
            world: self.world,
            r_max: W1_RADII.1,
            r_largest: W1_RADII.1,
            max_live: self.spheres.len(),
        }
    }

    /// Advances one frame: jitter each velocity (keeping its length at most
    /// [`W1_MAX_STEP`]), move, and reflect centres and velocities at the walls.
    pub fn step(&mut self) {
        let (lo, hi) = (self.world.min, self.world.max);
        for (s, v) in self.spheres.iter_mut().zip(&mut self.velocity) {
            let jitter = Vec3::new(
                self.rng.gen_range(-JITTER..=JITTER),
                self.rng.gen_range(-JITTER..=JITTER),
                self.rng.gen_range(-JITTER..=JITTER),
            );
            *v = (*v + jitter).clamp_length_max(W1_MAX_STEP);
            let mut c = s.center + *v;
            for a in 0..3 {
                if c[a] < lo[a] {
                    c[a] = 2.0 * lo[a] - c[a];
                    v[a] = -v[a];
                } else if c[a] > hi[a] {
                    c[a] = 2.0 * hi[a] - c[a];
                    v[a] = -v[a];
                }
            }
            s.center = c;
        }
    }
}

/// A standard normal sample (Box–Muller).
fn gaussian(rng: &mut Pcg64) -> f32 {
    let u: f32 = rng.gen_range(f32::EPSILON..=1.0);
    let v: f32 = rng.gen_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * v).cos()
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
    fn scenes_stay_in_their_world_with_their_radii_and_small_steps() {
        for kind in SceneKind::ALL {
            let mut w = Scene::new(kind, 500, 3);
            let world = w.world();
            if kind != SceneKind::Flat {
                assert!((world.extent().x - 4.0 * 500f32.cbrt()).abs() < 1e-4);
            }
            for _ in 0..100 {
                let before: Vec<_> = w.spheres().to_vec();
                w.step();
                for (a, b) in before.iter().zip(w.spheres()) {
                    assert!(world.contains_point(b.center), "{kind}");
                    assert!(a.center.distance(b.center) <= W1_MAX_STEP + 1e-4);
                    assert!((W1_RADII.0..=W1_RADII.1).contains(&b.radius));
                }
            }
        }
    }

    #[test]
    fn scenes_are_deterministic_and_parse_by_name() {
        for kind in SceneKind::ALL {
            let (mut a, mut b) = (Scene::new(kind, 100, 9), Scene::new(kind, 100, 9));
            a.step();
            b.step();
            assert_eq!(a.spheres(), b.spheres());
            assert_ne!(Scene::new(kind, 100, 10).spheres(), a.spheres());
            assert_eq!(kind.name().parse::<SceneKind>(), Ok(kind));
        }
        assert!("cube".parse::<SceneKind>().is_err());
    }

    #[test]
    fn clusters_are_denser_than_uniform() {
        // Mean distance to the nearest of 50 others is a cheap density proxy.
        let spread = |kind| {
            let w = Scene::new(kind, 2000, 4);
            let s = w.spheres();
            let mut sum = 0.0;
            for a in &s[..50] {
                let d = s[50..]
                    .iter()
                    .map(|b| a.center.distance(b.center))
                    .fold(f32::INFINITY, f32::min);
                sum += d;
            }
            sum
        };
        assert!(spread(SceneKind::Clustered) < 0.8 * spread(SceneKind::Uniform));
    }
}
