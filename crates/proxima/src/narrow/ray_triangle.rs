//! Ray–triangle intersection, watertight (Woop, Benthin, Wald: "Watertight
//! Ray/Triangle Intersection", JCGT 2013), evaluated in `f64`.

use crate::geom::Ray;
use glam::{DVec3, Vec3};

/// Where a ray meets a triangle: parameter `t` and barycentrics `(u, v)` with the
/// hit point `(1-u-v)·a + u·b + v·c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter (in units of `ray.dir`), in `[0, ray.max_t]`.
    pub t: f32,
    /// Weight of the second corner.
    pub u: f32,
    /// Weight of the third corner.
    pub v: f32,
}

/// Closed ray–triangle test: the hit with `0 <= t <= ray.max_t`, edges and corners
/// included. Watertight: the ray is translated to the origin and sheared so that
/// it runs along +z; the three edge functions are then 2D cross products that
/// depend only on the edge's two corners, so a ray through a shared edge sees the
/// same sign on both triangles and cannot slip between them. Computed in `f64`
/// from `f32` inputs (translation exact in most cases, far fewer rounding ties).
///
/// A triangle seen exactly edge-on (zero sheared area), including every degenerate
/// triangle, is never hit. O(1).
pub fn ray_triangle(ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
    let d = ray.dir.as_dvec3();
    let o = ray.origin.as_dvec3();
    // kz: the dominant axis of the direction; kx, ky keep the winding.
    let ad = d.abs();
    let kz = if ad.x >= ad.y && ad.x >= ad.z {
        0
    } else if ad.y >= ad.z {
        1
    } else {
        2
    };
    let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    let sx = d[kx] * sz;
    let sy = d[ky] * sz;
    let rel = |p: Vec3| -> DVec3 {
        let q = p.as_dvec3() - o;
        DVec3::new(q[kx] - sx * q[kz], q[ky] - sy * q[kz], sz * q[kz])
    };
    let (a, b, c) = (rel(tri[0]), rel(tri[1]), rel(tri[2]));
    let u = c.x * b.y - c.y * b.x;
    let v = a.x * c.y - a.y * c.x;
    let w = b.x * a.y - b.y * a.x;
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t_scaled = u * a.z + v * b.z + w * c.z;
    let t = t_scaled / det;
    if t.is_nan() || t < 0.0 || t > ray.max_t as f64 {
        return None;
    }
    Some(TriangleHit {
        t: t as f32,
        u: (v / det) as f32,
        v: (w / det) as f32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_edges_and_misses_outside() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let down = |x: f32, y: f32| Ray::new(Vec3::new(x, y, 1.0), Vec3::NEG_Z);
        let h = ray_triangle(&down(0.25, 0.25), &tri).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6 && (h.u - 0.25).abs() < 1e-6);
        assert!(ray_triangle(&down(0.5, 0.5), &tri).is_some()); // on the hypotenuse
        assert!(ray_triangle(&down(0.0, 0.0), &tri).is_some()); // on a corner
        assert!(ray_triangle(&down(0.6, 0.5), &tri).is_none());
        // Behind the origin, or beyond max_t.
        let up = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z);
        assert!(ray_triangle(&up, &tri).is_none());
        let short = Ray::with_max_t(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.5);
        assert!(ray_triangle(&short, &tri).is_none());
        // Degenerate triangle.
        assert!(ray_triangle(&down(0.0, 0.0), &[Vec3::ZERO; 3]).is_none());
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the diagonal of a unit square; rays through the
        // diagonal must hit at least one of them.
        let t1 = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
        let t2 = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        for i in 1..1000 {
            let s = i as f32 / 1000.0;
            let dir = Vec3::new(0.013, -0.007, -1.0);
            let r = Ray::new(Vec3::new(s, s, 0.0) - dir * 3.7, dir);
            assert!(
                ray_triangle(&r, &t1).is_some() || ray_triangle(&r, &t2).is_some(),
                "{s}"
            );
        }
    }
}
