//! Point and ball queries on one mesh: the nearest point of the surface, the
//! distance and overlap of a ball.

use super::query::Proximity;
use super::traverse::{descend_one, Cut, Order};
use super::triangle::Tri64;
use crate::error::check_vec3;
use crate::geom::Sphere;
use crate::narrow::bv::{slack_for, BoundingVolume};
use crate::narrow::{Bvh, CostCounters, Mesh};
use crate::Result;
use glam::{DVec3, Vec3};

/// The rounding slack of a query of tree `t` against the point `p` (no pose):
/// [`slack_for`] the largest `|x| + |y| + |z|` of a difference of their points.
pub(super) fn point_slack<BV>(t: &Bvh<BV>, p: Vec3) -> f32 {
    slack_for(2.0 * (t.coord_bound + p.abs().element_sum()), 0.0)
}

/// The point of a mesh nearest to a query point (or ball).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// The nearest point of the mesh surface, in the mesh's frame.
    pub point: DVec3,
    /// The mesh triangle it lies on.
    pub triangle: u32,
    /// The distance from the query point to `point` (for a ball: from its
    /// surface, `0` if they overlap).
    pub distance: f64,
    /// Cost counters of the query (`Nv` volume bounds, `Np` point–triangle
    /// distances).
    pub counters: CostCounters,
}

impl<BV: BoundingVolume> Mesh<BV> {
    /// The point of this mesh's surface nearest to `p` (in the mesh's frame),
    /// its triangle and distance: [`Proximity::closest_point`] with a new query
    /// object, whose scratch space is allocated for this one query; keep a
    /// [`Proximity`] for repeated queries.
    pub fn closest_point(&self, p: Vec3) -> Result<ClosestPoint> {
        Proximity::default().closest_point(self, p)
    }

    /// The distance between the ball `s` and this mesh's surface:
    /// [`Proximity::sphere_distance`] with a new query object (see
    /// [`Mesh::closest_point`]).
    pub fn sphere_distance(&self, s: &Sphere) -> Result<ClosestPoint> {
        Proximity::default().sphere_distance(self, s)
    }

    /// Whether the ball `s` touches this mesh's surface, with an early exit:
    /// [`Proximity::sphere_overlaps`] with a new query object (see
    /// [`Mesh::closest_point`]).
    pub fn sphere_overlaps(&self, s: &Sphere) -> Result<bool> {
        Proximity::default().sphere_overlaps(self, s)
    }
}

impl<BV: BoundingVolume> Proximity<BV> {
    /// The point of the mesh surface nearest to `p` (in the mesh's frame), the
    /// triangle it lies on and its distance, computed in `f64` (the projection on
    /// the triangle if it falls inside, else the nearest point of its edges).
    /// Ties go to whichever triangle the descent meets first.
    ///
    /// Cost: a best-first descent with the volumes' distance bounds to the point
    /// ([`BoundingVolume::distance_lower_bound`] against the volume of the point):
    /// O(log n) volumes and a few triangles for a point near the surface; more
    /// for a point far from a curved mesh (many triangles at similar distances).
    ///
    /// Fails on a non-finite `p`.
    pub fn closest_point(&mut self, mesh: &Mesh<BV>, p: Vec3) -> Result<ClosestPoint> {
        check_vec3(p, "query point")?;
        let cut = Cut {
            value: f64::INFINITY,
            inclusive: false,
        };
        let (best, counters) = self.nearest(mesh, p, Order::BestFirst, cut, false)?;
        // A mesh has a triangle and the first one met is kept.
        let (d, q, t) = best.unwrap_or((f64::INFINITY, DVec3::ZERO, 0));
        Ok(ClosestPoint {
            point: q,
            triangle: t,
            distance: d,
            counters,
        })
    }

    /// The distance between the ball `s` and the mesh surface (`0` if they
    /// overlap), with the surface point nearest to the centre. A ball entirely
    /// inside a closed mesh does not touch its surface: see
    /// [`Proximity::contains_point`] for the solid.
    ///
    /// Cost: [`Proximity::closest_point`] of the centre. Fails on a non-finite
    /// centre or radius, a negative radius.
    pub fn sphere_distance(&mut self, mesh: &Mesh<BV>, s: &Sphere) -> Result<ClosestPoint> {
        s.validate()?;
        let mut c = self.closest_point(mesh, s.center)?;
        c.distance = (c.distance - s.radius as f64).max(0.0);
        Ok(c)
    }

    /// Whether the ball `s` touches the mesh surface: some triangle within
    /// `s.radius` of the centre (closed). Always the same answer as
    /// `sphere_distance(..)?.distance == 0`, but stops at the first triangle
    /// found and cuts every volume farther than the radius.
    ///
    /// Fails as [`Proximity::sphere_distance`].
    pub fn sphere_overlaps(&mut self, mesh: &Mesh<BV>, s: &Sphere) -> Result<bool> {
        s.validate()?;
        let cut = Cut {
            value: s.radius as f64,
            inclusive: true,
        };
        let (hit, _) = self.nearest(mesh, s.center, Order::DepthFirst, cut, true)?;
        Ok(hit.is_some())
    }

    /// The triangle nearest to `p` within the cut (the first one within it if
    /// `any`): `(distance, point, mesh triangle)`.
    #[allow(clippy::type_complexity)]
    fn nearest(
        &mut self,
        mesh: &Mesh<BV>,
        p: Vec3,
        order: Order,
        mut cut: Cut,
        any: bool,
    ) -> Result<(Option<(f64, DVec3, u32)>, CostCounters)> {
        let (t, m) = (mesh.bvh(), mesh.trimesh());
        let slack = point_slack(t, p);
        let probe = BV::from_points(&[p]).inflated(slack);
        let (p64, verts) = (p.as_dvec3(), m.vertices());
        let mut c = CostCounters::default();
        let mut best = None;
        descend_one(
            &t.nodes,
            &probe,
            order,
            &mut self.frontier,
            &mut c.nv,
            &mut cut,
            |leaf, _, cut| {
                for k in t.nodes[leaf].triangle_range() {
                    c.np += 1;
                    let tri = Tri64::new(t.tris[k].map(|v| verts[v as usize]));
                    let q = tri.closest_point(p64);
                    let d = p64.distance(q);
                    if cut.keeps_distance(d) {
                        best = Some((d, q, t.ids[k]));
                        cut.value = d;
                        if any || d == 0.0 {
                            return true;
                        }
                    }
                }
                false
            },
        );
        self.counters = c;
        Ok((best, c))
    }
}
