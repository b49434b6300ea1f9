//! Ray–triangle intersection, watertight (Woop, Benthin, Wald: "Watertight
//! Ray/Triangle Intersection", JCGT 2013), evaluated in `f64`.

use crate::geom::Ray;
use glam::{DVec3, Vec3, Vec3A, Vec4};

/// Where a ray meets a mesh: which triangle, at which ray parameter `t`, and the
/// barycentrics `(u, v)` of the hit point `(1-u-v)·a + u·b + v·c` on that
/// triangle's corners `a, b, c`. The one hit type of every narrow-phase cast
/// ([`Mesh`](crate::narrow::Mesh), [`Bvh`](crate::narrow::Bvh),
/// [`RayBvh`](crate::narrow::RayBvh), and [`ray_triangle`] on a lone triangle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Index of the triangle in the mesh (`0` from [`ray_triangle`]: a lone
    /// triangle is triangle 0 of a one-triangle mesh).
    pub triangle: u32,
    /// Ray parameter (in units of `ray.dir`; for a segment, 0 at `a`, 1 at `b`),
    /// in `[0, ray.max_t]`.
    pub t: f32,
    /// Weight of the second corner.
    pub u: f32,
    /// Weight of the third corner.
    pub v: f32,
}

/// A hit on one triangle before it is named: `t` and the barycentrics `(u, v)`.
/// Twelve bytes, so the per-triangle test returns it in registers; the casts
/// name the triangle only for a hit that beats the best one ([`Hit::on`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Hit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

impl Hit {
    /// The hit on triangle `triangle` of a mesh.
    #[inline(always)]
    pub(crate) fn on(self, triangle: u32) -> TriangleHit {
        TriangleHit {
            triangle,
            t: self.t,
            u: self.u,
            v: self.v,
        }
    }

    /// The mesh casts' order of hits: this hit, on `triangle`, comes before
    /// `best` if it is nearer, or as near on a smaller triangle index. Every mesh
    /// cast keeps the first hit in this order (as the tests' brute force does), so
    /// its answer never depends on the order in which triangles are tested.
    #[inline(always)]
    pub(crate) fn precedes(&self, triangle: u32, best: &Option<TriangleHit>) -> bool {
        best.is_none_or(|b| self.t < b.t || (self.t == b.t && triangle < b.triangle))
    }
}

/// Closed ray–triangle test: the hit with `0 <= t <= ray.max_t`, edges and corners
/// included. Watertight: the ray is translated to the origin and sheared so that
/// it runs along +z; the three edge functions are then 2D cross products that
/// depend only on the edge's two corners, so a ray through a shared edge sees the
/// same sign on both triangles and cannot slip between them. Computed in `f64`
/// from `f32` inputs (translation exact in most cases, far fewer rounding ties).
///
/// A triangle seen exactly edge-on (zero sheared area), including every degenerate
/// triangle, is never hit. The hit's `triangle` is 0. O(1).
pub fn ray_triangle(ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
    WoopRay::new(ray).hit(tri).map(|h| h.on(0))
}

/// The per-ray part of [`ray_triangle`] (the dominant axis, the shear and the
/// `f64` origin), computed once for many triangles: `WoopRay::new(ray).hit(tri)`
/// *is* `ray_triangle(ray, tri)`, bit for bit (before naming the triangle).
#[derive(Clone, Copy, Debug)]
pub(crate) struct WoopRay {
    /// The origin, permuted to `(kx, ky, kz)`.
    o: DVec3,
    /// The axis permutation `(kx, ky, kz)` (each `< 3`; masked by 3 when used, so
    /// indexing a 4-array needs no bounds check).
    k: [usize; 3],
    s: DVec3,
    max_t: f64,
}

impl WoopRay {
    /// Prepares `ray` (a valid ray). Never inlined: the casts build it lazily, at
    /// most once per ray, and inlined its setup was hoisted into their loops.
    #[inline(never)]
    pub(crate) fn new(ray: &Ray) -> WoopRay {
        let d = ray.dir.as_dvec3();
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
        let o = ray.origin.as_dvec3();
        WoopRay {
            o: DVec3::new(o[kx], o[ky], o[kz]),
            k: [kx, ky, kz],
            s: DVec3::new(d[kx] * sz, d[ky] * sz, sz),
            max_t: ray.max_t as f64,
        }
    }

