//! Ball queries on a mesh ([`Mesh::triangles_in_sphere`],
//! [`Mesh::intersects_sphere`]): the collision tree culls with the ball's box as
//! a volume, the exact [`sphere_triangle`] decides at the leaves
//! [sources: near-objects].

use super::mesh::Mesh;
use crate::geom::Sphere;
use crate::narrow::bv::{slack_for, BoundingVolume};
use crate::narrow::sphere_triangle;
use crate::narrow::CostCounters;
use crate::Result;
use glam::Vec3;

impl<BV: BoundingVolume> Mesh<BV> {
    /// Every triangle (index in the mesh, ascending) that shares a point with
    /// the closed ball `sphere` in the mesh's own frame: exactly those for which
    /// [`sphere_triangle`] holds. Fails on a non-finite centre or a negative or
    /// non-finite radius.
    ///
    /// Cost: the collision tree is walked with the ball's bounding box as a
    /// volume (`O(log n)` nodes plus those the box overlaps), then one exact
    /// ball–triangle test per triangle in the leaves reached.
    pub fn triangles_in_sphere(&self, sphere: &Sphere) -> Result<Vec<u32>> {
        sphere.validate()?;
        let mut out = Vec::new();
        self.visit_sphere(sphere, false, &mut Vec::new(), &mut out);
        out.sort_unstable();
        Ok(out)
    }

    /// Whether some triangle shares a point with the closed ball `sphere` (mesh
    /// frame); stops at the first. Same cost bound as
    /// [`Mesh::triangles_in_sphere`], usually far less. Fails as it does.
    pub fn intersects_sphere(&self, sphere: &Sphere) -> Result<bool> {
        sphere.validate()?;
        let mut out = Vec::new();
        self.visit_sphere(sphere, true, &mut Vec::new(), &mut out);
        Ok(!out.is_empty())
    }

    /// Appends to `out` the triangles (mesh indices, traversal order) within the
    /// ball, stopping after the first when `first`; `stack` is scratch space.
    /// The sphere must be valid. Returns the cost counters (`nv` volume tests,
    /// `np` exact triangle tests, `nu = 0`).
    pub(crate) fn visit_sphere(
        &self,
        sphere: &Sphere,
        first: bool,
        stack: &mut Vec<u32>,
        out: &mut Vec<u32>,
    ) -> CostCounters {
        let bvh = self.bvh();
        let vertices = self.trimesh().vertices();
        let (c, r) = (sphere.center, sphere.radius);
        // The ball's box as a volume of the tree's kind, grown by the rounding
        // slack of volumes fitted from `f32` points (as a collision query does).
        let corners: [Vec3; 8] =
            std::array::from_fn(|i| c + Vec3::new(sign(i, 0), sign(i, 1), sign(i, 2)) * r);
        let scale = 2.0 * (bvh.coord_bound + c.abs().element_sum() + 3.0 * r);
        let query = BV::from_points(&corners).inflated(slack_for(scale, 0.0));
        let mut counters = CostCounters::default();
        stack.clear();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let node = &bvh.nodes[i as usize];
            counters.nv += 1;
            if !node.bv.overlaps_fixed(&query) {
                continue;
            }
            if !node.is_leaf() {
                let (l, r) = node.children(i);
                stack.push(r);
                stack.push(l);
                continue;
            }
            for k in node.triangle_range() {
                counters.np += 1;
                let tri = bvh.tris[k].map(|v| vertices[v as usize]);
                if sphere_triangle(c, r, &tri) {
                    out.push(bvh.ids[k]);
                    if first {
                        return counters;
                    }
                }
            }
        }
        counters
    }
}

/// `±1` from bit `axis` of corner number `i`.
#[inline]
fn sign(i: usize, axis: usize) -> f32 {
    if i >> axis & 1 == 0 {
        -1.0
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use crate::geom::Sphere;
    use crate::narrow::{sphere_triangle, Kdop18, Mesh, Obb};
    use crate::narrow::{BoundingVolume, Kdop14, Kdop26};
    use glam::Vec3;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// A bumpy height field.
    fn field(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f32 * 0.25, j as f32 * 0.25);
                v.push(Vec3::new(x, y, (x * 1.7).sin() * (y * 0.9).cos()));
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
        (v, t)
    }

    fn all_volumes<BV: BoundingVolume>() {
        let (v, t) = field(10);
        let mesh = Mesh::<BV>::new(v.clone(), t.clone()).unwrap();
        let mut rng = Pcg64::seed_from_u64(3);
        let mut hits = 0;
        for _ in 0..400 {
            let c = Vec3::new(
                rng.gen_range(-0.5..3.0),
                rng.gen_range(-0.5..3.0),
                rng.gen_range(-1.5..1.5),
            );
            let s = Sphere::new(c, rng.gen_range(0.0..0.6));
            let want: Vec<u32> = (0..t.len() as u32)
                .filter(|&k| sphere_triangle(c, s.radius, &t[k as usize].map(|i| v[i as usize])))
                .collect();
            assert_eq!(mesh.triangles_in_sphere(&s).unwrap(), want, "{}", BV::NAME);
            assert_eq!(mesh.intersects_sphere(&s).unwrap(), !want.is_empty());
            hits += !want.is_empty() as usize;
        }
        assert!((50..350).contains(&hits), "{hits}");
    }

    #[test]
    fn equals_every_triangle_tested_for_every_volume() {
        all_volumes::<Kdop18>();
        all_volumes::<Kdop14>();
        all_volumes::<Kdop26>();
        all_volumes::<Obb>();
        all_volumes::<crate::geom::Aabb>();
        all_volumes::<Sphere>();
    }

    #[test]
    fn bad_spheres_are_errors() {
        let (v, t) = field(2);
        let mesh = Mesh::<Kdop18>::new(v, t).unwrap();
        assert!(mesh
            .triangles_in_sphere(&Sphere::new(Vec3::ZERO, -1.0))
            .is_err());
        assert!(mesh
            .intersects_sphere(&Sphere::new(Vec3::NAN, 1.0))
            .is_err());
        assert!(mesh
            .intersects_sphere(&Sphere::new(Vec3::ZERO, f32::INFINITY))
            .is_err());
    }
}
