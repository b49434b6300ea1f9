//! [`Mesh`]: a triangle mesh that owns its trees, the narrow phase's main type.
//!
//! Its queries are found by name: collisions in `collide.rs` ([`Mesh::collide`]),
//! distances in `narrow/distance/` ([`Mesh::distance`], [`Mesh::closest_point`],
//! [`Mesh::contains_point`]), batches of rays in `par.rs`; construction,
//! deformation and single ray casts here. Loading from a file is [`Mesh::load`], in [`io`](crate::io).

use super::options::BuildOptions;
use super::ray_tree::RayBvh;
use super::tree::Bvh;
use crate::geom::{Aabb, Ray, Segment, Sphere};
use crate::narrow::bv::{enclosing_radius, BoundingVolume, Kdop18};
use crate::narrow::ray_triangle::TriangleHit;
use crate::narrow::TriMesh;
use crate::Result;
use glam::Vec3;
use std::sync::OnceLock;

/// A triangle mesh with the trees its queries need, built once and kept in step
/// with its vertices (as parry's `TriMesh` owns its `Bvh`).
///
/// - the validated geometry, a [`TriMesh`];
/// - the collision tree, a [`Bvh<BV>`](Bvh) (k-DOP-18 by default, the fastest
///   volume on W5), built at construction with the given [`BuildOptions`];
/// - the ray tree, a [`RayBvh`], built on the first ray cast (or by
///   [`Mesh::ray_bvh`]), so that a mesh that is only ever collided (most shapes
///   of a collision world) never pays its memory (~135 bytes per triangle plus
///   128 per 4-wide node). With the default options it is laid out from
///   the collision tree's own topology in O(n) (a separate
///   [`RayBvh::build`] would rebuild that topology in O(n log n));
/// - its bounds: an [`Aabb`], and a bounding [`Sphere`] around the box's centre,
///   a point fixed in the mesh, so that the sphere of the mesh moved by a rigid
///   pose is the same sphere moved by that pose (what a broad phase stores).
///
/// Queries: [`Mesh::collide`] / [`Mesh::collide_first`] against another mesh
/// (with a [`Collider`](crate::narrow::Collider) for a loop of them);
/// [`Mesh::distance`] / [`Mesh::within`] / [`Mesh::pairs_within`] against
/// another mesh and [`Mesh::closest_point`] / [`Mesh::contains_point`] /
/// [`Mesh::sphere_distance`] / [`Mesh::sphere_overlaps`] (with a
/// [`Proximity`](crate::narrow::Proximity) for a loop of them);
/// [`Mesh::cast_ray`] / [`Mesh::intersects_ray`] / [`Mesh::cast_segment`], and
/// `Mesh::cast_rays_par` (feature `parallel`). [`Mesh::set_vertices`] deforms
/// it, refitting both trees.
///
/// `Send + Sync` (the lazy ray tree is a [`OnceLock`]): share one in an `Arc`
/// between threads and shapes; a clone copies the geometry and the trees.
#[derive(Clone, Debug)]
pub struct Mesh<BV = Kdop18> {
    geometry: TriMesh,
    bvh: Bvh<BV>,
    rays: OnceLock<RayBvh>,
    ray_options: BuildOptions,
    aabb: Aabb,
    sphere: Sphere,
}