    /// The test of one triangle (see [`ray_triangle`]).
    #[inline]
    pub(crate) fn hit(&self, tri: &[Vec3; 3]) -> Option<Hit> {
        let (kx, ky, kz) = (self.k[0] & 3, self.k[1] & 3, self.k[2] & 3);
        let (sx, sy, sz) = (self.s.x, self.s.y, self.s.z);
        // Translate to the origin, permute, shear: the same operations on the same
        // values whatever the order, so the result is the same bit for bit.
        let rel = |p: Vec3| -> DVec3 {
            let p = p.extend(0.0).to_array();
            let q = DVec3::new(p[kx] as f64, p[ky] as f64, p[kz] as f64) - self.o;
            DVec3::new(q.x - sx * q.z, q.y - sy * q.z, sz * q.z)
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
        if t.is_nan() || t < 0.0 || t > self.max_t {
            return None;
        }
        Some(Hit {
            t: t as f32,
            u: (v / det) as f32,
            v: (w / det) as f32,
        })
    }
}

/// A ray prepared for the `f32` pre-test [`RayFilter::may_hit`] of many triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayFilter {
    o: Vec3A,
    d: Vec3A,
    /// `|d|₁`.
    d1: f32,
}

/// Relative error factor of the `f32` Möller–Trumbore edge functions (64 ε; the
/// analysis below needs 26 ε).
const FILTER_EPS: f32 = 64.0 * f32::EPSILON;
/// Covers the `f64` test's own rounding (relative `2^-48` at worst) when a
/// triangle is tiny compared with its distance to the ray origin.
const FILTER_FAR: f32 = 1.0 / (1u64 << 40) as f32;

impl RayFilter {
    /// Prepares `ray`.
    #[inline]
    pub(crate) fn new(ray: &Ray) -> RayFilter {
        let d = Vec3A::from(ray.dir);
        RayFilter {
            o: Vec3A::from(ray.origin),
            d,
            d1: d.abs().element_sum(),
        }
    }

    /// A conservative `f32` reject test: false only if [`ray_triangle`] certainly
    /// misses the triangle `v0, v1, v2` (whatever `max_t`); true means "maybe", and
    /// the caller runs the exact test. `e1 = v0 - v1`, `e2 = v2 - v0`,
    /// `ng = e1 × e2` and `e_l1 = max(|e1|₁, |e2|₁)` as computed in `f32`
    /// ([`prepare_triangle`]).
    ///
    /// Möller–Trumbore's unnormalized barycentrics `U = (d × c)·e2`,
    /// `V = (d × c)·e1` and `W = ng·d − U − V` (with `c = v0 − o`) are, in exact
    /// arithmetic, the three edge functions of the watertight test up to one common
    /// factor; the ray misses iff two of them have strictly opposite signs. Each
    /// is a sum of products of three coordinates, so its `f32` rounding error is at
    /// most `26 ε · |d|₁ · e · (e + |c|₁)` (with `e` the edges' L1 bound; this
    /// includes the rounding of `c`, of the edges and of `ng`). The test rejects
    /// only when one value is below `−τ` and another above `τ`, with `τ` that bound
    /// times 2.5 plus a term for the `f64` test's own rounding, so the `f64` test
    /// sees the same strict sign disagreement and returns `None` too. Overflow to
    /// infinity or NaN makes `τ` infinite or the comparisons false: no rejection.
    /// Costs about a fifth of the `f64` test.
    ///
    /// With `limit` (the ray's `max_t`, or the best hit so far) it also rejects a
    /// triangle whose plane the ray certainly crosses behind the origin or beyond
    /// `limit · (1 + 4ε)` (so a hit that would round to `limit` and win a tie is
    /// kept): `t = (ng·c) / (ng·d)`, both dot products within `64 ε e² |c|₁` and
    /// `64 ε e² |d|₁` of exact, used only when the sign of `ng·d` is certain; the
    /// `2^-40 |c|₁²` terms cover the `f64` test's own numerator and determinant
    /// errors with a factor `2^10` to spare, so it sees `t < 0` or `t > limit` too.
    #[inline(always)]
    pub(crate) fn may_hit(
        &self,
        v0: Vec3A,
        e1: Vec3A,
        e2: Vec3A,
        ng: Vec3A,
        e_l1: f32,
        limit: f32,
    ) -> bool {
        let c = v0 - self.o;
        let r = self.d.cross(c);
        let u = r.dot(e2);
        let v = r.dot(e1);
        let det = ng.dot(self.d);
        let w = det - u - v;
        let c1 = c.abs().element_sum();
        let far = FILTER_FAR * c1 * c1;
        let tau = self.d1 * (FILTER_EPS * e_l1 * (e_l1 + c1) + far);
        let lo = u.min(v).min(w);
        let hi = u.max(v).max(w);
        if lo < -tau && hi > tau {
            return false;
        }
        let e2l = FILTER_EPS * e_l1 * e_l1 + far;
        let (tau_det, tau_num) = (e2l * self.d1, e2l * c1);
        let a = det.abs();
        if a > tau_det {
            let b = if det < 0.0 { -ng.dot(c) } else { ng.dot(c) };
            // Behind the origin, or beyond the limit (never for an infinite limit).
            let l = limit * (1.0 + 4.0 * f32::EPSILON);
            if b < -tau_num || b - l * a > tau_num + l * tau_det {
                return false;
            }
        }
        true
    }
}

