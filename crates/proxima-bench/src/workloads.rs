//! The standard dynamic-sphere workloads [sources: w1, w2, w3], generated
//! deterministically from a seed.
//!
//! A workload is a set of spheres with fixed radii and per-sphere velocities. One
//! [`Workload::step`] moves every centre by its velocity and reflects it off the
//! walls of its cage (the world box, or for W3 a small box around its home
//! position). Velocities are drawn once, so stepping costs the same for every
//! structure and needs no random numbers.

use proxima::broad::SceneHint;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Smallest radius of every workload.
pub const R_MIN: f32 = 0.5;
/// Largest radius of every workload.
pub const R_MAX: f32 = 2.0;
/// Slowest speed, in units per frame.
pub const SPEED_MIN: f32 = 0.05;
/// Fastest speed, in units per frame.
pub const SPEED_MAX: f32 = 0.2;
/// Number of Gaussian clusters in W3.
pub const W3_CLUSTERS: usize = 8;
/// Half-width of the box a W3 sphere wanders in around its home position: keeps
/// the clusters from dissolving however many frames a benchmark runs.
pub const W3_WANDER: f32 = 3.0;

/// Which standard workload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Dynamic spheres, centres uniform in a cube of side `4 * N^(1/3)`.
    W1,
    /// Flat world: centres uniform in a 1000 × 1000 × 10 box.
    W2,
    /// Clustered: centres from a few tight Gaussian clusters in W1's cube.
    W3,
}

impl Kind {
    /// Every workload, in order.
    pub const ALL: [Kind; 3] = [Kind::W1, Kind::W2, Kind::W3];

    /// Lower-case name (`w1`, `w2`, `w3`).
    pub fn name(self) -> &'static str {
        match self {
            Kind::W1 => "w1",
            Kind::W2 => "w2",
            Kind::W3 => "w3",
        }
    }

    /// Parses `w1`, `w2` or `w3` (case-insensitive).
    pub fn parse(s: &str) -> Option<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
    }
}

/// What an index needs to know about a workload before any sphere is inserted.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Number of spheres.
    pub n: usize,
    /// A box that contains every sphere at every frame (centre box grown by
    /// [`R_MAX`]).
    pub world: Aabb,
    /// Largest radius.
    pub r_max: f32,
    /// Mean radius.
    pub r_mean: f32,
}

impl Scene {
    /// The scene as the library's index constructors take it (world box and
    /// largest radius).
    pub fn hint(&self) -> SceneHint {
        SceneHint {
            max_live: self.n,
            ..SceneHint::new(self.world, self.r_max)
        }
    }
}

/// A deterministic scene of moving spheres.
#[derive(Clone, Debug)]
pub struct Workload {
    /// Which workload this is.
    pub kind: Kind,
    /// The spheres at the current frame; sphere `i` is object `i`.
    pub spheres: Vec<Sphere>,
    velocities: Vec<Vec3>,
    /// Box that holds every centre.
    centre_box: Aabb,
    /// Per-sphere cages (W3 only); the others bounce off `centre_box`.
    cages: Option<Vec<Aabb>>,
    frame: u64,
}

/// Side of W1's and W3's cube: `4 * N^(1/3)` (about one sphere per 64 unit³).
pub fn cube_side(n: usize) -> f32 {
    4.0 * (n.max(1) as f32).cbrt()
}

/// A standard normal sample (Box–Muller; `rand` 0.8 has no normal distribution
/// without `rand_distr`).
fn gaussian(rng: &mut Pcg64) -> f32 {
    let u1: f32 = rng.gen_range(f32::EPSILON..1.0);
    let u2: f32 = rng.gen_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (std::f32::consts::TAU * u2).cos()
}

/// A uniformly random unit vector (rejection sampling in the unit ball).
pub fn unit_vector(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let l2 = v.length_squared();
        if l2 > 1e-4 && l2 <= 1.0 {
            return v / l2.sqrt();
        }
    }
}

fn uniform_in(rng: &mut Pcg64, b: &Aabb) -> Vec3 {
    Vec3::new(
        rng.gen_range(b.min.x..=b.max.x),
        rng.gen_range(b.min.y..=b.max.y),
        rng.gen_range(b.min.z..=b.max.z),
    )
}