impl<BV: BoundingVolume> Mesh<BV> {
    /// Checks the mesh ([`TriMesh::new`]) and builds its collision tree with
    /// [`BuildOptions::default`]. O(n log n) in the triangles.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Mesh<BV>> {
        Mesh::from_trimesh(TriMesh::new(vertices, triangles)?, BuildOptions::default())
    }

    /// Takes `mesh` and builds its collision tree with `options`
    /// ([`Bvh::build`]); the ray tree will be built with [`BuildOptions::RAYS`]
    /// (see [`Mesh::with_ray_options`]). O(n log n). Fails with
    /// [`Error::InvalidParameter`](crate::Error::InvalidParameter) on a leaf size
    /// of 0.
    pub fn from_trimesh(mesh: TriMesh, options: BuildOptions) -> Result<Mesh<BV>> {
        let bvh = Bvh::build(&mesh, options)?;
        let (aabb, sphere) = bounds(&mesh);
        Ok(Mesh {
            geometry: mesh,
            bvh,
            rays: OnceLock::new(),
            ray_options: BuildOptions::RAYS,
            aabb,
            sphere,
        })
    }

    /// The mesh with its ray tree built with `options` ([`RayBvh::build`]) instead
    /// of [`BuildOptions::RAYS`] (a ray tree already built is dropped, and built
    /// again on the next cast). O(1). Fails with
    /// [`Error::InvalidParameter`](crate::Error::InvalidParameter) on a leaf size
    /// of 0.
    pub fn with_ray_options(mut self, options: BuildOptions) -> Result<Mesh<BV>> {
        options.check()?;
        self.ray_options = options;
        self.rays = OnceLock::new();
        Ok(self)
    }

    /// The geometry.
    pub fn trimesh(&self) -> &TriMesh {
        &self.geometry
    }

    /// The collision tree.
    pub fn bvh(&self) -> &Bvh<BV> {
        &self.bvh
    }

    /// The ray tree, built now if no cast has built it yet (O(n log n) once; then
    /// O(1)). Call it after construction to keep that cost out of the first cast.
    pub fn ray_bvh(&self) -> &RayBvh {
        self.rays
            .get_or_init(|| RayBvh::build_reusing(&self.bvh, &self.geometry, self.ray_options))
    }

    /// The options the ray tree is (or will be) built with.
    pub fn ray_options(&self) -> BuildOptions {
        self.ray_options
    }

    /// The box of every triangle corner. O(1).
    pub fn aabb(&self) -> Aabb {
        self.aabb
    }

    /// A sphere containing every triangle corner, centred on the centre of
    /// [`Mesh::aabb`] (a point fixed in the mesh). The radius is rounded up, so the
    /// containment is exact, not up to rounding; it is infinite only for a mesh
    /// wider than `f32`'s range. O(1).
    pub fn bounding_sphere(&self) -> Sphere {
        self.sphere
    }

    /// The closest hit of `ray` on the mesh (smallest `t`, ties to the smaller
    /// triangle index), exact ([`RayBvh::cast_ray`]). O(log n) typical; the
    /// first cast builds the ray tree. Fails on an invalid ray (non-finite, zero
    /// direction, negative or NaN `max_t`).
    pub fn cast_ray(&self, ray: &Ray) -> Result<Option<TriangleHit>> {
        ray.validate()?;
        Ok(self.ray_bvh().cast_valid(ray, false))
    }

    /// Whether `ray` hits the mesh at all (stops at the first hit found).
    /// O(log n) typical. Fails on an invalid ray.
    pub fn intersects_ray(&self, ray: &Ray) -> Result<bool> {
        ray.validate()?;
        Ok(self.ray_bvh().cast_valid(ray, true).is_some())
    }

    /// [`Mesh::cast_ray`] for the segment from `seg.a` (`t = 0`) to `seg.b`
    /// (`t = 1`). Fails on a segment of zero length.
    pub fn cast_segment(&self, seg: &Segment) -> Result<Option<TriangleHit>> {
        self.cast_ray(&seg.to_ray())
    }

    /// Moves the vertices (same count, same triangles: a deformed mesh) and
    /// refits both trees ([`Bvh::refit`], [`RayBvh::refit`] if built) and the
    /// bounds. O(n). Fails, changing nothing, on a count mismatch or a non-finite
    /// vertex ([`TriMesh::set_vertices`]).
    pub fn set_vertices(&mut self, vertices: &[Vec3]) -> Result<()> {
        self.geometry.set_vertices(vertices)?;
        // Neither refit can fail now: same mesh, vertices checked.
        self.bvh.refit(&self.geometry)?;
        if let Some(rays) = self.rays.get_mut() {
            rays.refit(vertices)?;
        }
        (self.aabb, self.sphere) = bounds(&self.geometry);
        Ok(())
    }
}

