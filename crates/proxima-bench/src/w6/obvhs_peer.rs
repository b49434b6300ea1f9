//! W6 peer: obvhs 0.4, driven as its README and `cornell_box_cwbvh` example drive it:
//! `build_cwbvh_from_tris` with `BvhBuildParams::medium_build()` (PLOC build,
//! spatial pre-splits, collapse to a compressed 8-wide BVH), triangles re-laid out
//! in the BVH's primitive order as `RtTriangle` (its CPU-optimized layout), and
//! `CwBvh::ray_traverse` for the closest hit with `RtTriangle::intersect` (its own
//! Möller–Trumbore test, `f32`, not watertight).

use super::caster::RayCaster;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as ORay, RayHit as OHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use proxima::geom::Ray;
use proxima::narrow::TriMesh;
use std::time::Duration;

/// obvhs takes glam 0.33 vectors; the library uses glam 0.30.
fn v3a(p: proxima::glam::Vec3) -> glam33::Vec3A {
    glam33::Vec3A::new(p.x, p.y, p.z)
}

/// obvhs's CWBVH over a mesh.
pub struct Obvhs {
    bvh: CwBvh,
    tris: Vec<RtTriangle>,
}

impl Obvhs {
    /// Builds the CWBVH with obvhs's medium preset.
    pub fn build(mesh: &TriMesh) -> Self {
        let tris: Vec<Triangle> = (0..mesh.len())
            .map(|i| {
                let [a, b, c] = mesh.triangle(i);
                Triangle {
                    v0: v3a(a),
                    v1: v3a(b),
                    v2: v3a(c),
                }
            })
            .collect();
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        Obvhs { bvh, tris }
    }
}

impl RayCaster for Obvhs {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        let r = ORay::new(v3a(ray.origin), v3a(ray.dir), 0.0, ray.max_t);
        let mut hit = OHit::none();
        let tris = &self.tris;
        self.bvh
            .ray_traverse(r, &mut hit, |r, id| tris[id].intersect(r))
            .then(|| (self.bvh.primitive_indices[hit.primitive_id as usize], hit.t))
    }
}
