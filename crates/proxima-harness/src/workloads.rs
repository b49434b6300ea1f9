//! The standard dynamic-sphere workloads [sources: w1, w2, w3, w9], generated
//! deterministically from a seed: the scenes of the benchmarks (`proxima-bench`),
//! of `proxima demo`, and W4's static set (W1 at frame 0).
//!
//! # The motion model (one for every workload and every user)
//!
//! A workload is a set of spheres with fixed radii and per-sphere constant
//! velocities, drawn once from the seed: a uniformly random direction times a
//! speed uniform in [[`SPEED_MIN`], [`SPEED_MAX`]] units per frame. One
//! [`Workload::step`] moves every centre by its velocity and reflects it off the
//! walls of its cage (the velocity component across that wall flips): the cage is
//! the centre box, or for W3 a box of half-width [`W3_WANDER`] around the
//! sphere's starting point, so the clusters never dissolve. Stepping draws no
//! random numbers, so it costs the same for every structure, and frame `f` is the
//! same for everyone who steps a fresh workload `f` times.
//!
//! This is the benchmarks' model, kept bit for bit when it moved here. The demo
//! used to have its own (velocities jittered every frame, steps up to 0.25, W3
//! clusters of `sd = L / 12` picked at random); it now runs these workloads, so
//! the demo's scenes are exactly the benchmarks' for the same size and seed.
//!
//! # Where the centres and radii come from
//!
//! - W1 ([`Kind::W1`], `uniform`): centres uniform in a cube of side
//!   `L = 4·N^(1/3)` ([`cube_side`]), radii uniform in [[`R_MIN`], [`R_MAX`]];
//! - W2 ([`Kind::W2`], `flat`): centres uniform in a 1000 × 1000 × 10 box;
//! - W3 ([`Kind::W3`], `clustered`): centres from [`W3_CLUSTERS`] Gaussian clusters
//!   of standard deviation `L / 16` in W1's cube (sphere `i` in cluster `i mod 8`);
//! - W9 ([`Kind::W9`], `mixed`): W1's cube, radii from the power law
//!   `r = 0.25·(1 − u)^(−1/1.5)`, `u` uniform in `[0, 1)`, capped at 16
//!   ([`w9_radius`]): many pebbles, some crates, about 0.55% above 8.

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

/// Smallest radius of W9 (the power law's scale).
pub const W9_R_MIN: f32 = 0.25;
/// Exponent `α` of W9's power law: `P(r > x) = (W9_R_MIN / x)^α`.
pub const W9_ALPHA: f32 = 1.5;
/// Largest radius of W9 (the power law is capped here).
pub const W9_R_CAP: f32 = 16.0;
/// Size of W2's box.
pub const W2_BOX: Vec3 = Vec3::new(1000.0, 1000.0, 10.0);

/// Which standard workload. The discriminants seed the generator: never
/// renumber them (W9 is 3, after W3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Dynamic spheres, centres uniform in a cube of side `4 * N^(1/3)`.
    W1,
    /// Flat world: centres uniform in a 1000 × 1000 × 10 box.
    W2,
    /// Clustered: centres from a few tight Gaussian clusters in W1's cube.
    W3,
    /// Mixed sizes: W1 with power-law radii in [0.25, 16].
    W9,
}

impl Kind {
    /// Every workload, in order.
    pub const ALL: [Kind; 4] = [Kind::W1, Kind::W2, Kind::W3, Kind::W9];

    /// Lower-case name (`w1`, `w2`, `w3`, `w9`), as the benchmarks take it.
    pub fn name(self) -> &'static str {
        match self {
            Kind::W1 => "w1",
            Kind::W2 => "w2",
            Kind::W3 => "w3",
            Kind::W9 => "w9",
        }
    }

    /// The scene's name, as `proxima demo --scene` takes it (`uniform`, `flat`,
    /// `clustered`, `mixed`).
    pub fn scene_name(self) -> &'static str {
        match self {
            Kind::W1 => "uniform",
            Kind::W2 => "flat",
            Kind::W3 => "clustered",
            Kind::W9 => "mixed",
        }
    }

    /// Parses `w1`, `w2`, `w3` or `w9` (case-insensitive).
    pub fn parse(s: &str) -> Option<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
    }

    /// Parses a [`Kind::scene_name`] (exact).
    pub fn from_scene_name(s: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.scene_name() == s)
    }

    /// Smallest and largest radius a sphere of this workload can have.
    pub fn radii(self) -> (f32, f32) {
        match self {
            Kind::W9 => (W9_R_MIN, W9_R_CAP),
            _ => (R_MIN, R_MAX),
        }
    }
}