/// Four triangles' `f32` pre-test data side by side (one SIMD lane each, structure
/// of arrays) for [`RayFilter::may_hit4`]: the data of [`prepare_triangle`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriPacket {
    /// First corners, per axis.
    pub v0: [Vec4; 3],
    /// `v0 − v1`, per axis.
    pub e1: [Vec4; 3],
    /// `v2 − v0`, per axis.
    pub e2: [Vec4; 3],
    /// `e1 × e2`, per axis.
    pub ng: [Vec4; 3],
    /// `max(|e1|₁, |e2|₁)`.
    pub l1: Vec4,
}

impl TriPacket {
    /// The packet of up to four triangles (corners as stored); missing lanes
    /// repeat the last triangle (the caller masks them out).
    pub(crate) fn new(tris: &[[Vec3A; 3]]) -> TriPacket {
        let mut p = TriPacket {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            ng: [Vec4::ZERO; 3],
            l1: Vec4::ZERO,
        };
        for k in 0..4 {
            let t = &tris[k.min(tris.len() - 1)];
            let (e1, e2, ng, l1) = prepare_triangle(t);
            for a in 0..3 {
                p.v0[a][k] = t[0][a];
                p.e1[a][k] = e1[a];
                p.e2[a][k] = e2[a];
                p.ng[a][k] = ng[a];
            }
            p.l1[k] = l1;
        }
        p
    }
}