/// The box of every triangle corner, and the sphere around its centre (radius
/// from [`enclosing_radius`]: exact containment).
fn bounds(mesh: &TriMesh) -> (Aabb, Sphere) {
    let corners = || {
        mesh.triangles()
            .iter()
            .flatten()
            .map(|&v| mesh.vertices()[v as usize])
    };
    let aabb = corners().fold(Aabb::EMPTY, |b, p| Aabb::new(b.min.min(p), b.max.max(p)));
    let c = aabb.center();
    (aabb, Sphere::new(c, enclosing_radius(c, corners())))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync<T: Send + Sync>() {}

    #[test]
    fn mesh_is_send_and_sync() {
        assert_send_sync::<Mesh>();
        assert_send_sync::<Mesh<crate::narrow::Obb>>();
    }

    /// A bumpy `n × n` height field.
    fn field(n: u32) -> TriMesh {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f32, j as f32);
                v.push(Vec3::new(x, y, (x * 0.7).sin() * (y * 0.3).cos()));
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh::new(v, t).unwrap()
    }

    #[test]
    fn ray_tree_from_the_collision_tree_is_the_built_one() {
        let m = field(12);
        for options in [BuildOptions::RAYS, BuildOptions::default()] {
            let built = RayBvh::build(&m, options).unwrap();
            let reused = Mesh::<Kdop18>::from_trimesh(m.clone(), BuildOptions::default())
                .unwrap()
                .with_ray_options(options)
                .unwrap();
            let reused = reused.ray_bvh();
            assert_eq!(reused.triangle_order(), built.triangle_order());
            assert_eq!(reused.node_count(), built.node_count());
            assert_eq!(reused.bounds(), built.bounds());
            assert_eq!(reused.memory_bytes(), built.memory_bytes());
            for k in 0..200 {
                let o = Vec3::new(k as f32 * 0.07, (k % 13) as f32, 5.0);
                let ray = Ray::new(o, Vec3::new(0.1, -0.05 * (k % 7) as f32, -1.0));
                assert_eq!(reused.cast_ray(&ray), built.cast_ray(&ray));
            }
        }
        // Other options: built apart, same answers.
        let mesh = Mesh::<Kdop18>::from_trimesh(
            m.clone(),
            BuildOptions {
                split: crate::narrow::SplitRule::Median,
                leaf_size: 3,
            },
        )
        .unwrap();
        let built = RayBvh::build(&m, BuildOptions::RAYS).unwrap();
        assert_eq!(mesh.ray_bvh().triangle_order(), built.triangle_order());
    }

    #[test]
    fn bounds_contain_every_corner_and_ignore_unused_vertices() {
        let far = Vec3::splat(1e6);
        let v = vec![
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(-0.1, 7.0, 0.3),
            Vec3::new(1e-3, -4.0, 2.5),
            far,
        ];
        let m = Mesh::<Kdop18>::new(v.clone(), vec![[0, 1, 2]]).unwrap();
        let (b, s) = (m.aabb(), m.bounding_sphere());
        assert_eq!(
            b,
            Aabb::new(Vec3::new(-0.1, -4.0, 0.3), Vec3::new(1.0, 7.0, 3.0))
        );
        assert_eq!(s.center, b.center());
        for p in &v[..3] {
            assert!((p.as_dvec3() - s.center.as_dvec3()).length() <= s.radius as f64);
        }
        assert!(s.radius < 10.0);
        // Huge coordinates: the radius is rounded up, never down.
        let h = Mesh::<Kdop18>::new(
            vec![Vec3::splat(-3e37), Vec3::new(3e37, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let s = h.bounding_sphere();
        for p in h.trimesh().vertices() {
            assert!((p.as_dvec3() - s.center.as_dvec3()).length() <= s.radius as f64);
        }
    }
}