/// W9's radius for `u` in `[0, 1)`: `W9_R_MIN·(1 − u)^(−1/α)`, capped at
/// [`W9_R_CAP`] (the inverse of the power law's distribution function).
pub fn w9_radius(u: f32) -> f32 {
    (W9_R_MIN * (1.0 - u).powf(-1.0 / W9_ALPHA)).min(W9_R_CAP)
}

/// What an index needs to know about a workload before any sphere is inserted.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Number of spheres.
    pub n: usize,
    /// A box that contains every sphere at every frame (centre box grown by
    /// the largest radius).
    pub world: Aabb,
    /// Largest radius any sphere can have (a bound: structures that need one for
    /// exact answers, such as a point tree's query reach, read this).
    pub r_max: f32,
    /// Typical large radius: the 99th percentile of the radius distribution, as
    /// [`SceneHint::r_max`] means it (equal to `r_max` for W1–W3).
    pub r_typical: f32,
    /// Mean radius (of the distribution).
    pub r_mean: f32,
}

impl Scene {
    /// The scene as the library's index constructors take it: world box, the
    /// typical large radius as `r_max`, the largest as `r_largest`, `n` objects.
    pub fn hint(&self) -> SceneHint {
        SceneHint {
            max_live: self.n,
            r_largest: self.r_max,
            ..SceneHint::new(self.world, self.r_typical)
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

/// Standard deviation of W3's clusters in a cube of side `side`: `side / 16`,
/// tight, so each cluster is ~13x denser at its core than W1 while the cube
/// stays mostly empty.
pub fn w3_sigma(side: f32) -> f32 {
    side / 16.0
}

/// Mean radius of W9: `E[min(X, cap)] = r₀ + r₀^α (r₀^(1−α) − cap^(1−α)) / (α − 1)`
/// for the power law `X` of scale `r₀` (0.6875).
pub fn w9_mean() -> f32 {
    let (r0, a, cap) = (W9_R_MIN, W9_ALPHA, W9_R_CAP);
    r0 + r0.powf(a) * (r0.powf(1.0 - a) - cap.powf(1.0 - a)) / (a - 1.0)
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
            Kind::W1 | Kind::W3 | Kind::W9 => Aabb::new(Vec3::ZERO, Vec3::splat(cube_side(n))),
            Kind::W2 => Aabb::new(Vec3::ZERO, W2_BOX),
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
            Kind::W9 => {
                for _ in 0..n {
                    let c = uniform_in(&mut rng, &centre_box);
                    spheres.push(Sphere::new(c, w9_radius(rng.gen_range(0.0..1.0))));
                }
            }
            Kind::W3 => {
                let side = cube_side(n);
                let sigma = w3_sigma(side);
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
        let (r_max, r_typical, r_mean) = match self.kind {
            Kind::W9 => (W9_R_CAP, w9_radius(0.99), w9_mean()),
            _ => (R_MAX, R_MAX, 0.5 * (R_MIN + R_MAX)),
        };
        Scene {
            n: self.spheres.len(),
            world: self.centre_box.grown(r_max),
            r_max,
            r_typical,
            r_mean,
        }
    }

    /// The box every centre stays in (the world without the radii).
    pub fn centre_box(&self) -> Aabb {
        self.centre_box
    }

    /// One line describing the workload, as `proxima demo` prints it above its
    /// table (`W1 uniform: 50000 spheres, …`).
    pub fn describe(&self) -> String {
        let (n, e) = (self.spheres.len(), self.centre_box.extent());
        let head = format!(
            "{} {}: {n} spheres",
            self.kind.name().to_uppercase(),
            self.kind.scene_name()
        );
        match self.kind {
            Kind::W1 => format!("{head}, radii in [0.5, 2], cube side {:.1}", e.x),
            Kind::W2 => format!(
                "{head}, radii in [0.5, 2], box {:.0} x {:.0} x {:.0}",
                e.x, e.y, e.z
            ),
            Kind::W3 => format!(
                "{head}, radii in [0.5, 2], {W3_CLUSTERS} Gaussian clusters (sd {:.1}) \
                 in a cube of side {:.1}",
                w3_sigma(e.x),
                e.x
            ),
            Kind::W9 => format!(
                "{head}, radii 0.25 (1 - u)^(-1/1.5) capped at 16 (mean {:.2}), cube side {:.1}",
                w9_mean(),
                e.x
            ),
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
            let (lo, hi) = kind.radii();
            for _ in 0..50 {
                a.step();
                b.step();
            }
            assert_eq!(a.spheres, b.spheres);
            for s in &a.spheres {
                assert!(world.contains_sphere(s), "{kind:?}: {s:?} left {world:?}");
                assert!((lo..=hi).contains(&s.radius));
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
    fn scenes_stay_in_their_box_with_their_radii_and_small_steps() {
        for kind in Kind::ALL {
            let mut w = Workload::new(kind, 500, 3);
            let centres = w.centre_box();
            if kind != Kind::W2 {
                assert!((centres.extent().x - 4.0 * 500f32.cbrt()).abs() < 1e-4);
            }
            let (lo, hi) = kind.radii();
            for _ in 0..100 {
                let before = w.spheres.clone();
                w.step();
                for (a, b) in before.iter().zip(&w.spheres) {
                    assert!(centres.contains_point(b.center), "{kind:?}");
                    assert!(a.center.distance(b.center) <= SPEED_MAX + 1e-4);
                    assert!((lo..=hi).contains(&b.radius));
                    assert_eq!(a.radius, b.radius);
                }
            }
        }
    }

    #[test]
    fn names_parse_back() {
        for kind in Kind::ALL {
            assert_eq!(Kind::parse(kind.name()), Some(kind));
            assert_eq!(Kind::parse(&kind.name().to_uppercase()), Some(kind));
            assert_eq!(Kind::from_scene_name(kind.scene_name()), Some(kind));
            let w = Workload::new(kind, 100, 9);
            let head = format!(
                "{} {}: 100 spheres",
                kind.name().to_uppercase(),
                kind.scene_name()
            );
            assert!(w.describe().starts_with(&head), "{}", w.describe());
        }
        assert_eq!(Kind::parse("w4"), None);
        assert_eq!(Kind::from_scene_name("cube"), None);
        assert_eq!(Kind::from_scene_name("w1"), None);
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

    #[test]
    fn clusters_are_denser_than_uniform() {
        // Mean distance to the nearest of the others is a cheap density proxy.
        let spread = |kind| {
            let w = Workload::new(kind, 2000, 4);
            let s = &w.spheres;
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
        assert!(spread(Kind::W3) < 0.8 * spread(Kind::W1));
    }

    #[test]
    fn w9_radii_follow_the_power_law() {
        assert_eq!(w9_radius(0.0), W9_R_MIN);
        assert_eq!(w9_radius(0.999_999), W9_R_CAP);
        assert!((w9_radius(0.99) - 0.25 * 100f32.powf(2.0 / 3.0)).abs() < 1e-3);
        assert!((w9_mean() - 0.6875).abs() < 1e-6);
        let n = 100_000;
        let w = Workload::new(Kind::W9, n, 1);
        let r: Vec<f32> = w.spheres.iter().map(|s| s.radius).collect();
        let share = |f: &dyn Fn(f32) -> bool| r.iter().filter(|&&x| f(x)).count() as f64 / n as f64;
        // P(r > x) = (0.25 / x)^1.5: 0.552% above 8 (the design's "about 0.5%"),
        // 0.195% at the cap, half below 0.25 * 2^(2/3). Bounds are ~5 standard
        // deviations of the sample share.
        assert!((0.0044..=0.0067).contains(&share(&|x| x > 8.0)));
        assert!((0.0012..=0.0027).contains(&share(&|x| x == W9_R_CAP)));
        assert!((0.492..=0.508).contains(&share(&|x| x < 0.25 * 4f32.cbrt())));
        assert!(r.iter().all(|&x| (W9_R_MIN..=W9_R_CAP).contains(&x)));
        let mean = r.iter().map(|&x| x as f64).sum::<f64>() / n as f64;
        assert!((mean - w9_mean() as f64).abs() < 0.02, "{mean}");
        // The hint: the 99th percentile as r_max, the cap as the largest radius.
        let h = w.scene().hint();
        assert_eq!((h.r_largest, h.max_live), (W9_R_CAP, n));
        assert!((5.3..5.5).contains(&h.r_max), "{}", h.r_max);
        assert!(share(&|x| x > h.r_max) < 0.011);
    }

    #[test]
    fn w1_to_w3_hints_are_the_radius_bound() {
        for kind in [Kind::W1, Kind::W2, Kind::W3] {
            let s = Workload::new(kind, 300, 2).scene();
            let h = s.hint();
            assert_eq!((h.r_max, h.r_largest, h.max_live), (R_MAX, R_MAX, 300));
            assert_eq!(h.world, s.world);
        }
    }
}
