//! W6 peer: the `bvh` crate 0.13 (SAH build, `nearest_traverse_iterator`: leaves in
//! order of their box entry). The closest hit is the first triangle hit before the
//! next leaf's box entry. The crate's own `Ray::intersects_triangle` culls back
//! faces and rejects `det < f32::EPSILON` in absolute terms, which drops every
//! small triangle (3 % of the bunny's rays missed); the adapter uses a two-sided
//! Möller–Trumbore in `f32` instead (the same test as obvhs's).

use super::caster::RayCaster;
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::BHShape;
use bvh::bvh::Bvh;
use bvh::ray::Ray as BRay;
use nalgebra::{Point3, Vector3};
use proxima::geom::Ray;
use proxima::narrow::TriMesh;

fn p3(p: proxima::glam::Vec3) -> Point3<f32> {
    Point3::new(p.x, p.y, p.z)
}

/// One triangle as a `bvh` shape.
pub struct Tri {
    v: [Point3<f32>; 3],
    id: u32,
    node: usize,
}

impl Bounded<f32, 3> for Tri {
    fn aabb(&self) -> Aabb<f32, 3> {
        let [a, b, c] = self.v;
        Aabb::with_bounds(a.inf(&b).inf(&c), a.sup(&b).sup(&c))
    }
}

impl BHShape<f32, 3> for Tri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

/// Two-sided Möller–Trumbore: the hit distance, or infinity.
fn moller(r: &BRay<f32, 3>, [a, b, c]: &[Point3<f32>; 3]) -> f32 {
    let (e1, e2) = (b - a, c - a);
    let p = r.direction.cross(&e2);
    let det = e1.dot(&p);
    if det == 0.0 {
        return f32::INFINITY;
    }
    let inv = 1.0 / det;
    let s = r.origin - a;
    let u = s.dot(&p) * inv;
    let q = s.cross(&e1);
    let v = r.direction.dot(&q) * inv;
    let t = e2.dot(&q) * inv;
    if u < 0.0 || v < 0.0 || u + v > 1.0 || t < 0.0 {
        return f32::INFINITY;
    }
    t
}

/// The `bvh` crate's BVH over a mesh.
pub struct BvhCrate {
    bvh: Bvh<f32, 3>,
    tris: Vec<Tri>,
}

impl BvhCrate {
    /// Builds the SAH BVH (single-threaded).
    pub fn build(mesh: &TriMesh) -> Self {
        let mut tris: Vec<Tri> = (0..mesh.len())
            .map(|i| Tri {
                v: mesh.triangle(i).map(p3),
                id: i as u32,
                node: 0,
            })
            .collect();
        let bvh = Bvh::build(&mut tris);
        BvhCrate { bvh, tris }
    }
}

impl RayCaster for BvhCrate {
    fn cast(&self, ray: &Ray) -> Option<(u32, f32)> {
        // The crate normalizes the direction: distances are in units of length.
        let len = ray.dir.length();
        let r = BRay::new(
            p3(ray.origin),
            Vector3::new(ray.dir.x, ray.dir.y, ray.dir.z),
        );
        let max = ray.max_t * len;
        let mut best: Option<(u32, f32)> = None;
        for t in self.bvh.nearest_traverse_iterator(&r, &self.tris) {
            let limit = best.map_or(max, |b| b.1);
            if let Some((enter, _)) = r.intersection_slice_for_aabb(&t.aabb()) {
                if enter > limit {
                    break;
                }
            }
            let d = moller(&r, &t.v);
            if d.is_finite() && d <= limit && best.is_none_or(|b| d < b.1) {
                best = Some((t.id, d));
            }
        }
        best.map(|(i, d)| (i, d / len))
    }
}
