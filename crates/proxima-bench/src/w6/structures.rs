//! The W6 structures: Proxima's BVH with every bounding volume, brute force, and
//! the peers, behind one object-safe interface.

use crate::bvh_peer::BvhCrate;
use crate::obvhs_peer::Obvhs;
use crate::parry_mesh_peer::ParryMesh;
use proxima::geom::{Aabb, Ray, Sphere};
use proxima::narrow::{
    ray_triangle, BoundingVolume, BuildOptions, Bvh, Kdop14, Kdop18, Kdop26, Obb, RayBvh, TriMesh,
};
use rayon::prelude::*;

/// A closest hit: `(mesh triangle, t)`, or `None` for a miss.
pub type Answer = Option<(u32, f32)>;

/// A closest-hit ray caster over one mesh: `(mesh triangle, t)` or `None`.
pub trait RayCaster: Sync {
    /// The closest hit of a valid ray.
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)>;

    /// Every ray of a batch on the current rayon pool (the generic `par_iter`; ours
    /// override it with the library's batch helper).
    fn cast_par(&self, rays: &[Ray]) -> Vec<Option<(u32, f32)>> {
        rays.par_iter()
            .with_min_len(256)
            .map(|r| self.cast(r))
            .collect()
    }
}

/// Proxima's `Bvh<BV>` and its `cast_ray`.
pub struct Proxima<BV: BoundingVolume> {
    bvh: Bvh<BV>,
    mesh: TriMesh,
}

impl<BV: BoundingVolume> RayCaster for Proxima<BV> {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        self.bvh
            .cast_ray(&self.mesh, ray)
            .expect("valid ray")
            .map(|h| (h.triangle, h.t))
    }

    fn cast_par(&self, rays: &[Ray]) -> Vec<Option<(u32, f32)>> {
        self.bvh
            .cast_rays_par(&self.mesh, rays)
            .expect("valid rays")
            .into_iter()
            .map(|h| h.map(|h| (h.triangle, h.t)))
            .collect()
    }
}

/// Proxima's `RayBvh` (the ray layout of the SAH AABB tree).
pub struct ProximaRay(RayBvh);

impl RayCaster for ProximaRay {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        self.0
            .cast_ray(ray)
            .expect("valid ray")
            .map(|h| (h.triangle, h.t))
    }

    fn cast_par(&self, rays: &[Ray]) -> Vec<Option<(u32, f32)>> {
        self.0
            .cast_rays_par(rays)
            .expect("valid rays")
            .into_iter()
            .map(|h| h.map(|h| (h.triangle, h.t)))
            .collect()
    }
}

/// Every triangle, with the library's `ray_triangle`: the oracle.
pub struct Brute(pub TriMesh);

impl RayCaster for Brute {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        let mut best: Option<(u32, f32)> = None;
        for i in 0..self.0.len() {
            if let Some(h) = ray_triangle(ray, &self.0.triangle(i)) {
                if best.is_none_or(|(_, t)| h.t < t) {
                    best = Some((i as u32, h.t));
                }
            }
        }
        best
    }
}

/// One row of the W6 table.
pub struct Entry {
    /// Structure name.
    pub name: &'static str,
    /// A peer crate (its answers may differ on grazing rays).
    pub peer: bool,
    /// Runs on a subset of the rays only (brute force).
    pub subset: bool,
    /// Builds the structure.
    pub make: fn(&TriMesh, BuildOptions) -> Box<dyn RayCaster>,
}

fn proxima<BV: BoundingVolume>(m: &TriMesh, o: BuildOptions) -> Box<dyn RayCaster> {
    Box::new(Proxima::<BV> {
        bvh: Bvh::build(m, o).expect("valid options"),
        mesh: m.clone(),
    })
}

/// The name of the peer every ratio is taken against.
pub const OBVHS: &str = "obvhs-cwbvh";

/// Every W6 structure; the first is the reference the others are checked against.
pub fn entries() -> Vec<Entry> {
    let e = |name, peer, subset, make| Entry {
        name,
        peer,
        subset,
        make,
    };
    vec![
        e("proxima-aabb", false, false, proxima::<Aabb>),
        e("proxima-ray", false, false, |m, o| {
            Box::new(ProximaRay(RayBvh::build(m, o).expect("valid options")))
        }),
        e("proxima-kdop14", false, false, proxima::<Kdop14>),
        e("proxima-kdop18", false, false, proxima::<Kdop18>),
        e("proxima-kdop26", false, false, proxima::<Kdop26>),
        e("proxima-obb", false, false, proxima::<Obb>),
        e("proxima-sphere", false, false, proxima::<Sphere>),
        e("brute-force", false, true, |m, _| {
            Box::new(Brute(m.clone()))
        }),
        e(OBVHS, true, false, |m, _| Box::new(Obvhs::build(m))),
        e("bvh", true, false, |m, _| Box::new(BvhCrate::build(m))),
        e("parry3d-trimesh", true, false, |m, _| {
            Box::new(ParryMesh::build(m).expect("valid mesh"))
        }),
    ]
}
