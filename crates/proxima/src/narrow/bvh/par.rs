//! Parallel batch ray casts [sources: parallel]: one ray per task on rayon's pool, for
//! [`Mesh`], [`RayBvh`] and [`Bvh`] (feature `parallel`).

use super::mesh::Mesh;
use super::ray_tree::RayBvh;
use super::tree::Bvh;
use crate::geom::Ray;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::ray_triangle::TriangleHit;
use crate::narrow::TriMesh;
use crate::Result;
use rayon::prelude::*;

/// Casts every ray of `rays` with `cast` on the current rayon pool (the global one,
/// or whatever pool the caller `install`s), results in ray order. Every ray is
/// validated first, so a bad ray fails the whole batch before any work is done.
/// Cost: the sum of the single casts divided by the thread count.
fn par_cast<F>(rays: &[Ray], cast: F) -> Result<Vec<Option<TriangleHit>>>
where
    F: Fn(&Ray) -> Option<TriangleHit> + Sync + Send,
{
    for r in rays {
        r.validate()?;
    }
    // Chunks of rays, not single rays: a ray costs about a microsecond, a task
    // split must cost much less.
    Ok(rays.par_iter().with_min_len(256).map(cast).collect())
}

impl<BV: BoundingVolume> Mesh<BV> {
    /// [`Mesh::cast_ray`] for every ray of `rays`, in parallel on the current rayon
    /// pool; `out[i]` is the closest hit of `rays[i]`, exactly as the sequential
    /// cast returns it. Builds the ray tree first if no cast has yet. Fails,
    /// before casting anything, on an invalid ray.
    pub fn cast_rays_par(&self, rays: &[Ray]) -> Result<Vec<Option<TriangleHit>>> {
        self.ray_bvh().cast_rays_par(rays)
    }
}

impl RayBvh {
    /// [`RayBvh::cast_ray`] for every ray of `rays`, in parallel on the current
    /// rayon pool, results in ray order. Fails, before casting anything, on an
    /// invalid ray.
    pub fn cast_rays_par(&self, rays: &[Ray]) -> Result<Vec<Option<TriangleHit>>> {
        par_cast(rays, |r| self.cast_valid(r, false))
    }
}

impl<BV: BoundingVolume> Bvh<BV> {
    /// [`Bvh::cast_ray`] for every ray of `rays`, in parallel on the current rayon
    /// pool, results in ray order. Fails, before casting anything, on an invalid
    /// ray or a mesh other than the tree's.
    pub fn cast_rays_par(&self, mesh: &TriMesh, rays: &[Ray]) -> Result<Vec<Option<TriangleHit>>> {
        self.check_mesh(mesh)?;
        par_cast(rays, |r| self.cast_valid(mesh, r, false))
    }
}
