//! The AABB (6-DOP) as a BVH bounding volume.

use super::{box_gap, clip_slab, BoundingVolume};
use crate::geom::{Aabb, Ray};
use glam::{Affine3A, Vec3};

/// The AABB is the 6-DOP of [sources: kdop]: three coordinate slabs, 6 comparisons per test.
impl BoundingVolume for Aabb {
    /// `(lo, hi)`: the translation minus/plus the slack, added to `min`/`max`.
    type Motion = (Vec3, Vec3);

    const NAME: &'static str = "aabb";
    const AXIS_ALIGNED: bool = true;

    fn from_points(points: &[Vec3]) -> Self {
        let mut b = Aabb::EMPTY;
        for &p in points {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }

    fn from_triangles(triangles: &[[Vec3; 3]]) -> Self {
        let mut b = Aabb::EMPTY;
        for t in triangles {
            for &p in t {
                b.min = b.min.min(p);
                b.max = b.max.max(p);
            }
        }
        b
    }

    #[inline]
    fn merge(&self, o: &Self) -> Self {
        self.union(o)
    }

    /// The AABB of the rotated box: centre moved, half-extents `|R|·e`. Conservative.
    fn transformed(&self, pose: &Affine3A) -> Self {
        let c = pose.transform_point3(self.center());
        let e = self.half_extent();
        let m = pose.matrix3;
        let r = Vec3::new(
            Vec3::from(m.row(0)).abs().dot(e),
            Vec3::from(m.row(1)).abs().dot(e),
            Vec3::from(m.row(2)).abs().dot(e),
        );
        Aabb::new(c - r, c + r)
    }

    fn motion(pose: &Affine3A, slack: f32) -> Self::Motion {
        let t = Vec3::from(pose.translation);
        (t - Vec3::splat(slack), t + Vec3::splat(slack))
    }

    #[inline]
    fn overlaps(&self, m: &Self::Motion, o: &Self) -> bool {
        (self.min + m.0).cmple(o.max).all() && o.min.cmple(self.max + m.1).all()
    }

    fn inflated(&self, slack: f32) -> Self {
        self.grown(slack)
    }

    #[inline(always)]
    fn overlaps_fixed(&self, o: &Self) -> bool {
        self.min.cmple(o.max).all() && o.min.cmple(self.max).all()
    }

    #[inline]
    fn size(&self) -> f32 {
        let e = self.extent();
        e.x + e.y + e.z
    }

    fn ray_entry(&self, ray: &Ray, slack: f32) -> Option<f32> {
        let (mut t0, mut t1) = (0.0f32, ray.max_t);
        for a in 0..3 {
            if !clip_slab(
                ray.origin[a],
                ray.dir[a],
                self.min[a] - slack,
                self.max[a] + slack,
                &mut t0,
                &mut t1,
            ) {
                return None;
            }
        }
        Some(t0)
    }

    /// The distance between the moved box (grown by the slack) and `o`. Exact for
    /// boxes, up to the slack.
    #[inline]
    fn distance_lower_bound(&self, m: &Self::Motion, o: &Self) -> f32 {
        box_gap(self.min + m.0, self.max + m.1, o.min, o.max)
    }

    #[inline(always)]
    fn distance_lower_bound_fixed(&self, o: &Self) -> f32 {
        box_gap(self.min, self.max, o.min, o.max)
    }
}
