//! The W6 structures: Proxima's mesh (its ray tree) and its BVH with every
//! bounding volume, brute force, and the peers, behind one object-safe interface.

use super::bvh_peer::BvhCrate;
use super::caster::{Answer, RayCaster};
use super::obvhs_peer::Obvhs;
use super::parry_mesh_peer::ParryMesh;
use proxima::geom::{Aabb, Ray, Sphere};
use proxima::narrow::{
    ray_triangle, BoundingVolume, BuildOptions, Kdop14, Kdop18, Kdop26, Mesh, Obb, TriMesh,
    TriangleHit,
};

fn answer(h: Option<TriangleHit>) -> Answer {
    h.map(|h| (h.triangle, h.t))
}

/// Proxima's collision tree `Bvh<BV>` of a `Mesh<BV>` and its `cast_ray` (the
/// source's volumes compared on rays, [sources: bv-kinds]).
pub struct Proxima<BV: BoundingVolume>(Mesh<BV>);

impl<BV: BoundingVolume> RayCaster for Proxima<BV> {
    fn cast(&self, ray: &Ray) -> Answer {
        answer(
            self.0
                .bvh()
                .cast_ray(self.0.trimesh(), ray)
                .expect("valid ray"),
        )
    }

    fn cast_par(&self, rays: &[Ray]) -> Vec<Answer> {
        let hits = self.0.bvh().cast_rays_par(self.0.trimesh(), rays);
        hits.expect("valid rays").into_iter().map(answer).collect()
    }
}

/// Proxima's `Mesh::cast_ray` (its ray tree, a `RayBvh` laid out from the SAH
/// tree).
pub struct ProximaMesh(Mesh<Aabb>);

impl RayCaster for ProximaMesh {
    fn cast(&self, ray: &Ray) -> Answer {
        answer(self.0.cast_ray(ray).expect("valid ray"))
    }

    fn cast_par(&self, rays: &[Ray]) -> Vec<Answer> {
        let hits = self.0.cast_rays_par(rays).expect("valid rays");
        hits.into_iter().map(answer).collect()
    }
}

/// Every triangle, with the library's `ray_triangle`: the oracle.
pub struct Brute(pub TriMesh);

impl RayCaster for Brute {
    fn cast(&self, ray: &Ray) -> Answer {
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
    Box::new(Proxima(
        Mesh::<BV>::from_trimesh(m.clone(), o).expect("valid options"),
    ))
}

/// The mesh whose ray tree is built with `o`, built now (inside the build's
/// clock, not in the first timed batch). Its collision tree is the SAH tree the
/// ray tree is laid out from, so the build is that of a `RayBvh` alone.
fn proxima_mesh(m: &TriMesh, o: BuildOptions) -> Box<dyn RayCaster> {
    let binary = BuildOptions { leaf_size: 1, ..o };
    let mesh = Mesh::<Aabb>::from_trimesh(m.clone(), binary)
        .and_then(|mesh| mesh.with_ray_options(o))
        .expect("valid options");
    mesh.ray_bvh();
    Box::new(ProximaMesh(mesh))
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
        e("proxima-ray", false, false, proxima_mesh),
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
