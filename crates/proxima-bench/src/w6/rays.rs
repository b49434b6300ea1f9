//! The W6 ray set for one mesh: deterministic, three kinds mixed.

use proxima::geom::{Aabb, Ray};
use proxima::glam::Vec3;
use proxima::narrow::TriMesh;
use proxima_harness::workloads::unit_vector;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The bounding box of a mesh's vertices.
pub fn bounds(mesh: &TriMesh) -> Aabb {
    let mut b = Aabb::EMPTY;
    for &p in mesh.vertices() {
        b.min = b.min.min(p);
        b.max = b.max.max(p);
    }
    b
}

fn inside(rng: &mut Pcg64, lo: Vec3, hi: Vec3) -> Vec3 {
    Vec3::new(
        rng.gen_range(lo.x..=hi.x),
        rng.gen_range(lo.y..=hi.y),
        rng.gen_range(lo.z..=hi.z),
    )
}

/// `n` rays with unit directions around `mesh`:
/// - 50 %: from a random point on the sphere of twice the bounding radius around
///   the box centre, aimed at a random point of the box (mostly hits), unbounded;
/// - 30 %: from a random point of the box enlarged 1.5× (some inside the mesh) in a
///   uniformly random direction (many misses), unbounded;
/// - 20 %: as the first kind but `max_t` uniform in [0.5, 1] × the distance to the
///   aimed point (hits, misses short of the surface, and hits near `max_t`).
pub fn rays(mesh: &TriMesh, n: usize, seed: u64) -> Vec<Ray> {
    let b = bounds(mesh);
    let c = b.center();
    let h = (b.max - b.min) * 0.5;
    let r = h.length().max(1e-6);
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|i| match i % 10 {
            0..=4 | 8 | 9 => {
                let o = c + unit_vector(&mut rng) * (2.0 * r);
                let target = inside(&mut rng, b.min, b.max);
                let d = target - o;
                let len = d.length();
                let max_t = if i % 10 >= 8 {
                    len * rng.gen_range(0.5..=1.0)
                } else {
                    f32::INFINITY
                };
                Ray::with_max_t(o, d / len, max_t)
            }
            _ => {
                let o = inside(&mut rng, c - 1.5 * h, c + 1.5 * h);
                Ray::new(o, unit_vector(&mut rng))
            }
        })
        .collect()
}
