//! W4's query batches [sources: w4]: deterministic from a seed, sized to the scene.
//!
//! Over W1's set (centres uniform in a cube of side `L = 4·N^(1/3)`, radii in
//! `[0.5, 2]`, about one sphere per 64 unit³):
//! - spheres: centre uniform in the cube, radius uniform in `[1, 4]` (a few hits);
//! - boxes: centre uniform, half-extents uniform in `[1, 4]` per axis;
//! - rays: origin uniform, direction uniform on the sphere; even rays have
//!   `max_t` uniform in `[5, 20]` (unit directions, so that is their length), odd
//!   rays are unbounded and cross the cube;
//! - frusta: a camera at a uniform point looking at another, 60° vertical field of
//!   view, aspect 16:9, near 0.1, far `L / 4`
//!   (`Mat4::perspective_rh * Mat4::look_at_rh`, depth 0..1).

use proxima::geom::{Aabb, Frustum, Ray, Sphere};
use proxima::glam::{Mat4, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The four query kinds, in table order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QueryKind {
    /// Sphere overlap queries.
    Sphere,
    /// Box overlap queries.
    Aabb,
    /// Rays (all hits).
    Ray,
    /// Frustum culling.
    Frustum,
}

impl QueryKind {
    /// Every kind, in order.
    pub const ALL: [QueryKind; 4] = [
        QueryKind::Sphere,
        QueryKind::Aabb,
        QueryKind::Ray,
        QueryKind::Frustum,
    ];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            QueryKind::Sphere => "sphere",
            QueryKind::Aabb => "aabb",
            QueryKind::Ray => "ray",
            QueryKind::Frustum => "frustum",
        }
    }
}

/// One batch of each kind.
#[derive(Clone, Debug)]
pub struct Batches {
    /// Sphere queries.
    pub spheres: Vec<Sphere>,
    /// Box queries.
    pub boxes: Vec<Aabb>,
    /// Rays, half bounded, half unbounded.
    pub rays: Vec<Ray>,
    /// Frusta.
    pub frusta: Vec<Frustum>,
}

impl Batches {
    /// Number of queries of a kind.
    pub fn len(&self, kind: QueryKind) -> usize {
        match kind {
            QueryKind::Sphere => self.spheres.len(),
            QueryKind::Aabb => self.boxes.len(),
            QueryKind::Ray => self.rays.len(),
            QueryKind::Frustum => self.frusta.len(),
        }
    }
}

fn point(rng: &mut Pcg64, side: f32) -> Vec3 {
    Vec3::new(
        rng.gen_range(0.0..=side),
        rng.gen_range(0.0..=side),
        rng.gen_range(0.0..=side),
    )
}

/// `q` queries of each point kind and `frusta` frusta over the W1 cube of side
/// `side`, from `seed`.
pub fn generate(side: f32, q: usize, frusta: usize, seed: u64) -> Batches {
    let mut rng = Pcg64::seed_from_u64(seed ^ 0x5734_0000_0004);
    let spheres = (0..q)
        .map(|_| {
            let c = point(&mut rng, side);
            Sphere::new(c, rng.gen_range(1.0..=4.0))
        })
        .collect();
    let boxes = (0..q)
        .map(|_| {
            let c = point(&mut rng, side);
            let h = Vec3::new(
                rng.gen_range(1.0..=4.0),
                rng.gen_range(1.0..=4.0),
                rng.gen_range(1.0..=4.0),
            );
            Aabb::new(c - h, c + h)
        })
        .collect();
    let rays = (0..q)
        .map(|i| {
            let (o, d) = (
                point(&mut rng, side),
                proxima_harness::workloads::unit_vector(&mut rng),
            );
            if i % 2 == 0 {
                Ray::with_max_t(o, d, rng.gen_range(5.0..=20.0))
            } else {
                Ray::new(o, d)
            }
        })
        .collect();
    let proj = Mat4::perspective_rh(60f32.to_radians(), 16.0 / 9.0, 0.1, side / 4.0);
    let frusta = (0..frusta)
        .map(|_| {
            let eye = point(&mut rng, side);
            let mut target = point(&mut rng, side);
            if target.distance(eye) < 1.0 {
                target = eye + Vec3::X;
            }
            // Up: Z unless looking (almost) along it.
            let fwd = (target - eye).normalize();
            let up = if fwd.z.abs() > 0.99 { Vec3::Y } else { Vec3::Z };
            let view = Mat4::look_at_rh(eye, target, up);
            Frustum::from_view_projection(proj * view).expect("finite camera")
        })
        .collect();
    Batches {
        spheres,
        boxes,
        rays,
        frusta,
    }
}