impl RayFilter {
    /// [`RayFilter::may_hit`] on four triangles at once: the mask of the lanes that
    /// may be hit at or before `limit` (bit `k` for lane `k`) and, per lane, an
    /// estimate of the hit's `t` (the `f32` plane crossing when the sign of
    /// `ng·d` is certain, else `0`: only an ordering hint, never a bound). The same
    /// bounds as the scalar test, lane by lane (its error analysis does not depend
    /// on the order of the three products in a sum); a lane with a NaN edge
    /// function is never rejected.
    #[inline(always)]
    pub(crate) fn may_hit4(&self, p: &TriPacket, limit: f32) -> (u32, Vec4) {
        let o = [
            Vec4::splat(self.o.x),
            Vec4::splat(self.o.y),
            Vec4::splat(self.o.z),
        ];
        let d = [
            Vec4::splat(self.d.x),
            Vec4::splat(self.d.y),
            Vec4::splat(self.d.z),
        ];
        let c = [p.v0[0] - o[0], p.v0[1] - o[1], p.v0[2] - o[2]];
        // r = d × c
        let r = [
            d[1] * c[2] - d[2] * c[1],
            d[2] * c[0] - d[0] * c[2],
            d[0] * c[1] - d[1] * c[0],
        ];
        let dot = |a: &[Vec4; 3], b: &[Vec4; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let u = dot(&r, &p.e2);
        let v = dot(&r, &p.e1);
        let det = dot(&p.ng, &d);
        let w = det - u - v;
        let c1 = c[0].abs() + c[1].abs() + c[2].abs();
        let far = Vec4::splat(FILTER_FAR) * c1 * c1;
        let d1 = Vec4::splat(self.d1);
        let eps = Vec4::splat(FILTER_EPS);
        let tau = d1 * (eps * p.l1 * (p.l1 + c1) + far);
        let lo = u.min(v).min(w);
        let hi = u.max(v).max(w);
        let numbers = u.cmpeq(u) & v.cmpeq(v) & w.cmpeq(w);
        let miss = lo.cmplt(-tau) & hi.cmpgt(tau) & numbers;
        let e2l = eps * p.l1 * p.l1 + far;
        let (tau_det, tau_num) = (e2l * d1, e2l * c1);
        let a = det.abs();
        let certain = a.cmpgt(tau_det);
        let nc = dot(&p.ng, &c);
        let b = Vec4::select(det.cmplt(Vec4::ZERO), -nc, nc);
        let l = Vec4::splat(limit * (1.0 + 4.0 * f32::EPSILON));
        let out = b.cmplt(-tau_num) | (b - l * a).cmpgt(tau_num + l * tau_det);
        let reject = miss | (certain & out);
        let est = Vec4::select(certain, b / a, Vec4::ZERO);
        ((!reject).bitmask(), est)
    }
}

/// The `f32` data of [`RayFilter::may_hit`] for triangle `t`: `(e1, e2, ng, e_l1)`.
#[inline(always)]
pub(crate) fn prepare_triangle(t: &[Vec3A; 3]) -> (Vec3A, Vec3A, Vec3A, f32) {
    let e1 = t[0] - t[1];
    let e2 = t[2] - t[0];
    let l1 = e1.abs().element_sum().max(e2.abs().element_sum());
    (e1, e2, e1.cross(e2), l1)
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

    /// The `f32` pre-test never rejects a triangle the exact test hits, on rays
    /// aimed at corners, edges and interiors (where rounding matters most), from
    /// near and far, at all scales.
    #[test]
    fn filter_never_rejects_a_hit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let (mut hits, mut rejected) = (0, 0);
        for i in 0..200_000 {
            let scale = 10f32.powi(rng.gen_range(-3..4));
            let p = |rng: &mut rand_pcg::Pcg64| {
                Vec3::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ) * scale
            };
            let tri = [p(&mut rng), p(&mut rng), p(&mut rng)];
            let far = if i % 3 == 0 { 1000.0 } else { 3.0 };
            let o = p(&mut rng) * far;
            // Aim at a corner, an edge point, an interior point or anywhere.
            let (a, b) = (rng.gen_range(0.0..1.0f32), rng.gen_range(0.0..1.0f32));
            let target = match i % 5 {
                0 => tri[i % 3],
                1 => tri[0] + (tri[1] - tri[0]) * a,
                2 => tri[1] + (tri[2] - tri[1]) * a,
                3 => tri[0] + (tri[1] - tri[0]) * a * (1.0 - b) + (tri[2] - tri[0]) * b * (1.0 - a),
                _ => p(&mut rng),
            };
            let ray = Ray::new(o, target - o);
            if ray.dir == Vec3::ZERO {
                continue;
            }
            let exact = ray_triangle(&ray, &tri);
            let (e1, e2, ng, l1) = prepare_triangle(&tri.map(Vec3A::from));
            let maybe =
                RayFilter::new(&ray).may_hit(Vec3A::from(tri[0]), e1, e2, ng, l1, f32::INFINITY);
            if exact.is_some() {
                hits += 1;
                assert!(maybe, "rejected a hit: {ray:?} {tri:?}");
            } else if !maybe {
                rejected += 1;
            }
        }
        assert!(hits > 50_000 && rejected > 10_000, "{hits} {rejected}");
    }

    /// The four-lane pre-test rejects exactly what the scalar one rejects on
    /// random packets (so it inherits its guarantee, checked above), and never a
    /// lane the exact test hits, with finite and finite-limit rays.
    #[test]
    fn packet_filter_matches_scalar_filter() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let (mut hits, mut rejected) = (0, 0);
        for i in 0..50_000 {
            let scale = 10f32.powi(rng.gen_range(-3..4));
            let p = |rng: &mut rand_pcg::Pcg64| {
                Vec3::new(
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ) * scale
            };
            let n = rng.gen_range(1..=4);
            let tris: Vec<[Vec3; 3]> = (0..n)
                .map(|_| [p(&mut rng), p(&mut rng), p(&mut rng)])
                .collect();
            let o = p(&mut rng) * if i % 3 == 0 { 1000.0 } else { 3.0 };
            let tri = tris[i % n];
            let (a, b) = (rng.gen_range(0.0..1.0f32), rng.gen_range(0.0..1.0f32));
            let target = match i % 4 {
                0 => tri[i % 3],
                1 => tri[0] + (tri[1] - tri[0]) * a,
                2 => tri[0] + (tri[1] - tri[0]) * a * (1.0 - b) + (tri[2] - tri[0]) * b * (1.0 - a),
                _ => p(&mut rng),
            };
            if target == o {
                continue;
            }
            let max_t = if i % 2 == 0 {
                f32::INFINITY
            } else {
                rng.gen_range(0.0..2.0) * (target - o).length()
            };
            let ray = Ray::with_max_t(o, target - o, max_t);
            let filter = RayFilter::new(&ray);
            let stored: Vec<[Vec3A; 3]> = tris.iter().map(|t| t.map(Vec3A::from)).collect();
            let (mask, _) = filter.may_hit4(&TriPacket::new(&stored), ray.max_t);
            for (k, t) in stored.iter().enumerate() {
                let (e1, e2, ng, l1) = prepare_triangle(t);
                let scalar = filter.may_hit(t[0], e1, e2, ng, l1, ray.max_t);
                assert_eq!(mask >> k & 1 == 1, scalar, "lane {k}: {ray:?} {t:?}");
                if ray_triangle(&ray, &tris[k]).is_some() {
                    hits += 1;
                    assert!(scalar);
                } else if !scalar {
                    rejected += 1;
                }
            }
        }
        assert!(hits > 5_000 && rejected > 10_000, "{hits} {rejected}");
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