impl Workload {
    /// Generates workload `kind` with `n` spheres from `seed`. The same arguments
    /// always give the same spheres and the same motion.
    pub fn new(kind: Kind, n: usize, seed: u64) -> Workload {
        let mut rng = Pcg64::seed_from_u64(seed ^ (kind as u64).wrapping_mul(0x9E37_79B9));
        let centre_box = match kind {
            Kind::W1 | Kind::W3 => Aabb::new(Vec3::ZERO, Vec3::splat(cube_side(n))),
            Kind::W2 => Aabb::new(Vec3::ZERO, Vec3::new(1000.0, 1000.0, 10.0)),
        };
        let mut spheres = Vec::with_capacity(n);
        let mut velocities = Vec::with_capacity(n);
        let mut cages = None;
        match kind {
            Kind::W1 | Kind::W2 => {
                for _ in 0..n {
                    let c = uniform_in(&mut rng, &centre_box);
                    spheres.push(Sphere::new(c, rng.gen_range(R_MIN..=R_MAX)));
                }
            }
            Kind::W3 => {
                let side = cube_side(n);
                // Tight: sigma = side / 16, so each cluster is ~13x denser at its
                // core than W1 while the cube stays mostly empty.
                let sigma = side / 16.0;
                let inner = Aabb::new(Vec3::splat(2.0 * sigma), Vec3::splat(side - 2.0 * sigma));
                let centres: Vec<Vec3> = (0..W3_CLUSTERS)
                    .map(|_| uniform_in(&mut rng, &inner))
                    .collect();
                let mut cage_list = Vec::with_capacity(n);
                for i in 0..n {
                    let k = centres[i % W3_CLUSTERS];
                    let offset =
                        Vec3::new(gaussian(&mut rng), gaussian(&mut rng), gaussian(&mut rng))
                            * sigma;
                    let c = (k + offset).clamp(centre_box.min, centre_box.max);
                    let cage = Aabb::new(
                        (c - Vec3::splat(W3_WANDER)).max(centre_box.min),
                        (c + Vec3::splat(W3_WANDER)).min(centre_box.max),
                    );
                    cage_list.push(cage);
                    spheres.push(Sphere::new(c, rng.gen_range(R_MIN..=R_MAX)));
                }
                cages = Some(cage_list);
            }
        }
        for _ in 0..n {
            velocities.push(unit_vector(&mut rng) * rng.gen_range(SPEED_MIN..=SPEED_MAX));
        }
        Workload {
            kind,
            spheres,
            velocities,
            centre_box,
            cages,
            frame: 0,
        }
    }

    /// What an index needs before insertion: count, world box, radii.
    pub fn scene(&self) -> Scene {
        Scene {
            n: self.spheres.len(),
            world: self.centre_box.grown(R_MAX),
            r_max: R_MAX,
            r_mean: 0.5 * (R_MIN + R_MAX),
        }
    }

    /// Number of [`Workload::step`] calls so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Advances one frame: every centre moves by its velocity and is reflected off
    /// its cage's walls (the velocity component flips). O(n).
    pub fn step(&mut self) {
        let centre_box = self.centre_box;
        for (i, (s, v)) in self
            .spheres
            .iter_mut()
            .zip(self.velocities.iter_mut())
            .enumerate()
        {
            let cage = match &self.cages {
                Some(c) => c[i],
                None => centre_box,
            };
            let mut p = s.center + *v;
            for a in 0..3 {
                if p[a] < cage.min[a] {
                    p[a] = (2.0 * cage.min[a] - p[a]).min(cage.max[a]);
                    v[a] = -v[a];
                } else if p[a] > cage.max[a] {
                    p[a] = (2.0 * cage.max[a] - p[a]).max(cage.min[a]);
                    v[a] = -v[a];
                }
            }
            s.center = p;
        }
        self.frame += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_and_inside_the_world() {
        for kind in Kind::ALL {
            let mut a = Workload::new(kind, 500, 7);
            let mut b = Workload::new(kind, 500, 7);
            let world = a.scene().world;
            for _ in 0..50 {
                a.step();
                b.step();
            }
            assert_eq!(a.spheres, b.spheres);
            for s in &a.spheres {
                assert!(world.contains_sphere(s), "{kind:?}: {s:?} left {world:?}");
                assert!((R_MIN..=R_MAX).contains(&s.radius));
            }
            let c = Workload::new(kind, 500, 8);
            assert_ne!(a.spheres[0], c.spheres[0]);
        }
    }

    #[test]
    fn spheres_move_by_their_speed() {
        let mut w = Workload::new(Kind::W1, 200, 3);
        let before = w.spheres.clone();
        w.step();
        for (a, b) in before.iter().zip(&w.spheres) {
            let d = a.center.distance(b.center);
            assert!(d <= SPEED_MAX * 1.001, "moved {d}");
            assert!(d > 0.0);
        }
    }

    #[test]
    fn w3_is_clustered() {
        // The clustered workload must have many more overlaps than W1 at equal N.
        let count = |w: &Workload| {
            let s = &w.spheres;
            let mut c = 0;
            for i in 0..s.len() {
                for j in i + 1..s.len() {
                    c += usize::from(s[i].intersects_sphere(&s[j]));
                }
            }
            c
        };
        let w1 = Workload::new(Kind::W1, 2000, 1);
        let w3 = Workload::new(Kind::W3, 2000, 1);
        assert!(count(&w3) > 3 * count(&w1));
    }
}
