//! W6 peer: parry3d 0.31's `TriMesh` (its own BVH built by `TriMesh::new`) and its
//! `RayCast::cast_local_ray_and_get_normal` (closest hit, `solid = false`: a ray
//! starting inside reports the first surface crossing, as ours does).

use super::caster::RayCaster;
use parry3d::math::Vector;
use parry3d::query::{Ray as PRay, RayCast};
use parry3d::shape::{FeatureId, TriMesh as PTriMesh};
use proxima::geom::Ray;
use proxima::narrow::TriMesh;

fn v(p: proxima::glam::Vec3) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

/// parry3d's triangle mesh.
pub struct ParryMesh {
    mesh: PTriMesh,
    n: u32,
}

impl ParryMesh {
    /// [`crate::parry_mesh::convert`] (the same conversion as the W5 peer).
    pub fn build(mesh: &TriMesh) -> Result<Self, String> {
        Ok(ParryMesh {
            mesh: crate::parry_mesh::convert(mesh)?,
            n: mesh.len() as u32,
        })
    }
}

impl RayCaster for ParryMesh {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        let r = PRay::new(v(ray.origin), v(ray.dir));
        self.mesh
            .cast_local_ray_and_get_normal(&r, ray.max_t, false)
            .map(|h| {
                // Back faces are reported as `Face(i + n)`.
                let id = match h.feature {
                    FeatureId::Face(i) => i % self.n,
                    _ => u32::MAX,
                };
                (id, h.time_of_impact)
            })
    }
}
